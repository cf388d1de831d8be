"""The method's floor for a stance: a minimal hand-written dopri5 with the lift-off event alone.

Used by ``bench_limit.py`` (issue 41), run by hand, not in CI. Run alone
(``python benchmarks/_method_floor.py``) it checks that the floor takes the stride
kernel's steps (the same final state, bit for bit, and step count) and prints its
breakdown against the stance kernel's.

**The floor** is the time of :func:`floor_stance`: one stance of the Table 6.1 gait by
the plainest adaptive Dormand-Prince 5(4) loop that takes the stride kernel's steps and
ends where it ends. It has

* the kernel's right-hand side, ``_stance.rhs_inline``, in every stage, and at a step's
  last stage also the lift-off value ``F_y`` (eq. 2.6), from that stage's sines and
  cosines (as the kernel shares them: ``_stance.rhs_events_inline``);
* the kernel's starting step (Hairer, Norsett & Wanner II.4: one probe right-hand side),
  error norm (Hairer's RMS of ``h sum (b_j - bhat_j) K_j`` over
  ``atol + rtol max(|y|, |ynew|)``) and step-size rule (``0.9 err^(-1/5)`` clipped to
  ``[0.2, 10]``, no growth right after a rejection), written out here with the tableau's
  coefficients as literals, the sums in the kernel's order, so the steps are the same;
* lift-off by a sign change of ``F_y`` from > 0 to <= 0 over an accepted step, located on
  the step's dense output (dopri5's ``contd5``) by the Illinois method to ``1e-15`` in
  theta, then one fresh step to it (as the kernel ends a stance: ``_stride.step_to_event``);

and nothing else: no other event (the kernel's hip at the ground, ``xdot_m < 0``, the
collapsed leg, the thrust's switch, each a value at every step's end and a sign test),
no guard (step count, stance time, smallest step, finite state), no record, no run-time
choice of the pair (the tableau is constants here, read from ``_rk``'s arrays there), no
arrays beyond one scratch block per call, everything in one compiled function.

Its parts, each timed as a loop over the stance's own steps (:func:`floor_parts`):
``steps`` replays the stages (the accepted steps' sizes given, nothing decided);
``+ error norm`` also computes each step's error norm, ``+ step size`` also its ``pow``
and the next size (both still not used: the sizes are replayed, so neither lies on the
path from one step to the next); the whole floor then adds the lift-off's detection and
location, the starting step, and the wait for each step's size (the error norm, ``pow``
and factor between one step's end and the next step's stages).

Its stage loop (:func:`_step`, the tableau's constants folded in) ran slower than the
kernel's own (``bench_limit``'s ``steps``: 2.45 against 1.21 us a stance on 2026-12-06,
load 6): that part of the floor is no floor, so :func:`floor_lines` also gives the floor
with the faster of the two stage loops. The per-step control is the floor's claim.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable

import numpy as np
from numba import njit

from tslip.model._pack import O_ATOL, O_RTOL, P_C0, P_CL, P_NEXP, P_THRUST
from tslip.simulation import _rk, _stance

#: compiled like the kernels (numpy's error model), uncached
_KJIT = dict(getattr(_rk, "_JIT", {"error_model": "numpy"}), cache=False)
_RHS = _stance.rhs_inline
_TERMS = _stance.stance_terms
_PUT = _stance.put_rhs

# Dormand-Prince 5(4) (Hairer, Norsett & Wanner I, Table II.5.2), written out
A21 = 1.0 / 5.0
A31, A32 = 3.0 / 40.0, 9.0 / 40.0
A41, A42, A43 = 44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0
A51, A52, A53, A54 = 19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0
A61, A62, A63, A64, A65 = (9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0,
                           -5103.0 / 18656.0)
B1, B3, B4, B5, B6 = 35.0 / 384.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0
E1, E3, E4, E5, E6, E7 = (71.0 / 57600.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0,
                          22.0 / 525.0, -1.0 / 40.0)
D1, D3, D4, D5, D6, D7 = (-12715105075.0 / 11282082432.0, 87487479700.0 / 32700410799.0,
                          -10690763975.0 / 1880347072.0, 701980252875.0 / 199316789632.0,
                          -1453857185.0 / 822651844.0, 69997945.0 / 29380423.0)


@njit(inline="always", **_KJIT)
def _stage(y, h, K, s, out):
    """``out = y + h sum_j a_sj K_j`` for stage ``s`` (2..7; 7: the solution), the
    non-zero terms in order from ``j = 1``."""
    for i in range(6):
        if s == 2:
            acc = A21 * K[0, i]
        elif s == 3:
            acc = A31 * K[0, i] + A32 * K[1, i]
        elif s == 4:
            acc = A41 * K[0, i] + A42 * K[1, i] + A43 * K[2, i]
        elif s == 5:
            acc = A51 * K[0, i] + A52 * K[1, i] + A53 * K[2, i] + A54 * K[3, i]
        elif s == 6:
            acc = (A61 * K[0, i] + A62 * K[1, i] + A63 * K[2, i] + A64 * K[3, i]
                   + A65 * K[4, i])
        else:
            acc = B1 * K[0, i] + B3 * K[2, i] + B4 * K[3, i] + B5 * K[4, i] + B6 * K[5, i]
        out[i] = y[i] + h * acc


@njit(inline="always", **_KJIT)
def _lift_off(fl, tau, l, sb, cb):
    """``F_y`` (eq. 2.6) from the leg force, hip torque, leg length and ``sin, cos beta``."""
    return fl * sb + tau / l * cb


@njit(inline="always", **_KJIT)
def _lift_off_at(P, y):
    """``F_y`` at ``y``: the two sines and cosines it needs, the torque, the leg force."""
    sb, cb = math.sin(y[1]), math.cos(y[1])
    tau = _stance.hip_torque(P, y[2], y[4], y[5])
    return _lift_off(_stance.leg_force(P, y[0], y[3]), tau, y[0], sb, cb)


@njit(inline="always", **_KJIT)
def _step(P, y, h, K, ytmp, ynew):
    """One dopri5 step from ``y`` (``K[0] = f(y)``): ``ynew``, ``K[6] = f(ynew)``; returns
    ``F_y(ynew)`` (its sines and cosines those of the last stage)."""
    _stage(y, h, K, 2, ytmp)
    _RHS(P, ytmp, K[1])
    _stage(y, h, K, 3, ytmp)
    _RHS(P, ytmp, K[2])
    _stage(y, h, K, 4, ytmp)
    _RHS(P, ytmp, K[3])
    _stage(y, h, K, 5, ytmp)
    _RHS(P, ytmp, K[4])
    _stage(y, h, K, 6, ytmp)
    _RHS(P, ytmp, K[5])
    _stage(y, h, K, 7, ynew)
    sb, cb, sp, cp, tau, fl = _TERMS(P, ynew)
    _PUT(P, ynew, sb, cb, sp, cp, tau, fl, K[6])
    return _lift_off(fl, tau, ynew[0], sb, cb)


@njit(inline="always", **_KJIT)
def _error(y, ynew, h, K, rtol, atol):
    """Hairer's RMS error norm of the step (units of the tolerance)."""
    s = 0.0
    for i in range(6):
        acc = (E1 * K[0, i] + E3 * K[2, i] + E4 * K[3, i] + E5 * K[4, i] + E6 * K[5, i]
               + E7 * K[6, i])
        sk = atol + rtol * max(abs(y[i]), abs(ynew[i]))
        s += (h * acc / sk) ** 2
    return math.sqrt(s / 6)


