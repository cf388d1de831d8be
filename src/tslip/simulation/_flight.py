"""Compiled flight in closed form: the swing leg, the flight state, the next touch-down.

Private (see :mod:`._kernels`). Flight is ballistic (eq. 2.7) with the leg reset
of eq. 2.17 (signs in docs/conventions.md) and the optional retraction stop
(Section 7.5, ``Params.alpha_stop``); only the touch-down time needs a
search (:func:`find_touchdown`, which compiles on its own, as does
:func:`alpha_r_column`, the touch-down's derivative in ``alpha_r`` for the gait
search; the other functions are ``inline="always"``, copied into the kernels
that call them).
"""

from __future__ import annotations

import math

from numba import njit

from .._kernel_cache import check as _check_cache
from ..model._pack import (
    O_TMAX_FLIGHT,
    OUT_LO,
    OUT_TD,
    OUT_TF,
    P_ALPHA,
    P_APEX,
    P_G,
    P_GLOBAL,
    P_L0,
    P_OMEGA,
    P_R,
    P_STOP,
    ST_ERR_FLIGHT_TIMEOUT,
    ST_FALL_NO_TOUCHDOWN,
    ST_FALL_TRIP,
    ST_OK,
)
from ._rk import _INLINE, _JIT


@njit(**_INLINE)
def retraction_start(P, yd0):
    """Time after lift-off at which the retraction clock starts, for lift-off ``ydot = yd0``.

    0 with ``retraction="liftoff"`` (eq. 2.17). With ``retraction="apex"`` the
    apex ``yd0 / g`` of a flight that leaves the ground moving up, and 0 (the
    clock starts at lift-off) for one that has no apex (``yd0 <= 0``).
    """
    if P[P_APEX] != 0.0 and yd0 > 0.0:
        return yd0 / P[P_G]
    return 0.0


@njit(**_INLINE)
def stop_time(P, ta):
    """Time after lift-off at which the leg reaches its stop, ``inf`` if it never does.

    ``ta`` is the retraction clock's start (:func:`retraction_start`). The leg
    stops at ``max(alpha_r, alpha_stop)`` (``min`` for ``omega_r < 0``), so at
    ``ta`` itself when ``alpha_r`` is already beyond the stop; no stop
    (``alpha_stop`` packed as 0.0, i.e. ``None``) or ``omega_r = 0``: ``inf``.
    """
    stop = P[P_STOP]
    w = P[P_OMEGA]
    if stop == 0.0 or w == 0.0:
        return math.inf
    return ta + max((stop - P[P_ALPHA]) / w, 0.0)


@njit(**_INLINE)
def stop_binds(P, yd0, tf):
    """Whether a flight of ``tf`` after a lift-off at ``ydot = yd0`` touches down stopped:
    at or after :func:`stop_time` (never without a stop or with ``omega_r = 0``)."""
    return tf >= stop_time(P, retraction_start(P, yd0))


@njit(**_INLINE)
def stop_angle(P):
    """Angle held once stopped: ``max(alpha_r, alpha_stop)`` (``min`` if ``omega_r < 0``)."""
    return P[P_STOP] if (P[P_STOP] - P[P_ALPHA]) * P[P_OMEGA] > 0.0 else P[P_ALPHA]


@njit(**_INLINE)
def flight_leg_angle(P, phi0, phid, t, ta):
    """Leg angle ``beta(t)`` in flight, ``t`` since lift-off, and its rate.

    The hip angle is ``alpha_r + omega_r max(0, t - ta)`` with ``ta`` from
    :func:`retraction_start` (held at ``alpha_r`` until then), held at the stop
    from :func:`stop_time` on (``min(alpha_r + omega_r max(0, t - ta),
    max(alpha_r, alpha_stop))`` for ``omega_r > 0``, docs/conventions.md);
    ``beta = alpha - phi(t)`` for the local reset, ``beta = alpha`` for the
    global one. The rate is the one from ``t`` on (retracting at ``t = ta``,
    stopped at the stop time).
    """
    if t >= ta:
        s = t - ta
        w = P[P_OMEGA]
    else:
        s = 0.0
        w = 0.0
    a = P[P_ALPHA] + P[P_OMEGA] * s
    if P[P_STOP] != 0.0 and t >= stop_time(P, ta):  # a stop (0.0: none), reached
        a = stop_angle(P)
        w = 0.0
    if P[P_GLOBAL] != 0.0:
        return a, w
    return a - (phi0 + phid * t), w - phid


@njit(**_INLINE)
def flight_state(P, lo, t, out):
    """Flight state ``t`` after lift-off from ``lo = (x, y, xd, yd, phi, phid)``.

    Writes ``(x, y, xd, yd, phi, phid, beta, foot_x, foot_y, hip_y)`` to ``out``.
    """
    ph = lo[4] + lo[5] * t
    b, _ = flight_leg_angle(P, lo[4], lo[5], t, retraction_start(P, lo[3]))
    x, y, yd, _, hip_y, foot_x, foot_y = flight_point(P, lo, t, math.sin(ph), math.cos(ph),
                                                       math.sin(b), math.cos(b))
    out[0] = x
    out[1] = y
    out[2] = lo[2]
    out[3] = yd
    out[4] = ph
    out[5] = lo[5]
    out[6] = b
    out[7] = foot_x
    out[8] = foot_y
    out[9] = hip_y


