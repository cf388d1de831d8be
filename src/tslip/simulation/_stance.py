"""Compiled stance dynamics: equations of motion, ground force, events, touch-down state.

Private (see :mod:`._kernels`). The readable reference for the equations is
:mod:`tslip.model.dynamics`; the tests check that both agree.

Only :func:`rhs` and :func:`event_values` compile on their own: every stride
kernel calls them from several places. The other functions are ``inline="always"``
(numba copies them into the kernel that calls them, so a stride compiles as a few
functions, not dozens); each still runs on its own when called from Python.
"""

from __future__ import annotations

import math

from numba import njit

from .._kernel_cache import check as _check_cache
from ..model._pack import P_C0, P_CL, P_G, P_J, P_K, P_L0, P_M, P_NEXP, P_R, P_THRUST
from ._rk import _INLINE, _JIT

#: Stance state ``y = (l, beta, phi, ld, betad, phid)``.
NSTATE = 6


@njit(**_INLINE)
def hip_torque(P, phi, betad, phid):
    """Hip torque of the stance controller (eqs 2.12-2.16), linear in the state.

    ``tau = a0 + a1 phi + a2 betad + a3 phid`` with the coefficients from
    ``Controller.torque_coefficients``.
    """
    return P[P_C0] + P[P_C0 + 1] * phi + P[P_C0 + 2] * betad + P[P_C0 + 3] * phid


@njit(**_INLINE)
def rest_length(P):
    """The leg's current rest length ``l_rest``: ``l0``, or ``l0 (1 + d)`` once a
    stance's thrust has switched (its working copy then holds ``-d`` in ``P_THRUST``)."""
    d = P[P_THRUST]
    return P[P_L0] if d >= 0.0 else P[P_L0] * (1.0 - d)


@njit(**_INLINE)
def spring_force(P, l):
    """Compressive spring force ``F_s = k l0 sgn(x) |x|^n``, ``x = (l_rest - l) / l0``.

    ``n = 1`` is eq. 2.1's ``k (l_rest - l)``, computed as such (docs/model.md,
    "Leg spring and thrust").
    """
    n = P[P_NEXP]
    lr = rest_length(P)
    if n == 1.0:
        return P[P_K] * (lr - l)  # eq. 2.1
    x = (lr - l) / P[P_L0]
    f = P[P_K] * P[P_L0] * abs(x) ** n
    return f if x >= 0.0 else -f


@njit(**_INLINE)
def leg_force(P, l, ld):
    """Compressive leg force ``F_l = F_s - c_l ldot`` (eq. 2.1 at ``n = 1``)."""
    return spring_force(P, l) - P[P_CL] * ld


@njit(**_INLINE)
def spring_slope(P, l):
    """``dF_s/dl = -k n |x|^(n-1)`` (``-k`` at ``n = 1``); infinite at ``x = 0`` for ``n < 1``."""
    n = P[P_NEXP]
    if n == 1.0:
        return -P[P_K]
    x = (rest_length(P) - l) / P[P_L0]
    return -P[P_K] * n * abs(x) ** (n - 1.0)


@njit(**_INLINE)
def spring_energy(P, l):
    """Spring potential ``V = k l0^2 |x|^(n+1) / (n+1)`` (``k (l_rest - l)^2 / 2`` at ``n = 1``)."""
    n = P[P_NEXP]
    lr = rest_length(P)
    if n == 1.0:
        return 0.5 * P[P_K] * (lr - l) * (lr - l)
    l0 = P[P_L0]
    return P[P_K] * l0 * l0 * abs((lr - l) / l0) ** (n + 1.0) / (n + 1.0)


@njit(**_INLINE)
def liftoff_on_spring(P):
    """Whether lift-off is located as ``l_rest - l = 0`` rather than ``F_y = 0``: a
    non-linear spring (``n != 1``) with no leg damping and no hip torque, where
    ``F_y = F_s sin(beta)`` vanishes with the spring (with zero slope for ``n > 1``,
    infinite for ``n < 1``); the same instant, found more accurately."""
    return (P[P_NEXP] != 1.0 and P[P_CL] == 0.0 and P[P_C0] == 0.0 and P[P_C0 + 1] == 0.0
            and P[P_C0 + 2] == 0.0 and P[P_C0 + 3] == 0.0)


@njit(**_INLINE)
def stance_terms(P, y):
    """What the stance's right-hand side and events share at ``y``: ``(sin beta, cos beta,
    sin phi, cos phi, tau, F_l)``, the hip torque (eqs 2.12-2.16) and the leg force (eq. 2.1)."""
    b, ph = y[1], y[2]
    tau = hip_torque(P, ph, y[4], y[5])
    fl = leg_force(P, y[0], y[3])  # eq. 2.1
    return math.sin(b), math.cos(b), math.sin(ph), math.cos(ph), tau, fl


