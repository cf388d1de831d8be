"""Biped equations of motion: TMT kernels vs an independent Lagrangian derivation."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from tslip.biped import BipedOptions, BipedParams, BipedState, energy, mass_matrix, simulate
from tslip.biped.dynamics import bias_forces, body_positions, controller_references


@pytest.fixture(scope="module")
def lagrangian():
    """M(q) and the passive generalised force -(C + dV/dq) from T - V by sympy.

    Written from eqs E.2-E.8 directly (positions only, velocities by sympy
    differentiation), independent of the kernels' hand-written Jacobians.
    """
    t = sp.symbols("t")
    names = ["x", "z", "tb", "ltR", "lsR", "thR", "ltL", "lsL", "thL"]
    qf = [sp.Function(n)(t) for n in names]
    mb, Jb, mt, Jt, ms, Js, mf, r1, r2, g = sp.symbols("mb Jb mt Jt ms Js mf r1 r2 g")
    x, z, tb = qf[:3]
    ez = sp.Matrix([0, 1])
    Ry = lambda a: sp.Matrix([[sp.cos(a), sp.sin(a)], [-sp.sin(a), sp.cos(a)]])  # noqa: E731
    bz = Ry(tb) * ez  # eq. E.2 as a matrix-vector product: b_z = (sin, cos) theta_b
    ph = sp.Matrix([x, z]) + r1 * bz
    T = sp.Rational(1, 2) * mb * (sp.diff(x, t) ** 2 + sp.diff(z, t) ** 2)
    T += sp.Rational(1, 2) * Jb * sp.diff(tb, t) ** 2
    V = mb * g * z
    for b in (3, 6):
        lt, ls, th = qf[b], qf[b + 1], qf[b + 2]
        hz = Ry(tb + th) * ez  # eq. E.3
        for pos, m, J in (
            (ph - r2 * lt * hz, mt, Jt),
            (ph - (lt + r2 * ls) * hz, ms, Js),
            (ph - (lt + ls) * hz, mf, 0),
        ):
            v = pos.diff(t)
            T += sp.Rational(1, 2) * m * (v.T * v)[0] + sp.Rational(1, 2) * J * sp.diff(
                tb + th, t) ** 2
            V += m * g * pos[1]
    q = sp.symbols("q0:9")
    qd = sp.symbols("qd0:9")
    sub = {sp.diff(f, t): s for f, s in zip(qf, qd, strict=True)}
    sub2 = {f: s for f, s in zip(qf, q, strict=True)}
    Ts = T.subs(sub).subs(sub2)
    Vs = V.subs(sub2)
    M = sp.Matrix(9, 9, lambda i, j: sp.diff(Ts, qd[i], qd[j]))
    # Lagrange: M qdd + sum_jk (dM_ij/dq_k - 1/2 dM_jk/dq_i) qd_j qd_k + dV/dq = Q
    cvec = []
    for i in range(9):
        ci = sum(
            (sp.diff(M[i, j], q[k]) - sp.Rational(1, 2) * sp.diff(M[j, k], q[i])) * qd[j] * qd[k]
            for j in range(9) for k in range(9)
        )
        cvec.append(-(ci + sp.diff(Vs, q[i])))
    pars = (mb, Jb, mt, Jt, ms, Js, mf, r1, r2, g)
    fM = sp.lambdify((q, pars), M, "numpy")
    fh = sp.lambdify((q, qd, pars), sp.Matrix(cvec), "numpy")
    return fM, fh


def _pars(p: BipedParams):
    return (p.m_b, p.J_b, p.m_t, p.J_t, p.m_s, p.J_s, p.m_f, p.r_1, p.r_2, p.g)


def _random_state(rng):
    q = np.array([0.3, 0.6, 0.4, 0.7, 0.3, -0.5, 0.5, 0.25, 0.8])
    q = q + rng.uniform(-0.2, 0.2, 9)
    qd = rng.uniform(-3.0, 3.0, 9)
    return q, qd


def test_mass_matrix_symmetric_positive_definite_and_equals_lagrangian(lagrangian, rng):
    fM, _ = lagrangian
    p = BipedParams(r_2=0.35, J_s=0.004)
    worst = 0.0
    for _ in range(20):
        q, _qd = _random_state(rng)
        M = mass_matrix(p, q)
        assert np.array_equal(M, M.T)
        assert np.linalg.eigvalsh(M).min() > 0.0
        ref = np.array(fM(q, _pars(p)), dtype=float)
        worst = max(worst, np.abs(M - ref).max() / np.abs(ref).max())
    assert worst < 1e-10, worst


def test_convective_and_gravity_forces_equal_lagrangian(lagrangian, rng):
    _, fh = lagrangian
    p = BipedParams(r_1=-0.2, g=1.3)
    worst = 0.0
    for _ in range(20):
        q, qd = _random_state(rng)
        h = bias_forces(p, q, qd)
        ref = np.array(fh(q, qd, _pars(p)), dtype=float).ravel()
        worst = max(worst, np.abs(h - ref).max() / (1.0 + np.abs(ref).max()))
    assert worst < 1e-10, worst


def test_table_e2_start_puts_the_right_foot_on_the_ground():
    pos = body_positions(BipedParams(), BipedState.thesis())
    assert abs(pos[3, 1]) < 1e-4  # right foot (Table E.2 is rounded to 3 digits)
    assert pos[6, 1] > 0.05  # left foot in the air


def test_energy_conserved_in_free_flight_without_actuation_or_damping():
    p = BipedParams(actuated=False, contact=False, c_l=0.0)
    s = BipedState.thesis()
    qd = s.qd.copy()
    qd[1] = 1.0  # start upward: hip stays above ground for 2 time units
    state = BipedState(s.q, qd)
    opts = BipedOptions(rtol=1e-12, atol=1e-12, check_falls=False)
    tr = simulate(p, state, 1, t_end=2.0, options=opts)
    assert tr.stats["t_end"] == pytest.approx(2.0)
    e = np.array([energy(p, row[1:19]) for row in tr.data])
    drift = np.abs(e - e[0]).max() / abs(e[0])
    assert drift < 1e-8, drift
    # momentum: horizontal momentum constant, vertical changes at rate -m g
    assert tr.final_state[9] != pytest.approx(qd[0], abs=1e-3)  # legs exchange momentum


def test_controller_references_are_continuous_and_differentiate():
    p = BipedParams()
    rho = np.linspace(0.0, 1.0, 20001)[:-1]
    ref = controller_references(p, rho)
    assert np.abs(np.diff(ref[:, 0])).max() < 1e-3
    assert np.abs(np.diff(ref[:, 2])).max() < 1e-3
    # wrap-around: end of swing equals start of stance
    assert ref[-1, 0] == pytest.approx(ref[0, 0], abs=1e-3)
    assert ref[-1, 2] == pytest.approx(ref[0, 2], abs=1e-3)
    drho = rho[1] - rho[0]
    num = np.gradient(ref[:, 2], drho) / p.T
    mask = (np.abs(rho - p.d) > 1e-3) & (rho > 1e-3) & (rho < 1 - 1e-3)
    assert np.abs(num[mask] - ref[mask, 3]).max() < 1e-3
    num_l = np.gradient(ref[:, 0], drho) / p.T
    assert np.abs(num_l[mask] - ref[mask, 1]).max() < 1e-3
    assert ref[0, 2] == pytest.approx(p.theta_f)
    assert controller_references(p, p.d)[2] == pytest.approx(p.theta_f + p.theta_s)
