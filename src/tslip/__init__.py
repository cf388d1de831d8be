"""tslip: self-stable planar running with the spring-mass model with a trunk (TSLIP).

Implements the model of M. J. van den Broek, "Fast Self-Stable Planar Bipedal
Running" (TU Delft / IHMC, 2019), in the dimensionless units of its Table 3.1.

The public names below are imported on first use (PEP 562), so ``import
tslip`` loads neither numba's kernels nor pandas or scipy.
"""

__version__ = "0.3.0"

from typing import TYPE_CHECKING  # noqa: E402

if TYPE_CHECKING:  # the same names, for type checkers and tslip._codehash
    # mypy: ``robustness`` names both a function and its submodule of tslip.gait
    from ._results import load
    from .gait import (  # type: ignore[no-redef]
        ApexState,
        Branch,
        Floquet,
        Gait,
        all_gaits,
        apex_map,
        apex_map_batch,
        continue_gait,
        find_gait,
        floquet,
        robustness,
        robustness_report,
        stable_region,
    )
    from .model import (
        ConstantTorque,
        GlobalPD,
        LocalVelocity,
        Params,
        Passive,
        Terrain,
        TouchdownState,
        preset,
        presets,
    )
    from .simulation import (
        Disturbance,
        IntegratorOptions,
        Status,
        StepResult,
        Trajectory,
        run_batch,
        simulate,
        step,
        step_batch,
        step_jacobian,
        step_map,
    )
    from .sweeps.design_spec import DesignSpec
    from .sweeps.pareto import design

#: The subpackage (or private module) each public name is imported from.
_SUBPACKAGE = {
    **dict.fromkeys(("ConstantTorque", "GlobalPD", "LocalVelocity", "Params", "Passive",
                     "Terrain", "TouchdownState", "preset", "presets"), "model"),
    **dict.fromkeys(("Disturbance", "IntegratorOptions", "Status", "StepResult", "Trajectory",
                     "run_batch", "simulate", "step", "step_batch", "step_map",
                     "step_jacobian"), "simulation"),
    **dict.fromkeys(("Gait", "find_gait", "Floquet", "floquet", "robustness",
                     "robustness_report", "Branch", "continue_gait", "all_gaits",
                     "stable_region", "ApexState", "apex_map", "apex_map_batch"), "gait"),
    "design": "sweeps.pareto", "DesignSpec": "sweeps.design_spec",
    "load": "_results",
}

#: Subpackages, imported on first attribute access too (``tslip.gait.analyse``).
_SUBPACKAGES = ("biped", "cli", "experiment", "gait", "model", "plotting", "protocols",
               "simulation", "spatial", "sweeps")

__all__ = [
    "__version__",
    "ConstantTorque", "GlobalPD", "LocalVelocity", "Params", "Passive", "Terrain",
    "TouchdownState", "preset", "presets",
    "Disturbance", "IntegratorOptions", "Status", "StepResult", "Trajectory",
    "run_batch", "simulate", "step", "step_batch", "step_map", "step_jacobian",
    "Gait", "find_gait", "Floquet", "floquet", "robustness", "robustness_report", "Branch",
    "continue_gait", "all_gaits", "stable_region", "ApexState", "apex_map", "apex_map_batch",
    "design", "DesignSpec", "load",
]


def __getattr__(name: str) -> object:
    import importlib

    if name in _SUBPACKAGES:
        return importlib.import_module(f".{name}", __name__)
    sub = _SUBPACKAGE.get(name)
    if sub is None:
        raise AttributeError(f"module 'tslip' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{sub}", __name__), name)
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
