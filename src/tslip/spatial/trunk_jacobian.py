"""The exact Jacobian of the 3-D TSLIP's touch-down maps: variational equations and
event-time (saltation) corrections.

Issue 43, Part 2. The one-step map on the 10-D touch-down section
(:mod:`tslip.spatial.trunk_section`) is a chain; each link is differentiated exactly
(the planar model's :mod:`tslip.simulation._variational` and the 3-D SLIP's
:func:`tslip.spatial.stride.step_jacobian` do the same):

1. the chart in, section ``x`` -> touch-down state ``y0`` (13): the attitude ``R =
   R_y(yaw) R_z(pitch) R_x(roll)`` and its quaternion, and the CoM ``c = p - r y_b - l0
   R d(a, R)`` placed by the foot ``p`` on the ground (``d`` the leg direction with the
   roll couplings). The stance depends on ``c`` and ``p`` through ``c - p`` only and the
   rest of the stride not on the horizontal position, so the foot is held and ``c``
   moves (:func:`chart_in`);
2. the stance flow ``Phi = dy/dy0``: the variational equation ``Phi' = Df(y) Phi``
   integrated with the state on the same Runge-Kutta core, ``Df`` exact to rounding
   (:mod:`tslip.spatial._trunk_variational`); a thrust's switch (``-ldot = 0``, where the
   field jumps) adds ``(f- - f+) dt_sw``;
3. lift-off at ``g = F . e_y = 0`` (eq. 2.8; ``l_rest - l`` under the planar rule
   for a power-law leg): ``dy_LO = Phi dy0 + f dt_LO``, ``dt_LO = -(grad
   g . Phi dy0) / (grad g . f)``; the quaternion's renormalisation
   ``(I - q q^T) / |q|``;
4. the flight flow (ballistic CoM, torque-free trunk: Euler's equations) the same way,
   its clock started at lift-off (``t_a = vy_LO / g`` under ``retraction="apex"``, a
   function of the lift-off state), and touch-down at the foot height ``g(y, t, t_a) =
   H_y + l0 (R d(t))_y = 0`` (eq. 2.9 in 3-D), an explicit function of the time through
   the swing leg's angle ``a(t)`` (eq. 2.17, retraction): ``dt_TD = -(grad g . dy +
   g_ta dt_a) / (grad g . f + g_t)``;
5. the chart out, touch-down -> section: the hip angle ``a(t_TD)`` (plus the pitch under
   the global reset), yaw, pitch and roll of ``R``, the velocities (:func:`chart_out`).

The map's value comes from the same integration (its state part is
:func:`~tslip.spatial._trunk_kernels.run_phase`'s arithmetic, the step sizes
controlled by the state alone), so it is :func:`~tslip.spatial.trunk_section.one_step_map`'s
(to the tolerance for a power-law leg, whose steps the sensitivity's error controls
too). Agreement with central differences: tests/spatial/test_trunk_jacobian.py and
docs/analyses/spatial_tslip.md.
"""

from __future__ import annotations

import math

import numpy as np

from ..model._pack import O_TMAX_FLIGHT, O_TMAX_STANCE
from ..simulation.options import IntegratorOptions
from . import _trunk_kernels as kn
from . import _trunk_variational as tv
from .trunk import TrunkStatus, TrunkTouchdown, _crossed, _heading, rotation, touchdown_fall
from .trunk_parameters import TrunkParams
from .trunk_section import from_section, section

__all__ = ["one_step_jacobian", "two_step_jacobian_exact", "chart_in", "chart_out"]

N = kn.NSTATE


def _hamilton(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    w1, x1, y1, z1 = p
    w2, x2, y2, z2 = q
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                     w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                     w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def _axis_quaternions(yaw: float, pitch: float, roll: float) -> list[tuple[np.ndarray,
                                                                          np.ndarray]]:
    """The quaternions of ``R_y(yaw)``, ``R_z(pitch)``, ``R_x(roll)`` and their derivatives."""
    out = []
    for ang, ax in ((yaw, 2), (pitch, 3), (roll, 1)):
        c, s = math.cos(ang / 2), math.sin(ang / 2)
        q, dq = np.zeros(4), np.zeros(4)
        q[0], q[ax] = c, s
        dq[0], dq[ax] = -0.5 * s, 0.5 * c
        out.append((q, dq))
    return out


def _attitude_derivatives(yaw: float, pitch: float, roll: float) -> list[np.ndarray]:
    """``dR/dyaw``, ``dR/dpitch``, ``dR/droll`` of ``R = R_y R_z R_x``."""
    cy, sy, cp, sp, cr, sr = (math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch),
                              math.cos(roll), math.sin(roll))
    Ry = np.array([[cy, 0.0, sy], [0.0, 1.0, 0.0], [-sy, 0.0, cy]])
    Rz = np.array([[cp, -sp, 0.0], [sp, cp, 0.0], [0.0, 0.0, 1.0]])
    Rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    dRy = np.array([[-sy, 0.0, cy], [0.0, 0.0, 0.0], [-cy, 0.0, -sy]])
    dRz = np.array([[-sp, -cp, 0.0], [cp, -sp, 0.0], [0.0, 0.0, 0.0]])
    dRx = np.array([[0.0, 0.0, 0.0], [0.0, -sr, -cr], [0.0, cr, -sr]])
    return [dRy @ Rz @ Rx, Ry @ dRz @ Rx, Ry @ Rz @ dRx]


