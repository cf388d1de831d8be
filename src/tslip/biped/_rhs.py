"""Compiled right-hand side of the biped: TMT dynamics, contact and actuation (eq. E.22).

Private (see :mod:`._kernels`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._kernel_cache import check as _check_cache
from ._contact import contact_law, foot_state_trig
from ._control import NRC, actuation
from ._jit import FAST, JIT
from ._pack import CS_ON_R, P_CONTACT, P_R1
from ._tmt import NBLK, block_solve, tmt_blocks


@njit(**FAST)
def rhs(P, t, y, cs, ctl, clamp, out, ws, aux):
    """State derivative of ``y = (q, qd)`` (eq. E.22); forces go to ``aux`` (10).

    ``clamp``: see :func:`._contact.contact_force` (the integrator steps
    unclamped). ``ws`` is a workspace of :func:`make_workspace`; it also keeps
    the sines and cosines of ``y`` (``ws[5]``, see :func:`._tmt.tmt_blocks`)
    and caches the controller references (``ws[6]``, see
    :func:`._control.references_at`), so one workspace serves one parameter
    vector ``P``.
    """
    blk, h, qdd, S, Nw, trig, rc = ws
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
        ft, fs, tau = actuation(P, t, y, ctl, leg, rc)
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
            np.empty(6), np.full((2, NRC), np.nan))


_make_ws = njit(**JIT)(make_workspace)


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(rhs, __file__)
