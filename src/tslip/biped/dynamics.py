"""Biped equations of motion (TMT method, eqs E.1-E.22) as NumPy-facing calls.

The compiled kernels in :mod:`._kernels` give per body the position Jacobian
``J`` (eq. E.11) and convective acceleration ``c = (dJ/dq qd) qd`` (eq. E.20)
in closed form, and the products ``M = J^T M_f J`` (eq. E.14) and
``Q - C = J^T (f_g + f_grf - M_f c) + f_a`` (eqs E.18-E.22) summed in closed
form over the three bodies of each leg.
The tests compare them with an independent symbolic Lagrangian derivation.

Notes on the thesis text
------------------------
* Eq. E.13 lists ``J_t`` for the shank; the shank inertia ``J_s`` is used.
* Eq. E.21 prints ``C = J^T M c``; the full-coordinate mass matrix ``M_f`` is
  meant (dimensions).
* Eq. E.17 places the hip torque on the thigh angle only, which would make it
  an external torque. The hip torque, thigh force and shank force are
  internal, so their generalised forces are ``tau`` on ``theta_h``, ``F_t`` on
  ``l_t`` and ``F_s`` on ``l_s`` (virtual work of a joint actuator).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from . import _kernels as kn
from . import _pack as pk
from .parameters import BipedParams, BipedState

__all__ = [
    "mass_matrix",
    "bias_forces",
    "accelerations",
    "energy",
    "body_positions",
    "momentum",
    "foot_position",
    "hip_position",
    "controller_references",
    "leg_phase",
]


def _q(q: NDArray[np.float64] | BipedState, qd: NDArray[np.float64] | None = None,
       ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    if isinstance(q, BipedState):
        return q.q.copy(), q.qd.copy()
    q = np.asarray(q, dtype=np.float64)
    if q.shape == (18,):
        return q[:9].copy(), q[9:].copy()
    if q.shape != (9,):
        raise ValueError(f"q must have shape (9,) or (18,), got {q.shape}")
    qd = np.zeros(9) if qd is None else np.asarray(qd, dtype=np.float64)
    if qd.shape != (9,):
        raise ValueError(f"qd must have shape (9,), got {qd.shape}")
    return q, qd


def _tmt(params: BipedParams, q: NDArray[np.float64], qd: NDArray[np.float64],
         ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(M, h)`` of :func:`._kernels.mass_matrix_and_bias` (eqs E.14-E.21)."""
    M = np.empty((9, 9))
    h = np.empty(9)
    kn.mass_matrix_and_bias(pk.pack_params(params), q, qd, M, h)
    return M, h


def _kin(params: BipedParams, q: NDArray[np.float64], qd: NDArray[np.float64]):
    """Body positions, Jacobians, masses and inertias (eqs E.4-E.13)."""
    P = pk.pack_params(params)
    pos, Jp, Ja, cv, mass, inertia = kn._make_kin_ws()
    kn.kinematics(P, q, qd, pos, Jp, Ja, cv)
    kn.body_props(P, mass, inertia)
    return pos, Jp, Ja, mass, inertia


def mass_matrix(params: BipedParams, q: NDArray[np.float64] | BipedState) -> NDArray[np.float64]:
    """Mass matrix in minimal coordinates, ``M = J_T^T M_f J_T`` (eq. E.14).

    Returns
    -------
    ndarray, shape (9, 9)
        Symmetric positive definite.
    """
    q, qd = _q(q)
    return _tmt(params, q, qd)[0]


