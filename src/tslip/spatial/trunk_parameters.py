"""Parameters of the TSLIP in three dimensions (issue 43, Part 2).

Dimensionless in the units of the planar model (thesis Table 3.1: body mass M,
gravity g, rest leg length L). Frame: x forward, y up, z = x cross y (the
runner's right); side ``s = +1`` is the right leg, ``-1`` the left.

The trunk is a rigid body with principal inertias ``J_roll`` (about its forward
axis ``x_b``), ``J_yaw`` (its long axis ``y_b``) and ``J`` (its lateral axis
``z_b``: the planar pitch inertia). The defaults are thesis Table 2.1 (the
planar :class:`tslip.Params` defaults) with ``J_roll = J_yaw = J`` and no
splay. Every planar field keeps its planar meaning (docs/conventions.md):
``r > 0`` hangs the CoM below the hip; ``alpha_r``, ``omega_r``,
``retraction`` and ``alpha_stop`` set the flight leg's angle in the trunk's
sagittal plane (``leg_reset="local"``, the base model) or its pitch in the
world (``"global"``, the pitch of a yaw-pitch-roll sequence; for the planar
limit); ``controller`` is one of the four planar hip controllers, acting about
``z_b``. ``splay`` turns the flight leg outward about ``x_b`` (towards
``+z_b`` for the right leg). ``k_splay`` and ``k_trail`` (0: the base model)
couple the placement to the trunk's roll ``rho`` (the roll of the yaw-pitch-roll
sequence, > 0 leaning right): splay ``splay + k_splay s rho``, and the leg turned
about ``y_b`` by ``-k_trail rho`` (a trail: to the right when leaning right).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from .._checks import check_fields, check_number
from ..model.controllers import Controller, Passive
from ..model.parameters import LEG_RESETS, RETRACTIONS, LegReset, Params, Retraction
from . import _trunk_kernels as kn

__all__ = ["TrunkParams"]

_INF = math.inf


def _f(default: float, unit: str, description: str, lower: float = -_INF,
       upper: float = _INF, lower_open: bool = True, upper_open: bool = True) -> Any:
    return field(default=default, metadata={
        "unit": unit, "description": description, "lower": lower, "upper": upper,
        "lower_open": lower_open, "upper_open": upper_open})


@dataclass(frozen=True, slots=True, kw_only=True)
class TrunkParams:
    """The 3-D TSLIP (module docstring; the model in :mod:`tslip.spatial.trunk`)."""

    m: float = _f(1.0, "M", "body mass", 0.0)
    J: float = _f(0.1, "ML^2", "trunk inertia about its lateral axis z_b (pitch)", 0.0)
    J_roll: float = _f(0.1, "ML^2", "trunk inertia about its forward axis x_b (roll)", 0.0)
    J_yaw: float = _f(0.1, "ML^2", "trunk inertia about its long axis y_b (yaw)", 0.0)
    r: float = _f(0.3, "L", "CoM offset below the hip (r > 0: hanging mass)")
    k: float = _f(25.0, "MgL^-1", "leg spring stiffness", 0.0)
    l0: float = _f(1.0, "L", "rest leg length", 0.0)
    g: float = _f(1.0, "g", "gravitational acceleration", 0.0)
    c_l: float = _f(0.0, "Mg^1/2 L^-1/2", "leg damping coefficient", 0.0, lower_open=False)
    omega_r: float = _f(1.0, "rad g^1/2 L^-1/2", "swing-leg retraction rate (+: foot moves back)")
    alpha_r: float = _f(1.0, "rad", "leg reset angle at lift-off")
    leg_exponent: float = _f(1.0, "-", "leg spring exponent n", 0.5, 3.0, False, False)
    leg_thrust: float = _f(0.0, "-", "leg thrust d: rest length l0 (1 + d) after max compression",
                           0.0, 0.5, False, False)
    splay: float = _f(0.0, "rad", "leg abduction about the trunk's forward axis (+: outward)",
                      -math.pi / 2, math.pi / 2)
    k_splay: float = _f(0.0, "-", "splay per roll angle at placement (+: outward leaning "
                        "towards the leg)")
    k_trail: float = _f(0.0, "-", "placement yaw per roll angle (+: to the right leaning right)")
    controller: Controller = field(default_factory=Passive)
    leg_reset: LegReset = "local"
    retraction: Retraction = "liftoff"
    alpha_stop: float | None = None

    def __post_init__(self) -> None:
        check_fields(self, prefix="TrunkParams.")
        if not isinstance(self.controller, Controller):
            raise ValueError(f"TrunkParams.controller must be a tslip controller, "
                             f"got {self.controller!r}")
        for name, allowed in (("leg_reset", LEG_RESETS), ("retraction", RETRACTIONS)):
            value = getattr(self, name)
            if not (isinstance(value, str) and value in allowed):
                raise ValueError(f"TrunkParams.{name} must be "
                                 f"{' or '.join(map(repr, allowed))}, got {value!r}")
        if self.alpha_stop is not None:
            object.__setattr__(self, "alpha_stop", float(check_number(
                self.alpha_stop, "TrunkParams.alpha_stop", unit="rad", lower=0.0,
                upper=math.pi, lower_open=True, upper_open=True)))

    @classmethod
    def from_planar(cls, params: Params, **changes: Any) -> TrunkParams:
        """The 3-D model of a planar :class:`tslip.Params` (``J_roll = J_yaw = J`` unless
        ``changes`` say otherwise); ``v0`` and ``beta0`` (the planar gait's nominal
        touch-down) have no 3-D field."""
        own = {f.name for f in fields(cls)}
        base = {name: getattr(params, name) for name in own if hasattr(params, name)}
        base["J_roll"] = base["J_yaw"] = params.J
        base.update(changes)
        return cls(**base)

    def to_dict(self) -> dict[str, Any]:
        """Plain ``dict`` (JSON friendly; the run record of a saved result), the controller
        as a sub-table, ``alpha_stop`` omitted when ``None`` (no stop)."""
        out: dict[str, Any] = {f.name: getattr(self, f.name) for f in fields(self)
                               if f.name not in ("controller", "alpha_stop")}
        if self.alpha_stop is not None:
            out["alpha_stop"] = self.alpha_stop
        out["controller"] = self.controller.to_dict()
        return out

    def packed(self, side: int = 1) -> np.ndarray:
        """The kernel's parameter vector (:mod:`tslip.spatial._trunk_kernels`), for ``side``."""
        P = np.zeros(kn.NP)
        P[kn.P_M], P[kn.P_J], P[kn.P_JROLL], P[kn.P_JYAW] = self.m, self.J, self.J_roll, self.J_yaw
        P[kn.P_R], P[kn.P_K], P[kn.P_L0], P[kn.P_G] = self.r, self.k, self.l0, self.g
        P[kn.P_CL], P[kn.P_NEXP], P[kn.P_THRUST] = self.c_l, self.leg_exponent, self.leg_thrust
        P[kn.P_OMEGA], P[kn.P_ALPHA], P[kn.P_SPLAY] = self.omega_r, self.alpha_r, self.splay
        P[kn.P_GLOBAL] = 1.0 if self.leg_reset == "global" else 0.0
        P[kn.P_STOP] = 0.0 if self.alpha_stop is None else self.alpha_stop
        P[kn.P_KSPLAY], P[kn.P_KTRAIL] = self.k_splay, self.k_trail
        P[kn.P_C0:kn.P_C0 + 4] = self.controller.torque_coefficients()
        P[kn.P_SIDE] = float(side)
        P[kn.P_LREST] = self.l0
        P[kn.P_PENDING] = 1.0 if self.leg_thrust > 0.0 else 0.0
        P[kn.P_APEX] = 1.0 if self.retraction == "apex" else 0.0
        return P
