"""Compiled strides (touch-down -> lift-off -> touch-down), one kernel for both integrator methods.

Private (see :mod:`._kernels`). One kernel, :func:`stride`, holds a whole stride: the
stance's step-size and event loop (its named steps from :mod:`._stepper` and below:
Runge-Kutta step, error control, event detection, dense output, event location, the
step to the event, following the thesis's Section 2.3), the lift-off state and the
closed-form flight. The Runge-Kutta pair is a run-time argument, read from the options
(``O[O_METHOD]``): every kernel here (and :func:`._record.record_run`,
:func:`._variational.stride_jacobian`) compiles once for both pairs, where one copy
per pair, the pair a compile-time constant, compiled everything twice for a process
using both: a first ``step_map``, ``step_jacobian`` and ``simulate`` with each pair took
42 s of CPU from an empty cache, not 63 s (one pair alone, 36 s before: 15 % more, the
branches on the pair now compiled in; a loaded machine, two runs side by side). At run
time the one kernel costs about what one per pair did: a Table 6.1 stride executes
101,800 instructions with dopri5 (one kernel per pair: 101,400) and 88,000 with dop853
(91,500; callgrind, ``NUMBA_CPU_NAME=generic``, a call from Python and its dispatch, the
difference of runs of 200 and 100 calls).
It cost 109,900 and 93,800 while the error norm and the dense output read the pair's
tableau at run time (loads and zero tests of its coefficients, loops of run-time
length): they now branch once on the pair to code with its sizes and coefficients
constants (:func:`._rk.error_norm`, :func:`._rk.dense_coeffs`, :func:`._rk.dense_eval`),
which the compiler unrolls; :func:`._stepper.stage_input` keeps the stage sums in
registers. A copy of the stage loop per pair inside the one kernel (the pair a
constant in each) ran no fewer instructions: its rows are read at a run-time stage.

Only what a call uses compiles: a first :func:`tslip.step_map` compiles
:func:`section_map`, the stride kernel and the functions it calls
(:func:`._stance.rhs`, :func:`._stance.event_values`,
:func:`._flight.find_touchdown`, and, called once a stride, :func:`stride_finish`,
:func:`._stepper.initial_step` and :func:`._stepper.first_event`).
Those three compile on their own because numba types every inlined copy with
the body it lands in: inlined, a cold first step_map took 18.4-18.7 s, not 16.5-17.1 s.
The same kernel records the stance when given rows to record into
(``tslip.simulate``, the exact Jacobian): a copy with recording compiled out ran
no faster (``run_row`` and ``simulate`` within 1 %, alternate calls) and cost
another 10 s of compilation.

The small helpers are ``inline="always"``; a large body never is: numba copies
an inlined function's IR block by block, each copy with its whole variable
scope, so inlining the stance integrator into the stride took over a minute.

Over 600 lines: one concept, the compiled stride and the drivers built on it.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numba import njit, prange

from .._kernel_cache import check as _check_cache
from ..model._pack import (
    NOUT,
    NREC,
    NTD,
    O_ATOL,
    O_H0,
    O_HMIN,
    O_MAXSTEPS,
    O_METHOD,
    O_RTOL,
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
    OUT_TSW,
    OUT_XF,
    P_L0,
    P_R,
    P_THRUST,
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
from ._flight import find_touchdown, flight_state
from ._rk import _INLINE, _JIT
from ._stance import (
    EV_BACKWARD,
    EV_COLLAPSE,
    EV_HIP_GROUND,
    EV_LIFTOFF,
    EV_THRUST,
    NEVENTS,
    NSTATE,
    com_velocity,
    event_values,
    grf,
    rhs,
    stance_initial,
)
from ._stepper import (
    append_row,
    crossed,
    first_event,
    grow_step,
    initial_step,
    record_grid,
    retry_step,
    rising_from_zero,
    rk_step,
    stage_input,
)

#: numba's options for the ``prange`` batch kernels (compiled only when first used)
_PAR = dict(_JIT, parallel=True)


@njit(**_INLINE)
def stride_start(P, td, y0, out):
    """Start a stride at the touch-down state ``td``: ``out`` cleared, the stance state
    ``y0`` (eq. A.5 inverted), the foot position ``x_f`` (returned) and whether ``F_y < 0``."""
    for i in range(NOUT):
        out[i] = math.nan
    out[OUT_TS] = 0.0
    out[OUT_TF] = 0.0
    out[OUT_NREC] = 0.0
    out[OUT_RECOVF] = 0.0
    stance_initial(P, td, y0)
    xf = td[5] + P[P_L0] * math.cos(td[0]) - P[P_R] * math.sin(td[1])
    out[OUT_XF] = xf
    fx0, fy0, _ = grf(P, y0)
    out[OUT_FYNEG] = 1.0 if fy0 < 0.0 else 0.0
    return xf


@njit(**_JIT)
def stride_finish(P, O, status, td, xf, y1, stats, tx, th, out, work):
    """The rest of a stride after its stance (``status``, final state ``y1``,
    ``stats``): lift-off state, closed-form flight, touch-down; returns the status.
    ``work`` (19) is scratch space.

    Compiled on its own (once for both methods): see the module docstring."""
    r = P[P_R]
    h = td[6]
    ts = stats[0]
    out[OUT_TS] = ts
    out[OUT_NSTEP] = stats[1]
    out[OUT_NREJ] = stats[2]
    out[OUT_NREC] = stats[3]
    out[OUT_RECOVF] = stats[4]
    # lift-off (or final) CoM state
    l, b, ph = y1[0], y1[1], y1[2]
    xd, yd = com_velocity(P, y1)
    lo = work[0:6]
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
    res = work[6:9]
    fstatus = find_touchdown(P, O, lo, tx, th, res)
    tf = res[0]
    out[OUT_TF] = tf
    out[OUT_CLEAR] = res[2]
    if fstatus != ST_OK:
        if fstatus < 10:
            out[OUT_TFALL] = ts + tf
        return fstatus
    fs = work[9:19]
    flight_state(P, lo, tf, fs)
    out[OUT_TD + 0] = fs[6]
    out[OUT_TD + 1] = fs[4]
    out[OUT_TD + 2] = fs[2]
    out[OUT_TD + 3] = fs[3]
    out[OUT_TD + 4] = fs[5]
    out[OUT_TD + 5] = fs[0]
    out[OUT_TD + 6] = res[1]
    return ST_OK


@njit(**_INLINE)
def touchdown_fall(gv, y):
    """The fall a stance starts in (``gv`` its event values, ``y`` its state), else ``ST_OK``:
    the hip at the ground, moving backward, or the leg lengthening (``ld > 0``: the
    spring would stretch past ``l0`` and pull on the ground; docs/conventions.md, "Events")."""
    if gv[EV_HIP_GROUND] <= 0.0:
        return ST_FALL_HIP_GROUND
    if gv[EV_BACKWARD] < 0.0:
        return ST_FALL_BACKWARD
    if y[3] > 0.0:
        return ST_FALL_LENGTHENING
    return ST_OK


@njit(**_INLINE)
def step_guard(O, n_steps, t, h):
    """``ST_OK`` if the stance may take another step, else the error that stops it."""
    if n_steps >= int(O[O_MAXSTEPS]):
        return ST_ERR_MAX_STEPS
    if t >= O[O_TMAX_STANCE]:
        return ST_ERR_STANCE_TIMEOUT
    if h < O[O_HMIN]:
        return ST_ERR_STEP_UNDERFLOW
    return ST_OK


@njit(**_INLINE)
def event_status(ev):
    """How a stance ends at event ``ev`` (:func:`._stance.event_values`): lift-off
    (eq. 2.8) is ``ST_OK``; the hip at the ground (eq. 2.11, or the leg collapsed)
    and moving backward (eq. 2.10) are falls."""
    if ev == EV_LIFTOFF:
        return ST_OK
    if ev == EV_HIP_GROUND or ev == EV_COLLAPSE:
        return ST_FALL_HIP_GROUND
    return ST_FALL_BACKWARD


@njit(**_INLINE)
def step_to_event(y, ynew, t, h):
    """The stance at a located event: the end ``ynew`` of the step of ``h = theta h_acc``
    from the start of the accepted step (of size ``h_acc``) in which the event was located
    at ``theta`` (``y``, unless ``h`` is 0); returns the event's time ``t + h``.

    The stride's loop takes that step as its next pass (the loop's one call of
    :func:`._stepper.rk_step`, so that the stage arithmetic compiles once): a fresh step
    of the pair's full order, whose end is a point of the numerical solution itself, not
    the dense output's value at ``theta`` (one order lower: 4 against 5 for dopri5, 7
    against 8 for dop853). Reaching the event from the dense output instead would save
    the step's stages (6 or 12 right-hand sides a stance), but it is another
    approximation of the event state, so every stride's result would change
    (``benchmarks/compare_kernels.py`` requires the bits of the earlier checkouts), and
    the stride Jacobian's replay (:mod:`._variational`) differentiates the steps the
    stride takes, which would then end with an interpolation: so the fresh step is kept."""
    if h > 0.0:
        copy_state(y, ynew)
    return t + h


@njit(**_INLINE)
def working_params(P):
    """The stance's parameters: a copy of ``P`` to switch the rest length in if it has
    leg thrust (:func:`thrust_switch`), else ``P`` itself."""
    return P.copy() if P[P_THRUST] > 0.0 else P


@njit(**_INLINE)
def thrust_switch(Pw, O, method, y, K, gv, ytmp, fly, t, out):
    """The leg thrust's switch at the stance state ``y`` (event 4, at time ``t``, kept in
    ``out[OUT_TSW]`` of a stride): the working parameters ``Pw`` take the rest length
    ``l0 (1 + d)`` (``P_THRUST`` holds ``-d``); ``K[0] = f(y)`` and the event values
    ``gv`` anew; returns the next step size, estimated afresh (the field jumps there)."""
    if fly:
        out[OUT_TSW] = t
    Pw[P_THRUST] = -Pw[P_THRUST]
    event_values(Pw, y, gv)
    rhs(Pw, y, K[0])
    return initial_step(Pw, method, y, K[0], O[O_RTOL], O[O_ATOL], ytmp, K[1])


@njit(**_INLINE)
def record_close(rec, nrec, t, y, on_grid, status):
    """Close a grid record with the lift-off row: ``(rows used, overflow)``."""
    if on_grid and status == ST_OK:
        return append_row(rec, nrec, t, y)
    return nrec, 0.0


@njit(**_INLINE)
def stance_out(y, stats, out):
    """``out`` of a stance alone: the final state, then ``stats``."""
    for i in range(NSTATE):
        out[i] = y[i]
    for i in range(5):
        out[NSTATE + i] = stats[i]


@njit(**_INLINE)
def record_start(rec, rec_dt, y):
    """How a stance is recorded into ``rec``, and its first row: ``(on a grid, at each
    step, rows used, overflow)`` (no recording if ``rec`` has no rows)."""
    if rec.shape[0] == 0:
        return False, False, 0, 0.0
    nrec, overflow = append_row(rec, 0, 0.0, y)
    return rec_dt > 0.0, rec_dt <= 0.0, nrec, overflow


@njit(**_INLINE)
def stance_begin(P, O, method, y, K, gv, ytmp):
    """The stance's start at ``y``: ``(status, h)``, its event values into ``gv``,
    ``K[0] = f(y)``; ``status`` from :func:`touchdown_fall`, ``h`` the first step
    (``O_H0``, or estimated if that is 0 and the stance goes on)."""
    event_values(P, y, gv)
    rhs(P, y, K[0])
    status = touchdown_fall(gv, y)
    h = O[O_H0]
    if h <= 0.0 and status == ST_OK:
        h = initial_step(P, method, y, K[0], O[O_RTOL], O[O_ATOL], ytmp, K[1])
    return status, h


@njit(**_INLINE)
def advance(method, y, ynew, K, gv_old, gv_new):
    """Move on to the accepted step's end: ``y``, its ``f`` (FSAL) and event values."""
    ns = _rk.n_stages(method)
    for i in range(NSTATE):
        y[i] = ynew[i]
        K[0, i] = K[ns, i]
    for i in range(NEVENTS):
        gv_old[i] = gv_new[i]


