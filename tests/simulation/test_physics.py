"""Physical consistency of simulated runs: energy, momentum, forces, work.

These tests use only the public trajectory columns and the thesis's physics:
total mechanical energy ``E = m v^2 / 2 + J phid^2 / 2 + m g y + k (l0 - l)^2 / 2``,
the ground reaction force of eqs 2.5-2.6 as the only external force besides
gravity (the leg and foot are massless), and the hip torque doing work on the
local hip angle ``alpha = beta + phi`` (eq. A.9).
"""

from __future__ import annotations

import dataclasses
import math
from functools import cache

import numpy as np
import pytest

import tslip
from tslip.gait import find_gait

TIGHT = tslip.IntegratorOptions(rtol=1e-12, atol=1e-12)


@cache
def gait(name: str):
    g = find_gait(tslip.preset(name))
    assert g.residual < 1e-2, g.message
    return g.params, g.state


def energy(p: tslip.Params, y, xd, yd, phid, l):
    return (0.5 * p.m * (xd**2 + yd**2) + 0.5 * p.J * phid**2 + p.m * p.g * y
            + 0.5 * p.k * (p.l0 - l) ** 2)


def energy_cols(p: tslip.Params, traj: tslip.Trajectory, rows=slice(None)) -> np.ndarray:
    return energy(p, traj["y"][rows], traj["xd"][rows], traj["yd"][rows], traj["phid"][rows],
                  traj["l"][rows])


def touchdown_energy(p: tslip.Params, s: tslip.TouchdownState) -> float:
    """Energy just after touch-down: l = l0, CoM height from eq. 2.9."""
    y = s.h + p.l0 * math.sin(s.beta) - p.r * math.cos(s.phi)
    return float(energy(p, y, s.xd, s.yd, s.phid, p.l0))


def stance_rows(traj: tslip.Trajectory, i: int) -> np.ndarray:
    rows = np.nonzero((traj["step"] == i) & (traj["stance"] == 1))[0]
    assert rows.size > 10
    assert np.all(np.diff(rows) == 1), "stance rows of one step are contiguous"
    return rows


def hip_torque(p: tslip.Params, phi, phid, alphad):
    c = p.controller
    if isinstance(c, tslip.Passive):
        return np.zeros_like(phi)
    if isinstance(c, tslip.GlobalPD):
        return c.Kp * (c.phi_ref - phi) + c.Kd * (c.phid_ref - phid)
    if isinstance(c, tslip.LocalVelocity):
        return c.Kd * (c.alphad_ref - alphad)
    if isinstance(c, tslip.ConstantTorque):
        return c.tau_c - c.c_h * alphad
    raise TypeError(c)


# ---------------------------------------------------------------------------
# (a) energy conservation of the passive model
# ---------------------------------------------------------------------------


def test_passive_energy_conserved_over_100_steps():
    """Relative energy drift < 1e-8 over 100 strides at tolerance 1e-10."""
    p, s = gait("table2.1")
    opts = tslip.IntegratorOptions(rtol=1e-10, atol=1e-10)
    traj = tslip.simulate(p, s, 100, options=opts)
    assert traj.status == tslip.Status.OK and len(traj.steps) == 100
    tds = traj.touchdowns
    assert len(tds) == 101
    E0 = touchdown_energy(p, s)
    e_td = np.array([touchdown_energy(p, td) for td in tds])
    drift_td = np.max(np.abs(e_td - E0)) / E0
    # the whole sampled trajectory, from the columns and the energy column
    e_cols = energy_cols(p, traj)
    drift_cols = np.max(np.abs(e_cols - E0)) / E0
    drift_col = np.max(np.abs(traj["energy"] - E0)) / E0
    print(f"energy drift: touch-downs {drift_td:.2e}, samples {drift_cols:.2e}, "
          f"energy column {drift_col:.2e}")
    assert drift_td < 1e-8
    assert drift_cols < 1e-8
    assert drift_col < 1e-8
    np.testing.assert_allclose(traj["energy"], e_cols, rtol=1e-13, atol=0)
    # the run actually goes somewhere: 100 strides forward, time increasing
    assert traj["x"][-1] > 100 * 0.5 * (p.v0 * 0.4)
    assert np.all(np.diff(traj["t"]) > 0)