@njit(**_INLINE)
def accel_of(P, y, sb, cb, sp, cp, tau, fl):
    """Generalised accelerations ``(ldd, betadd, phidd)`` from :func:`stance_terms`.

    Solves ``M qdd = Q - C`` (eq. 2.3) for ``q = (l, beta, phi)``. The Schur
    complement of the mass matrix (eq. 2.4) on the phi row is exactly ``J``,
    so the 3x3 solve is closed form.
    """
    m = P[P_M]
    r = P[P_R]
    g = P[P_G]
    l, ld, bd, phd = y[0], y[3], y[4], y[5]
    sa = sb * cp + cb * sp  # sin(beta + phi)
    ca = cb * cp - sb * sp  # cos(beta + phi)
    # R = Q - C (eq. A.11, A.13)
    r1 = -m * g * sb + fl - (m * r * phd * phd * sa - m * l * bd * bd)
    r2 = tau - m * g * l * cb - (m * r * l * phd * phd * ca + 2.0 * m * l * bd * ld)
    r3 = tau - m * g * r * sp - (m * r * l * bd * bd * ca + 2.0 * m * r * bd * ld * sa)
    phdd = (r3 + r * ca * r1 - r * sa * r2 / l) / P[P_J]
    ldd = r1 / m + r * ca * phdd
    bdd = r2 / (m * l * l) - r * sa / l * phdd
    return ldd, bdd, phdd


@njit(**_INLINE)
def stance_accel(P, y):
    """Generalised accelerations and forces in stance (eq. 2.3, :func:`accel_of`).

    Returns ``(ldd, betadd, phidd, F_l, tau)``.
    """
    sb, cb, sp, cp, tau, fl = stance_terms(P, y)
    ldd, bdd, phdd = accel_of(P, y, sb, cb, sp, cp, tau, fl)
    return ldd, bdd, phdd, fl, tau


@njit(**_JIT)
def rhs(P, y, out):
    """Stance state derivative for ``y = (l, beta, phi, ld, betad, phid)``."""
    rhs_inline(P, y, out)


@njit(**_INLINE)
def rhs_inline(P, y, out):
    """:func:`rhs` inlined where it is called: the integrator's stage loop only.

    LLVM inlined the plain ``rhs`` there by itself until the power-law spring's branch (a
    ``pow`` call) made it larger; each stage then paid a numba call, 9 ns of a 40 ns right-
    hand side, and the Table 6.1 stride took 16 % longer. Inlined at numba's level in
    ``rk_step`` alone the stride is within 3-4 % of the linear-only kernel again, for about
    2 s more compile CPU (everywhere: 11 s; ``benchmarks/bench_limit.py``)."""
    sb, cb, sp, cp, tau, fl = stance_terms(P, y)
    put_rhs(P, y, sb, cb, sp, cp, tau, fl, out)


@njit(**_INLINE)
def put_rhs(P, y, sb, cb, sp, cp, tau, fl, out):
    """``out = f(y)`` from :func:`stance_terms`."""
    ldd, bdd, phdd = accel_of(P, y, sb, cb, sp, cp, tau, fl)
    out[0] = y[3]
    out[1] = y[4]
    out[2] = y[5]
    out[3] = ldd
    out[4] = bdd
    out[5] = phdd


@njit(**_INLINE)
def rhs_events_inline(P, y, out, gv):
    """``out = f(y)`` and the event values ``gv`` at ``y`` (:func:`event_values`), sharing
    their sines, cosines, torque and leg force: the last stage of a step (its end, FSAL),
    where both are needed. The same values, bit for bit, as the two apart, for about 25 ns
    (three trigonometric calls and a call) less a step."""
    sb, cb, sp, cp, tau, fl = stance_terms(P, y)
    put_rhs(P, y, sb, cb, sp, cp, tau, fl, out)
    put_events(P, y, sb, cb, cp, tau, fl, gv)


@njit(**_INLINE)
def grf(P, y):
    """Ground reaction force ``(F_x, F_y, tau)`` (eqs 2.5-2.6)."""
    b = y[1]
    return grf_at(P, y[0], y[2], y[3], y[4], y[5], math.sin(b), math.cos(b))


@njit(**_INLINE)
def grf_at(P, l, ph, ld, bd, phd, sb, cb):
    """:func:`grf` with ``sin(beta), cos(beta)`` given: the formula's one copy, shared with
    the recorded run's rows (:func:`._record.fill_table`, :func:`._record.stance_forces`),
    which derive the forces from the recorded state with vectorised sines and cosines
    (:mod:`._sincos`, within 1 ulp of libm's that :func:`grf` uses)."""
    tau = hip_torque(P, ph, bd, phd)
    fx, fy = grf_of(leg_force(P, l, ld), tau, l, sb, cb)
    return fx, fy, tau


