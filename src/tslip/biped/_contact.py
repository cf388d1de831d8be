"""Compiled ground contact of the biped: foot state and the spring-damper law (eqs E.23-E.24).

Private (see :mod:`._kernels`).
"""

from __future__ import annotations

import math

from numba import njit

from .._kernel_cache import check as _check_cache
from ._jit import FAST, INLINE
from ._pack import (
    CS_ON_R,
    CS_XR,
    CS_ZR,
    EV_LO_R,
    EV_TD_R,
    P_CONTACT,
    P_CX,
    P_CZ,
    P_KX,
    P_KZ,
    P_R1,
)


@njit(**INLINE)
def foot_state_trig(P, y, leg, sb, cb, sg, cg):
    """:func:`foot_state` given ``sin, cos`` of ``theta_b`` and of the leg angle."""
    r1 = P[P_R1]
    tbd = y[11]
    b = 3 + 3 * leg
    s = y[b] + y[b + 1]
    sd = y[9 + b] + y[9 + b + 1]
    gd = tbd + y[9 + b + 2]
    x = y[0] + r1 * sb - s * sg
    z = y[1] + r1 * cb - s * cg
    xd = y[9] + r1 * cb * tbd - sd * sg - s * cg * gd
    zd = y[10] - r1 * sb * tbd - sd * cg + s * sg * gd
    return x, z, xd, zd


@njit(**FAST)
def foot_state(P, y, leg):
    """Foot position and velocity ``(x, z, xd, zd)`` of a leg (eq. E.8)."""
    gam = y[2] + y[3 + 3 * leg + 2]
    return foot_state_trig(P, y, leg, math.sin(y[2]), math.cos(y[2]), math.sin(gam),
                           math.cos(gam))


@njit(**FAST)
def foot_state_of(P, y, leg, trig):
    """:func:`foot_state` with the sines and cosines ``trig`` of :func:`._tmt.tmt_blocks`."""
    return foot_state_trig(P, y, leg, trig[0], trig[1], trig[2 + 2 * leg], trig[3 + 2 * leg])


@njit(**FAST)
def contact_force(P, y, cs, leg, clamp):
    """``(F_x, F_z, F_z_raw)`` of a foot in contact (eqs E.23-E.24).

    With ``clamp`` the force is zero unless the foot pushes (eq. E.23); without,
    the spring-damper law holds throughout the contact, the smooth continuation
    the integrator steps with until the lift-off event ends the contact.
    """
    if P[P_CONTACT] == 0.0 or cs[CS_ON_R + leg] == 0.0:
        return 0.0, 0.0, 0.0
    return contact_law(P, foot_state(P, y, leg), cs, leg, clamp)


@njit(**FAST)
def contact_force_trig(P, y, cs, leg, clamp, trig):
    """:func:`contact_force` with the sines and cosines ``trig`` of the state."""
    if P[P_CONTACT] == 0.0 or cs[CS_ON_R + leg] == 0.0:
        return 0.0, 0.0, 0.0
    return contact_law(P, foot_state_of(P, y, leg, trig), cs, leg, clamp)


@njit(**INLINE)
def contact_law(P, foot, cs, leg, clamp):
    """Eqs E.23-E.24 for the foot state ``foot = (x, z, xd, zd)`` (see :func:`contact_force`)."""
    x, z, xd, zd = foot
    xt = cs[CS_XR + 2 * leg]
    zt = cs[CS_ZR + 2 * leg]
    fz = P[P_KZ] * (zt - z) - P[P_CZ] * zd
    if not clamp or (fz > 0.0 and z <= zt):
        return P[P_KX] * (xt - x) - P[P_CX] * xd, fz, fz
    return 0.0, 0.0, fz


@njit(**INLINE)
def contact_switch(P, y, cs, leg, trig):
    """Touch-down or lift-off of a leg at its located event: ``(kind, x_f, z_f)``.

    A foot in flight touches down: the contact starts, anchored at the foot's
    ``x_f`` on the ground (``x_f,TD`` and ``z_f,TD = 0`` of eqs E.23-E.24); a
    foot in contact lifts off. ``kind`` is ``EV_TD_R + leg`` or ``EV_LO_R + leg``;
    ``trig`` holds the sines and cosines of ``y`` (:func:`foot_state_of`).
    """
    x, z, _, _ = foot_state_of(P, y, leg, trig)
    if cs[CS_ON_R + leg] == 0.0:
        cs[CS_ON_R + leg] = 1.0
        cs[CS_XR + 2 * leg] = x
        cs[CS_ZR + 2 * leg] = 0.0
        return EV_TD_R + leg, x, z
    cs[CS_ON_R + leg] = 0.0
    return EV_LO_R + leg, x, z


@njit(**FAST)
def init_contact(P, y, cs):
    """Contact flags at the start: a foot at or below ground that is pushing.

    The anchor is at the ground, or at the foot if it is above (by at most
    1e-9 L, e.g. a section state placed at the ground up to rounding): an
    anchor below the foot would zero the force at the first instant (the
    ground pushes only a foot at or below its anchor).
    """
    for leg in range(2):
        x, z, xd, zd = foot_state(P, y, leg)
        cs[CS_ON_R + leg] = 0.0
        cs[CS_XR + 2 * leg] = x
        cs[CS_ZR + 2 * leg] = max(z, 0.0)
        if P[P_CONTACT] != 0.0 and z <= 1e-9 and -P[P_KZ] * z - P[P_CZ] * zd > 0.0:
            cs[CS_ON_R + leg] = 1.0


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(init_contact, __file__)