def chart_in(params: TrunkParams, x: np.ndarray, side: int) -> tuple[TrunkTouchdown,
                                                                      np.ndarray]:
    """The touch-down of section vector ``x`` (:func:`~.trunk_section.from_section`) and
    ``dy0/dx`` (13 x 10), the CoM's rows relative to the foot (module docstring, link 1)."""
    x = np.asarray(x, dtype=float)
    state = from_section(params, x, side)
    a, yaw, pitch, roll = (float(v) for v in x[0:4])
    R = state.R
    P = params.packed(side)
    P[kn.P_ALPHA], P[kn.P_OMEGA], P[kn.P_GLOBAL], P[kn.P_STOP] = a, 0.0, 0.0, 0.0
    D = np.zeros((N, 10))
    d, dd = np.empty(3), np.empty(3)
    zero = np.zeros((3, 3))
    tv.leg_tangent(P, R, zero, 0.0, 0.0, 0.0, 1.0, d, dd)
    D[0:3, 0] = -params.l0 * (R @ dd)
    for k, dR in enumerate(_attitude_derivatives(yaw, pitch, roll)):
        dR = np.ascontiguousarray(dR)
        tv.leg_tangent(P, R, dR, 0.0, 0.0, 0.0, 0.0, d, dd)
        D[0:3, 1 + k] = -(params.r * dR[:, 1] + params.l0 * (dR @ d + R @ dd))
    (qy, dqy), (qz, dqz), (qx, dqx) = _axis_quaternions(yaw, pitch, roll)
    q = _hamilton(_hamilton(qy, qz), qx)
    sign = 1.0 if float(q @ state.y[6:10]) >= 0.0 else -1.0
    D[6:10, 1] = sign * _hamilton(_hamilton(dqy, qz), qx)
    D[6:10, 2] = sign * _hamilton(_hamilton(qy, dqz), qx)
    D[6:10, 3] = sign * _hamilton(_hamilton(qy, qz), dqx)
    D[3:6, 4:7] = np.eye(3)
    D[10:13, 7:10] = np.eye(3)
    return state, D


def chart_out(P: np.ndarray, y: np.ndarray, t: float) -> np.ndarray:
    """The section's derivative at a touch-down ``y`` (unit quaternion), ``t`` after
    lift-off, with the flight's parameters ``P``: 10 x 15, columns ``y`` (13), ``t`` and
    the retraction clock's start ``t_a`` (module docstring, link 5)."""
    R = np.empty((3, 3))
    dRq = np.empty((4, 3, 3))
    tv.rotation_jacobian(y, R, dRq)
    S = np.zeros((10, N + 2))
    d, dd = np.empty(3), np.empty(3)
    ct = math.hypot(R[0, 0], R[2, 0])
    for k in range(4):
        dR = dRq[k]
        j = 6 + k
        S[0, j] = tv.leg_tangent(P, R, dR, t, 0.0, 0.0, 0.0, d, dd)[1]
        S[1, j] = (R[2, 0] * dR[0, 0] - R[0, 0] * dR[2, 0]) / (ct * ct)
        dct = (R[0, 0] * dR[0, 0] + R[2, 0] * dR[2, 0]) / ct
        S[2, j] = (ct * dR[1, 0] - R[1, 0] * dct) / (R[1, 0] ** 2 + ct * ct)
        S[3, j] = (R[1, 2] * dR[1, 1] - R[1, 1] * dR[1, 2]) / (R[1, 1] ** 2 + R[1, 2] ** 2)
    zero = np.zeros((3, 3))
    S[0, N] = tv.leg_tangent(P, R, zero, t, 1.0, 0.0, 0.0, d, dd)[1]
    S[0, N + 1] = tv.leg_tangent(P, R, zero, t, 0.0, 1.0, 0.0, d, dd)[1]
    S[4:7, 3:6] = np.eye(3)
    S[7:10, 10:13] = np.eye(3)
    return S


def _renormalise(y: np.ndarray, M: np.ndarray) -> None:
    """``q /= |q|`` in ``y`` and its derivative ``(I - q q^T) / |q|`` on ``M``'s rows."""
    q = y[6:10]
    nq = float(np.linalg.norm(q))
    qh = q / nq
    M[6:10] = (np.eye(4) - np.outer(qh, qh)) @ M[6:10] / nq
    y[6:10] = qh


def _fail(what: str, status: TrunkStatus | int) -> ValueError:
    return ValueError(f"one_step_jacobian: the stride from this touch-down fails in the "
                      f"{what} ({TrunkStatus(int(status)).name}): no Jacobian")


