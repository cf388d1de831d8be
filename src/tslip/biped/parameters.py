"""Biped parameters and state: thesis Tables E.1-E.4 as frozen dataclasses.

All quantities are dimensionless in the units of thesis Table 3.1 (total mass
M, gravity g, leg length L). The defaults are the thesis values of Table E.1
(bodies), Table E.3 (ground contact) and Table E.4 (controller); the start
state :meth:`BipedState.thesis` is Table E.2.

Two switches, ``actuated`` and ``contact``, turn the controller (thigh and hip
actuators) and the ground off; they exist for the conservation tests.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from .._checks import check_fields

__all__ = [
    "BipedParameterInfo",
    "BIPED_PARAMETER_TABLE",
    "BipedParams",
    "BipedState",
    "STATE_FIELDS",
]


class BipedParameterInfo(NamedTuple):
    """One row of :data:`BIPED_PARAMETER_TABLE`."""

    name: str
    symbol: str
    unit: str
    default: float
    lower: float
    upper: float
    lower_open: bool
    upper_open: bool
    description: str
    source: str


_INF = math.inf
#: name, symbol, unit, default, lower, upper, lower_open, upper_open, description, source
BIPED_PARAMETER_TABLE: tuple[BipedParameterInfo, ...] = tuple(
    BipedParameterInfo(*row)
    for row in (
        ("m_b", "m_b", "M", 0.80, 0.0, _INF, True, True, "body (trunk) mass", "Table E.1"),
        ("J_b", "J_b", "ML^2", 0.10, 0.0, _INF, True, True, "body inertia", "Table E.1"),
        ("l_t0", "l_t", "L", 0.70, 0.0, _INF, True, True,
         "thigh length (stance reference l_t,0)", "Table E.1, eq. E.29"),
        ("m_t", "m_t", "M", 0.08, 0.0, _INF, True, True, "thigh mass", "Table E.1"),
        ("J_t", "J_t", "ML^2", 0.01, 0.0, _INF, True, True, "thigh inertia", "Table E.1"),
        ("l_s0", "l_s", "L", 0.30, 0.0, _INF, True, True,
         "shank length (spring rest length l_s,0)", "Table E.1, eq. E.28"),
        ("m_s", "m_s", "M", 0.01, 0.0, _INF, True, True, "shank mass", "Table E.1"),
        ("J_s", "J_s", "ML^2", 0.005, 0.0, _INF, True, True, "shank inertia", "Table E.1"),
        ("m_f", "m_f", "M", 0.01, 0.0, _INF, True, True, "foot point mass", "Table E.1"),
        ("r_1", "r_1", "L", 0.30, -_INF, _INF, True, True,
         "hip offset above the body CoM", "Table E.1, eq. E.5"),
        ("r_2", "r_2", "-", 0.40, 0.0, 1.0, False, False,
         "segment CoM as a fraction of the segment length", "Table E.1, eqs E.6-E.7"),
        ("g", "g", "g", 1.0, 0.0, _INF, True, True, "gravitational acceleration", "eq. E.15"),
        ("k_z", "k_z", "MgL^-1", 100.0, 0.0, _INF, False, True,
         "vertical ground stiffness", "Table E.3, eq. E.23"),
        ("c_z", "c_z", "Mg^1/2 L^-1/2", 10.0, 0.0, _INF, False, True,
         "vertical ground damping", "Table E.3, eq. E.23"),
        ("k_x", "k_x", "MgL^-1", 200.0, 0.0, _INF, False, True,
         "horizontal ground stiffness", "Table E.3, eq. E.24"),
        ("c_x", "c_x", "Mg^1/2 L^-1/2", 20.0, 0.0, _INF, False, True,
         "horizontal ground damping", "Table E.3, eq. E.24"),
        ("d", "d", "-", 0.58, 0.0, 1.0, True, True, "duty factor", "Table E.4, eq. E.29"),
        ("T", "T", "g^-1/2 L^1/2", 1.40, 0.0, _INF, True, True, "stride time",
         "Table E.4, eq. E.25"),
        ("rho0", "rho_0", "-", 0.08, 0.0, 1.0, False, True,
         "initial phase offset of the right leg", "Table E.4, eq. E.26"),
        ("Kp_t", "K_p,t", "MgL^-1", 500.0, 0.0, _INF, False, True,
         "thigh proportional gain", "Table E.4, eq. E.31"),
        ("Kd_t", "K_d,t", "Mg^1/2 L^-1/2", 20.0, 0.0, _INF, False, True,
         "thigh derivative gain", "Table E.4, eq. E.31"),
        ("l_ts", "l_t,s", "L", 0.40, 0.0, _INF, False, True,
         "thigh retraction in swing", "Table E.4, eq. E.29"),
        ("Kp_h", "K_p,theta", "MgL rad^-1", 0.50, 0.0, _INF, False, True,
         "hip proportional gain", "Table E.4, eq. E.34"),
        ("Kd_h", "K_d,theta", "Mg^1/2 L^3/2 rad^-1", 0.50, 0.0, _INF, False, True,
         "hip derivative gain", "Table E.4, eq. E.34"),
        ("theta_f", "theta_f", "rad", -0.54, -_INF, _INF, True, True,
         "hip angle forward reference", "Table E.4, eq. E.32"),
        ("theta_s", "theta_s", "rad", 1.44, -_INF, _INF, True, True,
         "hip angle sweep", "Table E.4, eq. E.32"),
        ("k", "k", "MgL^-1", 8.0, 0.0, _INF, False, True,
         "shank spring stiffness", "Table E.4, eq. E.28"),
        ("c_l", "c_l", "Mg^1/2 L^-1/2", 0.30, 0.0, _INF, False, True,
         "shank spring damping", "Table E.4, eq. E.28"),
    )
)
_TABLE = {row.name: row for row in BIPED_PARAMETER_TABLE}


def _f(name: str) -> Any:
    row = _TABLE[name]
    return field(
        default=row.default,
        metadata={"symbol": row.symbol, "unit": row.unit, "lower": row.lower,
                  "upper": row.upper, "lower_open": row.lower_open,
                  "upper_open": row.upper_open, "description": row.description,
                  "source": row.source},
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class BipedParams:
    """Parameters of the two-legged running model (thesis Appendix E).

    Parameters
    ----------
    m_b, J_b : float
        Body mass [M] and inertia [ML^2] (Table E.1).
    l_t0, m_t, J_t : float
        Thigh length [L] (the stance reference ``l_t,0`` of eq. E.29), mass
        [M] and inertia [ML^2].
    l_s0, m_s, J_s : float
        Shank rest length [L] (``l_s,0`` of eq. E.28), mass and inertia.
    m_f : float
        Foot point mass [M].
    r_1 : float
        Hip offset above the body CoM along the body axis [L] (eq. E.5).
    r_2 : float
        Segment CoM as a fraction of the segment length from its top [-].
    g : float
        Gravity [g].
    k_z, c_z, k_x, c_x : float
        Ground spring-damper, vertical and horizontal (Table E.3).
    d, T, rho0 : float
        Duty factor [-], stride time [g^-1/2 L^1/2], right-leg phase offset
        [-] (eqs E.25-E.27).
    Kp_t, Kd_t, l_ts : float
        Thigh PD gains and swing retraction [L] (eqs E.29-E.31).
    Kp_h, Kd_h, theta_f, theta_s : float
        Hip PD gains, forward reference [rad] and sweep [rad] (eqs E.32-E.34).
    k, c_l : float
        Shank spring stiffness and damping (eq. E.28).
    actuated : bool
        Thigh and hip actuators on (eqs E.31, E.34). Off: ``F_t = tau = 0``.
    contact : bool
        Ground contact on (eqs E.23-E.24).

    Raises
    ------
    ValueError
        If a value is outside its range, or the swing thigh length
        ``l_t0 - l_ts`` is not positive.

    Examples
    --------
    >>> p = BipedParams()
    >>> p.total_mass
    1.0
    """

    m_b: float = _f("m_b")
    J_b: float = _f("J_b")
    l_t0: float = _f("l_t0")
    m_t: float = _f("m_t")
    J_t: float = _f("J_t")
    l_s0: float = _f("l_s0")
    m_s: float = _f("m_s")
    J_s: float = _f("J_s")
    m_f: float = _f("m_f")
    r_1: float = _f("r_1")
    r_2: float = _f("r_2")
    g: float = _f("g")
    k_z: float = _f("k_z")
    c_z: float = _f("c_z")
    k_x: float = _f("k_x")
    c_x: float = _f("c_x")
    d: float = _f("d")
    T: float = _f("T")
    rho0: float = _f("rho0")
    Kp_t: float = _f("Kp_t")
    Kd_t: float = _f("Kd_t")
    l_ts: float = _f("l_ts")
    Kp_h: float = _f("Kp_h")
    Kd_h: float = _f("Kd_h")
    theta_f: float = _f("theta_f")
    theta_s: float = _f("theta_s")
    k: float = _f("k")
    c_l: float = _f("c_l")
    actuated: bool = field(default=True, metadata={"unit": "-", "description": "actuators on"})
    contact: bool = field(default=True, metadata={"unit": "-", "description": "ground on"})

    def __post_init__(self) -> None:
        check_fields(self)  # the table's ranges, as for the TSLIP's Params
        for name in ("actuated", "contact"):
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise ValueError(f"{name} must be True or False, got {getattr(self, name)!r}")
        if not self.l_ts < self.l_t0:
            raise ValueError(
                f"l_ts [L] must be below l_t0 = {self.l_t0:g} (positive swing thigh length), "
                f"got {self.l_ts!r}"
            )

    @property
    def total_mass(self) -> float:
        """Total mass ``m_b + 2 (m_t + m_s + m_f)`` [M]."""
        return round(self.m_b + 2.0 * (self.m_t + self.m_s + self.m_f), 12)

    @property
    def leg_length(self) -> float:
        """Rest leg length ``l_t0 + l_s0`` [L]."""
        return self.l_t0 + self.l_s0

    def replace(self, **changes: Any) -> BipedParams:
        """Return a validated copy with ``changes`` applied."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Plain ``{name: value}`` for JSON and TOML."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}

    @classmethod
    def from_dict(cls, data: dict[str, Any], base: BipedParams | None = None) -> BipedParams:
        """Build from ``{name: value}``; unknown names raise ``ValueError``."""
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(data) - names)
        if unknown:
            raise ValueError(f"unknown biped parameter(s) {unknown}; known: {sorted(names)}")
        return dataclasses.replace(base or cls(), **data)


