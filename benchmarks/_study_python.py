"""A study point's Python alone: ``_study_limit``'s study with its kernel calls answered
from a recording.

One untimed round records every kernel call of the study (:func:`_study_limit._record`:
the stride map, the stride with its exact Jacobian, the touch-down's ``alpha_r``
derivative). Each timed round then runs the same study with those kernels replaced by
stand-ins that write the recorded outputs into the call's arrays and return the
recorded status, in call order: the study takes the same path, bit for bit, and what
its CPU time measures is the Python around the kernels (the stand-ins cost about a
microsecond a call). Prints the kernel calls per point by kind and the median CPU
milliseconds per point::

    python benchmarks/_study_python.py [--rounds 9] [--profile]

``--profile`` adds a ``cProfile`` of one round (by own time): the Python costs without
the kernels' time between them.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import statistics
import time
from collections import Counter
from typing import Any

import _study_limit as sl
import numpy as np


def _answering(obj: Any, queue: dict[int, list[sl.Call]], pos: dict[int, int]) -> Any:
    """``obj`` (as :func:`_study_limit._recording` takes it) answering from ``queue``."""
    if isinstance(obj, tuple):
        return tuple(_answering(k, queue, pos) for k in obj)

    def call(*args: Any) -> Any:
        key = id(sl._kernel_of(obj, args))
        _, _, after, status = queue[key][pos[key]]
        pos[key] += 1
        for a, b in zip(args, after, strict=True):
            if isinstance(a, np.ndarray):
                a[...] = b
        return status

    return call


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=9)
    ap.add_argument("--profile", action="store_true")
    a = ap.parse_args()

    from tslip.simulation import _kernels as kn
    from tslip.simulation import _variational as va
    from tslip.sweeps.catalogue import study

    spec = study(sl.STUDY, quick=True).with_resolution([sl.GRID, sl.GRID])
    calls = sl._record(spec)
    kinds = Counter(c[0].py_func.__name__ for c in calls)
    print("kernel calls per point:", ", ".join(
        f"{k} {n / spec.n_points:.2f}" for k, n in kinds.items()),
        f"(all {len(calls) / spec.n_points:.2f})")
    queue: dict[int, list[sl.Call]] = {}
    for c in calls:
        queue.setdefault(id(c[0]), []).append(c)
    pos = dict.fromkeys(queue, 0)
    maps = next(n for n in ("section_map", "SECTION_MAP", "STRIDE") if hasattr(kn, n))
    hooked = [(kn, maps), (va, "stride_jacobian"), (kn, "alpha_r_column")]
    saved = [getattr(mod, name) for mod, name in hooked]
    for (mod, name), obj in zip(hooked, saved, strict=True):
        setattr(mod, name, _answering(obj, queue, pos))

    def run() -> None:
        for k in pos:
            pos[k] = 0
        sl._run_study(spec)

    try:
        run()  # warm
        seconds = []
        for _ in range(a.rounds):
            t0 = time.process_time()
            run()
            seconds.append((time.process_time() - t0) / spec.n_points)
        median, low = statistics.median(seconds) * 1e3, min(seconds) * 1e3
        print(f"[cpu] study point without its kernels: median {median:.3f} ms, "
              f"min {low:.3f} ms ({a.rounds} rounds)")
        if a.profile:
            pr = cProfile.Profile(time.process_time)
            pr.runcall(run)
            pstats.Stats(pr).sort_stats("tottime").print_stats(30)
    finally:
        for (mod, name), obj in zip(hooked, saved, strict=True):
            setattr(mod, name, obj)


if __name__ == "__main__":
    main()
