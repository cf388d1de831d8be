"""The 3-D TSLIP's touch-down section, its mirror, and the two-step map's multipliers.

Issue 43, Part 2. At a touch-down the leg has its rest length and the foot is on
flat ground, so given the side ``s`` the state less the horizontal translations
(``x``, ``z``; the model does not depend on them) is the 10-vector
(:data:`SECTION_NAMES`)

    (a, yaw, pitch, roll, vx, vy, vz, w_roll, w_yaw, w_pitch):

``a`` the hip angle at touch-down (the leg direction in the trunk frame is
``(cos a, -sin a cos(splay), s sin a sin(splay))``, ``0 < a < pi``), the trunk's
attitude ``R = R_y(yaw) R_z(pitch) R_x(roll)`` (yaw about the vertical, pitch
about the lateral axis, roll about the forward axis), the CoM velocity and the
body angular velocity. The CoM height follows from the foot on the ground
(eq. 2.9 in 3-D). With ``splay = 0`` and no lateral motion, ``a = beta + phi``
and ``pitch = phi``: the planar section (docs/conventions.md).

The mirror in the sagittal plane (z -> -z) negates ``yaw``, ``roll``, ``vz``,
``w_roll`` and ``w_yaw`` and swaps the side; a left-right symmetric gait is a
right touch-down whose stride lands on its mirror image. The model is invariant
under yaw (the leg placement and the controllers are local; the global reset and
PD use the pitch only), so the two-step map has a multiplier 1 along the yaw
(the heading), and a conservative model one along the energy.
"""

from __future__ import annotations

import math

import numpy as np

from ..simulation.options import IntegratorOptions
from . import _trunk_kernels as kn
from .trunk import TrunkStatus, TrunkTouchdown, rotation, trunk_step
from .trunk_parameters import TrunkParams

__all__ = ["SECTION_NAMES", "MIRROR", "section", "from_section", "mirror_section",
           "two_step_map", "two_step_jacobian", "one_step_map", "symmetric_gait", "yaw_rotated"]

#: Names of the 10-D touch-down section, in order.
SECTION_NAMES: tuple[str, ...] = ("a", "yaw", "pitch", "roll", "vx", "vy", "vz", "w_roll",
                                  "w_yaw", "w_pitch")
#: Signs of the mirror z -> -z on the section.
MIRROR = np.array([1.0, -1.0, 1.0, -1.0, 1.0, 1.0, -1.0, -1.0, -1.0, 1.0])


def _attitude(yaw: float, pitch: float, roll: float) -> np.ndarray:
    cy, sy, cp, sp, cr, sr = (math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch),
                              math.cos(roll), math.sin(roll))
    Ry = np.array([[cy, 0.0, sy], [0.0, 1.0, 0.0], [-sy, 0.0, cy]])
    Rz = np.array([[cp, -sp, 0.0], [sp, cp, 0.0], [0.0, 0.0, 1.0]])
    Rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    return Ry @ Rz @ Rx


def _quaternion(R: np.ndarray) -> np.ndarray:
    """A unit quaternion (w, x, y, z) of the rotation ``R`` (Shepperd's method)."""
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    cands = [tr, R[0, 0], R[1, 1], R[2, 2]]
    k = int(np.argmax(cands))
    if k == 0:
        w = 0.5 * math.sqrt(1.0 + tr)
        q = [w, (R[2, 1] - R[1, 2]) / (4 * w), (R[0, 2] - R[2, 0]) / (4 * w),
             (R[1, 0] - R[0, 1]) / (4 * w)]
    elif k == 1:
        x = 0.5 * math.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2])
        q = [(R[2, 1] - R[1, 2]) / (4 * x), x, (R[0, 1] + R[1, 0]) / (4 * x),
             (R[0, 2] + R[2, 0]) / (4 * x)]
    elif k == 2:
        y = 0.5 * math.sqrt(1.0 - R[0, 0] + R[1, 1] - R[2, 2])
        q = [(R[0, 2] - R[2, 0]) / (4 * y), (R[0, 1] + R[1, 0]) / (4 * y), y,
             (R[1, 2] + R[2, 1]) / (4 * y)]
    else:
        z = 0.5 * math.sqrt(1.0 - R[0, 0] - R[1, 1] + R[2, 2])
        q = [(R[1, 0] - R[0, 1]) / (4 * z), (R[0, 2] + R[2, 0]) / (4 * z),
             (R[1, 2] + R[2, 1]) / (4 * z), z]
    qa = np.array(q)
    return qa if qa[0] >= 0.0 else -qa


