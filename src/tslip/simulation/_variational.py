"""Compiled kernels for the exact Jacobian of the touch-down map.

The stride map ``q -> q'`` on the section ``q = (beta, phi, xd, yd, phid)`` is a
chain; each link is differentiated exactly:

1. touch-down state -> stance state ``y0`` (eq. A.5 inverted), analytic;
2. the stance flow, by *internal numerical differentiation*: the same
   Runge-Kutta step sequence is replayed with each stage's sensitivity
   ``dK_i = Df(Y_i) dY_i``, which is the variational equation integrated by the
   same Runge-Kutta scheme (so it is the derivative of the computed map); for a
   power-law leg (``n != 1``) each recorded step is split where the error estimate
   of ``(y, Phi)`` asks for it (:func:`_sens_steps`: the leg's stiffness
   ``|x|^(n-1)`` is not smooth at the spring's rest length);
3. the lift-off event ``F_y = 0`` (``l_rest - l = 0`` when
   :func:`._stance.liftoff_on_spring`) by the saltation (event-time) correction
   ``dy_LO = Phi - f (grad F_y . Phi) / (grad F_y . f)``;
4. lift-off -> CoM flight state, analytic;
5. the closed-form flight, with the touch-down time's implicit derivative
   ``dt_TD = -(df/dlo) / (df/dt)`` for the foot height ``f``; with the apex
   retraction clock (``retraction="apex"``) the touch-down leg angle also
   depends on the lift-off ``ydot`` through the apex time ``t_apex = ydot / g``,
   ``d beta / d ydot = -omega_r / g`` when the leg retracts at touch-down (0 when
   it touches down still held, and for a flight without apex); a touch-down
   after the retraction stop (``alpha_stop``) has a constant hip angle, whose
   derivatives are 0.

``Df`` comes from differentiating ``M qdd = R`` (eq. 2.3, ``R = Q - C``):
``d qdd = M^-1 (dR - dM qdd)``, with the closed-form ``M^-1`` of
:func:`._stance.stance_accel`.

One kernel, :func:`stride_jacobian`, for both integrator methods (the pair is read
from the options ``O`` at run time, ``O[O_METHOD]``), which calls the stride kernel
(:func:`._stride.stride`) recording every accepted step, then takes the links above
in turn, each a named helper; :func:`_aug_rhs` compiles on its own, the other helpers
are ``inline="always"``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._kernel_cache import check as _check_cache
from ..model._pack import (
    NREC,
    O_ATOL,
    O_METHOD,
    O_RTOL,
    OUT_LO,
    OUT_NREC,
    OUT_RECOVF,
    OUT_TF,
    OUT_TSW,
    P_C0,
    P_CL,
    P_G,
    P_GLOBAL,
    P_J,
    P_L0,
    P_M,
    P_NEXP,
    P_OMEGA,
    P_R,
    P_THRUST,
    ST_OK,
)
from . import _rk
from ._flight import flight_leg_angle, retraction_start, stop_time
from ._rk import _INLINE, _JIT
from ._stance import (
    NSTATE,
    hip_torque,
    leg_force,
    liftoff_on_spring,
    rhs,
    spring_slope,
    stance_initial,
)
from ._stepper import NONFINITE_SHRINK
from ._stride import stride


@njit(**_INLINE)
def _solve_m(P, l, sa, ca, v1, v2, v3):
    """``M^-1 v`` in closed form (Schur complement on the phi row is ``J``)."""
    r = P[P_R]
    x3 = (v3 + r * ca * v1 - r * sa * v2 / l) / P[P_J]
    return v1 / P[P_M] + r * ca * x3, v2 / (P[P_M] * l * l) - r * sa / l * x3, x3


@njit(**_INLINE)
def rhs_jacobian(P, y, Jf, ldd, bdd, phdd):
    """Jacobian ``Df`` (6 x 6) of the stance right-hand side at ``y``.

    ``ldd, bdd, phdd``: the accelerations at ``y`` (:func:`._stance.stance_accel`,
    which the caller has just computed for ``f(y)``).
    """
    m = P[P_M]
    r = P[P_R]
    g = P[P_G]
    cl = P[P_CL]
    a1, a2, a3 = P[P_C0 + 1], P[P_C0 + 2], P[P_C0 + 3]
    l, b, ph, ld, bd, phd = y[0], y[1], y[2], y[3], y[4], y[5]
    sb, cb = math.sin(b), math.cos(b)
    sp, cp = math.sin(ph), math.cos(ph)
    sa = sb * cp + cb * sp
    ca = cb * cp - sb * sp
    for i in range(6):
        for j in range(6):
            Jf[i, j] = 0.0
    Jf[0, 3] = 1.0
    Jf[1, 4] = 1.0
    Jf[2, 5] = 1.0
    # dR/dy_j - dM/dy_j qdd, column by column (R = Q - C of eqs A.11, A.13)
    # d/dl: dM22 = 2 m l, dM23 = m r sa
    c1 = spring_slope(P, l) + m * bd * bd
    c2 = -m * g * cb - m * r * phd * phd * ca - 2.0 * m * bd * ld - (2.0 * m * l * bdd
                                                                       + m * r * sa * phdd)
    c3 = -m * r * bd * bd * ca - m * r * sa * bdd
    Jf[3, 0], Jf[4, 0], Jf[5, 0] = _solve_m(P, l, sa, ca, c1, c2, c3)
    # d/dbeta and d/dphi share dM: dM13 = m r sa, dM23 = m r l ca
    dm1 = m * r * sa * phdd
    dm2 = m * r * l * ca * phdd
    dm3 = m * r * sa * ldd + m * r * l * ca * bdd
    c1 = -m * g * cb - m * r * phd * phd * ca - dm1
    c2 = m * g * l * sb + m * r * l * phd * phd * sa - dm2
    c3 = m * r * l * bd * bd * sa - 2.0 * m * r * bd * ld * ca - dm3
    Jf[3, 1], Jf[4, 1], Jf[5, 1] = _solve_m(P, l, sa, ca, c1, c2, c3)
    c1 = -m * r * phd * phd * ca - dm1
    c2 = a1 + m * r * l * phd * phd * sa - dm2
    c3 = a1 - m * g * r * cp + m * r * l * bd * bd * sa - 2.0 * m * r * bd * ld * ca - dm3
    Jf[3, 2], Jf[4, 2], Jf[5, 2] = _solve_m(P, l, sa, ca, c1, c2, c3)
    # velocities: M does not depend on them
    Jf[3, 3], Jf[4, 3], Jf[5, 3] = _solve_m(P, l, sa, ca, -cl, -2.0 * m * l * bd,
                                            -2.0 * m * r * bd * sa)
    Jf[3, 4], Jf[4, 4], Jf[5, 4] = _solve_m(
        P, l, sa, ca, 2.0 * m * l * bd, a2 - 2.0 * m * l * ld,
        a2 - 2.0 * m * r * l * bd * ca - 2.0 * m * r * ld * sa)
    Jf[3, 5], Jf[4, 5], Jf[5, 5] = _solve_m(
        P, l, sa, ca, -2.0 * m * r * phd * sa, a3 - 2.0 * m * r * l * phd * ca, a3)


@njit(**_INLINE)
def fy_gradient(P, y, gr):
    """Gradient of the lift-off event with respect to the stance state: of ``F_y``
    (eq. 2.6), or of ``l_rest - l`` when :func:`._stance.liftoff_on_spring`."""
    l, b, ph, ld, bd, phd = y[0], y[1], y[2], y[3], y[4], y[5]
    if liftoff_on_spring(P):
        for i in range(NSTATE):
            gr[i] = 0.0
        gr[0] = -1.0
        return
    sb, cb = math.sin(b), math.cos(b)
    tau = hip_torque(P, ph, bd, phd)
    fl = leg_force(P, l, ld)
    gr[0] = spring_slope(P, l) * sb - tau * cb / (l * l)
    gr[1] = fl * cb - tau / l * sb
    gr[2] = P[P_C0 + 1] * cb / l
    gr[3] = -P[P_CL] * sb
    gr[4] = P[P_C0 + 2] * cb / l
    gr[5] = P[P_C0 + 3] * cb / l


NAUG = NSTATE + NSTATE * NSTATE  # y and the sensitivity Phi, row-major


@njit(**_JIT)
def _aug_rhs(P, z, out, Jf):
    """Right-hand side of ``(y, Phi)``: ``(f(y), Df(y) Phi)``, the variational equation.

    The position rows of ``Df`` are ``[0 I]`` (``q' = qd``), so the position
    rows of ``Df Phi`` are the velocity rows of ``Phi``, copied: the same
    numbers as the full product (whose other terms are exact zeros), for half
    its multiplications.
    """
    y = z[:NSTATE]
    rhs(P, y, out[:NSTATE])
    rhs_jacobian(P, y, Jf, out[3], out[4], out[5])  # the accelerations of f(y)
    half = NSTATE // 2
    for i in range(half):
        for c in range(NSTATE):
            out[NSTATE + i * NSTATE + c] = z[NSTATE + (i + half) * NSTATE + c]
    for i in range(half, NSTATE):
        for c in range(NSTATE):
            acc = 0.0
            for q in range(NSTATE):
                acc += Jf[i, q] * z[NSTATE + q * NSTATE + c]
            out[NSTATE + i * NSTATE + c] = acc


@njit(**_INLINE)
def _sens_step(P, method, z, h, K, ztmp, Jf):
    """One step of ``(y, Phi)`` (in place) with the Runge-Kutta pair of the stride.

    A Runge-Kutta method commutes with linearisation, so this is the
    derivative of the computed step; the ``y`` part repeats the stride's
    stage arithmetic (:func:`._rk.stage_state` acts elementwise), with the
    step sizes recovered from the recorded times.
    """
    _aug_rhs(P, z, K[0], Jf)
    ns = _rk.n_stages(method)
    for s in range(1, ns):
        _rk.stage_state(method, NAUG, z, h, K, s, ztmp)
        _aug_rhs(P, ztmp, K[s], Jf)
    _rk.stage_state(method, NAUG, z, h, K, ns, ztmp)
    for i in range(NAUG):
        z[i] = ztmp[i]


#: At most this many substeps of one recorded step in :func:`_sens_steps` (a Table 2.1
#: stance at ``n = 1.2``, ``k`` 20 x 0.15^-0.2, DOP853 at 1e-12: 40 recorded steps, 116
#: attempted substeps, at most 9 in one step).
MAX_SUBSTEPS = 10000
#: The largest growth of a substep after an accepted one (below the stride's
#: ``_stepper.FAC_MAX``: the substeps end at the recorded step's end, no further)
SUBSTEP_FAC_MAX = 5.0
#: A substep this small (a fraction of the recorded step) is accepted whatever its error:
#: the error control of ``Phi`` cannot stall the replay at the spring's rest length
SUBSTEP_MIN = 1e-12


@njit(**_INLINE)
def _sens_steps(P, O, method, z, h, K, ztmp, zold, Jf, rec_row):
    """One recorded step ``h`` of ``(y, Phi)`` (in place), split where ``Phi`` needs it.

    A linear leg (``n = 1``): :func:`_sens_step`, the derivative of the computed step.
    A power-law leg (``n != 1``): ``dF_s/dl = -k n |x|^(n-1)`` is not smooth at the
    spring's rest length ``x = 0`` (not Lipschitz for ``n < 2``), and the variational
    equation, whose right-hand side carries it, loses one order of smoothness more than
    the state there: the stride's steps, sized by the state's error alone, leave an
    error of about ``tol^(n/(n+1))`` in ``Phi`` where a stance ends on the spring's zero
    (:func:`._stance.liftoff_on_spring`; the Jacobian was off by 1e-7 to 1.1e-5 at
    tolerance 1e-12 for ``n`` 1.2-1.5, by 2e-9 at most with this). So the recorded step
    is integrated with error control on ``(y, Phi)`` by the same pair and tolerances (the
    whole step first, the same arithmetic as :func:`_sens_step` if that is accepted), and
    ``y`` is then reset to the stride's recorded state ``rec_row[1:]``. Table 2.1
    stances attempt 1.5 to 3 times the recorded steps (``tests/gait/
    test_power_law_jacobian.py`` compares against an independent model).
    """
    if P[P_NEXP] == 1.0:
        _sens_step(P, method, z, h, K, ztmp, Jf)
        return
    ns = _rk.n_stages(method)
    rtol, atol = O[O_RTOL], O[O_ATOL]
    done = 0.0
    hs = h
    for _ in range(MAX_SUBSTEPS):
        last = done + hs >= h
        if last:
            hs = h - done
        for i in range(NAUG):
            zold[i] = z[i]
        _sens_step(P, method, z, hs, K, ztmp, Jf)
        _aug_rhs(P, z, K[ns], Jf)  # the FSAL row of the error estimate
        err = _rk.error_norm(method, NAUG, zold, z, hs, K, rtol, atol)
        if err <= 1.0 or hs <= SUBSTEP_MIN * h:
            done += hs
            if last:
                break
            hs *= _rk.step_factor(method, err, SUBSTEP_FAC_MAX)
        else:
            for i in range(NAUG):
                z[i] = zold[i]
            hs *= _rk.step_factor(method, err, 1.0) if math.isfinite(err) else NONFINITE_SHRINK
    for i in range(NSTATE):
        z[i] = rec_row[1 + i]


@njit(**_INLINE)
def _switch_saltation(Pw, z):
    """The thrust's switch at ``(y, Phi) = z`` (event ``-ldot = 0``): ``Pw`` switches its
    rest length and ``Phi += (f- - f+) dt_sw`` with ``dt_sw = -Phi[3] / f-[3]``, the
    saltation of a vector field that jumps on an event surface."""
    fm = np.empty(NSTATE)
    fp = np.empty(NSTATE)
    rhs(Pw, z[:NSTATE], fm)
    Pw[P_THRUST] = -Pw[P_THRUST]
    rhs(Pw, z[:NSTATE], fp)
    for c in range(NSTATE):
        dt = -z[NSTATE + 3 * NSTATE + c] / fm[3]
        for i in range(NSTATE):
            z[NSTATE + i * NSTATE + c] += (fm[i] - fp[i]) * dt


@njit(**_INLINE)
def _fail(Jq):
    """``Jq`` all NaN: a stride that did not end in a touch-down has no Jacobian."""
    for i in range(5):
        for j in range(5):
            Jq[i, j] = math.nan


@njit(**_INLINE)
def _touchdown_jacobian(P, td, y):
    """Link 1: the stance state ``y`` at touch-down (eq. A.5 inverted, into ``y``) and its
    Jacobian ``dy0/dq`` (6 x 5, returned), ``q = (beta, phi, xd, yd, phid)``."""
    l0 = P[P_L0]
    r = P[P_R]
    stance_initial(P, td, y)
    b, ph, xd, yd, phd = td[0], td[1], td[2], td[3], td[4]
    sb, cb = math.sin(b), math.cos(b)
    sp, cp = math.sin(ph), math.cos(ph)
    u = xd - r * cp * phd
    w = yd - r * sp * phd
    du = np.array([0.0, r * sp * phd, 1.0, 0.0, -r * cp])
    dw = np.array([0.0, -r * cp * phd, 0.0, 1.0, -r * sp])
    D0 = np.zeros((NSTATE, 5))
    D0[1, 0] = 1.0
    D0[2, 1] = 1.0
    D0[5, 4] = 1.0
    for j in range(5):
        D0[3, j] = -cb * du[j] + sb * dw[j]
        D0[4, j] = (sb * du[j] + cb * dw[j]) / l0
    D0[3, 0] += u * sb + w * cb
    D0[4, 0] += (u * cb - w * sb) / l0
    return D0


@njit(**_INLINE)
def _replay_stance(Pw, O, method, y, rec, nrec, tsw):
    """Link 2: ``(y, Phi)`` at lift-off (returned, :data:`NAUG`), the stride's accepted steps
    (``rec``'s ``nrec`` rows) replayed from ``y`` with sensitivities (:func:`_sens_steps`),
    the thrust's switch at ``tsw`` (NaN if none) crossed by :func:`_switch_saltation`
    (which switches the working parameters ``Pw`` in place)."""
    z = np.zeros(NAUG)
    for i in range(NSTATE):
        z[i] = y[i]
        # Phi's column 0, the response to the touch-down leg length, stays 0: that
        # length is l0 on the section (D0's row 0 is 0), and the stiffness |x|^(n-1)
        # of a power-law leg is not smooth at touch-down (_sens_steps)
        z[NSTATE + i * NSTATE + i] = 1.0 if i > 0 else 0.0
    K = np.empty((_rk.NK, NAUG))
    ztmp = np.empty(NAUG)
    zold = np.empty(NAUG)
    Jf = np.empty((NSTATE, NSTATE))
    for k in range(1, nrec):
        h = rec[k, 0] - rec[k - 1, 0]
        if h > 0.0:
            _sens_steps(Pw, O, method, z, h, K, ztmp, zold, Jf, rec[k])
        if rec[k, 0] == tsw and Pw[P_THRUST] > 0.0:
            _switch_saltation(Pw, z)
    return z


@njit(**_INLINE)
def _liftoff_saltation(Pw, z, D0, y):
    """Link 3: ``dy_LO/dq`` (6 x 5, returned) from the replay's ``z = (y, Phi)``: ``Phi D0``
    corrected by the lift-off's saltation ``dt_LO = -(grad F_y . Phi) / (grad F_y . f)``
    (:func:`fy_gradient`); ``y`` receives the lift-off stance state."""
    for i in range(NSTATE):
        y[i] = z[i]
    Phi = z[NSTATE:].copy().reshape((NSTATE, NSTATE))
    f = np.empty(NSTATE)
    rhs(Pw, y, f)
    gr = np.empty(NSTATE)
    fy_gradient(Pw, y, gr)
    gf = 0.0
    for i in range(NSTATE):
        gf += gr[i] * f[i]
    S = Phi @ D0  # dy_LO/dq before the event correction
    dtlo = np.zeros(5)
    for j in range(5):
        acc = 0.0
        for i in range(NSTATE):
            acc += gr[i] * S[i, j]
        dtlo[j] = -acc / gf
    for i in range(NSTATE):
        for j in range(5):
            S[i, j] += f[i] * dtlo[j]
    return S


@njit(**_INLINE)
def _liftoff_com_jacobian(r, y):
    """Link 4: the Jacobian (5 x 6) of the lift-off CoM state ``lo = (y_m, xd, yd, phi,
    phid)`` with respect to the stance state ``y`` (eqs A.3-A.5; ``r = P[P_R]``)."""
    l, b, ph, ld, bd, phd = y[0], y[1], y[2], y[3], y[4], y[5]
    sb, cb = math.sin(b), math.cos(b)
    sp, cp = math.sin(ph), math.cos(ph)
    L = np.zeros((5, NSTATE))
    L[0, 0], L[0, 1], L[0, 2] = sb, l * cb, r * sp
    L[1, 0], L[1, 1], L[1, 2] = sb * bd, ld * sb + l * cb * bd, -r * sp * phd
    L[1, 3], L[1, 4], L[1, 5] = -cb, l * sb, r * cp
    L[2, 0], L[2, 1], L[2, 2] = cb * bd, ld * cb - l * sb * bd, r * cp * phd
    L[2, 3], L[2, 4], L[2, 5] = sb, l * cb, r * sp
    L[3, 2] = 1.0
    L[4, 5] = 1.0
    return L


@njit(**_INLINE)
def _flight_jacobian(P, out, G, Jq):
    """Link 5: ``Jq = dq'/dq`` from ``G = d lo/dq`` through the closed-form flight of the
    stride ``out``, with the touch-down time's implicit derivative for the foot height
    ``f(t) = y + yd t - g t^2/2 + r cos(phi(t)) - l0 sin(beta(t)) - H``."""
    l0 = P[P_L0]
    r = P[P_R]
    g = P[P_G]
    tf = out[OUT_TF]
    phi0 = out[OUT_LO + 4]
    phid0 = out[OUT_LO + 5]
    yd0 = out[OUT_LO + 3]
    ta = retraction_start(P, yd0)
    bt, bdot = flight_leg_angle(P, phi0, phid0, tf, ta)
    pht = phi0 + phid0 * tf
    local = P[P_GLOBAL] == 0.0
    dbdphi = -1.0 if local else 0.0
    dbdphid = -tf if local else 0.0
    # apex clock: beta = alpha_r + omega_r (t - yd0 / g) [- phi(t)] once retracting,
    # until the retraction stop (then the hip angle is a constant)
    dbdyd = -P[P_OMEGA] / g if (ta > 0.0 and tf >= ta and tf < stop_time(P, ta)) else 0.0
    spt, cbt = math.sin(pht), math.cos(bt)
    # partials of f with respect to lo = (y, xd, yd, phi, phid) and t
    df = np.array([1.0, 0.0, tf, -r * spt - l0 * cbt * dbdphi,
                   -r * spt * tf - l0 * cbt * dbdphid])
    if dbdyd != 0.0:
        df[2] -= l0 * cbt * dbdyd
    dfdt = yd0 - g * tf - r * spt * phid0 - l0 * cbt * bdot
    dttd = np.zeros(5)
    for j in range(5):
        acc = 0.0
        for i in range(5):
            acc += df[i] * G[i, j]
        dttd[j] = -acc / dfdt
    # q' = (beta(t), phi(t), xd, yd - g t, phid)
    for j in range(5):
        Jq[0, j] = dbdphi * G[3, j] + dbdphid * G[4, j] + bdot * dttd[j]
        if dbdyd != 0.0:
            Jq[0, j] += dbdyd * G[2, j]
        Jq[1, j] = G[3, j] + tf * G[4, j] + phid0 * dttd[j]
        Jq[2, j] = G[1, j]
        Jq[3, j] = G[2, j] - g * dttd[j]
        Jq[4, j] = G[4, j]


@njit(**_JIT)
def stride_jacobian(P, O, td, tx, th, Jq, out):
    """Next touch-down state and its exact Jacobian ``Jq = dq'/dq`` (5 x 5), the links of
    the module docstring in turn, with the Runge-Kutta pair ``O[O_METHOD]``.

    Returns the stride status; ``out`` is filled as by :func:`._stride.stride`.
    """
    rec = np.empty((4096, NREC))
    status = stride(P, O, td, tx, th, rec, 0.0, out)
    if status != ST_OK or out[OUT_RECOVF] != 0.0:
        _fail(Jq)
        return status
    y = np.empty(NSTATE)
    D0 = _touchdown_jacobian(P, td, y)
    Pw = P.copy() if P[P_THRUST] > 0.0 else P  # the stance's working parameters
    z = _replay_stance(Pw, O, int(O[O_METHOD]), y, rec, int(out[OUT_NREC]), out[OUT_TSW])
    S = _liftoff_saltation(Pw, z, D0, y)
    G = _liftoff_com_jacobian(P[P_R], y) @ S  # d lo / dq
    _flight_jacobian(P, out, G, Jq)
    return status


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(_aug_rhs, __file__)

