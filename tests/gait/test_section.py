"""The apex section (tslip.gait.section) against an independent SLIP written here.

The reference: a point mass on a massless spring leg, stance by scipy's
DOP853 at rtol 1e-12, flight in closed form, on the apex section at fixed
energy (Seyfarth et al. 2002). Nothing here uses tslip's kernels.
"""

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import tslip
from tslip.gait.section import (
    ApexState,
    apex_map,
    apex_map_batch,
    apex_map_states,
    apex_to_touchdown,
    total_energy,
    touchdown_to_apex,
)
from tslip.simulation.result import Status

TIGHT = tslip.IntegratorOptions.tight("dop853")


def ref_stance(y0, vx, vy, beta, k, m=1.0, g=1.0, l0=1.0):
    """Point-mass stance from touch-down, foot at the origin; the lift-off state or None."""

    def f(t, s):
        x, y, u, v = s
        l = math.hypot(x, y)
        a = k * (l0 - l) / (m * l)
        return [u, v, a * x, a * y - g]

    def lift_off(t, s):
        return math.hypot(s[0], s[1]) - l0

    def hits_ground(t, s):
        return s[1]

    lift_off.terminal, lift_off.direction = True, 1.0
    hits_ground.terminal, hits_ground.direction = True, -1.0
    s0 = [-l0 * math.cos(beta), y0, vx, vy]
    sol = solve_ivp(f, (0.0, 20.0), s0, method="DOP853", rtol=1e-12, atol=1e-12,
                    events=(lift_off, hits_ground), first_step=1e-6)
    if sol.status != 1 or sol.t_events[0].size == 0:
        return None
    return sol.y_events[0][0], float(sol.t_events[0][0])


def ref_apex_map(y, E, beta, k, m=1.0, g=1.0, l0=1.0):
    """(next apex height, next forward speed) or None (fall / no apex), at energy E."""
    vx = math.sqrt(2.0 * (E - m * g * y) / m)
    y_td = l0 * math.sin(beta)
    if y <= y_td:
        return None
    vy = -math.sqrt(2.0 * g * (y - y_td))
    st = ref_stance(y_td, vx, vy, beta, k, m, g, l0)
    if st is None:
        return None
    (_, y_lo, vx_lo, vy_lo), _ = st
    if vy_lo < 0.0 or vx_lo < 0.0:
        return None
    return y_lo + 0.5 * vy_lo**2 / g, vx_lo


@pytest.fixture(scope="module")
def slip():
    return tslip.preset("slip")


def test_apex_touchdown_round_trip_and_closed_form(slip):
    a = ApexState.from_energy(slip, 1.05, 2.2, x=0.3, h=0.1)
    td = apex_to_touchdown(slip, a)
    # closed form by hand: the foot at l0 sin(alpha_r) above the ground, free fall from y
    T = math.sqrt(2.0 * (1.05 - math.sin(slip.alpha_r)))
    assert td.beta == slip.alpha_r and td.h == 0.1
    assert td.yd == pytest.approx(-T, abs=1e-15)
    assert td.x == pytest.approx(0.3 + a.xd * T, abs=1e-15)
    back = touchdown_to_apex(slip, td)
    np.testing.assert_allclose(back.as_array(), a.as_array(), atol=1e-14)
    assert total_energy(slip, td) == pytest.approx(2.2, abs=1e-14)
    assert total_energy(slip, a) == pytest.approx(2.2, abs=1e-14)


def test_touchdown_to_apex_with_offset_and_pitch_rate():
    """With r != 0 and a turning trunk: the parabola's vertex, by hand (eqs 2.7, 2.9)."""
    p = tslip.preset("table2.1")
    td = tslip.TouchdownState(beta=1.05, phi=0.1, xd=4.9, yd=-0.6, phid=0.3, x=2.0)
    a = touchdown_to_apex(p, td)
    T = 0.6 / p.g
    y_td = p.l0 * math.sin(1.05) - p.r * math.cos(0.1)
    assert a.y == pytest.approx(y_td + 0.5 * 0.6**2, abs=1e-15)
    assert a.phi == pytest.approx(0.1 - 0.3 * T, abs=1e-15)
    assert a.x == pytest.approx(2.0 - 4.9 * T, abs=1e-15)
    assert total_energy(p, a) == pytest.approx(total_energy(p, td), abs=1e-13)
    with pytest.raises(ValueError, match="yd must be <= 0"):
        touchdown_to_apex(p, dataclasses.replace(td, yd=0.2))


