"""Biped momenta and the metacentric pitch test (Section E.3.3, Figure E.4)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tslip.biped import BipedOptions, BipedParams, BipedState, simulate
from tslip.biped.dynamics import body_positions, foot_position, hip_position, momentum
from tslip.biped.metacentre import metacentric_table, metacentric_test, pitched_state
from tslip.biped.stored import load_gait
from tslip.plotting.biped import plot_metacentric


def _gait(name: str) -> tuple[BipedParams, BipedState, float]:
    p, y, t0, _ = load_gait(name)
    return p, BipedState.from_array(y), t0


def test_momenta_are_conserved_in_an_actuated_flight():
    """Without ground the hip and leg actuators are internal: L_c and p_x stay,
    p_z falls at M g. A spin sign error in ``momentum`` breaks this by ~1e-2."""
    p = BipedParams(contact=False)
    y = BipedState.thesis().to_array()
    y[11] += 0.7  # trunk pitch rate, so that the hip torques work hard
    tr = simulate(p, y, 1, t_end=2.0,
                  options=BipedOptions(rtol=1e-11, atol=1e-11, check_falls=False))
    _, p0, L0 = momentum(p, tr.data[0, 1:19])
    _, p1, L1 = momentum(p, tr.data[-1, 1:19])
    assert tr.time[-1] - tr.time[0] == pytest.approx(2.0)
    assert abs(L0) > 0.05 and np.ptp(tr["tau_R"]) > 0.1
    assert L1 == pytest.approx(L0, abs=1e-10)
    np.testing.assert_allclose(p1, p0 - np.array([0.0, p.total_mass * p.g * 2.0]), atol=1e-10)


def test_momentum_of_a_rigid_translation():
    """All bodies moving at one velocity: p = M v and L_c = 0."""
    p = BipedParams()
    q = BipedState.thesis().q
    qd = np.zeros(9)
    qd[:2] = (1.3, -0.4)
    com, mom, L = momentum(p, BipedState(q, qd))
    np.testing.assert_allclose(mom, p.total_mass * qd[:2], rtol=1e-14)
    assert L == pytest.approx(0.0, abs=1e-14)
    masses = np.array([p.m_b, p.m_t, p.m_s, p.m_f, p.m_t, p.m_s, p.m_f])
    np.testing.assert_allclose(com, masses @ body_positions(p, q) / masses.sum(), rtol=1e-14)


def test_pitched_state_keeps_hip_and_feet_in_the_world():
    p, s, _ = _gait("converged-e2")
    for d in (0.5, -0.5):
        s2 = pitched_state(p, s, d)
        assert s2.q[2] == pytest.approx(s.q[2] + d)
        np.testing.assert_allclose(hip_position(p, s2.q), hip_position(p, s.q), atol=1e-15)
        for leg in (0, 1):
            np.testing.assert_allclose(foot_position(p, s2.q, leg), foot_position(p, s.q, leg),
                                       atol=1e-14)
        np.testing.assert_array_equal(s2.qd, s.qd)


@pytest.fixture(scope="module")
def converged():
    p, s, t0 = _gait("converged-e2")
    return metacentric_test(p, s, t0)


def test_recorded_forces_match_the_momentum_change(converged):
    """The impulse and moment reported are from the momenta; the recorded forces
    (a separate path: contact law at each step) must integrate to the same."""
    for imp in converged:
        assert imp.quadrature_error < 1e-4
        assert imp.I_y == pytest.approx(np.trapezoid(imp.F_y, imp.time), abs=1e-4)
        assert 0.55 < imp.stance_time < 0.7


def test_periodic_gait_stance_has_no_net_moment(converged):
    """At the converged (left-right symmetric) gait the right stance's angular
    impulse and horizontal impulse are zero up to the periodicity residual."""
    nom = converged.nominal
    assert abs(nom.torque) < 1e-6 and abs(nom.I_x) < 1e-6


def test_thesis_e43_restoring_moment_little_change_of_direction(converged):
    """Section E.4.3: after +-0.5 rad of body pitch the impulse's moment about the
    CoM restores the pitch, and its direction changes little (tolerance 5 deg;
    we see 1.6 and 0.6 deg). The magnitude changes by +7.5 % / -14 %."""
    assert converged.restoring[1:] == (True, True)
    for dd in converged.direction_change[1:]:
        assert abs(math.degrees(dd)) < 5.0
    rows = metacentric_table(converged)
    assert [r["dtheta"] for r in rows] == [0.0, 0.5, -0.5]
    assert rows[1]["dtorque"] > 0.02 and rows[2]["dtorque"] < -0.02  # counter-clockwise
    for r in rows[1:]:
        assert 0.05 < abs(r["magnitude_change"]) < 0.2


def test_thesis_start_state_is_also_restoring():
    """From Table E.2 (not periodic) the moment change restores both ways too."""
    res = metacentric_test(BipedParams(), BipedState.thesis())
    assert res.restoring[1:] == (True, True)
    assert all(abs(math.degrees(d)) < 5.0 for d in res.direction_change)


def test_a_falling_stance_is_a_clear_error():
    p, s, t0 = _gait("converged-e2")  # pitch -0.32 rad; -1.4 more is beyond -pi/2
    with pytest.raises(ValueError, match="lift-off.*pitch"):
        metacentric_test(p, s, t0, pitches=(-1.4,))


def test_plot_metacentric(converged):
    fig = plot_metacentric(converged)
    assert len(fig.axes) == 2
    assert "clipped" in fig.axes[0].get_title()  # the touch-down spike of the ground damper