def _placement(params: TrunkParams, side: int, a: float, R: np.ndarray) -> np.ndarray:
    """The leg direction in the trunk frame at hip angle ``a`` (with the roll couplings):
    the kernel's :func:`~tslip.spatial._trunk_kernels.leg_direction` itself."""
    P = params.packed(side)
    P[kn.P_ALPHA], P[kn.P_OMEGA], P[kn.P_GLOBAL], P[kn.P_STOP] = a, 0.0, 0.0, 0.0
    d = np.empty(3)
    kn.leg_direction(P, np.ascontiguousarray(R), 0.0, d)
    return d


def from_section(params: TrunkParams, x: np.ndarray, side: int = 1) -> TrunkTouchdown:
    """The touch-down of section vector ``x`` (module docstring), CoM above ``x = z = 0``."""
    x = np.asarray(x, dtype=float)
    if x.shape != (10,):
        raise ValueError(f"section vector must have shape (10,), got {x.shape}")
    a, yaw, pitch, roll = x[0:4]
    R = _attitude(yaw, pitch, roll)
    d = _placement(params, side, a, R)
    off = params.r * R[:, 1] + params.l0 * (R @ d)
    c = np.array([0.0, -off[1], 0.0])
    foot = c + off
    foot[1] = 0.0
    y = np.concatenate([c, x[4:7], _quaternion(R), x[7:10]])
    return TrunkTouchdown(y, foot, side)


def section(params: TrunkParams, state: TrunkTouchdown) -> np.ndarray:
    """The section vector of a touch-down (inverse of :func:`from_section`)."""
    y = state.y
    R = rotation(y)
    u = R.T @ (state.foot - y[0:3] - params.r * R[:, 1])
    roll = math.atan2(-R[1, 2], R[1, 1])
    if params.k_trail != 0.0:  # undo the trail's turn about y_b (kernel's leg_direction)
        psi = -params.k_trail * roll
        c, z = math.cos(psi), math.sin(psi)
        u = np.array([c * u[0] - z * u[2], u[1], z * u[0] + c * u[2]])
    a = math.atan2(math.hypot(u[1], u[2]), u[0])
    yaw = math.atan2(-R[2, 0], R[0, 0])
    pitch = math.atan2(R[1, 0], math.hypot(R[0, 0], R[2, 0]))
    return np.array([a, yaw, pitch, roll, *y[3:6], *y[10:13]])


def yaw_rotated(x: np.ndarray, angle: float) -> np.ndarray:
    """The section vector of the same touch-down turned by ``angle`` about the vertical
    (the yaw and the velocity turn; the body-frame rates do not)."""
    out = np.array(x, dtype=float)
    c, s = math.cos(angle), math.sin(angle)
    out[1] += angle
    out[4], out[6] = c * x[4] + s * x[6], -s * x[4] + c * x[6]
    return out


def mirror_section(x: np.ndarray) -> np.ndarray:
    """The mirror image (z -> -z) of a section vector; the side swaps with it."""
    return MIRROR * np.asarray(x, dtype=float)


def two_step_map(params: TrunkParams, x: np.ndarray, *, side: int = 1,
                 options: IntegratorOptions | None = None) -> tuple[np.ndarray, TrunkStatus]:
    """Two strides from the touch-down ``x`` of ``side``: the section after them (NaN after
    a fall) and the status."""
    state = from_section(params, x, side)
    for _ in range(2):
        r = trunk_step(params, state, options=options)
        if not r.ok or r.state is None:
            return np.full(10, np.nan), r.status
        state = r.state
    return section(params, state), TrunkStatus.OK


