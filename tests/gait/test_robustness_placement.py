"""Where a push or pitch-rate disturbance is applied (robustness ``placement``)."""

import math

import numpy as np
import pytest

import tslip
from tslip.gait.robustness import run_disturbed
from tslip.simulation.integrate import step


@pytest.fixture(scope="module")
def gait():
    return tslip.find_gait(tslip.preset("table6.1"))  # with swing-leg retraction


@pytest.mark.parametrize("placement", ["liftoff", "apex"])
def test_undisturbed_flight_placement_lands_on_the_gait(gait, placement):
    # d = 0 must reach the periodic gait's own touch-down: this checks the
    # flight re-based at the apex keeps the leg's retraction clock
    assert gait.params.omega_r != 0
    run = run_disturbed(gait.params, gait.state, "pitch_rate", [0.0], n_steps=2,
                        placement=placement)
    assert run.status[0] == 0 and run.n_done[0] == 2
    ref = run_disturbed(gait.params, gait.state, "pitch_rate", [0.0], n_steps=3)
    np.testing.assert_allclose(run.touchdowns[0], ref.touchdowns[0, 1:], rtol=0, atol=1e-10)
    np.testing.assert_allclose(run.touchdowns[0, 0, :5], gait.state.as_array()[:5], atol=1e-6)


@pytest.mark.parametrize("placement", ["liftoff", "apex"])
def test_flight_pitch_rate_is_ballistic(gait, placement):
    # in flight the massless leg exerts no torque: the pitch rate is the
    # lift-off one plus the disturbance, and the pitch grows linearly
    d = 0.2
    lo = step(gait.params, gait.state).liftoff
    run = run_disturbed(gait.params, gait.state, "pitch_rate", [d], n_steps=1,
                        placement=placement)
    td = run.touchdowns[0, 0]
    assert td[4] == pytest.approx(lo.phid + d, abs=1e-12)
    # the touch-down time from the CoM height: y(t) = y_lo + yd_lo t - t^2 / 2 (g = 1)
    yd_td = td[3]
    t_f = (lo.yd - yd_td) / gait.params.g
    t_a = max(lo.yd, 0.0) / gait.params.g if placement == "apex" else 0.0
    expected_phi = lo.phi + lo.phid * t_f + d * (t_f - t_a)
    assert td[1] == pytest.approx(expected_phi, abs=1e-9)
    # and the touch-down differs from the undisturbed one
    assert not math.isclose(td[1], gait.state.phi, abs_tol=1e-3)


def test_touchdown_hip_keeps_the_hip_velocity(gait):
    p, s = gait.params, gait.state
    d = -0.4
    run = run_disturbed(p, s, "pitch_rate", [0.0, d], n_steps=1, placement="touchdown_hip")
    rows = run.touchdowns[:, 0]

    def hip_velocity(row):  # d/dt of (x - r sin phi, y + r cos phi)
        return (row[2] - p.r * math.cos(row[1]) * row[4], row[3] - p.r * math.sin(row[1]) * row[4])

    assert rows[1, 4] == pytest.approx(s.phid + d)
    np.testing.assert_allclose(hip_velocity(rows[1]), hip_velocity(rows[0]), atol=1e-12)
    assert rows[1, 2] != pytest.approx(s.xd)  # the CoM velocity changed


def test_placement_is_checked(gait):
    with pytest.raises(ValueError, match="placement"):
        run_disturbed(gait.params, gait.state, "step_down", [-0.1], placement="apex")
    with pytest.raises(ValueError, match="placement"):
        run_disturbed(gait.params, gait.state, "push", [-0.1], placement="touchdown_hip")
    with pytest.raises(ValueError, match="placement"):
        run_disturbed(gait.params, gait.state, "push", [-0.1], placement="midair")
