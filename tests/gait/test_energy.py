"""Speed after a ground step (eq. 3.8, Figures 4.4-4.7)."""

import doctest
import math

import numpy as np
import pytest
from matplotlib.figure import Figure

import tslip
import tslip.gait.energy as energy_module
from tslip.gait.energy import (
    expected_velocity_change,
    step_down_response,
    velocity_after_height_change,
    velocity_angle_effect,
)
from tslip.plotting.gait import plot_step_down_response, plot_velocity_angle_effect


@pytest.fixture(scope="module")
def passive():
    return tslip.find_gait(tslip.preset("table2.1"))


@pytest.fixture(scope="module")
def local():
    return tslip.find_gait(tslip.preset("table2.1-local-velocity"))


def test_expected_velocity_change_eq_3_8():
    assert expected_velocity_change(5.0, -0.2) == pytest.approx(math.sqrt(25.4) - 5.0, rel=1e-14)
    assert expected_velocity_change(5.0, 0.0) == 0.0
    assert expected_velocity_change(5.0, -0.1) > 0 > expected_velocity_change(5.0, 0.1)
    # energy: v_inf^2 / 2 + g dh = v0^2 / 2, also with g != 1
    dv = expected_velocity_change(3.0, 0.2, g=9.81)
    assert 0.5 * (3.0 + dv) ** 2 + 9.81 * 0.2 == pytest.approx(4.5, rel=1e-12)
    with pytest.raises(ValueError, match="step up"):
        expected_velocity_change(1.0, 0.6)


@pytest.mark.parametrize("dh", [-0.2, -0.1, 0.05])
def test_figure_4_4_left_passive_speed_follows_the_energy_balance(passive, dh):
    """Mean of the last 50 of 200 touch-down speeds vs eq. 3.8, within 1e-3.

    Measured errors: 1.8e-6 (-0.2), -5.1e-6 (-0.1), -4.0e-5 (+0.05). A 0.1 L
    step up makes the passive gait fall at stride 8 (FALL_NO_TOUCHDOWN).
    """
    r = velocity_after_height_change(passive, dh)
    assert r.status == tslip.Status.OK and r.converged
    assert r.dv == pytest.approx(r.dv_expected, abs=1e-3)
    assert abs(r.dv - r.dv_expected) < 0.1 * abs(r.dv_expected)
    assert r.spread > 1e-4  # still oscillating: the passive gait is only neutrally damped
    assert len(r.speeds) == 201 and r.speeds[0] == pytest.approx(passive.state.v)


@pytest.mark.parametrize("dh", [-0.1, 0.1])
def test_figure_4_4_right_local_velocity_control_returns_to_v0(local, dh):
    """Measured |dv| < 3e-8 after 200 strides; tolerance 1e-5 (expected |dv| 0.02)."""
    r = velocity_after_height_change(local, dh)
    assert r.converged
    assert abs(r.dv) < 1e-5
    assert abs(r.dv_expected) > 0.019


def test_a_fall_is_reported_not_raised(passive):
    r = velocity_after_height_change(passive, 0.1)
    assert r.status.fell and not r.converged and math.isnan(r.dv)


def test_figures_4_5_4_6_height_and_speed_oscillate_in_opposite_phase(passive):
    resp = step_down_response(passive, dh=-0.2, n_steps=30)
    assert len(resp.stride) == 31
    assert resp.h[0] == 0.0 and np.all(resp.h[1:] == -0.2)
    # Figure 4.5 plots xd: measured correlation -0.75; with the speed it is -0.99997
    assert resp.phase_correlation < -0.5
    assert np.corrcoef(resp.height[1:], resp.speed[1:])[0, 1] < -0.99
    # converging: the oscillation shrinks (ptp 0.050 in strides 1-10, 0.005 in 21-30)
    assert np.ptp(resp.xd[-10:]) < 0.3 * np.ptp(resp.xd[1:11])
    # the passive model conserves energy at every touch-down (m = g = 1)
    p = passive.params
    e = 0.5 * resp.speed**2 + 0.5 * p.J * np.array([s.phid for s in
                                                    resp.trajectory.touchdowns]) ** 2 + resp.y
    np.testing.assert_allclose(e, e[0], atol=1e-6)


def test_figure_4_7_steeper_landing_converts_vertical_into_forward_speed(passive):
    """Measured for ddelta = -0.05, 0, +0.05: t_s 0.2147, 0.2006, 0.1857;
    t_f 0.141, 0.252, 0.433; I_x +0.0225, 0.0, -0.0146."""
    down, nominal, up = velocity_angle_effect(passive, (-0.05, 0.0, 0.05))
    assert down.stance_time > nominal.stance_time > up.stance_time
    assert down.flight_time < nominal.flight_time < up.flight_time
    assert down.impulse.I_x > 1e-3 and up.impulse.I_x < -1e-3
    assert abs(nominal.impulse.I_x) < 1e-6
    assert down.liftoff_delta < nominal.liftoff_delta < up.liftoff_delta  # flatter lift-off
    assert np.max(down.impulse.F_y) > np.max(nominal.impulse.F_y)  # spring compressed more
    assert down.delta == pytest.approx(passive.state.delta - 0.05, abs=1e-12)


