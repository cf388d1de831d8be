"""Compiled strides (touch-down -> lift-off -> touch-down), one kernel per integrator method.

Private (see :mod:`._kernels`). The Runge-Kutta pair and whether the stance is
recorded are compile-time constants of each kernel (:mod:`._specialise`), and
only what a call uses compiles: a first :func:`tslip.step_map` compiles one
stride kernel, its stance integrator and the functions they call
(:func:`._stance.rhs`, :func:`._stance.event_values`,
:func:`._flight.find_touchdown`), against about 35 functions when every helper
was a kernel of its own and the method a run-time argument.

The small helpers are ``inline="always"``; a large body never is: numba copies
an inlined function's IR block by block, each copy with its whole variable
scope, so inlining the stance integrator into the stride took over a minute.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numba import njit, prange

from .._kernel_cache import check as _check_cache
from ..model._pack import (
    M_DOPRI5,
    NOUT,
    NREC,
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
    P_L0,
    P_R,
    ST_FALL_BACKWARD,
    ST_OK,
)
from ._flight import find_touchdown, flight_state
from ._rk import _INLINE, _JIT
from ._specialise import specialise
from ._stance import NSTATE, com_velocity, grf, stance_initial
from ._stepper import integrate_stance_of

#: numba's options for the ``prange`` batch kernels (compiled only when first used)
_PAR = dict(_JIT, parallel=True)


def _make_stride(method: int, record: bool) -> Callable:
    def stride(P, O, td, tx, th, rec, rec_dt, out):
        """One stride from the touch-down state ``td`` (7) to the next, with the pair ``method``.

        Fills ``out`` (layout ``OUT_*`` in ``_pack``) and returns the status.
        With ``record`` the stance is recorded into ``rec`` (see
        :func:`._stepper._make_integrate_stance`).
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
        status = integrate_stance_of(method, record, P, O, y0, y1, rec, rec_dt, stats)
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

    return stride


#: The stride kernels ``(P, O, td, tx, th, rec, rec_dt, out) -> status``, by method:
#: recording nothing (``rec`` has no rows) and recording the stance into ``rec``.
STRIDE = specialise(_make_stride, "stride", False)
STRIDE_REC = specialise(_make_stride, "stride_rec", True)
_STRIDE_DOPRI5, _STRIDE_DOP853 = STRIDE


_STRIDE_REC_DOPRI5, _STRIDE_REC_DOP853 = STRIDE_REC


@njit(**_INLINE)
def stride_of(method, record, P, O, td, tx, th, rec, rec_dt, out):
    """``STRIDE[_REC][method]`` called from a kernel where both are constants."""
    if record:
        if method == M_DOPRI5:
            return _STRIDE_REC_DOPRI5(P, O, td, tx, th, rec, rec_dt, out)
        return _STRIDE_REC_DOP853(P, O, td, tx, th, rec, rec_dt, out)
    if method == M_DOPRI5:
        return _STRIDE_DOPRI5(P, O, td, tx, th, rec, rec_dt, out)
    return _STRIDE_DOP853(P, O, td, tx, th, rec, rec_dt, out)


# ---------------------------------------------------------------------------
# Batches: each driver exists twice, a serial loop in the calling thread (small
# batches: waking threads costs more than a row, and under load a sleeping core
# is not free) and a ``prange`` loop over numba's thread pool; ``parallel=True``
# kernels compile only when first used. A row calls the compiled stride.
# ---------------------------------------------------------------------------


def _make_run_row(method: int) -> Callable:
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
            st = stride_of(method, False, P, O, td, tx, th, no_rec, 0.0, out)
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

    return run_row


RUN_ROW = specialise(_make_run_row, "run_row")
_RUN_ROW_DOPRI5, _RUN_ROW_DOP853 = RUN_ROW


@njit(**_INLINE)
def run_row_of(method, P, O, td0, n_steps, tx, th, hist):
    """``RUN_ROW[method]`` called from a kernel whose ``method`` is a constant."""
    if method == M_DOPRI5:
        return _RUN_ROW_DOPRI5(P, O, td0, n_steps, tx, th, hist)
    return _RUN_ROW_DOP853(P, O, td0, n_steps, tx, th, hist)


def _make_run_batch(method: int, parallel: bool) -> Callable:
    if parallel:
        def run_batch(Ps, O, TDs, n_steps, TX, TH, td_hist, status, n_done, t_fall):
            for i in prange(Ps.shape[0]):
                status[i], n_done[i], t_fall[i] = run_row_of(method, Ps[i], O, TDs[i], n_steps,
                                                             TX[i], TH[i], td_hist[i])
        return run_batch

    def run_batch_serial(Ps, O, TDs, n_steps, TX, TH, td_hist, status, n_done, t_fall):
        for i in range(Ps.shape[0]):
            status[i], n_done[i], t_fall[i] = run_row_of(method, Ps[i], O, TDs[i], n_steps,
                                                         TX[i], TH[i], td_hist[i])
    return run_batch_serial


#: ``(Ps, O, TDs, n_steps, TX, TH, td_hist, status, n_done, t_fall)``: ``n_steps``
#: strides for each row. ``Ps`` (n, NP), ``TDs`` (n, 7), per-row terrain ``TX``
#: (n, nb) and ``TH`` (n, nb + 1) (pad breakpoints with ``+inf``). Writes each
#: row's touch-down states into ``td_hist`` (n, n_steps + 1, 7), the final
#: ``status``, the number of completed strides ``n_done`` and the time of the fall
#: ``t_fall`` (NaN if none). In the calling thread, and in parallel over rows.
RUN_BATCH_SERIAL = specialise(_make_run_batch, "run_batch_serial", False)
RUN_BATCH = specialise(_make_run_batch, "run_batch", True, jit=_PAR)


def _make_stride_batch(method: int, parallel: bool) -> Callable:
    if parallel:
        def stride_batch(Ps, O, TDs, TX, TH, OUTs, status):
            no_rec = np.empty((0, NREC))  # zero rows: never written, shared by the threads
            for i in prange(Ps.shape[0]):
                status[i] = stride_of(method, False, Ps[i], O, TDs[i], TX[i], TH[i], no_rec, 0.0,
                                      OUTs[i])
        return stride_batch

    def stride_batch_serial(Ps, O, TDs, TX, TH, OUTs, status):
        no_rec = np.empty((0, NREC))
        for i in range(Ps.shape[0]):
            status[i] = stride_of(method, False, Ps[i], O, TDs[i], TX[i], TH[i], no_rec, 0.0,
                                      OUTs[i])
    return stride_batch_serial


#: ``(Ps, O, TDs, TX, TH, OUTs, status)``: one stride per row (the batched Poincare
#: map), in the calling thread and in parallel over rows.
STRIDE_BATCH_SERIAL = specialise(_make_stride_batch, "stride_batch_serial", False)
STRIDE_BATCH = specialise(_make_stride_batch, "stride_batch", True, jit=_PAR)


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(_STRIDE_DOPRI5, __file__)
