# mypy: ignore-errors
# (numba kernels are checked by numba, not mypy: pyproject.toml's [tool.mypy] note)
"""The 3-D TSLIP's stance and flight: one compiled Runge-Kutta loop on the project's core.

Private (issue 43, Part 2; the model is described in :mod:`tslip.spatial.trunk`).
State ``y`` (:data:`NSTATE` = 13), in both phases::

    y[0:3]   c       centre of mass, world frame (x forward, y up, z right)
    y[3:6]   v       its velocity
    y[6:10]  q       unit quaternion (w, x, y, z), trunk frame -> world frame
    y[10:13] w_b     body angular velocity (about x_b, y_b, z_b)

``R(q)`` has the trunk's axes as columns: ``x_b`` forward, ``y_b`` along the
trunk from the CoM to the hip, ``z_b`` right. The quaternion is renormalised
wherever ``R`` is formed, and between phases by the stride (:mod:`._trunk_stride`).

Stance (foot fixed at ``p`` on the ground, ``y_p = 0``): hip ``H = c + r y_b``,
leg ``l u = p - H`` (``u`` hip -> foot), ``ldot = -u . Hdot``. The compressive
leg force ``F_l = F_s(l) - c_l ldot`` (eq. 2.1, the planar law with its
exponent and thrust: :func:`tslip.simulation._stance.spring_force`). The hip
torque ``tau`` of the planar controllers (eqs 2.12-2.16, the four coefficients
of ``Controller.torque_coefficients``) acts about ``z_b``; only its part across
the leg, ``T_perp = tau (z_b - (z_b . u) u)``, reaches the trunk (a point foot
takes no torque about the leg). The foot force on the body is

    F = -F_l u + T_perp x u / l          (moment l u x F = T_perp about the hip),

so ``m c'' = F - m g e_y`` and, about the CoM, ``T = r y_b x F + T_perp``;
Euler's equations ``J w_b' + w_b x J w_b = R^T T`` with ``J = diag(J_roll,
J_yaw, J)``; ``q' = q (0, w_b) / 2``. The controllers' angles: the hip angle
``alpha`` is the angle of the leg's projection on the trunk's sagittal plane,
``atan2(-u_yb, u_xb)``, so ``alphad`` is its rate; the global pitch ``theta =
asin(x_b . e_y)`` is the pitch of the yaw(y)-pitch(z)-roll(x) sequence, and
``betad = alphad - thetad``. Then ``tau = a0 + a1 theta + a2 betad + a3
thetad``, which is the planar law in the planar limit (``phi = theta``).

Flight: ballistic CoM; the trunk a torque-free rigid body (Euler's equations,
``T = 0``). Events are functions > 0 during the phase that fire on a crossing
to <= 0 (docs/conventions.md):

* stance: 0 lift-off ``F . e_y`` (eq. 2.8; ``l_rest - l`` for a power-law leg
  with no damping and no torque, the planar rule), 1 hip height (eq. 2.11),
  2 forward speed ``v . h`` along the trunk's horizontal heading ``h`` (eq.
  2.10), 3 leg collapse ``l - 1e-3 l0``, 4 the leg thrust's switch ``-ldot``
  while it is pending (else 1);
* flight: 0 the foot height ``H_y + l0 (R d)_y`` (eq. 2.9 in 3-D; ``d`` the leg
  direction in the trunk frame, :func:`leg_direction`), 1 hip height (no
  touch-down before the hip reaches the ground).

Known limit: the flight's events are checked at the ends of each accepted step, so
a foot that rises above the ground and comes back below within one step (a
grazing hump shorter than a step) is not seen; the planar flight's certified
safe steps (:func:`tslip.simulation._flight.find_touchdown`) have no 3-D twin yet.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._kernel_cache import check as _check_cache
from ..model._pack import O_ATOL, O_H0, O_HMIN, O_MAXSTEPS, O_METHOD, O_RTOL
from ..simulation import _rk
from ..simulation._rk import _INLINE, _JIT

#: Parameter vector layout (:meth:`tslip.spatial.trunk_parameters.TrunkParams.packed`)
(P_M, P_J, P_JROLL, P_JYAW, P_R, P_K, P_L0, P_G, P_CL, P_NEXP, P_THRUST, P_OMEGA, P_ALPHA,
 P_SPLAY, P_GLOBAL, P_STOP, P_KSPLAY, P_KTRAIL, P_C0) = range(19)
#: Per-phase slots: side, foot (x, y, z), current rest length, thrust pending (1/0),
#: retraction clock start after lift-off; then whether the retraction clock starts at the
#: apex (1/0: ``retraction="apex"``; read by the stride, :mod:`._trunk_stride`)
P_SIDE = P_C0 + 4
P_FOOT = P_SIDE + 1
P_LREST = P_FOOT + 3
P_PENDING = P_LREST + 1
P_TA = P_PENDING + 1
P_APEX = P_TA + 1
NP = P_APEX + 1

NSTATE = 13
STANCE, FLIGHT = 0, 1
NEV = 5
EV_LIFTOFF, EV_HIP, EV_FORWARD, EV_COLLAPSE, EV_SWITCH = range(5)
EV_TOUCHDOWN = 0
L_COLLAPSE = 1e-3

#: Statuses of :func:`run_phase` (named in :class:`tslip.spatial.trunk.TrunkStatus`)
ST_OK = 0
ST_FALL_BACKWARD = 1
ST_FALL_HIP_GROUND = 2
ST_FALL_NO_TOUCHDOWN = 3
ST_FALL_LENGTHENING = 5
ST_FALL_CROSSED_LEG = 6
ST_SWITCH = 9  # internal: the leg thrust switched; the stance goes on
ST_ERR_STEP_UNDERFLOW = 10
ST_ERR_MAX_STEPS = 11
ST_ERR_TIMEOUT = 12
ST_ERR_NONFINITE = 14

#: Output of :func:`run_phase`: status, time, accepted, rejected steps, event, end state
OUT_STATUS, OUT_T, OUT_NSTEP, OUT_NREJ, OUT_EVENT, OUT_NREC = range(6)
OUT_Y = 6
NOUT = OUT_Y + NSTATE


@njit(**_INLINE)
def rotation(y, R):
    """``R`` (3 x 3, columns the trunk axes in the world) of the renormalised quaternion."""
    n = math.sqrt(y[6] * y[6] + y[7] * y[7] + y[8] * y[8] + y[9] * y[9])
    w, a, b, c = y[6] / n, y[7] / n, y[8] / n, y[9] / n
    R[0, 0] = 1.0 - 2.0 * (b * b + c * c)
    R[0, 1] = 2.0 * (a * b - w * c)
    R[0, 2] = 2.0 * (a * c + w * b)
    R[1, 0] = 2.0 * (a * b + w * c)
    R[1, 1] = 1.0 - 2.0 * (a * a + c * c)
    R[1, 2] = 2.0 * (b * c - w * a)
    R[2, 0] = 2.0 * (a * c - w * b)
    R[2, 1] = 2.0 * (b * c + w * a)
    R[2, 2] = 1.0 - 2.0 * (a * a + b * b)


@njit(**_INLINE)
def pitch(R, ww):
    """Pitch ``theta = asin(x_b . e_y)`` of the yaw-pitch-roll sequence and its rate
    ``((w x x_b) . e_y) / cos(theta)`` (``ww`` the world angular velocity)."""
    ct = math.sqrt(R[0, 0] * R[0, 0] + R[2, 0] * R[2, 0])
    th = math.atan2(R[1, 0], ct)
    thd = (ww[2] * R[0, 0] - ww[0] * R[2, 0]) / ct
    return th, thd


@njit(**_INLINE)
def spring_force(P, l):
    """The planar leg law ``F_s = k l0 sgn(x) |x|^n``, ``x = (l_rest - l) / l0``."""
    n = P[P_NEXP]
    lr = P[P_LREST]
    if n == 1.0:
        return P[P_K] * (lr - l)
    x = (lr - l) / P[P_L0]
    f = P[P_K] * P[P_L0] * abs(x) ** n
    return f if x >= 0.0 else -f


@njit(**_INLINE)
def liftoff_on_spring(P):
    """The planar rule: lift-off located as ``l_rest - l`` for ``n != 1``, ``c_l = 0`` and
    no torque."""
    return P[P_NEXP] != 1.0 and P[P_CL] == 0.0 and not has_torque(P)


@njit(**_INLINE)
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(**_JIT)
def stance_terms(P, y, R, o):
    """The stance's forces at ``y`` into ``o`` (16): foot force ``F`` (3), torque about the
    CoM ``T`` (3), ``u`` (3), ``l``, ``ldot``, ``tau``, ``F_l``, ``alpha``, ``alphad``,
    ``theta`` (the last three NaN, and ``tau`` 0, for a controller without torque: the
    right-hand side skips the angles then)."""
    rotation(y, R)
    r = P[P_R]
    ww0 = R[0, 0] * y[10] + R[0, 1] * y[11] + R[0, 2] * y[12]
    ww1 = R[1, 0] * y[10] + R[1, 1] * y[11] + R[1, 2] * y[12]
    ww2 = R[2, 0] * y[10] + R[2, 1] * y[11] + R[2, 2] * y[12]
    ry0, ry1, ry2 = r * R[0, 1], r * R[1, 1], r * R[2, 1]
    e0 = P[P_FOOT] - y[0] - ry0
    e1 = P[P_FOOT + 1] - y[1] - ry1
    e2 = P[P_FOOT + 2] - y[2] - ry2
    l = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    u0, u1, u2 = e0 / l, e1 / l, e2 / l
    c0, c1, c2 = _cross(ww0, ww1, ww2, ry0, ry1, ry2)
    hd0, hd1, hd2 = y[3] + c0, y[4] + c1, y[5] + c2
    ld = -(u0 * hd0 + u1 * hd1 + u2 * hd2)
    fl = spring_force(P, l) - P[P_CL] * ld
    F0, F1, F2 = -fl * u0, -fl * u1, -fl * u2
    t0, t1, t2 = _cross(ry0, ry1, ry2, F0, F1, F2)
    tau = 0.0
    o[13], o[14], o[15] = math.nan, math.nan, math.nan
    if has_torque(P):
        tau = _torque(P, R, y, u0, u1, u2, l, ld, hd0, hd1, hd2, ww0, ww1, ww2, o)
        zu = R[0, 2] * u0 + R[1, 2] * u1 + R[2, 2] * u2
        tp0, tp1, tp2 = (tau * (R[0, 2] - zu * u0), tau * (R[1, 2] - zu * u1),
                         tau * (R[2, 2] - zu * u2))
        m0, m1, m2 = _cross(tp0, tp1, tp2, u0, u1, u2)
        F0, F1, F2 = F0 + m0 / l, F1 + m1 / l, F2 + m2 / l
        t0, t1, t2 = _cross(ry0, ry1, ry2, F0, F1, F2)
        t0, t1, t2 = t0 + tp0, t1 + tp1, t2 + tp2
    o[0], o[1], o[2] = F0, F1, F2
    o[3], o[4], o[5] = t0, t1, t2
    o[6], o[7], o[8] = u0, u1, u2
    o[9], o[10], o[11], o[12] = l, ld, tau, fl


@njit(**_INLINE)
def has_torque(P):
    """Whether the hip controller's law (its four coefficients) can give a torque."""
    return (P[P_C0] != 0.0 or P[P_C0 + 1] != 0.0 or P[P_C0 + 2] != 0.0
            or P[P_C0 + 3] != 0.0)


