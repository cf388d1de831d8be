"""Experiment pipeline: video -> tracks -> step-averaged states -> fitted model.

Sections 5.4-5.7 and Appendix D of the thesis: :mod:`.synth` lays out a
synthetic recording of the TSLIP or the biped with known truth, :mod:`.render`
draws it, :mod:`.video` tracks the markers
(the only module that imports OpenCV, lazily), :mod:`.signals` filters,
splits and averages the steps, :mod:`.fit` fits the TSLIP model and scores it
(eqs 5.1-5.2, Tables 6.2-6.3).
"""

from .fit import fit_model
from .render import write_video
from .signals import average_steps, correlation, process_tracks, vaf
from .synth import synthesize, synthesize_biped
from .video import Calibration, TrackerOptions, track_video

__all__ = [
    "Calibration", "TrackerOptions", "average_steps", "correlation", "fit_model",
    "process_tracks", "synthesize", "synthesize_biped", "track_video", "vaf", "write_video",
]
