"""The NumPy reference EOM against the thesis's printed matrices and the kernels."""

import dataclasses

import numpy as np
import pytest

import tslip
from tslip.model import _pack as pk
from tslip.model import dynamics as dyn
from tslip.simulation import _kernels as kn

CONTROLLERS = [
    tslip.Passive(),
    tslip.GlobalPD(Kp=5.0, Kd=0.5, phi_ref=0.1, phid_ref=-0.2),
    tslip.LocalVelocity(Kd=0.5, alphad_ref=4.0),
    tslip.ConstantTorque(tau_c=0.3, c_h=0.7),
]


def _random_case(rng, ctrl):
    p = dataclasses.replace(
        tslip.preset("table2.1"), m=rng.uniform(0.5, 2), J=rng.uniform(0.05, 0.5),
        r=rng.uniform(-1, 1), k=rng.uniform(5, 100), l0=rng.uniform(0.5, 1.5),
        c_l=rng.uniform(0, 2), controller=ctrl)
    y = np.array([rng.uniform(0.5, 1.2) * p.l0, rng.uniform(0.6, 2.4), rng.uniform(-1, 1),
                  rng.normal(), rng.normal() * 3, rng.normal()])
    return p, y


def test_mass_matrix_is_eq_2_4(rng):
    for _ in range(20):
        p, y = _random_case(rng, tslip.Passive())
        l, b, ph = y[:3]
        m, r, J = p.m, p.r, p.J
        a = b + ph
        expected = np.array([
            [m, 0, -m * r * np.cos(a)],
            [0, m * l**2, m * r * l * np.sin(a)],
            [-m * r * np.cos(a), m * r * l * np.sin(a), J + m * r**2],
        ])
        M = dyn.mass_matrix(p, y[:3])
        np.testing.assert_allclose(M, expected, rtol=1e-13, atol=1e-13)
        assert np.all(np.linalg.eigvalsh(M) > 0)


def test_forces_and_convective_terms_are_eqs_a11_a13(rng):
    for ctrl in CONTROLLERS:
        p, y = _random_case(rng, ctrl)
        l, b, ph, ld, bd, phd = y
        m, r, g, k = p.m, p.r, p.g, p.k
        tau = dyn.hip_torque(p, y[:3], y[3:])
        Q = [-m * g * np.sin(b) + k * (p.l0 - l) - p.c_l * ld, tau - m * g * l * np.cos(b),
             tau - m * g * r * np.sin(ph)]
        a = b + ph
        C = [m * r * phd**2 * np.sin(a) - m * l * bd**2,
             m * r * l * phd**2 * np.cos(a) + 2 * m * l * bd * ld,
             m * r * l * bd**2 * np.cos(a) + 2 * m * r * bd * ld * np.sin(a)]
        np.testing.assert_allclose(dyn.forces(p, y[:3], y[3:]), Q, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(dyn.convective(p, y[:3], y[3:]), C, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("ctrl", CONTROLLERS, ids=lambda c: c.name)
def test_kernel_rhs_and_grf_equal_numpy_reference(rng, ctrl):
    out = np.empty(6)
    for _ in range(25):
        p, y = _random_case(rng, ctrl)
        P = pk.pack_params(p)
        kn.rhs(P, y, out)
        np.testing.assert_allclose(out, dyn.stance_rhs(p, y), rtol=1e-11, atol=1e-11)
        fx, fy, tau = kn.grf(P, y)
        np.testing.assert_allclose([fx, fy], dyn.ground_reaction_force(p, y), rtol=1e-12,
                                   atol=1e-12)
        assert tau == pytest.approx(dyn.hip_torque(p, y[:3], y[3:]), abs=1e-14)


def test_grf_equals_com_acceleration(rng):
    """The leg is massless: GRF + gravity = m * CoM acceleration (eqs 2.5-2.6)."""
    for ctrl in CONTROLLERS:
        p, y = _random_case(rng, ctrl)
        yd = dyn.stance_rhs(p, y)
        JT = dyn.jacobian(p, y[:3])
        # CoM acceleration = J_T qdd + dJ_T/dt qd  (finite difference for the second term)
        eps = 1e-7
        J2 = dyn.jacobian(p, y[:3] + eps * y[3:])
        J1 = dyn.jacobian(p, y[:3] - eps * y[3:])
        acc = JT @ yd[3:] + ((J2 - J1) / (2 * eps)) @ y[3:]
        F = dyn.ground_reaction_force(p, y)
        np.testing.assert_allclose(F, [p.m * acc[0], p.m * acc[1] + p.m * p.g], rtol=1e-6,
                                   atol=1e-6)
