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
# small helpers of the right-hand side, inlined into it (numba IR inlining)
_INLINE = dict(_JIT, inline="always")
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


#: layout of the compact mass matrix ``blk`` of :func:`tmt_blocks`: the trunk
#: block (xx, xz, x theta_b, zz, z theta_b, theta_b theta_b), then per leg the
#: columns of l_t, l_s, theta_h in the trunk rows (3 each) and the leg block
#: entries (l_t l_t, l_t l_s, l_s l_s, theta_h theta_h)
NBLK = 6 + 2 * 13


@njit(**_INLINE)
def tmt_blocks(P, q, qd, blk, h, trig):
    """Mass matrix (eq. E.14) as compact blocks, and ``h = J^T (f_g - M_f c)``
    (eqs E.15, E.20-E.21).

    Closed form of the TMT products of :func:`kinematics`: the three bodies of
    a leg lie on its axis ``u = (sin gamma, cos gamma)`` at distances
    ``s_k = a_k l_t + b_k l_s`` below the hip (eqs E.6-E.8), so with
    ``u' = du/dgamma``, ``e = d b_z / d theta_b`` (eq. E.2) and
    ``theta_h = gamma - theta_b`` each entry is a sum over the leg's masses:
    ``S1 = sum m_k s_k``, ``S2 = sum m_k s_k^2`` and constants
    ``sum m_k a_k``, ``sum m_k a_k b_k``, ... The legs do not couple to each
    other, and within a leg ``theta_h`` does not couple to ``l_t, l_s``
    (``u . u' = 0``): the zeros :func:`block_solve` relies on. ``trig`` gets
    ``sin, cos`` of ``theta_b`` and of both leg angles (for the contact forces).
    """
    mt = P[P_MT]
    ms = P[P_MS]
    mf = P[P_MF]
    r1 = P[P_R1]
    r2 = P[P_R2]
    g = P[P_G]
    m3 = mt + ms + mf
    a1 = mt * r2 + ms + mf  # sum m_k a_k
    b1 = ms * r2 + mf  # sum m_k b_k
    jl = P[P_JT] + P[P_JS]
    tb = q[2]
    tbd = qd[2]
    sb = math.sin(tb)
    cb = math.cos(tb)
    trig[0] = sb
    trig[1] = cb
    mtot = P[P_MB] + 2.0 * m3
    blk[0] = mtot
    blk[1] = 0.0
    blk[2] = 0.0
    blk[3] = mtot
    blk[4] = 0.0
    blk[5] = P[P_JB]
    h[0] = 0.0
    h[1] = -P[P_MB] * g
    h[2] = 0.0
    f0x = r1 * tbd * tbd * sb  # gravity minus the hip's convective acceleration
    f0z = -g + r1 * tbd * tbd * cb
    for j in range(2):
        b = 3 + 3 * j
        o = 6 + 13 * j
        lt = q[b]
        ls = q[b + 1]
        ltd = qd[b]
        lsd = qd[b + 1]
        gam = tb + q[b + 2]
        gd = tbd + qd[b + 2]
        ux = math.sin(gam)
        uz = math.cos(gam)
        trig[2 + 2 * j] = ux
        trig[3 + 2 * j] = uz
        upx = uz
        upz = -ux
        sth = ux * cb - uz * sb  # sin, cos theta_h
        cth = uz * cb + ux * sb
        st_ = r2 * lt  # thigh, shank, foot distances from the hip (eqs E.6-E.8)
        ss_ = lt + r2 * ls
        sf_ = lt + ls
        s1 = a1 * lt + b1 * ls
        s2 = mt * st_ * st_ + ms * ss_ * ss_ + mf * sf_ * sf_
        sd1 = a1 * ltd + b1 * lsd
        ssd = mt * st_ * r2 * ltd + ms * ss_ * (ltd + r2 * lsd) + mf * sf_ * (ltd + lsd)
        as_ = mt * r2 * st_ + ms * ss_ + mf * sf_
        bs_ = ms * r2 * ss_ + mf * sf_
        blk[2] += m3 * r1 * cb - s1 * upx
        blk[4] += -m3 * r1 * sb - s1 * upz
        blk[5] += m3 * r1 * r1 + s2 - 2.0 * r1 * s1 * cth + jl
        blk[o] = -a1 * ux
        blk[o + 1] = -a1 * uz
        blk[o + 2] = -a1 * r1 * sth
        blk[o + 3] = -b1 * ux
        blk[o + 4] = -b1 * uz
        blk[o + 5] = -b1 * r1 * sth
        blk[o + 6] = -s1 * upx
        blk[o + 7] = -s1 * upz
        blk[o + 8] = s2 - r1 * s1 * cth + jl
        blk[o + 9] = mt * r2 * r2 + ms + mf
        blk[o + 10] = ms * r2 + mf
        blk[o + 11] = ms * r2 * r2 + mf
        blk[o + 12] = s2 + jl
        # sum of m_k (g - c_k) over the leg, and its moments about the hip
        fx = m3 * f0x + 2.0 * gd * sd1 * upx - gd * gd * s1 * ux
        fz = m3 * f0z + 2.0 * gd * sd1 * upz - gd * gd * s1 * uz
        w = s1 * (upx * f0x + upz * f0z) + 2.0 * gd * ssd  # sum s_k u'.F_k
        uf0 = ux * f0x + uz * f0z
        h[0] += fx
        h[1] += fz
        h[2] += r1 * (cb * fx - sb * fz) - w
        h[b] = -(a1 * uf0 - gd * gd * as_)
        h[b + 1] = -(b1 * uf0 - gd * gd * bs_)
        h[b + 2] = -w


