"""A parameter study as data: base parameters, swept axes, analyses.

A study is a frozen :class:`StudySpec`. Its points are the grid of its axes
(one axis: a line; two axes: a grid, computed as one continuation line along
the last axis per value of the first). Specs come from code or from TOML::

    name = "mass-offset"           # the results' folder name
    preset = "table2.1"            # base parameters
    analyses = ["floquet", "robustness"]
    n_steps = 25                   # strides a disturbed run must survive
    tol = 1e-10                    # optional: the gait search's tolerance (default 1e-10)
    neutral_tol = 1e-6             # optional: Floquet's neutral band (default 1e-6)

    [params]                       # overrides of the preset
    k = 25.0
    controller = { type = "local_velocity", Kd = 0.5 }

    [[axis]]
    param = "r"                    # a Params field, omega_r_bar or controller.<gain>
    from = -1.0
    to = 1.0
    points = 50                    # or: values = [0.1, 0.2, 0.5]

``model`` (default ``"tslip"``, the planar model above) names another model: the 3-D
ones, ``"slip3d"`` and ``"tslip3d"`` (:mod:`tslip.sweeps.spatial_spec`), register
themselves in :data:`MODELS`; a spec naming one of their presets needs no ``model``.
Their base is a :class:`ModelBase` instead of :class:`Params`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from .._checks import check_fits, check_name, check_number
from .._io import read_toml
from ..gait.continuation import get_param, set_param
from ..model.parameters import Params, preset

__all__ = ["Axis", "StudySpec", "ANALYSES", "MODELS", "MODEL_PRESETS", "ModelBase",
           "name_list", "read_spec", "spec_header"]

#: Analyses a study can run at each point. ``floquet`` is always run.
ANALYSES = ("floquet", "robustness", "stride")
#: The tolerances a TOML study may set (kept in ``StudySpec.meta``, read by
#: :func:`tslip.sweeps.point.gait_tol` and ``floquet_tol``), with their allowed ranges.
TOLERANCES: dict[str, tuple[float, float]] = {"tol": (1e-14, 1e-4), "neutral_tol": (1e-12, 0.1)}
#: Memory one study point holds at least: its value and one result row (about 20 numbers
#: and their labels in a table).
_POINT_BYTES = 1000.0


class ModelBase(Protocol):
    """The base parameters of a study of a model other than the planar TSLIP.

    ``model`` names it, ``analyses`` are those its studies can run, ``get`` and
    ``set`` read and change one swept parameter (``set`` checks the value: a
    one-line ``ValueError`` naming it and its allowed range), ``to_dict`` is
    every value (the TOML form, and part of the cache key).
    """

    @property
    def model(self) -> str: ...
    @property
    def analyses(self) -> tuple[str, ...]: ...
    def get(self, name: str) -> float: ...
    def set(self, name: str, value: float) -> ModelBase: ...
    def to_dict(self) -> dict[str, Any]: ...


#: The models besides the planar ``"tslip"``: name -> ``reader(preset, overrides)``, the
#: base of a spec naming that model (``preset`` None: the model's default). Filled by the
#: models' modules when :mod:`tslip.sweeps` is imported (:mod:`.spatial_spec`).
MODELS: dict[str, Callable[[str | None, dict[str, Any]], ModelBase]] = {}
#: Presets of those models -> the model (a spec naming one needs no ``model`` key).
MODEL_PRESETS: dict[str, str] = {}


def _get(base: Params | ModelBase, name: str) -> float:
    return get_param(base, name) if isinstance(base, Params) else base.get(name)


def _set(base: Params | ModelBase, name: str, value: float) -> Any:
    return set_param(base, name, value) if isinstance(base, Params) else base.set(name, value)


def read_spec(path: str | Path, what: str) -> dict[str, Any]:
    """A spec's TOML file as data, its ``name`` defaulting to the file's stem."""
    data = read_toml(path, what)
    data.setdefault("name", Path(path).stem)
    return data


def spec_header(data: dict[str, Any], what: str, keys: set[str]) -> tuple[str, Params]:
    """The name and base parameters of a spec's TOML form (a study's, a design search's).

    ``keys``: the spec's own keys beside ``name``, ``description``, ``preset`` and
    ``params``; any other key is a one-line error naming the allowed ones. The base is
    ``preset`` (default ``table2.1``) with the ``[params]`` overrides.
    """
    name, overrides = _header(data, what, keys)
    return name, Params.from_dict(overrides, base=preset(data.get("preset", "table2.1")))


def _header(data: dict[str, Any], what: str, keys: set[str]) -> tuple[str, dict[str, Any]]:
    """:func:`spec_header`'s checks: the name and the ``[params]`` overrides."""
    allowed = {"name", "description", "preset", "params", *keys}
    unknown = set(data) - allowed
    if unknown:
        raise ValueError(f"unknown {what} key {sorted(unknown)[0]!r}; allowed: "
                         f"{sorted(allowed)}")
    for key in ("name", "preset", "description"):
        if key in data and not isinstance(data[key], str):
            raise ValueError(f"{what} {key} must be a string, got {data[key]!r}")
    name = str(data.get("name", what))
    overrides = data.get("params", {})
    if not isinstance(overrides, dict):
        raise ValueError(f"{what} [params] must be a table")
    if "preset" in overrides:
        raise ValueError(f"{what} {name}: give preset at the top level, not in [params]")
    return name, overrides


