"""Compiled stride loop of the biped: Runge-Kutta steps with events (thesis Appendix E).

Private (see :mod:`._kernels`). The integrator is the shared core
:mod:`tslip.simulation._rk` (tableaus, error norm, dense output, event root
finding); only its stage loop is written here, with this model's right-hand
side (the core cannot take the right-hand side as an argument and stay
cacheable, see there).

The right-hand side (eq. E.22) is smooth between discontinuities, which are
events (see :mod:`._control`): a foot touches down or lifts off (eqs
E.23-E.24), a leg's controller switches branch (eqs E.25-E.34), or the
runner falls. The loop :func:`_integrate` is a few named steps, each a
function below, in the order a step takes them (thesis Section 2.3 and
E.2.5: an embedded Dormand-Prince pair at a tolerance of 1e-8, the right
touch-down a switching condition that ends the stride):

1. :func:`rk_step`: one Runge-Kutta step ``t -> t + h`` (its last stage the
   next step's first, FSAL);
2. :func:`_step_error`, :func:`_rejected`: error control; a rejected step is
   retried shorter, an accepted one sets the next step size (Hairer's
   controller, :func:`tslip.simulation._rk.step_factor`); so is the first step
   after a (re)start that jumped a whole hump of a switching function that
   started at its zero (:func:`_jumped_hump`: a foot's lift-off function at its
   touch-down);
3. :func:`_first_event`: event detection, a crossing of a switching function
   of :func:`._events.event_g` from > 0 to <= 0 between the step's ends;
4. :func:`_locate`: event location of each crossing on the dense output
   (:func:`dense_output`; Illinois, to 1e-13 in time), the earliest one wins;
5. :func:`_event_state`, :func:`_apply_events`, :func:`_restart`: the
   integration stops at the event, every event that occurs there is applied
   (contact :func:`._contact.contact_switch`, controller
   :func:`._control.ctl_switch`, fall) and it restarts in the new discrete
   state; :func:`_advance` moves to the step's end when there is none;
6. :func:`_record`, :func:`_run_status`: a row of the trajectory, then the
   checks that end a run (a fall: the first fall margin of
   :func:`._events.fall_value` to reach zero; the time limits).

Speed (``benchmarks/bench_biped.py``): the loop and everything it calls are
compiled without numba's reference counting (:mod:`tslip._nrt`), so
:func:`run` allocates every work array and passes it in; the loop is
compiled once for both Runge-Kutta pairs: the pair is a run-time argument,
read from ``O_METHOD``, and the tableau rows and stage counts are read from
the arrays of :mod:`tslip.simulation._rk` (compiling the loop once per pair,
with the pair a constant, cost some 7 s of compile CPU more for the second
pair); the switching functions at the end of a step read the sines and
cosines the right-hand side has just computed there. The steps are
``inline="always"`` into the loop, each with one call site, so the loop
compiles as one function, as it did when it was one body: each function
compiled on its own costs a first run some 0.5 s of compilation (its own
module, optimised again with everything it calls), and only :func:`rhs`
(eq. E.22, called from every stage), :func:`_record` (only when recording)
and :func:`dense_output` are. Inlining :func:`rhs` too would make a stride
faster but compile for over twice as long (see :func:`rk_step`); inlining
:func:`dense_output` (its extra stages call :func:`rhs`) cost some 6 s more
compile CPU for the two pairs than compiling it on its own.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._kernel_cache import check as _check_cache
from ..simulation import _rk
from ._contact import contact_force_trig, contact_switch
from ._control import actuation, ctl_switch, ctl_switch_time, init_ctl
from ._events import K_CTL, K_FALL, NEVK, event_g, fall_check_trig, fall_value_trig, state_trig
from ._jit import FAST, INLINE, N
from ._pack import (
    CS_ON_L,
    CS_ON_R,
    EV_FALL,
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
    loop (one for both Runge-Kutta pairs, see the module docstring).
    """
    y = np.array(y0, dtype=np.float64)
    cs = np.array(cs0, dtype=np.float64)
    return _integrate(P, O, float(t0), y, cs, int(n_strides), rec, ev, strides, yend, csend,
                      stats, make_work())


