"""Conversion between SI and the dimensionless units of thesis Table 3.1.

Quantities are normalised by body mass M, gravity g and rest leg length L:
``dimensionless = SI / (M^a g^b L^c)`` (eq. 3.1), with each parameter's
exponents ``(a, b, c)`` in its ``dims`` metadata.

Examples
--------
>>> s = Scaling(M=3.3, g=9.81, L=0.5)            # the robot of Table 5.1
>>> round(s.to_dimensionless(4.4, "speed"), 2)    # 4.4 m/s
1.99
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .parameters import PARAMETER_TABLE, Params

__all__ = [
    "Scaling", "QUANTITY_DIMS", "ROBOT_SI", "ROBOT_SCALING", "to_si", "from_si", "robot_params",
    "UNIT", "COLUMN_UNITS", "param_unit",
]

#: (M, g, L) exponents of each quantity kind of Table 3.1.
QUANTITY_DIMS: dict[str, tuple[float, float, float]] = {
    "length": (0, 0, 1),
    "time": (0, -0.5, 0.5),
    "frequency": (0, 0.5, -0.5),
    "speed": (0, 0.5, 0.5),
    "acceleration": (0, 1, 0),
    "mass": (1, 0, 0),
    "inertia": (1, 0, 2),
    "force": (1, 1, 0),
    "torque": (1, 1, 1),
    "impulse": (1, 0.5, 0.5),
    "stiffness": (1, 1, -1),
    "damping": (1, 0.5, -0.5),
    "energy": (1, 1, 1),
    "angle": (0, 0, 0),
    "angular_velocity": (0, 0.5, -0.5),
    "rotational_damping": (1, 0.5, 1.5),
}

#: The unit of each quantity kind of Table 3.1, written as :data:`PARAMETER_TABLE` does;
#: ``"-"`` for a pure number, a count, a flag or a text label.
UNIT: dict[str, str] = {
    "length": "L",
    "time": "g^-1/2 L^1/2",
    "frequency": "g^1/2 L^-1/2",
    "speed": "g^1/2 L^1/2",
    "acceleration": "g",
    "mass": "M",
    "force": "Mg",
    "torque": "MgL",
    "energy": "MgL",
    "impulse": "M g^1/2 L^1/2",
    "angular_impulse": "M g^1/2 L^3/2",
    "angle": "rad",
    "angular_velocity": "rad g^1/2 L^-1/2",
    "none": "-",
}

#: Units of the columns that result tables (``to_dataframe()``) share: the
#: trajectory's columns (``tslip.simulation.result.TRAJECTORY_COLUMNS``), the
#: touch-down state, stride times and outcomes.
COLUMN_UNITS: dict[str, str] = {
    **dict.fromkeys(("t", "stance_time", "flight_time", "stride_time", "t_fall"), UNIT["time"]),
    **dict.fromkeys(("x", "y", "l", "foot_x", "foot_y", "hip_x", "hip_y", "h", "x_p", "y_p",
                     "foot_clearance"), UNIT["length"]),
    **dict.fromkeys(("xd", "yd", "ld", "v"), UNIT["speed"]),
    **dict.fromkeys(("phi", "beta", "alpha", "delta", "alpha_r"), UNIT["angle"]),
    **dict.fromkeys(("phid", "betad", "alphad_ref"), UNIT["angular_velocity"]),
    **dict.fromkeys(("Fx", "Fy", "F_x", "F_y"), UNIT["force"]),
    **dict.fromkeys(("tau", "energy", "tau_c"), UNIT["torque"]),
    **dict.fromkeys(("step", "row", "stance", "status", "converged", "message", "method",
                     "residual", "reason", "kind", "stability"), UNIT["none"]),
}


def param_unit(name: str) -> str | None:
    """The unit of a parameter or controller gain by name, None if there is none.

    From :data:`PARAMETER_TABLE` and the controllers' field metadata (also as
    a dotted ``"controller.<gain>"`` name); ``omega_r_bar`` (eq. 2.18) is a
    ratio, ``"-"``.
    """
    from dataclasses import fields

    from .controllers import CONTROLLERS

    if name == "omega_r_bar":
        return "-"
    if name == "alpha_stop":
        return "rad"
    for row in PARAMETER_TABLE:
        if row.name == name:
            return row.unit
    gain = name.removeprefix("controller.")
    for cls in CONTROLLERS.values():
        for f in fields(cls):
            if f.name == gain and f.metadata.get("unit"):
                return str(f.metadata["unit"])
    return None


#: The Planar Elliptical Runner's approximate parameters in SI (Table 5.1).
ROBOT_SI: dict[str, float] = {"v0": 4.4, "m": 3.3, "r": 0.15, "g": 9.81, "l0": 0.5}


@dataclass(frozen=True, slots=True)
class Scaling:
    """Scales of Table 3.1: body mass ``M`` [kg], gravity ``g`` [m/s^2], length ``L`` [m]."""

    M: float
    g: float
    L: float

    def __post_init__(self) -> None:
        for name in ("M", "g", "L"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"Scaling.{name} must be in (0, inf), got {v!r}")

    def factor(self, dims: tuple[float, float, float] | str) -> float:
        """Scaling factor ``M^a g^b L^c`` for exponents or a quantity name."""
        if isinstance(dims, str):
            if dims not in QUANTITY_DIMS:
                raise ValueError(f"quantity must be one of {sorted(QUANTITY_DIMS)}, got {dims!r}")
            dims = QUANTITY_DIMS[dims]
        a, b, c = dims
        return self.M**a * self.g**b * self.L**c

    def to_dimensionless(self, value: float, dims: tuple[float, float, float] | str) -> float:
        """SI -> dimensionless (eq. 3.1)."""
        return value / self.factor(dims)

    def to_si(self, value: float, dims: tuple[float, float, float] | str) -> float:
        """Dimensionless -> SI."""
        return value * self.factor(dims)


#: Scaling of the Planar Elliptical Runner (Table 5.1): M = 3.3 kg, L = 0.5 m.
ROBOT_SCALING = Scaling(M=ROBOT_SI["m"], g=ROBOT_SI["g"], L=ROBOT_SI["l0"])

_CONTROLLER_DIMS: dict[str, tuple[float, float, float]] = {
    "Kp": QUANTITY_DIMS["torque"],
    "Kd": QUANTITY_DIMS["rotational_damping"],
    "phi_ref": QUANTITY_DIMS["angle"],
    "phid_ref": QUANTITY_DIMS["angular_velocity"],
    "alphad_ref": QUANTITY_DIMS["angular_velocity"],
    "tau_c": QUANTITY_DIMS["torque"],
    "c_h": QUANTITY_DIMS["rotational_damping"],
}


def to_si(params: Params, scaling: Scaling) -> dict[str, Any]:
    """All parameters of ``params`` in SI units (controller as a sub-dict)."""
    out: dict[str, Any] = {
        row.name: scaling.to_si(getattr(params, row.name), row.dims) for row in PARAMETER_TABLE
    }
    ctrl = params.controller.to_dict()
    out["controller"] = {
        k: (scaling.to_si(v, _CONTROLLER_DIMS[k]) if k in _CONTROLLER_DIMS else v)
        for k, v in ctrl.items()
    }
    out["leg_reset"] = params.leg_reset
    out["retraction"] = params.retraction
    if params.alpha_stop is not None:  # an angle: the same in SI
        out["alpha_stop"] = params.alpha_stop
    return out


def from_si(values: dict[str, Any], scaling: Scaling | None = None,
            base: Params | None = None) -> Params:
    """Dimensionless :class:`Params` from SI values.

    ``scaling`` defaults to ``M = values["m"], g = values["g"], L = values["l0"]``
    (so m, g and l0 become 1). Missing parameters come from ``base``.
    """
    values = dict(values)
    if scaling is None:
        try:
            scaling = Scaling(M=values["m"], g=values["g"], L=values["l0"])
        except KeyError as exc:
            raise ValueError(
                f"from_si needs m, g and l0 to define the scaling (missing {exc.args[0]!r}) "
                "or an explicit scaling"
            ) from None
    dims = {row.name: row.dims for row in PARAMETER_TABLE}
    changes: dict[str, Any] = {}
    for key, value in values.items():
        if key == "controller":
            ctrl = dict(value)
            changes["controller"] = {
                k: (scaling.to_dimensionless(v, _CONTROLLER_DIMS[k]) if k in _CONTROLLER_DIMS
                    else v) for k, v in ctrl.items()
            }
        elif key in ("leg_reset", "retraction", "alpha_stop"):
            changes[key] = value
        elif key in dims:
            changes[key] = scaling.to_dimensionless(float(value), dims[key])
        else:
            raise ValueError(f"unknown parameter {key!r}; allowed: {sorted(dims)}")
    return Params.from_dict(changes, base=base or Params())


def robot_params(base: Params | None = None) -> Params:
    """Table 5.1 robot values in dimensionless units on top of ``base``."""
    return from_si(ROBOT_SI, ROBOT_SCALING, base=base)
