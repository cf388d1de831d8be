"""tslip: self-stable planar running with the spring-mass model with a trunk (TSLIP).

Implements the model of M. J. van den Broek, "Fast Self-Stable Planar Bipedal
Running" (TU Delft / IHMC, 2019), in the dimensionless units of its Table 3.1.
"""

__version__ = "0.2.0"

from .gait import (  # noqa: E402
    Branch,
    Floquet,
    Gait,
    continue_gait,
    find_gait,
    floquet,
    robustness,
    robustness_report,
)
from .model import (  # noqa: E402
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
from .simulation import (  # noqa: E402
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

__all__ = [
    "__version__",
    "ConstantTorque", "GlobalPD", "LocalVelocity", "Params", "Passive", "Terrain",
    "TouchdownState", "preset", "presets",
    "Disturbance", "IntegratorOptions", "Status", "StepResult", "Trajectory",
    "run_batch", "simulate", "step", "step_batch", "step_map", "step_jacobian",
    "Gait", "find_gait", "Floquet", "floquet", "robustness", "robustness_report", "Branch",
    "continue_gait",
]
