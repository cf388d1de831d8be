"""Static plots of a run: CoM path, pitch, leg length, ground reaction forces.

All functions take a :class:`~tslip.simulation.result.Trajectory` (and an
optional figure or axes), draw with the matplotlib object API only (no
``pyplot`` state, so they work headless) and return the
:class:`~matplotlib.figure.Figure`. Units are the dimensionless units of
thesis Table 3.1: length L, time g^-1/2 L^1/2, force Mg.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..model.state import TouchdownState
    from ..model.terrain import Terrain
    from ..simulation.result import StepResult, Trajectory

__all__ = [
    "plot_path",
    "plot_trajectory",
    "plot_touchdowns",
    "flight_intervals",
    "ground_profile",
    "LABELS",
]

#: Axis labels in thesis notation (Table 3.1 units).
LABELS: dict[str, str] = {
    "t": r"$t$ [g$^{-1/2}$ L$^{1/2}$]",
    "x": r"$x$ [L]",
    "y": r"$y$ [L]",
    "phi": r"$\phi$ [rad]",
    "l": r"$l$ [L]",
    "F": r"$F$ [Mg]",
    "v": r"$v$ [g$^{1/2}$ L$^{1/2}$]",
    "xd": r"$\dot x$ [g$^{1/2}$ L$^{1/2}$]",
    "yd": r"$\dot y$ [g$^{1/2}$ L$^{1/2}$]",
    "delta": r"$\delta$ [rad]",
    "beta": r"$\beta$ [rad]",
    "phid": r"$\dot\phi$ [rad g$^{1/2}$ L$^{-1/2}$]",
    "h": r"$h$ [L]",
    "stance_time": r"$t_s$ [g$^{-1/2}$ L$^{1/2}$]",
    "flight_time": r"$t_f$ [g$^{-1/2}$ L$^{1/2}$]",
    "foot_clearance": r"foot clearance [L]",
}

_FLIGHT_COLOR = "0.88"

_TD_QUANTITIES: dict[str, Callable[[TouchdownState], float]] = {
    "v": lambda s: s.v,
    "delta": lambda s: s.delta,
    "beta": lambda s: s.beta,
    "phi": lambda s: s.phi,
    "phid": lambda s: s.phid,
    "xd": lambda s: s.xd,
    "yd": lambda s: s.yd,
    "h": lambda s: s.h,
}
_STEP_QUANTITIES: dict[str, Callable[[StepResult], float]] = {
    "stance_time": lambda s: s.stance_time,
    "flight_time": lambda s: s.flight_time,
    "foot_clearance": lambda s: s.foot_clearance,
}


def flight_intervals(traj: Trajectory, column: str = "t") -> list[tuple[float, float]]:
    """Flight phases as ``(start, end)`` pairs of ``traj[column]``.

    A flight starts at the last stance sample (lift-off) and ends at the
    first sample of the next stance (touch-down) or at the end of the data.

    Parameters
    ----------
    traj : Trajectory
    column : str
        Column giving the interval ends, ``"t"`` (time) or ``"x"`` (CoM x).

    Returns
    -------
    list of (float, float)
    """
    values = traj[column]
    stance = traj["stance"] > 0.5
    n = len(values)
    if n == 0:
        return []
    flight = np.concatenate(([0], (~stance).astype(np.int8), [0]))
    edges = np.diff(flight)
    starts = np.flatnonzero(edges == 1)  # first flight sample of each run
    ends = np.flatnonzero(edges == -1) - 1  # last flight sample of each run
    out = []
    for a, b in zip(starts, ends, strict=True):
        lo = values[a - 1] if a > 0 else values[a]
        hi = values[b + 1] if b + 1 < n else values[b]
        out.append((float(lo), float(hi)))
    return out


def ground_profile(
    traj: Trajectory, terrain: Terrain | None = None, margin: float = 2.0
) -> tuple[np.ndarray, np.ndarray]:
    """Polyline ``(x, y)`` of the ground under a run.

    Parameters
    ----------
    traj : Trajectory
    terrain : Terrain, optional
        Defaults to the terrain the run used, ``traj.terrain``.
    margin : float
        Extra length [L] before and after the run.
    """
    terrain = traj.terrain if terrain is None else terrain
    xs = [traj["x"], traj["hip_x"], traj["foot_x"]] if len(traj.data) else []
    x_lo = min((float(np.min(a)) for a in xs), default=0.0) - margin
    x_hi = max((float(np.max(a)) for a in xs), default=0.0) + margin
    bps = [b for b in terrain.breakpoints if x_lo < b < x_hi]
    px, py = [x_lo], [terrain.height(x_lo)]
    for b in bps:
        px += [b, b]
        py += [terrain.height(b - 1e-12), terrain.height(b)]
    px.append(x_hi)
    py.append(terrain.height(x_hi))
    return np.array(px), np.array(py)


def _shade_flight(ax: Axes, intervals: Sequence[tuple[float, float]]) -> None:
    for i, (a, b) in enumerate(intervals):
        ax.axvspan(a, b, color=_FLIGHT_COLOR, lw=0, zorder=0, label="flight" if i == 0 else None)


def plot_trajectory(
    traj: Trajectory, fig: Figure | None = None, *, terrain: Terrain | None = None
) -> Figure:
    """Four panels: CoM path, pitch, leg length and ground reaction forces.

    Flight phases are shaded grey (as in thesis Figure 6.1); the CoM path
    panel also shows the hip path, the footholds and the ground.

    Parameters
    ----------
    traj : Trajectory
        A run from :func:`tslip.simulate`.
    fig : Figure, optional
        An empty figure to draw into; a new 10 x 6.5 inch figure by default.
    terrain : Terrain, optional
        Ground to draw; rebuilt from the touch-downs by default.

    Returns
    -------
    Figure
        With four axes, in the order path ``y(x)``, ``phi(t)``, ``l(t)``,
        ``F(t)``. The path panel's line labelled ``"CoM"`` holds
        ``traj["x"]``, ``traj["y"]``.

    Examples
    --------
    >>> import tslip
    >>> p = tslip.preset("table2.1")
    >>> s = tslip.TouchdownState(beta=1.05, phi=0.0, xd=5.0, yd=-0.13, phid=0.0)
    >>> fig = plot_trajectory(tslip.simulate(p, s, n_steps=2))
    >>> len(fig.axes)
    4
    """
    if fig is None:
        fig = Figure(figsize=(10, 6.5), layout="constrained")
    ax_path, ax_phi, ax_l, ax_f = fig.subplots(2, 2).ravel()
    t = traj["t"]
    t_flight = flight_intervals(traj, "t")

    plot_path(traj, ax_path, terrain=terrain)

    # -- pitch, leg length, forces ------------------------------------------
    for ax in (ax_phi, ax_l, ax_f):
        _shade_flight(ax, t_flight)
        ax.set_xlabel(LABELS["t"])
        if len(t):
            ax.set_xlim(float(t[0]), float(t[-1]))
    ax_phi.plot(t, traj["phi"], color="C0", label=r"$\phi$")
    ax_phi.set_ylabel(LABELS["phi"])
    ax_phi.set_title("trunk pitch")
    ax_l.plot(t, traj["l"], color="C0", label=r"$l$")
    ax_l.set_ylabel(LABELS["l"])
    ax_l.set_title("leg length")
    ax_f.plot(t, traj["Fx"], color="C2", label=r"$F_x$")
    ax_f.plot(t, traj["Fy"], color="C3", label=r"$F_y$")
    ax_f.axhline(0.0, color="k", lw=0.5)
    ax_f.set_ylabel(LABELS["F"])
    ax_f.set_title("ground reaction force")
    if len(t):
        f_lo = min(float(np.min(traj["Fx"])), float(np.min(traj["Fy"])), 0.0)
        f_hi = max(float(np.max(traj["Fx"])), float(np.max(traj["Fy"])), 0.0)
        pad = 0.05 * (f_hi - f_lo) or 0.1
        ax_f.set_ylim(f_lo - pad, f_hi + 6 * pad)  # room for the legend
    ax_f.legend(loc="upper center", fontsize="small", ncols=3)
    n = len(traj.steps)
    title = f"{n} stride{'' if n == 1 else 's'}, status {traj.status.name}"
    if traj.status.name != "OK":
        title += f": {traj.status.reason}"
    fig.suptitle(title)
    return fig


def plot_path(traj: Trajectory, ax: Axes | None = None, *,
              terrain: Terrain | None = None) -> Figure:
    """The CoM and hip paths over the ground, with the footholds; flights shaded.

    The path panel of :func:`plot_trajectory`; on ``ax`` or a new figure.
    """
    if ax is None:
        fig = Figure(figsize=(8, 3), layout="constrained")
        ax = fig.add_subplot()
    x, y = traj["x"], traj["y"]
    _shade_flight(ax, flight_intervals(traj, "x"))
    gx, gy = ground_profile(traj, terrain, margin=0.5)
    ax.fill_between(gx, gy, np.min(gy) - 0.2, color="0.75", lw=0, zorder=1)
    ax.plot(gx, gy, color="k", lw=1.5, label="ground", zorder=2)
    ax.plot(traj["hip_x"], traj["hip_y"], color="C1", lw=1, ls="--", label="hip")
    ax.plot(x, y, color="C0", lw=1.5, label="CoM", zorder=3)
    feet = [(e.foot_x, e.foot_y) for e in traj.events if e.kind == "touchdown"]
    if feet:
        fx, fy = np.array(feet).T
        ax.plot(fx, fy, ls="none", marker="^", ms=6, color="C3", label="foot", zorder=4)
    ax.set_xlabel(LABELS["x"])
    ax.set_ylabel(LABELS["y"])
    ax.set_title("centre of mass path")
    if len(x):
        ax.set_xlim(float(np.min(gx)), float(np.max(gx)))
        y_top = float(np.max(traj["hip_y"]))
        y_bottom = min(float(np.min(gy)), float(np.min(y)))  # a fall can end below ground
        ax.set_ylim(y_bottom - 0.1, y_top + 0.15 * (y_top - y_bottom))
    ax.legend(loc="center", fontsize="small", ncols=5)
    return ax.get_figure()  # type: ignore[return-value]


def plot_touchdowns(
    traj: Trajectory,
    ax: Axes | None = None,
    *,
    quantities: Sequence[str] = ("v", "delta", "beta", "phi", "phid"),
) -> Figure:
    """Per-step values: the touch-down state and stride times vs step number.

    Parameters
    ----------
    traj : Trajectory
    ax : Axes, optional
        Draw every quantity into this axes (with a legend). By default a new
        figure gets one stacked panel per quantity.
    quantities : sequence of str
        Touch-down state values ``v, delta, beta, phi, phid, xd, yd, h``
        (one point per touch-down, including the last) and stride values
        ``stance_time, flight_time, foot_clearance`` (one per stride).

    Returns
    -------
    Figure

    Raises
    ------
    ValueError
        For an unknown quantity name.
    """
    quantities = list(quantities)
    allowed = [*_TD_QUANTITIES, *_STEP_QUANTITIES]
    for q in quantities:
        if q not in allowed:
            raise ValueError(f"quantities: unknown quantity {q!r}; allowed: {allowed}")
    if not quantities:
        raise ValueError("quantities must name at least one quantity")
    if ax is None:
        fig = Figure(figsize=(6, 1.6 * len(quantities) + 0.6), layout="constrained")
        axes = list(np.atleast_1d(fig.subplots(len(quantities), 1, sharex=True)))
    else:
        fig = ax.get_figure()  # type: ignore[assignment]
        axes = [ax] * len(quantities)
    tds = traj.touchdowns
    for i, (q, a) in enumerate(zip(quantities, axes, strict=True)):
        if q in _TD_QUANTITIES:
            n = np.arange(len(tds))
            vals = [_TD_QUANTITIES[q](s) for s in tds]
        else:
            n = np.arange(len(traj.steps))
            vals = [_STEP_QUANTITIES[q](s) for s in traj.steps]
        a.plot(
            n,
            vals,
            marker="o",
            ms=3,
            lw=1,
            color=f"C{i}" if ax is not None else "C0",
            label=LABELS[q],
        )
        if ax is None or len(quantities) == 1:
            a.set_ylabel(LABELS[q])
    if ax is not None and len(quantities) > 1:
        ax.legend(fontsize="small")
    axes[-1].set_xlabel("touch-down number")
    if ax is None:
        fig.suptitle("touch-down states and stride times")
    return fig
