"""Compiled TMT dynamics of the biped: kinematics, mass matrix, bias forces (eqs E.1-E.22).

Private (see :mod:`._kernels`). Arguments are float64 arrays and floats.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._kernel_cache import check as _check_cache
from ._jit import FAST, INLINE, JIT, NB
from ._pack import P_G, P_JB, P_JS, P_JT, P_K, P_LS0, P_MB, P_MF, P_MS, P_MT, P_R1, P_R2

# ---------------------------------------------------------------------------
# Kinematics and TMT terms (eqs E.1-E.22)
# ---------------------------------------------------------------------------


@njit(**FAST)
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


@njit(**FAST)
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


@njit(**INLINE)
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


@njit(**JIT)
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


@njit(**INLINE)
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




def make_kin_workspace():
    """Work arrays for :func:`kinematics`: pos, Jp, Ja, cv, mass, inertia."""
    return (np.empty((NB, 2)), np.empty((NB, 2, 9)), np.empty((NB, 9)), np.empty((NB, 2)),
            np.empty(NB), np.empty(NB))


_make_kin_ws = njit(**JIT)(make_kin_workspace)


@njit(**JIT)
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

# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(block_solve, __file__)