@njit(**_INLINE)
def _torque(P, R, y, u0, u1, u2, l, ld, hd0, hd1, hd2, ww0, ww1, ww2, o):
    """The hip torque ``tau`` of the controllers' law (module docstring); the hip angle
    ``alpha``, its rate and the pitch into ``o[13:16]``."""
    ub0 = R[0, 0] * u0 + R[1, 0] * u1 + R[2, 0] * u2
    ub1 = R[0, 1] * u0 + R[1, 1] * u1 + R[2, 1] * u2
    ub2 = R[0, 2] * u0 + R[1, 2] * u1 + R[2, 2] * u2
    ud0, ud1, ud2 = (-hd0 - u0 * ld) / l, (-hd1 - u1 * ld) / l, (-hd2 - u2 * ld) / l
    wc0, wc1, _ = _cross(y[10], y[11], y[12], ub0, ub1, ub2)
    ubd0 = R[0, 0] * ud0 + R[1, 0] * ud1 + R[2, 0] * ud2 - wc0
    ubd1 = R[0, 1] * ud0 + R[1, 1] * ud1 + R[2, 1] * ud2 - wc1
    X, Y, Xd, Yd = ub0, -ub1, ubd0, -ubd1
    alphad = (X * Yd - Y * Xd) / (X * X + Y * Y)
    th, thd = pitch(R, (ww0, ww1, ww2))
    o[13], o[14], o[15] = math.atan2(Y, X), alphad, th
    return P[P_C0] + P[P_C0 + 1] * th + P[P_C0 + 2] * (alphad - thd) + P[P_C0 + 3] * thd