@njit(inline="always", **_KJIT)
def _factor(err, fac_max):
    """``0.9 err^(-1/5)`` clipped to ``[0.2, fac_max]`` (``fac_max`` for a zero error)."""
    if err <= 0.0:
        return fac_max
    return min(fac_max, max(0.2, 0.9 * err ** -0.2))


@njit(inline="always", **_KJIT)
def _start(y, f0, f1, ytmp, P, rtol, atol):
    """The starting step (Hairer, Norsett & Wanner II.4); ``f1`` receives the probe."""
    d0 = d1 = 0.0
    for i in range(6):
        sk = atol + rtol * abs(y[i])
        d0 += (y[i] / sk) ** 2
        d1 += (f0[i] / sk) ** 2
    d0 = math.sqrt(d0 / 6)
    d1 = math.sqrt(d1 / 6)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    for i in range(6):
        ytmp[i] = y[i] + h0 * f0[i]
    _RHS(P, ytmp, f1)
    d2 = 0.0
    for i in range(6):
        sk = atol + rtol * abs(y[i])
        d2 += ((f1[i] - f0[i]) / sk) ** 2
    d2 = math.sqrt(d2 / 6) / h0
    dm = max(d1, d2)
    h1 = max(1e-6, h0 * 1e-3) if dm <= 1e-15 else (0.01 / dm) ** 0.2
    return min(100.0 * h0, h1)