def _model(data: dict[str, Any]) -> str:
    """The model a study's TOML form names (popping ``model``): ``"tslip"`` by default,
    or the model of a preset in :data:`MODEL_PRESETS`."""
    allowed = ["tslip", *MODELS]
    model = data.pop("model", None)
    if model is not None and not (isinstance(model, str) and model in allowed):
        raise ValueError(f"study model must be one of {allowed}, got {model!r}")
    named = data.get("preset")
    if model is None:
        return MODEL_PRESETS.get(named, "tslip") if isinstance(named, str) else "tslip"
    return str(model)


def name_list(value: Any, field: str, allowed: Sequence[str]) -> tuple[str, ...]:
    """A TOML list of names (or one name) as a tuple; anything else is a one-line error."""
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ValueError(f"{field} must be a list of names from {list(allowed)}, "
                         f"got {value!r}")
    return tuple(value)


@dataclass(frozen=True, slots=True)
class Axis:
    """One swept parameter and its values (ascending)."""

    param: str
    values: tuple[float, ...]

    @classmethod
    def linspace(cls, param: str, start: float, stop: float, points: int) -> Axis:
        """``points`` evenly spaced values from ``start`` to ``stop``."""
        points = int(check_number(points, f"axis {param}: points", lower=1, integer=True))
        start = float(check_number(start, f"axis {param}: from"))
        stop = float(check_number(stop, f"axis {param}: to"))
        check_fits(points, _POINT_BYTES, f"axis {param}: points", "the study's results")
        if points > 1 and not start < stop:
            raise ValueError(f"axis {param}: empty range, from ({start:g}) must be below "
                             f"to ({stop:g})")
        return cls(param, tuple(float(v) for v in np.linspace(start, stop, points)))

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Axis:
        data = dict(data)
        param = data.pop("param", None)
        if not isinstance(param, str):
            raise ValueError("every [[axis]] needs a param name")
        if "values" in data:
            vals = data.pop("values")
            if data:
                raise ValueError(f"axis {param}: give values or from/to/points, not both")
            if not isinstance(vals, list) or not vals:
                raise ValueError(f"axis {param}: empty range, values must be a non-empty list")
            values = tuple(sorted(float(check_number(v, f"axis {param}: values entry"))
                                  for v in vals))
            return cls(param, values)
        unknown = set(data) - {"from", "to", "points"}
        if unknown:
            raise ValueError(f"axis {param}: unknown key {sorted(unknown)[0]!r}; use from, to, "
                             "points or values")
        try:
            return cls.linspace(param, data["from"], data["to"], data.get("points", 50))
        except KeyError as exc:
            raise ValueError(f"axis {param}: missing {exc.args[0]!r}") from None


