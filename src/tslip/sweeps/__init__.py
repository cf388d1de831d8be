"""Parameter studies and design searches: declarative specs, a parallel resumable runner."""

from . import spatial_spec as _spatial_spec  # noqa: F401  (registers the 3-D models)
from .run import StudyResult, run_study
from .spec import ANALYSES, Axis, StudySpec

# design searches (and pymoo, their optional dependency) load on first use
_DESIGN = {"design": "pareto", "DesignResult": "pareto", "DesignSpec": "design_spec",
           "Variable": "design_spec"}

__all__ = ["ANALYSES", "Axis", "DesignResult", "DesignSpec", "StudyResult", "StudySpec",
           "Variable", "design", "run_study"]


def __getattr__(name: str) -> object:
    import importlib

    if name in _DESIGN:
        return getattr(importlib.import_module(f".{_DESIGN[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