@njit(inline="always", **_KJIT)
def _root(P, y, ynew, h, K, g_lo, g_hi, ytmp):
    """The lift-off's theta in the step: ``contd5``'s coefficients, then Illinois on them."""
    R = K[7:12]
    for i in range(6):
        ydiff = ynew[i] - y[i]
        bspl = h * K[0, i] - ydiff
        R[0, i] = y[i]
        R[1, i] = ydiff
        R[2, i] = bspl
        R[3, i] = ydiff - h * K[6, i] - bspl
        R[4, i] = h * (D1 * K[0, i] + D3 * K[2, i] + D4 * K[3, i] + D5 * K[4, i]
                       + D6 * K[5, i] + D7 * K[6, i])
    a, b, fa, fb, side = 0.0, 1.0, g_lo, g_hi, 0.0
    for _ in range(100):
        c = (a * fb - b * fa) / (fb - fa) if fb != fa else 0.5 * (a + b)
        if not (a < c < b):
            c = 0.5 * (a + b)
        t1 = 1.0 - c
        for i in range(6):
            ytmp[i] = R[0, i] + c * (R[1, i] + t1 * (R[2, i] + c * (R[3, i] + t1 * R[4, i])))
        fc = _lift_off_at(P, ytmp)
        if fc > 0.0:
            a, fa = c, fc
            if side == -1.0:
                fb *= 0.5
            side = -1.0
        else:
            b, fb = c, fc
            if side == 1.0:
                fa *= 0.5
            side = 1.0
        if b - a < 1e-15:
            break
    return b


@njit(**_KJIT)
def floor_stance(P, y0, rtol, atol, out):  # noqa: N803
    """One stance from ``y0`` to lift-off (module docstring): ``out`` = final state, time,
    accepted and rejected steps."""
    W = np.empty(12 * 6 + 3 * 6)
    K = W[:72].reshape((12, 6))
    y, ytmp, ynew = W[72:78], W[78:84], W[84:90]
    for i in range(6):
        y[i] = y0[i]
    sb, cb, sp, cp, tau, fl = _TERMS(P, y)
    _PUT(P, y, sb, cb, sp, cp, tau, fl, K[0])
    g_old = _lift_off(fl, tau, y[0], sb, cb)
    h = _start(y, K[0], K[1], ytmp, P, rtol, atol)
    t = 0.0
    n_acc = n_rej = 0
    last_rejected = False
    ended = False
    while not ended:  # (numba could not type the loop as `while True` with a break)
        g_new = _step(P, y, h, K, ytmp, ynew)
        err = _error(y, ynew, h, K, rtol, atol)
        if not err <= 1.0:
            h *= _factor(err, 10.0)
            n_rej += 1
            last_rejected = True
            continue
        n_acc += 1
        if g_old > 0.0 and g_new <= 0.0:
            h *= _root(P, y, ynew, h, K, g_old, g_new, ytmp)
            _step(P, y, h, K, ytmp, ynew)
            t += h
            ended = True
            continue
        t += h
        for i in range(6):
            y[i] = ynew[i]
            K[0, i] = K[6, i]
        g_old = g_new
        fac = _factor(err, 10.0)
        if last_rejected:
            fac = min(1.0, fac)
        h *= fac
        last_rejected = False
    for i in range(6):
        out[i] = ynew[i]
    out[6], out[7], out[8] = t, n_acc, n_rej