@njit(**_INLINE)
def copy_state(y, src):
    """``y[:] = src[:NSTATE]`` (a loop: a slice assignment costs numba more to compile)."""
    for i in range(NSTATE):
        y[i] = src[i]


@njit(**_INLINE)
def finite(y):
    """Whether every component of the state ``y`` is finite."""
    for i in range(NSTATE):
        if not math.isfinite(y[i]):
            return False
    return True


#: The length of :func:`work_arrays`' one allocation (its offsets are written out for
#: six states and five events).
NWORK = 3 * NSTATE + 3 * NEVENTS + 5 + 5 + (_rk.NK + _rk.NR) * NSTATE + 19
assert (NSTATE, NEVENTS) == (6, 5), "work_arrays' offsets"


@njit(**_INLINE)
def work_arrays():
    """A stride's work arrays as views of one allocation: ``(y, ynew, ytmp, gv_old, gv_new,
    gv_tmp, st, stats, K, R, scratch)`` (``scratch``: :func:`stride_finish`'s 19).

    numba puts each array on the heap; thirteen of them (malloc, free and their
    reference counts) cost a Table 6.1 stride about 0.2 us of its 9.5 (measured apart:
    13 small arrays 200-300 ns, one cut into views 70-90 ns)."""
    W = np.empty(NWORK)
    y, ynew, ytmp = W[0:6], W[6:12], W[12:18]  # NSTATE each
    gv_old, gv_new, gv_tmp = W[18:23], W[23:28], W[28:33]  # NEVENTS each
    st, stats = W[33:38], W[38:43]
    a = 43 + _rk.NK * NSTATE
    K = W[43:a].reshape((_rk.NK, NSTATE))
    R = W[a:a + _rk.NR * NSTATE].reshape((_rk.NR, NSTATE))
    a += _rk.NR * NSTATE
    return y, ynew, ytmp, gv_old, gv_new, gv_tmp, st, stats, K, R, W[a:a + 19]


