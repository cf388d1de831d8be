"""Ground impulse (eqs 3.3-3.5) and its pitch response (Figures 4.1-4.3, 6.2)."""

import dataclasses
import doctest
import math

import numpy as np
import pytest
from matplotlib.figure import Figure

import tslip
import tslip.gait.impulse as impulse_module
from tslip.gait.impulse import (
    impulse_linearisation,
    pitch_disturbance_response,
    stance_impulse,
)
from tslip.plotting.gait import plot_impulse_linearisation, plot_pitch_impulse


@pytest.fixture(scope="module")
def passive():
    return tslip.find_gait(tslip.preset("table2.1"))


@pytest.fixture(scope="module")
def global_pd():
    return tslip.find_gait(tslip.preset("table2.1-global-pd"))


@pytest.fixture(scope="module")
def fit():
    return tslip.find_gait(tslip.preset("table6.1"))


@pytest.mark.parametrize("dphi", [0.0, 0.3, -0.5])
def test_quadrature_matches_the_exact_momentum_impulse(passive, fit, dphi):
    """Simpson on dt = 1e-3 dense samples vs m dv + m g t_s and J dphid.

    Simpson's error at dt = 1e-3 is below 1e-12 here, so what remains is the
    integrator's 1e-8 tolerance: allow 1e-7.
    """
    for g in (passive, fit):
        s = dataclasses.replace(g.state, phi=g.state.phi + dphi)
        imp = stance_impulse(g.params, s)
        assert imp.quadrature_error < 1e-7
        ix, iy = tslip.step(g.params, s).impulse
        assert imp.I_x == pytest.approx(ix, abs=1e-12)
        assert imp.I_y == pytest.approx(iy, abs=1e-12)
        # the quadrature itself, independently of the stored exact values
        assert np.trapezoid(imp.F_y, imp.time) == pytest.approx(iy, abs=1e-5)  # O(dt^2)


def test_periodic_gait_impulse_balances_gravity_and_is_vertical(passive, fit):
    """Over a period the ground must return the weight: I_y = m g (t_s + t_f), I_x = 0."""
    for g in (passive, fit):
        imp = stance_impulse(g.params, g.state, options=tslip.IntegratorOptions.tight())
        p = g.params
        assert imp.I_y == pytest.approx(p.m * p.g * (g.stance_time + g.flight_time), abs=1e-9)
        assert abs(imp.I_x) < 1e-9
        assert abs(imp.torque) < 1e-9  # periodic pitch rate: no net angular impulse
        assert imp.direction == pytest.approx(math.pi / 2, abs=1e-8)
        assert imp.y_p_ill_conditioned  # eq. 3.5's y_p is 0/0 at a periodic gait


def test_symmetric_passive_stance(passive):
    """The passive gait's stance is nearly mirror-symmetric: x_p ~ 0, hip mirrored."""
    imp = stance_impulse(passive.params, passive.state, options=tslip.IntegratorOptions.tight())
    assert abs(imp.x_p) < 1e-4  # measured 1e-11
    assert imp.hip_touchdown[0] == pytest.approx(-imp.hip_liftoff[0], abs=1e-4)
    assert imp.hip_touchdown[1] == pytest.approx(passive.params.r, abs=1e-4)
    # force along the leg: the GRF points from the foot at the hip (passive, tau = 0)
    leg_x, leg_y = imp.hip_x - imp.x, imp.hip_y - imp.y
    cross = imp.F_x * leg_y - imp.F_y * leg_x
    assert np.max(np.abs(cross)) < 1e-9 * np.max(imp.F_y) * 10