# ---------------------------------------------------------------------------
# The steps of the loop, in the order a step takes them (module docstring)
# ---------------------------------------------------------------------------


@njit(**INLINE)
def _start(P, O, t0, ctl, tsw, active):
    """The discrete state at ``t0``; returns the first step size.

    Each leg's controller branch and cycle at ``t0`` (phases, eqs E.25-E.27)
    and the time its branch ends; which switching functions are armed:
    contact (without ``P_CONTACT`` the feet never touch), controller (without
    ``P_ACT`` no actuation, no switch) and falls (``O_FALLS``).
    """
    init_ctl(P, t0, ctl)
    for leg in range(2):
        tsw[leg] = ctl_switch_time(P, ctl, leg)
    for leg in range(2):
        active[leg] = P[P_CONTACT] != 0.0
        active[K_CTL + leg] = P[P_ACT] != 0.0
    active[K_FALL] = O[O_FALLS] != 0.0
    h = O[O_H0]
    if h <= 0.0:
        h = min(1e-3, O[O_HMAX])
    return h


@njit(**INLINE)
def _step_size(h, hmax, t, t_end):
    """``(h_step, at_end)``: the next step, ``h`` capped at ``hmax`` and cut to end
    at ``t_end``, and whether it was cut."""
    hstep = min(h, hmax)
    at_end = t + hstep >= t_end
    if at_end:
        hstep = t_end - t
    return hstep, at_end


@njit(**INLINE)
def _step_error(method, y, ynew, h, K, rtol, atol):
    """Error of the step ``y -> ynew`` in units of the tolerance (accept if <= 1);
    a non-finite error counts as 1e10 (a rejection)."""
    err = _rk.error_norm(method, N, y, ynew, h, K, rtol, atol)
    if not math.isfinite(err):
        err = 1e10
    return err


@njit(**INLINE)
def _rejected(method, hstep, err, hmin, ynew):
    """``(h, status)`` after a rejected step: a shorter step, or an error below ``hmin``."""
    h = hstep * _rk.step_factor(method, err, 5.0)
    if h < hmin:
        return h, ST_ERR_UNDERFLOW if math.isfinite(ynew[0]) else ST_ERR_NONFINITE
    return h, ST_OK


@njit(**INLINE)
def _locate(method, P, k, t, h, g_lo, g_hi, R, cs, tsw, yev, trig_ev, st):
    """Event location: where in the step ``t -> t + h`` switching function ``k``
    crosses from ``g_lo > 0`` to ``g_hi <= 0``.

    Illinois on the dense output ``R`` (to 1e-13 in time, at most 100
    evaluations); returns the earliest ``theta`` in (0, 1] known to be at or
    past the crossing. ``yev``, ``trig_ev``, ``st`` are work arrays.
    """
    _rk.root_start(st, g_lo, g_hi)
    for _ in range(100):
        c = _rk.root_guess(st)
        _rk.dense_eval(method, R, c, yev)
        state_trig(yev, trig_ev)
        gc = event_g(P, k, t + c * h, yev, cs, tsw, trig_ev)
        if _rk.root_update(st, c, gc, 1e-13 / h):
            break
    return st[1]


@njit(**INLINE)
def _end_values(P, t, ynew, h, cs, tsw, active, g_new, ws):
    """The armed switching functions at the end ``(t + h, ynew)`` of an accepted step, into
    ``g_new``: complete before any crossing is located, as they read the sines and
    cosines of ``ynew`` in ``ws[5]`` (the step's last right-hand side was there), which
    the dense output's extra stages (dop853) overwrite."""
    trig = ws[5]
    for k in range(NEVK):
        if active[k]:
            g_new[k] = event_g(P, k, t + h, ynew, cs, tsw, trig)


