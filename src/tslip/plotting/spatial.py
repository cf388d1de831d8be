"""Figures and animations of the 3-D results (:mod:`tslip.spatial`, issue 43).

* :func:`plot_multipliers`: Floquet multipliers in the unit circle (the 3-D SLIP's
  :class:`~tslip.spatial.gait.Multipliers`, a lateral gait's
  :class:`~tslip.spatial.lateral.LateralPoint`), as the planar Floquet plot;
* :func:`plot_lateral_table`: the largest non-trivial ``|multiplier|`` of a
  :class:`~tslip.spatial.lateral.LateralTable` over ``r``, the splay or a gain, or over
  the ``k_splay`` x ``k_trail`` grid;
* :func:`plot_run`: a :class:`~tslip.spatial.trunk_run.TrunkRun`'s CoM path and
  footholds from the side and from above;
* :func:`draw_views`, :func:`render_run_frames`, :func:`animate_run`: the runner drawn
  in a front view (``z``-``y``, seen from ahead: the runner's right on the viewer's
  left) and a side view (``x``-``y``, seen from the runner's right) side by side, one
  frame or a ``.gif`` / ``.mp4`` through the planar animation's frame times and writers
  (:mod:`tslip.plotting.animation`: written atomically, a link at the path replaced,
  never written through).

The runner: the trunk a thick line along its long axis ``y_b`` (``|r| + l0/2`` long,
centred midway between hip and CoM, as the planar drawing), a bar along ``z_b`` at the
hip (its roll shows in the front view), the stance leg dark, the swing leg (in flight,
at rest length) light, the CoM black, the hip white, the stance foot red. Units of
thesis Table 3.1; the matplotlib object API only (no ``pyplot``).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..spatial.trunk_run import RUN_COLUMNS
from .animation import TIME_UNIT_1M, TRUNK_WIDTH, checked_output, frame_times, write_frames
from .results import _axes

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes

    from ..spatial.trunk_run import TrunkRun

__all__ = ["plot_multipliers", "plot_lateral_table", "plot_run", "draw_views",
           "render_run_frames", "animate_run", "VIEWS"]

_C = {name: i for i, name in enumerate(RUN_COLUMNS)}
#: The two views: (name, horizontal world axis, its label).
VIEWS: tuple[tuple[str, str, str], ...] = (
    ("front", "z", "z [L] (right +, seen from ahead)"),
    ("side", "x", "x [L]"))


def plot_multipliers(nontrivial: Sequence[complex] | np.ndarray,
                     trivial: Sequence[complex] | np.ndarray = (), ax: Axes | None = None, *,
                     title: str = "") -> Figure:
    """Multipliers in the complex plane with the unit circle, the trivial ones hollow
    (thesis Section 3.1.2; :func:`tslip.plotting.results.plot_floquet` for the planar
    model)."""
    fig, ax = _axes(ax, (4.2, 4.0))
    th = np.linspace(0.0, 2.0 * np.pi, 361)
    ax.plot(np.cos(th), np.sin(th), color="0.5", lw=0.8, label="unit circle")
    m = np.asarray(nontrivial, dtype=complex)
    ax.plot(m.real, m.imag, "o", color="C0", label="multiplier")
    tr = np.asarray(trivial, dtype=complex)
    if tr.size:
        ax.plot(tr.real, tr.imag, "o", mfc="none", color="C1", label="trivial")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(r"Re $\lambda$ [-]")
    ax.set_ylabel(r"Im $\lambda$ [-]")
    ax.set_title(title, fontsize="medium")
    ax.legend(fontsize="small")
    return fig


#: The table columns a lateral table may vary, and their axis labels.
_VARIED = {"r": "mass offset r [L]", "splay": "splay [rad]", "k_splay": "k_splay [-]",
           "k_trail": "k_trail [-]"}


def plot_lateral_table(df: pd.DataFrame, ax: Axes | None = None) -> Figure:
    """The largest non-trivial ``|multiplier|`` of a lateral table (its
    :meth:`~tslip.spatial.lateral.LateralTable.to_dataframe`): over the one column of
    ``r``, ``splay``, ``k_splay``, ``k_trail`` that varies (the first varying one, the
    others as labels), or, when both gains vary, as a colour map over the gain grid with
    the points' values written in (stable ones bold)."""
    fig, ax = _axes(ax)
    varied = [c for c in _VARIED if df[c].nunique() > 1]
    if {"k_splay", "k_trail"} <= set(varied):
        ks, kt = np.sort(df["k_splay"].unique()), np.sort(df["k_trail"].unique())
        grid = np.full((len(ks), len(kt)), np.nan)
        for a, b, v in zip(df["k_splay"], df["k_trail"], df["largest"]):
            grid[np.searchsorted(ks, a), np.searchsorted(kt, b)] = v
        im = ax.pcolormesh(np.arange(len(kt) + 1) - 0.5, np.arange(len(ks) + 1) - 0.5, grid,
                           cmap="viridis")
        for a, b, v, st in zip(df["k_splay"], df["k_trail"], df["largest"], df["stable"]):
            ax.text(np.searchsorted(kt, b), np.searchsorted(ks, a), f"{v:.3f}", ha="center",
                    va="center", fontsize="x-small", color="w",
                    fontweight="bold" if st else "normal")
        ax.set_xticks(range(len(kt)), [f"{v:g}" for v in kt])
        ax.set_yticks(range(len(ks)), [f"{v:g}" for v in ks])
        ax.set_xlabel(_VARIED["k_trail"])
        ax.set_ylabel(_VARIED["k_splay"])
        fig.colorbar(im, ax=ax, label="largest non-trivial |multiplier| [-]")
        return fig
    col = varied[0] if varied else None
    x = df[col].to_numpy() if col else np.arange(len(df))
    ax.plot(x, df["largest"].to_numpy(), "o-", color="C0")
    ax.axhline(1.0, color="k", lw=0.8, ls="--")
    ax.set_xlabel(_VARIED[col] if col else "gait [-]")
    ax.set_ylabel("largest non-trivial |multiplier| [-]")
    fixed = ", ".join(f"{c} {df[c].iloc[0]:g}" for c in _VARIED if c != col and len(df))
    ax.set_title(fixed, fontsize="medium")
    return fig


