"""The TSLIP gait as the biped's starting point (Section E.2.6, Table E.2).

The thesis builds the biped's initial guess from a TSLIP fixed point: the
entries of Table E.2 marked "based on a fixed point from the TSLIP model"
(body position, velocity and pitch, right thigh and shank at rest and the
right hip angle) follow from the TSLIP touch-down state; the rest were found
by the periodic-gait search. :func:`tslip_start` makes that map.

Geometry (docs/conventions.md for the TSLIP, eqs E.2-E.8 for the biped): the
TSLIP CoM is ``hip + r (sin phi, -cos phi)`` and its foot ``hip + l0 (cos
beta, -sin beta)``; the biped CoM is ``hip - r_1 (sin theta_b, cos
theta_b)`` and its foot ``hip - (l_t + l_s) (sin gamma, cos gamma)`` with
``gamma = theta_b + theta_h``. Hence, with ``r = r_1`` and ``l0 = l_t0 +
l_s0``::

    theta_b = -phi,  theta_hR = beta - pi/2 + phi,
    z_b = l0 sin beta - r_1 cos phi,  (xd_b, zd_b) = (xd, yd).

From the Table 6.1 gait this gives the "+" entries of Table E.2 to the
printed three decimals (a test).
"""

from __future__ import annotations

import math

import numpy as np

from ..model.state import TouchdownState
from .parameters import BipedParams, BipedState

__all__ = ["TSLIP_BASED", "tslip_start"]

#: Entries of ``(q, qd)`` (indices into the 18-vector) that Table E.2 marks as
#: based on the TSLIP fixed point.
TSLIP_BASED: tuple[int, ...] = (0, 1, 2, 3, 4, 5, 9, 10)


def tslip_start(state: TouchdownState, params: BipedParams,
                rest: BipedState | None = None) -> BipedState:
    """Biped state at a right touch-down built from a TSLIP touch-down state.

    Parameters
    ----------
    state : TouchdownState
        TSLIP state just after touch-down on flat ground (e.g. ``find_gait(
        preset("table6.1")).state``).
    params : BipedParams
        Supplies ``r_1`` and the rest lengths ``l_t0``, ``l_s0``.
    rest : BipedState, optional
        Source of the entries the TSLIP does not fix (pitch rate, right leg
        rates, left leg); default Table E.2 (:meth:`BipedState.thesis`).

    Returns
    -------
    BipedState
        The right foot on the ground at ``x = l0 cos beta`` ahead of the hip.
    """
    if not isinstance(state, TouchdownState):
        raise ValueError(f"state must be a TouchdownState, got {type(state).__name__}")
    y = (rest or BipedState.thesis()).to_array()
    l0 = params.l_t0 + params.l_s0
    y[0] = 0.0
    y[1] = l0 * math.sin(state.beta) - params.r_1 * math.cos(state.phi)
    y[2] = -state.phi
    y[3] = params.l_t0
    y[4] = params.l_s0
    y[5] = state.beta - 0.5 * math.pi + state.phi
    y[9] = state.xd
    y[10] = state.yd
    return BipedState.from_array(np.asarray(y))