@njit(**_INLINE)
def flight_point(P, lo, t, sp, cp, sb, cb):
    """``(x, y, yd, hip_x, hip_y, foot_x, foot_y)`` ``t`` after lift-off from ``lo`` (eq.
    2.7), given the sine and cosine of ``phi(t)`` (``sp, cp``) and of ``beta(t)`` (``sb,
    cb``): the formula's one copy, for :func:`flight_state` (libm's sines) and the
    recorded run's table (:func:`._record.fill_table`, vectorised ones)."""
    g = P[P_G]
    r = P[P_R]
    l0 = P[P_L0]
    x = lo[0] + lo[2] * t
    y = lo[1] + lo[3] * t - 0.5 * g * t * t
    hip_x = x - r * sp
    hip_y = y + r * cp
    return x, y, lo[3] - g * t, hip_x, hip_y, hip_x + l0 * cb, hip_y - l0 * sb


@njit(**_INLINE)
def _flight_heights(P, lo, t, ta):
    """Foot and hip height, their rates and the foot x-position at ``t`` (clock from ``ta``)."""
    g = P[P_G]
    r = P[P_R]
    l0 = P[P_L0]
    ph = lo[4] + lo[5] * t
    b, bd = flight_leg_angle(P, lo[4], lo[5], t, ta)
    y = lo[1] + lo[3] * t - 0.5 * g * t * t
    yd = lo[3] - g * t
    hip_y = y + r * math.cos(ph)
    hip_yd = yd - r * math.sin(ph) * lo[5]
    foot_y = hip_y - l0 * math.sin(b)
    foot_yd = hip_yd - l0 * math.cos(b) * bd
    foot_x = lo[0] + lo[2] * t - r * math.sin(ph) + l0 * math.cos(b)
    return foot_y, foot_yd, hip_y, hip_yd, foot_x


@njit(**_INLINE)
def _segment(tx, x):
    """Index of the terrain segment holding ``x`` (breakpoints ``tx`` sorted)."""
    k = 0
    while k < tx.shape[0] and x >= tx[k]:
        k += 1
    return k


@njit(**_INLINE)
def _safe_dt(f, fd, K):
    """Time ``f`` (> 0) surely stays positive given ``|f''| <= K`` and rate ``fd``."""
    return (fd + math.sqrt(fd * fd + 2.0 * K * f)) / K


@njit(**_INLINE)
def _foot_bounds(P, lo, bd):
    """``(Kf, vx)`` for a leg turning at ``bd``: the bound on the foot height's second
    derivative and on the foot's horizontal speed in flight (``phid = lo[5]``)."""
    g = P[P_G]
    r = abs(P[P_R])
    l0 = P[P_L0]
    phid = lo[5]
    Kf = g + r * phid * phid + l0 * bd * bd + 1e-300
    vx = abs(lo[2]) + r * abs(phid) + l0 * abs(bd) + 1e-300
    return Kf, vx


@njit(**_INLINE)
def _leg_rate_bound(P, phid, ta):
    """The swing leg's rate ``beta'`` in flight, or a bound on its size that holds on both
    sides of the apex when the retraction clock starts there (``ta > 0``): before it the
    held leg turns with the trunk (local reset) or not at all (global)."""
    bd = P[P_OMEGA] if P[P_GLOBAL] != 0.0 else P[P_OMEGA] - phid
    if ta > 0.0:
        bd = max(abs(bd), abs(0.0 if P[P_GLOBAL] != 0.0 else phid))
    return bd


@njit(**_INLINE)
def _breakpoint_dt(tx, k, foot_x, vx, dt):
    """``dt`` cut so that a foot moving at most ``vx`` sideways does not cross a terrain
    breakpoint of segment ``k`` unnoticed (at least 1e-12)."""
    if tx.shape[0] > 0:
        dist = math.inf
        if k > 0:
            dist = foot_x - tx[k - 1]
        if k < tx.shape[0]:
            dist = min(dist, tx[k] - foot_x)
        dt = min(dt, max(dist / vx, 1e-12))
    return dt


@njit(**_INLINE)
def _clock_dt(t, ta, ts, dt):
    """``dt`` cut at the apex ``ta`` (the foot's rate jumps there) or, after it, at the
    retraction stop ``ts`` (Section 7.5): no step crosses either."""
    if t < ta:
        dt = min(dt, ta - t)
    elif ts < math.inf:
        dt = min(dt, ts - t)
    return dt