def bias_forces(params: BipedParams, q: NDArray[np.float64] | BipedState,
                qd: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
    """Gravity minus convective forces, ``J^T (f_g - M_f c)`` (eqs E.15, E.20-E.21).

    Returns
    -------
    ndarray, shape (9,)
        Passive generalised forces without ground, actuators and shank spring.
    """
    q, qd = _q(q, qd)
    return _tmt(params, q, qd)[1]


def accelerations(params: BipedParams, state: BipedState | NDArray[np.float64], t: float = 0.0,
                  contact: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
    """Generalised accelerations ``qdd`` from eq. E.22 with all forces at time ``t``.

    ``contact`` is the contact state ``(on_R, on_L, x_R, z_R, x_L, z_L)``;
    default: no foot in contact.
    """
    q, qd = _q(state)
    y = np.concatenate([q, qd])
    P = pk.pack_params(params)
    cs = np.zeros(pk.NCS) if contact is None else np.asarray(contact, dtype=np.float64)
    out = np.empty(18)
    ctl = np.empty(4)
    kn.init_ctl(P, float(t), ctl)
    kn.rhs(P, float(t), y, cs, ctl, True, out, kn._make_ws(), np.empty(10))
    return out[9:]


def energy(params: BipedParams, state: BipedState | NDArray[np.float64]) -> float:
    """Kinetic, gravitational and shank-spring energy [M g L] (ground excluded)."""
    q, qd = _q(state)
    return float(kn.energy(pk.pack_params(params), np.concatenate([q, qd])))


def body_positions(params: BipedParams, q: NDArray[np.float64] | BipedState,
                   ) -> NDArray[np.float64]:
    """CoM positions (x, z) of trunk, thigh R, shank R, foot R, thigh L, shank L, foot L.

    Returns
    -------
    ndarray, shape (7, 2)
        Eqs E.4-E.8.
    """
    q, qd = _q(q)
    return _kin(params, q, qd)[0]


def momentum(params: BipedParams, state: BipedState | NDArray[np.float64],
             ) -> tuple[NDArray[np.float64], NDArray[np.float64], float]:
    """Centre of mass, linear momentum and angular momentum about the CoM.

    ``L = sum_i m_i (p_i - c) x v_i + J_i omega_i`` over the seven bodies of
    eq. E.13, with ``v_i = J_i qd`` (eq. E.11). Moments are counter-clockwise
    positive (x forward, z up); segment angles are clockwise positive (eq.
    E.2: ``b_z = (sin theta_b, cos theta_b)``), so ``omega_i = -dangle_i/dt``.
    Only the ground forces change ``L``: gravity acts at the body CoMs and the
    actuators are internal.

    Returns
    -------
    com : ndarray, shape (2,)
        Whole-body CoM ``(x, z)`` [L].
    p : ndarray, shape (2,)
        Linear momentum [M g^1/2 L^1/2].
    L : float
        Angular momentum about ``com`` [M g^1/2 L^3/2].
    """
    q, qd = _q(state)
    pos, Jp, Ja, mass, inertia = _kin(params, q, qd)
    v = Jp @ qd
    m_tot = float(mass.sum())
    com = mass @ pos / m_tot
    r = pos - com
    L = float(np.sum(mass * (r[:, 0] * v[:, 1] - r[:, 1] * v[:, 0])) - inertia @ (Ja @ qd))
    return com, mass @ v, L


def hip_position(params: BipedParams, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Hip position(s) ``p_b + r_1 b_z`` (eq. E.5) for q of shape (..., 9)."""
    q = np.asarray(q, dtype=np.float64)
    return np.stack([q[..., 0] + params.r_1 * np.sin(q[..., 2]),
                     q[..., 1] + params.r_1 * np.cos(q[..., 2])], axis=-1)


def foot_position(params: BipedParams, q: NDArray[np.float64], leg: int) -> NDArray[np.float64]:
    """Foot position(s) (eq. E.8) for q of shape (..., 9); ``leg`` 0 right, 1 left."""
    if leg not in (0, 1):
        raise ValueError(f"leg must be 0 (right) or 1 (left), got {leg!r}")
    q = np.asarray(q, dtype=np.float64)
    b = 3 + 3 * leg
    s = q[..., b] + q[..., b + 1]
    gam = q[..., 2] + q[..., b + 2]
    hip = hip_position(params, q)
    return np.stack([hip[..., 0] - s * np.sin(gam), hip[..., 1] - s * np.cos(gam)], axis=-1)


def leg_phase(params: BipedParams, t: NDArray[np.float64] | float, leg: int,
              ) -> NDArray[np.float64]:
    """Leg phase in [0, 1) at time(s) ``t`` (eqs E.25-E.27)."""
    t = np.asarray(t, dtype=np.float64)
    rho = np.mod(np.mod(t, params.T) / params.T + params.rho0, 1.0)
    return np.mod(rho + 0.5, 1.0) if leg == 1 else rho


def controller_references(params: BipedParams, rho: NDArray[np.float64] | float,
                          ) -> NDArray[np.float64]:
    """``(l_ref, ld_ref, theta_ref, thetad_ref)`` at phase(s) ``rho`` (eqs E.29-E.33).

    Returns
    -------
    ndarray, shape (..., 4)

    Notes
    -----
    Eq. E.32 as printed jumps by ``theta_s`` at ``rho = 0`` and ``rho = d``;
    the stance branch used is ``theta_f + theta_s/2 (1 - cos(pi rho / d))``,
    continuous and with eq. E.33 as its derivative.
    """
    P = pk.pack_params(params)
    r = np.atleast_1d(np.asarray(rho, dtype=np.float64))
    out = np.array([kn.references(P, float(x)) for x in r.ravel()]).reshape(r.shape + (4,))
    return out[0] if np.ndim(rho) == 0 else out