@njit(**INLINE)
def _jumped_hump(P, t, y, cs, tsw, active, f, h, g_old, g_new, yp, trig_p):
    """Whether the first step after a (re)start at ``(t, y)`` (``f = f(t, y)``, step ``h``)
    jumped a whole hump of a switching function that starts at its zero
    (:func:`tslip.simulation._rk.jumped_hump`); the loop then retries it shorter.

    A foot's lift-off function ``min(F_z, k_z (z_TD - z_f))`` starts a contact a few
    ulps from 0 (the touch-down is located to 1e-13 in time), so a contact shorter than
    the step after it was jumped and its lift-off put at the touch-down. Only a step
    that ends with a function at or below zero reads the probe ``(t + d, y + d f)``,
    ``d = ZERO_PROBE h`` (``yp``, ``trig_p`` work arrays)."""
    below = False
    for k in range(NEVK):
        below = below or (active[k] and g_new[k] <= 0.0)
    if not below:
        return False
    d = _rk.ZERO_PROBE * h
    for i in range(N):
        yp[i] = y[i] + d * f[i]
    state_trig(yp, trig_p)
    for k in range(NEVK):
        if active[k] and _rk.jumped_hump(g_old[k], g_new[k],
                                         event_g(P, k, t + d, yp, cs, tsw, trig_p)):
            return True
    return False


@njit(**INLINE)
def _first_event(method, P, t, y, ynew, h, K, R, cs, ctl, tsw, active, g_old, g_new, yev,
                 trig_ev, st, ws, aux):
    """Event detection in the accepted step ``(t, y) -> (t + h, ynew)``: ``(k, theta, nfev)``.

    The armed switching functions at the step's end are in ``g_new``
    (:func:`_end_values`; their values at its start are ``g_old``); each that
    crosses from > 0 to <= 0 is located (:func:`_locate`) on the step's dense
    output, computed at the first crossing (``nfev`` right-hand sides). ``k`` is
    the earliest event (-1 if none) at ``t + theta h``.
    """
    theta_ev = 2.0
    k_ev = -1
    nfev = 0
    have_dense = False
    for k in range(NEVK):
        if active[k] and g_old[k] > 0.0 and g_new[k] <= 0.0:
            if not have_dense:
                nfev += dense_output(P, method, t, y, ynew, h, K, R, yev, cs, ctl, ws, aux)
                have_dense = True
            theta = _locate(method, P, k, t, h, g_old[k], g_new[k], R, cs, tsw, yev, trig_ev,
                            st)
            if theta < theta_ev:
                theta_ev = theta
                k_ev = k
    return k_ev, theta_ev, nfev


@njit(**INLINE)
def _event_state(method, k_ev, theta, t, h, R, tsw, y, trig):
    """Move to the located event: ``y`` (and its sines and cosines ``trig``) from
    the dense output at ``theta``; returns the event's time, for a controller
    switch its known time (the phase reaching d or 1, eqs E.25-E.27)."""
    _rk.dense_eval(method, R, theta, y)
    t_ev = t + theta * h
    if K_CTL <= k_ev < K_FALL:
        t_ev = tsw[k_ev - K_CTL]
    state_trig(y, trig)
    return t_ev


@njit(**INLINE)
def _log_event(ev, nev, t, kind, a, b):
    """Row ``nev`` of the event rows ``ev``, ``(t, kind, a, b)``, while there is room;
    returns the rows written."""
    if nev < ev.shape[0]:
        ev[nev, 0] = t
        ev[nev, 1] = kind
        ev[nev, 2] = a
        ev[nev, 3] = b
        nev += 1
    return nev


@njit(**INLINE)
def _log_stride(strides, nstr, t, y, cs):
    """Row ``nstr`` of ``strides``: ``t``, the state and the contact state just after
    a right touch-down (while there is room); returns the strides counted."""
    if nstr < strides.shape[0]:
        strides[nstr, 0] = t
        for i in range(N):
            strides[nstr, 1 + i] = y[i]
        for i in range(NCS):
            strides[nstr, 1 + N + i] = cs[i]
    return nstr + 1