# ---------------------------------------------------------------------------
# (b) ground impulse equals momentum change
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["table2.1", "table2.1-local-velocity", "table6.1"])
def test_grf_impulse_equals_momentum_change(name):
    """Trapezoid of (Fx, Fy) over a stance equals m (v_LO - v_TD) + (0, m g t_s).

    Tolerance: the composite trapezoid error bound ``t_s h^2 max|F''| / 12``
    with ``h`` the largest sample spacing and ``F''`` estimated by second
    differences of the samples, doubled, plus 1e-9 for the integrator.
    """
    p, s = gait(name)
    dt = 1e-4
    traj = tslip.simulate(p, s, 2, dt=dt, options=TIGHT)
    assert traj.status == tslip.Status.OK
    for i, st in enumerate(traj.steps):
        rows = stance_rows(traj, i)
        t = traj["t"][rows]
        assert t[-1] - t[0] == pytest.approx(st.stance_time, abs=1e-12)
        assert np.max(np.diff(t)) <= dt * (1 + 1e-9)
        ix = np.trapezoid(traj["Fx"][rows], t)
        iy = np.trapezoid(traj["Fy"][rows], t)
        m, g = p.m, p.g
        px = m * (st.liftoff.xd - st.start.xd)
        py = m * (st.liftoff.yd - st.start.yd) + m * g * st.stance_time
        # the trajectory's velocity columns at the stance ends carry the same momenta
        assert traj["xd"][rows[0]] == pytest.approx(st.start.xd, abs=1e-12)
        assert traj["yd"][rows[-1]] == pytest.approx(st.liftoff.yd, abs=1e-12)
        h = np.max(np.diff(t))
        tol = []
        for col in ("Fx", "Fy"):
            F = traj[col][rows]
            d2 = np.max(np.abs(np.diff(F, 2))) / h**2
            tol.append(2 * st.stance_time * h**2 * d2 / 12 + 1e-9)
        print(f"{name} step {i}: impulse error ({ix - px:.1e}, {iy - py:.1e}), "
              f"tolerance ({tol[0]:.1e}, {tol[1]:.1e})")
        assert abs(ix - px) < tol[0]
        assert abs(iy - py) < tol[1]
        assert st.impulse == pytest.approx((px, py), abs=1e-14)
        # the vertical impulse is substantial: a real check, not 0 == 0
        assert iy > 0.5 * m * g * st.stance_time


# ---------------------------------------------------------------------------
# (c) GRF of eqs 2.5-2.6 is the force that accelerates the body
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["table2.1", "table2.1-global-pd", "table2.1-local-velocity",
                                  "table2.1-constant-torque", "table6.1"])
def test_grf_equals_mass_times_acceleration(name):
    """(Fx, Fy) = m a + (0, m g) and J phidd = tau - r (Fx cos phi + Fy sin phi).

    Accelerations come from second-order finite differences of the sampled
    velocities (dt = 1e-4); their truncation error is about
    ``dt^2 / 6 |F'''| / m`` ~ 1e-5 here, so the tolerance is 1e-4 of the peak
    force. The torque and GRF columns are also checked against the
    controller law and eqs 2.5-2.6 evaluated on the sampled state (1e-10).
    """
    p, s = gait(name)
    traj = tslip.simulate(p, s, 1, dt=1e-4, options=TIGHT)
    assert traj.status == tslip.Status.OK
    rows = stance_rows(traj, 0)
    col = {c: traj[c][rows] for c in ("t", "x", "y", "xd", "yd", "phi", "phid", "l", "beta",
                                      "ld", "betad", "alpha", "Fx", "Fy", "tau")}
    t, b, l = col["t"], col["beta"], col["l"]
    # kinematics of eq. A.3 / A.5 hold on the samples
    np.testing.assert_allclose(col["alpha"], b + col["phi"], atol=1e-14)
    foot_x = col["x"] + l * np.cos(b) - p.r * np.sin(col["phi"])
    np.testing.assert_allclose(foot_x, traj.steps[0].foot_x, atol=1e-12)
    np.testing.assert_allclose(
        col["y"], s.h + l * np.sin(b) - p.r * np.cos(col["phi"]), atol=1e-12)
    # controller law and GRF of eqs 2.5-2.6 from the sampled state
    tau = hip_torque(p, col["phi"], col["phid"], col["betad"] + col["phid"])
    np.testing.assert_allclose(col["tau"], tau, rtol=0, atol=1e-10)
    Fl = p.k * (p.l0 - l) - p.c_l * col["ld"]
    Fx = -Fl * np.cos(b) + tau / l * np.sin(b)
    Fy = Fl * np.sin(b) + tau / l * np.cos(b)
    np.testing.assert_allclose(col["Fx"], Fx, rtol=0, atol=1e-10)
    np.testing.assert_allclose(col["Fy"], Fy, rtol=0, atol=1e-10)
    if name != "table2.1":
        assert np.max(np.abs(tau)) > 0.05  # the torque terms are exercised
    # Newton-Euler with finite-difference accelerations
    ax = np.gradient(col["xd"], t, edge_order=2)
    ay = np.gradient(col["yd"], t, edge_order=2)
    aphi = np.gradient(col["phid"], t, edge_order=2)
    inner = slice(2, -2)
    Fmax = np.max(np.hypot(Fx, Fy))
    tol = 1e-4 * Fmax
    err_x = np.max(np.abs(Fx - p.m * ax)[inner])
    err_y = np.max(np.abs(Fy - p.m * (ay + p.g))[inner])
    moment = tau - p.r * (Fx * np.cos(col["phi"]) + Fy * np.sin(col["phi"]))
    err_phi = np.max(np.abs(moment - p.J * aphi)[inner])
    print(f"{name}: |F - m a| max ({err_x:.1e}, {err_y:.1e}), pitch {err_phi:.1e}, "
          f"tolerance {tol:.1e}")
    assert err_x < tol and err_y < tol and err_phi < tol
    # velocities are derivatives of positions (consistency of the columns)
    vx = np.gradient(col["x"], t, edge_order=2)
    vy = np.gradient(col["y"], t, edge_order=2)
    np.testing.assert_allclose(vx[inner], col["xd"][inner], atol=1e-5)
    np.testing.assert_allclose(vy[inner], col["yd"][inner], atol=1e-5)


