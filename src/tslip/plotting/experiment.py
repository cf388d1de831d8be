"""Figures of the experiment pipeline: Figure 6.1 (measured mean +- std vs model), Figure D.2.

Functions take results from :mod:`tslip.experiment` and return a
:class:`~matplotlib.figure.Figure`; they never use pyplot.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from ..model.units import UNIT
from .notation import axis_label

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..experiment.fit import FitResult
    from ..experiment.signals import StepAverage, StepData

__all__ = ["plot_step_average", "plot_foot_trajectory", "plot_fit_scores"]

_LABELS = {k: axis_label(sym, UNIT[kind]) for k, sym, kind in (
    ("y", "$y_m$", "length"), ("l", "$l$", "length"), ("beta", r"$\beta$", "angle"),
    ("phi", r"$\phi$", "angle"), ("xd", r"$\dot{x}_m$", "speed"),
    ("yd", r"$\dot{y}_m$", "speed"), ("ld", r"$\dot{l}$", "speed"),
    ("betad", r"$\dot{\beta}$", "angular_velocity"),
    ("phid", r"$\dot{\phi}$", "angular_velocity"))}


def plot_step_average(avg: StepAverage, fit: FitResult | None = None, *,
                      ax: Axes | None = None, signal: str = "y") -> Figure:
    """Measured step mean +- std against the model (Figure 6.1 layout, 3 x 3).

    The flight phase (after the mean measured duty factor) is shaded grey.
    With ``ax``, only ``signal`` is drawn, into it.
    """
    duty = float(np.mean(avg.duty_factor))
    if ax is not None:
        if signal not in _LABELS:
            raise ValueError(f"signal must be one of {list(_LABELS)}, got {signal!r}")
        _plot_signal(ax, avg, signal, fit, duty)
        ax.set_xlabel("normalised step time [-]")
        ax.legend(fontsize="small")
        return ax.get_figure()  # type: ignore[return-value]
    fig = Figure(figsize=(11, 8), layout="constrained")
    axes = fig.subplots(3, 3, sharex=True)
    for a, name in zip(axes.ravel(), _LABELS):
        _plot_signal(a, avg, name, fit, duty)
    for a in axes[-1]:
        a.set_xlabel("normalised step time [-]")
    axes[0, 0].legend(fontsize="small")
    return fig


def _plot_signal(ax: Axes, avg: StepAverage, name: str, fit: FitResult | None,
                 duty: float) -> None:
    m, s = avg.mean[name].to_numpy(), avg.std[name].to_numpy()
    ax.axvspan(duty, 1.0, color="0.9", lw=0)
    ax.fill_between(avg.tau, m - s, m + s, color="C0", alpha=0.3, lw=0)
    ax.plot(avg.tau, m, color="C0", label=f"measured (n = {avg.n_steps})")
    if fit is not None:
        ax.plot(avg.tau, fit.curves[name], color="C3", ls="--", label="TSLIP fit")
    ax.set_ylabel(_LABELS[name])


def plot_fit_scores(fit: FitResult, ax: Axes | None = None) -> Figure:
    """VAF (eq. 5.2) of each signal in stance and over the stride, as bars (Table 6.3)."""
    if ax is None:
        fig = Figure(figsize=(6.4, 3.4), layout="constrained")
        ax = fig.add_subplot()
    sc = fit.scores
    x = np.arange(len(sc))
    ax.bar(x - 0.2, sc["vaf_stance"], width=0.4, color="C0", label="stance")
    ax.bar(x + 0.2, sc["vaf_full"], width=0.4, color="C1", label="stride")
    ax.set_xticks(x, list(sc["signal"]))
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_ylabel("VAF [%]")
    ax.set_title(f"TSLIP fit: cost {fit.cost:.3g}, {'' if fit.converged else 'not '}converged",
                 fontsize="medium")
    ax.legend(fontsize="small")
    return ax.get_figure()  # type: ignore[return-value]


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
