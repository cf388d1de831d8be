"""The power-law leg spring and the leg thrust (issue 26, section 1) against physics.

The reference here is an independent model written in this file: the TSLIP as a
point-mass trunk in Cartesian coordinates (CoM position and pitch), the massless leg
pushing along the foot-hip line, integrated by scipy's ``solve_ivp`` at rtol 1e-11
with the lift-off and the thrust's switch as events. It shares no code with the
package's polar Lagrangian (eqs 2.3-2.4) or its kernels.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import tslip
from tslip.gait.section import ApexState, apex_map
from tslip.model import _pack as pk
from tslip.simulation import _kernels as kn
from tslip.simulation import _stance

TIGHT = tslip.IntegratorOptions(rtol=1e-12, atol=1e-12, method="dop853")
STATE = np.array([1.05, 0.0, 5.0, -0.3, 0.0])  # a Table 2.1 touch-down


def spring(p, l, l_rest):
    """``F_s`` and ``V`` of the issue's definition, written out."""
    x = (l_rest - l) / p.l0
    n = p.leg_exponent
    return (p.k * p.l0 * math.copysign(abs(x) ** n, x),
            p.k * p.l0**2 * abs(x) ** (n + 1) / (n + 1))


def reference_stance(p, td, l_rest=None):
    """Stance from the touch-down ``td`` (beta, phi, xd, yd, phid) by solve_ivp.

    Returns ``(t_lo, u_lo, l_min)``: lift-off time, CoM state ``(x, y, phi, xd, yd,
    phid)`` (CoM at x = 0 at touch-down, ground at 0) and the leg's minimum length (at the
    thrust's switch, or over 400 samples of the stance without thrust).
    Passive hip (no torque). With ``p.leg_thrust`` the rest length steps to
    ``l0 (1 + d)`` where ``ldot`` first crosses from < 0 to >= 0.
    """
    b, ph, xd, yd, phd = td
    r = p.r
    foot = np.array([0.0 - r * math.sin(ph) + p.l0 * math.cos(b), 0.0])
    u0 = np.array([0.0, p.l0 * math.sin(b) - r * math.cos(ph), ph, xd, yd, phd])

    def leg(u, lr):
        hip = np.array([u[0] - r * math.sin(u[2]), u[1] + r * math.cos(u[2])])
        hv = np.array([u[3] - r * math.cos(u[2]) * u[5], u[4] - r * math.sin(u[2]) * u[5]])
        e = hip - foot
        l = math.hypot(*e)
        e /= l
        ld = e @ hv
        return l, ld, e, spring(p, l, lr)[0] - p.c_l * ld

    def rhs(lr):
        def f(t, u):
            l, ld, e, fl = leg(u, lr)
            rel = (-r * math.sin(u[2]), r * math.cos(u[2]))  # hip - CoM
            torque = rel[0] * fl * e[1] - rel[1] * fl * e[0]
            return [u[3], u[4], u[5], fl * e[0] / p.m, fl * e[1] / p.m - p.g, torque / p.J]
        return f

    def liftoff(lr):
        def g(t, u):
            l, ld, e, fl = leg(u, lr)
            return lr - l if (p.c_l == 0.0 and p.leg_exponent != 1.0) else fl * e[1]
        g.terminal, g.direction = True, -1
        return g

    def switch(t, u):
        return leg(u, p.l0)[1]  # ldot
    switch.terminal, switch.direction = True, 1

    kw = dict(rtol=1e-11, atol=1e-12, method="DOP853", dense_output=True)
    events = [liftoff(p.l0)] + ([switch] if p.leg_thrust > 0 else [])
    sol = solve_ivp(rhs(p.l0), (0.0, 5.0), u0, events=events, **kw)
    l_min = min(leg(sol.sol(t), p.l0)[0] for t in np.linspace(0, sol.t[-1], 400))
    if p.leg_thrust > 0:
        assert len(sol.t_events[1]) == 1, "no switch before lift-off"
        t_sw, u_sw = sol.t_events[1][0], sol.y_events[1][0]
        l_min = leg(u_sw, p.l0)[0]
        lr = p.l0 * (1 + p.leg_thrust)
        sol = solve_ivp(rhs(lr), (t_sw, 5.0), u_sw, events=[liftoff(lr)], **kw)
    assert len(sol.t_events[0]) == 1, "no lift-off"
    return sol.t_events[0][0], sol.y_events[0][0], l_min


def _params(preset, **kw):
    return dataclasses.replace(tslip.preset(preset), **kw)


@pytest.mark.parametrize("n, c_l", [(1.5, 0.0), (0.8, 0.0), (1.5, 0.4), (2.5, 0.0)])
def test_tslip_stance_matches_an_independent_integration(n, c_l):
    p = _params("table2.1", leg_exponent=n, c_l=c_l)
    res = tslip.step(p, STATE, options=TIGHT)
    t_lo, u, _ = reference_stance(p, STATE)
    lo = res.liftoff
    got = np.array([lo.x, lo.y, lo.phi, lo.xd, lo.yd, lo.phid])
    assert abs(res.stance_time - t_lo) < 1e-8
    np.testing.assert_allclose(got, u, rtol=0, atol=1e-8)


