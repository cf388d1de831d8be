"""Design search (``tslip design``): cost per candidate against a study point, and the example.

Run by hand (not in CI): ``python benchmarks/bench_design.py [--rounds N] [--run]``.

* cost: the median wall and CPU seconds of one candidate evaluation
  (:func:`tslip.sweeps.pareto.evaluate`: gait search from the default guesses, Floquet,
  the objectives) on random candidates of ``examples/design.toml``, interleaved with
  the same candidates' gait and Floquet alone and with a study point (one point of a
  serial 1-D continuation over the same candidates' ``k``), printed as ratios;
* ``--run``: the shipped example (3 variables, 2 objectives, 2000 evaluations) on 2
  workers into a fresh folder, wall seconds (issue 26: within 5 minutes, cold compile
  included when the numba cache is empty);
* ``--compare-cma [--budget B] [--seeds S]``: NSGA-II (``tslip.design``) against a
  scalarised CMA-ES at equal evaluations on the example spec, by the hypervolume of
  each one's front (issue 26 asks which measures better). The CMA-ES side: a tenth of
  the budget as a uniform random sample (which also sets each objective's scale), then
  one CMA-ES run (pycma, variables scaled to [0, 1], ``sigma0`` 0.3) per weight vector
  of the weighted Chebyshev scalarisation ``max_i w_i (f_i - f_i^min) / span_i``, the
  rest of the budget split evenly; infeasible candidates are handled by pycma's
  augmented Lagrangian (``cma.ConstrainedFitnessAL``) on the design's constraint value,
  not by a penalty. Both fronts are the non-dominated feasible designs among all of a
  method's evaluations; the hypervolume's reference point is the worst cost of the
  union of both fronts plus a tenth of its span.

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


def _cma_front(spec: DesignSpec, budget: int, seed: int, n_weights: int = 8
               ) -> tuple[np.ndarray, int]:
    """Costs (rows: feasible evaluated designs) of the scalarised CMA-ES, and its evaluations."""
    import warnings

    import cma

    warnings.filterwarnings("ignore", message=".*moarchiving")
    warnings.filterwarnings("ignore", message="iqr")

    from tslip.sweeps.pareto import _sign

    lo = np.array([v.lower for v in spec.variables])
    span = np.array([v.upper for v in spec.variables]) - lo
    memo: dict[tuple[float, ...], dict] = {}

    def row(u: np.ndarray) -> dict:
        key = tuple(np.clip(u, 0.0, 1.0).tolist())
        if key not in memo:
            memo[key] = evaluate(spec, dict(zip(spec.names, lo + span * np.array(key))))
        return memo[key]

    def cost(r: dict) -> np.ndarray:
        return np.array([_sign(o) * r[o] for o in spec.objectives])

    rng = np.random.default_rng(seed)
    for u in rng.uniform(size=(budget // 10, len(lo))):
        row(u)
    feas = np.array([cost(r) for r in memo.values() if r["feasible"]])
    fmin, fspan = feas.min(axis=0), np.ptp(feas, axis=0) + 1e-12
    per = (budget - len(memo)) // n_weights
    for i in range(n_weights):
        w = np.array([(i + 0.5) / n_weights, 1.0 - (i + 0.5) / n_weights])
        start = len(memo)

        def f(u: np.ndarray, w: np.ndarray = w) -> float:
            r = row(u)
            return float(np.max(w * (cost(r) - fmin) / fspan)) if r["feasible"] else 0.0

        def g(u: np.ndarray) -> list[float]:
            return [row(u)["violation"]]

        restart = 0
        while len(memo) - start < per:  # restarts from a new random mean when one stops
            cfun = cma.ConstrainedFitnessAL(f, g, find_feasible_first=True)
            es = cma.CMAEvolutionStrategy(rng.uniform(size=len(lo)), 0.3, {
                "bounds": [0, 1], "seed": seed * 1000 + 10 * i + restart + 1, "verbose": -9})
            while not es.stop() and len(memo) - start < per:
                xs = es.ask()
                es.tell(xs, [cfun(x) for x in xs])
                cfun.update(es)
            restart += 1
    rows = list(memo.values())[:budget]  # the last population may overshoot: cut at the budget
    costs = np.array([cost(r) for r in rows if r["feasible"]])
    return costs, len(rows)


def compare_cma(budget: int, seeds: int) -> None:
    import dataclasses

    from pymoo.indicators.hv import HV

    from tslip.sweeps.pareto import _costs, pareto_mask

    base = DesignSpec.from_toml(EXAMPLE)
    print(f"load {os.getloadavg()[0]:.2f}; {base.name}: {', '.join(base.objectives)}; "
          f"budget {budget} evaluations each")
    for seed in range(1, seeds + 1):
        spec = dataclasses.replace(base, budget=budget, seed=seed)
        with tempfile.TemporaryDirectory() as tmp:
            res = tslip.design(spec, Path(tmp) / "d", workers=2)
        c_nsga = _costs(res.frame, spec.objectives)
        c_nsga = c_nsga[~np.isnan(c_nsga).any(axis=1)]
        c_cma, n_cma = _cma_front(spec, budget, seed)
        fronts = {"NSGA-II": c_nsga[pareto_mask(c_nsga)], "CMA-ES": c_cma[pareto_mask(c_cma)]}
        union = np.vstack(list(fronts.values()))
        ref = union.max(axis=0) + 0.1 * np.ptp(union, axis=0)
        hv = {k: float(HV(ref_point=ref)(v)) for k, v in fronts.items()}
        print(f"seed {seed}: hypervolume NSGA-II {hv['NSGA-II']:.5g} ({len(res.frame)} "
              f"evaluations, {len(fronts['NSGA-II'])} on its front), scalarised CMA-ES "
              f"{hv['CMA-ES']:.5g} ({n_cma} evaluations, {len(fronts['CMA-ES'])} on its "
              f"front); ratio CMA-ES / NSGA-II {hv['CMA-ES'] / hv['NSGA-II']:.3f} "
              f"(load {os.getloadavg()[0]:.2f})")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=30)
    ap.add_argument("--run", action="store_true", help="also run the shipped example")
    ap.add_argument("--compare-cma", action="store_true",
                    help="only: NSGA-II against a scalarised CMA-ES by hypervolume")
    ap.add_argument("--budget", type=int, default=2000)
    ap.add_argument("--seeds", type=int, default=1)
    a = ap.parse_args()
    if a.compare_cma:
        compare_cma(a.budget, a.seeds)
    else:
        cost(a.rounds)
        if a.run:
            run_example()