@njit(**_JIT)
def mass_matrix_and_bias(P, q, qd, M, h):
    """``M = J^T M_f J`` (eq. E.14, 9 x 9) and ``h`` from :func:`tmt_blocks`."""
    blk = np.empty(NBLK)
    tmt_blocks(P, q, qd, blk, h, np.empty(6))
    for a in range(9):
        for c in range(9):
            M[a, c] = 0.0
    M[0, 0], M[0, 1], M[0, 2] = blk[0], blk[1], blk[2]
    M[1, 1], M[1, 2], M[2, 2] = blk[3], blk[4], blk[5]
    for j in range(2):
        b = 3 + 3 * j
        o = 6 + 13 * j
        for col in range(3):
            for row in range(3):
                M[row, b + col] = blk[o + 3 * col + row]
        M[b, b], M[b, b + 1], M[b + 1, b + 1] = blk[o + 9], blk[o + 10], blk[o + 11]
        M[b + 2, b + 2] = blk[o + 12]
    for a in range(9):
        for c in range(a):
            M[a, c] = M[c, a]


@njit(**_INLINE)
def block_solve(blk, r, x, S, N):
    """Solve ``M x = r`` with M in the compact form of :func:`tmt_blocks`.

    Block elimination of the legs: with a leg's trunk columns ``m1, m2, w``
    (of ``l_t, l_s, theta_h``), its 2x2 block ``D2`` and ``d = M[theta_h,
    theta_h]``, the trunk's Schur complement is ``S = A - sum (m1 n1^T +
    m2 n2^T + w w^T / d)`` with ``(n1, n2) = D2^-1 (m1, m2)``; then
    ``x_leg = D^-1 (r_leg - B^T x_trunk)``. ``S`` (3, 3) and ``N`` (2, 3, 3) are
    work arrays. About 200 flops, against some 600
    for a Cholesky factorisation of the 9 x 9 matrix. Returns False unless
    every pivot is positive (M positive definite).
    """
    for k in range(3):
        x[k] = r[k]
    S[0, 0], S[0, 1], S[0, 2] = blk[0], blk[1], blk[2]
    S[1, 1], S[1, 2], S[2, 2] = blk[3], blk[4], blk[5]
    for j in range(2):
        b = 3 + 3 * j
        o = 6 + 13 * j
        aa, ab, bb, dd = blk[o + 9], blk[o + 10], blk[o + 11], blk[o + 12]
        det = aa * bb - ab * ab
        if not (aa > 0.0 and det > 0.0 and dd > 0.0):
            return False
        idet = 1.0 / det
        idd = 1.0 / dd
        p = bb * idet  # D2^-1 = [[p, pq], [pq, pr]]
        pq = -ab * idet
        pr = aa * idet
        z1 = p * r[b] + pq * r[b + 1]
        z2 = pq * r[b] + pr * r[b + 1]
        z3 = r[b + 2] * idd
        x[b], x[b + 1], x[b + 2] = z1, z2, z3
        for k in range(3):  # N[j] = (n1, n2, w / d): D^-1 B^T
            N[j, 0, k] = p * blk[o + k] + pq * blk[o + 3 + k]
            N[j, 1, k] = pq * blk[o + k] + pr * blk[o + 3 + k]
            N[j, 2, k] = blk[o + 6 + k] * idd
        for k in range(3):
            m1k = blk[o + k]
            m2k = blk[o + 3 + k]
            wk = blk[o + 6 + k]
            x[k] -= m1k * z1 + m2k * z2 + wk * z3
            for c in range(k, 3):
                S[k, c] -= m1k * N[j, 0, c] + m2k * N[j, 1, c] + wk * N[j, 2, c]
    # S x_trunk = x[0:3]: 3x3 symmetric, by cofactors; positive definite by
    # its leading minors (Sylvester)
    a, b_, c = S[0, 0], S[0, 1], S[0, 2]
    d, e, f = S[1, 1], S[1, 2], S[2, 2]
    c00 = d * f - e * e
    c01 = c * e - b_ * f
    c02 = b_ * e - c * d
    det = a * c00 + b_ * c01 + c * c02
    if not (a > 0.0 and a * d - b_ * b_ > 0.0 and det > 0.0):
        return False
    idet = 1.0 / det
    r0, r1, r2 = x[0], x[1], x[2]
    x[0] = (c00 * r0 + c01 * r1 + c02 * r2) * idet
    x[1] = (c01 * r0 + (a * f - c * c) * r1 + (b_ * c - a * e) * r2) * idet
    x[2] = (c02 * r0 + (b_ * c - a * e) * r1 + (a * d - b_ * b_) * r2) * idet
    for j in range(2):
        b = 3 + 3 * j
        for a in range(3):
            x[b + a] -= N[j, a, 0] * x[0] + N[j, a, 1] * x[1] + N[j, a, 2] * x[2]
    return True


