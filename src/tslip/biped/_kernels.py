"""Compiled biped kernels: TMT dynamics, contact, controller, Runge-Kutta with events.

Private. Arguments are float64 arrays, floats and ints; results are arrays and
an int status (codes in :mod:`._pack`). Everything also runs with
``NUMBA_DISABLE_JIT=1``.

The integrator is the shared core :mod:`tslip.simulation._rk` (tableaus, error
norm, dense output, event root finding); only its stage loop is written here,
with this model's right-hand side (the core cannot take the right-hand side as
an argument and stay cacheable, see there).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._kernel_cache import check as _check_cache
from ..simulation import _rk
from ._pack import (
    CS_ON_L,
    CS_ON_R,
    CS_XR,
    CS_ZR,
    EV_FALL,
    EV_LO_R,
    EV_TD_R,
    NCS,
    O_ATOL,
    O_FALLS,
    O_H0,
    O_HMAX,
    O_HMIN,
    O_MAXSTEPS,
    O_METHOD,
    O_RTOL,
    O_TEND,
    O_TSTRIDE,
    P_ACT,
    P_CL,
    P_CONTACT,
    P_CX,
    P_CZ,
    P_D,
    P_G,
    P_JB,
    P_JS,
    P_JT,
    P_K,
    P_KDH,
    P_KDT,
    P_KPH,
    P_KPT,
    P_KX,
    P_KZ,
    P_LS0,
    P_LT0,
    P_LTS,
    P_MB,
    P_MF,
    P_MS,
    P_MT,
    P_R1,
    P_R2,
    P_RHO0,
    P_T,
    P_THF,
    P_THS,
    R_CON,
    R_F,
    R_FS,
    R_FT,
    R_TAU,
    R_Y,
    S_NACC,
    S_NEV,
    S_NFEV,
    S_NREC,
    S_NREJ,
    S_NSTRIDE,
    S_RECFULL,
    S_TEND,
    ST_ERR_MAX_STEPS,
    ST_ERR_NONFINITE,
    ST_ERR_UNDERFLOW,
    ST_FALL_BACKWARD,
    ST_FALL_HIP,
    ST_FALL_LEG,
    ST_FALL_NO_TD,
    ST_FALL_PITCH,
    ST_OK,
    ST_TEND,
)

_JIT = {"cache": True, "nogil": True, "fastmath": False, "error_model": "numpy"}
N = 18  # state size
NB = 7  # bodies: trunk, thigh R, shank R, foot R, thigh L, shank L, foot L
FOOT = (3, 6)

# ---------------------------------------------------------------------------
# Kinematics and TMT terms (eqs E.1-E.22)
# ---------------------------------------------------------------------------


@njit(**_JIT)
def body_props(P, mass, inertia):
    """Masses and inertias of the 7 bodies (diagonal of eq. E.13)."""
    mass[0] = P[P_MB]
    inertia[0] = P[P_JB]
    for j in range(2):
        mass[1 + 3 * j] = P[P_MT]
        inertia[1 + 3 * j] = P[P_JT]
        mass[2 + 3 * j] = P[P_MS]
        inertia[2 + 3 * j] = P[P_JS]
        mass[3 + 3 * j] = P[P_MF]
        inertia[3 + 3 * j] = 0.0


@njit(**_JIT)
def kinematics(P, q, qd, pos, Jp, Ja, cv):
    """Body positions, Jacobians and convective accelerations (eqs E.4-E.12, E.20).

    ``pos[i]`` is the CoM of body ``i`` (eqs E.4-E.8), ``Jp[i]`` its (2, 9)
    position Jacobian, ``Ja[i]`` the (9,) Jacobian of its angle and ``cv[i]``
    the convective acceleration ``(dJp/dq qd) qd``. Segment angles have no
    convective term (they are linear in q).
    """
    for i in range(NB):
        for a in range(9):
            Jp[i, 0, a] = 0.0
            Jp[i, 1, a] = 0.0
            Ja[i, a] = 0.0
        Jp[i, 0, 0] = 1.0
        Jp[i, 1, 1] = 1.0
    r1 = P[P_R1]
    r2 = P[P_R2]
    tb = q[2]
    tbd = qd[2]
    sb = math.sin(tb)
    cb = math.cos(tb)
    pos[0, 0] = q[0]
    pos[0, 1] = q[1]
    Ja[0, 2] = 1.0
    cv[0, 0] = 0.0
    cv[0, 1] = 0.0
    hx = q[0] + r1 * sb  # hip, eq. E.5 (b_z = (sin, cos) theta_b, eq. E.2)
    hz = q[1] + r1 * cb
    hcx = -r1 * sb * tbd * tbd
    hcz = -r1 * cb * tbd * tbd
    for j in range(2):
        b = 3 + 3 * j
        lt = q[b]
        ls = q[b + 1]
        gam = tb + q[b + 2]  # leg angle in the world (eq. E.3)
        gd = tbd + qd[b + 2]
        ux = math.sin(gam)
        uz = math.cos(gam)
        upx = uz  # du/dgamma
        upz = -ux
        for k in range(3):
            if k == 0:  # thigh CoM, eq. E.6
                ca, cb2 = r2, 0.0
            elif k == 1:  # shank CoM, eq. E.7
                ca, cb2 = 1.0, r2
            else:  # foot, eq. E.8
                ca, cb2 = 1.0, 1.0
            i = 1 + 3 * j + k
            s = ca * lt + cb2 * ls
            sd = ca * qd[b] + cb2 * qd[b + 1]
            pos[i, 0] = hx - s * ux
            pos[i, 1] = hz - s * uz
            Jp[i, 0, 2] = r1 * cb - s * upx
            Jp[i, 1, 2] = -r1 * sb - s * upz
            Jp[i, 0, b + 2] = -s * upx
            Jp[i, 1, b + 2] = -s * upz
            Jp[i, 0, b] = -ca * ux
            Jp[i, 1, b] = -ca * uz
            Jp[i, 0, b + 1] = -cb2 * ux
            Jp[i, 1, b + 1] = -cb2 * uz
            cv[i, 0] = hcx - 2.0 * sd * gd * upx + s * gd * gd * ux
            cv[i, 1] = hcz - 2.0 * sd * gd * upz + s * gd * gd * uz
            if k < 2:
                Ja[i, 2] = 1.0
                Ja[i, b + 2] = 1.0


@njit(**_JIT)
def mass_matrix_and_bias(P, q, qd, pos, Jp, Ja, cv, mass, inertia, M, h):
    """``M = J^T M_f J`` (eq. E.14) and ``h = J^T (f_g - M_f c)`` (eqs E.15, E.20-E.21)."""
    kinematics(P, q, qd, pos, Jp, Ja, cv)
    body_props(P, mass, inertia)
    g = P[P_G]
    for a in range(9):
        h[a] = 0.0
        for c in range(9):
            M[a, c] = 0.0
    for i in range(NB):
        m = mass[i]
        J = inertia[i]
        fx = -m * cv[i, 0]
        fz = -m * g - m * cv[i, 1]
        for a in range(9):
            pa0 = Jp[i, 0, a]
            pa1 = Jp[i, 1, a]
            aa = Ja[i, a]
            h[a] += pa0 * fx + pa1 * fz
            if pa0 == 0.0 and pa1 == 0.0 and aa == 0.0:
                continue
            for c in range(a, 9):
                M[a, c] += m * (pa0 * Jp[i, 0, c] + pa1 * Jp[i, 1, c]) + J * aa * Ja[i, c]
    for a in range(9):
        for c in range(a):
            M[a, c] = M[c, a]


@njit(**_JIT)
def chol_solve(M, b, x):
    """Solve ``M x = b`` for symmetric positive definite M (in-place Cholesky of M)."""
    n = M.shape[0]
    for j in range(n):
        s = M[j, j]
        for k in range(j):
            s -= M[j, k] * M[j, k]
        if s <= 0.0:
            return False
        d = math.sqrt(s)
        M[j, j] = d
        for i in range(j + 1, n):
            s = M[i, j]
            for k in range(j):
                s -= M[i, k] * M[j, k]
            M[i, j] = s / d
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= M[i, k] * x[k]
        x[i] = s / M[i, i]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, n):
            s -= M[k, i] * x[k]
        x[i] = s / M[i, i]
    return True


# ---------------------------------------------------------------------------
# Controller (eqs E.25-E.34) and contact (eqs E.23-E.24)
# ---------------------------------------------------------------------------


@njit(**_JIT)
def leg_phase(P, t, leg):
    """Phase of a leg in [0, 1) (eqs E.25-E.27); ``leg`` 0 right, 1 left."""
    T = P[P_T]
    rho = (t % T) / T
    rr = (rho + P[P_RHO0]) % 1.0
    if leg == 1:
        rr = (rr + 0.5) % 1.0
    return rr


@njit(**_JIT)
def references(P, rho):
    """``(l_ref, ld_ref, th_ref, thd_ref)`` at phase ``rho`` (eqs E.29-E.30, E.32-E.33).

    Eq. E.32 is used in the form ``theta_f + theta_s/2 (1 - cos(pi rho/d))``
    in stance, the continuous trajectory whose derivative is eq. E.33 (the
    printed ``+1`` makes the reference jump by ``theta_s`` at ``rho = 0, d``).
    """
    d = P[P_D]
    T = P[P_T]
    ths = P[P_THS]
    thf = P[P_THF]
    lt0 = P[P_LT0]
    lts = P[P_LTS]
    if rho <= d:
        a = math.pi * rho / d
        return (lt0, 0.0, thf + 0.5 * ths * (1.0 - math.cos(a)),
                math.pi / d * 0.5 * ths * math.sin(a) / T)
    u = (2.0 * rho - 1.0 - d) / (1.0 - d)
    a = math.pi * (rho - d) / (1.0 - d)
    return (lts * u * u + (lt0 - lts), 4.0 * lts / (1.0 - d) * u / T,
            thf + 0.5 * ths * (math.cos(a) + 1.0),
            -math.pi / (1.0 - d) * 0.5 * ths * math.sin(a) / T)


@njit(**_JIT)
def foot_state(P, y, leg):
    """Foot position and velocity ``(x, z, xd, zd)`` of a leg (eq. E.8)."""
    r1 = P[P_R1]
    tb = y[2]
    tbd = y[11]
    b = 3 + 3 * leg
    s = y[b] + y[b + 1]
    sd = y[9 + b] + y[9 + b + 1]
    gam = tb + y[b + 2]
    gd = tbd + y[9 + b + 2]
    sg = math.sin(gam)
    cg = math.cos(gam)
    x = y[0] + r1 * math.sin(tb) - s * sg
    z = y[1] + r1 * math.cos(tb) - s * cg
    xd = y[9] + r1 * math.cos(tb) * tbd - sd * sg - s * cg * gd
    zd = y[10] - r1 * math.sin(tb) * tbd - sd * cg + s * sg * gd
    return x, z, xd, zd


@njit(**_JIT)
def contact_force(P, y, cs, leg):
    """``(F_x, F_z, F_z_raw)``: eqs E.23-E.24, zero unless in contact and pushing."""
    if P[P_CONTACT] == 0.0 or cs[CS_ON_R + leg] == 0.0:
        return 0.0, 0.0, 0.0
    x, z, xd, zd = foot_state(P, y, leg)
    xt = cs[CS_XR + 2 * leg]
    zt = cs[CS_ZR + 2 * leg]
    fz = P[P_KZ] * (zt - z) - P[P_CZ] * zd
    if fz > 0.0 and z <= zt:
        return P[P_KX] * (xt - x) - P[P_CX] * xd, fz, fz
    return 0.0, 0.0, fz


@njit(**_JIT)
def actuation(P, t, y, leg):
    """``(F_t, F_s, tau)`` of a leg (eqs E.28, E.31, E.34)."""
    b = 3 + 3 * leg
    fs = P[P_K] * (P[P_LS0] - y[b + 1]) - P[P_CL] * y[9 + b + 1]
    if P[P_ACT] == 0.0:
        return 0.0, fs, 0.0
    lr, ldr, thr, thdr = references(P, leg_phase(P, t, leg))
    ft = P[P_KPT] * (lr - y[b]) + P[P_KDT] * (ldr - y[9 + b])
    tau = P[P_KPH] * (thr - y[b + 2]) + P[P_KDH] * (thdr - y[9 + b + 2])
    return ft, fs, tau


@njit(**_JIT)
def rhs(P, t, y, cs, out, ws, aux):
    """State derivative of ``y = (q, qd)`` (eq. E.22); forces go to ``aux`` (10)."""
    pos, Jp, Ja, cv, mass, inertia, M, h, qdd = ws
    q = y[:9]
    qd = y[9:]
    mass_matrix_and_bias(P, q, qd, pos, Jp, Ja, cv, mass, inertia, M, h)
    for leg in range(2):
        fx, fz, _ = contact_force(P, y, cs, leg)
        f = FOOT[leg]
        for a in range(9):  # J^T f_grf (eq. E.18)
            h[a] += Jp[f, 0, a] * fx + Jp[f, 1, a] * fz
        ft, fs, tau = actuation(P, t, y, leg)
        b = 3 + 3 * leg  # internal actuators do work on their own coordinates
        h[b] += ft
        h[b + 1] += fs
        h[b + 2] += tau
        aux[2 * leg] = fx
        aux[2 * leg + 1] = fz
        aux[4 + leg] = tau
        aux[6 + leg] = ft
        aux[8 + leg] = fs
    ok = chol_solve(M, h, qdd)
    for a in range(9):
        out[a] = y[9 + a]
        out[9 + a] = qdd[a] if ok else math.nan


def make_workspace():
    """Work arrays for :func:`rhs` (a tuple; allocated once per run)."""
    return (np.empty((NB, 2)), np.empty((NB, 2, 9)), np.empty((NB, 9)), np.empty((NB, 2)),
            np.empty(NB), np.empty(NB), np.empty((9, 9)), np.empty(9), np.empty(9))


_make_ws = njit(**_JIT)(make_workspace)


@njit(**_JIT)
def energy(P, y):
    """Kinetic + gravitational + shank-spring energy (no ground springs)."""
    ws = _make_ws()
    pos, Jp, Ja, cv, mass, inertia, M, h, _ = ws
    mass_matrix_and_bias(P, y[:9], y[9:], pos, Jp, Ja, cv, mass, inertia, M, h)
    e = 0.0
    for a in range(9):
        for c in range(9):
            e += 0.5 * y[9 + a] * M[a, c] * y[9 + c]
    for i in range(NB):
        e += mass[i] * P[P_G] * pos[i, 1]
    for leg in range(2):
        dl = P[P_LS0] - y[3 + 3 * leg + 1]
        e += 0.5 * P[P_K] * dl * dl
    return e


# ---------------------------------------------------------------------------
# Runge-Kutta steps (tslip.simulation._rk) with events
# ---------------------------------------------------------------------------


@njit(**_JIT)
def _stage_time(method, s, t, h, t_end_eval):
    """Time of stage ``s``: ``t + c_s h``, or ``t_end_eval`` for ``c_s = 1``."""
    c = _rk.stage_c(method, s)
    return t_end_eval if c == 1.0 else t + c * h


@njit(**_JIT)
def rk_step(P, method, t, y, h, K, ytmp, ynew, cs, ws, aux, t_end_eval):
    """One step from ``(t, y)`` with ``K[0] = f(t, y)``; ``K[ns] = f(ynew)``.

    ``t_end_eval`` is the time at which the stages with ``c = 1`` (and the
    FSAL row) are evaluated: the left limit when the step ends on a controller
    phase boundary.
    """
    ns = _rk.n_stages(method)
    for s in range(1, ns):
        _rk.stage_state(method, N, y, h, K, s, ytmp)
        rhs(P, _stage_time(method, s, t, h, t_end_eval), ytmp, cs, K[s], ws, aux)
    _rk.stage_state(method, N, y, h, K, ns, ynew)
    rhs(P, t_end_eval, ynew, cs, K[ns], ws, aux)


@njit(**_JIT)
def dense_output(P, method, t, y, ynew, h, K, R, ytmp, cs, ws, aux, t_end_eval):
    """Continuous extension of the step just taken; returns the extra rhs calls."""
    ns = _rk.n_stages(method)
    ne = _rk.n_extra(method)
    for s in range(ns + 1, ns + 1 + ne):
        _rk.stage_state(method, N, y, h, K, s, ytmp)
        rhs(P, _stage_time(method, s, t, h, t_end_eval), ytmp, cs, K[s], ws, aux)
    _rk.dense_coeffs(method, y, ynew, h, K, R)
    return ne


@njit(**_JIT)
def event_value(P, y, cs, leg):
    """Switching function of a leg: touch-down ``z_f - z_g`` in flight, lift-off
    ``min(F_z, k_z (z_TD - z_f))`` in contact; an event is a crossing from > 0
    to <= 0."""
    x, z, xd, zd = foot_state(P, y, leg)
    if cs[CS_ON_R + leg] == 0.0:
        return z
    zt = cs[CS_ZR + 2 * leg]
    fz = P[P_KZ] * (zt - z) - P[P_CZ] * zd
    return min(fz, P[P_KZ] * (zt - z))


@njit(**_JIT)
def next_boundary(P, t):
    """Next time after ``t`` at which a leg phase crosses 0 or d (eqs E.26-E.27)."""
    T = P[P_T]
    d = P[P_D]
    s = t / T + P[P_RHO0]
    best = math.inf
    for c in (0.0, d, 0.5, (d + 0.5) % 1.0):
        cand = c + math.floor(s - c) + 1.0
        if cand - s < 1e-12:
            cand += 1.0
        if cand < best:
            best = cand
    return (best - P[P_RHO0]) * T


@njit(**_JIT)
def _record(P, rec, row, t, y, cs, aux):
    rec[row, 0] = t
    for i in range(N):
        rec[row, R_Y + i] = y[i]
    rec[row, R_CON] = cs[CS_ON_R]
    rec[row, R_CON + 1] = cs[CS_ON_L]
    for leg in range(2):
        fx, fz, _ = contact_force(P, y, cs, leg)
        ft, fs, tau = actuation(P, t, y, leg)
        rec[row, R_F + 2 * leg] = fx
        rec[row, R_F + 2 * leg + 1] = fz
        rec[row, R_TAU + leg] = tau
        rec[row, R_FT + leg] = ft
        rec[row, R_FS + leg] = fs


@njit(**_JIT)
def fall_check(P, y):
    """Fall status of a state, or ``ST_OK`` (hip, backward, pitch, leg collapse)."""
    if y[1] + P[P_R1] * math.cos(y[2]) <= 0.0:
        return ST_FALL_HIP
    if y[9] < 0.0:
        return ST_FALL_BACKWARD
    if abs(y[2]) >= 0.5 * math.pi:
        return ST_FALL_PITCH
    if y[3] <= 0.0 or y[4] <= 0.0 or y[6] <= 0.0 or y[7] <= 0.0:
        return ST_FALL_LEG
    return ST_OK


@njit(**_JIT)
def init_contact(P, y, cs):
    """Contact flags at the start: a foot at or below ground that is pushing.

    The anchor is at the ground, or at the foot if it is above (by at most
    1e-9 L, e.g. a section state placed at the ground up to rounding): an
    anchor below the foot would zero the force at the first instant (the
    ground pushes only a foot at or below its anchor).
    """
    for leg in range(2):
        x, z, xd, zd = foot_state(P, y, leg)
        cs[CS_ON_R + leg] = 0.0
        cs[CS_XR + 2 * leg] = x
        cs[CS_ZR + 2 * leg] = max(z, 0.0)
        if P[P_CONTACT] != 0.0 and z <= 1e-9 and -P[P_KZ] * z - P[P_CZ] * zd > 0.0:
            cs[CS_ON_R + leg] = 1.0


@njit(**_JIT)
def run(P, O, t0, y0, cs0, n_strides, rec, ev, strides, yend, csend, stats):
    """Integrate from ``(t0, y0, cs0)`` until ``n_strides`` right touch-downs.

    Stops earlier at ``O_TEND``, a fall (if ``O_FALLS``), no right touch-down
    within ``O_TSTRIDE``, or an integrator failure. Records every accepted
    step in ``rec`` (until full), events in ``ev`` and the state just after
    each right touch-down in ``strides``. Returns the status.
    """
    rtol = O[O_RTOL]
    atol = O[O_ATOL]
    hmax = O[O_HMAX]
    hmin = O[O_HMIN]
    maxsteps = int(O[O_MAXSTEPS])
    t_end = O[O_TEND]
    method = int(O[O_METHOD])
    ns = _rk.n_stages(method)
    ws = _make_ws()
    aux = np.empty(10)
    K = np.empty((_rk.NK, N))
    R = np.empty((_rk.NR, N))
    st = np.empty(5)
    y = y0.copy()
    ytmp = np.empty(N)
    ynew = np.empty(N)
    yev = np.empty(N)
    cs = cs0.copy()
    t = t0
    nrec = 0
    nev = 0
    nstr = 0
    nacc = 0
    nrej = 0
    nfev = 0
    t_last_td = t0
    status = ST_OK
    nrec_cap = rec.shape[0]
    if nrec_cap > 0:
        _record(P, rec, 0, t, y, cs, aux)
        nrec = 1
    rhs(P, t, y, cs, K[0], ws, aux)
    nfev += 1
    h = O[O_H0]
    if h <= 0.0:
        h = min(1e-3, hmax)
    g_old = np.empty(2)
    for leg in range(2):
        g_old[leg] = event_value(P, y, cs, leg)
    tb = next_boundary(P, t)
    done = n_strides <= 0
    while not done:
        if nacc + nrej >= maxsteps:
            status = ST_ERR_MAX_STEPS
            break
        clip = False
        hstep = min(h, hmax)
        if t + hstep >= tb:
            hstep = tb - t
            clip = True
        if t + hstep >= t_end:
            hstep = t_end - t
            clip = False
        t_eval = t + hstep
        if clip:
            t_eval = tb - 1e-12 * P[P_T]
        rk_step(P, method, t, y, hstep, K, ytmp, ynew, cs, ws, aux, t_eval)
        nfev += ns
        err = _rk.error_norm(method, N, y, ynew, hstep, K, rtol, atol)
        if not math.isfinite(err):
            err = 1e10
        if err > 1.0:
            nrej += 1
            h = hstep * _rk.step_factor(method, err, 5.0)
            if h < hmin:
                status = ST_ERR_UNDERFLOW if math.isfinite(ynew[0]) else ST_ERR_NONFINITE
                break
            continue
        # accepted: look for contact events inside the step (Illinois on the
        # dense output, to 1e-13 in time)
        theta_ev = 2.0
        leg_ev = -1
        have_dense = False
        for leg in range(2):
            if P[P_CONTACT] == 0.0:
                break
            g_new = event_value(P, ynew, cs, leg)
            if g_old[leg] > 0.0 and g_new <= 0.0:
                if not have_dense:
                    nfev += dense_output(P, method, t, y, ynew, hstep, K, R, yev, cs, ws, aux,
                                         t_eval)
                    have_dense = True
                _rk.root_start(st, g_old[leg], g_new)
                for _ in range(100):
                    c = _rk.root_guess(st)
                    _rk.dense_eval(method, R, c, yev)
                    if _rk.root_update(st, c, event_value(P, yev, cs, leg), 1e-13 / hstep):
                        break
                if st[1] < theta_ev:
                    theta_ev = st[1]
                    leg_ev = leg
        nacc += 1
        if leg_ev >= 0:
            _rk.dense_eval(method, R, theta_ev, ynew)
            t = t + theta_ev * hstep
            for i in range(N):
                y[i] = ynew[i]
            x, z, _, _ = foot_state(P, y, leg_ev)
            if cs[CS_ON_R + leg_ev] == 0.0:
                cs[CS_ON_R + leg_ev] = 1.0
                cs[CS_XR + 2 * leg_ev] = x
                cs[CS_ZR + 2 * leg_ev] = 0.0
                kind = EV_TD_R + leg_ev
            else:
                cs[CS_ON_R + leg_ev] = 0.0
                kind = EV_LO_R + leg_ev
            if nev < ev.shape[0]:
                ev[nev, 0] = t
                ev[nev, 1] = kind
                ev[nev, 2] = x
                ev[nev, 3] = z
                nev += 1
            if kind == EV_TD_R:
                t_last_td = t
                if nstr < strides.shape[0]:
                    strides[nstr, 0] = t
                    for i in range(N):
                        strides[nstr, 1 + i] = y[i]
                    for i in range(NCS):
                        strides[nstr, 1 + N + i] = cs[i]
                nstr += 1
                if nstr >= n_strides:
                    done = True
            rhs(P, t, y, cs, K[0], ws, aux)
            nfev += 1
        else:
            if clip:
                t = tb
            else:
                t = t + hstep
            for i in range(N):
                y[i] = ynew[i]
            if clip:  # right limit after a phase boundary
                rhs(P, t + 1e-12 * P[P_T], y, cs, K[0], ws, aux)
                nfev += 1
            else:
                for i in range(N):
                    K[0, i] = K[ns, i]
        if clip or leg_ev >= 0 or t >= tb:
            tb = next_boundary(P, t)
        for leg in range(2):
            g_old[leg] = event_value(P, y, cs, leg)
        if nrec < nrec_cap:
            _record(P, rec, nrec, t, y, cs, aux)
            nrec += 1
        elif nrec_cap > 0:
            stats[S_RECFULL] = 1.0
        if not math.isfinite(y[0]):
            status = ST_ERR_NONFINITE
            break
        if O[O_FALLS] != 0.0:
            fs = fall_check(P, y)
            if fs != ST_OK:
                status = fs
                break
            if t - t_last_td > O[O_TSTRIDE]:
                status = ST_FALL_NO_TD
                break
        if t >= t_end:
            status = ST_TEND
            break
        # step-size control (Hairer)
        h = hstep * _rk.step_factor(method, err, 5.0)
        if clip or leg_ev >= 0:
            h = max(h, 1e-3 * min(hmax, 1.0))
    if status >= 10 and status < 20 and nev < ev.shape[0]:
        ev[nev, 0] = t
        ev[nev, 1] = EV_FALL
        ev[nev, 2] = status
        ev[nev, 3] = 0.0
        nev += 1
    for i in range(N):
        yend[i] = y[i]
    for i in range(NCS):
        csend[i] = cs[i]
    stats[S_NREC] = nrec
    stats[S_NEV] = nev
    stats[S_NSTRIDE] = nstr
    stats[S_NACC] = nacc
    stats[S_NREJ] = nrej
    stats[S_TEND] = t
    stats[S_NFEV] = nfev
    return status


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(run, __file__)

