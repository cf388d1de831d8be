"""Gait analysis on the touch-down map (thesis Sections 2.8, 3.1-3.4, Appendices B-C).

periodic gaits (fixed_point), their continuation along a parameter
(continuation), Floquet stability (stability), robustness limits
(robustness), the ground impulse and its response to pitch (impulse), stride
theory and the no-slip check (stride), energy balance after ground steps
(energy), the apex section and its return map (section), every gait at fixed
energy and the stable region (allgaits), viability kernels and basins of
attraction on the apex section (viability), and one report of it all (report).
"""

from .allgaits import GaitSet, StableRegion, all_gaits, stable_region
from .continuation import Branch, continue_gait, get_param, set_param, stability_boundaries
from .energy import (
    HeightChangeResult,
    StepDownResponse,
    StrideWork,
    VelocityAngleCase,
    expected_velocity_change,
    step_down_response,
    stride_work,
    velocity_after_height_change,
    velocity_angle_effect,
)
from .fixed_point import (
    CMAReport,
    Gait,
    GaitProblem,
    cma_minimize,
    find_gait,
    gait_residual,
    nominal_energy,
)
from .impulse import (
    Impulse,
    ImpulseLinearisation,
    PitchResponse,
    impulse_linearisation,
    pitch_disturbance_response,
    stance_impulse,
)
from .report import GaitReport, analyse
from .robustness import RobustnessLimit, RobustnessResult, robustness, robustness_report
from .section import (
    ApexBatch,
    ApexState,
    ApexStep,
    apex_map,
    apex_map_batch,
    apex_map_states,
    apex_to_touchdown,
    total_energy,
    touchdown_to_apex,
)
from .stability import Floquet, apex_jacobian, floquet, map_jacobian, pitch_decoupled
from .stride import (
    FrictionCheck,
    StrideProperties,
    bounce_time,
    fast_running_index,
    friction_ratio,
    predicted_flight_time,
    predicted_stance_time,
    stride_properties,
)
from .viability import Basin, StateActionMap, Viability, basin, state_action_map, viability

__all__ = [
    "GaitSet", "StableRegion", "all_gaits", "stable_region", "nominal_energy", "apex_jacobian",
    "Branch", "continue_gait", "get_param", "set_param", "stability_boundaries",
    "HeightChangeResult", "StepDownResponse", "VelocityAngleCase", "expected_velocity_change",
    "step_down_response", "StrideWork", "stride_work", "velocity_after_height_change",
    "velocity_angle_effect",
    "CMAReport", "Gait", "GaitProblem", "cma_minimize", "find_gait", "gait_residual",
    "Impulse", "ImpulseLinearisation", "PitchResponse", "impulse_linearisation",
    "pitch_disturbance_response", "stance_impulse", "analyse", "GaitReport",
    "RobustnessLimit", "RobustnessResult", "robustness", "robustness_report",
    "Floquet", "floquet", "map_jacobian", "pitch_decoupled",
    "ApexBatch", "ApexState", "ApexStep", "apex_map", "apex_map_batch", "apex_map_states",
    "apex_to_touchdown", "total_energy", "touchdown_to_apex",
    "FrictionCheck", "StrideProperties", "bounce_time", "fast_running_index", "friction_ratio",
    "predicted_flight_time", "predicted_stance_time", "stride_properties",
    "Basin", "StateActionMap", "Viability", "basin", "state_action_map", "viability",
]
