"""The compiled stance integrator: the :mod:`._rk` stage loop with the stance ``rhs``, and events.

Private (see :mod:`._kernels`). :data:`INTEGRATE_STANCE` holds one kernel per
Runge-Kutta pair (:func:`._specialise.specialise`), whose ``method`` and
``record`` (whether the stance is recorded) are compile-time constants: each
holds one method's stage loop and, without ``record``, none of the recording
code. The helpers are small ``inline="always"`` functions taking them as
arguments.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numba import njit

from .._kernel_cache import check as _check_cache
from ..model._pack import (
    M_DOPRI5,
    O_ATOL,
    O_H0,
    O_HMIN,
    O_MAXSTEPS,
    O_RTOL,
    O_TMAX_STANCE,
    ST_ERR_MAX_STEPS,
    ST_ERR_NONFINITE,
    ST_ERR_STANCE_TIMEOUT,
    ST_ERR_STEP_UNDERFLOW,
    ST_FALL_BACKWARD,
    ST_FALL_HIP_GROUND,
    ST_FALL_LENGTHENING,
    ST_OK,
)
from . import _rk
from ._rk import _INLINE
from ._specialise import specialise
from ._stance import NEVENTS, NSTATE, event_values, grf, rhs


@njit(**_INLINE)
def rk_step(P, method, y, h, K, ytmp, ynew):
    """One step of size ``h`` from ``y`` with ``K[0] = f(y)`` (see :mod:`._rk`).

    Fills the stages ``K[1..ns]`` and ``ynew``; ``K[ns] = f(ynew)`` (FSAL). With
    a constant ``method`` the loops over the tableau compile like a hand-unrolled
    stepper, which the cheap stance right-hand side makes worth it
    (``benchmarks/bench_rk.py``).
    """
    ns = _rk.n_stages(method)
    for s in range(1, ns):
        _rk.stage_state(method, NSTATE, y, h, K, s, ytmp)
        rhs(P, ytmp, K[s])
    _rk.stage_state(method, NSTATE, y, h, K, ns, ynew)
    rhs(P, ynew, K[ns])


@njit(**_INLINE)
def dense_output(P, method, y, ynew, h, K, R, ytmp):
    """Continuous extension of the step just taken (extra stages for dop853)."""
    ns = _rk.n_stages(method)
    for s in range(ns + 1, ns + 1 + _rk.n_extra(method)):
        _rk.stage_state(method, NSTATE, y, h, K, s, ytmp)
        rhs(P, ytmp, K[s])
    _rk.dense_coeffs_inline(method, y, ynew, h, K, R)


@njit(**_INLINE)
def initial_step(P, method, y, f0, rtol, atol, ytmp, f1):
    """Starting step size (Hairer, Norsett & Wanner, II.4)."""
    h0, d1 = _rk.initial_probe(y, f0, rtol, atol, ytmp)
    rhs(P, ytmp, f1)
    return _rk.initial_step(method, y, f0, f1, h0, d1, rtol, atol)


@njit(**_INLINE)
def event_root(P, method, R, ev, g_lo, g_hi, ytmp, gv, st):
    """Root in theta of event ``ev`` on the dense output (Illinois method)."""
    _rk.root_start_inline(st, g_lo, g_hi)
    for _ in range(100):
        c = _rk.root_guess_inline(st)
        _rk.dense_eval_inline(method, R, c, ytmp)
        event_values(P, ytmp, gv)
        if _rk.root_update_inline(st, c, gv[ev], 1e-15):
            break
    return st[1]  # the earliest theta known to be at or past the crossing


@njit(**_INLINE)
def record_row(P, rec, row, t, y):
    """Stance record row ``row``: ``t, y, F_x, F_y, tau``."""
    rec[row, 0] = t
    for i in range(NSTATE):
        rec[row, 1 + i] = y[i]
    fx, fy, tau = grf(P, y)
    rec[row, 7] = fx
    rec[row, 8] = fy
    rec[row, 9] = tau


def _make_integrate_stance(method: int, record: bool) -> Callable:
    def integrate_stance(P, O, y0, yout, rec, rec_dt, stats):
        """Integrate the stance from ``y0`` until lift-off or a fall, with the pair ``method``.

        A stance that starts with the hip at the ground, ``xdot_m < 0`` or the leg
        lengthening (``ld > 0``: a spring leg cannot pull) ends at once with that
        fall (docs/conventions.md, "Events").

        With ``record``, ``rec`` (rows x NREC) receives ``t, y, F_x, F_y, tau``: at
        each accepted step if ``rec_dt <= 0``, else on a uniform grid of spacing
        ``rec_dt`` from the dense output; without, ``rec`` and ``rec_dt`` are not
        read. ``stats`` receives ``[t_end, n_accepted, n_rejected, n_recorded,
        overflow]``. Returns the status code; ``yout`` holds the final state.
        """
        rtol = O[O_RTOL]
        atol = O[O_ATOL]
        max_steps = int(O[O_MAXSTEPS])
        t_max = O[O_TMAX_STANCE]
        h_min = O[O_HMIN]
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
        nrec_max = rec.shape[0] if record else 0
        nrec = 0
        overflow = 0.0
        t = 0.0
        event_values(P, y, gv_old)
        status = ST_OK
        rhs(P, y, K[0])
        # record the first row
        if record and nrec_max > 0:
            record_row(P, rec, nrec, t, y)
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
        # a step that finds an event is followed by one exact step to the event time
        # (the next pass of the loop), for a full-order event state
        to_event = False
        first_ev = -1
        h_ev = 0.0
        while not done:
            if not to_event:
                if n_acc + n_rej >= max_steps:
                    status = ST_ERR_MAX_STEPS
                    break
                if t >= t_max:
                    status = ST_ERR_STANCE_TIMEOUT
                    break
                if h < h_min:
                    status = ST_ERR_STEP_UNDERFLOW
                    break
            if not to_event or h_ev > 0.0:
                rk_step(P, method, y, h_ev if to_event else h, K, ytmp, ynew)
            else:
                for i in range(NSTATE):
                    ynew[i] = y[i]
            if to_event:
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
                # accepted step: look for events, on the dense output (also the grid samples')
                n_acc += 1
                event_values(P, ynew, gv_new)
                dense = False
                if record and rec_dt > 0.0 and nrec_max > 0:
                    dense = True
                for ev in range(NEVENTS):
                    if gv_old[ev] > 0.0 and gv_new[ev] <= 0.0:
                        dense = True
                if dense:
                    dense_output(P, method, y, ynew, h, K, R, ytmp)
                theta_ev = 2.0
                # falls first: lift-off wins only if strictly earlier (F_y = F_l sin(beta)
                # and the hip height l sin(beta) vanish together when beta reaches 0)
                for j in range(NEVENTS):
                    ev = (1, 3, 2, 0)[j]
                    if gv_old[ev] > 0.0 and gv_new[ev] <= 0.0:
                        th = event_root(P, method, R, ev, gv_old[ev], gv_new[ev], ytmp, gv_tmp,
                                        st)
                        if th < theta_ev - 1e-9:
                            theta_ev = th
                            first_ev = ev
                if record and rec_dt > 0.0 and nrec_max > 0:
                    t_stop = t + h * min(theta_ev, 1.0)
                    while t_next_rec <= t_stop:
                        if nrec >= nrec_max:
                            overflow = 1.0
                            break
                        _rk.dense_eval_inline(method, R, (t_next_rec - t) / h, ytmp)
                        record_row(P, rec, nrec, t_next_rec, ytmp)
                        nrec += 1
                        t_next_rec += rec_dt
                if first_ev >= 0:
                    h_ev = theta_ev * h
                    to_event = True
                    continue
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
            if record and rec_dt <= 0.0 and nrec_max > 0:
                if nrec < nrec_max:
                    record_row(P, rec, nrec, t, y)
                    nrec += 1
                else:
                    overflow = 1.0
        if record and rec_dt > 0.0 and nrec_max > 0 and status == ST_OK:
            # always close the record with the lift-off row
            if nrec < nrec_max:
                record_row(P, rec, nrec, t, y)
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

    return integrate_stance


#: ``(P, O, y0, yout, rec, rec_dt, stats) -> status`` by method: recording nothing
#: (``rec`` and ``rec_dt`` unread) and recording into ``rec``.
INTEGRATE_STANCE = specialise(_make_integrate_stance, "integrate_stance", False)
INTEGRATE_STANCE_REC = specialise(_make_integrate_stance, "integrate_stance_rec", True)
_STANCE_DOPRI5, _STANCE_DOP853 = INTEGRATE_STANCE
_STANCE_REC_DOPRI5, _STANCE_REC_DOP853 = INTEGRATE_STANCE_REC


@njit(**_INLINE)
def integrate_stance_of(method, record, P, O, y0, yout, rec, rec_dt, stats):
    """``INTEGRATE_STANCE[_REC][method]`` from a kernel where both are constants."""
    if record:
        if method == M_DOPRI5:
            return _STANCE_REC_DOPRI5(P, O, y0, yout, rec, rec_dt, stats)
        return _STANCE_REC_DOP853(P, O, y0, yout, rec, rec_dt, stats)
    if method == M_DOPRI5:
        return _STANCE_DOPRI5(P, O, y0, yout, rec, rec_dt, stats)
    return _STANCE_DOP853(P, O, y0, yout, rec, rec_dt, stats)


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(_STANCE_DOPRI5, __file__)
