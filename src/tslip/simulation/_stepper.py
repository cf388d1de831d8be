"""The stance integrator's steps: the :mod:`._rk` stage loop with the stance ``rhs``, events.

Private (see :mod:`._kernels`). The stride kernel (:func:`._stride.stride`)
is the loop; its named steps are here, in the order a step takes them:

* :func:`rk_step`: one Runge-Kutta step (the stages, FSAL);
* :func:`shrink_step` / :func:`grow_step`: error control, the next step size
  after a rejected / an accepted step; :func:`retry_step`: whether a step is
  rejected, by its error or, for a stance's first step, by a jumped hump;
* :func:`crossed`: event detection, a sign change of an event function
  (thesis Section 2.3) over the accepted step; :func:`rising_from_zero`: no first
  step of a stance jumps a whole hump of an event function that starts at its zero;
* :func:`first_event`: event location, the earliest root on the dense output;
* :func:`record_row`, :func:`append_row`, :func:`record_grid`: the stance record.

The per-step functions are small and ``inline="always"``, taking the
Runge-Kutta pair ``method`` as a run-time argument (the stride reads it from its
options), so the one compiled stride serves both pairs; :func:`stage_input` keeps the
stage sums in registers. Those called once a stride or so (:func:`initial_step`,
:func:`first_event`, :func:`append_row`) compile on their own instead: numba's type
inference of the stride's body, most of a cold start, shrinks by their copies.
:func:`record_grid`, called at every accepted step of a recorded stance, is inlined
(its call cost more than its copy's compilation: see there). The step-control
constants (:data:`FAC_MAX`, :data:`NONFINITE_SHRINK`, the root's :data:`ROOT_TOL`, ...)
are named below, the safety factor and smallest factor in :mod:`._rk`.
"""

from __future__ import annotations

import math

from numba import njit

from .._kernel_cache import check as _check_cache
from . import _rk
from ._rk import _INLINE, _JIT
from ._stance import (
    EV_BACKWARD,
    EV_COLLAPSE,
    EV_HIP_GROUND,
    EV_LIFTOFF,
    EV_THRUST,
    NEVENTS,
    NSTATE,
    event_values,
    rhs,
    rhs_events_inline,
    rhs_inline,
)

#: The largest step-size factor after an accepted step (dopri5.f's default ``fac2``): a step
#: grows at most tenfold, so that one lucky error estimate cannot jump past the
#: stance's features (a rejected step's factor is below ``_rk.SAFETY`` anyway)
FAC_MAX = 10.0
#: The factor by which a step whose error is not finite (a NaN or infinite stage) is
#: retried shorter: its error estimate says nothing about the size to take
NONFINITE_SHRINK = 0.1
#: The width in theta (the fraction of the step) to which an event's root is located:
#: a few ulps of theta in [0, 1], so the event state is as exact as the step allows
ROOT_TOL = 1e-15
#: The most Illinois iterations for one root (it converges superlinearly: a bound only)
ROOT_MAXITER = 100
#: How much earlier (in theta) another event must be to win over one found before it in
#: :data:`EVENT_ORDER`: ``F_y = F_l sin(beta)`` and the hip height ``l sin(beta)``
#: vanish together when ``beta`` reaches 0, and their roots differ by rounding only
EVENT_TIE = 1e-9
#: The order in which :func:`first_event` searches the events: falls first, then
#: lift-off, the thrust's switch last (a tie within EVENT_TIE goes to the earlier here)
EVENT_ORDER = (EV_HIP_GROUND, EV_COLLAPSE, EV_BACKWARD, EV_LIFTOFF, EV_THRUST)


assert NSTATE == 6, "stage_input's accumulators"


@njit(**_INLINE)
def stage_input(method, y, h, K, s, out):
    """:func:`._rk.stage_state` for the stance's six states: ``out = y + h sum_{j<s} a_sj
    K[j]``, the same sums in the same order, accumulated in six local variables.

    The stride's arrays are views of one allocation (:func:`._stride.work_arrays`), so the
    compiler cannot tell ``out`` from ``K`` and would store and reload ``out`` after every
    term; locals stay in registers. With the pair a run-time value (one kernel for both),
    this recovers what its loops over the tableau lost against a compile-time pair
    (callgrind figures in :mod:`._stride`)."""
    a = _rk.A_TAB[method, s]
    o0 = o1 = o2 = o3 = o4 = o5 = 0.0
    for j in range(s):  # row by row, skipping zeros, as _rk.stage_state
        aj = a[j]
        if aj != 0.0:
            o0 += aj * K[j, 0]
            o1 += aj * K[j, 1]
            o2 += aj * K[j, 2]
            o3 += aj * K[j, 3]
            o4 += aj * K[j, 4]
            o5 += aj * K[j, 5]
    out[0] = y[0] + h * o0
    out[1] = y[1] + h * o1
    out[2] = y[2] + h * o2
    out[3] = y[3] + h * o3
    out[4] = y[4] + h * o4
    out[5] = y[5] + h * o5


