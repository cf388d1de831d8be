"""Biped simulator speed (thesis Appendix E): strides, stiffness, falling runs.

Three measurements, each printed as ratios measured in the same run:

1. *Is the right-hand side stiff?* One stride from the Table E.2 start with
   scipy's implicit (BDF, Radau, LSODA) and explicit (RK45, DOP853) solvers on
   the kernel's right-hand side, run piecewise between the same events (contact
   changes and controller switches located by ``solve_ivp``'s event finder, the
   discrete state switched between pieces): steps, right-hand sides (the
   implicit methods' finite-difference Jacobians included), time and the
   stride's end against the compiled run at 1e-12.
2. *Per stride*, the stride map (no recording) of the Table E.2 start at the
   tolerance (default 1e-8), with each Runge-Kutta pair, against revision
   ``1b54594`` (``_baseline.run_at``, wall time; and the CPU time of the
   process, steadier on a shared machine) and scipy's fastest solver of 1.
3. *A falling run*: a Table E.2 start perturbed within its rounding
   (:func:`tslip.sweeps.appendix_e.table_e2_perturbations`), 20 strides
   requested, against ``1b54594``.

    python benchmarks/bench_biped.py [--repeat 5] [--tol 1e-8] [--no-scipy] [--no-baseline]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _baseline import BASELINE_REV, best_of, run_at

from tslip.biped import BipedOptions, BipedParams, BipedState, simulate, step
from tslip.biped import _kernels as kn
from tslip.biped import _pack as pk
from tslip.sweeps.appendix_e import table_e2_perturbations

SCIPY_METHODS = ("BDF", "Radau", "LSODA", "RK45", "DOP853")


def scipy_stride(p: BipedParams, y0: np.ndarray, method: str, tol: float) -> dict:
    """One stride with ``solve_ivp(method)`` piecewise between events (see 1. above)."""
    from scipy.integrate import solve_ivp

    P = pk.pack_params(p)
    cs = np.zeros(pk.NCS)
    kn.init_contact(P, y0, cs)
    ctl = np.empty(4)
    kn.init_ctl(P, 0.0, ctl)
    ws = kn._make_ws()
    aux = np.empty(10)

    def f(t, y):
        out = np.empty(18)
        kn.rhs(P, t, y, cs, ctl, False, out, ws, aux)
        return out

    def contact(leg):
        def g(t, y):
            return kn.event_value(P, y, cs, leg)
        g.terminal, g.direction = True, -1
        return g

    def switch(leg):
        def g(t, y):
            return kn.ctl_switch_time(P, ctl, leg) - t
        g.terminal, g.direction = True, -1
        return g

    events = [contact(0), contact(1), switch(0), switch(1)]
    t, y = 0.0, y0.copy()
    steps = nfev = njev = 0
    while True:
        sol = solve_ivp(f, (t, t + 5.0), y, method=method, rtol=tol, atol=tol, events=events)
        steps += len(sol.t) - 1
        nfev += sol.nfev + 18 * sol.njev  # finite-difference Jacobians: 18 rhs each
        njev += sol.njev
        hit = [(te[0], k) for k, te in enumerate(sol.t_events) if len(te)]
        if not hit:
            raise RuntimeError(f"{method}: no event ({sol.message})")
        t, k = min(hit)
        y = sol.y_events[k][0].copy()
        if k >= 2:
            kn.ctl_switch(ctl, k - 2)
            continue
        x, _, _, _ = kn.foot_state(P, y, k)
        if cs[pk.CS_ON_R + k] == 0.0:
            cs[pk.CS_ON_R + k], cs[pk.CS_XR + 2 * k], cs[pk.CS_ZR + 2 * k] = 1.0, x, 0.0
            if k == 0:
                return {"t": t, "y": y, "steps": steps, "nfev": nfev, "njev": njev}
        else:
            cs[pk.CS_ON_R + k] = 0.0


# the baseline revision predates the shared names: its one stride is ``stride``
_SETUP = ("import numpy as np\n"
          "from tslip.biped import BipedOptions, BipedParams, BipedState, simulate, stride\n"
          "p = BipedParams(); y0 = BipedState.thesis().to_array()\n")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--tol", type=float, default=1e-8)
    ap.add_argument("--no-scipy", action="store_true")
    ap.add_argument("--no-baseline", action="store_true")
    a = ap.parse_args()
    p = BipedParams()
    y0 = BipedState.thesis().to_array()
    ref = step(p, y0, 0.0, options=BipedOptions(rtol=1e-12, atol=1e-12, method="dop853"))

    best_scipy = np.inf
    if not a.no_scipy:
        print(f"1. one stride, scipy solve_ivp piecewise between events, tolerance {a.tol:g}")
        print(f"   {'method':8s} {'steps':>7s} {'rhs':>8s} {'jac':>5s} {'time [s]':>9s} "
              f"{'|t - t_ref|':>11s} {'|y - y_ref|':>11s}")
        for m in SCIPY_METHODS:
            t0 = time.perf_counter()
            r = scipy_stride(p, y0, m, a.tol)
            dt = time.perf_counter() - t0
            if m in ("RK45", "DOP853"):
                best_scipy = min(best_scipy, dt)
            print(f"   {m:8s} {r['steps']:7d} {r['nfev']:8d} {r['njev']:5d} {dt:9.3f} "
                  f"{abs(r['t'] - ref.t):11.2e} {np.abs(r['y'] - ref.state).max():11.2e}")

    print(f"2. stride map, Table E.2 start, tolerance {a.tol:g} (best of {a.repeat}; wall "
          f"time, and CPU time of the process)")
    new, new_cpu = {}, {}
    for m in ("dopri5", "dop853"):
        opts = BipedOptions(rtol=a.tol, atol=a.tol, method=m)
        r = step(p, y0, 0.0, options=opts)
        new[m] = best_of(lambda opts=opts: step(p, y0, 0.0, options=opts), a.repeat)
        new_cpu[m] = best_of(lambda opts=opts: step(p, y0, 0.0, options=opts), a.repeat,
                           time.process_time)
        print(f"   {m:7s}: {1e3 * new[m]:7.2f} ms/stride wall, {1e3 * new_cpu[m]:7.2f} ms CPU, "
              f"{r.accepted} steps, |t - t_ref| {abs(r.t - ref.t):.1e}, |y - y_ref| "
              f"{np.abs(r.state - ref.state).max():.1e}")
    if not a.no_baseline:
        stmt = f"stride(p, y0, 0.0, options=BipedOptions(rtol={a.tol!r}, atol={a.tol!r}))"
        old = run_at(BASELINE_REV, _SETUP, stmt, repeat=a.repeat)
        old_cpu = run_at(BASELINE_REV, _SETUP, stmt, repeat=a.repeat, clock="process_time")
        print(f"   {BASELINE_REV} (dopri5): {1e3 * old:7.2f} ms/stride wall, {1e3 * old_cpu:7.2f} "
              f"ms CPU")
        for m in new:
            print(f"   speed-up vs {BASELINE_REV}, {m}: {old / new[m]:5.1f}x wall, "
                  f"{old_cpu / new_cpu[m]:5.1f}x CPU")
    if np.isfinite(best_scipy):
        for m in new:
            print(f"   speed-up vs scipy's fastest explicit solver, {m}: "
                  f"{best_scipy / new[m]:5.0f}x")

    print(f"3. falling run: perturbed Table E.2 start, 20 strides requested (best of "
          f"{min(a.repeat, 3)})")
    yf = table_e2_perturbations(0)[0]
    tr = simulate(p, yf, 20)
    t_new = best_of(lambda: simulate(p, yf, 20), min(a.repeat, 3))
    print(f"   now: {t_new:6.3f} s, {tr.status.name} at t = {tr.stats['t_end']:.3f}, "
          f"{tr.count_strides()} strides, {tr.stats['accepted']} steps "
          f"{tr.stats['rejected']} rejected")
    if not a.no_baseline:
        old = run_at(BASELINE_REV, _SETUP + "from tslip.sweeps.appendix_e import "
                     "table_e2_perturbations\nyf = table_e2_perturbations(0)[0]\n",
                     "simulate(p, yf, 20)", repeat=min(a.repeat, 3))
        print(f"   {BASELINE_REV}: {old:6.3f} s; speed-up {old / t_new:5.1f}x")


if __name__ == "__main__":
    main()
