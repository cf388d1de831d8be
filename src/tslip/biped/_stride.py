"""Compiled stride loop of the biped: Runge-Kutta steps with events (thesis Appendix E).

Private (see :mod:`._kernels`). The integrator is the shared core
:mod:`tslip.simulation._rk` (tableaus, error norm, dense output, event root
finding); only its stage loop is written here, with this model's right-hand
side (the core cannot take the right-hand side as an argument and stay
cacheable, see there).

The right-hand side is smooth between discontinuities, which are events (see
:mod:`._control`): after each accepted step the switching functions of
:func:`._events.event_g` are checked for a crossing, the earliest crossing is
located on the dense output (Illinois, to 1e-13 in time), the state there is
taken, every event that occurs there is applied and the integration
restarts. A fall is an event too: the run stops where the first fall margin
of :func:`._events.fall_value` reaches zero.

Speed (``benchmarks/bench_biped.py``): the loop and everything it calls are
compiled without numba's reference counting (:mod:`tslip._nrt`), so
:func:`run` allocates every work array and passes it in; the loop is
compiled once per Runge-Kutta pair (:func:`_integrate_dopri5`,
:func:`_integrate_dop853`), only for the pair a run uses, so that the
tableau is a constant; the switching functions at the end of a step read the
sines and cosines the right-hand side has just computed there.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._kernel_cache import check as _check_cache
from ..model._pack import M_DOP853, M_DOPRI5
from ..simulation import _rk
from ._contact import contact_force_trig, foot_state_of
from ._control import actuation, ctl_switch, ctl_switch_time, init_ctl
from ._events import K_CTL, K_FALL, NEVK, event_g, fall_check_trig, fall_value_trig, state_trig
from ._jit import FAST, INLINE, N
from ._pack import (
    CS_ON_L,
    CS_ON_R,
    CS_XR,
    CS_ZR,
    EV_FALL,
    EV_LO_R,
    EV_TD_R,
    NCS,
    O_ATOL,
    O_FALLS,
    O_H0,
    O_HMAX,
    O_HMIN,
    O_MAXSTEPS,
    O_METHOD,
    O_RTOL,
    O_TEND,
    O_TSTRIDE,
    P_ACT,
    P_CONTACT,
    R_CON,
    R_F,
    R_FS,
    R_FT,
    R_TAU,
    R_Y,
    S_NACC,
    S_NEV,
    S_NFEV,
    S_NREC,
    S_NREJ,
    S_NSTRIDE,
    S_RECFULL,
    S_TEND,
    ST_ERR_MAX_STEPS,
    ST_ERR_NONFINITE,
    ST_ERR_UNDERFLOW,
    ST_FALL_NO_TD,
    ST_OK,
    ST_TEND,
)
from ._rhs import make_workspace, rhs


@njit(**INLINE)
def rk_step(P, method, t, y, h, K, ytmp, ynew, cs, ctl, ws, aux):
    """One step from ``(t, y)`` with ``K[0] = f(t, y)``; ``K[ns] = f(ynew)``.

    The stages and the FSAL evaluation share one call of the right-hand side.
    (Inlining it there, ``rhs`` as ``inline="always"``, is some 8 % faster a
    stride but compiles for over twice as long.)
    """
    ns = _rk.n_stages(method)
    for s in range(1, ns + 1):
        ys = ynew if s == ns else ytmp
        _rk.stage_state(method, N, y, h, K, s, ys)
        ts = t + h if s == ns else t + _rk.stage_c(method, s) * h
        rhs(P, ts, ys, cs, ctl, False, K[s], ws, aux)


@njit(**FAST)
def dense_output(P, method, t, y, ynew, h, K, R, ytmp, cs, ctl, ws, aux):
    """Continuous extension of the step just taken; returns the extra rhs calls."""
    ns = _rk.n_stages(method)
    ne = _rk.n_extra(method)
    for s in range(ns + 1, ns + 1 + ne):
        _rk.stage_state(method, N, y, h, K, s, ytmp)
        rhs(P, t + _rk.stage_c(method, s) * h, ytmp, cs, ctl, False, K[s], ws, aux)
    _rk.dense_coeffs(method, y, ynew, h, K, R)
    return ne


@njit(**FAST)
def _record(P, rec, row, t, y, cs, ctl, ws):
    """Row ``row`` of ``rec``; ``ws`` holds the right-hand side at ``(t, y)``."""
    trig = ws[5]
    rc = ws[6]
    rec[row, 0] = t
    for i in range(N):
        rec[row, R_Y + i] = y[i]
    rec[row, R_CON] = cs[CS_ON_R]
    rec[row, R_CON + 1] = cs[CS_ON_L]
    for leg in range(2):
        fx, fz, _ = contact_force_trig(P, y, cs, leg, True, trig)
        ft, fs, tau = actuation(P, t, y, ctl, leg, rc)
        rec[row, R_F + 2 * leg] = fx
        rec[row, R_F + 2 * leg + 1] = fz
        rec[row, R_TAU + leg] = tau
        rec[row, R_FT + leg] = ft
        rec[row, R_FS + leg] = fs


def make_work():
    """Work arrays of :func:`_integrate` (a tuple; see :func:`run`)."""
    return (make_workspace(), np.empty(10), np.empty((_rk.NK, N)), np.empty((_rk.NR, N)),
            np.empty(5), np.empty(N), np.empty(N), np.empty(N), np.empty(4), np.empty(2),
            np.zeros(NEVK, dtype=np.bool_), np.empty(NEVK), np.empty(NEVK), np.empty(6))


def run(P, O, t0, y0, cs0, n_strides, rec, ev, strides, yend, csend, stats):
    """Integrate from ``(t0, y0, cs0)`` until ``n_strides`` right touch-downs.

    Stops earlier at ``O_TEND``, a fall (if ``O_FALLS``), no right touch-down
    within ``O_TSTRIDE``, or an integrator failure. Records every accepted
    step and event in ``rec`` (until full), contact events in ``ev`` and the
    state just after each right touch-down in ``strides``; the state and
    contact state at the end go to ``yend`` and ``csend``, the counts to
    ``stats``. Returns the status. ``y0`` and ``cs0`` are not changed.

    A Python function: it allocates the work arrays and calls the compiled
    loop of the run's Runge-Kutta pair (see the module docstring).
    """
    y = np.array(y0, dtype=np.float64)
    cs = np.array(cs0, dtype=np.float64)
    loop = _integrate_dop853 if int(O[O_METHOD]) == M_DOP853 else _integrate_dopri5
    return loop(P, O, float(t0), y, cs, int(n_strides), rec, ev, strides, yend, csend, stats,
                make_work())


@njit(**INLINE)
def _integrate(method, P, O, t0, y, cs, n_strides, rec, ev, strides, yend, csend, stats, work):
    """The loop of :func:`run` with the Runge-Kutta pair ``method`` (a constant);
    integrates ``y`` and ``cs`` in place."""
    ws, aux, K, R, st, ytmp, ynew, yev, ctl, tsw, active, g_old, g_new, trig_ev = work
    trig = ws[5]  # sines and cosines of the last right-hand side's state
    rtol = O[O_RTOL]
    atol = O[O_ATOL]
    hmax = O[O_HMAX]
    hmin = O[O_HMIN]
    maxsteps = int(O[O_MAXSTEPS])
    t_end = O[O_TEND]
    ns = _rk.n_stages(method)
    init_ctl(P, t0, ctl)
    for leg in range(2):
        tsw[leg] = ctl_switch_time(P, ctl, leg)
    for leg in range(2):
        active[leg] = P[P_CONTACT] != 0.0
        active[K_CTL + leg] = P[P_ACT] != 0.0
    active[K_FALL] = O[O_FALLS] != 0.0
    t = t0
    nrec = 0
    nev = 0
    nstr = 0
    nacc = 0
    nrej = 0
    nfev = 0
    t_last_td = t0
    status = ST_OK
    nrec_cap = rec.shape[0]
    rhs(P, t, y, cs, ctl, False, K[0], ws, aux)
    nfev += 1
    if nrec_cap > 0:
        _record(P, rec, 0, t, y, cs, ctl, ws)
        nrec = 1
    h = O[O_H0]
    if h <= 0.0:
        h = min(1e-3, hmax)
    for k in range(NEVK):
        g_old[k] = event_g(P, k, t, y, cs, tsw, trig)
    done = n_strides <= 0
    while not done:
        if nacc + nrej >= maxsteps:
            status = ST_ERR_MAX_STEPS
            break
        hstep = min(h, hmax)
        at_end = t + hstep >= t_end
        if at_end:
            hstep = t_end - t
        rk_step(P, method, t, y, hstep, K, ytmp, ynew, cs, ctl, ws, aux)
        nfev += ns
        err = _rk.error_norm(method, N, y, ynew, hstep, K, rtol, atol)
        if not math.isfinite(err):
            err = 1e10
        if err > 1.0:
            nrej += 1
            h = hstep * _rk.step_factor(method, err, 5.0)
            if h < hmin:
                status = ST_ERR_UNDERFLOW if math.isfinite(ynew[0]) else ST_ERR_NONFINITE
                break
            continue
        nacc += 1
        # accepted: the earliest crossing of a switching function in the step
        # (trig holds ynew's: the step's last right-hand side was at ynew)
        theta_ev = 2.0
        k_ev = -1
        have_dense = False
        for k in range(NEVK):
            if not active[k]:
                continue
            g_new[k] = event_g(P, k, t + hstep, ynew, cs, tsw, trig)
            if g_old[k] > 0.0 and g_new[k] <= 0.0:
                if not have_dense:  # (may overwrite trig: an event follows)
                    nfev += dense_output(P, method, t, y, ynew, hstep, K, R, yev, cs, ctl, ws,
                                         aux)
                    have_dense = True
                _rk.root_start(st, g_old[k], g_new[k])
                for _ in range(100):
                    c = _rk.root_guess(st)
                    _rk.dense_eval(method, R, c, yev)
                    state_trig(yev, trig_ev)
                    gc = event_g(P, k, t + c * hstep, yev, cs, tsw, trig_ev)
                    if _rk.root_update(st, c, gc, 1e-13 / hstep):
                        break
                if st[1] < theta_ev:
                    theta_ev = st[1]
                    k_ev = k
        if k_ev >= 0:
            _rk.dense_eval(method, R, theta_ev, ynew)
            t_ev = t + theta_ev * hstep
            if K_CTL <= k_ev < K_FALL:
                t_ev = tsw[k_ev - K_CTL]  # a controller switch is at a known time
            t = t_ev
            for i in range(N):
                y[i] = ynew[i]
            state_trig(y, trig_ev)
            # apply every event that has occurred at this point
            for k in range(NEVK):
                if not active[k] or not g_old[k] > 0.0:
                    continue
                if k != k_ev and event_g(P, k, t, y, cs, tsw, trig_ev) > 0.0:
                    continue
                if k == K_FALL:
                    status = fall_value_trig(P, y, trig_ev[1])[1]
                elif k >= K_CTL:
                    ctl_switch(ctl, k - K_CTL)
                    tsw[k - K_CTL] = ctl_switch_time(P, ctl, k - K_CTL)
                else:
                    x, z, _, _ = foot_state_of(P, y, k, trig_ev)
                    if cs[CS_ON_R + k] == 0.0:
                        cs[CS_ON_R + k] = 1.0
                        cs[CS_XR + 2 * k] = x
                        cs[CS_ZR + 2 * k] = 0.0
                        kind = EV_TD_R + k
                    else:
                        cs[CS_ON_R + k] = 0.0
                        kind = EV_LO_R + k
                    if nev < ev.shape[0]:
                        ev[nev, 0] = t
                        ev[nev, 1] = kind
                        ev[nev, 2] = x
                        ev[nev, 3] = z
                        nev += 1
                    if kind == EV_TD_R:
                        t_last_td = t
                        if nstr < strides.shape[0]:
                            strides[nstr, 0] = t
                            for i in range(N):
                                strides[nstr, 1 + i] = y[i]
                            for i in range(NCS):
                                strides[nstr, 1 + N + i] = cs[i]
                        nstr += 1
                        if nstr >= n_strides:
                            done = True
            rhs(P, t, y, cs, ctl, False, K[0], ws, aux)
            nfev += 1
            for k in range(NEVK):
                g_old[k] = event_g(P, k, t, y, cs, tsw, trig)
        else:
            t = t_end if at_end else t + hstep
            for i in range(N):
                y[i] = ynew[i]
                K[0, i] = K[ns, i]
            for k in range(NEVK):
                g_old[k] = g_new[k]
        # here trig holds y's again
        if nrec < nrec_cap:
            _record(P, rec, nrec, t, y, cs, ctl, ws)
            nrec += 1
        elif nrec_cap > 0:
            stats[S_RECFULL] = 1.0
        if status != ST_OK:  # fell at a located fall event
            break
        if not math.isfinite(y[0]):
            status = ST_ERR_NONFINITE
            break
        if O[O_FALLS] != 0.0:
            fs = fall_check_trig(P, y, trig[1])  # a margin that started at zero has no crossing
            if fs != ST_OK:
                status = fs
                break
            if t - t_last_td > O[O_TSTRIDE]:
                status = ST_FALL_NO_TD
                break
        if t >= t_end and not done:
            status = ST_TEND
            break
        # step-size control (Hairer)
        h = hstep * _rk.step_factor(method, err, 5.0)
    if status >= 10 and status < 20 and nev < ev.shape[0]:
        ev[nev, 0] = t
        ev[nev, 1] = EV_FALL
        ev[nev, 2] = status
        ev[nev, 3] = 0.0
        nev += 1
    for i in range(N):
        yend[i] = y[i]
    for i in range(NCS):
        csend[i] = cs[i]
    stats[S_NREC] = nrec
    stats[S_NEV] = nev
    stats[S_NSTRIDE] = nstr
    stats[S_NACC] = nacc
    stats[S_NREJ] = nrej
    stats[S_TEND] = t
    stats[S_NFEV] = nfev
    return status


@njit(**FAST)
def _integrate_dopri5(P, O, t0, y, cs, n_strides, rec, ev, strides, yend, csend, stats, work):
    """:func:`_integrate` with Dormand-Prince 5(4)."""
    return _integrate(M_DOPRI5, P, O, t0, y, cs, n_strides, rec, ev, strides, yend, csend,
                      stats, work)


@njit(**FAST)
def _integrate_dop853(P, O, t0, y, cs, n_strides, rec, ev, strides, yend, csend, stats, work):
    """:func:`_integrate` with Dormand-Prince 8(5,3)."""
    return _integrate(M_DOP853, P, O, t0, y, cs, n_strides, rec, ev, strides, yend, csend,
                      stats, work)


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(_integrate_dopri5, __file__)