@njit(**_INLINE)
def _body_rates(P, y, R, T0, T1, T2, f):
    """Euler's equations and the quaternion kinematics with the world torque ``T``."""
    Tb0 = R[0, 0] * T0 + R[1, 0] * T1 + R[2, 0] * T2
    Tb1 = R[0, 1] * T0 + R[1, 1] * T1 + R[2, 1] * T2
    Tb2 = R[0, 2] * T0 + R[1, 2] * T1 + R[2, 2] * T2
    Jx, Jy, Jz = P[P_JROLL], P[P_JYAW], P[P_J]
    wx, wy, wz = y[10], y[11], y[12]
    f[10] = (Tb0 - (Jz - Jy) * wy * wz) / Jx
    f[11] = (Tb1 - (Jx - Jz) * wz * wx) / Jy
    f[12] = (Tb2 - (Jy - Jx) * wx * wy) / Jz
    qw, qx, qy, qz = y[6], y[7], y[8], y[9]
    f[6] = -0.5 * (qx * wx + qy * wy + qz * wz)
    f[7] = 0.5 * (qw * wx + qy * wz - qz * wy)
    f[8] = 0.5 * (qw * wy + qz * wx - qx * wz)
    f[9] = 0.5 * (qw * wz + qx * wy - qy * wx)


