"""The TSLIP equations of motion in plain NumPy, meant to be read.

This is the reference the compiled kernels are tested against; it follows
the thesis's TMT derivation (Appendix A) term by term. Stance coordinates
are ``q = (l, beta, phi)`` with the foot fixed at ``(x_f, h)``.

References
----------
M. J. van den Broek, "Fast Self-Stable Planar Bipedal Running", TU Delft /
IHMC 2019, Section 2.2 and Appendix A.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .parameters import Params

__all__ = [
    "kinematics",
    "jacobian",
    "mass_matrix",
    "forces",
    "convective",
    "hip_torque",
    "spring_force",
    "spring_energy",
    "leg_force",
    "stance_rhs",
    "ground_reaction_force",
    "energy",
    "swing_angle",
]


def kinematics(p: Params, q: np.ndarray, xf: float = 0.0, h: float = 0.0) -> np.ndarray:
    """Full coordinates ``x = (x_m, y_m, l, beta, phi)`` from ``q`` (eq. A.3)."""
    l, b, ph = q
    return np.array([-l * np.cos(b) + p.r * np.sin(ph) + xf, l * np.sin(b) - p.r * np.cos(ph) + h,
                     l, b, ph])


def jacobian(p: Params, q: np.ndarray) -> np.ndarray:
    """Kinematic Jacobian ``J_T = dT/dq``, shape (5, 3) (eq. A.4)."""
    l, b, ph = q
    return np.array([
        [-np.cos(b), l * np.sin(b), p.r * np.cos(ph)],
        [np.sin(b), l * np.cos(b), p.r * np.sin(ph)],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ])


def _full_mass(p: Params) -> np.ndarray:
    """``M_f = diag(m, m, 0, 0, J)`` (eq. A.6): the leg is massless."""
    return np.diag([p.m, p.m, 0.0, 0.0, p.J])


def mass_matrix(p: Params, q: np.ndarray) -> np.ndarray:
    """``M = J_T^T M_f J_T`` (eqs 2.4, A.7)."""
    JT = jacobian(p, q)
    return JT.T @ _full_mass(p) @ JT


def hip_torque(p: Params, q: np.ndarray, qd: np.ndarray) -> float:
    """Hip torque of ``p.controller`` (eqs 2.12-2.16)."""
    c = p.controller
    _, _, ph = q
    _, bd, phd = qd
    alphad = bd + phd
    name = c.name
    if name == "passive":
        return 0.0
    if name == "global_pd":
        return c.Kp * (c.phi_ref - ph) + c.Kd * (c.phid_ref - phd)  # type: ignore[attr-defined]
    if name == "local_velocity":
        return c.Kd * (c.alphad_ref - alphad)  # type: ignore[attr-defined]
    return c.tau_c - c.c_h * alphad  # type: ignore[attr-defined]


def spring_force(p: Params, l: Any, l_rest: float | None = None) -> Any:
    """Compressive spring force ``F_s = k l0 sgn(x) |x|^n``, ``x = (l_rest - l) / l0``.

    ``n = p.leg_exponent``; ``n = 1`` is eq. 2.1's ``k (l_rest - l)``. ``l_rest``
    defaults to ``l0`` (before a leg thrust's switch; docs/model.md, "Leg spring
    and thrust"). ``l`` may be an array.
    """
    lr = p.l0 if l_rest is None else l_rest
    if p.leg_exponent == 1.0:
        return p.k * (lr - l)
    x = (lr - np.asarray(l, dtype=float)) / p.l0
    return p.k * p.l0 * np.sign(x) * np.abs(x) ** p.leg_exponent


def spring_energy(p: Params, l: Any, l_rest: float | None = None) -> Any:
    """Spring potential ``V = k l0^2 |x|^(n+1) / (n+1)`` (``k (l_rest - l)^2 / 2`` at n = 1)."""
    lr = p.l0 if l_rest is None else l_rest
    n = p.leg_exponent
    if n == 1.0:
        return 0.5 * p.k * (lr - l) ** 2
    x = np.abs((lr - np.asarray(l, dtype=float)) / p.l0)
    return p.k * p.l0**2 * x ** (n + 1) / (n + 1)


def leg_force(p: Params, q: np.ndarray, qd: np.ndarray, l_rest: float | None = None) -> Any:
    """Compressive leg force ``F_l = F_s - c_l ldot`` (eq. 2.1 at ``n = 1``)."""
    return spring_force(p, q[0], l_rest) - p.c_l * qd[0]


def forces(p: Params, q: np.ndarray, qd: np.ndarray,
           l_rest: float | None = None) -> np.ndarray:
    """Generalised forces ``Q = J_T^T (f_g + f_t + f_l)`` (eq. A.11)."""
    tau = hip_torque(p, q, qd)
    f = np.array([0.0, -p.m * p.g, leg_force(p, q, qd, l_rest), tau, tau])  # eqs A.8-A.10
    return jacobian(p, q).T @ f


def convective(p: Params, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """Convective terms ``C = J_T^T M_f ((dJ_T/dq) qd) qd`` (eqs A.12-A.13)."""
    l, b, ph = q
    ld, bd, phd = qd
    # c = d/dt(J_T) qd, the convective accelerations in full coordinates
    c = np.array([
        2 * ld * bd * np.sin(b) + l * bd**2 * np.cos(b) - p.r * phd**2 * np.sin(ph),
        2 * ld * bd * np.cos(b) - l * bd**2 * np.sin(b) + p.r * phd**2 * np.cos(ph),
        0.0, 0.0, 0.0,
    ])
    return jacobian(p, q).T @ _full_mass(p) @ c


def stance_rhs(p: Params, y: np.ndarray, l_rest: float | None = None) -> np.ndarray:
    """Time derivative of ``y = (l, beta, phi, ld, betad, phid)`` (eq. A.14)."""
    q, qd = y[:3], y[3:]
    qdd = np.linalg.solve(mass_matrix(p, q),
                          forces(p, q, qd, l_rest) - convective(p, q, qd))
    return np.concatenate([qd, qdd])


def ground_reaction_force(p: Params, y: np.ndarray,
                          l_rest: float | None = None) -> np.ndarray:
    """``(F_x, F_y)`` at the foot (eqs 2.5-2.6)."""
    q, qd = y[:3], y[3:]
    l, b = q[0], q[1]
    fl = leg_force(p, q, qd, l_rest)
    tau = hip_torque(p, q, qd)
    return np.array([-fl * np.cos(b) + tau / l * np.sin(b), fl * np.sin(b) + tau / l * np.cos(b)])


def energy(p: Params, y: np.ndarray, h: float = 0.0, l_rest: float | None = None) -> float:
    """Total mechanical energy in stance: kinetic + gravity + leg spring ``V`` [MgL]."""
    q, qd = y[:3], y[3:]
    x = kinematics(p, q, 0.0, h)
    v = jacobian(p, q) @ qd
    return float(0.5 * p.m * (v[0] ** 2 + v[1] ** 2) + 0.5 * p.J * v[4] ** 2 + p.m * p.g * x[1]
                 + spring_energy(p, q[0], l_rest))


def swing_angle(p: Params, s: float) -> float:
    """Flight leg angle in the frame of ``alpha_r``, ``s`` after the retraction clock's start.

    ``alpha_r + omega_r s`` (eq. 2.17; the local hip angle for ``leg_reset="local"``,
    the global leg angle for ``"global"``), held at the retraction stop
    (Section 7.5, ``p.alpha_stop``): ``min(alpha_r + omega_r s, max(alpha_r,
    alpha_stop))`` for ``omega_r > 0``, the mirror for ``omega_r < 0``
    (docs/conventions.md). ``s < 0`` (before the clock starts) holds ``alpha_r``.
    """
    a = p.alpha_r + p.omega_r * max(s, 0.0)
    if p.alpha_stop is None or p.omega_r == 0.0:
        return a
    if p.omega_r > 0.0:
        return min(a, max(p.alpha_r, p.alpha_stop))
    return max(a, min(p.alpha_r, p.alpha_stop))
