"""Two-legged running model with massed legs (thesis Appendix E).

Bodies, equations of motion (TMT, eqs E.1-E.22), ground contact (eqs
E.23-E.24), phase-based controller (eqs E.25-E.34) and the compiled
simulator; :mod:`.gait` holds the periodic-gait search and analyses.
"""

from .dynamics import accelerations, energy, mass_matrix
from .parameters import BIPED_PARAMETER_TABLE, BipedParams, BipedState
from .simulate import BipedOptions, BipedStatus, BipedTrajectory, simulate, stride

__all__ = [
    "BIPED_PARAMETER_TABLE",
    "BipedParams",
    "BipedState",
    "BipedOptions",
    "BipedStatus",
    "BipedTrajectory",
    "simulate",
    "stride",
    "mass_matrix",
    "accelerations",
    "energy",
]