@njit(**_JIT)
def rhs(P, phase, y, f, R, o):
    """The field of the phase (module docstring); ``R`` (3 x 3) and ``o`` (16) are scratch."""
    f[0], f[1], f[2] = y[3], y[4], y[5]
    if phase == STANCE:
        stance_terms(P, y, R, o)
        m = P[P_M]
        f[3], f[4], f[5] = o[0] / m, o[1] / m - P[P_G], o[2] / m
        _body_rates(P, y, R, o[3], o[4], o[5], f)
    else:
        rotation(y, R)
        f[3], f[4], f[5] = 0.0, -P[P_G], 0.0
        _body_rates(P, y, R, 0.0, 0.0, 0.0, f)


@njit(**_JIT)
def swing_angle(P, t):
    """The flight leg's angle ``t`` after lift-off: ``alpha_r + omega_r max(0, t - t_a)``
    held at the stop (the planar :func:`tslip.model.dynamics.swing_angle`); the hip angle
    for the local reset, the leg's pitch for the global one."""
    a = P[P_ALPHA] + P[P_OMEGA] * max(t - P[P_TA], 0.0)
    stop, w = P[P_STOP], P[P_OMEGA]
    if stop == 0.0 or w == 0.0:
        return a
    if w > 0.0:
        return min(a, max(P[P_ALPHA], stop))
    return max(a, min(P[P_ALPHA], stop))


@njit(**_INLINE)
def leg_direction(P, R, t, d):
    """The flight leg's direction in the trunk frame, ``d = (cos a, -sin a cos(splay),
    s sin a sin(splay))``, with the hip angle ``a`` (the global reset adds the pitch).

    The roll couplings (0 in the base model; ``rho`` the roll of the yaw-pitch-roll
    sequence, ``atan2(-R_12, R_11)``, > 0 leaning right): the splay is ``splay +
    k_splay s rho`` (outward when leaning towards the leg), and ``d`` is then turned
    about ``y_b`` by ``-k_trail rho`` (to the right when leaning right, a trail).
    """
    a = swing_angle(P, t)
    if P[P_GLOBAL] != 0.0:
        ct = math.sqrt(R[0, 0] * R[0, 0] + R[2, 0] * R[2, 0])
        a += math.atan2(R[1, 0], ct)
    s = P[P_SIDE]
    sp = P[P_SPLAY]
    ks, kt = P[P_KSPLAY], P[P_KTRAIL]
    rho = 0.0
    if ks != 0.0 or kt != 0.0:
        rho = math.atan2(-R[1, 2], R[1, 1])
        sp += ks * s * rho
    d[0] = math.cos(a)
    d[1] = -math.sin(a) * math.cos(sp)
    d[2] = s * math.sin(a) * math.sin(sp)
    if kt != 0.0:
        psi = -kt * rho
        c, z = math.cos(psi), math.sin(psi)
        d0, d2 = d[0], d[2]
        d[0] = c * d0 + z * d2
        d[2] = -z * d0 + c * d2


