"""The power-law leg away from unit length, mass and gravity (issue 40, section 6).

``F_s = k l0 sgn(x) |x|^n`` and ``V = k l0^2 |x|^(n+1) / (n+1)`` with ``x = (l_rest -
l) / l0`` (docs/model.md, "Leg spring and thrust"): at ``l0 = 1`` the factors ``l0`` and
``l0^2`` are invisible, and every other power-law test runs there. Here ``l0``, ``m`` and
``g`` are away from 1, against references written from those formulas and the thesis's
mechanics: a Newton-Euler stance in Cartesian coordinates (``test_leg_exponent.py``'s,
general in ``l0``: a point-mass trunk with pitch inertia, the massless leg pushing along
the foot-hip line, eqs 2.5-2.6) integrated by scipy's ``solve_ivp``, energy conservation
with the power-law ``V``, and the one-dimensional bounce ``m l'' = F_s(l)``.

The compiled kernels (``simulation._stance``), the recorded run's force and energy columns
(``simulation._record``), the readable model (``model.dynamics``) and the bounce time
(``gait.stride``) each compute the power law; a test below fails when any one of them
drops its ``l0`` factor.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import tslip
from tslip.gait.stride import bounce_time
from tslip.model import _pack as pk
from tslip.model import dynamics as dyn
from tslip.simulation import _kernels as kn

from .test_leg_exponent import reference_stance
from .test_leg_exponent import spring as power_law

TIGHT = tslip.IntegratorOptions(rtol=1e-12, atol=1e-12, method="dop853")
#: A touch-down (beta, phi, xd, yd, phid) of a fast run: the leg at Table 2.1's angle.
STATE = np.array([1.05, 0.05, 4.0, -0.3, 0.2])


def scaled(n, *, l0=0.9, m=1.3, g=0.8, c_l=0.0, d=0.0, compression=0.15):
    """Table 2.1 with ``l0, m, g`` away from 1 and a stiffness ``k`` that compresses the
    power-law leg about as far as the linear one (the force ``k l0 x^n`` equals Table 2.1's
    ``k x`` scaled by ``m g`` at ``x = compression``)."""
    k = 25.0 * m * g * compression ** (1 - n) / l0
    return dataclasses.replace(tslip.preset("table2.1"), l0=l0, m=m, g=g, J=0.1 * m,
                               k=k, c_l=c_l, leg_exponent=n, leg_thrust=d)


@pytest.mark.parametrize("n, c_l, d, l0", [
    (1.5, 0.0, 0.0, 0.9),   # lift-off where the spring relaxes
    (0.8, 0.0, 0.0, 0.9),
    (1.5, 0.4, 0.0, 0.9),   # damped: lift-off on F_y
    (2.0, 0.0, 0.0, 1.15),
    (1.5, 0.0, 0.1, 0.9),   # thrust: x = (l0 (1 + d) - l) / l0 after the switch
])
def test_stance_matches_an_independent_integration(n, c_l, d, l0):
    p = scaled(n, l0=l0, c_l=c_l, d=d)
    t_lo, u, l_min = reference_stance(p, STATE)
    assert 0.7 * l0 < l_min < 0.95 * l0  # a real compression, the force law well probed
    res = tslip.step(p, STATE, options=TIGHT)
    lo = res.liftoff
    got = np.array([lo.x, lo.y, lo.phi, lo.xd, lo.yd, lo.phid])
    assert abs(res.stance_time - t_lo) < 1e-8
    np.testing.assert_allclose(got, u, rtol=0, atol=1e-8)


@pytest.mark.parametrize("n", [1.5, 0.8])
def test_recorded_energy_is_constant_with_the_power_law_potential(n):
    """The recorded run's energy column (kinetic + gravity + ``V``) of a passive,
    undamped stride stays constant, and ``V`` matters in it."""
    p = scaled(n)
    tr = tslip.simulate(p, tslip.TouchdownState.from_section(STATE), 1, dt=0.004,
                        options=TIGHT)
    df = tr.to_dataframe()
    st = df[df["stance"] > 0]
    assert len(st) > 20 and (df["stance"] == 0).sum() > 3
    e = df["energy"].to_numpy()
    # the same sum from the recorded state, with V written here
    kin = 0.5 * p.m * (df["xd"] ** 2 + df["yd"] ** 2) + 0.5 * p.J * df["phid"] ** 2
    v = [power_law(p, l, p.l0)[1] if s > 0 else 0.0 for l, s in zip(df["l"], df["stance"])]
    np.testing.assert_allclose(e, kin + p.m * p.g * df["y"] + v, rtol=0, atol=1e-10)
    assert np.ptp(e) < 1e-9 * e[0]
    v_peak = max(v)
    assert v_peak > 1e4 * np.ptp(e)


@pytest.mark.parametrize("n, c_l", [(1.5, 0.4), (0.8, 0.0)])
def test_recorded_leg_force_is_the_power_law(n, c_l):
    """The leg force the recorded ground force carries, ``F_l = F_y sin(beta) - F_x
    cos(beta)`` (eqs 2.5-2.6, no hip torque), is ``k l0 |x|^n - c_l ldot`` on every stance
    row."""
    p = scaled(n, c_l=c_l)
    tr = tslip.simulate(p, tslip.TouchdownState.from_section(STATE), 1, dt=0.004,
                        options=TIGHT)
    st = tr.to_dataframe().query("stance > 0")
    b = st["beta"].to_numpy()
    got = st["Fy"].to_numpy() * np.sin(b) - st["Fx"].to_numpy() * np.cos(b)
    want = [power_law(p, l, p.l0)[0] - p.c_l * ld for l, ld in zip(st["l"], st["ld"])]
    assert max(want) > 0.5 * p.m * p.g  # the spring is loaded
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("n", [1.5, 0.8, 2.5])
def test_readable_model_is_the_power_law(rng, n):
    """``model.dynamics`` (the reference the kernels are read against) computes the same
    force and potential, before and after a thrust's switch, and its stance right-hand
    side equals the kernel's (itself checked against the integration above)."""
    p = scaled(n, c_l=0.3)
    P = pk.pack_params(p)
    out = np.empty(6)
    for _ in range(20):
        l = rng.uniform(0.6, 1.05) * p.l0
        lr = p.l0 * rng.choice([1.0, 1.1])
        f, v = power_law(p, l, lr)
        assert dyn.spring_force(p, l, lr) == pytest.approx(f, rel=1e-13, abs=1e-13)
        assert dyn.spring_energy(p, l, lr) == pytest.approx(v, rel=1e-13, abs=1e-13)
        y = np.array([l, rng.uniform(0.8, 2.2), rng.uniform(-0.3, 0.3), rng.normal(),
                      rng.normal(), rng.normal()])
        assert dyn.leg_force(p, y[:3], y[3:]) == pytest.approx(
            power_law(p, l, p.l0)[0] - p.c_l * y[3], rel=1e-13, abs=1e-13)
        kn.rhs(P, y, out)
        np.testing.assert_allclose(out, dyn.stance_rhs(p, y), rtol=1e-11, atol=1e-11)


@pytest.mark.parametrize("n, l0", [(1.5, 0.9), (0.8, 1.2), (2.0, 0.9)])
def test_bounce_time_is_that_of_the_one_dimensional_bounce(n, l0):
    """``gait.stride.bounce_time`` at a leg speed: the time ``m l'' = F_s(l)`` spends
    below ``l0`` after arriving there at that speed (no gravity, as eq. 3.9)."""
    p = scaled(n, l0=l0)
    speed = 0.7

    def f(t, u):
        return [u[1], power_law(p, u[0], p.l0)[0] / p.m]

    def back(t, u):
        return u[0] - p.l0
    back.terminal, back.direction = True, 1
    sol = solve_ivp(f, (0.0, 10.0), [p.l0, -speed], events=back, rtol=1e-12, atol=1e-13,
                    method="DOP853")
    assert len(sol.t_events[0]) == 1
    assert bounce_time(p, speed) == pytest.approx(sol.t_events[0][0], rel=1e-8)
