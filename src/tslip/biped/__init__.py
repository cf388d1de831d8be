"""Two-legged running model with massed legs (thesis Appendix E).

Bodies, equations of motion (TMT, eqs E.1-E.22), ground contact (eqs
E.23-E.24), phase-based controller (eqs E.25-E.34) and the compiled
simulator; :mod:`.gait` holds the step map, the periodic-gait search and
Floquet multipliers, :mod:`.robustness` the robustness limits.

The biped speaks the TSLIP's vocabulary (docs/model.md, "Vocabulary"): one
stride is :func:`step` -> :class:`StepResult`, a run is :func:`simulate` ->
:class:`Trajectory`, and both report the shared :class:`tslip.Status`. The
old names (``BipedStatus``, ``BipedTrajectory``, ``stride``, ``StrideResult``)
warn and are removed in 0.4. What both models' results share is written down
as the protocols of :mod:`tslip.protocols`.
"""

from .._renamed import module_getattr
from ..simulation.result import Status as Status  # the shared enum, also here
from ._legacy import SIMULATE_ALIASES
from .dynamics import accelerations, energy, mass_matrix
from .parameters import BIPED_PARAMETER_TABLE, BipedParams, BipedState
from .simulate import BipedOptions, StepResult, Trajectory, simulate, step

__all__ = [
    "BIPED_PARAMETER_TABLE",
    "BipedParams",
    "BipedState",
    "BipedOptions",
    "StepResult",
    "Trajectory",
    "simulate",
    "step",
    "mass_matrix",
    "accelerations",
    "energy",
]


#: Old names (deprecated, removed in 0.4).
__getattr__ = module_getattr(__name__, SIMULATE_ALIASES)