# ---------------------------------------------------------------------------
# Controller (eqs E.25-E.34) and contact (eqs E.23-E.24)
# ---------------------------------------------------------------------------
#
# The right-hand side is smooth between discontinuities, which are events:
# each leg's controller switches branch at phase d (stance -> swing, eq. E.29
# and E.30: the thigh velocity reference jumps) and at phase 1 = 0 (swing ->
# stance); a foot touches down or lifts off (eqs E.23-E.24). A run carries the
# discrete state of both: the contact state ``cs`` (flags and anchors) and the
# controller state ``ctl = (branch_R, n_R, branch_L, n_L)``, the branch (0
# stance, 1 swing) and the cycle of each leg, so that the phase is
# ``rho = t/T + rho0 (+ 1/2 for the left leg) - n`` (eqs E.25-E.27) without a
# modulo. Within one discrete state the right-hand side is the smooth
# continuation of the current branch and contact law, so a step may run past
# a switch; the event is then located on the dense output and the integration
# restarted there in the new state.


@njit(**_JIT)
def leg_phase(P, t, leg):
    """Phase of a leg in [0, 1) (eqs E.25-E.27); ``leg`` 0 right, 1 left."""
    T = P[P_T]
    rho = (t % T) / T
    rr = (rho + P[P_RHO0]) % 1.0
    if leg == 1:
        rr = (rr + 0.5) % 1.0
    return rr