@njit(**_INLINE)
def rk_step(P, method, y, h, K, ytmp, ynew, gv):
    """One step of size ``h`` from ``y`` with ``K[0] = f(y)`` (see :mod:`._rk`).

    Fills the stages ``K[1..ns]`` and ``ynew``; ``K[ns] = f(ynew)`` (FSAL), and the
    event values at ``ynew`` into ``gv`` (event detection needs them once the step is
    accepted; they share the last stage's sines and cosines). ``method`` is a run-time
    value: the stages are inlined into the stride's loop, the pair's tableau read row by
    row (:func:`stage_input`).
    """
    ns = _rk.n_stages(method)
    for s in range(1, ns):
        stage_input(method, y, h, K, s, ytmp)
        rhs_inline(P, ytmp, K[s])
    stage_input(method, y, h, K, ns, ynew)
    rhs_events_inline(P, ynew, K[ns], gv)


@njit(**_JIT)
def initial_step(P, method, y, f0, rtol, atol, ytmp, f1):
    """Starting step size (Hairer, Norsett & Wanner, II.4)."""
    h0, d1 = _rk.initial_probe(y, f0, rtol, atol, ytmp)
    rhs(P, ytmp, f1)
    return _rk.initial_step(method, y, f0, f1, h0, d1, rtol, atol)


@njit(**_INLINE)
def event_root(P, method, R, ev, g_lo, g_hi, ytmp, gv, st):
    """Root in theta of event ``ev`` on the dense output (Illinois method)."""
    _rk.root_start_inline(st, g_lo, g_hi)
    for _ in range(ROOT_MAXITER):
        c = _rk.root_guess_inline(st)
        _rk.dense_eval_inline(method, R, c, ytmp)
        event_values(P, ytmp, gv)
        if _rk.root_update_inline(st, c, gv[ev], ROOT_TOL):
            break
    return st[1]  # the earliest theta known to be at or past the crossing


@njit(**_INLINE)
def shrink_step(method, h, err):
    """The step size after a rejected step (error ``err`` > 1 or not finite): a NaN or
    infinite stage shrinks it by NONFINITE_SHRINK, else :func:`._rk.step_factor`."""
    if not math.isfinite(err):
        return h * NONFINITE_SHRINK
    return h * _rk.step_factor(method, err, FAC_MAX)


@njit(**_INLINE)
def retry_step(method, h, err, rising, gv_new):
    """The size to retry the step just taken with, or 0.0 if it is accepted: a step whose
    error ``err`` is above 1 (or not finite) is retried shorter (:func:`shrink_step`), and
    so is a stance's first step that ends with an event of the mask ``rising``
    (:func:`rising_from_zero`) at or below zero again: it jumped a whole hump of it, and is
    retried ``HUMP_SHRINK`` times as long. (The mask is an integer, not an array, so that
    the stride's loop pays one comparison a step for it: a call with the event arrays in
    the loop cost a Table 6.1 stride 2.9 % more instructions, the mask 0.3 %: callgrind,
    20000 strides against the revision before it.)"""
    if not err <= 1.0:
        return shrink_step(method, h, err)
    if rising != 0:
        for ev in range(NEVENTS):
            if (rising >> ev) & 1 and gv_new[ev] <= 0.0:
                return h * _rk.HUMP_SHRINK
    return 0.0


@njit(**_INLINE)
def grow_step(method, h, err, last_rejected):
    """The step size after an accepted step; it does not grow right after a rejection."""
    fac = _rk.step_factor(method, err, FAC_MAX)
    if last_rejected:
        fac = min(1.0, fac)
    return h * fac


@njit(**_JIT)
def rising_from_zero(P, y, f, h, gv_old, ytmp, gv_tmp):
    """The events that leave their zero upward at the start ``y`` of a stance (or of its
    part after the thrust's switch), as a bit mask for :func:`retry_step` (bit ``ev``): 0,
    without a probe, when every event starts above zero (the usual case); else those that
    :func:`._rk.left_zero_upward` from their values at ``y + ZERO_PROBE h f(y)``
    (``f = f(y)``, ``h`` the first step).

    The lift-off event starts exactly at 0 whenever the leg force vanishes at touch-down
    (an undamped leg, no hip torque: ``F_y`` at rest length, or ``l_rest - l`` of
    :func:`._stance.liftoff_on_spring`); after a near-vertical touch-down its whole hump
    of ``F_y > 0`` can be far shorter than the first step, which then ends with ``F_y <= 0``
    again: no crossing from > 0, the lift-off never seen, a false fall. Compiled on its
    own: it runs once a stance, and only when an event starts at or below zero.
    """
    at_zero = False
    for ev in range(NEVENTS):
        at_zero = at_zero or gv_old[ev] <= 0.0
    if not at_zero:
        return 0
    d = _rk.ZERO_PROBE * h
    for i in range(NSTATE):
        ytmp[i] = y[i] + d * f[i]
    event_values(P, ytmp, gv_tmp)
    mask = 0
    for ev in range(NEVENTS):
        if _rk.left_zero_upward(gv_old[ev], gv_tmp[ev]):
            mask |= 1 << ev
    return mask


