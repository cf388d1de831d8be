"""Compiled kernels: stance dynamics, its Runge-Kutta stepper and events, closed-form flight.

Private. Arguments are float64 arrays, floats and ints; results are arrays plus
an int status (codes in :mod:`tslip.model._pack`). Nothing here prints or
builds Python objects, and everything also runs with ``NUMBA_DISABLE_JIT=1``.

The readable reference for the equations is :mod:`tslip.model.dynamics`; the
tests check that both agree.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .._kernel_cache import check as _check_cache
from ..model._pack import (
    M_DOP853,
    M_DOPRI5,
    NOUT,
    NREC,
    NTD,
    O_ATOL,
    O_H0,
    O_HMIN,
    O_MAXSTEPS,
    O_METHOD,
    O_RTOL,
    O_TMAX_FLIGHT,
    O_TMAX_STANCE,
    OUT_CLEAR,
    OUT_FYNEG,
    OUT_LO,
    OUT_NREC,
    OUT_NREJ,
    OUT_NSTEP,
    OUT_RECOVF,
    OUT_TD,
    OUT_TF,
    OUT_TFALL,
    OUT_TS,
    OUT_XF,
    P_ALPHA,
    P_APEX,
    P_C0,
    P_CL,
    P_G,
    P_GLOBAL,
    P_J,
    P_K,
    P_L0,
    P_M,
    P_OMEGA,
    P_R,
    RI_LOFY,
    RI_NSTANCE,
    RI_ROW0,
    RI_ROW1,
    RI_STATUS,
    RI_T0,
    RI_TDY,
    RUN_FULL,
    ST_ERR_FLIGHT_TIMEOUT,
    ST_ERR_MAX_STEPS,
    ST_ERR_NONFINITE,
    ST_ERR_STANCE_TIMEOUT,
    ST_ERR_STEP_UNDERFLOW,
    ST_FALL_BACKWARD,
    ST_FALL_HIP_GROUND,
    ST_FALL_LENGTHENING,
    ST_FALL_NO_TOUCHDOWN,
    ST_FALL_TRIP,
    ST_OK,
    TR_ALPHA,
    TR_BETA,
    TR_BETAD,
    TR_ENERGY,
    TR_FOOTX,
    TR_FOOTY,
    TR_FX,
    TR_FY,
    TR_HIPX,
    TR_HIPY,
    TR_L,
    TR_LD,
    TR_PHI,
    TR_PHID,
    TR_STANCE,
    TR_STEP,
    TR_T,
    TR_TAU,
    TR_X,
    TR_XD,
    TR_Y,
    TR_YD,
)
from . import _rk

_JIT = {"cache": True, "nogil": True, "fastmath": False, "error_model": "numpy"}

# ---------------------------------------------------------------------------
# Stance dynamics (eqs 2.1-2.6, A.7-A.14)
# ---------------------------------------------------------------------------


@njit(**_JIT)
def hip_torque(P, phi, betad, phid):
    """Hip torque of the stance controller (eqs 2.12-2.16), linear in the state.

    ``tau = a0 + a1 phi + a2 betad + a3 phid`` with the coefficients from
    ``Controller.torque_coefficients``.
    """
    return P[P_C0] + P[P_C0 + 1] * phi + P[P_C0 + 2] * betad + P[P_C0 + 3] * phid


@njit(**_JIT)
def stance_accel(P, y):
    """Generalised accelerations and forces in stance.

    Solves ``M qdd = Q - C`` (eq. 2.3) for ``q = (l, beta, phi)``. The Schur
    complement of the mass matrix (eq. 2.4) on the phi row is exactly ``J``,
    so the 3x3 solve is closed form.

    Returns ``(ldd, betadd, phidd, F_l, tau)``.
    """
    m = P[P_M]
    r = P[P_R]
    g = P[P_G]
    l, b, ph, ld, bd, phd = y[0], y[1], y[2], y[3], y[4], y[5]
    sb = math.sin(b)
    cb = math.cos(b)
    sp = math.sin(ph)
    cp = math.cos(ph)
    sa = sb * cp + cb * sp  # sin(beta + phi)
    ca = cb * cp - sb * sp  # cos(beta + phi)
    tau = hip_torque(P, ph, bd, phd)
    fl = P[P_K] * (P[P_L0] - l) - P[P_CL] * ld  # eq. 2.1
    # R = Q - C (eq. A.11, A.13)
    r1 = -m * g * sb + fl - (m * r * phd * phd * sa - m * l * bd * bd)
    r2 = tau - m * g * l * cb - (m * r * l * phd * phd * ca + 2.0 * m * l * bd * ld)
    r3 = tau - m * g * r * sp - (m * r * l * bd * bd * ca + 2.0 * m * r * bd * ld * sa)
    phdd = (r3 + r * ca * r1 - r * sa * r2 / l) / P[P_J]
    ldd = r1 / m + r * ca * phdd
    bdd = r2 / (m * l * l) - r * sa / l * phdd
    return ldd, bdd, phdd, fl, tau


@njit(**_JIT)
def rhs(P, y, out):
    """Stance state derivative for ``y = (l, beta, phi, ld, betad, phid)``."""
    ldd, bdd, phdd, _, _ = stance_accel(P, y)
    out[0] = y[3]
    out[1] = y[4]
    out[2] = y[5]
    out[3] = ldd
    out[4] = bdd
    out[5] = phdd


@njit(**_JIT)
def grf(P, y):
    """Ground reaction force ``(F_x, F_y, tau)`` (eqs 2.5-2.6)."""
    l, b = y[0], y[1]
    tau = hip_torque(P, y[2], y[4], y[5])
    fl = P[P_K] * (P[P_L0] - l) - P[P_CL] * y[3]
    sb = math.sin(b)
    cb = math.cos(b)
    return -fl * cb + tau / l * sb, fl * sb + tau / l * cb, tau


@njit(**_JIT)
def _com_velocity(r, l, sb, cb, sp, cp, ld, bd, phd):
    """CoM velocity (eq. A.5) from the leg and pitch with their sines and cosines."""
    xd = -ld * cb + l * sb * bd + r * cp * phd
    yd = ld * sb + l * cb * bd + r * sp * phd
    return xd, yd


@njit(**_JIT)
def com_velocity(P, y):
    """CoM velocity from the stance state (eq. A.5)."""
    l, b, ph = y[0], y[1], y[2]
    return _com_velocity(P[P_R], l, math.sin(b), math.cos(b), math.sin(ph), math.cos(ph),
                         y[3], y[4], y[5])


NEVENTS = 4  # event_values
#: Leg length, as a fraction of ``l0``, at which a stance ends as the hip reaching the
#: ground (eq. 2.11, ``Status.FALL_HIP_GROUND``): a leg compressed that far has put the
#: hip on its foot. Without it such a stance ground on at ever smaller steps until
#: ``IntegratorOptions.max_steps`` (100,000 steps, about 0.1 s of CPU a stride).
L_COLLAPSE = 1e-3


@njit(**_JIT)
def event_values(P, y, gv):
    """Stance event functions; each event fires on a crossing from > 0 to <= 0.

    0: lift-off, ``F_y`` (eq. 2.8); 1: hip height above the foot
    ``l sin(beta)`` (eq. 2.11); 2: ``xdot_m`` (eq. 2.10); 3: the leg
    collapsing, ``l - L_COLLAPSE l0``: the hip reaching the foot, on the
    ground, which event 1 cannot see (it only approaches zero as ``l -> 0``,
    where the polar equations are singular, ``betad ~ 1/l^2``).
    """
    l, b, ph, ld, bd, phd = y[0], y[1], y[2], y[3], y[4], y[5]
    sb = math.sin(b)
    cb = math.cos(b)
    tau = hip_torque(P, ph, bd, phd)
    fl = P[P_K] * (P[P_L0] - l) - P[P_CL] * ld
    gv[0] = fl * sb + tau / l * cb  # F_y, eq. 2.6
    gv[1] = l * sb
    gv[2] = -ld * cb + l * sb * bd + P[P_R] * math.cos(ph) * phd  # xdot_m, eq. A.5
    gv[3] = l - L_COLLAPSE * P[P_L0]


# ---------------------------------------------------------------------------
# The stance stepper: the stage loop of tslip.simulation._rk with this rhs
# ---------------------------------------------------------------------------
NSTATE = 6


@njit(**_JIT)
def rk_step(P, method, y, h, K, ytmp, ynew):
    """One step of size ``h`` from ``y`` with ``K[0] = f(y)`` (see :mod:`._rk`).

    Fills the stages ``K[1..ns]`` and ``ynew``; ``K[ns] = f(ynew)`` (FSAL).
    The branch makes the method a compile-time constant of the inlined stage
    loop, which the cheap stance right-hand side makes worth it (measurably
    faster strides at the thesis tolerance, ``benchmarks/bench_rk.py``).
    """
    if method == M_DOPRI5:
        _rk_stages(P, M_DOPRI5, y, h, K, ytmp, ynew)
    else:
        _rk_stages(P, M_DOP853, y, h, K, ytmp, ynew)


@njit(**dict(_JIT, inline="always"))
def _rk_stages(P, method, y, h, K, ytmp, ynew):
    ns = _rk.n_stages(method)
    for s in range(1, ns):
        _rk.stage_state(method, NSTATE, y, h, K, s, ytmp)
        rhs(P, ytmp, K[s])
    _rk.stage_state(method, NSTATE, y, h, K, ns, ynew)
    rhs(P, ynew, K[ns])


@njit(**_JIT)
def dense_output(P, method, y, ynew, h, K, R, ytmp):
    """Continuous extension of the step just taken (extra stages for dop853)."""
    ns = _rk.n_stages(method)
    for s in range(ns + 1, ns + 1 + _rk.n_extra(method)):
        _rk.stage_state(method, NSTATE, y, h, K, s, ytmp)
        rhs(P, ytmp, K[s])
    _rk.dense_coeffs(method, y, ynew, h, K, R)


@njit(**_JIT)
def initial_step(P, method, y, f0, rtol, atol, ytmp, f1):
    """Starting step size (Hairer, Norsett & Wanner, II.4)."""
    h0, d1 = _rk.initial_probe(y, f0, rtol, atol, ytmp)
    rhs(P, ytmp, f1)
    return _rk.initial_step(method, y, f0, f1, h0, d1, rtol, atol)


@njit(**_JIT)
def _event_root(P, method, R, ev, g_lo, g_hi, ytmp, gv, st):
    """Root in theta of event ``ev`` on the dense output (Illinois method)."""
    _rk.root_start(st, g_lo, g_hi)
    for _ in range(100):
        c = _rk.root_guess(st)
        _rk.dense_eval(method, R, c, ytmp)
        event_values(P, ytmp, gv)
        if _rk.root_update(st, c, gv[ev], 1e-15):
            break
    return st[1]  # the earliest theta known to be at or past the crossing


@njit(**_JIT)
def integrate_stance(P, O, y0, yout, rec, rec_dt, stats):
    """Integrate the stance from ``y0`` until lift-off or a fall.

    A stance that starts with the hip at the ground, ``xdot_m < 0`` or the leg
    lengthening (``ld > 0``: a spring leg cannot pull) ends at once with that
    fall (docs/conventions.md, "Events").

    ``rec`` (rows x NREC) receives ``t, y, F_x, F_y, tau``: at each accepted
    step if ``rec_dt <= 0``, else on a uniform grid of spacing ``rec_dt``
    from the dense output. ``stats`` receives
    ``[t_end, n_accepted, n_rejected, n_recorded, overflow]``.
    Returns the status code; ``yout`` holds the final state.
    """
    rtol = O[O_RTOL]
    atol = O[O_ATOL]
    max_steps = int(O[O_MAXSTEPS])
    t_max = O[O_TMAX_STANCE]
    h_min = O[O_HMIN]
    method = int(O[O_METHOD])
    ns = _rk.n_stages(method)
    K = np.empty((_rk.NK, NSTATE))
    R = np.empty((_rk.NR, NSTATE))
    st = np.empty(5)
    y = np.empty(NSTATE)
    ynew = np.empty(NSTATE)
    ytmp = np.empty(NSTATE)
    gv_old = np.empty(NEVENTS)
    gv_new = np.empty(NEVENTS)
    gv_tmp = np.empty(NEVENTS)
    for i in range(NSTATE):
        y[i] = y0[i]
    nrec_max = rec.shape[0]
    nrec = 0
    overflow = 0.0
    t = 0.0
    event_values(P, y, gv_old)
    status = ST_OK
    rhs(P, y, K[0])
    # record the first row
    if nrec_max > 0:
        _record(P, rec, nrec, t, y)
        nrec += 1
    t_next_rec = rec_dt
    # fallen already at touch-down: hip at the ground, moving backward, or the leg
    # lengthening (ld > 0: the spring would stretch past l0 and pull on the ground,
    # docs/conventions.md "Events")
    if gv_old[1] <= 0.0 or gv_old[2] < 0.0 or y[3] > 0.0:
        for i in range(NSTATE):
            yout[i] = y[i]
        stats[0] = 0.0
        stats[1] = 0.0
        stats[2] = 0.0
        stats[3] = nrec
        stats[4] = 0.0
        if gv_old[1] <= 0.0:
            return ST_FALL_HIP_GROUND
        return ST_FALL_BACKWARD if gv_old[2] < 0.0 else ST_FALL_LENGTHENING
    h = O[O_H0]
    if h <= 0.0:
        h = initial_step(P, method, y, K[0], rtol, atol, ytmp, K[1])
    n_acc = 0
    n_rej = 0
    last_rejected = False
    done = False
    while not done:
        if n_acc + n_rej >= max_steps:
            status = ST_ERR_MAX_STEPS
            break
        if t >= t_max:
            status = ST_ERR_STANCE_TIMEOUT
            break
        if h < h_min:
            status = ST_ERR_STEP_UNDERFLOW
            break
        rk_step(P, method, y, h, K, ytmp, ynew)
        err = _rk.error_norm(method, NSTATE, y, ynew, h, K, rtol, atol)
        if not math.isfinite(err):
            # a NaN/inf stage: shrink hard, give up below h_min
            h *= 0.1
            n_rej += 1
            last_rejected = True
            continue
        if err > 1.0:
            h *= _rk.step_factor(method, err, 10.0)
            n_rej += 1
            last_rejected = True
            continue
        # accepted step: look for events
        n_acc += 1
        event_values(P, ynew, gv_new)
        first_ev = -1
        theta_ev = 2.0
        have_dense = False
        # falls first: lift-off wins only if strictly earlier (F_y = F_l sin(beta)
        # and the hip height l sin(beta) vanish together when beta reaches 0)
        for j in range(NEVENTS):
            ev = (1, 3, 2, 0)[j]
            if gv_old[ev] > 0.0 and gv_new[ev] <= 0.0:
                if not have_dense:
                    dense_output(P, method, y, ynew, h, K, R, ytmp)
                    have_dense = True
                th = _event_root(P, method, R, ev, gv_old[ev], gv_new[ev], ytmp, gv_tmp, st)
                if th < theta_ev - 1e-9:
                    theta_ev = th
                    first_ev = ev
        if rec_dt > 0.0 and nrec_max > 0:
            if not have_dense:
                dense_output(P, method, y, ynew, h, K, R, ytmp)
                have_dense = True
            t_stop = t + h * min(theta_ev, 1.0)
            while t_next_rec <= t_stop:
                if nrec >= nrec_max:
                    overflow = 1.0
                    break
                _rk.dense_eval(method, R, (t_next_rec - t) / h, ytmp)
                _record(P, rec, nrec, t_next_rec, ytmp)
                nrec += 1
                t_next_rec += rec_dt
        if first_ev >= 0:
            # exact step to the event time for a full-order event state
            h_ev = theta_ev * h
            if h_ev > 0.0:
                rk_step(P, method, y, h_ev, K, ytmp, ynew)
            else:
                for i in range(NSTATE):
                    ynew[i] = y[i]
            t += h_ev
            for i in range(NSTATE):
                y[i] = ynew[i]
            if first_ev == 0:
                status = ST_OK
            elif first_ev == 1 or first_ev == 3:
                status = ST_FALL_HIP_GROUND
            else:
                status = ST_FALL_BACKWARD
            done = True
        else:
            t += h
            for i in range(NSTATE):
                y[i] = ynew[i]
                K[0, i] = K[ns, i]  # FSAL
            for i in range(NEVENTS):
                gv_old[i] = gv_new[i]
            fac = _rk.step_factor(method, err, 10.0)
            if last_rejected:
                fac = min(1.0, fac)
            h *= fac
            last_rejected = False
        for i in range(NSTATE):
            if not math.isfinite(y[i]):
                status = ST_ERR_NONFINITE
                done = True
        if rec_dt <= 0.0 and nrec_max > 0:
            if nrec < nrec_max:
                _record(P, rec, nrec, t, y)
                nrec += 1
            else:
                overflow = 1.0
    if rec_dt > 0.0 and nrec_max > 0 and status == ST_OK:
        # always close the record with the lift-off row
        if nrec < nrec_max:
            _record(P, rec, nrec, t, y)
            nrec += 1
        else:
            overflow = 1.0
    for i in range(NSTATE):
        yout[i] = y[i]
    stats[0] = t
    stats[1] = n_acc
    stats[2] = n_rej
    stats[3] = nrec
    stats[4] = overflow
    return status


@njit(**_JIT)
def _record(P, rec, row, t, y):
    rec[row, 0] = t
    for i in range(NSTATE):
        rec[row, 1 + i] = y[i]
    fx, fy, tau = grf(P, y)
    rec[row, 7] = fx
    rec[row, 8] = fy
    rec[row, 9] = tau


# ---------------------------------------------------------------------------
# Flight in closed form (eqs 2.7, 2.17 with the sign of docs/conventions.md)
# ---------------------------------------------------------------------------


@njit(**_JIT)
def retraction_start(P, yd0):
    """Time after lift-off at which the retraction clock starts, for lift-off ``ydot = yd0``.

    0 with ``retraction="liftoff"`` (eq. 2.17). With ``retraction="apex"`` the
    apex ``yd0 / g`` of a flight that leaves the ground moving up, and 0 (the
    clock starts at lift-off) for one that has no apex (``yd0 <= 0``).
    """
    if P[P_APEX] != 0.0 and yd0 > 0.0:
        return yd0 / P[P_G]
    return 0.0


@njit(**_JIT)
def flight_leg_angle(P, phi0, phid, t, ta):
    """Leg angle ``beta(t)`` in flight, ``t`` since lift-off, and its rate.

    The hip angle is ``alpha_r + omega_r max(0, t - ta)`` with ``ta`` from
    :func:`retraction_start` (held at ``alpha_r`` until then); ``beta = alpha -
    phi(t)`` for the local reset, ``beta = alpha`` for the global one. The rate
    is the one from ``t`` on (retracting at ``t = ta``).
    """
    if t >= ta:
        s = t - ta
        w = P[P_OMEGA]
    else:
        s = 0.0
        w = 0.0
    if P[P_GLOBAL] != 0.0:
        return P[P_ALPHA] + P[P_OMEGA] * s, w
    return P[P_ALPHA] + P[P_OMEGA] * s - (phi0 + phid * t), w - phid


@njit(**_JIT)
def flight_state(P, lo, t, out):
    """Flight state ``t`` after lift-off from ``lo = (x, y, xd, yd, phi, phid)``.

    Writes ``(x, y, xd, yd, phi, phid, beta, foot_x, foot_y, hip_y)`` to ``out``.
    """
    g = P[P_G]
    r = P[P_R]
    l0 = P[P_L0]
    x = lo[0] + lo[2] * t
    y = lo[1] + lo[3] * t - 0.5 * g * t * t
    ph = lo[4] + lo[5] * t
    b, _ = flight_leg_angle(P, lo[4], lo[5], t, retraction_start(P, lo[3]))
    hip_x = x - r * math.sin(ph)
    hip_y = y + r * math.cos(ph)
    out[0] = x
    out[1] = y
    out[2] = lo[2]
    out[3] = lo[3] - g * t
    out[4] = ph
    out[5] = lo[5]
    out[6] = b
    out[7] = hip_x + l0 * math.cos(b)
    out[8] = hip_y - l0 * math.sin(b)
    out[9] = hip_y


@njit(**_JIT)
def _flight_heights(P, lo, t, ta):
    """Foot and hip height, their rates and the foot x-position at ``t`` (clock from ``ta``)."""
    g = P[P_G]
    r = P[P_R]
    l0 = P[P_L0]
    ph = lo[4] + lo[5] * t
    b, bd = flight_leg_angle(P, lo[4], lo[5], t, ta)
    y = lo[1] + lo[3] * t - 0.5 * g * t * t
    yd = lo[3] - g * t
    hip_y = y + r * math.cos(ph)
    hip_yd = yd - r * math.sin(ph) * lo[5]
    foot_y = hip_y - l0 * math.sin(b)
    foot_yd = hip_yd - l0 * math.cos(b) * bd
    foot_x = lo[0] + lo[2] * t - r * math.sin(ph) + l0 * math.cos(b)
    return foot_y, foot_yd, hip_y, hip_yd, foot_x


@njit(**_JIT)
def _segment(tx, x):
    """Index of the terrain segment holding ``x`` (breakpoints ``tx`` sorted)."""
    k = 0
    while k < tx.shape[0] and x >= tx[k]:
        k += 1
    return k


@njit(**_JIT)
def _safe_dt(f, fd, K):
    """Time ``f`` (> 0) surely stays positive given ``|f''| <= K`` and rate ``fd``."""
    return (fd + math.sqrt(fd * fd + 2.0 * K * f)) / K


@njit(**_JIT)
def find_touchdown(P, O, lo, tx, th, res):
    """First touch-down after lift-off, by certified safe steps.

    With ``|f''| <= K`` bounding the foot (and hip) height's second
    derivative, a step of ``_safe_dt`` cannot skip a zero, so the first
    downward crossing is never missed; near the root the step is Newton-like.
    The foot must first be above the ground (a reset foot that starts below
    it has to rise, docs/conventions.md). Terrain: heights ``th[k]`` between
    breakpoints ``tx`` (``len(th) == len(tx) + 1``). With the apex clock the
    leg rate jumps at the apex, so ``K`` bounds both rates and no step
    crosses the apex.

    ``res`` receives ``(t_td, ground_h, clearance_at_reset)``.
    """
    g = P[P_G]
    r = abs(P[P_R])
    l0 = P[P_L0]
    phid = lo[5]
    bd = P[P_OMEGA] if P[P_GLOBAL] != 0.0 else P[P_OMEGA] - phid
    ta = retraction_start(P, lo[3])
    if ta > 0.0:  # before the apex the held leg turns with the trunk (local) or not at all
        bd = max(abs(bd), abs(0.0 if P[P_GLOBAL] != 0.0 else phid))
    Kf = g + r * phid * phid + l0 * bd * bd + 1e-300
    Kh = g + r * phid * phid + 1e-300
    vx = abs(lo[2]) + r * abs(phid) + l0 * abs(bd) + 1e-300
    t_max = O[O_TMAX_FLIGHT]
    tol = 1e-13
    t = 0.0
    foot_y, foot_yd, hip_y, hip_yd, foot_x = _flight_heights(P, lo, t, ta)
    k = _segment(tx, foot_x)
    res[1] = th[k]
    res[2] = foot_y - th[k]
    armed = foot_y - th[k] > 0.0
    for _ in range(100000):
        if t > t_max:
            res[0] = t
            return ST_ERR_FLIGHT_TIMEOUT
        H = th[k]
        hh = hip_y - H
        if hh <= tol:  # the safe steps approach the hip's contact without crossing it
            res[0] = t
            res[1] = H
            return ST_FALL_NO_TOUCHDOWN
        f = foot_y - H
        if armed:
            # a downward crossing: just after arming the foot is at the ground but rising
            if f <= tol and foot_yd <= 0.0:
                res[0] = t
                res[1] = H
                return ST_OK
            dt = _safe_dt(f, foot_yd, Kf)
        else:
            if f > 0.0:
                armed = True
                continue
            # wait for the foot to rise above the ground: -f must reach 0
            dt = _safe_dt(max(-f, 1e-300), -foot_yd, Kf)
            dt = max(dt, 1e-12)
        dt = min(dt, _safe_dt(hh, hip_yd, Kh))
        # do not step across a terrain breakpoint unnoticed
        if tx.shape[0] > 0:
            dist = math.inf
            if k > 0:
                dist = foot_x - tx[k - 1]
            if k < tx.shape[0]:
                dist = min(dist, tx[k] - foot_x)
            dt = min(dt, max(dist / vx, 1e-12))
        if t < ta:  # stop at the apex: the foot's rate jumps there
            dt = min(dt, ta - t)
        t += dt
        foot_y, foot_yd, hip_y, hip_yd, foot_x = _flight_heights(P, lo, t, ta)
        knew = _segment(tx, foot_x)
        if knew != k:
            k = knew
            if armed and foot_y - th[k] <= 0.0:
                res[0] = t
                res[1] = th[k]
                return ST_FALL_TRIP
    res[0] = t
    return ST_ERR_FLIGHT_TIMEOUT


# ---------------------------------------------------------------------------
# One stride: touch-down -> lift-off -> touch-down
# ---------------------------------------------------------------------------


@njit(**_JIT)
def stance_initial(P, td, y0):
    """Stance state at touch-down (l = l0), from eq. A.5 inverted for ld, betad."""
    l0 = P[P_L0]
    r = P[P_R]
    b, ph, xd, yd, phd = td[0], td[1], td[2], td[3], td[4]
    u = xd - r * math.cos(ph) * phd
    w = yd - r * math.sin(ph) * phd
    y0[0] = l0
    y0[1] = b
    y0[2] = ph
    y0[3] = -u * math.cos(b) + w * math.sin(b)
    y0[4] = (u * math.sin(b) + w * math.cos(b)) / l0
    y0[5] = phd


@njit(**_JIT)
def stride(P, O, td, tx, th, rec, rec_dt, out):
    """One stride from the touch-down state ``td`` (7) to the next.

    Fills ``out`` (layout ``OUT_*`` in ``_pack``) and returns the status.
    """
    for i in range(NOUT):
        out[i] = math.nan
    out[OUT_TS] = 0.0
    out[OUT_TF] = 0.0
    out[OUT_NREC] = 0.0
    out[OUT_RECOVF] = 0.0
    l0 = P[P_L0]
    r = P[P_R]
    y0 = np.empty(NSTATE)
    y1 = np.empty(NSTATE)
    stats = np.empty(5)
    stance_initial(P, td, y0)
    x_m, h = td[5], td[6]
    xf = x_m + l0 * math.cos(td[0]) - r * math.sin(td[1])
    out[OUT_XF] = xf
    fx0, fy0, _ = grf(P, y0)
    out[OUT_FYNEG] = 1.0 if fy0 < 0.0 else 0.0
    status = integrate_stance(P, O, y0, y1, rec, rec_dt, stats)
    ts = stats[0]
    out[OUT_TS] = ts
    out[OUT_NSTEP] = stats[1]
    out[OUT_NREJ] = stats[2]
    out[OUT_NREC] = stats[3]
    out[OUT_RECOVF] = stats[4]
    # lift-off (or final) CoM state
    l, b, ph = y1[0], y1[1], y1[2]
    xd, yd = com_velocity(P, y1)
    lo = np.empty(6)
    lo[0] = xf - l * math.cos(b) + r * math.sin(ph)
    lo[1] = h + l * math.sin(b) - r * math.cos(ph)
    lo[2] = xd
    lo[3] = yd
    lo[4] = ph
    lo[5] = y1[5]
    for i in range(6):
        out[OUT_LO + i] = lo[i]
    out[OUT_LO + 6] = l
    out[OUT_LO + 7] = b
    out[OUT_LO + 8] = y1[3]
    out[OUT_LO + 9] = y1[4]
    if status != ST_OK:
        if status < 10:
            out[OUT_TFALL] = ts
        return status
    if xd < 0.0:
        out[OUT_TFALL] = ts
        return ST_FALL_BACKWARD
    res = np.empty(3)
    fstatus = find_touchdown(P, O, lo, tx, th, res)
    tf = res[0]
    out[OUT_TF] = tf
    out[OUT_CLEAR] = res[2]
    if fstatus != ST_OK:
        if fstatus < 10:
            out[OUT_TFALL] = ts + tf
        return fstatus
    fs = np.empty(10)
    flight_state(P, lo, tf, fs)
    out[OUT_TD + 0] = fs[6]
    out[OUT_TD + 1] = fs[4]
    out[OUT_TD + 2] = fs[2]
    out[OUT_TD + 3] = fs[3]
    out[OUT_TD + 4] = fs[5]
    out[OUT_TD + 5] = fs[0]
    out[OUT_TD + 6] = res[1]
    return ST_OK


# Batches: one row's work is a plain kernel; each driver exists twice, a serial
# loop in the calling thread (small batches: waking threads costs more than a
# row, and under load a sleeping core is not free) and a ``prange`` loop over
# numba's thread pool. ``parallel=True`` kernels compile only when first used.
# They call :func:`stride` directly, with no wrapper kernel: every kernel level
# re-optimises all the code below it, so a wrapper level costs a sixth of the
# first stride's compile time.
_PAR = {"parallel": True, "cache": True, "nogil": True}


@njit(**_JIT)
def run_row(P, O, td0, n_steps, tx, th, hist):
    """Run up to ``n_steps`` strides from ``td0``; returns ``(status, n_done, t_fall)``.

    ``hist`` (n_steps + 1, 7) receives the touch-down states (rows after a
    fall are left as they are); ``t_fall`` is NaN unless the run fell.
    """
    out = np.empty(NOUT)
    no_rec = np.empty((0, NREC))
    td = td0.copy()
    for j in range(7):
        hist[0, j] = td[j]
    t_total = 0.0
    st = ST_OK
    done = 0
    t_fall = math.nan
    for s in range(n_steps):
        st = stride(P, O, td, tx, th, no_rec, 0.0, out)
        if st != ST_OK:
            if st < 10:
                t_fall = t_total + out[OUT_TFALL]
            break
        t_total += out[OUT_TS] + out[OUT_TF]
        for j in range(7):
            td[j] = out[OUT_TD + j]
            hist[s + 1, j] = td[j]
        done = s + 1
    return st, done, t_fall


@njit(**_JIT)
def run_batch_serial(Ps, O, TDs, n_steps, TX, TH, td_hist, status, n_done, t_fall):
    """:func:`run_batch` row after row in the calling thread."""
    for i in range(Ps.shape[0]):
        status[i], n_done[i], t_fall[i] = run_row(Ps[i], O, TDs[i], n_steps, TX[i], TH[i],
                                                  td_hist[i])


@njit(**_PAR)
def run_batch(Ps, O, TDs, n_steps, TX, TH, td_hist, status, n_done, t_fall):
    """Run ``n_steps`` strides for each row, in parallel over rows.

    ``Ps`` (n, NP), ``TDs`` (n, 7), per-row terrain ``TX`` (n, nb) and
    ``TH`` (n, nb + 1) (pad breakpoints with ``+inf``). Writes each row's
    touch-down states into ``td_hist`` (n, n_steps + 1, 7), the final
    ``status``, the number of completed strides ``n_done`` and the time of
    the fall ``t_fall`` (NaN if none).
    """
    for i in prange(Ps.shape[0]):
        status[i], n_done[i], t_fall[i] = run_row(Ps[i], O, TDs[i], n_steps, TX[i], TH[i],
                                                  td_hist[i])


@njit(**_JIT)
def stride_batch_serial(Ps, O, TDs, TX, TH, OUTs, status):
    """:func:`stride_batch` row after row in the calling thread."""
    no_rec = np.empty((0, NREC))
    for i in range(Ps.shape[0]):
        status[i] = stride(Ps[i], O, TDs[i], TX[i], TH[i], no_rec, 0.0, OUTs[i])


@njit(**_PAR)
def stride_batch(Ps, O, TDs, TX, TH, OUTs, status):
    """One stride per row, in parallel over rows (the batched Poincare map)."""
    no_rec = np.empty((0, NREC))  # zero rows: never written, shared by the threads
    for i in prange(Ps.shape[0]):
        status[i] = stride(Ps[i], O, TDs[i], TX[i], TH[i], no_rec, 0.0, OUTs[i])


@njit(**_JIT)
def flight_samples(P, lo, ts, out):
    """:func:`flight_state` at each time in ``ts``; ``out`` has shape (n, 10)."""
    for i in range(ts.shape[0]):
        flight_state(P, lo, ts[i], out[i])


# ---------------------------------------------------------------------------
# A recorded run (tslip.simulate): strides sampled into trajectory rows
# ---------------------------------------------------------------------------


@njit(**_JIT)
def _energy(P, y, xd, yd, phid, l):
    """Total mechanical energy: kinetic + gravity + leg spring [MgL]."""
    return (0.5 * P[P_M] * (xd * xd + yd * yd) + 0.5 * P[P_J] * phid * phid
            + P[P_M] * P[P_G] * y + 0.5 * P[P_K] * (P[P_L0] - l) * (P[P_L0] - l))


@njit(**_JIT)
def _stance_row(P, t0, i, xf, h, r, row):
    """Trajectory row from the stance record row ``r`` (eq. A.3-A.5: CoM, hip from the leg)."""
    rp = P[P_R]
    l, b, ph, ld, bd, phd = r[1], r[2], r[3], r[4], r[5], r[6]
    sb = math.sin(b)
    cb = math.cos(b)
    sp = math.sin(ph)
    cp = math.cos(ph)
    y = h + l * sb - rp * cp
    xd, yd = _com_velocity(rp, l, sb, cb, sp, cp, ld, bd, phd)
    row[TR_T] = t0 + r[0]
    row[TR_STEP] = i
    row[TR_STANCE] = 1.0
    row[TR_X] = xf - l * cb + rp * sp
    row[TR_Y] = y
    row[TR_XD] = xd
    row[TR_YD] = yd
    row[TR_PHI] = ph
    row[TR_PHID] = phd
    row[TR_L] = l
    row[TR_BETA] = b
    row[TR_LD] = ld
    row[TR_BETAD] = bd
    row[TR_ALPHA] = b + ph
    row[TR_FOOTX] = xf
    row[TR_FOOTY] = h
    row[TR_HIPX] = xf - l * cb
    row[TR_HIPY] = h + l * sb
    row[TR_FX] = r[7]
    row[TR_FY] = r[8]
    row[TR_TAU] = r[9]
    row[TR_ENERGY] = _energy(P, y, xd, yd, phd, l)


@njit(**_JIT)
def _flight_row(P, t_lo, i, lo, tau, fs, row):
    """Trajectory row ``tau`` after lift-off at ``t_lo`` (closed-form flight, eq. 2.7)."""
    flight_state(P, lo, tau, fs)
    l0 = P[P_L0]
    row[TR_T] = t_lo + tau
    row[TR_STEP] = i
    row[TR_STANCE] = 0.0
    for j in range(6):  # x, y, xd, yd, phi, phid
        row[TR_X + j] = fs[j]
    row[TR_L] = l0
    row[TR_BETA] = fs[6]
    row[TR_LD] = 0.0
    row[TR_BETAD] = flight_leg_angle(P, lo[4], lo[5], tau, retraction_start(P, lo[3]))[1]
    row[TR_ALPHA] = fs[6] + fs[4]
    row[TR_FOOTX] = fs[7]
    row[TR_FOOTY] = fs[8]
    row[TR_HIPX] = fs[0] - P[P_R] * math.sin(fs[4])
    row[TR_HIPY] = fs[9]
    row[TR_FX] = 0.0
    row[TR_FY] = 0.0
    row[TR_TAU] = 0.0
    row[TR_ENERGY] = _energy(P, fs[1], fs[2], fs[3], fs[5], l0)


@njit(**_JIT)
def n_flight_samples(tf, dt, final):
    """Flight samples of a stride: ``dt, 2 dt, ...`` strictly before ``tf`` (those within
    1e-9 of it dropped: the next touch-down row follows), plus ``tf`` itself if ``final``."""
    n = max(0, int(math.ceil((tf - dt) / dt))) if tf > dt else 0
    if n > 0 and tf - (dt + (n - 1) * dt) < 1e-9:
        n -= 1
    return n + 1 if final else n


@njit(**_JIT)
def record_run(P, O, td, tx, th, first, last, close, dt, data, tloc, starts, outs, info, pos):
    """Strides ``first .. last - 1`` of a run, sampled every ``dt`` into trajectory rows.

    Starts from the touch-down state ``td`` (7) at time ``pos[1]`` and writes
    from row ``pos[0]`` of ``data`` (rows x NTRAJ, columns ``TR_*``): each
    stance on the grid of :func:`integrate_stance` (touch-down and lift-off
    rows included), each flight in closed form at ``dt, 2 dt, ...`` after
    lift-off, and the touch-down instant closing the last stride if ``close``
    (otherwise the next stride's first row is that instant). ``tloc`` gets each
    stance row's time since its touch-down. Stride ``s`` fills ``starts[s]``
    (its touch-down state), ``outs[s]`` (:func:`stride`'s output) and
    ``info[s]`` (``RI_*``).

    Returns the status of the last stride run (it stops at the first that is
    not OK), or ``RUN_FULL`` if the next stride's rows would not fit; then
    ``td``, ``pos = (row, t0, stride)`` say where to resume with more rows.
    """
    rec = np.empty((64, NREC))
    out = np.empty(NOUT)
    lo = np.empty(6)
    fs = np.empty(10)
    row = int(pos[0])
    t0 = pos[1]
    nmax = data.shape[0]
    status = ST_OK
    for s in range(first, last):
        pos[0] = row
        pos[1] = t0
        pos[2] = s
        while True:
            status = stride(P, O, td, tx, th, rec, dt, out)
            if out[OUT_RECOVF] == 0.0:
                break
            rec = np.empty((4 * rec.shape[0], NREC))
        nrec = int(out[OUT_NREC])
        ts = out[OUT_TS]
        tf = out[OUT_TF]
        final = status != ST_OK or (close and s == last - 1)
        nfl = n_flight_samples(tf, dt, final) if tf > 0.0 else 0
        if row + nrec + nfl > nmax:
            return RUN_FULL
        xf = out[OUT_XF]
        h = td[6]
        for k in range(nrec):
            _stance_row(P, t0, s, xf, h, rec[k], data[row + k])
            tloc[row + k] = rec[k, 0]
        t_lo = t0 + ts
        for j in range(6):
            lo[j] = out[OUT_LO + j]
        for k in range(nfl):
            tau = dt + k * dt
            if final and k == nfl - 1:
                tau = tf
            _flight_row(P, t_lo, s, lo, tau, fs, data[row + nrec + k])
        for j in range(NTD):
            starts[s, j] = td[j]
        for j in range(NOUT):
            outs[s, j] = out[j]
        inf = info[s]
        inf[RI_T0] = t0
        inf[RI_ROW0] = row
        inf[RI_NSTANCE] = nrec
        inf[RI_ROW1] = row + nrec + nfl
        inf[RI_STATUS] = status
        inf[RI_TDY] = h + P[P_L0] * math.sin(td[0]) - P[P_R] * math.cos(td[1])
        inf[RI_LOFY] = (lo[1] + P[P_R] * math.cos(lo[4])) - out[OUT_LO + 6] * math.sin(
            out[OUT_LO + 7])
        row += nrec + nfl
        pos[0] = row
        pos[2] = s + 1
        if status != ST_OK:
            break
        t0 = t_lo + tf
        pos[1] = t0
        for j in range(NTD):
            td[j] = out[OUT_TD + j]
    return status


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(flight_samples, __file__)