@njit(**_INLINE)
def references_branch(P, rho, swing):
    """``(l_ref, ld_ref, th_ref, thd_ref)`` of one branch at phase ``rho``
    (eqs E.29-E.30, E.32-E.33), continued smoothly beyond its interval.

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
    if not swing:
        w = math.pi / d
        a = w * rho
        return (lt0, 0.0, thf + 0.5 * ths * (1.0 - math.cos(a)), w * 0.5 * ths * math.sin(a) / T)
    e = 1.0 / (1.0 - d)
    u = (2.0 * rho - 1.0 - d) * e
    a = math.pi * (rho - d) * e
    return (lts * u * u + (lt0 - lts), 4.0 * lts * e * u / T,
            thf + 0.5 * ths * (math.cos(a) + 1.0), -math.pi * e * 0.5 * ths * math.sin(a) / T)


@njit(**_JIT)
def references(P, rho):
    """References at phase ``rho`` in [0, 1): stance branch for ``rho <= d``."""
    return references_branch(P, rho, rho > P[P_D])


#: a phase within this of a branch end counts as past it (the right limit)
PHASE_EPS = 1e-12


@njit(**_JIT)
def init_ctl(P, t, ctl):
    """Controller state at time ``t``: the branch that holds just after ``t``."""
    d = P[P_D]
    for leg in range(2):
        s = t / P[P_T] + P[P_RHO0] + 0.5 * leg
        n = float(math.floor(s))
        r = s - n
        if r >= 1.0 - PHASE_EPS:
            n += 1.0
            r = 0.0
        ctl[2 * leg] = 1.0 if r >= d - PHASE_EPS else 0.0
        ctl[2 * leg + 1] = n


@njit(**_INLINE)
def ctl_phase(P, t, ctl, leg):
    """Phase of a leg within its current cycle (may pass the branch end slightly)."""
    return t / P[P_T] + P[P_RHO0] + 0.5 * leg - ctl[2 * leg + 1]


@njit(**_JIT)
def ctl_switch_time(P, ctl, leg):
    """Time at which the leg's current branch ends (phase d or 1)."""
    end = 1.0 if ctl[2 * leg] != 0.0 else P[P_D]
    return (ctl[2 * leg + 1] + end - P[P_RHO0] - 0.5 * leg) * P[P_T]


@njit(**_JIT)
def ctl_switch(ctl, leg):
    """Next branch of a leg: stance -> swing, swing -> stance of the next cycle."""
    if ctl[2 * leg] != 0.0:
        ctl[2 * leg] = 0.0
        ctl[2 * leg + 1] += 1.0
    else:
        ctl[2 * leg] = 1.0


@njit(**_INLINE)
def foot_state_trig(P, y, leg, sb, cb, sg, cg):
    """:func:`foot_state` given ``sin, cos`` of ``theta_b`` and of the leg angle."""
    r1 = P[P_R1]
    tbd = y[11]
    b = 3 + 3 * leg
    s = y[b] + y[b + 1]
    sd = y[9 + b] + y[9 + b + 1]
    gd = tbd + y[9 + b + 2]
    x = y[0] + r1 * sb - s * sg
    z = y[1] + r1 * cb - s * cg
    xd = y[9] + r1 * cb * tbd - sd * sg - s * cg * gd
    zd = y[10] - r1 * sb * tbd - sd * cg + s * sg * gd
    return x, z, xd, zd


@njit(**_JIT)
def foot_state(P, y, leg):
    """Foot position and velocity ``(x, z, xd, zd)`` of a leg (eq. E.8)."""
    gam = y[2] + y[3 + 3 * leg + 2]
    return foot_state_trig(P, y, leg, math.sin(y[2]), math.cos(y[2]), math.sin(gam),
                           math.cos(gam))


@njit(**_JIT)
def contact_force(P, y, cs, leg, clamp):
    """``(F_x, F_z, F_z_raw)`` of a foot in contact (eqs E.23-E.24).

    With ``clamp`` the force is zero unless the foot pushes (eq. E.23); without,
    the spring-damper law holds throughout the contact, the smooth continuation
    the integrator steps with until the lift-off event ends the contact.
    """
    if P[P_CONTACT] == 0.0 or cs[CS_ON_R + leg] == 0.0:
        return 0.0, 0.0, 0.0
    return contact_law(P, foot_state(P, y, leg), cs, leg, clamp)


@njit(**_INLINE)
def contact_law(P, foot, cs, leg, clamp):
    """Eqs E.23-E.24 for the foot state ``foot = (x, z, xd, zd)`` (see :func:`contact_force`)."""
    x, z, xd, zd = foot
    xt = cs[CS_XR + 2 * leg]
    zt = cs[CS_ZR + 2 * leg]
    fz = P[P_KZ] * (zt - z) - P[P_CZ] * zd
    if not clamp or (fz > 0.0 and z <= zt):
        return P[P_KX] * (xt - x) - P[P_CX] * xd, fz, fz
    return 0.0, 0.0, fz


