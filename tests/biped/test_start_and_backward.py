"""Two biped outcome rules on both sides: a foot starting in contact, a backward fall.

The expected values are computed here: the foot's height and vertical speed
from the state (eq. E.8, written out below), the ground's spring-damper law
(eqs E.23-E.24: ``F_z = k_z (0 - z) - c_z zd``, and only a pushing ground is
a contact), and eq. 2.10's fall rule (the body moving backward, ``xd_b < 0``).
"""

from __future__ import annotations

import pytest

from tslip.biped import BipedParams, BipedState, Status, simulate

from ._foot import foot

P = BipedParams()


def _foot(y, leg):
    """Height and vertical speed of a foot (eq. E.8)."""
    return foot(P, y, leg)


@pytest.mark.parametrize("zd", [-0.44, -0.1, 0.3, 1.0])
def test_a_foot_starts_in_contact_only_if_the_ground_pushes(zd):
    """The thesis state's right foot, just below the ground, moving down or up at ``zd``."""
    y = BipedState.thesis().to_array()
    z, zd0 = _foot(y, 0)
    assert -1e-4 < z <= 0.0 and _foot(y, 1)[0] > 0.1  # right foot at the ground, left clear
    y[10] += zd - zd0  # the body's vertical speed moves the foot at zd
    push = P.k_z * (0.0 - z) - P.c_z * zd
    assert abs(push) > 0.1  # far from the boundary
    tr = simulate(P, BipedState.from_array(y), 1, t_end=0.02).to_dataframe()
    assert tr["contact_R"].iloc[0] == float(push > 0.0)
    assert tr["Fz_R"].iloc[0] == pytest.approx(max(push, 0.0), rel=1e-12, abs=1e-12)
    assert tr["Fz_R"].min() >= 0.0  # the ground never pulls


@pytest.mark.parametrize("xd", [-0.5, -0.05])
def test_a_body_moving_backward_falls_backward(xd):
    """Eq. 2.10: ``xd_b < 0`` is a backward fall, at once (here within the first step)."""
    y = BipedState.thesis().to_array()
    y[9] = xd
    tr = simulate(P, BipedState.from_array(y), 3)
    assert tr.status == Status.FALL_BACKWARD
    assert tr.events[-1].kind == "fall" and tr.events[-1].t < 1e-3
    assert tr.to_dataframe()["x_b_d"].iloc[-1] < 0.0


def test_a_slow_forward_body_does_not_fall_backward():
    y = BipedState.thesis().to_array()
    y[9] = 0.05
    tr = simulate(P, BipedState.from_array(y), 3)
    assert (tr.to_dataframe()["x_b_d"] > 0.0).all()
    assert tr.status != Status.FALL_BACKWARD
