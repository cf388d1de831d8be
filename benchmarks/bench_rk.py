"""The two Runge-Kutta pairs on the TSLIP: right-hand sides per stride and speed.

Run by hand (not in CI): ``python benchmarks/bench_rk.py``. On the Table 6.1
gait, for ``dopri5`` and ``dop853`` at each tolerance, all timed in the same
run (so the ratios are what counts on a shared, noisy machine):

* ``rhs/stride``: stance right-hand sides of one stride, counted exactly
  (``_rhs_count.py``: the kernels as plain Python in a subprocess, every call
  of ``rhs`` counted);
* ``strides/s``: :func:`tslip.run_batch` on one core;
* ``map/s``: :func:`tslip.step_map` calls (what Newton's gait search pays);
* ``jac/s``: exact stride Jacobians (variational equations; Floquet, Newton);
* ``gait s``: :func:`tslip.find_gait` from its default start, end to end.
"""

from __future__ import annotations

import argparse
import time

import numba
import numpy as np
from _baseline import best_of
from _rhs_count import rhs_per_stride

import tslip
from tslip.gait.stability import map_jacobian

METHODS = ("dopri5", "dop853")
NMAP, NJAC = 300, 100  # step_map and Jacobian calls per timing


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tols", type=float, nargs="+", default=[1e-8, 1e-12])
    ap.add_argument("--rows", type=int, default=50)
    ap.add_argument("--steps", type=int, default=40)
    ap.add_argument("--count-strides", type=int, default=3)
    args = ap.parse_args()

    counts = rhs_per_stride([(m, t) for t in args.tols for m in METHODS], args.count_strides)
    gait = tslip.find_gait(tslip.preset("table6.1"))
    p, s = gait.params, gait.state
    q = s.section()
    states = [s] * args.rows
    numba.set_num_threads(1)
    rows = {}
    for tol in args.tols:
        for m in METHODS:
            o = tslip.IntegratorOptions(rtol=tol, atol=tol, method=m)
            tslip.run_batch(p, states[:1], 1, options=o)  # compile / load
            map_jacobian(p, q, options=o)
            n = args.rows * args.steps
            cpu = time.process_time  # steadier than wall time on a shared machine
            batch = n / best_of(lambda o=o: tslip.run_batch(p, states, args.steps, options=o),
                                clock=cpu)
            smap = NMAP / best_of(
                lambda o=o: [tslip.step_map(p, q, options=o) for _ in range(NMAP)], clock=cpu)
            jac = NJAC / best_of(lambda o=o: [map_jacobian(p, q, options=o) for _ in range(NJAC)],
                                 clock=cpu)
            gs = best_of(lambda o=o: tslip.find_gait(tslip.preset("table6.1"), options=o),
                         clock=cpu)
            r = tslip.step(p, s, options=o)
            rows[(tol, m)] = (counts[f"{m} {tol:g}"], r.n_integrator_steps, batch, smap, jac, gs,
                              r.state.section())
    print("Table 6.1 gait, one core; ratios dop853 / dopri5 at the same tolerance")
    print(f"{'tol':>7} {'method':<8}{'rhs/stride':>11}{'steps':>7}{'strides/s':>11}"
          f"{'map/s':>9}{'jac/s':>9}{'gait s':>8}")
    for tol in args.tols:
        for m in METHODS:
            c, st, b, sm, j, gs, _ = rows[(tol, m)]
            print(f"{tol:>7g} {m:<8}{c:>11.0f}{st:>7d}{b:>11,.0f}{sm:>9,.0f}{j:>9,.0f}"
                  f"{gs:>8.3f}")
        a, b = rows[(tol, "dopri5")], rows[(tol, "dop853")]
        print(f"{tol:>7g} {'ratio':<8}{b[0] / a[0]:>11.2f}{b[1] / a[1]:>7.2f}{b[2] / a[2]:>11.2f}"
              f"{b[3] / a[3]:>9.2f}{b[4] / a[4]:>9.2f}{b[5] / a[5]:>8.2f}"
              f"   |dq| = {np.abs(a[6] - b[6]).max():.1e}")


if __name__ == "__main__":
    main()