@njit(**_KJIT)
def floor_loop(P, y0, rtol, atol, reps):  # noqa: N803
    """``reps`` floor stances from ``y0``, as ``bench_limit``'s ``_stance_loop`` runs the kernel."""
    out = np.empty(9)
    acc = 0.0
    for _ in range(reps):
        floor_stance(P, y0, rtol, atol, out)
        acc += out[0]
    return acc


def _make_part(error: bool, size: bool):  # noqa: ANN202 - a compiled function
    @njit(**_KJIT)
    def part(P, y0, hs, rtol, atol, reps):  # noqa: N803
        """``reps`` replays of the stance's steps (sizes ``hs``) by :func:`_step`, with
        ``f(y0)``; ``error``, ``size``: also each step's error norm, next size (unused)."""
        W = np.empty(12 * 6 + 3 * 6)
        K = W[:72].reshape((12, 6))
        y, ytmp, ynew = W[72:78], W[78:84], W[84:90]
        acc = 0.0
        for _ in range(reps):
            for i in range(6):
                y[i] = y0[i]
            _RHS(P, y, K[0])
            for h in hs:
                acc += _step(P, y, h, K, ytmp, ynew)
                if error:
                    err = _error(y, ynew, h, K, rtol, atol)
                    acc += h * _factor(err, 10.0) if size else err
                for i in range(6):
                    y[i] = ynew[i]
                    K[0, i] = K[6, i]
            acc += y[0]
        return acc

    return part


#: the floor's parts (module docstring): the steps alone, + error norm, + step size
floor_parts = {"steps": _make_part(False, False), "+ error norm": _make_part(True, False),
               "+ step size": _make_part(True, True)}


def applies(P: np.ndarray) -> bool:
    """Whether the floor's stance is the kernel's for the parameters ``P``: lift-off located
    as ``F_y`` (a linear spring or some damping or torque) and no leg thrust."""
    on_spring = (P[P_NEXP] != 1.0 and P[P_CL] == 0.0 and not P[P_C0:P_C0 + 4].any())
    return not on_spring and P[P_THRUST] <= 0.0


def floor_fns(P: np.ndarray, O: np.ndarray, y0: np.ndarray, hs: np.ndarray,  # noqa: N803
              reps: int) -> dict[str, Callable[[], object]]:
    """The floor and its parts as workloads for ``_baseline.ab``: ``reps`` stances each."""
    rtol, atol = O[O_RTOL], O[O_ATOL]
    fns: dict[str, Callable[[], object]] = {
        "floor": lambda: floor_loop(P, y0, rtol, atol, reps)}
    for k, f in floor_parts.items():
        fns["floor " + k] = lambda f=f: f(P, y0, hs, rtol, atol, reps)
    return fns


def same_as_kernel(P: np.ndarray, O: np.ndarray, y0: np.ndarray, y_end: np.ndarray,  # noqa: N803
                   stats: np.ndarray) -> bool:
    """Whether the floor ends its stance from ``y0`` where the kernel did (``y_end``, bit for
    bit) after as many accepted and rejected steps (``stats``), at the same time."""
    out = np.empty(9)
    floor_stance(P, y0, O[O_RTOL], O[O_ATOL], out)
    return bool(np.array_equal(out[:6].view(np.uint64), y_end.view(np.uint64))
                and out[6] == stats[0] and out[7] == stats[1] and out[8] == stats[2])


