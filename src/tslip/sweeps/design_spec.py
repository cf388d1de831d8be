"""A design search as data: base parameters, free variables with bounds, objectives.

A robot designer fixes what the robot is (its speed, mass, leg length: the
base parameters) and asks which values of the free parameters give the best
trade-off between objectives such as robustness and leg load. A design search
is a frozen :class:`DesignSpec`; :func:`tslip.design` finds its Pareto front
(:mod:`tslip.sweeps.pareto`). Specs come from code or from TOML::

    name = "robot-leg"             # the results' folder name
    preset = "table2.1"            # base parameters
    objectives = ["step_down", "peak_leg_force"]
    budget = 2000                  # evaluations (candidate designs)
    population = 40                # NSGA-II population per generation
    seed = 1                       # the search is reproducible from its seed

    [params]                       # fixed values, overrides of the preset
    v0 = 5.0

    [[variable]]
    param = "k"                    # a Params field, omega_r_bar or controller.<gain>
    from = 15.0
    to = 30.0

Variables use the names of :func:`tslip.continue_gait` and the studies;
variables the gait search solves for (``alpha_r``, ``controller.alphad_ref``,
``controller.tau_c``) are refused.

Objectives and their senses (:data:`OBJECTIVES`): the magnitudes of the
step-down, push and pitch-rate limits (:func:`tslip.robustness`, the thesis's
25 strides) are maximised; the largest non-trivial Floquet multiplier, the
stance time, the peak leg force and the energy per stride (the hip's net work,
:func:`tslip.gait.stride_work`; zero for a passive gait) are minimised.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .._checks import check_name, check_number
from ..gait.continuation import get_param, set_param
from ..model.parameters import Params
from .spec import name_list, read_spec, spec_header

__all__ = ["OBJECTIVES", "DesignSpec", "Variable"]

#: Objective -> (sense, unit, description). Sense +1: maximise the magnitude; -1: minimise.
OBJECTIVES: dict[str, tuple[int, str, str]] = {
    "step_down": (+1, "L", "step-down limit |dh| (robustness, 25 strides)"),
    "push": (+1, "g^1/2 L^1/2", "backward push limit |dxd| (robustness, 25 strides)"),
    "pitch_rate": (+1, "rad g^1/2 L^-1/2", "pitch-rate limit |dphid| (robustness, 25 strides)"),
    "max_multiplier": (-1, "-", "largest non-trivial Floquet multiplier |lambda|"),
    "stance_time": (-1, "g^-1/2 L^1/2", "stance time t_s"),
    "peak_leg_force": (-1, "m g", "peak axial leg force F_l = F_s - c_l ld over stance"),
    "energy_per_stride": (-1, "M g L", "hip's net work per stride (tslip.gait.stride_work)"),
}
#: Limits of the search's settings (a search of more evaluations is a study of its own).
MAX_BUDGET = 1_000_000
MAX_POPULATION = 10_000


@dataclass(frozen=True, slots=True)
class Variable:
    """One free parameter and its bounds (``lower < upper``, both valid values)."""

    param: str
    lower: float
    upper: float

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Variable:
        data = dict(data)
        param = data.pop("param", None)
        if not isinstance(param, str):
            raise ValueError("every [[variable]] needs a param name")
        unknown = set(data) - {"from", "to"}
        if unknown:
            raise ValueError(f"variable {param}: unknown key {sorted(unknown)[0]!r}; use from, to")
        try:
            lo = float(check_number(data["from"], f"variable {param}: from"))
            hi = float(check_number(data["to"], f"variable {param}: to"))
        except KeyError as exc:
            raise ValueError(f"variable {param}: missing {exc.args[0]!r}") from None
        return cls(param, lo, hi)


@dataclass(frozen=True)
class DesignSpec:
    """A multi-objective design search (see the module docstring).

    Parameters
    ----------
    name : str
        Identifier and folder name of the results (:data:`tslip._checks.NAME_RULE`).
    base : Params
        The fixed parameters (the robot as given).
    variables : tuple of Variable
        One to eight free parameters with their bounds.
    objectives : tuple of str
        One to four names of :data:`OBJECTIVES`.
    budget : int
        Candidate designs evaluated (whole generations: rounded up to ``population``).
    population : int
        Candidates per generation (NSGA-II), at least 4.
    seed : int
        Seed of the search (0 <= seed < 2**31); the same spec and seed give the same designs.
    n_steps : int
        Strides a disturbed run must survive (robustness, Section 3.1.3; thesis: 25).
    description : str
        One line for reports.
    """

    name: str
    base: Params
    variables: tuple[Variable, ...]
    objectives: tuple[str, ...]
    budget: int = 2000
    population: int = 40
    seed: int = 1
    n_steps: int = 25
    description: str = ""

    def __post_init__(self) -> None:
        check_name(self.name, "design name")
        if not 1 <= len(self.variables) <= 8:
            raise ValueError(f"design {self.name}: needs 1 to 8 variables, "
                             f"got {len(self.variables)}")
        names = [v.param for v in self.variables]
        if len(set(names)) != len(names):
            raise ValueError(f"design {self.name}: a variable is given twice: {names}")
        if not 1 <= len(self.objectives) <= 4:
            raise ValueError(f"design {self.name}: needs 1 to 4 objectives, "
                             f"got {len(self.objectives)}")
        for o in self.objectives:
            if o not in OBJECTIVES:
                raise ValueError(f"design {self.name}: unknown objective {o!r}; "
                                 f"allowed: {list(OBJECTIVES)}")
        if len(set(self.objectives)) != len(self.objectives):
            raise ValueError(f"design {self.name}: an objective is given twice")
        check_number(self.budget, f"design {self.name}: budget", lower=1, upper=MAX_BUDGET,
                     integer=True)
        check_number(self.population, f"design {self.name}: population", lower=4,
                     upper=MAX_POPULATION, integer=True)
        check_number(self.seed, f"design {self.name}: seed", lower=0, upper=2**31 - 1,
                     integer=True)
        check_number(self.n_steps, f"design {self.name}: n_steps", lower=1, integer=True)
        for v in self.variables:
            get_param(self.base, v.param)  # unknown and solved-for names raise here
            if not v.lower < v.upper:
                raise ValueError(f"variable {v.param}: empty range, from ({v.lower:g}) must be "
                                 f"below to ({v.upper:g})")
            for x in (v.lower, v.upper):  # both bounds must give valid parameters
                try:
                    set_param(self.base, v.param, x)
                except ValueError as exc:
                    raise ValueError(f"variable {v.param}: {exc}") from None

    @property
    def names(self) -> tuple[str, ...]:
        """The variables' names, in order."""
        return tuple(v.param for v in self.variables)

    @property
    def generations(self) -> int:
        """Generations the budget pays for (the last one whole)."""
        return -(-int(self.budget) // int(self.population))

    def params_at(self, values: dict[str, float]) -> Params:
        """The base parameters with the variables set to ``values``."""
        p = self.base
        for name in self.names:
            p = set_param(p, name, values[name])
        return p

    # -- serialisation ----------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """Plain dict (the TOML form, with the full base parameters)."""
        return {
            "name": self.name, "description": self.description,
            "objectives": list(self.objectives), "budget": self.budget,
            "population": self.population, "seed": self.seed, "n_steps": self.n_steps,
            "params": self.base.to_dict(),
            "variable": [{"param": v.param, "from": v.lower, "to": v.upper}
                         for v in self.variables],
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> DesignSpec:
        """Build from the TOML form (see the module docstring)."""
        data = dict(data)
        name, base = spec_header(data, "design", {"variable", "objectives", "budget",
                                                  "population", "seed", "n_steps"})
        var_data = data.get("variable")
        if not isinstance(var_data, list) or not var_data:
            raise ValueError(f"design {name}: needs at least one [[variable]]")
        objectives = name_list(data.get("objectives"), f"design {name}: objectives",
                               list(OBJECTIVES))
        return cls(name=name, base=base,
                   variables=tuple(Variable.from_dict(v) for v in var_data),
                   objectives=objectives, budget=data.get("budget", 2000),
                   population=data.get("population", 40), seed=data.get("seed", 1),
                   n_steps=data.get("n_steps", 25),
                   description=str(data.get("description", "")))

    @classmethod
    def from_toml(cls, path: str | Path) -> DesignSpec:
        """Read a design search from a TOML file."""
        return cls.from_dict(read_spec(path, "design file"))
