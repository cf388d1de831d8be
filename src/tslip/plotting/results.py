"""One-panel figures of result objects that had none: what their ``.plot(ax=None)`` draws.

Each function draws on ``ax`` (or a new figure) with the matplotlib object
API and returns the Figure. Units are those of thesis Table 3.1.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.figure import Figure

from .trajectories import LABELS

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..gait.fixed_point import Gait
    from ..gait.robustness import RobustnessLimits
    from ..gait.stability import Floquet
    from ..simulation.integrate import BatchRun
    from ..simulation.result import StepResult

__all__ = ["plot_step", "plot_floquet", "plot_robustness", "plot_gait", "plot_batch_run",
           "plot_series"]


def _axes(ax: Axes | None, size: tuple[float, float] = (6.0, 3.6)) -> tuple[Figure, Axes]:
    if ax is None:
        fig = Figure(figsize=size, layout="constrained")
        return fig, fig.add_subplot()
    return ax.get_figure(), ax  # type: ignore[return-value]


def plot_step(step: StepResult, ax: Axes | None = None) -> Figure:
    """Ground reaction force ``F_x``, ``F_y`` [Mg] and hip torque [MgL] over one stance."""
    fig, ax = _axes(ax)
    t = step.grf[:, 0]
    ax.plot(t, step.grf[:, 1], color="C2", label=r"$F_x$")
    ax.plot(t, step.grf[:, 2], color="C3", label=r"$F_y$")
    if np.any(step.grf[:, 3]):
        ax.plot(t, step.grf[:, 3], color="C0", ls="--", label=r"$\tau$ [MgL]")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel(r"time since touch-down [g$^{-1/2}$ L$^{1/2}$]")
    ax.set_ylabel(LABELS["F"])
    ax.set_title(f"one stance: {step.status.name}", fontsize="medium")
    ax.legend(fontsize="small")
    return fig


def plot_floquet(fl: Floquet, ax: Axes | None = None) -> Figure:
    """The multipliers in the complex plane with the unit circle (thesis Section 3.1.2).

    Trivial (structural) multipliers are hollow.
    """
    fig, ax = _axes(ax, (4.2, 4.0))
    th = np.linspace(0.0, 2.0 * np.pi, 361)
    ax.plot(np.cos(th), np.sin(th), color="0.5", lw=0.8, label="unit circle")
    m, triv = np.asarray(fl.multipliers), np.asarray(fl.trivial, dtype=bool)
    ax.plot(m.real[~triv], m.imag[~triv], "o", color="C0", label="multiplier")
    if triv.any():
        ax.plot(m.real[triv], m.imag[triv], "o", mfc="none", color="C1", label="trivial")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(r"Re $\lambda$ [-]")
    ax.set_ylabel(r"Im $\lambda$ [-]")
    ax.set_title(f"{fl.stability}: max |lambda| = {fl.max_nontrivial:.3g}", fontsize="medium")
    ax.legend(fontsize="small")
    return fig


def plot_robustness(res: RobustnessLimits, ax: Axes | None = None) -> Figure:
    """One bar per searched disturbance and direction: its limit, in its unit."""
    fig, ax = _axes(ax)
    labels = [f"{lim.kind} {'+' if lim.sign > 0 else '-'}\n[{lim.unit}]" for lim in res.limits]
    vals = np.array([lim.limit for lim in res.limits], dtype=float)
    shown = np.where(np.isfinite(vals), vals, 0.0)
    bars = ax.bar(range(len(vals)), shown, color=["C0" if v < 0 else "C2" for v in shown])
    for b, v in zip(bars, vals):
        ax.annotate(f"{v:.4g}", (b.get_x() + b.get_width() / 2, b.get_height()),
                    ha="center", va="bottom" if v >= 0 else "top", fontsize="small")
    ax.set_xticks(range(len(vals)), labels, fontsize="small")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_ylabel("largest survived disturbance")
    n = getattr(res, "n_steps", None)
    ax.set_title("robustness" + (f" over {n} strides" if n else ""), fontsize="medium")
    return fig


def plot_gait(gait: Gait, ax: Axes | None = None, n_steps: int = 2) -> Figure:
    """The gait's CoM path over ``n_steps`` strides (simulated from its touch-down state)."""
    from ..simulation.integrate import simulate
    from .trajectories import plot_path

    fig, ax = _axes(ax, (8.0, 3.0))
    plot_path(simulate(gait.params, gait.state, n_steps=n_steps), ax)
    ax.set_title(f"periodic gait: v = {gait.state.v:.4g}, stance {gait.stance_time:.4g}, "
                 f"flight {gait.flight_time:.4g}", fontsize="medium")
    return fig


def plot_batch_run(run: BatchRun, ax: Axes | None = None) -> Figure:
    """Touch-down speed stride by stride, one line per row of the batch."""
    fig, ax = _axes(ax)
    v = np.hypot(run.touchdowns[:, :, 2], run.touchdowns[:, :, 3])
    ax.plot(np.arange(v.shape[1]), v.T, lw=0.8, marker=".", ms=3)
    ax.set_xlabel("touch-down number [-]")
    ax.set_ylabel(LABELS["v"])
    ax.set_title(f"{len(run.status)} runs", fontsize="medium")
    return fig


def plot_series(values: Any, ax: Axes | None = None, *, level: float | None = None,
                xlabel: str = "touch-down number [-]", ylabel: str = LABELS["v"],
                title: str = "") -> Figure:
    """Values one by one (touch-down speeds, a search's best score), with a ``level`` line."""
    fig, ax = _axes(ax)
    ax.plot(np.arange(len(values)), values, marker="o", ms=3, color="C0")
    if level is not None and np.isfinite(level):
        ax.axhline(level, color="C3", ls="--", lw=1)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize="medium")
    return fig
