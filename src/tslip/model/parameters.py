"""TSLIP model parameters: one table, one frozen dataclass, named presets.

All quantities are dimensionless in the units of thesis Table 3.1 (body mass M,
gravity g, rest leg length L). ``dims`` gives each quantity's exponents of
(M, g, L), used by :mod:`tslip.model.units` to convert to and from SI.

The defaults are thesis Table 2.1 (the passive model). ``alpha_r`` (leg reset
angle) and the controller references are *solved* for a periodic gait in the
thesis (Section 2.8); the defaults here are nominal starting values.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, NamedTuple, get_args

from .._checks import check_fields, check_number
from .._io import read_toml
from .controllers import (
    ConstantTorque,
    Controller,
    GlobalPD,
    LocalVelocity,
    Passive,
    controller_from_dict,
)

__all__ = [
    "ParameterInfo",
    "PARAMETER_TABLE",
    "Params",
    "preset",
    "presets",
    "LegReset",
    "Retraction",
    "LEG_RESETS",
    "RETRACTIONS",
    "read_params_file",
]

LegReset = Literal["local", "global"]
Retraction = Literal["liftoff", "apex"]
#: The allowed values of the two string fields (their ``Literal`` types' arguments).
LEG_RESETS: tuple[str, ...] = get_args(LegReset)
RETRACTIONS: tuple[str, ...] = get_args(Retraction)
_CHOICES: dict[str, tuple[str, ...]] = {"leg_reset": LEG_RESETS, "retraction": RETRACTIONS}


def _check_choice(name: str, value: object) -> None:
    """One-line ``ValueError`` naming the string field ``name`` and its allowed values."""
    allowed = _CHOICES[name]
    if not (isinstance(value, str) and value in allowed):
        raise ValueError(f"{name} must be {' or '.join(map(repr, allowed))}, got {value!r}")


class ParameterInfo(NamedTuple):
    """One row of :data:`PARAMETER_TABLE`."""

    name: str
    symbol: str
    unit: str
    dims: tuple[float, float, float]  # exponents of (M, g, L), Table 3.1
    default: float
    lower: float
    upper: float
    lower_open: bool
    upper_open: bool
    description: str
    source: str


_INF = math.inf
#: name, symbol, unit, dims (M, g, L), default, lower, upper, lower_open, upper_open,
#: description, source
PARAMETER_TABLE: tuple[ParameterInfo, ...] = tuple(
    ParameterInfo(*row)
    for row in (
        ("m", "m", "M", (1, 0, 0), 1.0, 0.0, _INF, True, True, "body mass", "Table 2.1"),
        ("J", "J", "ML^2", (1, 0, 2), 0.1, 0.0, _INF, True, True,
         "trunk rotational inertia about the CoM", "Table 2.1"),
        ("r", "r", "L", (0, 0, 1), 0.3, -_INF, _INF, True, True,
         "CoM offset below the hip (r > 0: hanging mass)", "Table 2.1"),
        ("k", "k", "MgL^-1", (1, 1, -1), 25.0, 0.0, _INF, True, True,
         "leg spring stiffness", "Table 2.1, eq. 2.1"),
        ("l0", "l_0", "L", (0, 0, 1), 1.0, 0.0, _INF, True, True,
         "rest leg length", "eq. 2.1"),
        ("g", "g", "g", (0, 1, 0), 1.0, 0.0, _INF, True, True,
         "gravitational acceleration", "Table 2.1"),
        ("v0", "v_0", "g^1/2 L^1/2", (0, 0.5, 0.5), 5.0, 0.0, _INF, True, True,
         "nominal CoM speed at touch-down of the periodic gait", "Table 2.1"),
        ("beta0", "beta_0", "rad", (0, 0, 0), 1.05, 0.0, math.pi / 2, True, True,
         "nominal touch-down leg angle of the periodic gait", "Table 2.1"),
        ("c_l", "c_l", "Mg^1/2 L^-1/2", (1, 0.5, -0.5), 0.0, 0.0, _INF, False, True,
         "leg damping coefficient", "eq. 2.1, Table 2.1"),
        ("omega_r", "omega_r", "rad g^1/2 L^-1/2", (0, 0.5, -0.5), 1.0, -_INF, _INF, True, True,
         "swing-leg retraction rate in flight (+: foot moves back)", "eq. 2.17, Table 2.1"),
        ("alpha_r", "alpha_r", "rad", (0, 0, 0), 1.0, -_INF, _INF, True, True,
         "leg reset angle at lift-off (local hip angle unless leg_reset='global')",
         "Section 2.3.2; solved in Section 2.8"),
        ("leg_exponent", "n", "-", (0, 0, 0), 1.0, 0.5, 3.0, False, False,
         "leg spring exponent: F_s = k l0 sgn(x) |x|^n, x = (l_rest - l) / l0",
         "beyond the thesis (Section 7.8); eq. 2.1 at n = 1"),
        ("leg_thrust", "d", "-", (0, 0, 0), 0.0, 0.0, 0.5, False, False,
         "leg thrust: rest length l0 (1 + d) from maximum compression to lift-off",
         "beyond the thesis (Section 7.8)"),
    )
)
#: Fields beyond the thesis, saved only when they differ from their default (so the
#: files and cache keys of the thesis's models stay as they were).
_OPTIONAL = ("leg_exponent", "leg_thrust")
_TABLE = {row.name: row for row in PARAMETER_TABLE}

#: The optional retraction stop angle (Section 7.5): not a row of :data:`PARAMETER_TABLE`,
#: whose fields are all numbers, because its default is ``None`` (no stop).
ALPHA_STOP_INFO: dict[str, Any] = {
    "symbol": "alpha_stop", "unit": "rad", "dims": (0, 0, 0), "range": "(0, pi)",
    "description": "retraction stop angle in flight, in the frame of alpha_r (None: no stop)",
    "source": "Section 7.5 (suggested)",
}


def _check_alpha_stop(value: object) -> float:
    """``alpha_stop`` checked: a number in (0, pi) [rad] (``None`` is handled by the caller)."""
    return float(check_number(value, "alpha_stop", unit="rad", lower=0.0, upper=math.pi,
                              lower_open=True, upper_open=True))


def _f(name: str) -> Any:
    row = _TABLE[name]
    return field(
        default=row.default,
        metadata={
            "symbol": row.symbol,
            "unit": row.unit,
            "dims": row.dims,
            "lower": row.lower,
            "upper": row.upper,
            "lower_open": row.lower_open,
            "upper_open": row.upper_open,
            "description": row.description,
            "source": row.source,
        },
    )


class _PackCache:
    """The slot where :func:`tslip.model._pack.packed_params` keeps a ``Params``' kernel vector.

    Not a dataclass field, so equality, hashing, ``repr``, ``dataclasses.replace``
    and pickling (a slotted dataclass pickles its fields only) never see it: a
    copy or an unpickled instance packs itself again on first use.
    """

    __slots__ = ("_packed",)


@dataclass(frozen=True, slots=True, kw_only=True)
class Params(_PackCache):
    """Parameters of the TSLIP model (thesis Table 2.1, Figure 2.1).

    Parameters
    ----------
    m, J, r, k, l0, g : float
        Mass [M], trunk inertia [ML^2], CoM offset below the hip [L], leg
        stiffness [MgL^-1], rest leg length [L], gravity [g].
    v0, beta0 : float
        Nominal touch-down speed [g^1/2 L^1/2] and leg angle [rad] of the gait.
    c_l : float
        Leg damping [M g^1/2 L^-1/2] (eq. 2.1).
    omega_r : float
        Swing-leg retraction rate [rad g^1/2 L^-1/2] (eq. 2.17, sign of
        docs/conventions.md: ``alpha(t) = alpha_r + omega_r (t - t_LO)``).
    alpha_r : float
        Leg angle set at lift-off [rad].
    leg_exponent : float
        Leg spring exponent ``n`` [-], 0.5 to 3 (1: eq. 2.1). With ``x = (l_rest -
        l) / l0``, ``F_s = k l0 sgn(x) |x|^n`` and ``V = k l0^2 |x|^(n+1) / (n+1)``
        (docs/model.md, "Leg spring and thrust").
    leg_thrust : float
        Leg thrust ``d`` [-], 0 to 0.5: in each stance the rest length steps from
        ``l0`` to ``l0 (1 + d)`` at maximum compression (the first ``ldot`` crossing
        from < 0 to >= 0), for the rest of that stance.
    controller : Controller
        Hip controller in stance, default :class:`Passive`.
    leg_reset : {"local", "global"}
        ``"local"`` (thesis): ``alpha_r`` and ``omega_r`` are relative to the
        trunk. ``"global"``: the classic SLIP reset, ``beta(t) = alpha_r +
        omega_r (t - t_LO)`` in the inertial frame (Section 7.6).
    retraction : {"liftoff", "apex"}
        When the retraction clock starts. ``"liftoff"`` (thesis, eq. 2.17):
        ``alpha(t) = alpha_r + omega_r (t - t_LO)``. ``"apex"`` (Seyfarth et
        al. 2003, the policy Section 2.5 cites): the leg is held at ``alpha_r``
        from lift-off to the flight apex ``t_apex`` (``ydot = 0``) and then
        retracts, ``alpha(t) = alpha_r + omega_r max(0, t - t_apex)``; a flight
        that leaves the ground moving down has no apex, and its clock starts
        at lift-off (``t_apex = t_LO``). docs/conventions.md, "Frames and angles".
    alpha_stop : float or None
        Retraction stop angle [rad] in (0, pi), in the frame of ``alpha_r``
        (Section 7.5): the swing leg retracts no further than
        ``max(alpha_r, alpha_stop)`` (``min`` for ``omega_r < 0``); ``None``
        (default) retracts without a stop. docs/conventions.md, "Frames and angles".

    Examples
    --------
    >>> import dataclasses
    >>> p = preset("table2.1")
    >>> dataclasses.replace(p, k=30.0).k
    30.0
    >>> round(p.omega_r_bar, 3)
    0.2
    """

    m: float = _f("m")
    J: float = _f("J")
    r: float = _f("r")
    k: float = _f("k")
    l0: float = _f("l0")
    g: float = _f("g")
    v0: float = _f("v0")
    beta0: float = _f("beta0")
    c_l: float = _f("c_l")
    omega_r: float = _f("omega_r")
    alpha_r: float = _f("alpha_r")
    leg_exponent: float = _f("leg_exponent")
    leg_thrust: float = _f("leg_thrust")
    controller: Controller = field(default_factory=Passive)
    leg_reset: LegReset = "local"
    retraction: Retraction = "liftoff"
    alpha_stop: float | None = field(default=None, metadata=ALPHA_STOP_INFO)

    def __post_init__(self) -> None:
        check_fields(self)  # every PARAMETER_TABLE row, by its field's metadata
        if self.alpha_stop is not None:
            object.__setattr__(self, "alpha_stop", _check_alpha_stop(self.alpha_stop))
        if not isinstance(self.controller, Controller):
            raise ValueError(
                "controller must be one of Passive, GlobalPD, LocalVelocity, ConstantTorque, "
                f"got {self.controller!r}"
            )
        for name in _CHOICES:
            _check_choice(name, getattr(self, name))

    # -- derived quantities (never stored) ---------------------------------
    @property
    def omega_r_bar(self) -> float:
        """Normalised retraction rate ``omega_r l0 / v0`` (eq. 2.18)."""
        return self.omega_r * self.l0 / self.v0

    def with_omega_r_bar(self, omega_r_bar: float) -> Params:
        """Copy with ``omega_r`` set from the normalised rate of eq. 2.18."""
        if not math.isfinite(omega_r_bar):
            raise ValueError(f"omega_r_bar [-] must be finite, got {omega_r_bar!r}")
        return dataclasses.replace(self, omega_r=omega_r_bar * self.v0 / self.l0)

    @property
    def bounce_time(self) -> float:
        """Spring-mass half period ``pi sqrt(m/k)`` (eq. 3.9) of the linear leg."""
        if self.leg_exponent != 1.0:
            raise ValueError("bounce_time of a leg_exponent != 1 spring depends on its "
                             "amplitude; use tslip.gait.bounce_time(params, leg_speed)")
        return math.pi * math.sqrt(self.m / self.k)

    # -- serialisation -------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """Plain ``dict`` (TOML / JSON friendly), controller as a sub-table."""
        out: dict[str, Any] = {row.name: getattr(self, row.name) for row in PARAMETER_TABLE
                               if row.name not in _OPTIONAL or getattr(self, row.name)
                               != row.default}
        out["leg_reset"] = self.leg_reset
        out["retraction"] = self.retraction
        if self.alpha_stop is not None:  # None (no stop) is omitted
            out["alpha_stop"] = self.alpha_stop
        out["controller"] = self.controller.to_dict()
        return out

    @classmethod
    def from_dict(cls, data: dict[str, Any], base: Params | None = None) -> Params:
        """Build from a dict of overrides on ``base`` (default: Table 2.1).

        Accepts the field names, ``omega_r_bar`` (eq. 2.18), ``preset`` (a
        base preset name), ``controller`` (a name or a table), ``leg_reset``,
        ``retraction`` and ``alpha_stop``. Values are
        typed strictly (see :func:`tslip._checks.check_number`); a ``preset``
        that differs from a given ``base``, or both ``omega_r`` and
        ``omega_r_bar``, is an error rather than a silent choice.
        """
        data = dict(data)
        if "preset" in data:
            name = data.pop("preset")
            if not isinstance(name, str):
                raise ValueError(f"preset must be one of {presets()}, got {name!r}")
            named = preset(name)
            if base is not None and base != named:
                raise ValueError(
                    f"preset {name!r} conflicts with the base parameters given; give one"
                )
            base = named
        base = base or cls()
        if "omega_r" in data and "omega_r_bar" in data:
            raise ValueError("give omega_r or omega_r_bar (eq. 2.18), not both")
        changes: dict[str, Any] = {}
        omega_r_bar = data.pop("omega_r_bar", None)
        if "controller" in data:
            changes["controller"] = controller_from_dict(data.pop("controller"))
        for name in _CHOICES:
            if name in data:
                _check_choice(name, data[name])
                changes[name] = data.pop(name)
        if "alpha_stop" in data:
            changes["alpha_stop"] = _check_alpha_stop(data.pop("alpha_stop"))
        for key, value in data.items():
            if key not in _TABLE:
                raise ValueError(
                    f"unknown parameter {key!r}; allowed: {sorted(_TABLE)} "
                    "plus omega_r_bar, controller, leg_reset, retraction, alpha_stop, preset"
                )
            row = _TABLE[key]
            changes[key] = check_number(
                value, key, unit=row.unit, lower=row.lower, upper=row.upper,
                lower_open=row.lower_open, upper_open=row.upper_open,
            )
        out = dataclasses.replace(base, **changes)
        if omega_r_bar is not None:
            out = out.with_omega_r_bar(check_number(omega_r_bar, "omega_r_bar", unit="-"))
        return out

    @classmethod
    def from_toml(cls, path: str | Path, base: Params | None = None) -> Params:
        """Read parameters from a TOML file (see :func:`read_params_file`, :meth:`from_dict`)."""
        data = read_params_file(path)
        try:
            return cls.from_dict(data, base=base)
        except ValueError as exc:
            raise ValueError(f"parameter file {str(path)!r}: {exc}") from None


def read_params_file(path: str | Path) -> dict[str, Any]:
    """The parameter entries of a TOML file: its ``[params]`` table or its top-level keys.

    A file with a ``[params]`` table may have nothing else at the top level
    except ``preset``: a stray top-level key (e.g. ``k = 30`` above
    ``[params]``) would otherwise be ignored, so it is an error.
    """
    data = read_toml(path, "parameter file")
    if "params" not in data:
        return data
    table = data["params"]
    if not isinstance(table, dict):
        raise ValueError(f"parameter file {str(path)!r}: params must be a table [params]")
    stray = sorted(set(data) - {"params", "preset"})
    if stray:
        raise ValueError(
            f"parameter file {str(path)!r}: top-level key {stray[0]!r} beside the [params] "
            "table; put it inside [params]"
        )
    out = dict(table)
    if "preset" in data:
        if "preset" in out and out["preset"] != data["preset"]:
            raise ValueError(
                f"parameter file {str(path)!r}: preset given twice ({data['preset']!r} and "
                f"{out['preset']!r} in [params])"
            )
        out["preset"] = data["preset"]
    return out


# -- presets ----------------------------------------------------------------

def _table21(**kw: Any) -> Params:
    return Params(**kw)


#: Seyfarth, Geyer, Guenther & Blickhan (2002), "A movement criterion for running",
#: J. Biomech. 35: the human-running SLIP used across the literature, in SI.
SLIP_HUMAN_SI = {"m": 80.0, "l0": 1.0, "g": 9.81, "k": 20000.0, "v0": 5.0,
                 "beta0": math.radians(68.0)}


def _slip(**kw: Any) -> Params:
    """The SLIP limit (Section 7.6): no trunk offset, no hip torque, no damping, global
    leg reset to the touch-down angle and no retraction (``J`` plays no part)."""
    kw.setdefault("alpha_r", kw["beta0"])
    return Params(r=0.0, c_l=0.0, omega_r=0.0, leg_reset="global", controller=Passive(), **kw)


def _slip_human() -> Params:
    from .units import Scaling  # units imports this module

    s = Scaling(M=SLIP_HUMAN_SI["m"], g=SLIP_HUMAN_SI["g"], L=SLIP_HUMAN_SI["l0"])
    return _slip(k=s.to_dimensionless(SLIP_HUMAN_SI["k"], _TABLE["k"].dims),
                 v0=s.to_dimensionless(SLIP_HUMAN_SI["v0"], _TABLE["v0"].dims),
                 beta0=SLIP_HUMAN_SI["beta0"])


_PRESETS: dict[str, tuple[str, Any]] = {
    "table2.1": ("Table 2.1 passive model", lambda: _table21()),
    "table2.1-global-pd": (
        "Table 2.1 with the global PD pitch controller (Kp 5, Kd 0.5)",
        lambda: _table21(controller=GlobalPD(Kp=5.0, Kd=0.5)),
    ),
    "table2.1-local-velocity": (
        "Table 2.1 with local hip-velocity control (Kd 0.5; alphad_ref solved)",
        lambda: _table21(controller=LocalVelocity(Kd=0.5, alphad_ref=5.0)),
    ),
    "table2.1-constant-torque": (
        "Table 2.1 with a constant hip torque and leg damping c_l 0.5 (tau_c solved)",
        lambda: _table21(c_l=0.5, controller=ConstantTorque(tau_c=0.0, c_h=0.0)),
    ),
    "table6.1": (
        "Table 6.1: fit to the Planar Elliptical Runner (local velocity control, leg damping)",
        lambda: Params(
            v0=1.90, J=0.10, m=1.0, r=0.30, k=8.0, beta0=0.93, omega_r=1.50, c_l=0.32,
            alpha_r=0.93, controller=LocalVelocity(Kd=0.40, alphad_ref=2.42),
        ),
    ),
    "slip": (
        "SLIP limit (r 0, passive, c_l 0, global reset, no retraction): k 25 (Table 2.1), "
        "v0 1.6, beta0 1.19 (68 deg; Seyfarth et al. 2002 human running, rounded)",
        lambda: _slip(k=25.0, v0=1.6, beta0=1.19),
    ),
    "slip-human": (
        "SLIP of Seyfarth et al. 2002: 80 kg, l0 1 m, k 20 kN/m, 5 m/s touch-down speed, "
        "68 deg; in Table 3.1 units (M 80 kg, g 9.81 m/s^2, L 1 m): k 25.48, v0 1.596, "
        "beta0 1.187 rad",
        _slip_human,
    ),
}


def presets() -> list[str]:
    """Names accepted by :func:`preset`."""
    return list(_PRESETS)


def preset_description(name: str) -> str:
    """One-line description of a preset."""
    preset(name)  # validates the name
    return _PRESETS[name][0]


def preset(name: str) -> Params:
    """Named parameter set: the thesis tables, and the SLIP limit (``slip``, ``slip-human``).

    Raises
    ------
    ValueError
        If ``name`` is not one of :func:`presets`.
    """
    key = name.strip().lower()
    if key not in _PRESETS:
        raise ValueError(f"preset must be one of {presets()}, got {name!r}")
    return _PRESETS[key][1]()