def two_step_jacobian(params: TrunkParams, x: np.ndarray, *, side: int = 1,
                      step: float = 1e-6, columns: tuple[int, ...] | None = None,
                      options: IntegratorOptions | None = None,
                      method: str = "exact") -> np.ndarray:
    """The Jacobian (10 x 10) of :func:`two_step_map` at ``x``; its eigenvalues at a
    symmetric gait are the Floquet multipliers of the two-step map.

    ``method="exact"`` (the default): the variational equations on the same Runge-Kutta
    core with the event-time corrections at lift-off and touch-down
    (:func:`tslip.spatial.trunk_jacobian.two_step_jacobian_exact`; within 1e-8 of
    central differences relative to its norm at the gaits of
    docs/analyses/spatial_tslip.md). ``"fd"``: central differences with ``step`` (the
    only use of ``step``).
    ``columns`` limits it to those section components (10 x len(columns)); the planar
    ones ``(0, 2, 4, 5, 9)`` keep a planar gait with ``splay = 0`` in its plane, where a
    roll of either sign would cross a leg."""
    x = np.asarray(x, dtype=float)
    cols = tuple(range(10)) if columns is None else tuple(columns)
    if method == "exact":
        from .trunk_jacobian import two_step_jacobian_exact

        try:
            return two_step_jacobian_exact(params, x, side=side, options=options)[1][:, cols]
        except ValueError as err:
            raise ValueError(f"two_step_jacobian: {err}") from None
    if method != "fd":
        raise ValueError(f"two_step_jacobian: method must be 'exact' or 'fd', got {method!r}")
    Jm = np.empty((10, len(cols)))
    for k, j in enumerate(cols):
        e = np.zeros(10)
        e[j] = step
        fp, sp = two_step_map(params, x + e, side=side, options=options)
        fm, sm = two_step_map(params, x - e, side=side, options=options)
        if sp != TrunkStatus.OK or sm != TrunkStatus.OK:
            raise ValueError(f"two_step_jacobian: a perturbed stride failed ({sp.name}, "
                             f"{sm.name}) at column {SECTION_NAMES[j]}")
        Jm[:, k] = (fp - fm) / (2.0 * step)
    return Jm


def one_step_map(params: TrunkParams, x: np.ndarray, *, side: int = 1,
                 options: IntegratorOptions | None = None) -> tuple[np.ndarray, TrunkStatus]:
    """One stride from the touch-down ``x`` of ``side``: the other leg's section (NaN after
    a fall) and the status."""
    r = trunk_step(params, from_section(params, x, side), options=options)
    if not r.ok or r.state is None:
        return np.full(10, np.nan), r.status
    return section(params, r.state), TrunkStatus.OK


def symmetric_gait(params: TrunkParams, guess: np.ndarray, *, fixed: int = 4,
                   tol: float = 1e-11, max_iter: int = 30,
                   options: IntegratorOptions | None = None) -> np.ndarray:
    """A left-right symmetric gait: a right touch-down ``x`` whose stride lands on its
    mirror image, ``one_step_map(x) = MIRROR x`` (10 equations), by Gauss-Newton from
    ``guess`` with the component ``fixed`` (default ``vx``, the forward speed) held.

    The equations have one redundancy for a conservative model (the energy), so the
    least-squares Newton step is used. Raises ``ValueError`` in one line when a stride
    fails or the residual stays above ``tol``.
    """
    x = np.array(guess, dtype=float)
    free = [j for j in range(10) if j != fixed]

    def res(z: np.ndarray) -> np.ndarray:
        f, st = one_step_map(params, z, options=options)
        if st != TrunkStatus.OK:
            raise ValueError(f"symmetric_gait: a stride failed ({st.name})")
        return f - MIRROR * z

    F = res(x)
    for _ in range(max_iter):
        if np.max(np.abs(F)) < tol:
            return x
        J = np.empty((10, len(free)))
        for k, j in enumerate(free):
            e = np.zeros(10)
            e[j] = 1e-6
            J[:, k] = (res(x + e) - res(x - e)) / 2e-6
        dz = np.linalg.lstsq(J, -F, rcond=None)[0]
        x[free] += dz
        F = res(x)
    if np.max(np.abs(F)) < max(tol, 1e-9):
        return x
    raise ValueError(f"symmetric_gait: no convergence, residual {np.max(np.abs(F)):.2e}")