@njit(**_JIT)
def find_touchdown(P, O, lo, tx, th, res):
    """First touch-down after lift-off, by certified safe steps.

    With ``|f''| <= K`` bounding the foot (and hip) height's second
    derivative, a step of ``_safe_dt`` cannot skip a zero, so the first
    downward crossing is never missed; near the root the step is Newton-like.
    The foot must first be above the ground (a reset foot that starts below
    it has to rise, docs/conventions.md). Terrain: heights ``th[k]`` between
    breakpoints ``tx`` (``len(th) == len(tx) + 1``). With the apex clock the
    leg rate jumps at the apex, so ``K`` bounds both rates and no step
    crosses the apex. The retraction stop (``alpha_stop``) splits the search
    at :func:`stop_time` too: no step crosses it, and ``K`` is the held leg's
    from there on (a flight that touches down before it takes the steps it
    takes without a stop).

    ``res`` receives ``(t_td, ground_h, clearance_at_reset)``.
    """
    r = abs(P[P_R])
    phid = lo[5]
    ta = retraction_start(P, lo[3])
    ts = stop_time(P, ta)
    Kf, vx = _foot_bounds(P, lo, _leg_rate_bound(P, phid, ta))
    Kh = P[P_G] + r * phid * phid + 1e-300
    t_max = O[O_TMAX_FLIGHT]
    tol = 1e-13
    t = 0.0
    foot_y, foot_yd, hip_y, hip_yd, foot_x = _flight_heights(P, lo, t, ta)
    k = _segment(tx, foot_x)
    res[1] = th[k]
    res[2] = foot_y - th[k]
    armed = foot_y - th[k] > 0.0
    for _ in range(100000):
        if t >= ts:  # stopped from here on: the leg turns with the trunk (local) or not at all
            ts = math.inf
            Kf, vx = _foot_bounds(P, lo, 0.0 if P[P_GLOBAL] != 0.0 else phid)
        if t > t_max:
            res[0] = t
            return ST_ERR_FLIGHT_TIMEOUT
        H = th[k]
        hh = hip_y - H
        if hh <= tol:  # the safe steps approach the hip's contact without crossing it
            res[0] = t
            res[1] = H
            return ST_FALL_NO_TOUCHDOWN
        f = foot_y - H
        if armed:
            # a downward crossing: just after arming the foot is at the ground but rising
            if f <= tol and foot_yd <= 0.0:
                res[0] = t
                res[1] = H
                return ST_OK
            dt = _safe_dt(f, foot_yd, Kf)
        else:
            if f > 0.0:
                armed = True
                continue
            # wait for the foot to rise above the ground: -f must reach 0
            dt = _safe_dt(max(-f, 1e-300), -foot_yd, Kf)
            dt = max(dt, 1e-12)
        dt = min(dt, _safe_dt(hh, hip_yd, Kh))
        t += _clock_dt(t, ta, ts, _breakpoint_dt(tx, k, foot_x, vx, dt))
        foot_y, foot_yd, hip_y, hip_yd, foot_x = _flight_heights(P, lo, t, ta)
        knew = _segment(tx, foot_x)
        if knew != k:
            k = knew
            if armed and foot_y - th[k] <= 0.0:
                res[0] = t
                res[1] = th[k]
                return ST_FALL_TRIP
    res[0] = t
    return ST_ERR_FLIGHT_TIMEOUT


@njit(**_JIT)
def flight_samples(P, lo, ts, out):
    """:func:`flight_state` at each time in ``ts``; ``out`` has shape (n, 10)."""
    for i in range(ts.shape[0]):
        flight_state(P, lo, ts[i], out[i])


@njit(**_JIT)
def alpha_r_column(P, out, col):
    """``dq'/d alpha_r`` of a completed stride into ``col`` (5), from its output ``out``.

    The derivation is :func:`tslip.simulation._packed.alpha_r_column`'s, which
    calls this. It is compiled because in Python its four small kernel calls
    and a dozen scalar reads of ``P`` cost about 3 us, once per Newton Jacobian
    of every gait search. A touch-down held at the retraction stop does not depend
    on ``alpha_r`` (0), unless the reset is beyond the stop and is held at ``alpha_r``.
    """
    g, r, l0 = P[P_G], P[P_R], P[P_L0]
    tf = out[OUT_TF]
    phi0, yd0, phid0 = out[OUT_LO + 4], out[OUT_LO + 3], out[OUT_LO + 5]
    if stop_binds(P, yd0, tf) and stop_angle(P) != P[P_ALPHA]:
        for i in range(5):
            col[i] = 0.0
        return
    b = out[OUT_TD]  # beta(t_TD)
    _, bdot = flight_leg_angle(P, phi0, phid0, tf, retraction_start(P, yd0))
    ph = phi0 + phid0 * tf
    dfdt = yd0 - g * tf - r * math.sin(ph) * phid0 - l0 * math.cos(b) * bdot
    dt = l0 * math.cos(b) / dfdt
    col[0] = 1.0 + bdot * dt
    col[1] = phid0 * dt
    col[2] = 0.0
    col[3] = -g * dt
    col[4] = 0.0


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(find_touchdown, __file__)