@dataclass(frozen=True)
class StudySpec:
    """A parameter study.

    Parameters
    ----------
    name : str
        Identifier; also the folder name of its results: a letter or digit, then up to 63
        letters, digits, "_", "." or "-" (:data:`tslip._checks.NAME_RULE`).
    base : Params or ModelBase
        Parameters at every point except the swept ones: a :class:`Params` (the planar
        TSLIP) or another model's :class:`ModelBase` (:data:`MODELS`).
    axes : tuple of Axis
        One or two axes. The last is the continuation axis.
    analyses : tuple of str
        Subset of :data:`ANALYSES` (another model: of its ``base.analyses``).
    n_steps : int
        Strides a disturbed run must survive (robustness, Section 3.1.3).
    description : str
        One line for reports.
    """

    name: str
    base: Params | ModelBase
    axes: tuple[Axis, ...]
    analyses: tuple[str, ...] = ("floquet",)
    n_steps: int = 25
    description: str = ""
    meta: dict[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        check_name(self.name, "study name")
        if not 1 <= len(self.axes) <= 2:
            raise ValueError(f"study {self.name}: needs one or two axes, got {len(self.axes)}")
        names = [a.param for a in self.axes]
        if len(set(names)) != len(names):
            raise ValueError(f"study {self.name}: an axis is given twice: {names}")
        bad = set(self.analyses) - set(self.allowed_analyses)
        if bad:
            raise ValueError(f"study {self.name}: unknown analysis {sorted(bad)[0]!r}; "
                             f"allowed: {list(self.allowed_analyses)}")
        check_number(self.n_steps, f"study {self.name}: n_steps", lower=1, integer=True)
        check_fits(self.n_points, _POINT_BYTES, f"study {self.name}: points", "its results")
        for axis in self.axes:
            if not axis.values:
                raise ValueError(f"axis {axis.param}: empty range")
            _get(self.base, axis.param)  # unknown names raise here
        # every value must give valid parameters (e.g. no negative stiffness)
        for axis in self.axes:
            for v in (axis.values[0], axis.values[-1]):
                try:
                    _set(self.base, axis.param, v)
                except ValueError as exc:
                    raise ValueError(f"axis {axis.param}: {exc}") from None

    # -- points -------------------------------------------------------------
    @property
    def model(self) -> str:
        """``"tslip"`` (the planar model, a :class:`Params` base) or another model's name."""
        return "tslip" if isinstance(self.base, Params) else self.base.model

    @property
    def allowed_analyses(self) -> tuple[str, ...]:
        """The analyses a study of this model can run."""
        return ANALYSES if isinstance(self.base, Params) else self.base.analyses

    @property
    def shape(self) -> tuple[int, ...]:
        """Number of values per axis."""
        return tuple(len(a.values) for a in self.axes)

    @property
    def n_points(self) -> int:
        """Total number of points."""
        return int(np.prod(self.shape))

    def lines(self) -> list[tuple[dict[str, float], Axis]]:
        """Continuation lines: fixed outer assignments and the inner axis."""
        inner = self.axes[-1]
        if len(self.axes) == 1:
            return [({}, inner)]
        return [({self.axes[0].param: v}, inner) for v in self.axes[0].values]

    def params_at(self, assignment: dict[str, float]) -> Any:
        """Base parameters with the given axis values applied, in axis order (of the
        base's type: :class:`Params` for the planar model)."""
        p: Any = self.base
        for axis in self.axes:
            if axis.param in assignment:
                p = _set(p, axis.param, assignment[axis.param])
        return p

    def with_resolution(self, points: Sequence[int]) -> StudySpec:
        """Same study with ``points[i]`` evenly spaced values on axis ``i``."""
        axes = tuple(Axis.linspace(a.param, a.values[0], a.values[-1], n) if len(a.values) > 1
                     else a for a, n in zip(self.axes, points))
        return StudySpec(self.name, self.base, axes, self.analyses, self.n_steps,
                         self.description, dict(self.meta))

    # -- serialisation ----------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """Plain dict (the TOML form, with the full base parameters)."""
        model = {} if isinstance(self.base, Params) else {"model": self.base.model}
        return {
            "name": self.name, **model, "description": self.description,
            "analyses": list(self.analyses), "n_steps": self.n_steps,
            **{k: self.meta[k] for k in TOLERANCES if k in self.meta},
            "params": self.base.to_dict(),
            "axis": [{"param": a.param, "values": list(a.values)} for a in self.axes],
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> StudySpec:
        """Build from the TOML form (see the module docstring)."""
        data = dict(data)
        model = _model(data)
        base: Params | ModelBase
        if model == "tslip":
            name, base = spec_header(data, "study",
                                     {"axis", "analyses", "n_steps", *TOLERANCES})
        else:  # the tolerances are the planar gait search's and Floquet's
            name, overrides = _header(data, "study", {"axis", "analyses", "n_steps"})
            base = MODELS[model](data.get("preset"), overrides)
        meta = {k: check_number(data[k], f"study {name}: {k}", lower=lo, upper=hi)
                for k, (lo, hi) in TOLERANCES.items() if k in data}
        axes_data = data.get("axis")
        if not isinstance(axes_data, list) or not axes_data:
            raise ValueError(f"study {name}: needs at least one [[axis]]")
        axes = tuple(Axis.from_dict(a) for a in axes_data)
        analyses = name_list(data.get("analyses", ["floquet"]), f"study {name}: analyses",
                             ANALYSES if isinstance(base, Params) else base.analyses)
        return cls(name=name, base=base, axes=axes, analyses=analyses,
                   n_steps=data.get("n_steps", 25),
                   description=str(data.get("description", "")), meta=meta)

    @classmethod
    def from_toml(cls, path: str | Path) -> StudySpec:
        """Read a study from a TOML file."""
        return cls.from_dict(read_spec(path, "study file"))
