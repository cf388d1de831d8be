"""The 3-D TSLIP against physics and an independent implementation (issue 43, Part 2).

* the whole body's angular momentum about the fixed foot changes only by gravity's
  moment, with a hip torque, roll and yaw motion and three different inertias;
* a scipy ``solve_ivp`` Newton-Euler model written here (world coordinates, the rotation
  matrix integrated directly) gives the same stance, flight and touch-down with roll,
  yaw and splay;
* energy is conserved by the undamped passive model;
* a crossed leg is a named fall on both sides; bad parameters get one-line errors.

Parameters are away from 1 (m, l0, g) so that a missing factor shows.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicHermiteSpline
from scipy.spatial.transform import Rotation

import tslip
from tslip.model.controllers import ConstantTorque, GlobalPD, Passive
from tslip.spatial import _trunk_kernels as kn
from tslip.spatial.trunk import TrunkStatus, TrunkTouchdown, trunk_energy, trunk_stance, trunk_step
from tslip.spatial.trunk_parameters import TrunkParams

OPT = tslip.IntegratorOptions(rtol=1e-12, atol=1e-12)
EY = np.array([0.0, 1.0, 0.0])

TORQUED = TrunkParams(m=1.4, J=0.11, J_roll=0.07, J_yaw=0.045, r=0.25, k=28.0, l0=0.9, g=1.3,
                      c_l=0.05, splay=0.08, alpha_r=0.95, omega_r=0.8,
                      controller=ConstantTorque(tau_c=0.25, c_h=0.05))
PASSIVE = TrunkParams(m=1.4, J=0.11, J_roll=0.07, J_yaw=0.045, r=0.25, k=28.0, l0=0.9, g=1.3,
                      splay=0.08, alpha_r=0.95, omega_r=0.8, controller=Passive())


def _leg(tp, side, a, R):
    """World direction of the leg at hip angle ``a`` (the issue's formula, written here)."""
    d = np.array([math.cos(a), -math.sin(a) * math.cos(tp.splay),
                  side * math.sin(a) * math.sin(tp.splay)])
    return R @ d


def _touchdown(tp, side=1, a=1.0, yaw=0.1, pitch=0.05, roll=-0.06, v=(2.2, -0.4, 0.15),
               w=(0.3, -0.25, -0.2)):
    """A touch-down with the foot on the ground, at hip angle ``a`` from the given attitude."""
    rot = Rotation.from_euler("YZX", [yaw, pitch, roll])
    R = rot.as_matrix()
    x, y, z, qw = rot.as_quat()
    off = tp.r * R[:, 1] + tp.l0 * _leg(tp, side, a, R)  # foot - CoM
    c = np.array([0.3, -off[1], -0.1])
    state = np.array([*c, *v, qw, x, y, z, *w])
    return TrunkTouchdown(state, c + off, side)


# --- an independent model: Newton-Euler in world coordinates, R integrated directly ----

def _split(s):
    return s[0:3], s[3:6], s[6:15].reshape(3, 3), s[15:18]


def _ref_stance_rhs(tp, foot):
    Jb = np.diag([tp.J_roll, tp.J_yaw, tp.J])
    a0, a1, a2, a3 = tp.controller.torque_coefficients()

    def forces(s):
        c, v, R, w = _split(s)
        hip = c + tp.r * R[:, 1]
        hipd = v + np.cross(w, tp.r * R[:, 1])
        e = foot - hip
        l = np.linalg.norm(e)
        u = e / l
        ld = -u @ hipd
        Fl = tp.k * (tp.l0 - l) - tp.c_l * ld
        # hip angle of the leg's projection on the sagittal plane, and its rate
        ub = R.T @ u
        ubd = R.T @ ((-hipd - u * ld) / l) - R.T @ np.cross(w, u)
        alphad = (ub[0] * -ubd[1] - (-ub[1]) * ubd[0]) / (ub[0] ** 2 + ub[1] ** 2)
        theta, thetad = _pitch_and_rate(R, R.T @ w)
        tau = a0 + a1 * theta + a2 * (alphad - thetad) + a3 * thetad
        tvec = tau * R[:, 2]
        tperp = tvec - (tvec @ u) * u
        F = -Fl * u + np.cross(tperp, u) / l
        return F, tperp, hip, c, R, w

    def f(t, s):
        F, tperp, hip, c, R, w = forces(s)
        I = R @ Jb @ R.T
        T = np.cross(hip - c, F) + tperp
        wd = np.linalg.solve(I, T - np.cross(w, I @ w))
        Rd = np.cross(w[:, None], R, axis=0)  # [w]x R, column by column
        return np.concatenate([s[3:6], F / tp.m - tp.g * EY, Rd.ravel(), wd])

    def fy(t, s):
        return forces(s)[0][1]

    fy.terminal, fy.direction = True, -1
    return f, fy


def _hip_angle(tp, t, R):
    """The flight hip angle: eq. 2.17's swing, plus the pitch under the global reset."""
    a = tp.alpha_r + tp.omega_r * t
    if tp.leg_reset == "global":
        a += Rotation.from_matrix(R).as_euler("YZX")[1]
    return a


def _pitch_and_rate(R, wb):
    """Pitch of R = R_y(yaw) R_z(pitch) R_x(roll) and its rate, from the Euler-angle
    kinematics w_b = Rx^T Rz^T (0, yawd, 0) + Rx^T (0, 0, pitchd) + (rolld, 0, 0)."""
    _, th, ph = Rotation.from_matrix(R).as_euler("YZX")
    Rz = Rotation.from_euler("Z", th).as_matrix()
    Rx = Rotation.from_euler("X", ph).as_matrix()
    A = np.column_stack([Rx.T @ Rz.T @ EY, Rx.T @ [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    return th, np.linalg.solve(A, wb)[1]


def _ref_flight(tp, side):
    Jb = np.diag([tp.J_roll, tp.J_yaw, tp.J])

    def f(t, s):
        _, _, R, w = _split(s)
        I = R @ Jb @ R.T
        wd = np.linalg.solve(I, -np.cross(w, I @ w))
        return np.concatenate([s[3:6], -tp.g * EY, np.cross(w[:, None], R, axis=0).ravel(), wd])

    def foot_y(t, s):
        c, _, R, _ = _split(s)
        return (c + tp.r * R[:, 1] + tp.l0 * _leg(tp, side, _hip_angle(tp, t, R), R))[1]

    foot_y.terminal, foot_y.direction = True, -1
    return f, foot_y


def _to_world(y):
    R = Rotation.from_quat([y[7], y[8], y[9], y[6]]).as_matrix()
    return np.concatenate([y[0:6], R.ravel(), R @ y[10:13]])


def _from_world(s):
    c, v, R, w = _split(s)
    x, y, z, qw = Rotation.from_matrix(R).as_quat()
    q = np.array([qw, x, y, z])
    return np.concatenate([c, v, q, R.T @ w])


@pytest.mark.parametrize("tp", [TORQUED, dataclasses.replace(
    TORQUED, leg_reset="global", alpha_r=0.8, controller=GlobalPD(Kp=2.0, Kd=0.3, phi_ref=0.1))],
    ids=["local-torque", "global-pd"])
def test_stride_agrees_with_an_independent_newton_euler_model(tp):
    td = _touchdown(tp)
    r = trunk_step(tp, td, options=OPT)
    assert r.ok, r.status
    f, ev = _ref_stance_rhs(tp, td.foot)
    sol = solve_ivp(f, (0, 5), _to_world(td.y), method="DOP853", rtol=1e-12, atol=1e-12,
                    events=ev)
    assert sol.status == 1
    ts, slo = sol.t_events[0][0], sol.y_events[0][0]
    assert abs(r.stance_time - ts) < 1e-9
    lo = _to_world(r.liftoff)
    np.testing.assert_allclose(lo, slo, rtol=0, atol=1e-8)
    # the motion left the sagittal plane: roll, yaw and lateral velocity are all there
    assert abs(slo[5]) > 0.05 and abs(r.liftoff[10]) > 0.05 and abs(r.liftoff[11]) > 0.05
    f, ev = _ref_flight(tp, -td.side)
    sol = solve_ivp(f, (0, 5), slo, method="DOP853", rtol=1e-12, atol=1e-12, events=ev)
    assert sol.status == 1
    tf, std = sol.t_events[0][0], sol.y_events[0][0]
    assert abs(r.flight_time - tf) < 1e-9
    np.testing.assert_allclose(_to_world(r.state.y), std, rtol=0, atol=1e-8)
    c, _, R, _ = _split(std)
    foot = c + tp.r * R[:, 1] + tp.l0 * _leg(tp, -td.side, _hip_angle(tp, tf, R), R)
    np.testing.assert_allclose(r.state.foot, foot, rtol=0, atol=1e-8)
    assert r.state.side == -td.side


@pytest.mark.parametrize("side", [1, -1])
def test_angular_momentum_about_the_foot_changes_by_gravity_alone(side):
    tp = TORQUED
    td = _touchdown(tp, side=side, roll=0.08 * side)
    status, ts, _, rec, _ = trunk_stance(tp, td, options=OPT, rows=100000)
    assert status == TrunkStatus.OK and rec.shape[0] > 20
    p, m, g = td.foot, tp.m, tp.g
    Jd = np.array([tp.J_roll, tp.J_yaw, tp.J])
    t, Y = rec[:, 0], rec[:, 1:]
    L = np.empty((len(t), 3))
    tau = np.empty(len(t))
    P = tp.packed(side)
    P[kn.P_FOOT:kn.P_FOOT + 3] = p
    o = np.empty(16)
    for i, y in enumerate(Y):
        R = Rotation.from_quat([y[7], y[8], y[9], y[6]]).as_matrix()
        L[i] = np.cross(y[0:3] - p, m * y[3:6]) + R @ (Jd * y[10:13])
        kn.stance_terms(P, y, np.empty((3, 3)), o)
        tau[i] = o[11]
    assert np.min(np.abs(tau)) > 0.05  # a real hip torque acts throughout
    # gravity's moment (c - p) x (-m g e_y) = m g ((c - p)_z, 0, -(c - p)_x), integrated
    # with the recorded positions and velocities (cubic Hermite: exact to O(h^5))
    grav = np.zeros_like(L)
    for k, (col, sgn) in enumerate(((2, 1.0), (None, 0.0), (0, -1.0))):
        if col is None:
            continue
        spl = CubicHermiteSpline(t, Y[:, col] - p[col], Y[:, 3 + col])
        grav[:, k] = sgn * m * g * np.array([spl.integrate(0.0, ti) for ti in t])
    np.testing.assert_allclose(L - L[0], grav, rtol=0, atol=1e-9)
    assert np.ptp(L[:, 0]) > 0.05 and np.ptp(L[:, 2]) > 0.05  # and it did change


def test_undamped_passive_model_conserves_energy():
    tp = PASSIVE
    td = _touchdown(tp)
    E0 = trunk_energy(tp, td.y)
    status, _, ylo, rec, _ = trunk_stance(tp, td, options=OPT, rows=100000)
    assert status == TrunkStatus.OK
    Es = [trunk_energy(tp, row[1:], td.foot) for row in rec]
    assert max(abs(E - E0) for E in Es) < 1e-9 * E0
    r = trunk_step(tp, td, options=OPT)
    assert r.ok
    assert abs(trunk_energy(tp, r.liftoff) - E0) < 1e-9 * E0
    assert abs(trunk_energy(tp, r.state.y) - E0) < 1e-9 * E0
    # the torque-free flight keeps |L| about the CoM (its world vector, in fact)
    RL = Rotation.from_quat(np.roll(r.liftoff[6:10], -1)).as_matrix()
    RT = Rotation.from_quat(np.roll(r.state.y[6:10], -1)).as_matrix()
    Jd = np.array([tp.J_roll, tp.J_yaw, tp.J])
    np.testing.assert_allclose(RL @ (Jd * r.liftoff[10:13]), RT @ (Jd * r.state.y[10:13]),
                               atol=1e-10)


@pytest.mark.parametrize("side", [1, -1])
def test_crossed_leg_at_touchdown_is_a_named_fall_on_both_sides(side):
    tp = PASSIVE
    # rolling towards the leg's side puts its foot on the far side of the mid-plane
    good = _touchdown(tp, side=side, roll=-0.05 * side, v=(2.2, -0.4, 0.0))
    bad = _touchdown(tp, side=side, roll=0.3 * side, v=(2.2, -0.4, 0.0))
    assert side * (bad.foot[2] - bad.y[2]) < 0.0 < side * (good.foot[2] - good.y[2])
    assert trunk_step(tp, bad, options=OPT).status == TrunkStatus.FALL_CROSSED_LEG
    assert trunk_step(tp, good, options=OPT).status != TrunkStatus.FALL_CROSSED_LEG


@pytest.mark.parametrize("side", [1, -1])
def test_a_flight_that_rolls_the_next_leg_across_is_a_crossed_leg(side):
    # the next leg is -side; a fast roll towards it in flight lands it crossed
    tp = TrunkParams(alpha_r=0.95, omega_r=0.8)
    calm = _touchdown(tp, side=side, yaw=0.0, roll=0.0, pitch=0.0, v=(2.5, -0.5, 0.0),
                      w=(0.0, 0.0, 0.0))
    r = trunk_step(tp, calm, options=OPT)
    assert r.ok and r.state.side == -side
    roll_rate = -side * 1.0  # positive rolls the foot to -z: crossed for a right leg
    rolled = TrunkTouchdown(np.concatenate([calm.y[:10], [roll_rate, 0.0, 0.0]]), calm.foot,
                            side)
    r = trunk_step(tp, rolled, options=OPT)
    assert r.status == TrunkStatus.FALL_CROSSED_LEG
    assert r.state is not None and r.state.side * (r.state.foot[2] - r.state.y[2]) < 0.0


@pytest.mark.parametrize(("change", "field"), [
    ({"splay": 2.0}, "splay"), ({"J_roll": 0.0}, "J_roll"), ({"J_yaw": -1.0}, "J_yaw"),
    ({"leg_reset": "inertial"}, "leg_reset"), ({"retraction": "x"}, "retraction"),
    ({"leg_thrust": 0.9}, "leg_thrust"), ({"alpha_stop": 4.0}, "alpha_stop"),
    ({"k": float("nan")}, "k"),
])
def test_bad_parameters_are_refused_in_one_line(change, field):
    with pytest.raises(ValueError, match=f"TrunkParams.{field}") as err:
        TrunkParams(**change)
    assert "\n" not in str(err.value)


def test_bad_touchdown_states_are_refused_in_one_line():
    y = _touchdown(PASSIVE).y
    for kwargs, word in (({"y": y[:12], "foot": np.zeros(3)}, "y"),
                         ({"y": y, "foot": np.zeros(2)}, "foot"),
                         ({"y": y, "foot": np.zeros(3), "side": 0}, "side")):
        with pytest.raises(ValueError, match=f"TrunkTouchdown.{word}"):
            TrunkTouchdown(**kwargs)
