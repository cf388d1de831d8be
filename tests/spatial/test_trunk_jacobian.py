"""The 3-D TSLIP's exact Jacobian (variational equations with event-time corrections)
against central differences of the map and of its pieces, and against the model's
symmetries (yaw invariance, energy conservation)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import tslip
from tslip.model.controllers import ConstantTorque, GlobalPD, LocalVelocity
from tslip.spatial import _trunk_kernels as kn
from tslip.spatial import _trunk_variational as tv
from tslip.spatial.lateral import lateral_multipliers, table21_gait, table21_params
from tslip.spatial.trunk import TrunkTouchdown, trunk_energy
from tslip.spatial.trunk_jacobian import chart_in, chart_out, one_step_jacobian
from tslip.spatial.trunk_parameters import TrunkParams
from tslip.spatial.trunk_section import (
    from_section,
    one_step_map,
    section,
    two_step_jacobian,
    yaw_rotated,
)

OPT = tslip.IntegratorOptions(rtol=1e-12, atol=1e-12)
H = 1e-5  # the central differences' step on the section
#: Parameters away from 1 (m, l0, g, the inertias), with damping and a hip torque
ODD = TrunkParams(m=1.4, J=0.11, J_roll=0.07, J_yaw=0.045, r=0.25, k=28.0, l0=0.9, g=1.3,
                  c_l=0.05, splay=0.08, alpha_r=0.95, omega_r=0.8,
                  controller=ConstantTorque(tau_c=0.25, c_h=0.05))
#: A touch-down with yaw, pitch, roll, lateral velocity and all three body rates
X_ODD = np.array([1.0, 0.1, 0.05, -0.03, 2.2, -0.4, 0.15, 0.3, -0.25, -0.2])
#: A displacement of the Table 2.1 gait in yaw, pitch, roll, lateral velocity and rates
DX21 = np.array([0.0, 0.05, 0.01, 0.005, 0.0, 0.0, 0.03, 0.05, -0.04, 0.0])


@pytest.fixture(scope="module")
def gait21() -> tuple[TrunkParams, np.ndarray]:
    """The symmetric Table 2.1 gait in 3-D (``preset("table2.1-3d")``, splay 0.05)."""
    p = table21_params()
    return p, table21_gait(p)


def _fd(f, x, h=H):
    cols = []
    for j in range(len(x)):
        e = np.zeros(len(x))
        e[j] = h
        cols.append((f(x + e) - f(x - e)) / (2.0 * h))
    return np.array(cols).T


def _map_fd(params, x, side=1):
    def f(z):
        v, st = one_step_map(params, z, side=side, options=OPT)
        assert st.name == "OK"
        return v
    return _fd(f, x)


def _close(J, Jfd, tol=1e-6):
    err = np.max(np.abs(J - Jfd)) / np.linalg.norm(Jfd)
    assert err < tol, f"relative error {err:.2e}"
    return err


def _packed(params, side, phase):
    """A parameter vector with every hip-torque coefficient nonzero and the foot off the
    origin (the RHS and event checks run on the kernels' own vectors)."""
    P = params.packed(side)
    P[kn.P_C0:kn.P_C0 + 4] = (0.3, -1.7, 0.45, -0.6)
    P[kn.P_FOOT:kn.P_FOOT + 3] = (0.6, 0.0, 0.13) if phase == kn.STANCE else 0.0
    P[kn.P_TA] = 0.07
    return P


#: A state off every symmetry: quaternion not of unit length, all rates nonzero
Y = np.array([0.05, 0.82, -0.04, 2.1, -0.35, 0.2, 0.97, 0.06, 0.11, -0.09, 0.4, -0.3, 0.7])


def _rhs(P, phase, y):
    f = np.empty(13)
    kn.rhs(P, phase, np.ascontiguousarray(y), f, np.empty((3, 3)), np.empty(16))
    return f


@pytest.mark.parametrize("phase", [kn.STANCE, kn.FLIGHT])
@pytest.mark.parametrize("leg", [{}, {"leg_exponent": 1.4}])
def test_rhs_jacobian_is_the_central_difference_of_the_field(phase, leg):
    P = _packed(dataclasses.replace(ODD, **leg), 1, phase)
    A = np.empty((13, 13))
    tv.rhs_jacobian(P, phase, Y, A)
    Afd = _fd(lambda y: _rhs(P, phase, y), Y, 1e-6)
    assert np.max(np.abs(Afd)) > 1.0
    np.testing.assert_allclose(A, Afd, rtol=0, atol=2e-8 * np.max(np.abs(Afd)))


@pytest.mark.parametrize("which", [kn.EV_LIFTOFF, kn.EV_SWITCH])
@pytest.mark.parametrize("leg", [{}, {"leg_exponent": 1.4, "c_l": 0.0,
                                      "controller": tslip.Passive()}])
def test_stance_event_gradients(which, leg):
    params = dataclasses.replace(ODD, **leg)
    P = _packed(params, 1, kn.STANCE)
    if leg:
        P[kn.P_C0:kn.P_C0 + 4] = 0.0  # the on-spring lift-off rule: l_rest - l
    P[kn.P_PENDING] = 1.0
    gr = np.empty(13)
    tv.stance_event_gradient(P, Y, which, gr)

    def ev(y):
        gv = np.empty(kn.NEV)
        kn.events(P, kn.STANCE, 0.0, np.ascontiguousarray(y), gv, np.empty((3, 3)),
                  np.empty(16))
        return gv[which:which + 1]
    want = _fd(ev, Y, 1e-6)[0]
    np.testing.assert_allclose(gr, want, rtol=0, atol=2e-8 * np.max(np.abs(want)))


@pytest.mark.parametrize("extra", [{}, {"leg_reset": "global", "k_splay": 0.7,
                                        "k_trail": -1.2}, {"alpha_stop": 0.96}])
def test_touchdown_event_partials(extra):
    P = _packed(dataclasses.replace(ODD, **extra), -1, kn.FLIGHT)
    t = 0.2
    gr = np.empty(13)
    g_t, g_ta = tv.touchdown_partials(P, Y, t, gr)

    def ev(z):
        Q = P.copy()
        Q[kn.P_TA] = z[14]
        gv = np.empty(kn.NEV)
        kn.events(Q, kn.FLIGHT, z[13], np.ascontiguousarray(z[:13]), gv, np.empty((3, 3)),
                  np.empty(16))
        return gv[:1]
    want = _fd(ev, np.concatenate([Y, [t, P[kn.P_TA]]]), 1e-6)[0]
    got = np.concatenate([gr, [g_t, g_ta]])
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-8)
    if "alpha_stop" in extra:  # held at the stop: no time dependence left
        assert g_t == g_ta == 0.0
    else:
        assert abs(g_t) > 0.1