def _phase(P: np.ndarray, O: np.ndarray, phase: int, y: np.ndarray,
           tmax: float) -> tuple[int, float, np.ndarray, np.ndarray]:
    out = np.empty(tv.NOUT)
    z = np.concatenate([y, np.eye(N).ravel()])
    st = int(tv.run_phase_var(P, O, phase, z, tmax, out))
    z = out[tv.OUT_Z:]
    return st, float(out[kn.OUT_T]), z[:N].copy(), z[N:].reshape(N, N).copy()


def _stance(params: TrunkParams, state: TrunkTouchdown, D: np.ndarray,
            O: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Links 2-3: the lift-off state and its derivative (13 x k) from ``D = dy0/dx``."""
    P = params.packed(state.side)
    P[kn.P_FOOT:kn.P_FOOT + 3] = state.foot
    y = state.y
    M = D
    t = 0.0
    while True:
        st, dt, y, Phi = _phase(P, O, kn.STANCE, y, O[O_TMAX_STANCE] - t)
        t += dt
        M = Phi @ M
        if st != kn.ST_SWITCH:
            break
        gr = np.empty(N)
        tv.stance_event_gradient(P, y, kn.EV_SWITCH, gr)
        fm = _field(P, kn.STANCE, y)
        P[kn.P_LREST] = params.l0 * (1.0 + params.leg_thrust)
        P[kn.P_PENDING] = 0.0
        fp = _field(P, kn.STANCE, y)
        M = M + np.outer(fm - fp, -(gr @ M) / float(gr @ fm))
    if st != kn.ST_OK:
        raise _fail("stance", st)
    gr = np.empty(N)
    tv.stance_event_gradient(P, y, kn.EV_LIFTOFF, gr)
    f = _field(P, kn.STANCE, y)
    M = M + np.outer(f, -(gr @ M) / float(gr @ f))
    _renormalise(y, M)
    return y, M


def _field(P: np.ndarray, phase: int, y: np.ndarray) -> np.ndarray:
    f = np.empty(N)
    kn.rhs(P, phase, y, f, np.empty((3, 3)), np.empty(16))
    return f


def one_step_jacobian(params: TrunkParams, x: np.ndarray, *, side: int = 1,
                      options: IntegratorOptions | None = None) -> tuple[np.ndarray,
                                                                          np.ndarray]:
    """The next section vector (the other leg's touch-down, as
    :func:`~.trunk_section.one_step_map`) and the exact 10 x 10 Jacobian of the one-step
    map at ``x`` (module docstring). Raises ``ValueError`` in one line if the stride
    fails."""
    if not isinstance(params, TrunkParams):
        raise TypeError(f"params must be TrunkParams, got {type(params).__name__}")
    O = (options or IntegratorOptions()).packed()
    state, D = chart_in(params, x, side)
    fall = touchdown_fall(params, state)
    if fall != TrunkStatus.OK:
        raise _fail("touch-down", fall)
    ylo, M = _stance(params, state, D, O)
    if float(np.dot(ylo[3:6], _heading(rotation(ylo)))) < 0.0:
        raise _fail("lift-off", TrunkStatus.FALL_BACKWARD)
    nxt = -state.side
    P = params.packed(nxt)
    vy = float(ylo[4])
    apex = params.retraction == "apex" and vy > 0.0
    P[kn.P_TA] = vy / params.g if apex else 0.0
    dta = M[4] / params.g if apex else np.zeros(M.shape[1])
    st, tf, y, Psi = _phase(P, O, kn.FLIGHT, ylo, O[O_TMAX_FLIGHT])
    if st != kn.ST_OK:
        raise _fail("flight", st)
    gr = np.empty(N)
    g_t, g_ta = tv.touchdown_partials(P, y, tf, gr)
    f = _field(P, kn.FLIGHT, y)
    G = Psi @ M
    dtf = -(gr @ G + g_ta * dta) / (float(gr @ f) + g_t)
    Y = G + np.outer(f, dtf)
    _renormalise(y, Y)
    R = rotation(y)
    d = np.empty(3)
    kn.leg_direction(P, R, tf, d)
    foot = y[0:3] + params.r * R[:, 1] + params.l0 * (R @ d)
    foot[1] = 0.0
    if _crossed(nxt, foot, y, _heading(R)):
        raise _fail("touch-down", TrunkStatus.FALL_CROSSED_LEG)
    S = chart_out(P, y, tf)
    J = S[:, :N] @ Y + np.outer(S[:, N], dtf) + np.outer(S[:, N + 1], dta)
    return section(params, TrunkTouchdown(y, foot, nxt)), J


def two_step_jacobian_exact(params: TrunkParams, x: np.ndarray, *, side: int = 1,
                            options: IntegratorOptions | None = None
                            ) -> tuple[np.ndarray, np.ndarray]:
    """The section after two strides from ``x`` (``side``, then the other leg) and the
    exact 10 x 10 Jacobian of the two-step map, the product of two one-step Jacobians."""
    x1, J1 = one_step_jacobian(params, x, side=side, options=options)
    x2, J2 = one_step_jacobian(params, x1, side=-side, options=options)
    return x2, J2 @ J1
