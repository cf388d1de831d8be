"""Experiment pipeline: video -> tracks -> step-averaged states -> fitted model.

Sections 5.4-5.7 and Appendix D of the thesis: :mod:`.synth` renders a
synthetic recording with known truth, :mod:`.video` tracks the markers
(the only module that imports OpenCV, lazily), :mod:`.signals` filters,
splits and averages the steps, :mod:`.fit` fits the TSLIP model and scores it
(eqs 5.1-5.2, Tables 6.2-6.3).
"""

from .fit import fit_model
from .signals import average_steps, correlation, process_tracks, vaf
from .synth import synthesize, write_video
from .video import Calibration, TrackerOptions, track_video

__all__ = [
    "Calibration", "TrackerOptions", "average_steps", "correlation", "fit_model",
    "process_tracks", "synthesize", "track_video", "vaf", "write_video",
]