@njit(**_INLINE)
def actuation(P, t, y, ctl, leg):
    """``(F_t, F_s, tau)`` of a leg (eqs E.28, E.31, E.34) in controller state ``ctl``."""
    b = 3 + 3 * leg
    fs = P[P_K] * (P[P_LS0] - y[b + 1]) - P[P_CL] * y[9 + b + 1]
    if P[P_ACT] == 0.0:
        return 0.0, fs, 0.0
    lr, ldr, thr, thdr = references_branch(P, ctl_phase(P, t, ctl, leg), ctl[2 * leg] != 0.0)
    ft = P[P_KPT] * (lr - y[b]) + P[P_KDT] * (ldr - y[9 + b])
    tau = P[P_KPH] * (thr - y[b + 2]) + P[P_KDH] * (thdr - y[9 + b + 2])
    return ft, fs, tau


@njit(**_JIT)
def rhs(P, t, y, cs, ctl, clamp, out, ws, aux):
    """State derivative of ``y = (q, qd)`` (eq. E.22); forces go to ``aux`` (10).

    ``clamp``: see :func:`contact_force` (the integrator steps unclamped).
    """
    blk, h, qdd, S, Nw, trig = ws
    tmt_blocks(P, y[:9], y[9:], blk, h, trig)
    r1 = P[P_R1]
    sb = trig[0]
    cb = trig[1]
    for leg in range(2):
        b = 3 + 3 * leg
        fx = 0.0
        fz = 0.0
        if P[P_CONTACT] != 0.0 and cs[CS_ON_R + leg] != 0.0:
            ux = trig[2 + 2 * leg]
            uz = trig[3 + 2 * leg]
            foot = foot_state_trig(P, y, leg, sb, cb, ux, uz)
            fx, fz, _ = contact_law(P, foot, cs, leg, clamp)
            # J_foot^T f_grf (eq. E.18), the foot at s = l_t + l_s on the leg axis
            s = y[b] + y[b + 1]
            upf = uz * fx - ux * fz
            uf = ux * fx + uz * fz
            h[0] += fx
            h[1] += fz
            h[2] += r1 * (cb * fx - sb * fz) - s * upf
            h[b] -= uf
            h[b + 1] -= uf
            h[b + 2] -= s * upf
        ft, fs, tau = actuation(P, t, y, ctl, leg)
        h[b] += ft  # internal actuators do work on their own coordinates
        h[b + 1] += fs
        h[b + 2] += tau
        aux[2 * leg] = fx
        aux[2 * leg + 1] = fz
        aux[4 + leg] = tau
        aux[6 + leg] = ft
        aux[8 + leg] = fs
    ok = block_solve(blk, h, qdd, S, Nw)
    for a in range(9):
        out[a] = y[9 + a]
        out[9 + a] = qdd[a] if ok else math.nan


def make_workspace():
    """Work arrays for :func:`rhs` (a tuple; allocated once per run)."""
    return (np.empty(NBLK), np.empty(9), np.empty(9), np.empty((3, 3)), np.empty((2, 3, 3)),
            np.empty(6))


_make_ws = njit(**_JIT)(make_workspace)


def make_kin_workspace():
    """Work arrays for :func:`kinematics`: pos, Jp, Ja, cv, mass, inertia."""
    return (np.empty((NB, 2)), np.empty((NB, 2, 9)), np.empty((NB, 9)), np.empty((NB, 2)),
            np.empty(NB), np.empty(NB))


_make_kin_ws = njit(**_JIT)(make_kin_workspace)


@njit(**_JIT)
def energy(P, y):
    """Kinetic + gravitational + shank-spring energy (no ground springs)."""
    M = np.empty((9, 9))
    h = np.empty(9)
    mass_matrix_and_bias(P, y[:9], y[9:], M, h)
    pos, Jp, Ja, cv, mass, inertia = _make_kin_ws()
    kinematics(P, y[:9], y[9:], pos, Jp, Ja, cv)
    body_props(P, mass, inertia)
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
def rk_step(P, method, t, y, h, K, ytmp, ynew, cs, ctl, ws, aux):
    """One step from ``(t, y)`` with ``K[0] = f(t, y)``; ``K[ns] = f(ynew)``."""
    ns = _rk.n_stages(method)
    for s in range(1, ns):
        _rk.stage_state(method, N, y, h, K, s, ytmp)
        rhs(P, t + _rk.stage_c(method, s) * h, ytmp, cs, ctl, False, K[s], ws, aux)
    _rk.stage_state(method, N, y, h, K, ns, ynew)
    rhs(P, t + h, ynew, cs, ctl, False, K[ns], ws, aux)