def _make_stride(fly: bool) -> Callable:
    def stride(P, O, td, tx, th, rec, rec_dt, out):
        """One stride from the touch-down state ``td`` (7) to the next, with the Runge-Kutta
        pair ``O[O_METHOD]``.

        With leg thrust (``P[P_THRUST] > 0``) the stance runs on a copy of ``P``
        whose rest length switches at the first ``ldot`` crossing from < 0 to >= 0
        (event 4, :func:`thrust_switch`; its time since touch-down in ``OUT_TSW``);
        without, on ``P`` itself, and no switch is looked for.

        Fills ``out`` (layout ``OUT_*`` in ``_pack``) and returns the status.
        Without ``fly``, the stance alone from the stance state ``td`` (6): ``out``
        receives the final state and ``stats`` (below), and nothing else runs.

        The stance (thesis Section 2.3): a stance that starts with the hip at the
        ground, ``xdot_m < 0`` or the leg lengthening ends at once with that fall
        (:func:`touchdown_fall`). Otherwise each pass of the loop takes one
        Runge-Kutta step and either rejects it (error control: a smaller step; or,
        for a first step, that it jumped a whole hump of an event function that
        started at its zero: :func:`._stepper.rising_from_zero`) or
        accepts it, looks for the sign changes of the event functions over it
        (lift-off, eq. 2.8; falls, eqs 2.10-2.11), locates the earliest on the
        step's dense output, and then ends the stance with one exact step to that
        event (a full-order event state), or moves on to the next step.

        If it has rows, ``rec`` (rows x NREC) receives ``t, y``: at each accepted
        step if ``rec_dt <= 0``, else on a uniform grid of spacing ``rec_dt`` from
        the dense output; without, ``rec`` and ``rec_dt`` are not read. The forces
        are derived from those rows when read (``._record.stance_forces``): with
        the switched rest length from the switch on, which a row at each step
        records at ``t >= OUT_TSW`` (the switch's own row is written after it) and
        a grid row at ``t > OUT_TSW`` (the grid up to the switch is sampled from the
        step before it). ``stats`` = ``[t_end, n_accepted, n_rejected, n_recorded,
        overflow]``.
        """
        y, ynew, ytmp, gv_old, gv_new, gv_tmp, st, stats, K, R, scratch = work_arrays()
        method = int(O[O_METHOD])
        P0 = P
        P = working_params(P0)
        if fly:
            xf = stride_start(P, td, y, out)
        else:
            xf = 0.0
            copy_state(y, td)
        rtol = O[O_RTOL]
        atol = O[O_ATOL]
        on_grid, at_steps, nrec, overflow = record_start(rec, rec_dt, y)
        t = 0.0
        t_next_rec = rec_dt
        status, h = stance_begin(P, O, method, y, K, gv_old, ytmp)
        # events that left their zero upward, until the first step is accepted (retry_step)
        rising = rising_from_zero(P, y, K[0], h, gv_old, ytmp, gv_tmp)
        n_acc = 0
        n_rej = 0
        last_rejected = False
        ev = -1  # the first event of the last accepted step, once located
        ended = status != ST_OK
        while not ended:
            if ev < 0:
                status = step_guard(O, n_acc + n_rej, t, h)
                if status != ST_OK:
                    break
            if ev < 0 or h > 0.0:
                # one Runge-Kutta step (the one loop holds the stage arithmetic once),
                # with the event values at its end
                rk_step(P, method, y, h, K, ytmp, ynew, gv_new)
            if ev >= 0:
                t = step_to_event(y, ynew, t, h)
                if ev == EV_THRUST:  # the stance goes on from the thrust's switch
                    h = thrust_switch(P, O, method, y, K, gv_old, ytmp, fly, t, out)
                    rising = rising_from_zero(P, y, K[0], h, gv_old, ytmp, gv_tmp)
                    ev = -1
                    last_rejected = False
                else:  # the stance ends
                    status = event_status(ev)
                    ended = True
            else:
                # error control
                err = _rk.error_norm(method, NSTATE, y, ynew, h, K, rtol, atol)
                h_retry = retry_step(method, h, err, rising, gv_new)
                if h_retry > 0.0:
                    h = h_retry
                    n_rej += 1
                    last_rejected = True
                    continue
                rising = 0
                n_acc += 1
                # event detection, dense output, event location (and grid samples)
                event = crossed(gv_old, gv_new)
                # the dense output, written out here: an inlined dense_output(P, method, y,
                # ynew, h, K, R, ytmp), its loop over dop853's extra stages of a run-time
                # length, kept numba's atomic reference counts of its six array arguments
                # at every step of a recorded stance (recording a Table 6.1 stride: 13,500
                # instructions more than an unrecorded one with them, 11,600 without;
                # callgrind as in _stepper.record_grid)
                if event or on_grid:
                    ns = _rk.n_stages(method)
                    for s in range(ns + 1, ns + 1 + _rk.n_extra(method)):
                        stage_input(method, y, h, K, s, ytmp)
                        rhs(P, ytmp, K[s])
                    _rk.dense_coeffs_inline(method, y, ynew, h, K, R)
                theta_ev, ev = (first_event(P, method, R, gv_old, gv_new, ytmp, gv_tmp, st)
                                if event else (2.0, -1))
                if on_grid:
                    nrec, t_next_rec, ovf = record_grid(method, R, rec, nrec, t, h,
                                                        t + h * min(theta_ev, 1.0),
                                                        t_next_rec, rec_dt)
                    overflow = max(overflow, ovf)
                if ev >= 0:
                    h *= theta_ev  # the next pass steps to the event
                    continue
                t += h
                advance(method, y, ynew, K, gv_old, gv_new)
                h = grow_step(method, h, err, last_rejected)
                last_rejected = False
            if not finite(y):
                status = ST_ERR_NONFINITE
                ended = True
            if at_steps:
                nrec, ovf = append_row(rec, nrec, t, y)
                overflow = max(overflow, ovf)
        nrec, ovf = record_close(rec, nrec, t, y, on_grid, status)  # the lift-off row
        overflow = max(overflow, ovf)
        stats[0] = t
        stats[1] = n_acc
        stats[2] = n_rej
        stats[3] = nrec
        stats[4] = overflow
        if fly:
            return stride_finish(P0, O, status, td, xf, y, stats, tx, th, out, scratch)
        stance_out(y, stats, out)
        return status

    # one name per copy: numba names a compiled function after its __qualname__ and a
    # counter that restarts in every process, and of two cached libraries exporting one
    # symbol the first loaded serves both (tests/simulation/test_kernel_variants.py)
    stride.__name__ = stride.__qualname__ = "stride" if fly else "stance_rec"
    return njit(**_JIT)(stride)