@njit(**_INLINE)
def crossed(gv_old, gv_new):
    """Whether an event function went from > 0 to <= 0 over the step (events fire so)."""
    for ev in range(NEVENTS):
        if gv_old[ev] > 0.0 and gv_new[ev] <= 0.0:
            return True
    return False


@njit(**_JIT)
def first_event(P, method, R, gv_old, gv_new, ytmp, gv_tmp, st):
    """The earliest event in the step with dense output ``R``: ``(theta, ev)``.

    ``theta`` is the fraction of the step at which event ``ev`` fires, ``(2.0, -1)``
    if none does. The events are searched in :data:`EVENT_ORDER` (falls first), and a
    later one wins only if earlier by :data:`EVENT_TIE`.
    """
    theta_ev = 2.0
    first = -1
    for j in range(NEVENTS):
        ev = EVENT_ORDER[j]
        if gv_old[ev] > 0.0 and gv_new[ev] <= 0.0:
            theta = event_root(P, method, R, ev, gv_old[ev], gv_new[ev], ytmp, gv_tmp, st)
            if theta < theta_ev - EVENT_TIE:
                theta_ev = theta
                first = ev
    return theta_ev, first


@njit(**_INLINE)
def record_row(rec, row, t, y):
    """Stance record row ``row``: ``t, y`` (the forces are derived from it when read:
    :func:`._record.fill_table`, :func:`._record.stance_forces`).

    Inlined into :func:`append_row` (seven stores: a call per sample cost more than the
    row); :func:`record_grid` writes its rows itself."""
    rec[row, 0] = t
    for i in range(NSTATE):
        rec[row, 1 + i] = y[i]


@njit(**_JIT)
def append_row(rec, row, t, y):
    """Record row ``row`` if ``rec`` has room: ``(rows used, 1.0 if it had none else 0.0)``."""
    if row < rec.shape[0]:
        record_row(rec, row, t, y)
        return row + 1, 0.0
    return row, 1.0


@njit(**_INLINE)
def record_grid(method, R, rec, row, t, h, t_stop, t_next, dt):
    """Record the grid times ``t_next, t_next + dt, ...`` up to ``t_stop`` of the step
    ``[t, t + h]`` from its dense output ``R``: ``(rows used, next grid time, overflow)``.

    Inlined into the stride, with one branch on the pair outside the loop over the rows
    (:func:`_record_grid_of`). Recording cost a Table 6.1 stride (dopri5, ``dt = 0.01``:
    59 grid rows over 23 steps) 16,970 instructions more than a stride not recorded
    while this compiled on its own, its dense output read through ``dense_eval`` into
    ``ytmp`` and copied row by row; 14,250 inlined, 13,500 written straight into ``rec``,
    11,600 since the stride writes its dense output out itself (callgrind,
    ``NUMBA_CPU_NAME=generic``, ``record_run`` against ``run_batch``, the difference of
    runs of 1000 and 500 strides; 07e68e4, one kernel per pair: 11,190). Inlined, a
    first ``simulate`` from an empty cache took 29.1 s of CPU, not 28.4 (one run each,
    a loaded machine)."""
    if method == _rk.M_DOPRI5:
        return _record_grid_of(5, R, rec, row, t, h, t_stop, t_next, dt)
    return _record_grid_of(8, R, rec, row, t, h, t_stop, t_next, dt)


@njit(**_INLINE)
def _record_grid_of(nd, R, rec, row, t, h, t_stop, t_next, dt):
    """:func:`record_grid` with ``nd`` dense rows (a constant: the loop over them unrolls).

    Each row is :func:`._rk.dense_eval`'s sum (the same operations in the same order),
    written straight into ``rec``, not through ``ytmp`` and a copy of it."""
    while t_next <= t_stop:
        if row >= rec.shape[0]:
            return row, t_next, 1.0
        theta = (t_next - t) / h
        t1 = 1.0 - theta
        rec[row, 0] = t_next
        for i in range(NSTATE):
            acc = R[nd - 1, i]
            for k in range(nd - 2, -1, -1):
                acc = R[k, i] + (theta if k % 2 == 0 else t1) * acc
            rec[row, 1 + i] = acc
        row += 1
        t_next += dt
    return row, t_next, 0.0


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(append_row, __file__)