#: State field names in the order of eq. E.9, then their rates.
Q_FIELDS: tuple[str, ...] = (
    "x_b", "z_b", "theta_b", "l_tR", "l_sR", "theta_hR", "l_tL", "l_sL", "theta_hL",
)
STATE_FIELDS: tuple[str, ...] = Q_FIELDS + tuple(name + "_d" for name in Q_FIELDS)


@dataclass(frozen=True, slots=True)
class BipedState:
    """Generalised coordinates ``q`` (eq. E.9) and rates ``qd``.

    Parameters
    ----------
    q : ndarray, shape (9,)
        ``x_b, z_b [L], theta_b [rad], l_tR, l_sR [L], theta_hR [rad], l_tL,
        l_sL [L], theta_hL [rad]``.
    qd : ndarray, shape (9,)
        Their time derivatives [g^1/2 L^1/2 or rad g^1/2 L^-1/2].
    """

    q: NDArray[np.float64]
    qd: NDArray[np.float64]

    def __post_init__(self) -> None:
        for name in ("q", "qd"):
            a = np.array(getattr(self, name), dtype=np.float64)
            if a.shape != (9,):
                raise ValueError(f"{name} must have shape (9,), got {a.shape}")
            if not np.all(np.isfinite(a)):
                raise ValueError(f"{name} must be finite, got {a.tolist()}")
            a.flags.writeable = False
            object.__setattr__(self, name, a)

    def to_array(self) -> NDArray[np.float64]:
        """The 18-vector ``(q, qd)``."""
        return np.concatenate([self.q, self.qd])

    @classmethod
    def from_array(cls, y: Any) -> BipedState:
        """From an 18-vector ``(q, qd)``."""
        y = np.asarray(y, dtype=np.float64)
        if y.shape != (18,):
            raise ValueError(f"biped state must have shape (18,), got {y.shape}")
        return cls(y[:9], y[9:])

    @classmethod
    def thesis(cls) -> BipedState:
        """Initial conditions of thesis Table E.2 (right foot just touched down)."""
        return cls(
            np.array([0.000, 0.514, -0.290, 0.700, 0.300, -0.351, 0.370, 0.300, 0.690]),
            np.array([1.898, -0.079, 0.202, -0.012, -0.886, 1.6282, -0.997, -0.136, -2.9350]),
        )

    def as_dict(self) -> dict[str, float]:
        """``{field: value}`` in :data:`STATE_FIELDS` order."""
        return dict(zip(STATE_FIELDS, self.to_array().tolist(), strict=True))
