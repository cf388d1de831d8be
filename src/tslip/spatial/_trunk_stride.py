# mypy: ignore-errors
# (numba kernels are checked by numba, not mypy: pyproject.toml's [tool.mypy] note)
"""The 3-D TSLIP's whole stride as one compiled kernel: touch-down -> stance -> flight.

Private (issue 43, Part 2; the model in :mod:`tslip.spatial.trunk`, the phases in
:mod:`._trunk_kernels`). :func:`stride` takes the touch-down state and returns the
next touch-down and the status, as the planar TSLIP's stride kernel does
(:func:`tslip.simulation._stride.stride`): the touch-down's falls, the stance
(resumed after the leg thrust's switch), the lift-off checks, the flight and the
new foot, with no Python between the phases (the Python glue between them cost
about twice the phases themselves). One loop, :func:`._trunk_kernels.phase_loop`,
integrates both phases, the Runge-Kutta pair read at run time from the options
(``O[O_METHOD]``, issue 41's rule), on one work array a stride.

The statuses (:class:`tslip.spatial.trunk.TrunkStatus`) are decided here in this
order: at the touch-down (:func:`touchdown_fall`) the foot across the body's
mid-plane, the hip at or below the ground, moving backward, the leg lengthening;
then the stance's own (:func:`._trunk_kernels.run_phase`); at lift-off moving
backward; the flight's; at the new touch-down the foot across the mid-plane.

Output ``out`` (:data:`NSOUT`): status, stance and flight durations, accepted steps,
stance rows recorded, the lift-off state (13; NaN if the stance failed), the next
touch-down state (13; NaN unless the flight reached it) and its foot (3).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._kernel_cache import check as _check_cache
from ..model._pack import O_TMAX_FLIGHT, O_TMAX_STANCE
from ..simulation._rk import _INLINE, _JIT
from ._trunk_kernels import (
    FLIGHT,
    NOUT,
    NSTATE,
    NWORK,
    OUT_NREC,
    OUT_NSTEP,
    OUT_T,
    OUT_Y,
    P_APEX,
    P_FOOT,
    P_G,
    P_L0,
    P_LREST,
    P_PENDING,
    P_R,
    P_SIDE,
    P_TA,
    P_THRUST,
    ST_FALL_BACKWARD,
    ST_FALL_CROSSED_LEG,
    ST_FALL_HIP_GROUND,
    ST_FALL_LENGTHENING,
    ST_OK,
    ST_SWITCH,
    STANCE,
    leg_direction,
    phase_loop,
    rotation,
    stance_terms,
)

#: Layout of :func:`stride`'s ``out``
S_STATUS, S_TS, S_TF, S_NSTEP, S_NREC = range(5)
S_LO = 5
S_TD = S_LO + NSTATE
S_FOOT = S_TD + NSTATE
NSOUT = S_FOOT + 3


@njit(**_INLINE)
def heading(R):
    """The trunk's horizontal heading ``h`` (``x_b`` projected on the ground, unit):
    its ``(x, z)`` components."""
    hn = math.hypot(R[0, 0], R[2, 0])
    return R[0, 0] / hn, R[2, 0] / hn


@njit(**_INLINE)
def crossed(side, p0, p2, c0, c2, h0, h2):
    """The foot ``p`` on the far side of the body's mid-plane from its leg:
    ``s (p - c) . n < 0`` with ``n = h x e_y`` (:mod:`tslip.spatial.trunk`)."""
    return side * (-(p0 - c0) * h2 + (p2 - c2) * h0) < 0.0


@njit(**_JIT)
def touchdown_fall(P, y, R, o):
    """The fall a stance starts in, else ``ST_OK``: in this order the foot
    (``P[P_FOOT:]``) across the mid-plane, the hip at or below the ground, moving
    backward (``v . h < 0``), the leg lengthening (``ldot > 0``). ``R`` (3 x 3) and
    ``o`` (16) are scratch."""
    rotation(y, R)
    h0, h2 = heading(R)
    if crossed(P[P_SIDE], P[P_FOOT], P[P_FOOT + 2], y[0], y[2], h0, h2):
        return ST_FALL_CROSSED_LEG
    if y[1] + P[P_R] * R[1, 1] <= 0.0:
        return ST_FALL_HIP_GROUND
    if y[3] * h0 + y[5] * h2 < 0.0:
        return ST_FALL_BACKWARD
    stance_terms(P, y, R, o)
    if o[10] > 0.0:
        return ST_FALL_LENGTHENING
    return ST_OK


@njit(**_INLINE)
def normalise(y):
    """The quaternion ``y[6:10]`` to unit length (between phases)."""
    n = math.sqrt(y[6] * y[6] + y[7] * y[7] + y[8] * y[8] + y[9] * y[9])
    for i in range(6, 10):
        y[i] /= n


@njit(**_JIT)
def stance(P, O, y, rec, W, ph, out):
    """The stance from ``y`` (in place: its end state, quaternion normalised) on the
    parameters ``P`` (changed: the thrust's switch), resumed after the switch with the
    switched rest length; the rows into ``rec``. Returns the status; the duration, the
    steps and rows into ``out``."""
    t = 0.0
    nsteps = 0
    nrec = 0
    while True:
        status = phase_loop(P, O, STANCE, y, O[O_TMAX_STANCE] - t, ph, rec, nrec, t, W)
        nrec += int(ph[OUT_NREC])
        t += ph[OUT_T]
        nsteps += int(ph[OUT_NSTEP])
        for i in range(NSTATE):
            y[i] = ph[OUT_Y + i]
        if status != ST_SWITCH:
            break
        P[P_LREST] = P[P_L0] * (1.0 + P[P_THRUST])
        P[P_PENDING] = 0.0
    normalise(y)
    out[S_TS] = t
    out[S_NSTEP] = nsteps
    out[S_NREC] = nrec
    return status


@njit(**_JIT)
def flight(P, O, y, W, R, ph, out):
    """The flight from the lift-off state ``y`` (unit quaternion) on the parameters
    ``P`` of the landing leg (its retraction clock set here); the touch-down state and
    foot into ``out``. Returns the status."""
    vy = y[4]
    P[P_TA] = vy / P[P_G] if (P[P_APEX] != 0.0 and vy > 0.0) else 0.0
    status = phase_loop(P, O, FLIGHT, y, O[O_TMAX_FLIGHT], ph, W[0:0].reshape((0, 1 + NSTATE)),
                        0, 0.0, W)
    tf = ph[OUT_T]
    out[S_TF] = tf
    out[S_NSTEP] += ph[OUT_NSTEP]
    if status != ST_OK:
        return status
    ytd = out[S_TD:S_TD + NSTATE]
    for i in range(NSTATE):
        ytd[i] = ph[OUT_Y + i]
    normalise(ytd)
    rotation(ytd, R)
    d = ph[0:3]
    leg_direction(P, R, tf, d)
    r, l0 = P[P_R], P[P_L0]
    for i in range(3):
        out[S_FOOT + i] = (ytd[i] + r * R[i, 1]) + l0 * (R[i, 0] * d[0] + R[i, 1] * d[1]
                                                         + R[i, 2] * d[2])
    out[S_FOOT + 1] = 0.0  # on the ground: the event located it there to the root's tolerance
    h0, h2 = heading(R)
    if crossed(P[P_SIDE], out[S_FOOT], out[S_FOOT + 2], ytd[0], ytd[2], h0, h2):
        return ST_FALL_CROSSED_LEG
    return ST_OK


@njit(**_JIT)
def stride(P, O, y0, foot, fly, rec, out):
    """One stride from the touch-down ``y0`` (13, unit quaternion) with the foot ``foot``
    (3) of the leg ``P[P_SIDE]`` (``P``: :meth:`~tslip.spatial.trunk_parameters.TrunkParams.packed`
    for that side; not changed) to the other leg's touch-down; returns the status and
    fills ``out`` (module docstring). ``rec`` (rows x 14, may have none) receives the
    stance's ``(t, y)`` at its start and each accepted step (the thrust's switch starts
    a row too). Without ``fly``, the stance alone from ``y0``: no touch-down falls are
    looked for and ``out[S_LO:]`` holds its end state whatever its status."""
    for i in range(NSOUT):
        out[i] = math.nan
    out[S_TS] = 0.0
    out[S_TF] = 0.0
    out[S_NSTEP] = 0.0
    out[S_NREC] = 0.0
    W = np.empty(NWORK + 2 * P.shape[0] + NOUT + 9)
    Ps = W[NWORK:NWORK + P.shape[0]]
    Pf = W[NWORK + P.shape[0]:NWORK + 2 * P.shape[0]]
    a = NWORK + 2 * P.shape[0]
    ph = W[a:a + NOUT]
    R = W[a + NOUT:a + NOUT + 9].reshape((3, 3))
    for i in range(P.shape[0]):
        Ps[i] = P[i]
        Pf[i] = P[i]
    for i in range(3):
        Ps[P_FOOT + i] = foot[i]
    y = out[S_LO:S_LO + NSTATE]
    if fly:
        status = touchdown_fall(Ps, y0, R, ph)
        if status != ST_OK:
            out[S_STATUS] = status
            return status
    for i in range(NSTATE):
        y[i] = y0[i]
    status = stance(Ps, O, y, rec, W, ph, out)
    if fly and status == ST_OK:
        rotation(y, R)
        h0, h2 = heading(R)
        if y[3] * h0 + y[5] * h2 < 0.0:
            status = ST_FALL_BACKWARD
        else:
            Pf[P_SIDE] = -P[P_SIDE]
            status = flight(Pf, O, y, W, R, ph, out)
    elif fly:
        for i in range(NSTATE):
            y[i] = math.nan
    out[S_STATUS] = status
    return status


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(stride, __file__)