# ---------------------------------------------------------------------------
# (d) damping dissipates
# ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "kind", ["leg", "hip"],
)
def test_damping_dissipates_monotonically(kind):
    """Leg damping (dE/dt = -c_l ld^2) or hip damping (-c_h alphad^2), no torque source.

    Energy is non-increasing sample to sample over the stance, and the total
    loss equals the dissipation integral within the trapezoid error (1e-6).
    """
    p, s = gait("table2.1")
    if kind == "leg":
        p = dataclasses.replace(p, c_l=0.5)
    else:
        p = dataclasses.replace(p, controller=tslip.ConstantTorque(tau_c=0.0, c_h=0.3))
    traj = tslip.simulate(p, s, 1, dt=1e-4, options=TIGHT)
    assert traj.status == tslip.Status.OK
    rows = stance_rows(traj, 0)
    t = traj["t"][rows]
    E = energy_cols(p, traj, rows)
    np.testing.assert_allclose(traj["energy"][rows], E, rtol=1e-13)
    dE = np.diff(E)
    assert np.all(dE <= 1e-12 * E[0]), f"energy rises by {dE.max():.2e}"
    if kind == "leg":
        power = p.c_l * traj["ld"][rows] ** 2
    else:
        power = 0.3 * (traj["betad"][rows] + traj["phid"][rows]) ** 2
    loss = np.trapezoid(power, t)
    print(f"{kind} damping: loss {E[0] - E[-1]:.6e}, dissipation integral {loss:.6e}")
    assert E[0] - E[-1] > 1e-3  # a real loss
    assert E[0] - E[-1] == pytest.approx(loss, abs=1e-6)
    # the flight that follows is conservative (ballistic)
    fl = np.nonzero((traj["step"] == 0) & (traj["stance"] == 0))[0]
    assert fl.size > 10
    Ef = energy_cols(p, traj, fl)
    np.testing.assert_allclose(Ef, Ef[0], rtol=1e-13)


# ---------------------------------------------------------------------------
# (e) constant torque without damping: work of the hip torque
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("tau_c", [0.2, -0.1])
def test_constant_torque_work(tau_c):
    """E(t) - E(0) = tau_c (alpha(t) - alpha(0)) through every stance (c_l = c_h = 0).

    Over a stride the leg reset at lift-off also removes the spring energy
    k (l0 - l_LO)^2 / 2 (l_LO != l0 because F_y = 0 with tau != 0), so the
    touch-down energies obey E_{n+1} - E_n = tau_c dalpha - k (l0 - l_LO)^2 / 2.
    """
    p, s = gait("table2.1")
    p = dataclasses.replace(p, c_l=0.0, controller=tslip.ConstantTorque(tau_c=tau_c, c_h=0.0))
    n = 3
    traj = tslip.simulate(p, s, n, dt=1e-3, options=TIGHT)
    assert traj.status == tslip.Status.OK and len(traj.steps) == n
    worst = 0.0
    for i, st in enumerate(traj.steps):
        rows = stance_rows(traj, i)
        E = energy_cols(p, traj, rows)
        alpha = traj["alpha"][rows]
        work = tau_c * (alpha - alpha[0])
        err = np.max(np.abs(E - E[0] - work))
        worst = max(worst, err)
        assert err < 1e-9 * E[0], err
        assert abs(work[-1]) > 1e-3  # the torque did measurable work
        lo = st.liftoff
        assert abs(lo.l - p.l0) > 1e-6  # the spring is still loaded at lift-off
        e_next = touchdown_energy(p, st.state)
        e_here = touchdown_energy(p, st.start)
        dalpha = (lo.beta + lo.phi) - (st.start.beta + st.start.phi)
        expect = tau_c * dalpha - 0.5 * p.k * (p.l0 - lo.l) ** 2
        assert e_next - e_here == pytest.approx(expect, abs=1e-9)
    print(f"tau_c {tau_c}: worst |E - E0 - tau dalpha| {worst:.2e}")