def test_apex_map_matches_scipy_on_a_grid(slip):
    E = 2.2
    ys = np.linspace(0.97, 1.15, 7)
    alphas = np.linspace(1.12, 1.3, 6)
    b = apex_map_batch(slip, ys[:, None], alphas[None, :], energy=E, options=TIGHT)
    assert b.y.shape == (7, 6)
    n_ok = 0
    for i, y in enumerate(ys):
        for j, al in enumerate(alphas):
            ref = ref_apex_map(float(y), E, float(al), slip.k)
            if ref is None:
                assert b.status[i, j] != Status.OK
                continue
            n_ok += 1
            assert b.status[i, j] == Status.OK
            assert b.y[i, j] == pytest.approx(ref[0], abs=1e-9)
            assert b.xd[i, j] == pytest.approx(ref[1], abs=1e-9)
            # energy at the next apex (conserved: no damping, no torque)
            e_next = 0.5 * b.xd[i, j] ** 2 + b.y[i, j]
            assert e_next == pytest.approx(E, abs=1e-10)
    assert n_ok >= 25


def test_single_map_equals_the_batch_and_the_states_map(slip):
    a = ApexState.from_energy(slip, 1.02, 2.2)
    s = apex_map(slip, a, options=TIGHT)
    b = apex_map_batch(slip, 1.02, energy=2.2, options=TIGHT)
    c = apex_map_states(slip, a.section()[None, :], options=TIGHT)
    assert s.status == Status.OK
    assert s.apex.y == float(b.y) == float(c.y[0])
    assert s.apex.xd == float(b.xd)
    # apex to apex: the descent, scipy's stance, the rise to the apex
    y_td = math.sin(slip.alpha_r)
    (_, _, _, vy_lo), t_s = ref_stance(y_td, a.xd, -math.sqrt(2.0 * (1.02 - y_td)),
                                       slip.alpha_r, slip.k)
    assert s.stance_time == pytest.approx(t_s, abs=1e-9)
    assert s.time == pytest.approx(math.sqrt(2.0 * (1.02 - y_td)) + t_s + vy_lo, abs=1e-9)


def test_no_apex_status_is_an_outcome_not_a_fall_or_error(slip):
    assert Status.NO_APEX.value >= 20
    assert not Status.NO_APEX.fell and not Status.NO_APEX.is_error
    assert all(not s.is_error for s in Status if s.fell)
    # a steep leg at low energy lifts off moving down: no apex in that flight
    b = apex_map_batch(slip, np.array([1.0]), np.array([1.45]), energy=1.3, options=TIGHT)
    ref = ref_stance(math.sin(1.45), math.sqrt(2 * 0.3), -math.sqrt(2 * (1.0 - math.sin(1.45))),
                     1.45, slip.k)
    assert ref is not None and ref[0][3] < 0.0  # scipy: lift-off moving down
    assert b.status[0] == Status.NO_APEX and math.isnan(b.y[0])


def test_apex_below_touchdown_height_falls(slip):
    b = apex_map_batch(slip, np.array([math.sin(1.2) - 0.01]), np.array([1.2]), energy=2.2)
    assert b.status[0] == Status.FALL_NO_TOUCHDOWN


def test_bad_inputs_are_one_line_errors(slip):
    with pytest.raises(ValueError, match="apex height y must be in"):
        apex_map_batch(slip, np.array([3.0]), energy=2.2)
    with pytest.raises(ValueError, match="omega_r must be 0"):
        apex_map(tslip.preset("table2.1"), ApexState(1.0, 5.0))
    with pytest.raises(ValueError, match="ApexState.y"):
        ApexState(math.nan, 1.0)