@pytest.mark.parametrize("extra", [{}, {"k_splay": 0.7, "k_trail": -1.2}])
def test_chart_in_is_the_derivative_of_from_section(extra):
    params = dataclasses.replace(ODD, **extra)
    state, D = chart_in(params, X_ODD, 1)

    def rel(x):  # the state with the CoM relative to the foot
        s = from_section(params, x, 1)
        y = s.y.copy()
        y[0:3] -= s.foot
        return y
    np.testing.assert_allclose(D, _fd(rel, X_ODD, 1e-6), rtol=0, atol=1e-9)


@pytest.mark.parametrize("extra", [{}, {"leg_reset": "global", "k_splay": 0.7,
                                        "k_trail": -1.2}])
def test_chart_out_is_the_derivative_of_section(extra):
    params = dataclasses.replace(ODD, **extra)
    P = _packed(params, -1, kn.FLIGHT)
    y = Y.copy()
    y[6:10] /= np.linalg.norm(y[6:10])
    t = 0.2

    def sec(z):
        Q = P.copy()
        Q[kn.P_TA] = z[14]
        s = TrunkTouchdown(z[:13], np.zeros(3), -1)
        d = np.empty(3)
        kn.leg_direction(Q, s.R, z[13], d)
        foot = s.y[0:3] + params.r * s.R[:, 1] + params.l0 * (s.R @ d)
        return section(params, TrunkTouchdown(s.y, foot, -1))
    want = _fd(sec, np.concatenate([y, [t, P[kn.P_TA]]]), 1e-6)
    np.testing.assert_allclose(chart_out(P, y, t), want, rtol=0, atol=1e-9)


def test_one_step_at_the_table21_gait(gait21):
    p, x = gait21
    for side, z in ((1, x), (-1, x * [1, -1, 1, -1, 1, 1, -1, -1, -1, 1])):
        v, J = one_step_jacobian(p, z, side=side, options=OPT)
        # the same steps as the map's (run_phase's arithmetic on the state's part)
        np.testing.assert_allclose(v, one_step_map(p, z, side=side, options=OPT)[0],
                                   rtol=0, atol=1e-12)
        _close(J, _map_fd(p, z, side))


CASES = {
    "constant torque, damping, odd m l0 g": (ODD, X_ODD),
    "global PD, apex retraction": (dataclasses.replace(
        table21_params(controller=GlobalPD(Kp=1.0, Kd=0.2), retraction="apex")), None),
    "local velocity": (table21_params(controller=LocalVelocity(Kd=0.05, alphad_ref=1.0)), None),
    "roll couplings": (table21_params(k_splay=1.0, k_trail=1.0), None),
    "global reset, stop": (table21_params(leg_reset="global", alpha_stop=0.85), None),
    "leg thrust": (table21_params(leg_thrust=0.05), None),
    "power-law leg": (table21_params(leg_exponent=1.3), None),
    "scaled": (table21_params(l0=1.3, m=2.0, g=0.7, k=40.0, J_roll=0.15, J_yaw=0.06), None),
}


