# mypy: ignore-errors
# (numba kernels are checked by numba, not mypy: pyproject.toml's [tool.mypy] note)
"""The 3-D TSLIP's variational equations: compiled pieces of the exact stride Jacobian.

Private (issue 43, Part 2; the chain rule that uses them is
:mod:`tslip.spatial.trunk_jacobian`). The model and its state ``y`` (13) are those of
:mod:`tslip.spatial._trunk_kernels`; this module differentiates them exactly:

* :func:`rhs_tangent`: the directional derivative ``Df(y) dy`` of the field of either
  phase (:func:`~tslip.spatial._trunk_kernels.rhs`), the chain rule written line by line
  along the field's own computation (forward mode: each intermediate of
  :func:`~tslip.spatial._trunk_kernels.stance_terms` with its tangent, the quaternion's
  renormalisation in ``R`` included), so ``Df`` is exact to rounding;
  :func:`rhs_jacobian` its 13 columns;
* :func:`leg_tangent`: the flight leg's direction (:func:`~tslip.spatial._trunk_kernels.
  leg_direction`) and hip angle with their derivatives along the attitude, the time
  since lift-off, the retraction clock's start and the reset angle;
* the event gradients: lift-off (``F . e_y``, eq. 2.8, or ``l_rest - l``), the thrust's
  switch ``-ldot`` (:func:`stance_event_gradient`), touch-down (the foot height, eq. 2.9
  in 3-D, with its explicit time and clock dependence: :func:`touchdown_partials`);
* :func:`run_phase_var`: a phase of :func:`~tslip.spatial._trunk_kernels.run_phase`
  with the sensitivity ``Phi = dy/dy0`` (13 x 13, row-major after ``y``:
  ``z[13 + 13 i + j] = Phi[i, j]``) integrated with the state, ``Phi' = Df(y) Phi``
  (the variational equation), on the same Runge-Kutta core. The state's part is
  ``run_phase``'s arithmetic exactly (stages act elementwise; the step size is
  controlled by the state's 13 components alone, as there), so ``Phi`` is the derivative
  of the computed steps; for a power-law leg (``leg_exponent != 1``, whose stiffness is
  not smooth at the rest length) the error control covers ``Phi`` too. The event's
  ``Phi`` is the dense output's, which is linear in the stages like the steps.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._kernel_cache import check as _check_cache
from ..model._pack import O_ATOL, O_H0, O_HMIN, O_MAXSTEPS, O_METHOD, O_RTOL
from ..simulation import _rk
from ..simulation._rk import _INLINE, _JIT
from . import _trunk_kernels as kn

NSTATE = kn.NSTATE
#: ``(y, Phi)``: the state and its 13 x 13 sensitivity, row-major
NZ = NSTATE + NSTATE * NSTATE
#: Output of :func:`run_phase_var`: as :func:`~._trunk_kernels.run_phase`'s, then ``z``
OUT_Z = kn.OUT_Y
NOUT = OUT_Z + NZ
#: Slots of :func:`stance_tangent`'s output: ``dF`` (3), ``dT`` (3), ``dl``, ``dldot``
T_F, T_T, T_L, T_LD = 0, 3, 6, 7


@njit(**_INLINE)
def rotation_tangent(y, dy, R, dR):
    """``R`` of the renormalised quaternion (as :func:`~._trunk_kernels.rotation`) and its
    directional derivative ``dR`` along ``dy``."""
    n = math.sqrt(y[6] * y[6] + y[7] * y[7] + y[8] * y[8] + y[9] * y[9])
    dn = (y[6] * dy[6] + y[7] * dy[7] + y[8] * dy[8] + y[9] * dy[9]) / n
    w, a, b, c = y[6] / n, y[7] / n, y[8] / n, y[9] / n
    dw, da, db, dc = ((dy[6] - w * dn) / n, (dy[7] - a * dn) / n, (dy[8] - b * dn) / n,
                      (dy[9] - c * dn) / n)
    kn.rotation(y, R)
    dR[0, 0] = -4.0 * (b * db + c * dc)
    dR[0, 1] = 2.0 * (da * b + a * db - dw * c - w * dc)
    dR[0, 2] = 2.0 * (da * c + a * dc + dw * b + w * db)
    dR[1, 0] = 2.0 * (da * b + a * db + dw * c + w * dc)
    dR[1, 1] = -4.0 * (a * da + c * dc)
    dR[1, 2] = 2.0 * (db * c + b * dc - dw * a - w * da)
    dR[2, 0] = 2.0 * (da * c + a * dc - dw * b - w * db)
    dR[2, 1] = 2.0 * (db * c + b * dc + dw * a + w * da)
    dR[2, 2] = -4.0 * (a * da + b * db)


@njit(**_JIT)
def rotation_jacobian(y, R, dRq):
    """``R`` of ``y``'s quaternion and ``dRq[k] = dR/dq_k`` (4 x 3 x 3, ``q = y[6:10]``)."""
    dy = np.zeros(NSTATE)
    dR = np.empty((3, 3))
    for k in range(4):
        dy[6 + k] = 1.0
        rotation_tangent(y, dy, R, dR)
        dy[6 + k] = 0.0
        for i in range(3):
            for j in range(3):
                dRq[k, i, j] = dR[i, j]