@njit(**_JIT)
def events(P, phase, t, y, gv, R, o):
    """The phase's event functions at ``y``, ``t`` into the phase (module docstring)."""
    if phase == STANCE:
        stance_terms(P, y, R, o)
    else:
        rotation(y, R)
    events_at(P, phase, t, y, gv, R, o)


@njit(**_INLINE)
def events_at(P, phase, t, y, gv, R, o):
    """:func:`events` with ``R`` (and, in stance, ``o`` of :func:`stance_terms`) already
    computed at ``y``, as :func:`rhs` leaves them: a step's end needs no second pass."""
    if phase == STANCE:
        l = o[9]
        gv[EV_LIFTOFF] = P[P_LREST] - l if liftoff_on_spring(P) else o[1]
        gv[EV_HIP] = y[1] + P[P_R] * R[1, 1]
        hx, hz = R[0, 0], R[2, 0]
        hn = math.sqrt(hx * hx + hz * hz)
        gv[EV_FORWARD] = (y[3] * hx + y[5] * hz) / hn
        gv[EV_COLLAPSE] = l - L_COLLAPSE * P[P_L0]
        gv[EV_SWITCH] = -o[10] if P[P_PENDING] != 0.0 else 1.0
    else:
        hip_y = y[1] + P[P_R] * R[1, 1]
        d = o[0:3]
        leg_direction(P, R, t, d)
        gv[EV_TOUCHDOWN] = hip_y + P[P_L0] * (R[1, 0] * d[0] + R[1, 1] * d[1] + R[1, 2] * d[2])
        gv[EV_HIP] = hip_y
        for i in range(2, NEV):
            gv[i] = 1.0


#: Length of a phase's work array (:func:`work_views`)
NWORK = (_rk.NK + _rk.NR) * NSTATE + 9 + 16 + 3 * NSTATE + 3 * NEV + 5


@njit(**_INLINE)
def work_views(W):
    """A phase's work arrays as views of ``W`` (:data:`NWORK`): ``K``, the dense output's
    ``Rd``, ``R`` (3 x 3), ``o`` (16), ``y``, ``ytmp``, ``ynew``, the event values old, new
    and trial, and the root bracket ``st`` (5): one allocation a stride, not eleven a phase."""
    a = _rk.NK * NSTATE
    b = a + _rk.NR * NSTATE
    K = W[0:a].reshape((_rk.NK, NSTATE))
    Rd = W[a:b].reshape((_rk.NR, NSTATE))
    R = W[b:b + 9].reshape((3, 3))
    b += 9
    o = W[b:b + 16]
    b += 16
    y, ytmp, ynew = W[b:b + NSTATE], W[b + NSTATE:b + 2 * NSTATE], W[b + 2 * NSTATE:b + 3 * NSTATE]
    b += 3 * NSTATE
    gv_old, gv_new, gv_tmp = W[b:b + NEV], W[b + NEV:b + 2 * NEV], W[b + 2 * NEV:b + 3 * NEV]
    b += 3 * NEV
    return K, Rd, R, o, y, ytmp, ynew, gv_old, gv_new, gv_tmp, W[b:b + 5]


@njit(**_JIT)
def run_phase(P, O, phase, y0, tmax, out, rec):
    """Integrate a phase from ``y0`` to its first event (or ``tmax``: an error).

    Fills ``out`` (:data:`NOUT`): status, duration, accepted and rejected steps, the
    event that ended it, the rows recorded and the state there; ``rec`` (rows of
    ``(t, y)``, 14 columns; may have 0 rows) receives the start and each accepted
    step while it has room. Stance: lift-off ``ST_OK``; the hip at
    the ground or the leg collapsing ``ST_FALL_HIP_GROUND``; moving backward
    ``ST_FALL_BACKWARD``; the thrust's switch ``ST_SWITCH``. Flight: touch-down
    ``ST_OK``, the hip at the ground ``ST_FALL_NO_TOUCHDOWN``. An event searched
    earlier in the order fall, backward, lift-off/touch-down, switch wins a tie.
    """
    return phase_loop(P, O, phase, y0, tmax, out, rec, 0, 0.0, np.empty(NWORK))


