"""A study point against its compiled work (issue 25's last ratio).

``measure(rounds)`` runs one catalogue study serially (``workers=1``) into a
fresh folder per round (so every point is computed and cached, as a first
run does) and returns the median over the rounds of

* the wall seconds per point of the whole ``run_study`` call (its fixed
  costs, such as the lock, ``run.json`` and ``results.parquet``, spread over
  the points), and
* the seconds per point spent inside the compiled stride kernels it calls,
  measured by wrapping every such call with a timer (the same clock): the stride map
  (``tslip.simulation._kernels.section_map``, what ``_packed.stride_map`` calls; on
  checkouts before it, the per-method tuple ``SECTION_MAP``, before that ``STRIDE``)
  and the stride with its exact Jacobian
  (``tslip.simulation._variational.stride_jacobian``). The timer's own
  overhead (two ``perf_counter`` calls) falls inside the kernel time.

The study is ``grid_v3`` (Figure 4.10, local velocity control at v0 = 3,
k x beta0, Floquet multipliers) at 25 x 25 points: 2-D seeded continuation,
the bulk of ``tslip reproduce``'s points. ``benchmarks/bench_limit.py``
prints the ratio as ``study point / its compiled work``; run alone::

    python benchmarks/_study_limit.py [--rounds 5]

On a loaded machine wall time counts the time this process waits for a core
wherever it happens to wait; ``clock="cpu"`` (process and thread CPU time)
gives the same ratio without that noise, and the script prints both.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

STUDY, GRID = "grid_v3", 25
#: (the whole run, a kernel call): wall, or CPU time (the kernels run in this thread).
CLOCKS = {"wall": (time.perf_counter, time.perf_counter),
          "cpu": (time.process_time, time.thread_time)}


def _timed(fn: Callable[..., Any], acc: list[float],
           clock: Callable[[], float]) -> Callable[..., Any]:
    def call(*args: Any) -> Any:
        t0 = clock()
        try:
            return fn(*args)
        finally:
            acc[0] += clock() - t0

    return call


def _one_round(spec: Any, acc: list[float], clock: Callable[[], float]) -> tuple[float, float]:
    from tslip.sweeps.run import run_study

    acc[0] = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        t0 = clock()
        run_study(spec, Path(tmp) / "study", workers=1)
        total = clock() - t0
    return total / spec.n_points, acc[0] / spec.n_points


def measure(rounds: int, clock: str = "wall") -> tuple[float, float]:
    """Median seconds of one study point and of its compiled kernel calls (``clock``)."""
    from tslip.simulation import _kernels as kn
    from tslip.simulation import _variational as va
    from tslip.sweeps.catalogue import study

    whole, call = CLOCKS[clock]
    spec = study(STUDY, quick=True).with_resolution([GRID, GRID])
    acc = [0.0]
    # the map's kernel: one for both methods (section_map), before it a tuple by method
    # (SECTION_MAP, calling STRIDE inside; STRIDE before that)
    maps = next(n for n in ("section_map", "SECTION_MAP", "STRIDE") if hasattr(kn, n))
    saved = getattr(kn, maps), va.stride_jacobian
    setattr(kn, maps, _timed(saved[0], acc, call) if maps == "section_map"
            else tuple(_timed(f, acc, call) for f in saved[0]))
    va.stride_jacobian = _timed(saved[1], acc, call)  # type: ignore[assignment]
    try:
        _one_round(spec, acc, whole)  # loads the kernels
        points, kernels = [], []
        for _ in range(rounds):
            w, k = _one_round(spec, acc, whole)
            points.append(w)
            kernels.append(k)
    finally:
        setattr(kn, maps, saved[0])
        va.stride_jacobian = saved[1]  # type: ignore[assignment]
    return statistics.median(points), statistics.median(kernels)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    a = ap.parse_args()
    ratios = {}
    for clock in ("cpu", "wall"):
        point, kernel = measure(a.rounds, clock)
        ratios[clock] = point / kernel
        print(f"[{clock}] study point {point * 1e3:.3f} ms, its compiled work "
              f"{kernel * 1e3:.3f} ms, ratio {ratios[clock]:.2f}")
    print(f"study point / its compiled work: {ratios['wall']:.2f}")


if __name__ == "__main__":
    main()
