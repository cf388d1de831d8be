"""The state just after touch-down: the Poincare section (docs/conventions.md).

At touch-down the leg has its rest length ``l0`` and the foot is on the ground,
so the configuration is fixed by ``(beta, phi)`` plus the ground height ``h``
and the horizontal position ``x``: ``y_m = h + l0 sin(beta) - r cos(phi)``
(eq. 2.9). The velocities are the CoM velocity ``(xd, yd)`` and the pitch rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._checks import check_number

__all__ = ["TouchdownState", "SECTION_NAMES"]

#: Names of the 5-D Poincare-section vector, in order.
SECTION_NAMES: tuple[str, ...] = ("beta", "phi", "xd", "yd", "phid")
_FIELDS = (*SECTION_NAMES, "x", "h")


@dataclass(frozen=True, slots=True)
class TouchdownState:
    """State just after touch-down.

    Parameters
    ----------
    beta : float
        Leg angle [rad] from +x down to the leg, clockwise positive (eq. A.3).
    phi : float
        Trunk pitch [rad], counter-clockwise positive.
    xd, yd : float
        CoM velocity [g^1/2 L^1/2].
    phid : float
        Pitch rate [rad g^1/2 L^-1/2].
    x : float
        CoM horizontal position [L].
    h : float
        Ground height under the foot [L].
    """

    beta: float
    phi: float
    xd: float
    yd: float
    phid: float
    x: float = 0.0
    h: float = 0.0

    def __post_init__(self) -> None:
        for name in _FIELDS:
            value = getattr(self, name)
            if type(value) is not float or not math.isfinite(value):  # else check_number's own
                object.__setattr__(self, name, check_number(value, f"TouchdownState.{name}"))

    @classmethod
    def from_velocity(
        cls, *, v: float, delta: float, beta: float, phi: float = 0.0, phid: float = 0.0,
        x: float = 0.0, h: float = 0.0,
    ) -> TouchdownState:
        """Build from speed ``v`` and velocity angle ``delta = atan2(yd, xd)``."""
        return cls(beta, phi, v * math.cos(delta), v * math.sin(delta), phid, x, h)

    @classmethod
    def from_section(cls, q: np.ndarray, x: float = 0.0, h: float = 0.0) -> TouchdownState:
        """Inverse of :meth:`section`."""
        q = np.asarray(q, dtype=float)
        if q.shape != (5,):
            raise ValueError(f"section vector must have shape (5,), got {q.shape}")
        beta, phi, xd, yd, phid = map(float, q)
        return cls(beta, phi, xd, yd, phid, x=x, h=h)

    @property
    def v(self) -> float:
        """CoM speed at touch-down [g^1/2 L^1/2]."""
        return math.hypot(self.xd, self.yd)

    @property
    def delta(self) -> float:
        """Velocity angle ``atan2(yd, xd)`` [rad]; negative when moving down."""
        return math.atan2(self.yd, self.xd)

    def section(self) -> np.ndarray:
        """The 5-D section vector ``(beta, phi, xd, yd, phid)``."""
        return np.array([self.beta, self.phi, self.xd, self.yd, self.phid])

    def as_array(self) -> np.ndarray:
        """All seven fields ``(beta, phi, xd, yd, phid, x, h)``."""
        return np.array([getattr(self, name) for name in _FIELDS], dtype=float)
