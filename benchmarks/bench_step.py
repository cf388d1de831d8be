"""Strides per second: compiled simulator vs a scipy ``solve_ivp`` (DOP853) stride.

Run by hand (not in CI): ``python benchmarks/bench_step.py``. Both sides
simulate the Table 2.1 passive periodic gait at the same tolerance (thesis:
rtol = atol = 1e-8) and are timed in the same run, so the ratio is what counts
on a shared, noisy machine.

* ``compiled, one core``: :func:`tslip.run_batch` with numba limited to one thread.
* ``compiled, all cores``: the same with every core.
* ``step_map loop``: one Python call per stride (what an unbatched analysis pays).
* ``scipy DOP853``: ``solve_ivp`` on the stance with a terminal lift-off event;
  the right-hand side is the package's own scalar stance function run as plain
  Python (``.py_func``), and the flight uses the same closed-form touch-down as
  the package, so the ratio isolates the stance integration.

``--baseline REV`` also times the default stride (one-core ``run_batch`` and the
``step_map`` loop) on revision ``REV`` and on this checkout, each in a
subprocess, alternately for ``--rounds`` rounds, and prints then / now (a
ratio above 1 means this checkout is faster).
"""

from __future__ import annotations

import argparse
import time

import numba
import numpy as np
from scipy.integrate import solve_ivp

import tslip
from tslip.model import _pack as pk
from tslip.simulation import _kernels as kn


def scipy_stride(params: tslip.Params, td: np.ndarray, tol: float) -> np.ndarray:
    """One stride with solve_ivp (DOP853) for the stance; returns the next TD (7)."""
    P = pk.pack_params(params)
    accel = kn.stance_accel.py_func
    grf = kn.grf.py_func

    def f(t, y):
        ldd, bdd, phdd, _, _ = accel(P, y)
        return [y[3], y[4], y[5], ldd, bdd, phdd]

    def liftoff(t, y):
        return grf(P, y)[1]

    liftoff.terminal = True
    liftoff.direction = -1
    y0 = np.empty(6)
    kn.stance_initial(P, td, y0)
    sol = solve_ivp(f, (0.0, 50.0), y0, method="DOP853", rtol=tol, atol=tol, events=liftoff)
    y1 = sol.y_events[0][0]
    xd, yd = kn.com_velocity(P, y1)
    xf = td[5] + params.l0 * np.cos(td[0]) - params.r * np.sin(td[1])
    lo = np.array([xf - y1[0] * np.cos(y1[1]) + params.r * np.sin(y1[2]),
                   td[6] + y1[0] * np.sin(y1[1]) - params.r * np.cos(y1[2]), xd, yd, y1[2], y1[5]])
    res = np.empty(3)
    kn.find_touchdown(P, tslip.IntegratorOptions().packed(), lo, np.empty(0), np.zeros(1), res)
    fs = np.empty(10)
    kn.flight_state(P, lo, res[0], fs)
    return np.array([fs[6], fs[4], fs[2], fs[3], fs[5], fs[0], 0.0])


def rate(fn, n: int, repeat: int = 3) -> float:
    """Best strides/s over ``repeat`` runs of ``fn`` doing ``n`` strides."""
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return n / best


_BASELINE_SETUP = """
import numba, tslip
numba.set_num_threads(1)
g = tslip.find_gait(tslip.preset("table2.1"))
p, s = g.params, g.state
opts = tslip.IntegratorOptions(rtol={tol}, atol={tol})
states, q = [s] * {rows}, s.section()
"""
_BASELINE_STMTS = {
    "compiled, one core": "tslip.run_batch(p, states, {steps}, options=opts)",
    "step_map Python loop": "for _ in range(5000): tslip.step_map(p, q, options=opts)",
}


def compare_with(rev: str, args: argparse.Namespace) -> None:
    """The default stride on ``rev`` and on this checkout: best times and their ratio."""
    from _baseline import run_at  # (benchmarks/ is on the path when run as a script)

    setup = _BASELINE_SETUP.format(tol=args.tol, rows=args.rows)
    print(f"default stride, revision {rev} vs this checkout, best of {args.rounds} x 3:")
    for name, stmt in _BASELINE_STMTS.items():
        stmt = stmt.format(steps=args.steps)
        then = now = float("inf")
        for _ in range(args.rounds):
            then = min(then, run_at(rev, setup, stmt, repeat=3, clock="process_time"))
            now = min(now, run_at(None, setup, stmt, repeat=3, clock="process_time"))
        print(f"  {name:<22} then {then * 1e3:8.1f} ms  now {now * 1e3:8.1f} ms  "
              f"then / now = {then / now:.3f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tol", type=float, default=1e-8)
    ap.add_argument("--rows", type=int, default=200)
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--scipy-strides", type=int, default=50)
    ap.add_argument("--baseline", metavar="REV", help="also compare with this git revision")
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    if args.baseline:
        compare_with(args.baseline, args)

    gait = tslip.find_gait(tslip.preset("table2.1"))
    p, s = gait.params, gait.state
    opts = tslip.IntegratorOptions(rtol=args.tol, atol=args.tol)
    states = [s] * args.rows
    n = args.rows * args.steps
    tslip.run_batch(p, states[:2], 2, options=opts)  # compile
    tslip.step_map(p, s.section(), options=opts)

    ncores = numba.config.NUMBA_NUM_THREADS
    numba.set_num_threads(1)
    one = rate(lambda: tslip.run_batch(p, states, args.steps, options=opts), n)
    numba.set_num_threads(ncores)
    allc = rate(lambda: tslip.run_batch(p, states, args.steps, options=opts), n)
    q = s.section()
    m = 5000
    loop = rate(lambda: [tslip.step_map(p, q, options=opts) for _ in range(m)], m)
    td = s.as_array()
    ref = scipy_stride(p, td, args.tol)
    ours = tslip.run_batch(p, [s], 1, options=opts).touchdowns[0, 1]
    k = args.scipy_strides
    sp = rate(lambda: [scipy_stride(p, td, args.tol) for _ in range(k)], k, repeat=2)

    steps = tslip.step(p, s, options=opts).n_integrator_steps
    print(f"Table 2.1 passive gait, tol {args.tol:g}, {steps} Dormand-Prince steps per stance")
    print(f"agreement with the scipy stride: max |diff| = {np.max(np.abs(ref[:5] - ours[:5])):.1e}")
    print(f"{'method':<24}{'strides/s':>14}{'us/stride':>12}{'vs scipy':>10}")
    for name, r in [("compiled, one core", one), (f"compiled, {ncores} cores", allc),
                    ("step_map Python loop", loop), ("scipy DOP853", sp)]:
        print(f"{name:<24}{r:>14,.0f}{1e6 / r:>12.1f}{r / sp:>10.0f}x")


if __name__ == "__main__":
    main()
