"""The TSLIP's viable set over (y, phi, phid): the r study, and the 3-D map at scale.

Run by hand (not in CI), one mode at a time:

``python benchmarks/bench_viability_3d.py study``
    The r study of docs/analyses/viability.md: the Table 2.1 passive model
    with no retraction (``omega_r = 0``, so the apex is a Poincare section)
    at r = -0.3, 0, 0.3, 0.6, all at the total energy of the Table 2.1 gait
    (r = 0.3, E = 13.0675 MgL), on one grid: apex height y in [0.4, 1.4] (26
    points), pitch phi in [-0.2, 0.2] (11), pitch rate phid in [-0.5, 0.5]
    (11), leg angle alpha_r in [0.85, 1.25] (21): 66,066 cells per r. For
    each r and cell rule: the share of strides that do not fail, the viable
    volume (share of the state grid), and the slice at phi = 0 / phid = 0 and
    projections, as :class:`tslip.gait.viability.ViableSection` fractions.
``python benchmarks/bench_viability_3d.py study --n 31 --out DIR``
    The same on the scale grid below (n^3 states x 41 actions), each r's map
    out of core in ``DIR/r<r>`` (resumable), on two worker processes.
``python benchmarks/bench_viability_3d.py scale --n 20 [--engines pool1,pool2,dask2] [--out DIR]``
    An n x n x n state grid (y in [0.4, 1.4], phi in [-0.2, 0.2], phid in
    [-0.5, 0.5]) x 41 actions (alpha_r in [0.85, 1.25]) at r = 0.3 through
    :func:`tslip.sweeps.viability.run_viability`: on 1 and 2 worker
    processes and on a Dask ``LocalCluster`` of 2 single-threaded worker
    processes (``--engines`` picks); wall, cells per second, CPU per cell
    (this process plus its children), and the peak resident memory of this
    process and of its largest child; progress about once a minute. With
    ``--out DIR`` each engine's run stays in ``DIR/<engine>``: rerunning the
    same command after an interruption resumes with the missing chunks (the
    figures then cover the cells computed in that run). The issue's grid is
    ``--n 60`` (8.9 million cells), e.g. (``nice -n 5`` on a shared machine)
    ``python benchmarks/bench_viability_3d.py scale --n 60 --engines pool2 --out DIR``.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import resource
import tempfile
import time

import numpy as np

E = 13.06748095449187  # the Table 2.1 gait's total energy [MgL] (r = 0.3)


def grid(n_y: int, n_phi: int, n_phid: int) -> dict[str, np.ndarray]:
    return {"y": np.linspace(0.4, 1.4, n_y), "phi": np.linspace(-0.2, 0.2, n_phi),
            "phid": np.linspace(-0.5, 0.5, n_phid)}


def params(r: float):  # noqa: ANN201
    import tslip

    return dataclasses.replace(tslip.preset("table2.1"), omega_r=0.0, r=r)


def study(n: int | None = None, out: str | None = None) -> None:
    from tslip.gait.viability import state_action_map, viability

    print(f"{'r':>5} {'rule':>8} {'no fall':>8} {'volume':>7} {'pairs':>7} "
          f"{'phi=0':>7} {'phid=0':>7} {'proj phi':>8} {'proj phid':>9} {'sweeps':>6}")
    for r in (-0.3, 0.0, 0.3, 0.6):
        if n is None:
            g = grid(26, 11, 11)
            m = state_action_map(params(r), g, ("alpha_r", np.linspace(0.85, 1.25, 21)),
                                 energy=E)
        else:  # the scale grid, out of core, one folder per r
            from tslip.sweeps.viability import run_viability

            m = run_viability(_spec(n, r), f"{out}/r{r:+.1f}" if out else None,
                              workers=2).map
        failed = m.failed
        for rule in ("bracket", "nearest", "vibly"):
            v = viability(m, rule)
            print(f"{r:5.1f} {rule:>8} {1 - failed.mean():8.4f} {v.volume_fraction:7.4f} "
                  f"{v.viable_fraction:7.4f} {v.slice('phi').fraction:7.4f} "
                  f"{v.slice('phid').fraction:7.4f} {v.projection('phi').fraction:8.4f} "
                  f"{v.projection('phid').fraction:9.4f} {v.sweeps:6d}", flush=True)


def _spec(n: int, r: float = 0.3):  # noqa: ANN202
    from tslip.sweeps.spec import Axis
    from tslip.sweeps.viability import ViabilitySpec

    g = grid(n, n, n)
    return ViabilitySpec(name=f"scale{n}", base=params(r),
                         states=tuple(Axis(k, tuple(float(x) for x in v)) for k, v in g.items()),
                         action=Axis("alpha_r", tuple(float(x) for x in
                                                      np.linspace(0.85, 1.25, 41))),
                         energy=E)


def run_scale(n: int, engines: list[str], out: str | None) -> None:
    from tslip.sweeps.viability import run_viability, saved_cells

    spec = _spec(n)
    cells = spec.n_cells
    print(f"{n}^3 x 41 = {cells} cells, {len(spec.chunks())} chunks; engines {engines}",
          flush=True)
    for label in engines:
        with tempfile.TemporaryDirectory() as tmp:
            folder = f"{out}/{label}" if out else tmp
            cached = saved_cells(spec, folder)
            if cached:
                print(f"{label}: resuming in {folder}, {cached} cells cached", flush=True)
            c0, w0 = _own_cpu(), time.perf_counter()
            if label == "dask2":
                from dask.distributed import Client, LocalCluster

                with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, Client(cluster) as client:
                    w0 = time.perf_counter()
                    c0 = _own_cpu() - sum(client.run(_own_cpu).values())
                    v = run_viability(spec, folder, scheduler=cluster.scheduler_address,
                                      progress=_Progress(w0, cached))
                    wall = time.perf_counter() - w0
                    cpu = _own_cpu() - c0 + sum(client.run(_own_cpu).values())
                    peak_w = max(client.run(_own_peak).values())
            else:
                workers = int(label.removeprefix("pool"))
                prog = _Progress(w0, cached)
                v = run_viability(spec, folder, workers=workers, progress=prog)
                wall = time.perf_counter() - w0
                cpu = _own_cpu() - c0 + sum(prog.cpu.values())
                peak_w = max(prog.peak.values(), default=0.0)
            t_it = time.perf_counter()
            q = v.q.sum()  # the viable sets are in memory; the map is on disk
            done = cells - cached
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        per = f"{1e6 * cpu / done:6.1f} us CPU per computed cell" if done else "all cached"
        print(f"{label}: wall {wall:8.1f} s for {done} computed cells "
              f"({done / wall:8.0f} cells/s); CPU {cpu:8.1f} s = {per}; "
              f"peak RSS here {peak:.0f} MB, largest worker {peak_w:.0f} MB; "
              f"volume {v.volume_fraction:.4f}, {q} viable pairs, {v.sweeps} sweeps "
              f"({time.perf_counter() - t_it:.1f} s to sum)", flush=True)


class _Progress:
    """At every progress call samples the CPU seconds and peak RSS (VmHWM) of every process
    below this one (the pool's workers are grandchildren, forked by a fork server, so
    ``RUSAGE_CHILDREN`` misses them); prints cells done, the rate and the time left about
    once a minute."""

    def __init__(self, w0: float, cached: int) -> None:
        import psutil

        self.me = psutil.Process()
        self.w0, self.cached, self.last = w0, cached, w0
        self.cpu: dict[int, float] = {}
        self.peak: dict[int, float] = {}

    def sample(self) -> None:
        import psutil

        for p in self.me.children(recursive=True):
            try:
                t = p.cpu_times()
                self.cpu[p.pid] = t.user + t.system
                with open(f"/proc/{p.pid}/status") as f:
                    hwm = next(ln for ln in f if ln.startswith("VmHWM:"))
                self.peak[p.pid] = int(hwm.split()[1]) / 1024
            except (psutil.Error, OSError, StopIteration):
                pass

    def __call__(self, done: int, total: int) -> None:
        self.sample()
        now = time.perf_counter()
        if now - self.last < 60 and done < total:
            return
        self.last = now
        rate = (done - self.cached) / max(now - self.w0, 1e-9)
        left = (total - done) / rate if rate > 0 else float("nan")
        print(f"  {done}/{total} cells, {rate:.0f} cells/s, {left / 60:.1f} min left "
              f"(load {os.getloadavg()[0]:.1f})", flush=True)


def _own_cpu() -> float:
    s = resource.getrusage(resource.RUSAGE_SELF)
    return s.ru_utime + s.ru_stime


def _own_peak() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", choices=("study", "scale"))
    ap.add_argument("--n", type=int, default=None,
                    help="state grid points per axis (scale: default 20; study: default the "
                         "26 x 11 x 11 grid in memory)")
    ap.add_argument("--engines", default="pool1,pool2,dask2",
                    help="comma-separated: poolN (N worker processes), dask2 (scale)")
    ap.add_argument("--out", default=None,
                    help="keep each run in OUT/<engine> (scale) or OUT/r<r> (study): rerun "
                         "to resume after an interruption (default: a temporary folder)")
    args = ap.parse_args()
    if args.mode == "study":
        study(args.n, args.out)
    else:
        run_scale(args.n or 20, args.engines.split(","), args.out)


if __name__ == "__main__":
    main()
