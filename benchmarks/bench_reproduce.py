"""Full-resolution ``tslip reproduce``: all cores vs serial, in the same run.

Run: ``python benchmarks/bench_reproduce.py [--quick]``. Each mode starts from
an empty study cache (a fresh temporary folder); numba's kernel cache is
left as it is (warm after the first run).
"""

from __future__ import annotations

import os
import sys
import tempfile
import time

from tslip.plotting.report import reproduce


def _time(quick: bool, workers: int) -> float:
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        reproduce(d, quick=quick, workers=workers)
        return time.perf_counter() - t0


def main() -> None:
    quick = "--quick" in sys.argv
    cores = os.cpu_count() or 1
    par = _time(quick, cores)
    ser = _time(quick, 1)
    mode = "quick" if quick else "full"
    print(f"reproduce ({mode}): {par:.1f} s on {cores} cores, {ser:.1f} s serial, "
          f"speed-up {ser / par:.2f}x")


if __name__ == "__main__":
    main()
