"""The 3-D spring-mass runner (3D-SLIP) of Seipel & Holmes (2005): issue 43, Part 1.

* :mod:`.parameters`: :class:`SpatialParams` (spring, leg angles, feedback, heading rule);
* :mod:`.stride`: the apex-to-apex step, its statuses and its exact Jacobian;
* :mod:`.gait`: left-right symmetric gaits and the Floquet multipliers of the two-step map;
* :mod:`._kernels`: the compiled stance loop on the project's Runge-Kutta core.
"""

from __future__ import annotations

from .gait import Multipliers, SymmetricGait, floquet, symmetric_gaits
from .parameters import HEADINGS, SpatialParams, preset, presets
from .stride import (
    SECTION_NAMES,
    SpatialApex,
    SpatialStatus,
    SpatialStep,
    apex_step,
    apex_steps,
    energy,
    mirror,
    section_map,
    step_jacobian,
)

__all__ = ["HEADINGS", "SpatialParams", "preset", "presets", "SECTION_NAMES", "SpatialApex",
           "SpatialStatus", "SpatialStep", "apex_step", "apex_steps", "energy", "mirror",
           "section_map", "step_jacobian", "Multipliers", "SymmetricGait", "floquet",
           "symmetric_gaits"]