#: ``(P, O, td, tx, th, rec, rec_dt, out) -> status``: one stride from the touch-down state
#: ``td`` (7), with the pair ``O[O_METHOD]``, recording the stance into ``rec`` if it has rows.
stride = _make_stride(True)
#: ``(P, O, y0, _, _, rec, rec_dt, out) -> status``: the stance alone from ``y0``, recorded
#: into ``rec``; ``out`` (11) receives the final state and the stats (for the tests)
stance_rec = _make_stride(False)


@njit(**_JIT)
def section_map(P, O, beta, phi, xd, yd, phid, h, out):
    """The Poincare map's stride (``tslip.step_map``, the analyses' ``_packed.stride_map``):
    from the section ``(beta, phi, xd, yd, phid)`` just after touch-down at ``x = 0``
    on level ground at height ``h``, nothing recorded; fills ``out``, returns the status.

    The stride kernel's arrays (touch-down state, terrain, empty record) are built
    here, from the section's floats: built in Python (NumPy arrays from lists,
    three more arrays for numba to dispatch) they cost about 1 us a map call,
    a tenth of a Table 6.1 stride (``step_map`` 1.33 -> 1.23 times the stride
    kernel, measured side by side with the Python construction).
    """
    W = np.empty(NTD + 1)
    td = W[0:NTD]
    td[0] = beta
    td[1] = phi
    td[2] = xd
    td[3] = yd
    td[4] = phid
    td[5] = 0.0
    td[6] = h
    th = W[NTD:NTD + 1]  # the ground's one segment, at h
    th[0] = h
    tx = W[NTD + 1:]  # no breakpoints
    rec = tx.reshape((0, NREC))  # no rows: nothing recorded
    return stride(P, O, td, tx, th, rec, 0.0, out)


