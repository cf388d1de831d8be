"""Compiled switching functions of the biped: contact, controller switches, falls.

Private (see :mod:`._kernels`). An event is a crossing of a switching
function from > 0 to <= 0 (the stride loop in :mod:`._stride` locates it).
The functions taking ``trig`` read the sines and cosines of the state from
it (the right-hand side has just computed them for the end of a step, see
:func:`._tmt.tmt_blocks`); :func:`state_trig` computes them for any other state.
"""

from __future__ import annotations

import math

from numba import njit

from .._kernel_cache import check as _check_cache
from ._contact import foot_state, foot_state_of
from ._jit import FAST
from ._pack import (
    CS_ON_R,
    CS_ZR,
    P_CZ,
    P_KZ,
    P_R1,
    ST_FALL_BACKWARD,
    ST_FALL_HIP,
    ST_FALL_LEG,
    ST_FALL_PITCH,
    ST_OK,
)


@njit(**FAST)
def state_trig(y, trig):
    """``sin, cos`` of ``theta_b`` and of both leg angles of ``y``, as
    :func:`._tmt.tmt_blocks` leaves them in its ``trig``."""
    tb = y[2]
    trig[0] = math.sin(tb)
    trig[1] = math.cos(tb)
    for j in range(2):
        gam = tb + y[3 + 3 * j + 2]
        trig[2 + 2 * j] = math.sin(gam)
        trig[3 + 2 * j] = math.cos(gam)


@njit(**FAST)
def _contact_g(P, cs, leg, z, zd):
    """:func:`event_value` of a foot at height ``z``, vertical speed ``zd``."""
    if cs[CS_ON_R + leg] == 0.0:
        return z
    zt = cs[CS_ZR + 2 * leg]
    fz = P[P_KZ] * (zt - z) - P[P_CZ] * zd
    return min(fz, P[P_KZ] * (zt - z))


@njit(**FAST)
def event_value(P, y, cs, leg):
    """Switching function of a leg: touch-down ``z_f - z_g`` in flight, lift-off
    ``min(F_z, k_z (z_TD - z_f))`` in contact; an event is a crossing from > 0
    to <= 0."""
    x, z, xd, zd = foot_state(P, y, leg)
    return _contact_g(P, cs, leg, z, zd)


@njit(**FAST)
def event_value_trig(P, y, cs, leg, trig):
    """:func:`event_value` given the sines and cosines ``trig`` of ``y``."""
    x, z, xd, zd = foot_state_of(P, y, leg, trig)
    return _contact_g(P, cs, leg, z, zd)


@njit(**FAST)
def fall_check_trig(P, y, cb):
    """:func:`fall_check` given ``cb = cos(theta_b)``."""
    if y[1] + P[P_R1] * cb <= 0.0:
        return ST_FALL_HIP
    if y[9] < 0.0:
        return ST_FALL_BACKWARD
    if abs(y[2]) >= 0.5 * math.pi:
        return ST_FALL_PITCH
    if y[3] <= 0.0 or y[4] <= 0.0 or y[6] <= 0.0 or y[7] <= 0.0:
        return ST_FALL_LEG
    return ST_OK


@njit(**FAST)
def fall_check(P, y):
    """Fall status of a state, or ``ST_OK`` (hip, backward, pitch, leg collapse)."""
    return fall_check_trig(P, y, math.cos(y[2]))


@njit(**FAST)
def fall_value_trig(P, y, cb):
    """:func:`fall_value` given ``cb = cos(theta_b)``."""
    g = y[1] + P[P_R1] * cb
    kind = ST_FALL_HIP
    if y[9] < g:
        g = y[9]
        kind = ST_FALL_BACKWARD
    v = 0.5 * math.pi - abs(y[2])
    if v < g:
        g = v
        kind = ST_FALL_PITCH
    for i in (3, 4, 6, 7):
        if y[i] < g:
            g = y[i]
            kind = ST_FALL_LEG
    return g, kind


@njit(**FAST)
def fall_value(P, y):
    """``(g, status)``: the smallest of the fall margins of :func:`fall_check` (hip
    height, forward speed, pitch to +-pi/2, thigh and shank lengths) and the
    fall it measures; a fall is its crossing to <= 0."""
    return fall_value_trig(P, y, math.cos(y[2]))


# events of a run: contact of each leg, controller switch of each leg, fall
NEVK = 5
K_CTL = 2
K_FALL = 4


@njit(**FAST)
def event_g(P, k, t, y, cs, tsw, trig):
    """Switching function ``k`` at ``(t, y)``: contact (0, 1), controller (2, 3),
    fall (4); ``trig`` the sines and cosines of ``y`` (:func:`state_trig`)."""
    if k < K_CTL:
        return event_value_trig(P, y, cs, k, trig)
    if k < K_FALL:
        return tsw[k - K_CTL] - t
    return fall_value_trig(P, y, trig[1])[0]


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(fall_value, __file__)
