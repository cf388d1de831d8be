"""``tslip reproduce``: wall time on 1 and 2 workers, CPU per phase, critical path, vs 1b54594.

Run: ``python benchmarks/bench_reproduce.py [--quick] [--no-baseline] [--repeat N]``.
Each run is a fresh interpreter starting from an empty output folder
(studies and Appendix E recomputed); numba's kernel cache is left as it is
(warm after the first run).

Printed, per worker count: the wall time of the computation
(:func:`tslip.plotting.report.compute`, as ``tslip reproduce`` runs it: every
study, figure and plot a task on one pool) and of the report left after it
(claims, HTML), the CPU seconds of the main process (assembling; with 1
worker, every task too) and of every task summed by phase (study solves,
study analyses, single-gait figures, Table 6.1, Appendix E, plots), and the
critical path: the longest chain of tasks, each made ready by the one before
(a 2-D study's lines), in CPU seconds. Then the 1 -> 2 worker speed-up,
what the wall time would be on a quiet 2-core machine (``max(CPU / 2,
critical path) + report``, CPU being the whole process tree's, worker
start-up included: the machine is shared, so the measured wall time
includes other people's work), the machine's ceiling for that speed-up (two
1-worker runs at once, each in its own interpreter, against one alone:
``2 T_alone / mean(T_pair)``, what two cores give this work with no scheduling
loss at all; ``--no-ceiling`` skips it), and the ratio against revision
:data:`_baseline.BASELINE_REV` timed in the same run
(``tslip.plotting.report.reproduce`` on all cores, best of ``--repeat``).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections import Counter, defaultdict
from typing import Any

from _baseline import BASELINE_REV, run_at

from tslip.plotting.report import compute, write_report


def _phase(key: Any) -> str:
    if key[0] == "plot":
        return "plots"
    if key[0] == "figure":
        return {"table6.1": "table 6.1", "E": "appendix E"}.get(key[1], "figures")
    return f"study {key[1]}"


def _critical_path(timing: dict[Any, tuple[float, float, Any]]) -> tuple[float, list[Any]]:
    """Longest chain of tasks (each made ready by the previous) in CPU seconds."""
    memo: dict[Any, float] = {}

    def length(key: Any) -> float:
        if key not in memo:
            cpu, _, parent = timing[key]
            memo[key] = cpu + (length(parent) if parent is not None else 0.0)
        return memo[key]

    end = max(timing, key=length)
    chain, k = [], end
    while k is not None:
        chain.append(k)
        k = timing[k][2]
    return length(end), chain[::-1]


def _server_cpu() -> float:
    """CPU seconds of the fork server and the workers it forked (ended by now), if any.

    They are not this process's children, so its ``RUSAGE_CHILDREN`` misses them.
    """
    from multiprocessing import forkserver

    import psutil

    pid = getattr(forkserver._forkserver, "_forkserver_pid", None)
    if pid is None:
        return 0.0
    server = psutil.Process(pid)
    deadline = time.monotonic() + 5.0
    while server.children() and time.monotonic() < deadline:  # not reaped yet
        time.sleep(0.05)
    t = server.cpu_times()
    return t.user + t.system + t.children_user + t.children_system


def _measure(resolution: str, workers: int) -> dict[str, Any]:
    """One run here (in a child process of :func:`_once`)."""
    cpu_before = time.process_time()  # this interpreter's start-up and imports
    with tempfile.TemporaryDirectory() as d:
        timing: dict[Any, tuple[float, float, Any]] = {}
        c0, t0 = time.process_time(), time.perf_counter()
        data, claims, _, images, _ = compute(d, resolution=resolution, workers=workers,
                                             timing=timing)
        t1, c1 = time.perf_counter(), time.process_time()
        write_report(os.path.join(d, "index.html"), data, claims, quick=data["quick"],
                     images=images)
        t2 = time.perf_counter()
        main_cpu = c1 - c0  # assembling (and, with 1 worker, every task)
    pool_cpu = _server_cpu()
    phases: dict[str, float] = defaultdict(float)
    for key, (cpu, _, _) in timing.items():
        phases[_phase(key)] += cpu
    path, chain = _critical_path(timing)
    verdicts = Counter(str(c.verdict.value) for c in claims)
    return {"compute": t1 - t0, "report": t2 - t1, "wall": t2 - t0, "phases": dict(phases),
            "cpu": sum(phases.values()), "path": path, "chain": chain, "tasks": len(timing),
            "main_cpu": main_cpu, "startup_cpu": cpu_before, "verdicts": dict(verdicts),
            "pool_cpu": pool_cpu}


def _once(resolution: str, workers: int) -> dict[str, Any]:
    """One run in a fresh interpreter (as ``tslip reproduce``); ``total_cpu``: its whole
    process tree's CPU seconds (the fork server and the workers, their start-up included),
    less the interpreter's own start-up and imports."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run([sys.executable, __file__, "--child", resolution, str(workers)],
                         capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(out.stderr[-3000:])
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    r: dict[str, Any] = json.loads(out.stdout.strip().splitlines()[-1])
    tree = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    r["total_cpu"] = tree - r["startup_cpu"] + r["pool_cpu"]
    return r


