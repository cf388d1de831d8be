"""``tslip reproduce``: wall time on 1 and 2 workers, CPU per phase, critical path, vs 1b54594.

Run: ``python benchmarks/bench_reproduce.py [--quick] [--no-baseline] [--repeat N]``.
Each run starts from an empty output folder (studies and Appendix E
recomputed); numba's kernel cache is left as it is (warm after the first run).

Printed, per worker count: the wall time of the computation (``run_all``,
plotting each figure in the main process as its data arrive, as ``tslip
reproduce`` does) and of the report left after it (claims, HTML), the CPU
seconds of the main process (plots, assembling) and of
every task summed by phase (study solves, study analyses, single-gait
figures, Table 6.1, Appendix E), and the critical path: the longest chain
of tasks, each made ready by the one before (a 2-D study's lines), in CPU
seconds. Then the 1 -> 2 worker speed-up, what the wall time would be on a
quiet 2-core machine (``max((task CPU + main CPU) / 2, critical path) +
report``: the machine is shared, so the measured wall time includes other
people's work), and
the ratio against revision :data:`_baseline.BASELINE_REV` timed in the same
run (``tslip.plotting.report.reproduce`` on all cores, best of ``--repeat``).
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from collections import defaultdict
from typing import Any

from _baseline import BASELINE_REV, run_at

from tslip.plotting.report import render_ready, write_report
from tslip.sweeps.reproduce import run_all


def _phase(key: Any) -> str:
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


def _once(resolution: str, workers: int) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as d:
        timing: dict[Any, tuple[float, float, Any]] = {}
        images: dict[str, str] = {}  # as tslip.plotting.report.reproduce: plots as data arrive
        c0, t0 = time.process_time(), time.perf_counter()
        data, claims, _ = run_all(d, resolution=resolution, workers=workers, timing=timing,
                                  on_result=lambda got: render_ready(got, images))
        t1, c1 = time.perf_counter(), time.process_time()
        write_report(os.path.join(d, "index.html"), data, claims, quick=data["quick"],
                     images=images)
        t2 = time.perf_counter()
        main_cpu = c1 - c0  # plots and assembling (and, with 1 worker, every task)
    phases: dict[str, float] = defaultdict(float)
    for key, (cpu, _, _) in timing.items():
        phases[_phase(key)] += cpu
    path, chain = _critical_path(timing)
    return {"compute": t1 - t0, "report": t2 - t1, "wall": t2 - t0, "phases": dict(phases),
            "cpu": sum(phases.values()), "path": path, "chain": chain, "tasks": len(timing),
            "main_cpu": main_cpu}


def _best(resolution: str, workers: int, repeat: int) -> dict[str, Any]:
    return min((_once(resolution, workers) for _ in range(repeat)), key=lambda r: r["wall"])


def _show(label: str, r: dict[str, Any]) -> None:
    print(f"{label}: wall {r['wall']:.1f} s (compute {r['compute']:.1f} s + report "
          f"{r['report']:.1f} s); {r['tasks']} tasks, CPU {r['cpu']:.1f} s, critical path "
          f"{r['path']:.1f} s; main-process CPU while computing {r['main_cpu']:.1f} s")
    for name, sec in sorted(r["phases"].items(), key=lambda kv: -kv[1]):
        print(f"    {name:16s} {sec:6.1f} s CPU")
    tail = " -> ".join("/".join(str(x) for x in k) for k in r["chain"][-4:])
    print(f"    critical path ends: {tail}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--no-baseline", action="store_true")
    ap.add_argument("--repeat", type=int, default=1)
    args = ap.parse_args()
    res = "quick" if args.quick else "full"
    _once("tiny", 1)  # load every kernel once (compile if the cache is cold)
    ser = _best(res, 1, args.repeat)
    par = _best(res, 2, args.repeat)
    _show(f"reproduce ({res}), 1 worker", ser)
    _show(f"reproduce ({res}), 2 workers", par)
    quiet = max((par["cpu"] + par["main_cpu"]) / 2, par["path"]) + par["report"]
    quiet_ser = ser["main_cpu"] + ser["report"]
    print(f"speed-up 1 -> 2 workers: {ser['wall'] / par['wall']:.2f}x measured; on a quiet "
          f"2-core machine about {quiet:.1f} s vs {quiet_ser:.1f} s serial, "
          f"{quiet_ser / quiet:.2f}x (max((task + main CPU) / 2, critical path) + report)")
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
