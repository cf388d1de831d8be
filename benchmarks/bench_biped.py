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
   ``1b54594``'s ``stride`` (DOPRI5 only) and scipy's fastest solver of 1.
   The old revision is imported in this process (``_baseline.import_at``)
   and timed interleaved with the new code, call by call (``_baseline.ab``,
   ``--rounds`` rounds), in wall time and in the CPU time of the process
   (steadier on a shared machine); best and median of the rounds.
3. *A falling run*: a Table E.2 start perturbed within its rounding
   (:func:`tslip.sweeps.appendix_e.table_e2_perturbations`), 20 strides
   requested, against ``1b54594`` (in process, interleaved, ``--repeat`` rounds).

    python benchmarks/bench_biped.py [--rounds 30] [--repeat 5] [--tol 1e-8] [--no-scipy]
                                     [--no-baseline]
"""

from __future__ import annotations

import argparse
import importlib
import time

import numpy as np
from _baseline import BASELINE_REV, ab, import_at

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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="rounds of the falling run")
    ap.add_argument("--rounds", type=int, default=30, help="rounds of the stride map")
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

    print(f"2. stride map, Table E.2 start, tolerance {a.tol:g} ({a.rounds} interleaved "
          f"rounds: best and median; wall time, and CPU time of the process)")
    fns = {}
    for m in ("dopri5", "dop853"):
        opts = BipedOptions(rtol=a.tol, atol=a.tol, method=m)
        r = step(p, y0, 0.0, options=opts)
        fns[m] = lambda opts=opts: step(p, y0, 0.0, options=opts)
        print(f"   {m:7s}: {r.accepted} steps, |t - t_ref| {abs(r.t - ref.t):.1e}, |y - y_ref| "
              f"{np.abs(r.state - ref.state).max():.1e}")
    if not a.no_baseline:
        old = import_at(BASELINE_REV).__name__  # its one stride is ``stride``, not ``step``
        ob = importlib.import_module(f"{old}.biped")
        p_old, y0_old = ob.BipedParams(), ob.BipedState.thesis().to_array()
        o_old = ob.BipedOptions(rtol=a.tol, atol=a.tol)
        r = ob.stride(p_old, y0_old, 0.0, options=o_old)
        fns[BASELINE_REV] = lambda: ob.stride(p_old, y0_old, 0.0, options=o_old)
        print(f"   {BASELINE_REV} (dopri5, {ob.__file__.split('/pkg/')[-1]}): {r.accepted} steps, "
              f"|t - t_ref| {abs(r.t - ref.t):.1e}, |y - y_ref| "
              f"{np.abs(r.state - ref.state).max():.1e}")
    wall, cpu = ab(fns, a.rounds), ab(fns, a.rounds, time.process_time)
    for m in fns:
        print(f"   {m:7s}: {1e3 * wall[m]:7.2f} ms/stride wall (median "
              f"{1e3 * wall.median[m]:7.2f}), {1e3 * cpu[m]:7.2f} ms CPU (median "
              f"{1e3 * cpu.median[m]:7.2f})")
    if not a.no_baseline:
        for m in ("dopri5", "dop853"):
            (w, wm), (c, cm) = wall.ratio(BASELINE_REV, m), cpu.ratio(BASELINE_REV, m)
            print(f"   speed-up vs {BASELINE_REV}, {m}: {w:5.2f}x wall (median {wm:5.2f}x), "
                  f"{c:5.2f}x CPU (median {cm:5.2f}x)")
    if np.isfinite(best_scipy):
        for m in ("dopri5", "dop853"):
            print(f"   speed-up vs scipy's fastest explicit solver, {m}: "
                  f"{best_scipy / wall[m]:5.0f}x")

    print(f"3. falling run: perturbed Table E.2 start, 20 strides requested ({a.repeat} "
          f"interleaved rounds)")
    yf = table_e2_perturbations(0)[0]
    tr = simulate(p, yf, 20)
    fns = {"now": lambda: simulate(p, yf, 20)}
    if not a.no_baseline:
        old_e = importlib.import_module(f"{old}.sweeps.appendix_e")
        yf_old = old_e.table_e2_perturbations(0)[0]
        fns[BASELINE_REV] = lambda: ob.simulate(p_old, yf_old, 20)
    t = ab(fns, a.repeat)
    print(f"   now: {t['now']:6.3f} s (median {t.median['now']:6.3f}), {tr.status.name} at "
          f"t = {tr.stats['t_end']:.3f}, {tr.count_strides()} strides, {tr.stats['accepted']} "
          f"steps {tr.stats['rejected']} rejected")
    if not a.no_baseline:
        tr_old = ob.simulate(p_old, yf_old, 20)
        best, med = t.ratio(BASELINE_REV, "now")
        print(f"   {BASELINE_REV}: {t[BASELINE_REV]:6.3f} s (median "
              f"{t.median[BASELINE_REV]:6.3f}), {tr_old.status.name} at t = "
              f"{tr_old.stats['t_end']:.3f}; speed-up {best:5.2f}x (median {med:5.2f}x)")


if __name__ == "__main__":
    main()