@njit(**_JIT)
def dense_output(P, method, t, y, ynew, h, K, R, ytmp, cs, ctl, ws, aux):
    """Continuous extension of the step just taken; returns the extra rhs calls."""
    ns = _rk.n_stages(method)
    ne = _rk.n_extra(method)
    for s in range(ns + 1, ns + 1 + ne):
        _rk.stage_state(method, N, y, h, K, s, ytmp)
        rhs(P, t + _rk.stage_c(method, s) * h, ytmp, cs, ctl, False, K[s], ws, aux)
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
def fall_value(P, y):
    """``(g, status)``: the smallest of the fall margins of :func:`fall_check` (hip
    height, forward speed, pitch to +-pi/2, thigh and shank lengths) and the
    fall it measures; a fall is its crossing to <= 0."""
    g = y[1] + P[P_R1] * math.cos(y[2])
    kind = ST_FALL_HIP
    if y[9] < g:
        g = y[9]
        kind = ST_FALL_BACKWARD
    v = 0.5 * math.pi - abs(y[2])
    if v < g:
        g = v
        kind = ST_FALL_PITCH
    for i in (3, 4, 6, 7):
        if y[i] < g:
            g = y[i]
            kind = ST_FALL_LEG
    return g, kind


# events of a run: contact of each leg, controller switch of each leg, fall
NEVK = 5
K_CTL = 2
K_FALL = 4


@njit(**_JIT)
def event_g(P, k, t, y, cs, tsw):
    """Switching function ``k`` at ``(t, y)``: contact (0, 1), controller (2, 3), fall (4)."""
    if k < K_CTL:
        return event_value(P, y, cs, k)
    if k < K_FALL:
        return tsw[k - K_CTL] - t
    return fall_value(P, y)[0]