@njit(**_INLINE)
def _phase_start(P, O, method, phase, y, K, Rd, R, o, ytmp, gv_old):
    """``K`` and ``Rd`` cleared, ``K[0] = f(y)``, the event values at ``y``; returns the
    first step."""
    for i in range(K.shape[0]):
        for j in range(NSTATE):
            K[i, j] = 0.0
    for i in range(Rd.shape[0]):
        for j in range(NSTATE):
            Rd[i, j] = 0.0
    rhs(P, phase, y, K[0], R, o)
    events_at(P, phase, 0.0, y, gv_old, R, o)
    h = O[O_H0]
    if h <= 0.0:
        h0, d1 = _rk.initial_probe(y, K[0], O[O_RTOL], O[O_ATOL], ytmp)
        rhs(P, phase, ytmp, K[1], R, o)
        h = _rk.initial_step(int(O[O_METHOD]), y, K[0], K[1], h0, d1, O[O_RTOL], O[O_ATOL])
    return h


@njit(**_INLINE)
def _record(rec, nrec, t, y):
    """Row ``nrec`` of ``rec`` is ``(t, y)`` if there is room; returns the rows used."""
    if nrec < rec.shape[0]:
        rec[nrec, 0] = t
        for i in range(NSTATE):
            rec[nrec, 1 + i] = y[i]
        return nrec + 1
    return nrec


@njit(**_INLINE)
def _end_status(phase, which):
    """How a phase ends at the located event ``which`` (:func:`run_phase`)."""
    if which == EV_HIP or which == EV_COLLAPSE:
        return ST_FALL_HIP_GROUND if phase == STANCE else ST_FALL_NO_TOUCHDOWN
    if which == EV_FORWARD:
        return ST_FALL_BACKWARD
    if which == EV_SWITCH:
        return ST_SWITCH
    return ST_OK


@njit(**_JIT)
def _locate(P, method, phase, t, h, y, ynew, K, Rd, R, o, ytmp, gv_old, gv_new, gv_tmp, st):
    """The first event in the accepted step ``y -> ynew`` of size ``h`` at ``t``: its
    fraction ``theta`` of the step (2 if none) and which; the state there into ``ytmp``.
    Each crossing is located by Illinois on the dense output to a bracket of 1e-15 or an
    exact zero of the event function."""
    n = NSTATE
    ns = _rk.n_stages(method)
    for s in range(ns + 1, ns + 1 + _rk.n_extra(method)):
        _rk.stage_state(method, n, y, h, K, s, ytmp)
        rhs(P, phase, ytmp, K[s], R, o)
    _rk.dense_coeffs(method, y, ynew, h, K, Rd)
    theta_ev = 2.0
    which = -1
    for ev in (EV_HIP, EV_COLLAPSE, EV_FORWARD, EV_LIFTOFF, EV_SWITCH):
        if gv_old[ev] > 0.0 and gv_new[ev] <= 0.0:
            _rk.root_start(st, gv_old[ev], gv_new[ev])
            for _ in range(200):
                c = _rk.root_guess(st)
                _rk.dense_eval(method, Rd, c, ytmp)
                events(P, phase, t + c * h, ytmp, gv_tmp, R, o)
                # an exact zero is the root (it closes the bracket at c): stop there, where
                # Illinois would bisect on (halving a zero end value leaves it 0)
                if _rk.root_update(st, c, gv_tmp[ev], 1e-15) or gv_tmp[ev] == 0.0:
                    break
            if st[1] < theta_ev - 1e-9:
                theta_ev = st[1]
                which = ev
    _rk.dense_eval(method, Rd, theta_ev, ytmp)
    return theta_ev, which


@njit(**_INLINE)
def _guard(O, n_tried, t, tmax, h):
    """``ST_OK`` if the phase may take another step (``n_tried`` steps taken, accepted
    or not), else the error that stops it."""
    if n_tried >= O[O_MAXSTEPS]:
        return ST_ERR_MAX_STEPS
    if t > tmax:
        return ST_ERR_TIMEOUT
    if h < O[O_HMIN]:
        return ST_ERR_STEP_UNDERFLOW
    return ST_OK


@njit(**_INLINE)
def _fired(gv_old, gv_new):
    """Whether an event function crossed from > 0 to <= 0 over the step."""
    for ev in range(NEV):
        if gv_old[ev] > 0.0 and gv_new[ev] <= 0.0:
            return True
    return False


