"""Design search (``tslip design``): cost per candidate against a study point, and the example.

Run by hand (not in CI): ``python benchmarks/bench_design.py [--rounds N] [--run]``.

* cost: the median wall and CPU seconds of one candidate evaluation
  (:func:`tslip.sweeps.pareto.evaluate`: gait search from the default guesses, Floquet,
  the objectives) on random candidates of ``examples/design.toml``, interleaved with
  the same candidates' gait and Floquet alone and with a study point (one point of a
  serial 1-D continuation over the same candidates' ``k``), printed as ratios;
* ``--run``: the shipped example (3 variables, 2 objectives, 2000 evaluations) on 2
  workers into a fresh folder, wall seconds (issue 26: within 5 minutes, cold compile
  included when the numba cache is empty).

Prints the 1-minute load beside every figure.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

import tslip
from tslip.sweeps import Axis, StudySpec, run_study
from tslip.sweeps.design_spec import DesignSpec
from tslip.sweeps.pareto import evaluate

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "design.toml"


def _timed(f):
    c, w = time.process_time(), time.perf_counter()
    f()
    return time.perf_counter() - w, time.process_time() - c


def cost(rounds: int) -> None:
    spec = DesignSpec.from_toml(EXAMPLE)
    rng = np.random.default_rng(1)
    cands = [{v.param: float(rng.uniform(v.lower, v.upper)) for v in spec.variables}
             for _ in range(rounds)]
    ks = sorted(c["k"] for c in cands)
    study = StudySpec("bench", spec.base, (Axis("k", tuple(ks)),), ("floquet",))
    run_study(study, None, workers=1)  # warm: compiled kernels loaded
    evaluate(spec, cands[0])
    ev, gf = [], []
    for c in cands:
        ev.append(_timed(lambda c=c: evaluate(spec, c)))
        gf.append(_timed(lambda c=c: tslip.floquet(tslip.find_gait(spec.params_at(c)))))
    st = _timed(lambda: run_study(study, None, workers=1))
    per_point = (st[0] / len(ks), st[1] / len(ks))
    med = lambda xs, i: statistics.median(x[i] for x in xs)  # noqa: E731
    print(f"load {os.getloadavg()[0]:.2f}; {rounds} random candidates of {EXAMPLE.name}")
    print(f"candidate (gait, Floquet, {', '.join(spec.objectives)}): "
          f"{med(ev, 0) * 1e3:.1f} ms wall, {med(ev, 1) * 1e3:.1f} ms CPU (median)")
    print(f"  of which gait search + Floquet: {med(gf, 0) * 1e3:.1f} ms wall")
    print(f"study point (1-D continuation over the same k, floquet): "
          f"{per_point[0] * 1e3:.2f} ms wall, {per_point[1] * 1e3:.2f} ms CPU")
    print(f"candidate / study point: {med(ev, 1) / per_point[1]:.1f} (CPU)")


def run_example() -> None:
    spec = DesignSpec.from_toml(EXAMPLE)
    with tempfile.TemporaryDirectory() as tmp:
        load = os.getloadavg()[0]
        t = time.perf_counter()
        res = tslip.design(spec, Path(tmp) / "d", workers=2)
        wall = time.perf_counter() - t
    print(f"example {spec.name}: {len(res.frame)} evaluations, {int(res.frame.feasible.sum())} "
          f"feasible, {len(res.front)} on the front: {wall:.1f} s wall on 2 workers "
          f"(load before {load:.2f}, after {os.getloadavg()[0]:.2f})")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=30)
    ap.add_argument("--run", action="store_true", help="also run the shipped example")
    a = ap.parse_args()
    cost(a.rounds)
    if a.run:
        run_example()
