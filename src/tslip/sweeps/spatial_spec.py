"""The base parameters of a 3-D study: the 3-D spring-mass runner and the 3-D TSLIP.

A study's TOML form names the model (or one of its presets, :mod:`tslip.spatial`)::

    name = "lateral"
    model = "tslip3d"              # or "slip3d"; or only preset = "slip3d" etc.
    analyses = ["floquet", "lateral_robustness"]
    [params]
    splay = 0.05                   # a TrunkParams field, or vx
    [[axis]]
    param = "r"
    values = [0.2, 0.3, 0.4]

``"slip3d"`` (:class:`~tslip.spatial.parameters.SpatialParams`, presets ``slip3d``
(the default) and ``slip3d-feedback``): the numeric fields ``m, k, l0, g, beta0,
gamma0, k_lat``, the choice ``heading`` and the gait's total ``energy`` [MgL]
(default :data:`SLIP3D_ENERGY`).

``"tslip3d"`` (:class:`~tslip.spatial.trunk_parameters.TrunkParams`, preset
``table2.1-3d``): its base is the Table 2.1 gait's
(:func:`tslip.spatial.lateral.table21_params`: the preset with the leg reset
angle ``alpha_r`` the planar gait search solved); the numeric fields but ``c_l``
and ``leg_thrust``, and the forward CoM speed at touch-down ``vx`` that the gait
holds [g^1/2 L^1/2] (default :data:`~tslip.spatial.lateral.TABLE21_VX`). The hip
is passive and the legs lossless: the multipliers set aside three trivial ones,
the energy's among them (:mod:`tslip.spatial.lateral`), which holds for the
conservative model only, so the leg damping, the thrust and a hip controller are
refused.

Importing this module registers both models in :data:`tslip.sweeps.spec.MODELS`
(:mod:`tslip.sweeps` imports it). What a point computes is in
:mod:`tslip.sweeps.spatial_point`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

from .._checks import check_number
from ..spatial.parameters import HEADINGS, SpatialParams
from ..spatial.parameters import preset as spatial_preset
from ..spatial.trunk_parameters import TrunkParams
from . import spec as _spec

__all__ = ["SpatialBase", "ANALYSES", "GAIT_PARAMS", "PRESETS", "SLIP3D_ENERGY", "read"]

#: The analyses of each model's studies (``floquet`` is always run).
ANALYSES: dict[str, tuple[str, ...]] = {"slip3d": ("floquet",),
                                        "tslip3d": ("floquet", "lateral_robustness")}
#: The presets of each model; the first is the default.
PRESETS: dict[str, tuple[str, ...]] = {"slip3d": ("slip3d", "slip3d-feedback"),
                                       "tslip3d": ("table2.1-3d",)}
#: The default energy of a ``slip3d`` study [MgL] (the fast gait of docs/analyses/spatial.md).
SLIP3D_ENERGY = 2.2
#: The gait's own parameter of each model: name, unit, description.
GAIT_PARAMS: dict[str, tuple[str, str, str]] = {
    "slip3d": ("energy", "MgL", "total energy of the symmetric gait"),
    "tslip3d": ("vx", "g^1/2 L^1/2", "forward CoM speed at touch-down, held by the gait"),
}
#: TrunkParams fields a ``tslip3d`` study cannot set (module docstring: not conservative).
_REFUSED = ("c_l", "leg_thrust")


def _numeric(cls: type) -> dict[str, dataclasses.Field[Any]]:
    """The numeric fields of a parameter class (those with bounds) a study can set."""
    return {f.name: f for f in dataclasses.fields(cls)
            if "lower" in f.metadata and f.name not in _REFUSED}


@dataclass(frozen=True)
class SpatialBase:
    """A 3-D study's base (a :class:`tslip.sweeps.spec.ModelBase`): the model's
    parameters and the gait's own parameter (``energy`` or ``vx``: :data:`GAIT_PARAMS`)."""

    model: str
    params: SpatialParams | TrunkParams
    gait: float

    @property
    def analyses(self) -> tuple[str, ...]:
        return ANALYSES[self.model]

    @property
    def gait_name(self) -> str:
        return GAIT_PARAMS[self.model][0]

    def names(self) -> list[str]:
        """The parameters a study can set or sweep."""
        return [*_numeric(type(self.params)), self.gait_name]

    def unit(self, name: str) -> str:
        """The unit of parameter ``name``."""
        if name == self.gait_name:
            return GAIT_PARAMS[self.model][1]
        return str(_numeric(type(self.params))[name].metadata["unit"])

    def _check_name(self, name: str) -> None:
        if name not in self.names():
            raise ValueError(f"unknown {self.model} parameter {name!r}; allowed: "
                             f"{self.names()}")

    def get(self, name: str) -> float:
        """The value of parameter ``name``."""
        self._check_name(name)
        return self.gait if name == self.gait_name else float(getattr(self.params, name))

    def set(self, name: str, value: float) -> SpatialBase:
        """A copy with parameter ``name`` at ``value`` (checked: one line naming its range)."""
        self._check_name(name)
        if name == self.gait_name:
            v = float(check_number(value, name, unit=self.unit(name), lower=0.0,
                                   lower_open=True))
            return dataclasses.replace(self, gait=v)
        md = _numeric(type(self.params))[name].metadata
        v = float(check_number(value, name, unit=md["unit"], lower=md["lower"],
                               upper=md.get("upper", math.inf),
                               lower_open=md.get("lower_open", False),
                               upper_open=md.get("upper_open", False)))
        changes: dict[str, Any] = {name: v}
        return dataclasses.replace(self, params=dataclasses.replace(self.params, **changes))

    def to_dict(self) -> dict[str, Any]:
        """Every value (the TOML form's ``[params]`` and the model): part of the cache key."""
        out: dict[str, Any] = {"model": self.model}
        for f in dataclasses.fields(self.params):
            v = getattr(self.params, f.name)
            out[f.name] = v.to_dict() if hasattr(v, "to_dict") else v
        out[self.gait_name] = self.gait
        return out

    def __post_init__(self) -> None:
        if self.model not in ANALYSES:
            raise ValueError(f"model must be one of {list(ANALYSES)}, got {self.model!r}")


