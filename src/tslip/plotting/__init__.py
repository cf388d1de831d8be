"""Plots and animations of TSLIP results: a result in, a Figure or a file out.

Nothing here calls ``pyplot``; figures are built with the matplotlib object
API so they work headless. Save with ``fig.savefig(path)``.
"""

from typing import TYPE_CHECKING

from .._lazy import lazy_names

if TYPE_CHECKING:  # the names below load on first use (PEP 562): see _LAZY
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

#: Each public name -> the module defining it, imported on first use: ``tslip reproduce``
#: imports :mod:`.report`, which needs matplotlib only to draw a figure the report folder
#: does not hold (a warm rerun draws none: matplotlib costs about 0.6 s to import).
_LAZY = {
    **dict.fromkeys(("animate", "frame_times", "render_frames"), "animation"),
    **dict.fromkeys(("plot_friction", "plot_impulse_linearisation", "plot_pitch_impulse",
                     "plot_step_down_response", "plot_velocity_angle_effect"), "gait"),
    "plot_branch": "sweeps",
    **dict.fromkeys(("flight_intervals", "ground_profile", "plot_touchdowns",
                     "plot_trajectory"), "trajectories"),
    **dict.fromkeys(("plot_basin", "plot_viability"), "viability"),
}

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


__getattr__, __dir__ = lazy_names(__name__, {name: (module, name)
                                              for name, module in _LAZY.items()})
