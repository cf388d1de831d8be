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


# ---------------------------------------------------------------------------
# the gait search at fixed energy and on the apex section, against the reference
# ---------------------------------------------------------------------------


def ref_apex_fixed_point(E, beta, k, lo, hi):
    """Fixed point of the reference apex map in (lo, hi) and its derivative there."""
    from scipy.optimize import brentq

    def f(y):
        return ref_apex_map(y, E, beta, k)[0] - y

    y = brentq(f, lo, hi, xtol=1e-14)

    def central(h):
        return (ref_apex_map(y + h, E, beta, k)[0] - ref_apex_map(y - h, E, beta, k)[0]) / (2 * h)

    return y, (4.0 * central(2e-5) - central(4e-5)) / 3.0  # Richardson


def test_fixed_energy_gait_matches_the_reference_fixed_point(slip):
    E = 2.2
    g = tslip.find_gait(slip, fix="energy", energy=E)
    assert g.converged and g.fix == "energy"
    s = g.state
    # the energy held, by hand (m = g = l0 = 1, r = 0): v^2/2 + sin(beta0)
    assert 0.5 * (s.xd**2 + s.yd**2) + math.sin(s.beta) == pytest.approx(E, abs=1e-12)
    assert g.params.v0 == pytest.approx(s.v, abs=1e-15)  # the touch-down speed found
    assert s.phi == 0.0 and s.phid == 0.0  # the undetermined pitch held at r = 0
    y_apex = math.sin(s.beta) + 0.5 * s.yd**2
    assert g.apex.y == pytest.approx(y_apex, abs=1e-14)
    y_ref, d_ref = ref_apex_fixed_point(E, slip.beta0, slip.k, y_apex - 0.01, y_apex + 0.01)
    assert y_apex == pytest.approx(y_ref, abs=1e-9)
    f_td = tslip.floquet(g)
    f_ap = tslip.floquet(g, section="apex")
    assert f_ap.multipliers.shape == (4,) and f_ap.section == "apex"
    assert f_ap.max_nontrivial == pytest.approx(abs(d_ref), abs=1e-6)
    assert f_td.max_nontrivial == pytest.approx(abs(d_ref), abs=1e-6)
    assert f_ap.stability == f_td.stability == "asymptotic"


def _nonzero_nontrivial(f):
    lam = f.multipliers[~f.trivial]
    return np.sort_complex(lam[np.abs(lam) > 1e-9])


@pytest.mark.parametrize("name, fd_tol", [("slip", 1e-6), ("table2.1", 2e-6)])
def test_apex_multipliers_equal_the_touchdown_ones(name, fd_tol):
    """Return maps of one flow on two sections are conjugate: the same multipliers but
    the touch-down 0 of a leg set at a fixed angle. Table 2.1 without retraction
    (r = 0.3, local reset) goes through the kernels' touch-down search from the apex."""
    p = dataclasses.replace(tslip.preset(name), omega_r=0.0)
    g = tslip.find_gait(p)
    assert g.converged
    f_td = tslip.floquet(g)
    f_ap = tslip.floquet(g, section="apex")
    f_fd = tslip.floquet(g, section="apex", method="fd")  # differences of the apex map itself
    lam_td = np.sort_complex(f_td.multipliers)
    assert np.min(np.abs(lam_td)) < 1e-9  # the touch-down 0 (the fixed leg angle)
    lam_td = lam_td[np.abs(lam_td) > 1e-9]
    np.testing.assert_allclose(np.sort_complex(f_ap.multipliers), lam_td, atol=1e-9)
    np.testing.assert_allclose(np.sort_complex(f_fd.multipliers), lam_td, atol=fd_tol)
    np.testing.assert_allclose(_nonzero_nontrivial(f_ap), _nonzero_nontrivial(f_td), atol=1e-9)
    assert f_ap.stability == f_td.stability


def test_apex_section_holds_the_forward_speed(slip):
    g = tslip.find_gait(slip, section="apex")
    assert g.converged and g.section == "apex"
    assert g.state.xd == pytest.approx(slip.v0, abs=1e-12)  # v0 is the apex speed here
    assert g.held == g.state.xd
    assert tslip.floquet(g).section == "apex"  # the gait's section by default


def test_fixed_energy_tslip_gait():
    """Table 2.1 (r = 0.3, the pitch free) at a fixed energy: held, and kept by the stride."""
    p = tslip.preset("table2.1")
    g = tslip.find_gait(p, fix="energy", energy=15.0)
    assert g.converged
    s = g.state
    by_hand = (0.5 * p.m * (s.xd**2 + s.yd**2) + 0.5 * p.J * s.phid**2
               + p.m * p.g * (p.l0 * math.sin(s.beta) - p.r * math.cos(s.phi)))
    assert by_hand == pytest.approx(15.0, abs=1e-12)
    nxt = tslip.step(g.params, s, options=TIGHT).state
    assert total_energy(p, nxt) == pytest.approx(15.0, abs=1e-9)