def floor_lines(t: dict[str, float], reps: int, t_rhs: float, n_rhs: int, n_limit: int,
                n_steps: int, n_acc: int, stride: float, same: bool) -> list[str]:
    """The context lines of the floor (``t``: median seconds of :func:`floor_fns`'s workloads
    and of ``stance``, the kernel's stance, and ``steps``, its steps replayed; ``n_rhs``
    right-hand sides a stance, ``n_limit`` the RHS-bound limit's; ``n_steps`` steps, the step
    to the lift-off included, ``n_acc`` accepted before it; ``stride`` the stride kernel's
    seconds)."""
    fl = t["floor"] / reps
    st, er, sz = (t["floor " + k] / reps for k in ("steps", "+ error norm", "+ step size"))
    stance, k_steps = t["stance"] / reps, t["steps"] / reps
    n_st = 1 + 6 * n_steps  # f(y0) and the steps' stages: the rest is the starting step's probe
    rest = t_rhs * (n_rhs - n_st)
    f_ctl, k_ctl = fl - st - rest, stance - k_steps - rest
    # the floor with the faster of the two stage loops (the kernel's, where it is faster)
    comp = t_rhs * n_rhs + min(st, k_steps) - t_rhs * n_st + f_ctl
    us = 1e6
    kind = "the same as the kernel's bit for bit" if same else "NOT the kernel's"
    return [
        f"method floor (benchmarks/_method_floor.py): a minimal dopri5 stance with lift-off "
        f"alone {fl * us:.2f} us ({n_acc} accepted steps; final state and steps "
        f"{kind}), "
        f"the stance kernel's {stance * us:.2f} us",
        f"floor breakdown: right-hand sides {t_rhs * n_rhs * us:.2f} us ({n_rhs}), stage "
        f"arithmetic and F_y {(st - t_rhs * n_st) * us:.2f} us (kernel's, five events: "
        f"{(k_steps - t_rhs * n_st) * us:.2f}), per-step control {f_ctl * us:.2f} us "
        f"({f_ctl / n_acc * 1e9:.0f} ns an accepted step; kernel's {k_ctl * us:.2f} us, "
        f"{k_ctl / n_acc * 1e9:.0f} ns): error norm {(er - st) * us:.2f}, step size "
        f"{(sz - er) * us:.2f}, lift-off location, starting step and waiting for each step's "
        f"size {(fl - sz - rest) * us:.2f}",
        f"floor / RHS-bound limit: {fl / (t_rhs * n_limit):.2f}, with the faster stage "
        f"arithmetic of the two: {comp / (t_rhs * n_limit):.2f} ({comp * us:.2f} us); "
        f"+ per-stride work: {(comp + stride - stance) / (t_rhs * n_limit):.2f}; "
        f"stride kernel / (floor + per-stride work): {stride / (fl + stride - stance):.2f}",
    ]


def main() -> None:
    """The floor against the stance kernel, both timed as ``bench_limit`` times them."""
    import time

    from _baseline import ab
    from bench_limit import _rhs_loop, _stance_kernel, _stance_loop, _steps_loop

    import tslip
    from tslip.model import _pack as pk
    from tslip.simulation import _kernels as kn

    g = tslip.find_gait(tslip.preset("table6.1"))
    P = pk.pack_params(g.params)
    O = tslip.IntegratorOptions().packed()  # noqa: N806
    assert applies(P)
    y0, yk, stats = np.empty(6), np.empty(6), np.empty(5)
    kn.stance_initial(P, np.r_[g.state.section(), 0.0, 0.0], y0)
    rec = np.empty((4096, pk.NREC))
    kn.integrate_stance(P, O, y0, yk, rec, 0.0, stats)
    hs = np.diff(rec[: int(stats[3]), pk.REC_T])
    Y = np.ascontiguousarray(tslip.step(g.params, g.state).stance[:, 1:7])  # noqa: N806
    same = same_as_kernel(P, O, y0, yk, stats)
    reps = 200
    stance = _stance_kernel()
    fns = floor_fns(P, O, y0, hs, reps)
    fns["stance"] = lambda: _stance_loop(stance, P, O, y0, reps)
    fns["steps"] = lambda: _steps_loop(P, y0, hs, reps)
    fns["rhs"] = lambda: _rhs_loop(P, Y, reps)
    load0 = os.getloadavg()[0]
    t = ab(fns, 21, clock=time.process_time).median
    t_rhs = t["rhs"] / (reps * len(Y))
    n_rhs = 2 + 6 * (int(stats[1] + stats[2]) + 1)  # f(y0), the probe, the steps, the last
    print(f"load {load0:.2f} before, {os.getloadavg()[0]:.2f} after; t_rhs {t_rhs * 1e9:.1f} ns")
    for line in floor_lines(t, reps, t_rhs, n_rhs, n_rhs, len(hs), int(stats[1]),
                            t["stance"] / reps, same):
        print(line)


if __name__ == "__main__":
    main()