@pytest.mark.parametrize("n", [1.5, 0.8])
def test_slip_apex_map_at_fixed_energy_matches_an_independent_integration(n):
    # the n = 1 leg's force at a compression of 0.1 (k_n = k x*^(1-n), issue 26 section 2)
    p = _params("slip", leg_exponent=n, k=25.0 * 0.1 ** (1 - n))
    E = 2.2
    for y in (0.98, 1.02):
        a = ApexState.from_energy(p, y, E)
        s = apex_map(p, a, options=TIGHT)
        assert s.status == tslip.Status.OK
        # reference: fall to the touch-down height, stance, rise to the apex
        b = p.alpha_r  # global reset, no retraction: the leg angle in flight
        yd_td = -math.sqrt(2 * p.g * (y - p.l0 * math.sin(b)))
        _, u, _ = reference_stance(p, (b, 0.0, a.xd, yd_td, 0.0))
        y_apex = u[1] + u[4] ** 2 / (2 * p.g)
        assert abs(s.apex.y - y_apex) < 1e-8
        assert abs(s.apex.xd - u[3]) < 1e-8
        # the map stays on its energy level (V = 0 at the apex)
        assert abs(p.m * p.g * s.apex.y + p.m * s.apex.xd**2 / 2 - E) < 1e-9


@pytest.mark.parametrize("n", [1.5, 0.8, 2.0])
def test_passive_model_conserves_energy_with_the_power_law_potential(n):
    p = _params("table2.1", leg_exponent=n, k=25.0 * 0.2 ** (1 - n))
    tr = tslip.simulate(p, tslip.TouchdownState.from_section(STATE), 1, dt=0.005,
                        options=TIGHT)
    df = tr.to_dataframe()  # a stance and its flight (which may end in a fall)
    assert (df["stance"] > 0).sum() > 20 and (df["stance"] == 0).sum() > 3
    e = df["energy"].to_numpy()
    assert np.ptp(e) < 1e-9 * e[0]
    # the spring holds energy in stance: without V the sum would vary by about V's peak
    st = df.query("stance > 0")
    v_peak = max(spring(p, l, p.l0)[1] for l in st["l"])
    assert v_peak > 1e3 * np.ptp(e)


def test_linear_leg_is_todays_expression_bit_for_bit():
    """n = 1, d = 0 evaluate eq. 2.1 as it was written before the extension (rtol 0)."""
    rng = np.random.default_rng(3)
    for p in (tslip.preset("table2.1"), tslip.preset("table6.1"),
              tslip.Params(leg_exponent=1.0, leg_thrust=0.0, c_l=0.3, k=13.7, l0=0.9)):
        P = pk.pack_params(p)
        assert np.array_equal(P, pk.pack_params(dataclasses.replace(p, leg_exponent=1.0)))
        for _ in range(50):
            y = np.array([rng.uniform(0.5, 1.1), rng.uniform(0.8, 2.2), rng.uniform(-0.3, 0.3),
                          rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-2, 2)])
            l, b, ld = y[0], y[1], y[3]
            old = P[pk.P_K] * (P[pk.P_L0] - l) - P[pk.P_CL] * ld  # main's eq. 2.1
            assert _stance.leg_force(P, l, ld) == old
            assert kn.stance_accel(P, y)[3] == old
            tau = kn.hip_torque(P, y[2], y[4], y[5])
            fx, fy, _ = kn.grf(P, y)
            assert fy == old * math.sin(b) + tau / l * math.cos(b)
            assert fx == -old * math.cos(b) + tau / l * math.sin(b)
            gv = np.empty(_stance.NEVENTS)
            kn.event_values(P, y, gv)
            assert gv[0] == fy and gv[4] == 1.0  # F_y; no switch looked for
            assert _stance.spring_slope(P, l) == -P[pk.P_K]
            assert (_stance.spring_energy(P, l)
                    == 0.5 * P[pk.P_K] * (P[pk.P_L0] - l) * (P[pk.P_L0] - l))


def _fd_jacobian(p, q, step=1e-5):
    cols = []
    for j in range(5):
        e = np.zeros(5)
        e[j] = step
        plus = tslip.step_map(p, q + e, options=TIGHT).q
        minus = tslip.step_map(p, q - e, options=TIGHT).q
        cols.append((plus - minus) / (2 * step))
    return np.array(cols).T


@pytest.mark.parametrize("preset, n", [
    ("table2.1", 1.5),  # lift-off located as l_rest - l = 0
    ("table2.1", 2.0),
    ("table6.1", 1.5),  # damping and hip torque: lift-off on F_y
    ("table6.1", 2.0),
])
def test_exact_jacobian_equals_finite_differences(preset, n):
    g = tslip.find_gait(_params(preset, leg_exponent=n, k=tslip.preset(preset).k * 0.2 ** (1 - n)))
    p, q = g.params, g.state.section()
    res, J = tslip.step_jacobian(p, q, options=TIGHT)
    assert res.status == tslip.Status.OK
    np.testing.assert_allclose(J, _fd_jacobian(p, q), rtol=0, atol=1e-7)


def test_exact_jacobian_is_refused_below_exponent_one():
    p = _params("table2.1", leg_exponent=0.8)
    with pytest.raises(ValueError, match="leg_exponent 0.8 < 1 has no exact Jacobian") as e:
        tslip.step_jacobian(p, STATE)
    assert "\n" not in str(e.value)
    g = tslip.find_gait(_params("slip", leg_exponent=0.8))
    fl = tslip.gait.floquet(g)  # falls back to finite differences
    assert fl.method == "fd" and np.all(np.isfinite(fl.multipliers))