def plot_run(run: TrunkRun, ax: Axes | None = None) -> Figure:
    """The CoM path with the footholds: from the side (``x``-``y``) and from above
    (``x``-``z``, the lateral drift); on ``ax``, the view from above alone."""
    if ax is None:
        fig = Figure(figsize=(8.0, 5.0), layout="constrained")
        side, top = fig.subplots(2, 1, sharex=True)
        _path(run, side, "y", "height y [L]")
        side.set_title(f"3-D TSLIP: {run.n_strides} strides, {run.status.name}",
                       fontsize="medium")
    else:
        fig, top = _axes(ax)
    _path(run, top, "z", "lateral z [L] (right +)")
    top.set_xlabel("x [L]")
    return fig


def _path(run: TrunkRun, ax: Axes, col: str, label: str) -> None:
    t = run["t"]
    if len(t):  # the integrator's steps are long in flight: the interpolated path
        k = _C[col]
        rows = run.sample(np.linspace(t[0], t[-1], max(200, 60 * run.n_strides)))
        x, v, st = rows[:, _C["x"]], rows[:, k], rows[:, _C["stance"]] > 0.5
        ax.plot(x, v, color="C0", lw=1.0, label="CoM")
        ax.plot(np.where(st, x, np.nan), np.where(st, v, np.nan), color="C0", lw=2.2,
                label="stance")
    feet = run.touchdowns
    if len(feet):
        fy = feet[:, 14 if col == "y" else 15]
        right = feet[:, 16] > 0
        ax.plot(feet[right, 13], fy[right], "v", color="C3", ms=5, label="right foot")
        ax.plot(feet[~right, 13], fy[~right], "^", color="C2", ms=5, label="left foot")
    ax.set_ylabel(label)
    ax.legend(fontsize="x-small", ncols=4)


