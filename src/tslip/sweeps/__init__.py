"""Parameter studies: declarative specs, a parallel resumable runner."""

from .run import StudyResult, run_study
from .spec import ANALYSES, Axis, StudySpec

__all__ = ["ANALYSES", "Axis", "StudyResult", "StudySpec", "run_study"]
