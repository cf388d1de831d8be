"""The SLIP limit (r = 0, no hip torque, global leg reset): presets and stability.

The reference is an independent SLIP written here: a point mass on a massless
spring leg, stance by scipy's DOP853 at 1e-12, flight in closed form, on the
apex section at fixed energy (Seyfarth et al. 2002). Its one non-trivial
multiplier is the derivative of the apex-height map at the fixed point; the
multipliers of conjugate return maps agree, so it must equal the non-trivial
touch-down multiplier of :func:`tslip.gait.floquet` with the decoupled pitch
(two multipliers 1) and the energy (one) set aside.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import tslip
from tslip.gait.continuation import continue_gait, stability_boundaries
from tslip.gait.stability import floquet, pitch_decoupled
from tslip.model.units import Scaling


def _stance(y0, vx, vy, beta, k):
    """Point-mass stance from touch-down (m = g = l0 = 1); returns the lift-off state."""

    def f(t, s):
        x, y, u, v = s
        l = math.hypot(x, y)
        a = k * (1.0 - l) / l
        return [u, v, a * x, a * y - 1.0]

    def lift_off(t, s):
        return math.hypot(s[0], s[1]) - 1.0

    lift_off.terminal, lift_off.direction = True, 1.0
    s0 = [-math.cos(beta), y0, vx, vy]  # the foot at the origin, ahead of the mass
    sol = solve_ivp(f, (0.0, 10.0), s0, method="DOP853", rtol=1e-12, atol=1e-12,
                    events=lift_off, first_step=1e-6)
    assert sol.status == 1, "no lift-off"
    return sol.y_events[0][0]


def apex_map(y, energy, beta, k):
    """Next apex height from apex height ``y`` at total energy ``energy`` (m = g = l0 = 1)."""
    vx = math.sqrt(2.0 * (energy - y))
    y_td = math.sin(beta)
    vy = -math.sqrt(2.0 * (y - y_td))
    _, y_lo, _, vy_lo = _stance(y_td, vx, vy, beta, k)
    return y_lo + 0.5 * max(vy_lo, 0.0) ** 2


def apex_fixed_point(energy, beta, k, y_guess):
    """Fixed point of the apex map and its derivative there (the SLIP's multiplier)."""
    lo = math.sin(beta) + 0.5 * (y_guess - math.sin(beta))  # above the touch-down height
    y = brentq(lambda z: apex_map(z, energy, beta, k) - z, lo, y_guess + 0.02, xtol=1e-13)

    def central(h):
        return (apex_map(y + h, energy, beta, k) - apex_map(y - h, energy, beta, k)) / (2 * h)

    # Richardson-extrapolated central differences: the map curves strongly here
    return y, (4.0 * central(2e-5) - central(4e-5)) / 3.0


def _apex_of(g):
    """Apex height and energy of a gait (r = 0, flat ground: y_td = sin beta0)."""
    s = g.state
    y_td = g.params.l0 * math.sin(s.beta)
    return y_td + 0.5 * s.yd**2, 0.5 * (s.xd**2 + s.yd**2) + y_td


def _nontrivial(f):
    """The SLIP's multiplier: the non-trivial one that is not the fixed leg angle's 0."""
    lam = f.multipliers[~f.trivial]
    lam = lam[np.abs(lam) > 1e-9]
    assert lam.size == 1
    return lam[0]


@pytest.fixture(scope="module")
def slip_gaits():
    return {name: tslip.find_gait(tslip.preset(name)) for name in ("slip", "slip-human")}


def test_presets_are_the_slip_limit():
    assert {"slip", "slip-human"} <= set(tslip.presets())
    for name in ("slip", "slip-human"):
        p = tslip.preset(name)
        assert p.r == 0.0 and p.c_l == 0.0 and p.omega_r == 0.0
        assert p.leg_reset == "global" and p.alpha_r == p.beta0
        assert isinstance(p.controller, tslip.Passive) and pitch_decoupled(p)
    # slip-human: 80 kg, 1 m, 20 kN/m, 5 m/s, 68 deg (Seyfarth et al. 2002) by hand
    h = tslip.preset("slip-human")
    assert h.k == pytest.approx(20000.0 * 1.0 / (80.0 * 9.81), rel=1e-12)
    assert h.v0 == pytest.approx(5.0 / math.sqrt(9.81 * 1.0), rel=1e-12)
    assert math.degrees(h.beta0) == pytest.approx(68.0, rel=1e-12)
    s = Scaling(M=80.0, g=9.81, L=1.0)
    assert s.to_si(h.k, "stiffness") == pytest.approx(20000.0, rel=1e-12)


@pytest.mark.parametrize("name", ["slip", "slip-human"])
def test_slip_multiplier_matches_an_independent_apex_map(slip_gaits, name):
    g = slip_gaits[name]
    assert g.converged
    f = floquet(g)
    assert f.trivial_kinds.count("pitch") == 2 and f.trivial_kinds.count("energy") == 1
    np.testing.assert_allclose(f.multipliers[f.trivial], 1.0, atol=1e-8)
    y_apex, energy = _apex_of(g)
    y_ref, d_ref = apex_fixed_point(energy, g.params.beta0, g.params.k, y_apex)
    assert y_apex == pytest.approx(y_ref, abs=1e-9)
    lam = _nontrivial(f)
    assert abs(lam.imag) < 1e-12
    assert lam.real == pytest.approx(d_ref, abs=1e-6)
    assert f.max_nontrivial == pytest.approx(abs(d_ref), abs=1e-6)
    assert abs(d_ref) < 1.0 and f.stability == "asymptotic"  # self-stable
    # the same with finite differences of the touch-down map (eq. B.2)
    assert _nontrivial(floquet(g, method="fd")).real == pytest.approx(d_ref, abs=1e-6)


def test_stability_switches_where_the_apex_map_derivative_crosses_one():
    """Along beta0 at fixed speed: labels from the independent |f'| and one boundary only.

    Before the decoupled pitch was set aside, the pitch's Jordan block (two
    multipliers 1, split by rounding) was the "largest non-trivial" one: every
    gait was "neutral" and the boundaries fell where rounding put it above 1.
    """
    p = tslip.preset("slip")
    b = continue_gait(p, "beta0", np.linspace(1.175, 1.35, 8))
    assert b.converged.all()
    d = []
    for g in b.gaits:
        y_apex, energy = _apex_of(g)
        d.append(apex_fixed_point(energy, g.params.beta0, p.k, y_apex)[1])
    d = np.abs(d)
    assert np.any(d < 1.0) and np.any(d > 1.0)  # the range crosses the boundary
    assert list(b.stability) == ["asymptotic" if x < 1.0 else "unstable" for x in d]
    np.testing.assert_allclose(b.max_nontrivial, d, rtol=1e-4)
    (x,) = stability_boundaries(b)  # one boundary, no false ones

    def excess(beta):  # |f'| - 1 on the gait at beta (energy at the touch-down speed v0)
        energy = 0.5 * p.v0**2 + math.sin(beta)
        i = int(np.argmin(np.abs(b.values - beta)))
        return abs(apex_fixed_point(energy, beta, p.k, _apex_of(b.gaits[i])[0])[1]) - 1.0

    i = int(np.argmax(d > 1.0))
    x_ref = brentq(excess, b.values[i - 1], b.values[i], xtol=1e-9)
    assert x == pytest.approx(x_ref, abs=1e-5)