@njit(**INLINE)
def _apply_events(P, t, y, cs, ctl, tsw, active, g_old, k_ev, trig, ev, nev, strides, nstr):
    """Apply every event that occurs at the located event ``k_ev`` at ``(t, y)``:
    ``(status, nev, nstr, right_td)``.

    An armed switching function that was > 0 at the step's start and is now
    <= 0 (or is ``k_ev`` itself) fires: a contact switch
    (:func:`._contact.contact_switch`, logged in ``ev``; a right touch-down
    also in ``strides``, it ends a stride, Section E.2.5), a controller switch
    (the leg's next branch and its end time), or a fall (``status``, the
    margin that reached zero).
    """
    status = ST_OK
    right_td = False
    for k in range(NEVK):
        if not active[k] or not g_old[k] > 0.0:
            continue
        if k != k_ev and event_g(P, k, t, y, cs, tsw, trig) > 0.0:
            continue
        if k == K_FALL:
            status = fall_value_trig(P, y, trig[1])[1]
        elif k >= K_CTL:
            ctl_switch(ctl, k - K_CTL)
            tsw[k - K_CTL] = ctl_switch_time(P, ctl, k - K_CTL)
        else:
            kind, x, z = contact_switch(P, y, cs, k, trig)
            nev = _log_event(ev, nev, t, kind, x, z)
            if kind == EV_TD_R:
                right_td = True
                nstr = _log_stride(strides, nstr, t, y, cs)
    return status, nev, nstr, right_td


@njit(**INLINE)
def _restart(P, t, y, cs, ctl, tsw, K, g_old, ws, aux):
    """(Re)start the integration at ``(t, y)`` in the discrete state ``cs``, ``ctl``:
    ``K[0] = f(t, y)`` (eq. E.22) and the switching functions there in ``g_old``."""
    rhs(P, t, y, cs, ctl, False, K[0], ws, aux)
    trig = ws[5]
    for k in range(NEVK):
        g_old[k] = event_g(P, k, t, y, cs, tsw, trig)


@njit(**INLINE)
def _advance(method, y, ynew, K, g_old, g_new):
    """Move to the end of an accepted step without events: ``y``, ``K[0]`` (FSAL) and
    the switching functions ``g_old`` take the step's end values."""
    ns = _rk.n_stages(method)
    for i in range(N):
        y[i] = ynew[i]
        K[0, i] = K[ns, i]
    for k in range(NEVK):
        g_old[k] = g_new[k]


@njit(**FAST)
def _record(P, rec, row, t, y, cs, ctl, ws, stats):
    """Row ``row`` of ``rec`` (if it has room, else ``S_RECFULL`` is set); returns
    the rows written. ``ws`` holds the right-hand side at ``(t, y)``."""
    if row >= rec.shape[0]:
        if rec.shape[0] > 0:
            stats[S_RECFULL] = 1.0
        return row
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
    return row + 1


@njit(**INLINE)
def _run_status(P, O, t, y, trig, t_last_td, done):
    """Whether the run ends at ``(t, y)`` (``trig`` its sines and cosines): a
    non-finite state, a fall (``O_FALLS``: a fall margin of
    :func:`._events.fall_check` at or below zero, or no right touch-down within
    ``O_TSTRIDE``), ``O_TEND`` reached before ``done``; else ``ST_OK``."""
    if not math.isfinite(y[0]):
        return ST_ERR_NONFINITE
    if O[O_FALLS] != 0.0:
        fs = fall_check_trig(P, y, trig[1])  # a margin that started at zero has no crossing
        if fs != ST_OK:
            return fs
        if t - t_last_td > O[O_TSTRIDE]:
            return ST_FALL_NO_TD
    if t >= O[O_TEND] and not done:
        return ST_TEND
    return ST_OK


@njit(**INLINE)
def _finish(t, y, cs, status, ev, nev, yend, csend, stats, nrec, nstr, nacc, nrej, nfev):
    """The end of a run: a fall's event row, the final state and the counts."""
    if status >= 10 and status < 20:
        nev = _log_event(ev, nev, t, EV_FALL, float(status), 0.0)
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