def test_plots(passive):
    resp = step_down_response(passive, n_steps=8)
    fig = plot_step_down_response(resp)
    assert isinstance(fig, Figure) and len(fig.axes) == 3  # path, xd, twin height
    xd_line = fig.axes[1].get_lines()[0]
    np.testing.assert_allclose(xd_line.get_ydata(), resp.xd)
    fig2 = plot_velocity_angle_effect(velocity_angle_effect(passive))
    assert len(fig2.axes) == 3 and len(fig2.axes[1].get_lines()) == 3


def test_docstring_examples():
    result = doctest.testmod(energy_module, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0


# -- one stride's energy balance (stride_work) ----------------------------------


def _stance_work_scipy(gait):
    """Hip work, damper loss and lift-off state by an independent integration.

    The stance of the readable reference equations (tslip.model.dynamics, eq. A.14)
    with two more states accumulating the hip power tau (phid + betad) and the
    damper power c_l ld^2, solved by scipy's DOP853 at rtol 1e-12 to the lift-off
    event F_y = 0 (eq. 2.8); the touch-down stance state from eq. A.5 inverted here.
    """
    from scipy.integrate import solve_ivp

    from tslip.model import dynamics

    p, s = gait.params, gait.state
    u = s.xd - p.r * math.cos(s.phi) * s.phid
    w = s.yd - p.r * math.sin(s.phi) * s.phid
    y0 = [p.l0, s.beta, s.phi, -u * math.cos(s.beta) + w * math.sin(s.beta),
          (u * math.sin(s.beta) + w * math.cos(s.beta)) / p.l0, s.phid, 0.0, 0.0]

    def rhs(_t, z):
        y = z[:6]
        q, qd = y[:3], y[3:]
        tau = dynamics.hip_torque(p, q, qd)
        return [*dynamics.stance_rhs(p, y), tau * (y[5] + y[4]), p.c_l * y[3] ** 2]

    def lift_off(_t, z):
        return dynamics.ground_reaction_force(p, z[:6])[1]

    lift_off.terminal, lift_off.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 5.0), y0, method="DOP853", rtol=1e-12, atol=1e-12,
                    events=lift_off)
    z = sol.y_events[0][0]
    return z[6], z[7], z[:6]


def test_stride_work_balances_on_the_powered_table61_gait():
    """Hip work = damper loss + the spring energy left at lift-off (a periodic gait).

    Table 6.1 (local velocity control, c_l = 0.32): lift-off (F_y = 0) comes while the
    leg is still compressed, so the hip puts in more than the damper takes out. Each
    term against the independent integration above; the spring energy from the
    lift-off leg length, 0.5 k (l0 - l)^2, not from the energy column.
    """
    g = tslip.find_gait(tslip.preset("table6.1"))
    w = tslip.gait.stride_work(g)
    hip, damper, y_lo = _stance_work_scipy(g)
    p = g.params
    assert w.hip == pytest.approx(hip, rel=1e-7)
    assert w.damper == pytest.approx(damper, rel=1e-7)
    # (rel 1e-6: the kernel locates lift-off at its own tolerance, 1e-8 relative in time)
    assert w.liftoff == pytest.approx(0.5 * p.k * (p.l0 - y_lo[0]) ** 2, rel=1e-6)
    # the balance: a periodic gait ends a stride with the energy it started with
    assert abs(w.change) < 1e-6 and abs(w.residual) < 1e-6
    assert w.hip == pytest.approx(w.damper + w.liftoff, abs=1e-6)
    # ... and the lift-off loss is not negligible (what made hip work != damper loss)
    assert w.liftoff > 0.1 * w.hip > 0.01


def test_stride_work_is_zero_for_the_passive_undamped_gait_and_refuses_a_fall(passive):
    w = tslip.gait.stride_work(passive)
    assert w.hip == 0.0 and w.damper == 0.0
    assert abs(w.liftoff) < 1e-12 and abs(w.change) < 1e-6
    with pytest.raises(ValueError, match="samples must be >= 100"):
        tslip.gait.stride_work(passive, samples=10)
    import dataclasses

    falls = dataclasses.replace(passive, state=dataclasses.replace(passive.state, xd=-1.0))
    with pytest.raises(ValueError, match="not a touch-down"):
        tslip.gait.stride_work(falls)