@njit(**_INLINE)
def grf_of(fl, tau, l, sb, cb):
    """Ground force ``(F_x, F_y)`` (eqs 2.5-2.6) from the leg force ``fl`` (eq. 2.1), the
    hip torque ``tau`` and the leg: :func:`grf_at`'s arithmetic, for a caller that has
    the leg force already (:func:`._record.fill_table`)."""
    return -fl * cb + tau / l * sb, fl * sb + tau / l * cb


@njit(**_INLINE)
def _com_velocity(r, l, sb, cb, sp, cp, ld, bd, phd):
    """CoM velocity (eq. A.5) from the leg and pitch with their sines and cosines."""
    xd = -ld * cb + l * sb * bd + r * cp * phd
    yd = ld * sb + l * cb * bd + r * sp * phd
    return xd, yd


@njit(**_INLINE)
def com_velocity(P, y):
    """CoM velocity from the stance state (eq. A.5)."""
    l, b, ph = y[0], y[1], y[2]
    return _com_velocity(P[P_R], l, math.sin(b), math.cos(b), math.sin(ph), math.cos(ph),
                         y[3], y[4], y[5])


NEVENTS = 5  # event_values
#: The stance events, indices into :func:`event_values` (each fires on a crossing from
#: > 0 to <= 0): lift-off, ``F_y`` (eq. 2.8; ``l_rest - l`` when :func:`liftoff_on_spring`)
EV_LIFTOFF = 0
#: the hip at the ground, ``l sin(beta)`` (eq. 2.11): a fall
EV_HIP_GROUND = 1
#: moving backward, ``xdot_m`` (eq. 2.10): a fall
EV_BACKWARD = 2
#: the leg collapsed, ``l - L_COLLAPSE l0`` (the hip at the foot, which EV_HIP_GROUND cannot
#: see): a fall
EV_COLLAPSE = 3
#: the leg thrust's switch, ``-ldot`` while it is pending: the stance goes on
EV_THRUST = 4
#: Leg length, as a fraction of ``l0``, at which a stance ends as the hip reaching the
#: ground (eq. 2.11, ``Status.FALL_HIP_GROUND``): a leg compressed that far has put the
#: hip on its foot. Without it such a stance ground on at ever smaller steps until
#: ``IntegratorOptions.max_steps`` (100,000 steps, about 0.1 s of CPU a stride).
L_COLLAPSE = 1e-3


@njit(**_JIT)
def event_values(P, y, gv):
    """Stance event functions; each event fires on a crossing from > 0 to <= 0.

    0: lift-off, ``F_y`` (eq. 2.8); 1: hip height above the foot
    ``l sin(beta)`` (eq. 2.11); 2: ``xdot_m`` (eq. 2.10); 3: the leg
    collapsing, ``l - L_COLLAPSE l0``: the hip reaching the foot, on the
    ground, which event 1 cannot see (it only approaches zero as ``l -> 0``,
    where the polar equations are singular, ``betad ~ 1/l^2``); 4: the leg
    thrust's switch, ``-ldot`` while it is pending (``P_THRUST > 0``), else 1.

    Lift-off is located as ``l_rest - l`` when :func:`liftoff_on_spring`.
    """
    sb, cb, _, cp, tau, fl = stance_terms(P, y)
    put_events(P, y, sb, cb, cp, tau, fl, gv)


@njit(**_INLINE)
def put_events(P, y, sb, cb, cp, tau, fl, gv):
    """The event values (:func:`event_values`) from :func:`stance_terms`."""
    l, ld, bd, phd = y[0], y[3], y[4], y[5]
    if liftoff_on_spring(P):
        gv[EV_LIFTOFF] = rest_length(P) - l
    else:
        gv[EV_LIFTOFF] = fl * sb + tau / l * cb  # F_y, eq. 2.6
    gv[EV_HIP_GROUND] = l * sb
    gv[EV_BACKWARD] = -ld * cb + l * sb * bd + P[P_R] * cp * phd  # xdot_m, eq. A.5
    gv[EV_COLLAPSE] = l - L_COLLAPSE * P[P_L0]
    gv[EV_THRUST] = -ld if P[P_THRUST] > 0.0 else 1.0


@njit(**_INLINE)
def stance_initial(P, td, y0):
    """Stance state at touch-down (l = l0), from eq. A.5 inverted for ld, betad."""
    l0 = P[P_L0]
    r = P[P_R]
    b, ph, xd, yd, phd = td[0], td[1], td[2], td[3], td[4]
    u = xd - r * math.cos(ph) * phd
    w = yd - r * math.sin(ph) * phd
    y0[0] = l0
    y0[1] = b
    y0[2] = ph
    y0[3] = -u * math.cos(b) + w * math.sin(b)
    y0[4] = (u * math.sin(b) + w * math.cos(b)) / l0
    y0[5] = phd


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(event_values, __file__)