def read(model: str, preset: str | None, overrides: dict[str, Any]) -> SpatialBase:
    """The base of a ``model`` study: its ``preset`` (None: the default) with ``overrides``
    (the ``[params]`` table); a one-line ``ValueError`` for a bad name or value."""
    allowed = PRESETS[model]
    name = allowed[0] if preset is None else preset
    if name not in allowed:
        raise ValueError(f"study preset must be one of {list(allowed)} for model {model!r}, "
                         f"got {name!r}")
    if model == "tslip3d":  # (the gait search's modules load only for a 3-D study)
        from ..spatial.lateral import TABLE21_VX, table21_params

        base = SpatialBase(model, table21_params(), TABLE21_VX)
    else:
        base = SpatialBase(model, spatial_preset(name), SLIP3D_ENERGY)
    overrides = dict(overrides)
    heading = overrides.pop("heading", None)
    for key, value in overrides.items():
        base = base.set(key, value)
    if heading is not None:  # last: k_lat must be 0 under "velocity" (SpatialParams)
        if model != "slip3d":
            raise ValueError(f"unknown {model} parameter 'heading'; allowed: {base.names()}")
        if heading not in HEADINGS:
            raise ValueError(f"heading must be one of {list(HEADINGS)}, got {heading!r}")
        changes: dict[str, Any] = {"heading": heading}
        base = dataclasses.replace(base, params=dataclasses.replace(base.params, **changes))
    return base


def _reader(model: str) -> Any:
    return lambda preset, overrides: read(model, preset, overrides)


for _name in ANALYSES:
    _spec.MODELS[_name] = _reader(_name)
    for _preset in PRESETS[_name]:
        _spec.MODEL_PRESETS[_preset] = _name