@njit(**FAST)
def _integrate(P, O, t0, y, cs, n_strides, rec, ev, strides, yend, csend, stats, work):
    """The loop of :func:`run`, with the Runge-Kutta pair ``O_METHOD`` (read at run
    time); integrates ``y`` and ``cs`` in place. Its steps: see the module docstring."""
    method = int(O[O_METHOD])
    ws, aux, K, R, st, ytmp, ynew, yev, ctl, tsw, active, g_old, g_new, trig_ev = work
    trig = ws[5]  # sines and cosines of the last right-hand side's state
    rtol = O[O_RTOL]
    atol = O[O_ATOL]
    hmax = O[O_HMAX]
    hmin = O[O_HMIN]
    maxsteps = int(O[O_MAXSTEPS])
    t_end = O[O_TEND]
    ns = _rk.n_stages(method)
    h = _start(P, O, t0, ctl, tsw, active)
    t = t0
    _restart(P, t, y, cs, ctl, tsw, K, g_old, ws, aux)
    first = True  # the first step after a (re)start is still to be accepted
    nfev = 1
    nrec = _record(P, rec, 0, t, y, cs, ctl, ws, stats)
    nev = 0
    nstr = 0
    nacc = 0
    nrej = 0
    t_last_td = t0
    status = ST_OK
    done = n_strides <= 0
    while not done:
        if nacc + nrej >= maxsteps:
            status = ST_ERR_MAX_STEPS
            break
        # 1. one Runge-Kutta step
        hstep, at_end = _step_size(h, hmax, t, t_end)
        rk_step(P, method, t, y, hstep, K, ytmp, ynew, cs, ctl, ws, aux)
        nfev += ns
        # 2. error control
        err = _step_error(method, y, ynew, hstep, K, rtol, atol)
        if err > 1.0:
            nrej += 1
            h, status = _rejected(method, hstep, err, hmin, ynew)
            if status != ST_OK:
                break
            continue
        _end_values(P, t, ynew, hstep, cs, tsw, active, g_new, ws)
        if first:
            if _jumped_hump(P, t, y, cs, tsw, active, K[0], hstep, g_old, g_new, yev, trig_ev):
                # it jumped a whole hump of a function that started at its zero
                nrej += 1
                h = hstep * _rk.HUMP_SHRINK
                if h < hmin:
                    status = ST_ERR_UNDERFLOW
                    break
                continue
            first = False
        nacc += 1
        # 3.-4. event detection and location
        k_ev, theta, nfe = _first_event(method, P, t, y, ynew, hstep, K, R, cs, ctl, tsw,
                                        active, g_old, g_new, yev, trig_ev, st, ws, aux)
        nfev += nfe
        # 5. stop at the event, apply it and restart; else to the step's end
        if k_ev >= 0:
            t = _event_state(method, k_ev, theta, t, hstep, R, tsw, y, trig_ev)
            status, nev, nstr, right_td = _apply_events(P, t, y, cs, ctl, tsw, active, g_old,
                                                        k_ev, trig_ev, ev, nev, strides, nstr)
            if right_td:
                t_last_td = t
                done = nstr >= n_strides
            _restart(P, t, y, cs, ctl, tsw, K, g_old, ws, aux)
            first = True
            nfev += 1
        else:
            t = t_end if at_end else t + hstep
            _advance(method, y, ynew, K, g_old, g_new)
        # 6. record (trig holds y's again), then the checks that end a run
        nrec = _record(P, rec, nrec, t, y, cs, ctl, ws, stats)
        if status == ST_OK:  # else fell at a located fall event
            status = _run_status(P, O, t, y, trig, t_last_td, done)
        if status != ST_OK:
            break
        # step-size control (Hairer)
        h = hstep * _rk.step_factor(method, err, 5.0)
    _finish(t, y, cs, status, ev, nev, yend, csend, stats, nrec, nstr, nacc, nrej, nfev)
    return status


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(_integrate, __file__)
