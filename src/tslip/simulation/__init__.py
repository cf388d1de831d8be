"""Hybrid stance/flight simulation: compiled Dormand-Prince stance, closed-form flight."""

from .integrate import (
    BatchRun,
    BatchStep,
    Disturbance,
    MapResult,
    run_batch,
    simulate,
    step,
    step_batch,
    step_jacobian,
    step_map,
)
from .options import IntegratorOptions
from .result import Event, IntegrationError, LiftoffState, Status, StepResult, Trajectory

__all__ = [
    "BatchRun", "BatchStep", "Disturbance", "MapResult", "run_batch", "simulate", "step",
    "step_batch", "step_jacobian", "step_map", "IntegratorOptions", "Event",
    "IntegrationError", "LiftoffState", "Status", "StepResult", "Trajectory",
]
