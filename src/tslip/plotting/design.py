"""The Pareto front of a design search (:func:`tslip.design`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from .results import _axes

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..sweeps.pareto import DesignResult

__all__ = ["plot_design"]


def plot_design(result: DesignResult, ax: Axes | None = None) -> Figure:
    """Every feasible design in the first two objectives (or the first objective against
    the first variable), the Pareto front as a line of dots, axes with units."""
    fig, ax = _axes(ax)
    spec, units = result.spec, result.to_dataframe().attrs["units"]
    x = spec.objectives[0]
    y = spec.objectives[1] if len(spec.objectives) > 1 else spec.names[0]
    f = result.frame[result.frame["feasible"]]
    front = result.front
    ax.plot(f[x], f[y], ".", color="0.7", ms=3, label=f"feasible designs ({len(f)})")
    ax.plot(front[x], front[y], "o-", color="C3", ms=4, label=f"Pareto front ({len(front)})")
    ax.set_xlabel(f"{x} [{units[x]}]")
    ax.set_ylabel(f"{y} [{units[y]}]")
    ax.set_title(f"design {spec.name}: {len(result.frame)} evaluations")
    ax.legend(loc="best", fontsize="small")
    return fig