class _Views:
    """The artists of the two views, updated in place per frame."""

    def __init__(self, run: TrunkRun, axes: Sequence[Axes], view_width: float) -> None:
        p = run.params
        self.l0, self.r = p.l0, p.r
        self.trunk_len = abs(p.r) + 0.5 * p.l0
        self.width = view_width
        self.axes = list(axes)
        feet = run.touchdowns
        self.parts: list[dict[str, Any]] = []
        for ax, (name, hcol, label) in zip(self.axes, VIEWS):
            ax.axhline(0.0, color="k", lw=1.2, zorder=1)
            ax.axhspan(-1.0, 0.0, color="0.88", lw=0, zorder=0)
            if len(feet):
                ax.plot(feet[:, 13 if hcol == "x" else 15], feet[:, 14], ls="none",
                        marker="|", ms=7, color="0.5", zorder=1)
            ax.set_aspect("equal", adjustable="box")
            ax.set_xlabel(label, fontsize="small")
            ax.set_ylabel("y [L]", fontsize="small")
            ax.tick_params(labelsize="x-small")
            ax.set_title(f"{name} view", fontsize="small")
            (trail,) = ax.plot([], [], color="C0", lw=1, alpha=0.6, zorder=2)
            (swing,) = ax.plot([], [], color="0.65", lw=1.4, zorder=3)
            (leg,) = ax.plot([], [], color="0.15", lw=1.8, zorder=4)
            (trunk,) = ax.plot([], [], color="#08519c", lw=7, alpha=0.55,
                               solid_capstyle="round", zorder=5)
            (bar,) = ax.plot([], [], color="#08519c", lw=2.5, zorder=6)
            (hip,) = ax.plot([], [], "o", mfc="white", mec="k", ms=5, zorder=7)
            (com,) = ax.plot([], [], "o", color="k", ms=6, zorder=7)
            (foot,) = ax.plot([], [], "o", mfc="C3", mec="k", ms=5, zorder=7)
            self.parts.append(dict(ax=ax, h=hcol, trail=trail, swing=swing, leg=leg,
                                   trunk=trunk, bar=bar, hip=hip, com=com, foot=foot))
        self.text = self.axes[-1].text(0.02, 0.97, "", transform=self.axes[-1].transAxes,
                                       va="top", ha="left", family="monospace",
                                       fontsize="x-small", zorder=8)

    def update(self, row: np.ndarray, trail: np.ndarray) -> None:
        c = row[_C["x"]:_C["x"] + 3]
        hip = row[_C["hip_x"]:_C["hip_x"] + 3]
        foot = row[_C["foot_x"]:_C["foot_x"] + 3]
        R = _rotation(row[_C["qw"]:_C["qw"] + 4])
        centre = 0.5 * (hip + c)
        ends = np.array([centre - 0.5 * self.trunk_len * R[:, 1],
                         centre + 0.5 * self.trunk_len * R[:, 1]])
        bar = np.array([hip - 0.5 * TRUNK_WIDTH * self.l0 * R[:, 2],
                        hip + 0.5 * TRUNK_WIDTH * self.l0 * R[:, 2]])
        stance = row[_C["stance"]] > 0.5
        leg = np.array([hip, foot])
        for part in self.parts:
            k = 0 if part["h"] == "x" else 2
            part["trail"].set_data(trail[:, k], trail[:, 1])
            (part["leg"] if stance else part["swing"]).set_data(leg[:, k], leg[:, 1])
            (part["swing"] if stance else part["leg"]).set_data([], [])
            part["trunk"].set_data(ends[:, k], ends[:, 1])
            part["bar"].set_data(bar[:, k], bar[:, 1])
            part["hip"].set_data([hip[k]], [hip[1]])
            part["com"].set_data([c[k]], [c[1]])
            part["foot"].set_data([foot[k]] if stance else [], [foot[1]] if stance else [])
            ax = part["ax"]
            if part["h"] == "x":
                ax.set_xlim(c[0] - 0.4 * self.width, c[0] + 0.6 * self.width)
                ax.set_ylim(-0.12 * self.l0, 1.6 * self.l0)
            else:  # from ahead: +z (the runner's right) on the viewer's left
                half = 0.45 * self.l0
                ax.set_xlim(c[2] + half, c[2] - half)
                ax.set_ylim(-0.12 * self.l0, 1.6 * self.l0)
        yaw, _, roll = row[_C["yaw"]:_C["yaw"] + 3]
        self.text.set_text(f"t {row[0]:6.3f}  stride {int(row[_C['stride']]):3d}  "
                           f"{'stance' if stance else 'flight'}\nroll {math.degrees(roll):+.2f}"
                           f" deg  yaw {math.degrees(yaw):+.2f} deg")