def test_fixed_energy_continuation_holds_energy_and_pitch():
    """The stop-17 case: along beta0 at fixed energy the undetermined pitch drifted (to 3e23)
    and the branch crashed; with the pitch held it runs, at constant energy."""
    p = dataclasses.replace(tslip.preset("slip"), k=25.0)
    b = tslip.continue_gait(p, "beta0", np.linspace(1.1, 1.4, 13), fix="energy", energy=2.2)
    assert b.fix == "energy" and b.energy == 2.2
    assert b.converged.sum() >= 10
    for g in b.gaits:
        if g is None:
            continue
        s = g.state
        assert 0.5 * (s.xd**2 + s.yd**2) + math.sin(s.beta) == pytest.approx(2.2, abs=1e-10)
        assert s.phi == 0.0 and s.phid == 0.0
    df = b.to_dataframe()
    np.testing.assert_allclose(df["energy"].dropna(), 2.2, atol=1e-10)
    # the apex branch: the same gaits and the same non-trivial multipliers
    a = tslip.continue_gait(p, "beta0", b.values[b.converged], fix="energy", energy=2.2,
                            section="apex")
    assert a.multipliers.shape == (b.converged.sum(), 4) and a.converged.all()
    np.testing.assert_allclose(a.max_nontrivial, b.max_nontrivial[b.converged], rtol=1e-8)


def test_stability_boundary_at_fixed_energy_matches_the_reference():
    """Where the SLIP's flat gait turns unstable along beta0 at E = 2.2: re-solved at fixed
    energy (at fixed speed the boundary would be elsewhere), against the reference."""
    from scipy.optimize import brentq

    p = tslip.preset("slip")
    b = tslip.continue_gait(p, "beta0", np.linspace(1.17, 1.215, 4), fix="energy", energy=2.2)
    assert b.converged.all()
    (x,) = tslip.gait.stability_boundaries(b)

    def excess(beta):
        g = b.gaits[int(np.argmin(np.abs(b.values - beta)))]
        y = g.apex.y
        lo = max(math.sin(beta) + 1e-6, y - 0.02)
        return abs(ref_apex_fixed_point(2.2, beta, p.k, lo, y + 0.02)[1]) - 1.0

    i = int(np.argmax(b.max_nontrivial > 1.0))
    x_ref = brentq(excess, b.values[i - 1], b.values[i], xtol=1e-8)
    assert x == pytest.approx(x_ref, abs=1e-5)
    fixed_speed = tslip.continue_gait(p, "beta0", np.linspace(1.17, 1.215, 4))
    assert abs(tslip.gait.stability_boundaries(fixed_speed)[0] - x) > 1e-4  # 7.7e-4


def test_tslip_descent_with_a_turning_trunk():
    """r = 0.3 and phid != 0: no closed form, the kernels' touch-down search from the apex.
    The touch-down it finds satisfies eq. 2.9 on the parabola, and the closed-form way back
    (touchdown_to_apex) returns the apex."""
    p = dataclasses.replace(tslip.preset("table2.1"), omega_r=0.0, alpha_r=1.0)
    a = ApexState(y=1.1, xd=4.8, phi=0.05, phid=0.4, x=0.2)
    td = apex_to_touchdown(p, a)
    T = -td.yd / p.g
    phi_t = a.phi + a.phid * T
    assert td.phi == pytest.approx(phi_t, abs=1e-14)
    assert td.beta == pytest.approx(p.alpha_r - phi_t, abs=1e-14)  # local reset: alpha - phi
    foot = a.y - 0.5 * p.g * T**2 + p.r * math.cos(phi_t) - p.l0 * math.sin(td.beta)
    assert abs(foot) < 1e-12  # eq. 2.9
    np.testing.assert_allclose(touchdown_to_apex(p, td).as_array(), a.as_array(), atol=1e-12)
    assert total_energy(p, td) == pytest.approx(total_energy(p, a), abs=1e-12)


@pytest.mark.parametrize("name", ["slip", "table6.1"])
def test_apex_section_with_retraction_timed_from_the_apex(name):
    """With ``retraction="apex"`` the apex is a section: the touch-down gait's apex is a
    fixed point of the apex map (which starts its clock at that apex), the map's
    touch-down is the gait's, and the apex multipliers are the touch-down ones
    less the 0 of the rank-4 map (retraction from the apex forgets the lift-off)."""
    p = tslip.preset(name)
    p = dataclasses.replace(p, retraction="apex", omega_r=0.5 if name == "slip" else p.omega_r)
    g = tslip.find_gait(p)
    assert g.converged
    a = touchdown_to_apex(g.params, g.state)
    r = apex_map(g.params, a, options=TIGHT)
    assert r.status == Status.OK
    assert r.apex.section() == pytest.approx(a.section(), abs=1e-8)
    assert r.touchdown.beta == pytest.approx(g.state.beta, abs=1e-10)
    f_td, f_ap = tslip.floquet(g), tslip.floquet(g, section="apex")
    assert f_ap.max_nontrivial == pytest.approx(f_td.max_nontrivial, abs=1e-8)
    assert np.min(np.abs(f_td.multipliers)) < 1e-12  # the rank-4 touch-down map's 0
