"""Plots of viability results (:mod:`tslip.gait.viability`): a result in, a Figure out.

:func:`plot_viability` draws the state-action grid as vibly does: each cell
coloured by whether its stride fails at once, survives it but leads out of
the viable set, or is viable; for two state variables, the viable states
coloured by the share of viable actions (of action pairs, for two actions);
for three, the projection over the last (:meth:`tslip.gait.viability.Viability.projection`).
:func:`plot_section` draws a 3-D result's slice or projection, labelled as
which it is. :func:`plot_basin` draws the
strides to reach the gait over the start grid, falls marked.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from ..model.units import UNIT
from .notation import axis_label
from .sweeps import _STABLE_GREEN, param_label

if TYPE_CHECKING:
    from ..gait.viability import Basin, Viability, ViableSection

__all__ = ["plot_viability", "plot_section", "plot_basin"]

_LABELS = {"y": axis_label("apex height $y$", UNIT["length"]),
           "phi": axis_label(r"apex pitch $\phi$", UNIT["angle"]),
           "phid": axis_label(r"apex pitch rate $\dot{\phi}$", UNIT["angular_velocity"])}
_CELLS = ListedColormap(["#8c8c8c", "#f2d0a4", _STABLE_GREEN])


def _fig(ax: Axes | None) -> tuple[Figure, Axes]:
    if ax is None:
        fig = Figure(figsize=(6.0, 4.2), layout="constrained")
        return fig, fig.add_subplot()
    return ax.figure, ax  # type: ignore[return-value]


def _label(name: str) -> str:
    return _LABELS.get(name) or param_label(name)


def _edges(g: np.ndarray) -> np.ndarray:
    """Cell edges around grid points (half-way between neighbours)."""
    if g.size == 1:
        return np.array([g[0] - 0.5, g[0] + 0.5])
    mid = 0.5 * (g[1:] + g[:-1])
    return np.concatenate([[2 * g[0] - mid[0]], mid, [2 * g[-1] - mid[-1]]])


def plot_viability(result: Viability, ax: Axes | None = None) -> Figure:
    """The viable state-action set (one state variable) or viable states (two).

    One state variable: each (action, state) cell grey where its stride fails
    at once (a fall, no touch-down, no apex), beige where it survives the
    stride but is not viable (it fails later, or leaves the grid, which the
    cell rule counts as not viable), green where it is viable. Two: the
    viable states, shaded by the share of their actions that are viable.
    Three: the projection over the last variable (:func:`plot_section`).
    """
    m = result.map
    if len(m.names) == 3:
        return plot_section(result.projection(m.names[2]), ax=ax)
    fig, ax = _fig(ax)
    energy = "" if np.isnan(m.energy) else f" at E = {m.energy:.4g} MgL"
    first = m.action_names[0]
    if len(m.names) == 1:
        # two actions: a cell over the first is viable for some value of the second, and
        # fails at once if it does for every value
        over = tuple(range(2, result.q.ndim))
        failed, q = m.failed.all(axis=over), result.q.any(axis=over)
        cls = np.where(failed, 0, np.where(q, 2, 1))
        ax.pcolormesh(_edges(m.action_grids[0]), _edges(m.grid[0]), cls, cmap=_CELLS, vmin=0,
                      vmax=2)
        more = m.action_names[1:]
        ax.set_xlabel(_label(first) + (f" (for some {more[0]})" if more else ""))
        ax.set_ylabel(_label(m.names[0]))
        kinds = ("fails at once", "not viable (fails later or leaves the grid)", "viable")
        ax.legend(handles=[Patch(color=_CELLS(i), label=t) for i, t in enumerate(kinds)],
                  loc="upper center", bbox_to_anchor=(0.5, -0.14), ncols=3, fontsize=8,
                  frameon=False)  # below the cells, never on them
    else:
        share = np.where(result.s, result.q.reshape(result.s.shape + (-1,)).mean(axis=-1),
                         np.nan)
        mesh = ax.pcolormesh(_edges(m.grid[1]), _edges(m.grid[0]), share, cmap="Greens",
                             vmin=0, vmax=1)
        fig.colorbar(mesh, ax=ax, label=f"share of viable {' x '.join(m.action_names)}")
        ax.set_xlabel(_label(m.names[1]))
        ax.set_ylabel(_label(m.names[0]))
    ax.set_title(f"viability ({result.rule}){energy}: {100 * result.viable_fraction:.1f} % "
                 "of pairs viable", fontsize=10)
    return fig


def plot_section(result: ViableSection, ax: Axes | None = None) -> Figure:
    """A slice or projection of a 3-D viable set, titled with which it is."""
    fig, ax = _fig(ax)
    ax.pcolormesh(_edges(result.grid[1]), _edges(result.grid[0]), result.s.astype(float),
                  cmap=ListedColormap(["#f2d0a4", _STABLE_GREEN]), vmin=0, vmax=1)
    ax.set_xlabel(_label(result.names[1]))
    ax.set_ylabel(_label(result.names[0]))
    energy = "" if np.isnan(result.energy) else f", E = {result.energy:.4g} MgL"
    ax.set_title(f"viable states ({result.rule}{energy}), {result.label}: "
                 f"{100 * result.fraction:.1f} %", fontsize=9)
    ax.legend(handles=[Patch(color=_STABLE_GREEN, label="viable"),
                       Patch(color="#f2d0a4", label="not viable")], fontsize=8,
              loc="upper center", bbox_to_anchor=(0.5, -0.14), ncols=2, frameon=False)
    return fig


def plot_basin(result: Basin, ax: Axes | None = None) -> Figure:
    """Strides to reach the gait from each start; grey where the run falls."""
    fig, ax = _fig(ax)
    steps = np.where(result.converged, result.steps, np.nan).astype(float)
    if len(result.names) == 1:
        g = result.grid[0]
        ax.plot(g[result.converged], result.steps[result.converged], "o", ms=3, color="C0",
                label="reaches the gait")
        fell = result.fell
        ax.plot(g[fell], np.zeros(int(fell.sum())), "x", color="C3", ms=4, label="falls")
        ax.set_xlabel(_label(result.names[0]))
        ax.set_ylabel("strides to the gait")
        ax.legend(fontsize=8)
    else:
        ax.pcolormesh(_edges(result.grid[1]), _edges(result.grid[0]),
                      np.where(result.fell, 1.0, np.nan), cmap=ListedColormap(["#8c8c8c"]))
        mesh = ax.pcolormesh(_edges(result.grid[1]), _edges(result.grid[0]), steps,
                             cmap="viridis_r")
        fig.colorbar(mesh, ax=ax, label="strides to the gait (grey: falls)")
        ax.set_xlabel(_label(result.names[1]))
        ax.set_ylabel(_label(result.names[0]))
    ax.set_title(f"basin of attraction, {result.n_steps} strides, tol {result.tol:g}",
                 fontsize=10)
    return fig