# ---------------------------------------------------------------------------
# Batches: each driver exists twice, a serial loop in the calling thread (small
# batches: waking threads costs more than a row, and under load a sleeping core
# is not free) and a ``prange`` loop over numba's thread pool; ``parallel=True``
# kernels compile only when first used. A row calls the compiled stride.
# ---------------------------------------------------------------------------


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


@njit(**_PAR)
def run_batch(Ps, O, TDs, n_steps, TX, TH, td_hist, status, n_done, t_fall):
    """``n_steps`` strides for each row, in parallel over rows (:func:`run_batch_serial`)."""
    for i in prange(Ps.shape[0]):
        status[i], n_done[i], t_fall[i] = run_row(Ps[i], O, TDs[i], n_steps, TX[i], TH[i],
                                                  td_hist[i])


@njit(**_JIT)
def run_batch_serial(Ps, O, TDs, n_steps, TX, TH, td_hist, status, n_done, t_fall):
    """``n_steps`` strides for each row, in the calling thread. ``Ps`` (n, NP), ``TDs``
    (n, 7), per-row terrain ``TX`` (n, nb) and ``TH`` (n, nb + 1) (pad breakpoints with
    ``+inf``). Writes each row's touch-down states into ``td_hist`` (n, n_steps + 1, 7),
    the final ``status``, the number of completed strides ``n_done`` and the time of the
    fall ``t_fall`` (NaN if none)."""
    for i in range(Ps.shape[0]):
        status[i], n_done[i], t_fall[i] = run_row(Ps[i], O, TDs[i], n_steps, TX[i], TH[i],
                                                  td_hist[i])


@njit(**_PAR)
def stride_batch(Ps, O, TDs, TX, TH, OUTs, status):
    """One stride per row (the batched Poincare map), in parallel over rows
    (:func:`stride_batch_serial`)."""
    no_rec = np.empty((0, NREC))  # zero rows: never written, shared by the threads
    for i in prange(Ps.shape[0]):
        status[i] = stride(Ps[i], O, TDs[i], TX[i], TH[i], no_rec, 0.0, OUTs[i])


@njit(**_JIT)
def stride_batch_serial(Ps, O, TDs, TX, TH, OUTs, status):
    """``(Ps, O, TDs, TX, TH, OUTs, status)``: one stride per row (the batched Poincare
    map) in the calling thread, ``OUTs[i]`` and ``status[i]`` as :func:`stride` fills them."""
    no_rec = np.empty((0, NREC))
    for i in range(Ps.shape[0]):
        status[i] = stride(Ps[i], O, TDs[i], TX[i], TH[i], no_rec, 0.0, OUTs[i])


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(stride, __file__)