@pytest.mark.parametrize("name", list(CASES))
def test_one_step_jacobian_is_the_central_difference_of_the_map(name, gait21):
    params, x = CASES[name]
    if x is None:
        x = gait21[1] + DX21  # roll, lateral velocity, yaw, rates: off the plane
    assert params.splay != 0.0 and x[3] != 0.0 and x[6] != 0.0
    _, J = one_step_jacobian(params, x, options=OPT)
    _close(J, _map_fd(params, x))


def test_the_one_step_jacobian_keeps_yaw_invariance_and_energy(gait21):
    """Independent of differences: turning the touch-down turns the next one
    (``F(rot x) = rot F(x)``, so ``J dx/dangle = dF/dangle``), and the passive model
    conserves the energy (``grad E(F(x)) J = grad E(x)``)."""
    p, x0 = gait21
    x = x0 + DX21
    v, J = one_step_jacobian(p, x, options=OPT)
    turn = (yaw_rotated(x, 1e-6) - yaw_rotated(x, -1e-6)) / 2e-6
    turn_next = (yaw_rotated(v, 1e-6) - yaw_rotated(v, -1e-6)) / 2e-6
    np.testing.assert_allclose(J @ turn, turn_next, rtol=0, atol=1e-8)

    def energy(z, side):
        s = from_section(p, z, side)
        return np.array([trunk_energy(p, s.y)])
    gE0 = _fd(lambda z: energy(z, 1), x, 1e-6)[0]
    gE1 = _fd(lambda z: energy(z, -1), v, 1e-6)[0]
    np.testing.assert_allclose(gE1 @ J, gE0, rtol=0, atol=1e-7 * np.linalg.norm(gE0))


@pytest.mark.parametrize("gains", [{}, {"k_splay": 1.0, "k_trail": 1.0}])
def test_two_step_jacobian_and_multipliers_exact_against_differences(gains, gait21):
    p = table21_params(**gains)
    x = table21_gait(p, guess=gait21[1])
    J = two_step_jacobian(p, x, options=OPT)
    Jfd = two_step_jacobian(p, x, options=OPT, method="fd", step=H)
    _close(J, Jfd)
    exact = lateral_multipliers(p, x)
    fd = lateral_multipliers(p, x, method="fd")
    left = list(fd.multipliers)
    for mu in exact.multipliers:  # pair each with its nearest
        k = int(np.argmin(np.abs(np.array(left) - mu)))
        assert abs(left.pop(k) - mu) < 1e-6
    # the three trivial multipliers: 1 for the exact map, as near as the map is computed
    assert exact.trivial_error < 1e-6
    assert abs(exact.largest - fd.largest) < 1e-8


def test_bad_method_and_failing_stride():
    p = table21_params()
    with pytest.raises(ValueError, match="method must be 'exact' or 'fd'"):
        two_step_jacobian(p, np.zeros(10) + 1.0, method="adjoint")
    x = X_ODD.copy()
    x[5] = 3.0  # the leg lengthens at touch-down
    with pytest.raises(ValueError, match="two_step_jacobian: one_step_jacobian: .*FALL"):
        two_step_jacobian(ODD, x)


def test_pure_python_kernels_agree_with_the_compiled_ones():
    """The variational kernels run with NUMBA_DISABLE_JIT=1 (CONTRIBUTING's rule) to the
    same Jacobian."""
    import json
    import os
    import subprocess
    import sys

    setup = ("import numpy as np, tslip\n"
             "from tslip.model.controllers import ConstantTorque\n"
             "from tslip.spatial.trunk_parameters import TrunkParams\n"
             "p = TrunkParams(m=1.4, J=0.11, J_roll=0.07, J_yaw=0.045, r=0.25, k=28.0, l0=0.9,"
             " g=1.3, c_l=0.05, splay=0.08, alpha_r=0.95, omega_r=0.8,"
             " controller=ConstantTorque(tau_c=0.25, c_h=0.05))\n"
             "o = tslip.IntegratorOptions(rtol=1e-7, atol=1e-7, method='dopri5')\n"
             "x = np.array([1.0, 0.1, 0.05, -0.03, 2.2, -0.4, 0.15, 0.3, -0.25, -0.2])\n")
    code = (setup + "import json\nfrom tslip.spatial.trunk_jacobian import one_step_jacobian\n"
            "print(json.dumps(one_step_jacobian(p, x, options=o)[1].tolist()))\n")
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         check=True).stdout
    o = tslip.IntegratorOptions(rtol=1e-7, atol=1e-7, method="dopri5")
    _, J = one_step_jacobian(ODD, X_ODD, options=o)
    np.testing.assert_allclose(json.loads(out), J, rtol=0, atol=1e-12 * np.linalg.norm(J))