@njit(**_JIT)
def _record(P, rec, row, t, y, cs, ctl):
    rec[row, 0] = t
    for i in range(N):
        rec[row, R_Y + i] = y[i]
    rec[row, R_CON] = cs[CS_ON_R]
    rec[row, R_CON + 1] = cs[CS_ON_L]
    for leg in range(2):
        fx, fz, _ = contact_force(P, y, cs, leg, True)
        ft, fs, tau = actuation(P, t, y, ctl, leg)
        rec[row, R_F + 2 * leg] = fx
        rec[row, R_F + 2 * leg + 1] = fz
        rec[row, R_TAU + leg] = tau
        rec[row, R_FT + leg] = ft
        rec[row, R_FS + leg] = fs


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

    Every discontinuity of the right-hand side is an event (see the section
    comment above): after each accepted step the switching functions of
    :func:`event_g` are checked for a crossing, the earliest crossing is
    located on the dense output (Illinois, :mod:`tslip.simulation._rk`, to
    1e-13 in time), the state there is taken, every event that occurs there
    is applied and the integration restarts. A fall is an event too: the run
    stops where the first fall margin of :func:`fall_value` reaches zero.

    Stops earlier at ``O_TEND``, a fall (if ``O_FALLS``), no right touch-down
    within ``O_TSTRIDE``, or an integrator failure. Records every accepted
    step and event in ``rec`` (until full), contact events in ``ev`` and the
    state just after each right touch-down in ``strides``. Returns the status.
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
    ctl = np.empty(4)
    init_ctl(P, t0, ctl)
    tsw = np.empty(2)
    for leg in range(2):
        tsw[leg] = ctl_switch_time(P, ctl, leg)
    active = np.zeros(NEVK, dtype=np.bool_)
    for leg in range(2):
        active[leg] = P[P_CONTACT] != 0.0
        active[K_CTL + leg] = P[P_ACT] != 0.0
    active[K_FALL] = O[O_FALLS] != 0.0
    g_old = np.empty(NEVK)
    g_new = np.empty(NEVK)
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
        _record(P, rec, 0, t, y, cs, ctl)
        nrec = 1
    rhs(P, t, y, cs, ctl, False, K[0], ws, aux)
    nfev += 1
    h = O[O_H0]
    if h <= 0.0:
        h = min(1e-3, hmax)
    for k in range(NEVK):
        g_old[k] = event_g(P, k, t, y, cs, tsw)
    done = n_strides <= 0
    while not done:
        if nacc + nrej >= maxsteps:
            status = ST_ERR_MAX_STEPS
            break
        hstep = min(h, hmax)
        at_end = t + hstep >= t_end
        if at_end:
            hstep = t_end - t
        rk_step(P, method, t, y, hstep, K, ytmp, ynew, cs, ctl, ws, aux)
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
        nacc += 1
        # accepted: the earliest crossing of a switching function in the step
        theta_ev = 2.0
        k_ev = -1
        have_dense = False
        for k in range(NEVK):
            if not active[k]:
                continue
            g_new[k] = event_g(P, k, t + hstep, ynew, cs, tsw)
            if g_old[k] > 0.0 and g_new[k] <= 0.0:
                if not have_dense:
                    nfev += dense_output(P, method, t, y, ynew, hstep, K, R, yev, cs, ctl, ws,
                                         aux)
                    have_dense = True
                _rk.root_start(st, g_old[k], g_new[k])
                for _ in range(100):
                    c = _rk.root_guess(st)
                    _rk.dense_eval(method, R, c, yev)
                    gc = event_g(P, k, t + c * hstep, yev, cs, tsw)
                    if _rk.root_update(st, c, gc, 1e-13 / hstep):
                        break
                if st[1] < theta_ev:
                    theta_ev = st[1]
                    k_ev = k
        if k_ev >= 0:
            _rk.dense_eval(method, R, theta_ev, ynew)
            t_ev = t + theta_ev * hstep
            if K_CTL <= k_ev < K_FALL:
                t_ev = tsw[k_ev - K_CTL]  # a controller switch is at a known time
            t = t_ev
            for i in range(N):
                y[i] = ynew[i]
            # apply every event that has occurred at this point
            for k in range(NEVK):
                if not active[k] or not g_old[k] > 0.0:
                    continue
                if k != k_ev and event_g(P, k, t, y, cs, tsw) > 0.0:
                    continue
                if k == K_FALL:
                    status = fall_value(P, y)[1]
                elif k >= K_CTL:
                    ctl_switch(ctl, k - K_CTL)
                    tsw[k - K_CTL] = ctl_switch_time(P, ctl, k - K_CTL)
                else:
                    x, z, _, _ = foot_state(P, y, k)
                    if cs[CS_ON_R + k] == 0.0:
                        cs[CS_ON_R + k] = 1.0
                        cs[CS_XR + 2 * k] = x
                        cs[CS_ZR + 2 * k] = 0.0
                        kind = EV_TD_R + k
                    else:
                        cs[CS_ON_R + k] = 0.0
                        kind = EV_LO_R + k
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
            rhs(P, t, y, cs, ctl, False, K[0], ws, aux)
            nfev += 1
            for k in range(NEVK):
                g_old[k] = event_g(P, k, t, y, cs, tsw)
        else:
            t = t_end if at_end else t + hstep
            for i in range(N):
                y[i] = ynew[i]
                K[0, i] = K[ns, i]
            for k in range(NEVK):
                g_old[k] = g_new[k]
        if nrec < nrec_cap:
            _record(P, rec, nrec, t, y, cs, ctl)
            nrec += 1
        elif nrec_cap > 0:
            stats[S_RECFULL] = 1.0
        if status != ST_OK:  # fell at a located fall event
            break
        if not math.isfinite(y[0]):
            status = ST_ERR_NONFINITE
            break
        if O[O_FALLS] != 0.0:
            fs = fall_check(P, y)  # a margin that started at zero has no crossing
            if fs != ST_OK:
                status = fs
                break
            if t - t_last_td > O[O_TSTRIDE]:
                status = ST_FALL_NO_TD
                break
        if t >= t_end and not done:
            status = ST_TEND
            break
        # step-size control (Hairer)
        h = hstep * _rk.step_factor(method, err, 5.0)
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
