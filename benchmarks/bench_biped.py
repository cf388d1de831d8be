"""Strides per second of the compiled biped simulator (thesis Appendix E).

Runs the Table E.2 start for its first two strides (before the gait degrades)
at tolerance 1e-8 on one core, with the stride map (no recording) and with a
recorded run, and prints integrator steps per stride. Baseline: the same two
strides with scipy's ``solve_ivp`` (DOP853) on the kernel right-hand side
called from Python, with contact switching only between steps (no event
location), at the same tolerance, so the ratio is the cost of the Python loop.

    python benchmarks/bench_biped.py [--repeat 5] [--tol 1e-8] [--no-scipy]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from tslip.biped import BipedOptions, BipedParams, BipedState, simulate, stride
from tslip.biped import _kernels as kn
from tslip.biped import _pack as pk


def _strides_compiled(p, y0, opts, n=2):
    t, y = 0.0, y0
    steps = 0
    for _ in range(n):
        r = stride(p, y, t, options=opts)
        t, y = r.t, r.state
        steps += r.accepted
    return steps


def _scipy_two_strides(p, y0, tol):
    from scipy.integrate import DOP853

    P = pk.pack_params(p)
    cs = np.zeros(pk.NCS)
    kn.init_contact(P, y0, cs)
    ws = kn._make_ws()
    aux = np.empty(10)
    out = np.empty(18)

    def f(t, y):
        kn.rhs(P, t, y, cs, out, ws, aux)
        return out.copy()

    solver = DOP853(f, 0.0, y0, 3.09, rtol=tol, atol=tol)
    g_old = [kn.event_value(P, y0, cs, leg) for leg in range(2)]
    while solver.status == "running":
        solver.step()
        for leg in range(2):  # switch contact after the step (no event location)
            g = kn.event_value(P, solver.y, cs, leg)
            if g_old[leg] > 0.0 and g <= 0.0:
                x, _, _, _ = kn.foot_state(P, solver.y, leg)
                on = cs[pk.CS_ON_R + leg] == 0.0
                cs[pk.CS_ON_R + leg] = 1.0 if on else 0.0
                if on:
                    cs[pk.CS_XR + 2 * leg] = x
                    cs[pk.CS_ZR + 2 * leg] = 0.0
            g_old[leg] = kn.event_value(P, solver.y, cs, leg)
    return solver.nfev


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--tol", type=float, default=1e-8)
    ap.add_argument("--no-scipy", action="store_true")
    a = ap.parse_args()
    p = BipedParams()
    y0 = BipedState.thesis().to_array()
    opts = BipedOptions(rtol=a.tol, atol=a.tol)
    steps = _strides_compiled(p, y0, opts)  # compile / load cache
    simulate(p, y0, 2, options=opts)
    best = np.inf
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        _strides_compiled(p, y0, opts)
        best = min(best, time.perf_counter() - t0)
    rate = 2 / best
    best_rec = np.inf
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        simulate(p, y0, 2, options=opts)
        best_rec = min(best_rec, time.perf_counter() - t0)
    print(f"tolerance {a.tol:g}: {steps / 2:.0f} accepted steps per stride")
    print(f"stride map (no recording): {rate:8.1f} strides/s  ({1e3 / rate:.1f} ms/stride)")
    print(f"recorded run             : {2 / best_rec:8.1f} strides/s")
    if not a.no_scipy:
        t0 = time.perf_counter()
        nfev = _scipy_two_strides(p, y0, a.tol)
        ts = time.perf_counter() - t0
        print(f"scipy DOP853 baseline    : {2 / ts:8.1f} strides/s  ({nfev} rhs calls); "
              f"compiled is {ts / best:.0f}x faster")


if __name__ == "__main__":
    main()