def _rotation(q: np.ndarray) -> np.ndarray:
    """``R`` of the unit quaternion ``(w, x, y, z)`` (trunk -> world)."""
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _trail(run: TrunkRun, t: float, row: np.ndarray, trail_time: float) -> np.ndarray:
    ts = run["t"]
    k = int(np.searchsorted(ts, t, side="right"))
    k0 = int(np.searchsorted(ts, t - trail_time, side="left"))
    return np.vstack([run.data[k0:k, _C["x"]:_C["x"] + 3], row[_C["x"]:_C["x"] + 3]])


def _figure(width: float, height: float, dpi: float) -> tuple[Figure, list[Axes]]:
    fig = Figure(figsize=(width, height), dpi=dpi, layout="constrained")
    axes = fig.subplots(1, 2, gridspec_kw={"width_ratios": (1.0, 2.2)})
    return fig, list(axes)


def draw_views(run: TrunkRun, t: float, *, figsize: tuple[float, float] = (9.0, 3.6),
               view_width: float | None = None, trail_time: float = 3.0) -> Figure:
    """The runner at time ``t`` [g^-1/2 L^1/2] in the front and the side view, with the
    CoM trail of the last ``trail_time`` (module docstring)."""
    fig, axes = _figure(*figsize, 100.0)
    views = _Views(run, axes, view_width or 4.0 * run.params.l0)
    row = run.sample(np.array([float(t)]))[0]
    views.update(row, _trail(run, float(t), row, trail_time))
    return fig


def render_run_frames(run: TrunkRun, t_frames: np.ndarray, *,
                      size: tuple[int, int] = (800, 360), dpi: float = 100.0,
                      view_width: float | None = None, trail_time: float = 3.0
                      ) -> Iterator[np.ndarray]:
    """RGB frames (``uint8``, ``(height, width, 3)``) of the two views at ``t_frames``."""
    width, height = (int(v) for v in size)
    if width < 16 or height < 16:
        raise ValueError(f"size must be at least 16 x 16 pixels, got {size!r}")
    if not (math.isfinite(dpi) and dpi > 0):
        raise ValueError(f"dpi must be a finite number > 0, got {dpi!r}")
    fig, axes = _figure(width / dpi, height / dpi, dpi)
    canvas = FigureCanvasAgg(fig)
    views = _Views(run, axes, view_width or 4.0 * run.params.l0)
    rows = run.sample(np.asarray(t_frames, dtype=float))
    if len(rows):
        views.update(rows[0], rows[:1, _C["x"]:_C["x"] + 3])
    canvas.draw()  # lay out once: the frames keep the first frame's axes
    fig.set_layout_engine("none")
    for tf, row in zip(t_frames, rows, strict=True):
        views.update(row, _trail(run, float(tf), row, trail_time))
        canvas.draw()
        frame = np.asarray(canvas.buffer_rgba())[..., :3]
        out = np.full((height, width, 3), 255, dtype=np.uint8)  # dpi rounding: pad/crop
        h, w = min(height, frame.shape[0]), min(width, frame.shape[1])
        out[:h, :w] = frame[:h, :w]
        yield out


def animate_run(run: TrunkRun, path: str | os.PathLike[str], fps: float = 30.0,
                speed: float = 0.25, dpi: float = 100.0, *, size: tuple[int, int] = (800, 360),
                time_unit: float = TIME_UNIT_1M, view_width: float | None = None,
                progress: Callable[[int, int], None] | None = None) -> Path:
    """Write the front and side views of ``run`` to ``.gif`` or ``.mp4`` (atomically).

    ``fps``, ``speed`` (playback speed against real time for a leg of ``time_unit``
    seconds per model time unit), ``dpi``, ``size`` (``.mp4``: multiples of 8 pixels) and
    ``progress`` as :func:`tslip.plotting.animation.animate`. Raises ``ValueError`` in one
    line for a bad suffix, a non-positive ``fps``/``speed``/``dpi`` or a run without
    samples.
    """
    path, fps = checked_output(path, fps, size)
    t_frames = frame_times(run, fps, speed, time_unit)  # type: ignore[arg-type]
    frames = render_run_frames(run, t_frames, size=size, dpi=dpi, view_width=view_width)
    return write_frames(path, frames, fps, total=len(t_frames), progress=progress)
