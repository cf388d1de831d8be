"""Stance-phase hip controllers (thesis Section 2.4, eqs 2.12-2.16).

Each controller is a frozen dataclass. The hip torque ``tau`` acts on the local
hip angle ``alpha = beta + phi`` (eq. A.9 puts ``+tau`` on both the beta and the
phi rows), so ``tau * alpha_dot`` is the power the hip delivers.

=====================  =====  ==============================================
controller             code   torque
=====================  =====  ==============================================
``Passive()``          0      ``tau = 0``                          (eq. 2.12)
``GlobalPD(...)``      1      ``Kp (phi_ref - phi) + Kd (phid_ref - phid)`` (2.13)
``LocalVelocity(...)`` 2      ``Kd (alphad_ref - alpha_dot)``      (eq. 2.14)
``ConstantTorque(...)``3      ``tau_c - c_h alpha_dot``        (eqs 2.15-2.16)
=====================  =====  ==============================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

from .._checks import check_fields, check_number

__all__ = [
    "Controller",
    "Passive",
    "GlobalPD",
    "LocalVelocity",
    "ConstantTorque",
    "CONTROLLERS",
    "controller_from_dict",
]


_ROT_DAMP = "Mg^1/2 L^3/2/rad"


def _meta(symbol: str, unit: str, description: str, lower: float = -math.inf) -> dict[str, Any]:
    return {"symbol": symbol, "unit": unit, "description": description, "lower": lower}


@dataclass(frozen=True, slots=True)
class Controller:
    """Base class: a hip controller packed to a code and four numbers."""

    code: ClassVar[int] = -1
    name: ClassVar[str] = ""

    def __post_init__(self) -> None:
        check_fields(self, prefix=f"{type(self).__name__}.")

    def torque_coefficients(self) -> tuple[float, float, float, float]:
        """``(a0, a1, a2, a3)`` of ``tau = a0 + a1 phi + a2 betad + a3 phid``.

        Every controller of eqs 2.12-2.16 is linear in the state, so the
        kernels (and the exact Jacobians) need only these four numbers.
        """
        raise NotImplementedError

    def to_dict(self) -> dict[str, Any]:
        """``{"type": name, **fields}``: the TOML / JSON form."""
        return {"type": self.name, **{f.name: getattr(self, f.name) for f in fields(self)}}


@dataclass(frozen=True, slots=True)
class Passive(Controller):
    """No hip torque, ``tau = 0`` (eq. 2.12)."""

    code: ClassVar[int] = 0
    name: ClassVar[str] = "passive"

    def torque_coefficients(self) -> tuple[float, float, float, float]:
        return (0.0, 0.0, 0.0, 0.0)


@dataclass(frozen=True, slots=True)
class GlobalPD(Controller):
    """PD control of the inertial trunk pitch (eq. 2.13); needs an IMU."""

    code: ClassVar[int] = 1
    name: ClassVar[str] = "global_pd"
    Kp: float = field(default=5.0, metadata=_meta("K_p", "MgL/rad", "proportional gain", 0.0))
    Kd: float = field(
        default=0.5, metadata=_meta("K_d", _ROT_DAMP, "derivative gain", 0.0)
    )
    phi_ref: float = field(default=0.0, metadata=_meta("phi_r", "rad", "reference pitch angle"))
    phid_ref: float = field(
        default=0.0, metadata=_meta("phidot_r", "rad g^1/2 L^-1/2", "reference pitch rate")
    )

    def torque_coefficients(self) -> tuple[float, float, float, float]:
        return (self.Kp * self.phi_ref + self.Kd * self.phid_ref, -self.Kp, 0.0, -self.Kd)


@dataclass(frozen=True, slots=True)
class LocalVelocity(Controller):
    """Local hip angular-velocity control (eq. 2.14): a voltage-driven motor."""

    code: ClassVar[int] = 2
    name: ClassVar[str] = "local_velocity"
    Kd: float = field(
        default=0.5, metadata=_meta("K_d", _ROT_DAMP, "derivative gain", 0.0)
    )
    alphad_ref: float = field(
        default=0.0, metadata=_meta("alphadot_r", "rad g^1/2 L^-1/2", "reference hip rate")
    )

    def torque_coefficients(self) -> tuple[float, float, float, float]:
        return (self.Kd * self.alphad_ref, 0.0, -self.Kd, -self.Kd)


@dataclass(frozen=True, slots=True)
class ConstantTorque(Controller):
    """Constant hip torque with optional hip damping (eqs 2.15-2.16)."""

    code: ClassVar[int] = 3
    name: ClassVar[str] = "constant_torque"
    tau_c: float = field(default=0.0, metadata=_meta("tau_c", "MgL", "constant hip torque"))
    c_h: float = field(default=0.0, metadata=_meta("c_h", _ROT_DAMP, "hip damping", 0.0))

    def torque_coefficients(self) -> tuple[float, float, float, float]:
        return (self.tau_c, 0.0, -self.c_h, -self.c_h)


CONTROLLERS: dict[str, type[Controller]] = {
    c.name: c for c in (Passive, GlobalPD, LocalVelocity, ConstantTorque)
}


def controller_from_dict(data: dict[str, Any] | str) -> Controller:
    """Build a controller from ``{"type": name, **gains}`` or a bare name."""
    if isinstance(data, str):
        data = {"type": data}
    data = dict(data)
    kind = str(data.pop("type", "passive")).lower().replace("-", "_")
    if kind not in CONTROLLERS:
        raise ValueError(f"controller must be one of {sorted(CONTROLLERS)}, got {kind!r}")
    cls = CONTROLLERS[kind]
    allowed = {f.name for f in fields(cls)}
    unknown = set(data) - allowed
    if unknown:
        raise ValueError(
            f"controller {kind!r} has no field {sorted(unknown)[0]!r}; allowed: {sorted(allowed)}"
        )
    return cls(**{k: check_number(v, f"controller.{k}") for k, v in data.items()})
