"""Plots and animations of TSLIP results: a result in, a Figure or a file out.

Nothing here calls ``pyplot``; figures are built with the matplotlib object
API so they work headless. Save with ``fig.savefig(path)``.
"""

from .animation import animate, frame_times, render_frames
from .gait import (
    plot_friction,
    plot_impulse_linearisation,
    plot_pitch_impulse,
    plot_step_down_response,
    plot_velocity_angle_effect,
)
from .sweeps import plot_branch
from .trajectories import flight_intervals, ground_profile, plot_touchdowns, plot_trajectory
from .viability import plot_basin, plot_viability

__all__ = [
    "animate",
    "plot_basin",
    "plot_branch",
    "flight_intervals",
    "frame_times",
    "ground_profile",
    "plot_friction",
    "plot_impulse_linearisation",
    "plot_pitch_impulse",
    "plot_step_down_response",
    "plot_touchdowns",
    "plot_trajectory",
    "plot_velocity_angle_effect",
    "plot_viability",
    "render_frames",
]
