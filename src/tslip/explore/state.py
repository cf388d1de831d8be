"""The explorer's state: its controls (unit, valid range, slider span) and the URL query.

The state is a preset plus the values of the controls. The URL query holds it
(``?preset=table6.1&k=9&controller=local_velocity&Kd=0.4``) and is parsed as
data: every number goes through :meth:`tslip.Params.from_dict` (or the
controller's own fields), the validators of ``Params``, one entry at a time, so
a bad entry is reported by name and the others still apply.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any
from urllib.parse import urlencode

from ..model.controllers import CONTROLLERS
from ..model.parameters import (
    ALPHA_STOP_INFO,
    PARAMETER_TABLE,
    RETRACTIONS,
    Params,
    preset,
    presets,
)

__all__ = ["Control", "CONTROLS", "GAINS", "STOP", "DISTURBANCES", "FRACTION", "ExploreState",
           "check_fraction", "parse_query", "control_for"]

#: The disturbance kinds of the runner strip (thesis Section 3.1.3).
DISTURBANCES: tuple[str, ...] = ("step_down", "push", "pitch_rate")


@dataclass(frozen=True, slots=True)
class Control:
    """One numeric control: its field, unit, valid range (the validators') and slider span."""

    name: str
    unit: str
    lower: float
    upper: float
    lower_open: bool
    upper_open: bool
    start: float
    end: float
    step: float
    description: str

    @property
    def range_text(self) -> str:
        """The valid range as an interval, e.g. ``(0, inf)``."""
        lo = "(" if self.lower_open else "["
        hi = ")" if self.upper_open else "]"
        return f"{lo}{self.lower:g}, {self.upper:g}{hi}"

    @property
    def title(self) -> str:
        """Label of the control: name, unit and valid range."""
        return f"{self.name} [{self.unit}], valid {self.range_text}"

    def span(self, value: float) -> tuple[float, float]:
        """The slider's span, widened to hold ``value`` (kept inside the valid range)."""
        return min(self.start, value), max(self.end, value)


#: Slider spans: the region where the thesis's gaits live (Tables 2.1, 6.1; Chapter 4).
_SPANS: dict[str, tuple[float, float, float]] = {
    "k": (2.0, 60.0, 0.5), "beta0": (0.6, 1.45, 0.01), "r": (-1.0, 1.0, 0.01),
    "v0": (0.5, 10.0, 0.05), "c_l": (0.0, 2.0, 0.01), "omega_r": (-5.0, 10.0, 0.05),
    "Kp": (0.0, 20.0, 0.1), "Kd": (0.0, 5.0, 0.01), "phi_ref": (-0.5, 0.5, 0.01),
    "phid_ref": (-2.0, 2.0, 0.05), "c_h": (0.0, 2.0, 0.01),
    "leg_exponent": (0.5, 3.0, 0.05), "leg_thrust": (0.0, 0.5, 0.01),
}


def _param_control(name: str) -> Control:
    row = next(r for r in PARAMETER_TABLE if r.name == name)
    start, end, step = _SPANS[name]
    return Control(name, row.unit, row.lower, row.upper, row.lower_open, row.upper_open,
                   start, end, step, row.description)


def _gain_control(name: str) -> Control:
    for cls in CONTROLLERS.values():
        for f in dataclasses.fields(cls):
            if f.name == name:
                md = f.metadata
                start, end, step = _SPANS[name]
                return Control(name, md["unit"], md.get("lower", -math.inf), math.inf, False,
                               True, start, end, step, md["description"])
    raise KeyError(name)


#: The model's controls (Params fields), in the page's order.
CONTROLS: tuple[Control, ...] = tuple(
    _param_control(n) for n in ("k", "beta0", "r", "v0", "c_l", "omega_r", "leg_exponent",
                                "leg_thrust"))
#: Each controller's gains the user sets (``alphad_ref`` and ``tau_c`` are solved with the
#: gait, Section 2.8, as is ``alpha_r``).
GAINS: dict[str, tuple[Control, ...]] = {
    "passive": (),
    "global_pd": tuple(_gain_control(n) for n in ("Kp", "Kd", "phi_ref", "phid_ref")),
    "local_velocity": (_gain_control("Kd"),),
    "constant_torque": (_gain_control("c_h"),),
}


#: The retraction stop angle ``alpha_stop`` (Section 7.5): a slider shown while the page's
#: "retraction stop" is on; off is ``None``, no stop, which no slider value can hold.
STOP = Control("alpha_stop", ALPHA_STOP_INFO["unit"], 0.0, math.pi, True, True, 0.8, 2.2,
               0.01, ALPHA_STOP_INFO["description"])


def control_for(name: str) -> Control:
    """The :class:`Control` of a parameter or gain name."""
    for c in (*CONTROLS, STOP, *(g for gains in GAINS.values() for g in gains)):
        if c.name == name:
            return c
    raise KeyError(name)


@dataclass(frozen=True, slots=True)
class ExploreState:
    """What the page shows: the preset, the parameters, and the runner's disturbance."""

    preset: str
    params: Params
    disturbance: str = "push"
    fraction: float = 0.5

    def __post_init__(self) -> None:
        check_fraction(self.fraction)

    def query(self) -> str:
        """The URL query of this state (only what differs from nothing: every control)."""
        p = self.params
        out: dict[str, Any] = {"preset": self.preset}
        out.update({c.name: repr(float(getattr(p, c.name))) for c in CONTROLS})
        out["retraction"] = p.retraction
        if p.alpha_stop is not None:  # absent: no stop
            out["alpha_stop"] = repr(float(p.alpha_stop))
        out["controller"] = p.controller.name
        for c in GAINS[p.controller.name]:
            out[c.name] = repr(float(getattr(p.controller, c.name)))
        out["disturbance"] = self.disturbance
        out["fraction"] = repr(float(self.fraction))
        return urlencode(out)


#: The disturbance's magnitude as a fraction of its limit: [0, 2] (a negative fraction
#: would flip the disturbance's direction, the limit's sign being the direction searched).
FRACTION = (0.0, 2.0)


def check_fraction(value: float) -> float:
    """``value`` if it is a fraction in :data:`FRACTION`, else a ValueError naming it."""
    lo, hi = FRACTION
    if not lo <= value <= hi:  # also refuses NaN
        raise ValueError(f"fraction [-] must be in [{lo:g}, {hi:g}], got {value!r}")
    return float(value)


def _number(text: str, name: str) -> float:
    """Text to a float; non-numeric text is an error naming the field (range checks follow)."""
    try:
        return float(text)
    except ValueError:
        raise ValueError(f"{name} must be a number, got {text!r}") from None


def parse_query(args: Mapping[str, str]) -> tuple[ExploreState, list[str]]:
    """The state a URL query describes, and one message per entry refused.

    A refused entry keeps the preset's value; unknown keys are refused too.
    """
    errors: list[str] = []
    name = args.get("preset", "table2.1")
    try:
        params = preset(name)
    except ValueError as exc:
        errors.append(str(exc))
        name, params = "table2.1", preset("table2.1")
    if "controller" in args:
        kind = args["controller"]
        if kind != params.controller.name:
            try:
                params = Params.from_dict({"controller": kind}, base=params)
            except ValueError as exc:
                errors.append(str(exc))
    for c in CONTROLS:
        if c.name in args:
            try:
                params = Params.from_dict({c.name: _number(args[c.name], c.name)}, base=params)
            except ValueError as exc:
                errors.append(str(exc))
    if "retraction" in args:
        try:
            params = Params.from_dict({"retraction": args["retraction"]}, base=params)
        except ValueError as exc:
            errors.append(str(exc))
    if "alpha_stop" in args:  # a number, or "none" (no stop)
        try:
            text = args["alpha_stop"]
            params = (dataclasses.replace(params, alpha_stop=None) if text == "none" else
                      Params.from_dict({"alpha_stop": _number(text, "alpha_stop")},
                                       base=params))
        except ValueError as exc:
            errors.append(str(exc))
    for c in GAINS[params.controller.name]:
        if c.name in args:
            try:
                ctrl = {**params.controller.to_dict(), c.name: _number(args[c.name], c.name)}
                params = Params.from_dict({"controller": ctrl}, base=params)
            except ValueError as exc:
                errors.append(str(exc))
    kind = args.get("disturbance", "push")
    if kind not in DISTURBANCES:
        errors.append(f"disturbance must be one of {list(DISTURBANCES)}, got {kind!r}")
        kind = "push"
    fraction = 0.5
    if "fraction" in args:
        try:
            fraction = check_fraction(_number(args["fraction"], "fraction"))
        except ValueError as exc:
            errors.append(str(exc))
    known = {"preset", "controller", "retraction", "alpha_stop", "disturbance", "fraction",
             *(c.name for c in CONTROLS), *(c.name for g in GAINS.values() for c in g)}
    errors.extend(f"unknown URL entry {k!r}; allowed: {sorted(known)}"
                  for k in sorted(set(args) - known))
    return ExploreState(name, params, kind, fraction), errors


#: The presets the page offers (all of :func:`tslip.presets`).
PRESETS: tuple[str, ...] = tuple(presets())
#: The retraction clocks (:data:`tslip.model.parameters.RETRACTIONS`).
CLOCKS: tuple[str, ...] = RETRACTIONS