def test_torque_is_the_moment_of_the_impulse_at_its_point_of_application(passive):
    s = dataclasses.replace(passive.state, phi=passive.state.phi + 0.5)
    imp = stance_impulse(passive.params, s)
    assert not imp.y_p_ill_conditioned  # I_x / |I| = 0.008 here
    assert imp.x_p * imp.I_y - imp.y_p * imp.I_x == pytest.approx(imp.torque, abs=1e-7)
    assert imp.line_x(imp.y_p) == pytest.approx(imp.x_p, abs=1e-6)
    assert imp.line_distance(imp.x_p, imp.y_p) == pytest.approx(0.0, abs=1e-6)
    # a point 0.1 L ahead of an (almost) upward impulse is 0.1 L to its right
    assert imp.line_distance(imp.x_p + 0.1, imp.y_p) == pytest.approx(0.1, abs=1e-3)


def test_figure_4_1_x_p_gradient_dominates_for_the_passive_gait(passive):
    """Figure 4.1: only the horizontal point of application moves with pitch.

    Measured: dI_x -5.4e-4, dI_y -0.012, dx_p -0.2885 (hip: -r cos(phi) = -0.300).
    """
    lin = impulse_linearisation(passive)
    assert abs(lin.dx_p) > 10 * max(abs(lin.dI_x), abs(lin.dI_y))
    assert -0.30 < lin.dx_p < -0.27  # follows the hip's -r cos(phi) to within 10 %
    assert lin.dtorque < 0  # restoring
    assert abs(lin.ddirection) < 0.01
    assert lin.y_p_ill_conditioned


def test_figure_4_2_passive_impulse_points_at_the_hip_and_restores(passive):
    """Measured: hip distance 0.0012 r and 0.0019 r, direction change 0.008 rad."""
    resp = pitch_disturbance_response(passive)
    assert resp.dphis == (0.0, 0.5, -0.5) and len(resp) == 3
    assert resp.restoring == (None, True, True)
    assert max(resp.hip_distance) < 0.05
    assert max(abs(d) for d in resp.direction_change) < 0.02
    assert all(0.9 < f < 1.1 for f in resp.x_p_follows_hip[1:])


def test_figure_4_3_global_pd_turns_the_impulse(global_pd):
    """The PD hip torque rotates the impulse instead (measured +0.65, -0.47 rad)."""
    resp = pitch_disturbance_response(global_pd)
    assert resp.restoring == (None, True, True)
    assert resp.direction_change[1] > 0.3 and resp.direction_change[2] < -0.3
    assert min(resp.hip_distance[1:]) > 1.0  # no longer through the hip
    for imp in resp.impulses[1:]:  # ... but still applied on the hip's side of the CoM
        assert np.sign(imp.x_p) == np.sign(imp.hip_mean[0])


def test_figure_6_2_fit_restores_pitch(fit):
    """Table 6.1 fit: restoring torque; x_p moves 0.76 and 0.87 of the hip's shift."""
    resp = pitch_disturbance_response(fit)
    assert resp.restoring == (None, True, True)
    assert resp[1].torque < 0 < resp[2].torque
    assert all(0.5 < f < 1.2 for f in resp.x_p_follows_hip[1:])


def test_a_stance_that_falls_raises():
    p = tslip.preset("table2.1")
    s = tslip.TouchdownState(beta=1.05, phi=0.0, xd=0.3, yd=-0.1, phid=0.0)
    with pytest.raises(ValueError, match="did not end in a lift-off"):
        stance_impulse(p, s)
    with pytest.raises(ValueError, match="dt"):
        stance_impulse(p, s, dt=0.0)


def test_plots_return_figures(passive):
    resp = pitch_disturbance_response(passive, dphis=(0.0, 0.3))
    fig = plot_pitch_impulse(resp)
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    fig2 = Figure()
    ax = fig2.subplots()
    assert plot_pitch_impulse(list(resp), ax=ax) is fig2
    lin = impulse_linearisation(passive)
    fig3 = plot_impulse_linearisation(lin)
    heights = [b.get_height() for b in fig3.axes[0].patches]
    assert heights[0] == pytest.approx(lin.dx_p) and heights[1] == 0.0  # y_p ill-conditioned


def test_docstring_examples():
    result = doctest.testmod(impulse_module, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
