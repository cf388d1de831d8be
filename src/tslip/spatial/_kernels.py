"""The 3-D spring-mass runner's stance: one compiled Runge-Kutta loop on the project's core.

Private. The stance of :mod:`tslip.spatial` (Seipel & Holmes 2005, eq. 1 there;
issue 43) in coordinates relative to the fixed foot ``p`` on flat ground at
height 0: ``q = c - p``, ``v = c'``,

    q' = v,   v' = (k/m) (l0/|q| - 1) q - g e_y,

so the mass's height above the ground is ``q_y``. Two events, each a function
that is > 0 during the stance and fires on its crossing to <= 0 (the planar
kernels' rule, docs/conventions.md):

* lift-off, ``l0 - |q|``: the leg back at rest length while extending. It
  starts at its zero, so a first step that jumps the whole stance is caught by
  the core's hump check (:func:`tslip.simulation._rk.left_zero_upward`,
  :func:`~tslip.simulation._rk.jumped_hump`) and retried shorter;
* fall, ``q_y``: the mass reaches the ground (searched first; lift-off wins
  only if strictly earlier).

With ``n = 42`` the state also carries the 6 x 6 variational matrix ``Phi``
(row-major, ``y[6 + 6 i + j] = Phi[i, j]``), ``Phi' = A Phi`` with ``A`` the
Jacobian of the field above: the exact derivative of the flow for the Floquet
multipliers (:mod:`tslip.spatial.gait`). The Runge-Kutta pair is a run-time
argument (``O[O_METHOD]``, :mod:`tslip.model._pack`'s codes): one compiled
loop serves both pairs and both state sizes.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._kernel_cache import check as _check_cache
from ..model._pack import O_ATOL, O_H0, O_HMIN, O_MAXSTEPS, O_METHOD, O_RTOL, O_TMAX_STANCE
from ..simulation import _rk
from ..simulation._rk import _JIT

#: Parameter vector layout
P_M, P_K, P_L0, P_G = range(4)
NP = 4
#: State sizes: the motion alone, and with the variational matrix
NSTATE = 6
NVAR = 42

#: Status codes (the Python side names them in :class:`tslip.spatial.stride.SpatialStatus`)
ST_OK = 0
ST_FALL = 1  # the mass reaches the ground in stance
ST_APEX_LOW = 2  # the apex is at or below the touch-down height l0 sin(beta0)
ST_NO_STANCE = 3  # at touch-down the mass moves away from the foot
ST_NO_APEX = 4  # the lift-off moves down: the flight after it has no apex
ST_ERR_STEP_UNDERFLOW = 10
ST_ERR_MAX_STEPS = 11
ST_ERR_STANCE_TIMEOUT = 12
ST_ERR_NONFINITE = 14

#: Output vector layout: status, stance time, accepted and rejected steps, the end state
OUT_STATUS, OUT_T, OUT_NSTEP, OUT_NREJ = range(4)
OUT_Y = 4
NOUT = OUT_Y + NVAR

EV_LIFTOFF, EV_FALL = 0, 1


@njit(**_JIT)
def rhs(P, n, y, f):
    """The stance field (module docstring) of the first ``n`` components (6 or 42)."""
    qx, qy, qz = y[0], y[1], y[2]
    r = math.sqrt(qx * qx + qy * qy + qz * qz)
    km = P[P_K] / P[P_M]
    a = km * (P[P_L0] / r - 1.0)
    f[0] = y[3]
    f[1] = y[4]
    f[2] = y[5]
    f[3] = a * qx
    f[4] = a * qy - P[P_G]
    f[5] = a * qz
    if n > NSTATE:
        # d(v')/dq = a I - (k/m) l0 q q^T / |q|^3
        b = km * P[P_L0] / (r * r * r)
        qv = (qx, qy, qz)
        for j in range(6):
            p0 = y[6 + j]
            p1 = y[12 + j]
            p2 = y[18 + j]
            f[6 + j] = y[24 + j]
            f[12 + j] = y[30 + j]
            f[18 + j] = y[36 + j]
            dot = qx * p0 + qy * p1 + qz * p2
            f[24 + j] = a * p0 - b * qv[0] * dot
            f[30 + j] = a * p1 - b * qv[1] * dot
            f[36 + j] = a * p2 - b * qv[2] * dot


@njit(**_JIT)
def events(P, y, gv):
    """Event functions (> 0 in stance): ``gv[0] = l0 - |q|`` (lift-off), ``gv[1] = q_y`` (fall)."""
    gv[EV_LIFTOFF] = P[P_L0] - math.sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2])
    gv[EV_FALL] = y[1]


@njit(**_JIT)
def _root(P, method, R, ev, g_lo, g_hi, ytmp, gv, st):
    """Root in theta of event ``ev`` on the dense output (the core's Illinois helpers)."""
    _rk.root_start(st, g_lo, g_hi)
    for _ in range(200):
        c = _rk.root_guess(st)
        _rk.dense_eval(method, R, c, ytmp)
        events(P, ytmp, gv)
        if _rk.root_update(st, c, gv[ev], 1e-15):
            break
    return st[1]  # the earliest theta known to be at or past the crossing


@njit(**_JIT)
def stance(P, O, y0, out):  # noqa: E741
    """Integrate one stance from ``y0`` (6 or 42 components) to its first event.

    Fills ``out`` (:data:`NOUT`): status, time since touch-down, accepted and
    rejected steps, and the state at the event (its first ``len(y0)`` slots).
    Returns the status. The method, tolerances and limits come from ``O``
    (:meth:`tslip.IntegratorOptions.packed`).
    """
    n = y0.shape[0]
    method = int(O[O_METHOD])
    rtol, atol = O[O_RTOL], O[O_ATOL]
    ns = _rk.n_stages(method)
    K = np.zeros((_rk.NK, n))
    R = np.zeros((_rk.NR, n))
    y = y0.copy()
    ytmp = np.empty(n)
    ynew = np.empty(n)
    gv_old = np.empty(2)
    gv_new = np.empty(2)
    gv_tmp = np.empty(2)
    st = np.empty(5)
    for i in range(out.shape[0]):
        out[i] = np.nan
    out[OUT_NSTEP] = 0.0
    out[OUT_NREJ] = 0.0
    rhs(P, n, y, K[0])
    h = O[O_H0]
    if h <= 0.0:
        h0, d1 = _rk.initial_probe(y, K[0], rtol, atol, ytmp)
        rhs(P, n, ytmp, K[1])
        h = _rk.initial_step(method, y, K[0], K[1], h0, d1, rtol, atol)
    events(P, y, gv_old)
    # the lift-off function starts at its zero: does it leave it upward (compression)?
    d = _rk.ZERO_PROBE * h
    for i in range(n):
        ytmp[i] = y[i] + d * K[0, i]
    events(P, ytmp, gv_tmp)
    g_start, g_probe = gv_old[EV_LIFTOFF], gv_tmp[EV_LIFTOFF]
    first = True
    last_rejected = False
    t = 0.0
    nstep = 0
    nrej = 0
    status = ST_OK
    while True:
        if nstep + nrej >= O[O_MAXSTEPS]:
            status = ST_ERR_MAX_STEPS
            break
        if t > O[O_TMAX_STANCE]:
            status = ST_ERR_STANCE_TIMEOUT
            break
        if h < O[O_HMIN]:
            status = ST_ERR_STEP_UNDERFLOW
            break
        for s in range(1, ns):
            _rk.stage_state(method, n, y, h, K, s, ytmp)
            rhs(P, n, ytmp, K[s])
        _rk.stage_state(method, n, y, h, K, ns, ynew)
        rhs(P, n, ynew, K[ns])
        err = _rk.error_norm(method, n, y, ynew, h, K, rtol, atol)
        if not err <= 1.0:
            nrej += 1
            last_rejected = True
            h *= 0.1 if not math.isfinite(err) else _rk.step_factor(method, err, 10.0)
            continue
        events(P, ynew, gv_new)
        if first and _rk.jumped_hump(g_start, gv_new[EV_LIFTOFF], g_probe):
            nrej += 1
            h *= _rk.HUMP_SHRINK
            continue
        first = False
        nstep += 1
        fired = False
        for ev in range(2):
            fired = fired or (gv_old[ev] > 0.0 and gv_new[ev] <= 0.0)
        if fired:
            for s in range(ns + 1, ns + 1 + _rk.n_extra(method)):
                _rk.stage_state(method, n, y, h, K, s, ytmp)
                rhs(P, n, ytmp, K[s])
            _rk.dense_coeffs(method, y, ynew, h, K, R)
            theta_ev = 2.0
            which = -1
            for ev in (EV_FALL, EV_LIFTOFF):
                if gv_old[ev] > 0.0 and gv_new[ev] <= 0.0:
                    th = _root(P, method, R, ev, gv_old[ev], gv_new[ev], ytmp, gv_tmp, st)
                    if th < theta_ev - 1e-9:
                        theta_ev = th
                        which = ev
            _rk.dense_eval(method, R, theta_ev, ytmp)
            for i in range(n):
                out[OUT_Y + i] = ytmp[i]
            out[OUT_T] = t + theta_ev * h
            status = ST_OK if which == EV_LIFTOFF else ST_FALL
            break
        if not _rk.all_finite(n, ynew):
            status = ST_ERR_NONFINITE
            break
        t += h
        _rk.accept_step(method, n, y, ynew, K)
        gv_old[0] = gv_new[0]
        gv_old[1] = gv_new[1]
        fac = _rk.step_factor(method, err, 10.0)
        if last_rejected:
            fac = min(1.0, fac)
        last_rejected = False
        h *= fac
    out[OUT_STATUS] = status
    out[OUT_NSTEP] = nstep
    out[OUT_NREJ] = nrej
    return status


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(stance, __file__)