@njit(**_INLINE)
def spring_slope(P, l):
    """``dF_s/dl`` of :func:`~._trunk_kernels.spring_force`: ``-k n |x|^(n-1)``."""
    n = P[P_NEXP]
    if n == 1.0:
        return -P[P_K]
    x = (P[P_LREST] - l) / P[P_L0]
    return -P[P_K] * n * abs(x) ** (n - 1.0)


P_NEXP, P_K, P_L0, P_LREST, P_R, P_CL, P_C0 = (kn.P_NEXP, kn.P_K, kn.P_L0, kn.P_LREST,
                                               kn.P_R, kn.P_CL, kn.P_C0)


@njit(**_INLINE)
def _crs(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(**_JIT)
def stance_tangent(P, y, dy, R, dR, o, td):
    """The stance's terms at ``y`` (:func:`~._trunk_kernels.stance_terms`, into ``o``) and
    their derivatives along ``dy`` into ``td``: ``dF`` (3), ``dT`` (3), ``dl``, ``dldot``."""
    kn.stance_terms(P, y, R, o)
    rotation_tangent(y, dy, R, dR)
    r = P[P_R]
    w0, w1, w2 = y[10], y[11], y[12]
    dw0, dw1, dw2 = dy[10], dy[11], dy[12]
    ww0 = R[0, 0] * w0 + R[0, 1] * w1 + R[0, 2] * w2
    ww1 = R[1, 0] * w0 + R[1, 1] * w1 + R[1, 2] * w2
    ww2 = R[2, 0] * w0 + R[2, 1] * w1 + R[2, 2] * w2
    dww0 = dR[0, 0] * w0 + dR[0, 1] * w1 + dR[0, 2] * w2 + R[0, 0] * dw0 + R[0, 1] * dw1 \
        + R[0, 2] * dw2
    dww1 = dR[1, 0] * w0 + dR[1, 1] * w1 + dR[1, 2] * w2 + R[1, 0] * dw0 + R[1, 1] * dw1 \
        + R[1, 2] * dw2
    dww2 = dR[2, 0] * w0 + dR[2, 1] * w1 + dR[2, 2] * w2 + R[2, 0] * dw0 + R[2, 1] * dw1 \
        + R[2, 2] * dw2
    ry0, ry1, ry2 = r * R[0, 1], r * R[1, 1], r * R[2, 1]
    dry0, dry1, dry2 = r * dR[0, 1], r * dR[1, 1], r * dR[2, 1]
    e0 = P[kn.P_FOOT] - y[0] - ry0
    e1 = P[kn.P_FOOT + 1] - y[1] - ry1
    e2 = P[kn.P_FOOT + 2] - y[2] - ry2
    de0, de1, de2 = -dy[0] - dry0, -dy[1] - dry1, -dy[2] - dry2
    l = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    dl = (e0 * de0 + e1 * de1 + e2 * de2) / l
    u0, u1, u2 = e0 / l, e1 / l, e2 / l
    du0, du1, du2 = (de0 - u0 * dl) / l, (de1 - u1 * dl) / l, (de2 - u2 * dl) / l
    c0, c1, c2 = _crs(ww0, ww1, ww2, ry0, ry1, ry2)
    a0, a1, a2 = _crs(dww0, dww1, dww2, ry0, ry1, ry2)
    b0, b1, b2 = _crs(ww0, ww1, ww2, dry0, dry1, dry2)
    hd0, hd1, hd2 = y[3] + c0, y[4] + c1, y[5] + c2
    dhd0, dhd1, dhd2 = dy[3] + a0 + b0, dy[4] + a1 + b1, dy[5] + a2 + b2
    ld = -(u0 * hd0 + u1 * hd1 + u2 * hd2)
    dld = -(du0 * hd0 + du1 * hd1 + du2 * hd2 + u0 * dhd0 + u1 * dhd1 + u2 * dhd2)
    fl = o[12]
    dfl = spring_slope(P, l) * dl - P[P_CL] * dld
    # hip angle's rate in the trunk's sagittal plane (stance_terms)
    ub0 = R[0, 0] * u0 + R[1, 0] * u1 + R[2, 0] * u2
    ub1 = R[0, 1] * u0 + R[1, 1] * u1 + R[2, 1] * u2
    ub2 = R[0, 2] * u0 + R[1, 2] * u1 + R[2, 2] * u2
    dub0 = dR[0, 0] * u0 + dR[1, 0] * u1 + dR[2, 0] * u2 + R[0, 0] * du0 + R[1, 0] * du1 \
        + R[2, 0] * du2
    dub1 = dR[0, 1] * u0 + dR[1, 1] * u1 + dR[2, 1] * u2 + R[0, 1] * du0 + R[1, 1] * du1 \
        + R[2, 1] * du2
    dub2 = dR[0, 2] * u0 + dR[1, 2] * u1 + dR[2, 2] * u2 + R[0, 2] * du0 + R[1, 2] * du1 \
        + R[2, 2] * du2
    ud0, ud1, ud2 = (-hd0 - u0 * ld) / l, (-hd1 - u1 * ld) / l, (-hd2 - u2 * ld) / l
    dud0 = (-dhd0 - du0 * ld - u0 * dld - ud0 * dl) / l
    dud1 = (-dhd1 - du1 * ld - u1 * dld - ud1 * dl) / l
    dud2 = (-dhd2 - du2 * ld - u2 * dld - ud2 * dl) / l
    wc0 = w1 * ub2 - w2 * ub1
    wc1 = w2 * ub0 - w0 * ub2
    dwc0 = dw1 * ub2 + w1 * dub2 - dw2 * ub1 - w2 * dub1
    dwc1 = dw2 * ub0 + w2 * dub0 - dw0 * ub2 - w0 * dub2
    ubd0 = R[0, 0] * ud0 + R[1, 0] * ud1 + R[2, 0] * ud2 - wc0
    ubd1 = R[0, 1] * ud0 + R[1, 1] * ud1 + R[2, 1] * ud2 - wc1
    dubd0 = (dR[0, 0] * ud0 + dR[1, 0] * ud1 + dR[2, 0] * ud2 + R[0, 0] * dud0
             + R[1, 0] * dud1 + R[2, 0] * dud2 - dwc0)
    dubd1 = (dR[0, 1] * ud0 + dR[1, 1] * ud1 + dR[2, 1] * ud2 + R[0, 1] * dud0
             + R[1, 1] * dud1 + R[2, 1] * dud2 - dwc1)
    X, Y, Xd, Yd = ub0, -ub1, ubd0, -ubd1
    dX, dY, dXd, dYd = dub0, -dub1, dubd0, -dubd1
    D = X * X + Y * Y
    alphad = (X * Yd - Y * Xd) / D
    dalphad = (dX * Yd + X * dYd - dY * Xd - Y * dXd - alphad * 2.0 * (X * dX + Y * dY)) / D
    # the pitch and its rate (_trunk_kernels.pitch)
    ct = math.sqrt(R[0, 0] * R[0, 0] + R[2, 0] * R[2, 0])
    dct = (R[0, 0] * dR[0, 0] + R[2, 0] * dR[2, 0]) / ct
    dth = (ct * dR[1, 0] - R[1, 0] * dct) / (R[1, 0] * R[1, 0] + ct * ct)
    thd = (ww2 * R[0, 0] - ww0 * R[2, 0]) / ct
    dthd = (dww2 * R[0, 0] + ww2 * dR[0, 0] - dww0 * R[2, 0] - ww0 * dR[2, 0] - thd * dct) / ct
    tau = o[11]
    dtau = P[P_C0 + 1] * dth + P[P_C0 + 2] * (dalphad - dthd) + P[P_C0 + 3] * dthd
    zu = R[0, 2] * u0 + R[1, 2] * u1 + R[2, 2] * u2
    dzu = (dR[0, 2] * u0 + dR[1, 2] * u1 + dR[2, 2] * u2 + R[0, 2] * du0 + R[1, 2] * du1
           + R[2, 2] * du2)
    tp0, tp1, tp2 = tau * (R[0, 2] - zu * u0), tau * (R[1, 2] - zu * u1), tau * (R[2, 2] - zu * u2)
    dtp0 = dtau * (R[0, 2] - zu * u0) + tau * (dR[0, 2] - dzu * u0 - zu * du0)
    dtp1 = dtau * (R[1, 2] - zu * u1) + tau * (dR[1, 2] - dzu * u1 - zu * du1)
    dtp2 = dtau * (R[2, 2] - zu * u2) + tau * (dR[2, 2] - dzu * u2 - zu * du2)
    m0, m1, m2 = _crs(tp0, tp1, tp2, u0, u1, u2)
    p0, p1, p2 = _crs(dtp0, dtp1, dtp2, u0, u1, u2)
    q0, q1, q2 = _crs(tp0, tp1, tp2, du0, du1, du2)
    dm0, dm1, dm2 = p0 + q0, p1 + q1, p2 + q2
    F0, F1, F2 = o[0], o[1], o[2]
    l2 = l * l
    dF0 = -dfl * u0 - fl * du0 + dm0 / l - m0 * dl / l2
    dF1 = -dfl * u1 - fl * du1 + dm1 / l - m1 * dl / l2
    dF2 = -dfl * u2 - fl * du2 + dm2 / l - m2 * dl / l2
    s0, s1, s2 = _crs(dry0, dry1, dry2, F0, F1, F2)
    v0, v1, v2 = _crs(ry0, ry1, ry2, dF0, dF1, dF2)
    td[T_F], td[T_F + 1], td[T_F + 2] = dF0, dF1, dF2
    td[T_T], td[T_T + 1], td[T_T + 2] = s0 + v0 + dtp0, s1 + v1 + dtp1, s2 + v2 + dtp2
    td[T_L], td[T_LD] = dl, dld


@njit(**_INLINE)
def _body_rates_tangent(P, y, dy, R, dR, T0, T1, T2, dT0, dT1, dT2, df):
    """The tangent of :func:`~._trunk_kernels._body_rates` (world torque ``T``, ``dT``)."""
    dTb0 = (dR[0, 0] * T0 + dR[1, 0] * T1 + dR[2, 0] * T2 + R[0, 0] * dT0 + R[1, 0] * dT1
            + R[2, 0] * dT2)
    dTb1 = (dR[0, 1] * T0 + dR[1, 1] * T1 + dR[2, 1] * T2 + R[0, 1] * dT0 + R[1, 1] * dT1
            + R[2, 1] * dT2)
    dTb2 = (dR[0, 2] * T0 + dR[1, 2] * T1 + dR[2, 2] * T2 + R[0, 2] * dT0 + R[1, 2] * dT1
            + R[2, 2] * dT2)
    Jx, Jy, Jz = P[kn.P_JROLL], P[kn.P_JYAW], P[kn.P_J]
    wx, wy, wz = y[10], y[11], y[12]
    dwx, dwy, dwz = dy[10], dy[11], dy[12]
    df[10] = (dTb0 - (Jz - Jy) * (dwy * wz + wy * dwz)) / Jx
    df[11] = (dTb1 - (Jx - Jz) * (dwz * wx + wz * dwx)) / Jy
    df[12] = (dTb2 - (Jy - Jx) * (dwx * wy + wx * dwy)) / Jz
    qw, qx, qy, qz = y[6], y[7], y[8], y[9]
    dqw, dqx, dqy, dqz = dy[6], dy[7], dy[8], dy[9]
    df[6] = -0.5 * (dqx * wx + qx * dwx + dqy * wy + qy * dwy + dqz * wz + qz * dwz)
    df[7] = 0.5 * (dqw * wx + qw * dwx + dqy * wz + qy * dwz - dqz * wy - qz * dwy)
    df[8] = 0.5 * (dqw * wy + qw * dwy + dqz * wx + qz * dwx - dqx * wz - qx * dwz)
    df[9] = 0.5 * (dqw * wz + qw * dwz + dqx * wy + qx * dwy - dqy * wx - qy * dwx)


@njit(**_JIT)
def rhs_tangent(P, phase, y, dy, df, R, dR, o, td):
    """``df = Df(y) dy``, the derivative of :func:`~._trunk_kernels.rhs` along ``dy``
    (``R``, ``dR`` 3 x 3, ``o`` 16 and ``td`` 8 are scratch)."""
    df[0], df[1], df[2] = dy[3], dy[4], dy[5]
    if phase == kn.STANCE:
        stance_tangent(P, y, dy, R, dR, o, td)
        m = P[kn.P_M]
        df[3], df[4], df[5] = td[T_F] / m, td[T_F + 1] / m, td[T_F + 2] / m
        _body_rates_tangent(P, y, dy, R, dR, o[3], o[4], o[5], td[T_T], td[T_T + 1],
                            td[T_T + 2], df)
    else:
        rotation_tangent(y, dy, R, dR)
        df[3], df[4], df[5] = 0.0, 0.0, 0.0
        _body_rates_tangent(P, y, dy, R, dR, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, df)


@njit(**_JIT)
def rhs_jacobian(P, phase, y, A):
    """``A = Df(y)`` (13 x 13), column by column (:func:`rhs_tangent`)."""
    R = np.empty((3, 3))
    dR = np.empty((3, 3))
    o = np.empty(16)
    td = np.empty(8)
    dy = np.zeros(NSTATE)
    df = np.empty(NSTATE)
    for j in range(NSTATE):
        dy[j] = 1.0
        rhs_tangent(P, phase, y, dy, df, R, dR, o, td)
        dy[j] = 0.0
        for i in range(NSTATE):
            A[i, j] = df[i]


@njit(**_JIT)
def aug_rhs(P, phase, z, f, A, R, o):
    """The field of ``(y, Phi)``: ``(f(y), Df(y) Phi)``, the variational equation."""
    kn.rhs(P, phase, z[:NSTATE], f[:NSTATE], R, o)
    rhs_jacobian(P, phase, z[:NSTATE], A)
    for i in range(NSTATE):
        for c in range(NSTATE):
            acc = 0.0
            for k in range(NSTATE):
                acc += A[i, k] * z[NSTATE + k * NSTATE + c]
            f[NSTATE + i * NSTATE + c] = acc


@njit(**_JIT)
def stance_event_gradient(P, y, which, gr):
    """The gradient (13) of the stance event ``which`` at ``y``: lift-off (``F . e_y``, or
    ``l_rest - l`` by :func:`~._trunk_kernels.liftoff_on_spring`) or the thrust's switch
    (``-ldot``)."""
    R = np.empty((3, 3))
    dR = np.empty((3, 3))
    o = np.empty(16)
    td = np.empty(8)
    dy = np.zeros(NSTATE)
    for j in range(NSTATE):
        dy[j] = 1.0
        stance_tangent(P, y, dy, R, dR, o, td)
        dy[j] = 0.0
        if which == kn.EV_SWITCH:
            gr[j] = -td[T_LD]
        elif kn.liftoff_on_spring(P):
            gr[j] = -td[T_L]
        else:
            gr[j] = td[T_F + 1]


@njit(**_JIT)
def leg_tangent(P, R, dR, t, dt, dta, dal, d, dd):
    """The flight leg's direction ``d`` in the trunk frame (:func:`~._trunk_kernels.
    leg_direction`) and its derivative ``dd`` along ``dR``, a change ``dt`` of the time
    since lift-off, ``dta`` of the retraction clock's start ``P[P_TA]`` and ``dal`` of the
    reset angle ``P[P_ALPHA]``. Returns the hip angle ``a`` (with the pitch for the global
    reset: the section's ``a``) and its derivative."""
    a = kn.swing_angle(P, t)
    raw = P[kn.P_ALPHA] + P[kn.P_OMEGA] * max(t - P[kn.P_TA], 0.0)
    da = dal if a == raw else 0.0  # held at the stop: a constant
    if a == raw and t > P[kn.P_TA]:
        da += P[kn.P_OMEGA] * (dt - dta)
    if P[kn.P_GLOBAL] != 0.0:
        ct = math.sqrt(R[0, 0] * R[0, 0] + R[2, 0] * R[2, 0])
        dct = (R[0, 0] * dR[0, 0] + R[2, 0] * dR[2, 0]) / ct
        a += math.atan2(R[1, 0], ct)
        da += (ct * dR[1, 0] - R[1, 0] * dct) / (R[1, 0] * R[1, 0] + ct * ct)
    s = P[kn.P_SIDE]
    sp = P[kn.P_SPLAY]
    ks, kt = P[kn.P_KSPLAY], P[kn.P_KTRAIL]
    dsp = 0.0
    drho = 0.0
    rho = 0.0
    if ks != 0.0 or kt != 0.0:
        rho = math.atan2(-R[1, 2], R[1, 1])
        drho = (R[1, 2] * dR[1, 1] - R[1, 1] * dR[1, 2]) / (R[1, 1] * R[1, 1] + R[1, 2] * R[1, 2])
        sp += ks * s * rho
        dsp = ks * s * drho
    sa, ca, ss, cs = math.sin(a), math.cos(a), math.sin(sp), math.cos(sp)
    d[0] = ca
    d[1] = -sa * cs
    d[2] = s * sa * ss
    dd[0] = -sa * da
    dd[1] = -ca * cs * da + sa * ss * dsp
    dd[2] = s * (ca * ss * da + sa * cs * dsp)
    if kt != 0.0:
        psi = -kt * rho
        dpsi = -kt * drho
        c, z = math.cos(psi), math.sin(psi)
        d0, d2, dd0, dd2 = d[0], d[2], dd[0], dd[2]
        d[0] = c * d0 + z * d2
        d[2] = -z * d0 + c * d2
        dd[0] = -z * dpsi * d0 + c * dd0 + c * dpsi * d2 + z * dd2
        dd[2] = -c * dpsi * d0 - z * dd0 - z * dpsi * d2 + c * dd2
    return a, da


@njit(**_JIT)
def touchdown_partials(P, y, t, gr):
    """The touch-down event ``g = H_y + l0 (R d)_y`` (:func:`~._trunk_kernels.events`) at
    ``y``, ``t`` after lift-off: its gradient in ``y`` into ``gr`` (13); returns
    ``(dg/dt, dg/dt_a)``, ``t_a`` the retraction clock's start ``P[P_TA]``."""
    R = np.empty((3, 3))
    dR = np.empty((3, 3))
    d = np.empty(3)
    dd = np.empty(3)
    dy = np.zeros(NSTATE)
    r, l0 = P[P_R], P[P_L0]
    out = np.empty(NSTATE + 2)
    for j in range(NSTATE + 2):
        if j < NSTATE:
            dy[j] = 1.0
        rotation_tangent(y, dy, R, dR)
        leg_tangent(P, R, dR, t, 1.0 if j == NSTATE else 0.0,
                    1.0 if j == NSTATE + 1 else 0.0, 0.0, d, dd)
        g = dy[1] + r * dR[1, 1]
        for k in range(3):
            g += l0 * (dR[1, k] * d[k] + R[1, k] * dd[k])
        out[j] = g
        if j < NSTATE:
            dy[j] = 0.0
    for j in range(NSTATE):
        gr[j] = out[j]
    return out[NSTATE], out[NSTATE + 1]


@njit(**_JIT)
def run_phase_var(P, O, phase, z0, tmax, out):
    """:func:`~._trunk_kernels.run_phase` (no records) on ``(y, Phi)`` (module docstring):
    ``out`` (:data:`NOUT`) as ``run_phase``'s, with ``z`` at the event from :data:`OUT_Z`.
    Returns the status."""
    n = NZ
    ny = NSTATE
    nerr = ny if P[kn.P_NEXP] == 1.0 else n
    method = int(O[O_METHOD])
    rtol, atol = O[O_RTOL], O[O_ATOL]
    ns = _rk.n_stages(method)
    K = np.zeros((_rk.NK, n))
    Rd = np.zeros((_rk.NR, n))
    R = np.empty((3, 3))
    A = np.empty((ny, ny))
    o = np.empty(16)
    y = z0.copy()
    ytmp = np.empty(n)
    ynew = np.empty(n)
    gv_old = np.empty(kn.NEV)
    gv_new = np.empty(kn.NEV)
    gv_tmp = np.empty(kn.NEV)
    st = np.empty(5)
    for i in range(out.shape[0]):
        out[i] = np.nan
    aug_rhs(P, phase, y, K[0], A, R, o)
    h = O[O_H0]
    if h <= 0.0:
        h0, d1 = _rk.initial_probe(y[:ny], K[0, :ny], rtol, atol, ytmp[:ny])
        kn.rhs(P, phase, ytmp[:ny], K[1, :ny], R, o)
        h = _rk.initial_step(method, y[:ny], K[0, :ny], K[1, :ny], h0, d1, rtol, atol)
    kn.events(P, phase, 0.0, y[:ny], gv_old, R, o)
    d = _rk.ZERO_PROBE * h
    for i in range(ny):
        ytmp[i] = y[i] + d * K[0, i]
    kn.events(P, phase, d, ytmp[:ny], gv_tmp, R, o)
    g_start, g_probe = gv_old[0], gv_tmp[0]
    first = True
    last_rejected = False
    t = 0.0
    nstep = 0
    nrej = 0
    status = kn.ST_OK
    which = -1
    while True:
        if nstep + nrej >= O[O_MAXSTEPS]:
            status = kn.ST_ERR_MAX_STEPS
            break
        if t > tmax:
            status = kn.ST_ERR_TIMEOUT
            break
        if h < O[O_HMIN]:
            status = kn.ST_ERR_STEP_UNDERFLOW
            break
        for s in range(1, ns):
            _rk.stage_state(method, n, y, h, K, s, ytmp)
            aug_rhs(P, phase, ytmp, K[s], A, R, o)
        _rk.stage_state(method, n, y, h, K, ns, ynew)
        aug_rhs(P, phase, ynew, K[ns], A, R, o)
        err = _rk.error_norm(method, nerr, y, ynew, h, K, rtol, atol)
        if not err <= 1.0:
            nrej += 1
            last_rejected = True
            h *= 0.1 if not math.isfinite(err) else _rk.step_factor(method, err, 10.0)
            continue
        kn.events(P, phase, t + h, ynew[:ny], gv_new, R, o)
        if phase == kn.STANCE and first and _rk.jumped_hump(g_start, gv_new[0], g_probe):
            nrej += 1
            h *= _rk.HUMP_SHRINK
            continue
        first = False
        nstep += 1
        fired = False
        for ev in range(kn.NEV):
            fired = fired or (gv_old[ev] > 0.0 and gv_new[ev] <= 0.0)
        if fired:
            for s in range(ns + 1, ns + 1 + _rk.n_extra(method)):
                _rk.stage_state(method, n, y, h, K, s, ytmp)
                aug_rhs(P, phase, ytmp, K[s], A, R, o)
            _rk.dense_coeffs(method, y, ynew, h, K, Rd)
            theta_ev = 2.0
            for ev in (kn.EV_HIP, kn.EV_COLLAPSE, kn.EV_FORWARD, kn.EV_LIFTOFF, kn.EV_SWITCH):
                if gv_old[ev] > 0.0 and gv_new[ev] <= 0.0:
                    _rk.root_start(st, gv_old[ev], gv_new[ev])
                    for _ in range(200):
                        c = _rk.root_guess(st)
                        _rk.dense_eval(method, Rd[:, :ny], c, ytmp[:ny])
                        kn.events(P, phase, t + c * h, ytmp[:ny], gv_tmp, R, o)
                        if _rk.root_update(st, c, gv_tmp[ev], 1e-15):
                            break
                    if st[1] < theta_ev - 1e-9:
                        theta_ev = st[1]
                        which = ev
            _rk.dense_eval(method, Rd, theta_ev, ytmp)
            for i in range(n):
                out[OUT_Z + i] = ytmp[i]
            out[kn.OUT_T] = t + theta_ev * h
            if which == kn.EV_HIP or which == kn.EV_COLLAPSE:
                status = kn.ST_FALL_HIP_GROUND if phase == kn.STANCE else kn.ST_FALL_NO_TOUCHDOWN
            elif which == kn.EV_FORWARD:
                status = kn.ST_FALL_BACKWARD
            elif which == kn.EV_SWITCH:
                status = kn.ST_SWITCH
            else:
                status = kn.ST_OK
            break
        if not _rk.all_finite(n, ynew):
            status = kn.ST_ERR_NONFINITE
            break
        t += h
        _rk.accept_step(method, n, y, ynew, K)
        for ev in range(kn.NEV):
            gv_old[ev] = gv_new[ev]
        fac = _rk.step_factor(method, err, 10.0)
        if last_rejected:
            fac = min(1.0, fac)
        last_rejected = False
        h *= fac
    if status >= 10:
        for i in range(n):
            out[OUT_Z + i] = y[i]
        out[kn.OUT_T] = t
    out[kn.OUT_STATUS] = status
    out[kn.OUT_NSTEP] = nstep
    out[kn.OUT_NREJ] = nrej
    out[kn.OUT_EVENT] = which
    out[kn.OUT_NREC] = 0
    return status


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(run_phase_var, __file__)