def _best(resolution: str, workers: int, repeat: int) -> dict[str, Any]:
    runs = [_once(resolution, workers) for _ in range(repeat)]
    for k, r in enumerate(runs):
        print(f"  [{workers} worker(s), run {k + 1}: wall {r['wall']:.1f} s, "
              f"CPU {r['total_cpu']:.1f} s]", flush=True)
    return min(runs, key=lambda r: r["wall"])


def _show(label: str, r: dict[str, Any]) -> None:
    print(f"{label}: wall {r['wall']:.1f} s (compute {r['compute']:.1f} s + report "
          f"{r['report']:.1f} s); CPU {r['total_cpu']:.1f} s in all, of which {r['tasks']} "
          f"tasks {r['cpu']:.1f} s; critical path {r['path']:.1f} s; main-process CPU while "
          f"computing {r['main_cpu']:.1f} s; verdicts {r['verdicts']}")
    for name, sec in sorted(r["phases"].items(), key=lambda kv: -kv[1]):
        print(f"    {name:16s} {sec:6.1f} s CPU")
    tail = " -> ".join("/".join(str(x) for x in k) for k in r["chain"][-4:])
    print(f"    critical path ends: {tail}")


def _pair(resolution: str) -> tuple[float, float]:
    """Two 1-worker runs at once, each in its own interpreter: their wall times."""
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(2) as ex:
        a, b = ex.map(lambda _: _once(resolution, 1), range(2))
    return a["wall"], b["wall"]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--no-baseline", action="store_true")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--no-ceiling", action="store_true",
                    help="skip the two serial runs at once (the machine's 2-core ceiling)")
    ap.add_argument("--child", nargs=2, metavar=("RESOLUTION", "WORKERS"),
                    help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        print(json.dumps(_measure(args.child[0], int(args.child[1]))))
        return
    res = "quick" if args.quick else "full"
    _once("tiny", 1)  # load every kernel once (compile if the cache is cold)
    ser = _best(res, 1, args.repeat)
    par = _best(res, 2, args.repeat)
    _show(f"reproduce ({res}), 1 worker", ser)
    _show(f"reproduce ({res}), 2 workers", par)
    quiet = max(par["total_cpu"] / 2, par["path"]) + par["report"]
    quiet_ser = ser["total_cpu"] + ser["report"]
    print(f"speed-up 1 -> 2 workers: {ser['wall'] / par['wall']:.2f}x measured; on a quiet "
          f"2-core machine about {quiet:.1f} s vs {quiet_ser:.1f} s serial, "
          f"{quiet_ser / quiet:.2f}x (max(CPU / 2, critical path) + report)")
    if not args.no_ceiling:
        walls = _pair(res)
        ceiling = 4.0 * ser["wall"] / sum(walls)
        print(f"ceiling of this machine: two 1-worker runs at once took {walls[0]:.1f} s and "
              f"{walls[1]:.1f} s against {ser['wall']:.1f} s alone, so two cores do this work "
              f"about {ceiling:.2f}x as fast as one (2 T_alone / mean T_pair), whatever the "
              f"schedule: the 1 -> 2 worker speed-up can reach at most that")
    if args.no_baseline:
        return
    setup = "import tempfile\nfrom tslip.plotting.report import reproduce"
    stmt = (f"with tempfile.TemporaryDirectory() as d:\n    reproduce(d, quick={args.quick}, "
            f"workers={os.cpu_count() or 1})")
    old = run_at(BASELINE_REV, setup, stmt, repeat=args.repeat)
    print(f"vs {BASELINE_REV} on {os.cpu_count()} cores: {old:.1f} s then, {par['wall']:.1f} s "
          f"now: {old / par['wall']:.2f}x faster")


if __name__ == "__main__":
    main()
