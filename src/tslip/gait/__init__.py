"""Gait analysis on the touch-down map: periodic gaits (more in later modules)."""

from .fixed_point import Gait, find_gait, gait_residual

__all__ = ["Gait", "find_gait", "gait_residual"]
