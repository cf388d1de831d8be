"""Compiled controller of the biped: phases, references, actuation (eqs E.25-E.34).

Private (see :mod:`._kernels`).

The right-hand side is smooth between discontinuities, which are events:
each leg's controller switches branch at phase d (stance -> swing, eq. E.29
and E.30: the thigh velocity reference jumps) and at phase 1 = 0 (swing ->
stance); a foot touches down or lifts off (eqs E.23-E.24). A run carries the
discrete state of both: the contact state ``cs`` (flags and anchors) and the
controller state ``ctl = (branch_R, n_R, branch_L, n_L)``, the branch (0
stance, 1 swing) and the cycle of each leg, so that the phase is
``rho = t/T + rho0 (+ 1/2 for the left leg) - n`` (eqs E.25-E.27) without a
modulo. Within one discrete state the right-hand side is the smooth
continuation of the current branch and contact law, so a step may run past
a switch; the event is then located on the dense output and the integration
restarted there in the new state.
"""

from __future__ import annotations

import math

from numba import njit

from .._kernel_cache import check as _check_cache
from ._jit import FAST, INLINE
from ._pack import (
    P_ACT,
    P_CL,
    P_D,
    P_K,
    P_KDH,
    P_KDT,
    P_KPH,
    P_KPT,
    P_LS0,
    P_LT0,
    P_LTS,
    P_RHO0,
    P_T,
    P_THF,
    P_THS,
)


@njit(**FAST)
def leg_phase(P, t, leg):
    """Phase of a leg in [0, 1) (eqs E.25-E.27); ``leg`` 0 right, 1 left."""
    T = P[P_T]
    rho = (t % T) / T
    rr = (rho + P[P_RHO0]) % 1.0
    if leg == 1:
        rr = (rr + 0.5) % 1.0
    return rr


@njit(**INLINE)
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
    w = math.pi / d
    e = 1.0 / (1.0 - d)
    u = (2.0 * rho - 1.0 - d) * e
    a = math.pi * (rho - d) * e if swing else w * rho
    # one place for both branches: the compiler evaluates the pair as one sincos
    ca = math.cos(a)
    sa = math.sin(a)
    if not swing:
        return (lt0, 0.0, thf + 0.5 * ths * (1.0 - ca), w * 0.5 * ths * sa / T)
    return (lts * u * u + (lt0 - lts), 4.0 * lts * e * u / T,
            thf + 0.5 * ths * (ca + 1.0), -math.pi * e * 0.5 * ths * sa / T)


@njit(**FAST)
def references(P, rho):
    """References at phase ``rho`` in [0, 1): stance branch for ``rho <= d``."""
    return references_branch(P, rho, rho > P[P_D])


#: a phase within this of a branch end counts as past it (the right limit)
PHASE_EPS = 1e-12


@njit(**FAST)
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


@njit(**INLINE)
def ctl_phase(P, t, ctl, leg):
    """Phase of a leg within its current cycle (may pass the branch end slightly)."""
    return t / P[P_T] + P[P_RHO0] + 0.5 * leg - ctl[2 * leg + 1]


@njit(**FAST)
def ctl_switch_time(P, ctl, leg):
    """Time at which the leg's current branch ends (phase d or 1)."""
    end = 1.0 if ctl[2 * leg] != 0.0 else P[P_D]
    return (ctl[2 * leg + 1] + end - P[P_RHO0] - 0.5 * leg) * P[P_T]


@njit(**FAST)
def ctl_switch(ctl, leg):
    """Next branch of a leg: stance -> swing, swing -> stance of the next cycle."""
    if ctl[2 * leg] != 0.0:
        ctl[2 * leg] = 0.0
        ctl[2 * leg + 1] += 1.0
    else:
        ctl[2 * leg] = 1.0


#: columns of the reference cache ``rc`` (one row per leg) of :func:`references_at`:
#: time, branch, cycle, then ``(l_ref, ld_ref, th_ref, thd_ref)``
NRC = 7


@njit(**FAST)
def references_at(P, t, ctl, leg, rc):
    """References of a leg at time ``t`` in controller state ``ctl``, cached in ``rc``.

    :func:`references_branch` at the leg's phase (eq. E.25), unless row ``leg``
    of ``rc`` holds them for the same time, branch and cycle: the stages of a
    Runge-Kutta step that share a time (the last stage and the FSAL
    evaluation, ``c = 1``), and the recording after the step, compute them
    once. The same numbers either way; a cache serves one parameter vector
    (a row of NaN is empty).
    """
    br = ctl[2 * leg]
    n = ctl[2 * leg + 1]
    if rc[leg, 0] == t and rc[leg, 1] == br and rc[leg, 2] == n:
        return rc[leg, 3], rc[leg, 4], rc[leg, 5], rc[leg, 6]
    lr, ldr, thr, thdr = references_branch(P, ctl_phase(P, t, ctl, leg), br != 0.0)
    rc[leg, 0] = t
    rc[leg, 1] = br
    rc[leg, 2] = n
    rc[leg, 3] = lr
    rc[leg, 4] = ldr
    rc[leg, 5] = thr
    rc[leg, 6] = thdr
    return lr, ldr, thr, thdr


@njit(**INLINE)
def actuation(P, t, y, ctl, leg, rc):
    """``(F_t, F_s, tau)`` of a leg (eqs E.28, E.31, E.34) in controller state ``ctl``
    (references through the cache ``rc`` of :func:`references_at`)."""
    b = 3 + 3 * leg
    fs = P[P_K] * (P[P_LS0] - y[b + 1]) - P[P_CL] * y[9 + b + 1]
    if P[P_ACT] == 0.0:
        return 0.0, fs, 0.0
    lr, ldr, thr, thdr = references_at(P, t, ctl, leg, rc)
    ft = P[P_KPT] * (lr - y[b]) + P[P_KDT] * (ldr - y[9 + b])
    tau = P[P_KPH] * (thr - y[b + 2]) + P[P_KDH] * (thdr - y[9 + b + 2])
    return ft, fs, tau


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(ctl_switch, __file__)
