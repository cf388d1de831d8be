"""Figures of the experiment pipeline: Figure 6.1 (measured mean +- std vs model), Figure D.2.

Functions take results from :mod:`tslip.experiment` and return a
:class:`~matplotlib.figure.Figure`; they never use pyplot.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..experiment.fit import FitResult
    from ..experiment.signals import StepAverage, StepData

__all__ = ["plot_step_average", "plot_foot_trajectory"]

_LABELS = {"y": "y_m [L]", "l": "l [L]", "beta": "beta [rad]", "phi": "phi [rad]",
           "xd": "xdot_m [g^1/2 L^1/2]", "yd": "ydot_m [g^1/2 L^1/2]",
           "ld": "ldot [g^1/2 L^1/2]", "betad": "betadot [rad g^1/2 L^-1/2]",
           "phid": "phidot [rad g^1/2 L^-1/2]"}


def plot_step_average(avg: StepAverage, fit: FitResult | None = None) -> Figure:
    """Measured step mean +- std against the model (Figure 6.1 layout, 3 x 3).

    The flight phase (after the mean measured duty factor) is shaded grey.
    """
    fig = Figure(figsize=(11, 8), layout="constrained")
    axes = fig.subplots(3, 3, sharex=True)
    duty = float(np.mean(avg.duty_factor))
    for ax, name in zip(axes.ravel(), _LABELS):
        m, s = avg.mean[name].to_numpy(), avg.std[name].to_numpy()
        ax.axvspan(duty, 1.0, color="0.9", lw=0)
        ax.fill_between(avg.tau, m - s, m + s, color="C0", alpha=0.3, lw=0)
        ax.plot(avg.tau, m, color="C0", label=f"measured (n = {avg.n_steps})")
        if fit is not None:
            ax.plot(avg.tau, fit.curves[name], color="C3", ls="--", label="TSLIP fit")
        ax.set_ylabel(_LABELS[name])
    for ax in axes[-1]:
        ax.set_xlabel("normalised step time [-]")
    axes[0, 0].legend(fontsize="small")
    return fig


def plot_foot_trajectory(data: StepData, ax: Axes | None = None) -> Figure:
    """Near-foot position relative to the CoM (Figure D.2) [m]."""
    if ax is None:
        fig = Figure(figsize=(6, 5), layout="constrained")
        ax = fig.add_subplot()
    else:
        fig = ax.get_figure()  # type: ignore[assignment]
    f = data.frames
    ax.plot(f["foot_rel_x"], f["foot_rel_y"], ".", ms=1.5, color="C0", alpha=0.4,
            label="near foot")
    ax.plot([0], [0], "k+", ms=12, label="CoM")
    ax.set_aspect("equal")
    ax.set_xlabel("x - x_m [m]")
    ax.set_ylabel("y - y_m [m]")
    ax.legend(fontsize="small")
    return fig