@njit(**_INLINE)
def _probe(P, phase, y, K, d, ytmp, gv_tmp, R, o):
    """The lift-off function at the probe ``y + d f(y)`` (``K[0] = f(y)``, the start's
    until a first step is accepted), time ``d``: :func:`_rk.jumped_hump`'s ``g_probe``."""
    for i in range(NSTATE):
        ytmp[i] = y[i] + d * K[0, i]
    events(P, phase, d, ytmp, gv_tmp, R, o)
    return gv_tmp[0]


@njit(**_JIT)
def phase_loop(P, O, phase, y0, tmax, out, rec, nrec0, t0, W):
    """:func:`run_phase` on the work array ``W`` (:data:`NWORK`), its rows into ``rec`` from
    row ``nrec0`` on at times ``t0 + t`` (a stance continued after the thrust's switch);
    ``out[OUT_NREC]`` counts this phase's rows."""
    n = NSTATE
    method = int(O[O_METHOD])
    rtol, atol = O[O_RTOL], O[O_ATOL]
    K, Rd, R, o, y, ytmp, ynew, gv_old, gv_new, gv_tmp, st = work_views(W)
    for i in range(out.shape[0]):
        out[i] = np.nan
    for i in range(n):
        y[i] = y0[i]
    h = _phase_start(P, O, method, phase, y, K, Rd, R, o, ytmp, gv_old)
    # the probe of a lift-off function starting at its zero (a ZERO_PROBE of the first
    # step), read once if a first stance step ends at or below zero (_rk.jumped_hump)
    g_start, g_probe, d_probe = gv_old[0], math.nan, _rk.ZERO_PROBE * h
    hump = phase == STANCE
    nrec = _record(rec, nrec0, t0, y)
    last_rejected = False
    t = 0.0
    nstep = 0
    nrej = 0
    which = -1
    while True:
        status = _guard(O, nstep + nrej, t, tmax, h)
        if status != ST_OK:
            break
        ns = _rk.n_stages(method)
        for s in range(1, ns):
            _rk.stage_state(method, n, y, h, K, s, ytmp)
            rhs(P, phase, ytmp, K[s], R, o)
        _rk.stage_state(method, n, y, h, K, ns, ynew)
        rhs(P, phase, ynew, K[ns], R, o)
        err = _rk.error_norm(method, n, y, ynew, h, K, rtol, atol)
        if not err <= 1.0:
            nrej += 1
            last_rejected = True
            h *= 0.1 if not math.isfinite(err) else _rk.step_factor(method, err, 10.0)
            continue
        events_at(P, phase, t + h, ynew, gv_new, R, o)  # R, o: the last stage's, at ynew
        if hump and gv_new[0] <= 0.0:
            if g_probe != g_probe:
                g_probe = _probe(P, phase, y, K, d_probe, ytmp, gv_tmp, R, o)
            if _rk.jumped_hump(g_start, gv_new[0], g_probe):
                nrej += 1
                h *= _rk.HUMP_SHRINK
                continue
        hump = False
        nstep += 1
        if _fired(gv_old, gv_new):
            theta_ev, which = _locate(P, method, phase, t, h, y, ynew, K, Rd, R, o, ytmp,
                                      gv_old, gv_new, gv_tmp, st)
            for i in range(n):
                out[OUT_Y + i] = ytmp[i]
            out[OUT_T] = t + theta_ev * h
            status = _end_status(phase, which)
            break
        if not _rk.all_finite(n, ynew):
            status = ST_ERR_NONFINITE
            break
        t += h
        _rk.accept_step(method, n, y, ynew, K)
        nrec = _record(rec, nrec, t0 + t, y)
        for ev in range(NEV):
            gv_old[ev] = gv_new[ev]
        fac = _rk.step_factor(method, err, 10.0)
        h *= min(1.0, fac) if last_rejected else fac
        last_rejected = False
    _phase_end(status, t, y, nstep, nrej, which, nrec - nrec0, out)
    return status


@njit(**_INLINE)
def _phase_end(status, t, y, nstep, nrej, which, nrec, out):
    """``out`` of a phase (:func:`run_phase`); after an error, the last accepted state."""
    if status >= 10:
        for i in range(NSTATE):
            out[OUT_Y + i] = y[i]
        out[OUT_T] = t
    out[OUT_STATUS] = status
    out[OUT_NSTEP] = nstep
    out[OUT_NREJ] = nrej
    out[OUT_EVENT] = which
    out[OUT_NREC] = nrec


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(run_phase, __file__)
