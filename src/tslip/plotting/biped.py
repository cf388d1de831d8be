"""Figures of the two-legged model: tracking (E.2), foot path (E.3), metacentre (E.4), frames.

Functions take results and an optional axes, return the Figure, never show.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..biped.dynamics import controller_references, foot_position, hip_position, leg_phase
from ..model.units import UNIT
from .gait import plot_pitch_impulse
from .notation import axis_label

if TYPE_CHECKING:
    from ..biped.simulate import Trajectory
    from ..gait.impulse import PitchResponse

__all__ = ["plot_tracking", "plot_foot_path", "plot_metacentric", "draw_biped", "animate_biped"]


def _window(tr: Trajectory, stride: int) -> np.ndarray:
    t_s = np.r_[tr.time[0], tr.strides[:, 0]]
    if stride + 1 >= t_s.size:
        return np.ones(tr.time.size, dtype=bool)
    return (tr.time >= t_s[stride]) & (tr.time <= t_s[stride + 1])


def plot_tracking(tr: Trajectory, stride: int = 0, leg: int = 0) -> Figure:
    """Reference vs actual thigh length, shank length and hip angle (Figure E.2)."""
    m = _window(tr, stride)
    t = tr.time[m]
    side = "R" if leg == 0 else "L"
    ref = controller_references(tr.params, leg_phase(tr.params, t, leg))
    fig = Figure(figsize=(7, 7), layout="constrained")
    axs = fig.subplots(3, 1, sharex=True)
    rows = [(f"l_t{side}", ref[:, 0], axis_label("thigh length $l_t$", UNIT["length"])),
            (f"l_s{side}", np.full(t.size, tr.params.l_s0),
             axis_label("shank length $l_s$", UNIT["length"])),
            (f"theta_h{side}", ref[:, 2], axis_label(r"hip angle $\theta_h$", UNIT["angle"]))]
    for ax, (col, r, label) in zip(axs, rows, strict=True):
        ax.plot(t, r, "k--", lw=1, label="reference" if col != f"l_s{side}" else "rest length")
        ax.plot(t, tr[col][m], "C0", lw=1.5, label="simulation")
        ax.set_ylabel(label)
        ax.legend(loc="best", fontsize=8)
    axs[-1].set_xlabel(axis_label("time", UNIT["time"]))
    fig.suptitle(f"controller tracking, {'right' if leg == 0 else 'left'} leg, stride {stride}")
    return fig


def plot_foot_path(tr: Trajectory, leg: int = 0, ax: Any = None,
                   stride: int | None = None) -> Figure:
    """Reference and actual foot path relative to the hip (Figure E.3).

    ``stride``: only that stride (from its right touch-down to the next);
    default every recorded stride.
    """
    p = tr.params
    q = tr.data[:, 1:10] if stride is None else tr.data[_window(tr, stride), 1:10]
    rel = foot_position(p, q, leg) - hip_position(p, q)
    rho = np.linspace(0, 1, 400)
    ref = controller_references(p, rho)
    gam = ref[:, 2]  # reference hip angle at zero pitch
    s = ref[:, 0] + p.l_s0
    ref_x, ref_z = -s * np.sin(gam), -s * np.cos(gam)
    if ax is None:  # sized to the path at equal aspect, with room for the labels and legend
        xs, zs = np.r_[ref_x, rel[:, 0]], np.r_[ref_z, rel[:, 1]]
        ratio = float(np.ptp(zs) / max(np.ptp(xs), 1e-9))
        fig = Figure(figsize=(6.4, min(6.0, 0.9 + 4.4 * ratio)), layout="constrained")
        ax = fig.subplots()
    else:
        fig = ax.figure
    ax.plot(ref_x, ref_z, "k--", lw=1, label=r"reference ($\theta_b = 0$)")
    ax.plot(rel[:, 0], rel[:, 1], "C0", lw=1, label="simulation")
    ax.set_aspect("equal")
    ax.set_xlabel(axis_label(r"$x - x_{hip}$", UNIT["length"]))
    ax.set_ylabel(axis_label(r"$z - z_{hip}$", UNIT["length"]))
    ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    return fig


def plot_metacentric(response: PitchResponse) -> Figure:
    """Ground reaction forces and resultant impulse for pitch changes (Figure E.4).

    Left: total ground reaction force over the right stance for each pitch
    change. Right: the forces at the centre of pressure, the impulse's line
    of action, the whole-body CoM (origin) and the mean hip, drawn by
    :func:`tslip.plotting.gait.plot_pitch_impulse` as for the TSLIP.

    Parameters
    ----------
    response : PitchResponse
        From :func:`tslip.biped.metacentre.metacentric_test`.
    """
    fig = Figure(figsize=(10, 5.0), layout="constrained")
    ax, ax2 = fig.subplots(1, 2, width_ratios=(1.0, 1.2))
    labels = [rf"$\Delta\theta_b$ = {d:+.1f} rad" for d in response.dphis]
    for i, imp in enumerate(response):
        ax.plot(imp.time, imp.F_y, f"C{i}")
        ax.plot(imp.time, imp.F_x, f"C{i}--")
    ax.set_xlabel(axis_label("time since touch-down", UNIT["time"]))
    ax.set_ylabel(axis_label("ground reaction force", UNIT["force"]))
    # the ground damper (Table E.3) gives short touch-down and lift-off spikes;
    # scale the axis to the rest of the stance and say how far the spikes go
    f_all = np.concatenate([np.r_[i.F_x, i.F_y] for i in response])
    lo, hi = np.percentile(f_all, [1.0, 99.0])
    if f_all.max() > 1.5 * hi or f_all.min() < lo - 0.5 * (hi - lo):
        ax.set_ylim(min(lo, 0.0) - 0.2 * (hi - lo), 1.3 * hi)
        ax.set_title(f"spikes clipped: range {f_all.min():.1f} to {f_all.max():.1f} Mg",
                     fontsize="small")
    ax.axhline(0.0, color="0.7", lw=0.5)
    # below the panels, never on the curves: colour = pitch change, line style = component
    keys = [Line2D([], [], color=f"C{i}", label=lab) for i, lab in enumerate(labels)]
    keys += [Line2D([], [], color="k", label="$F_z$"), Line2D([], [], color="k", ls="--",
                                                             label="$F_x$")]
    ax.legend(handles=keys, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.17),
              ncols=3, frameon=False)
    plot_pitch_impulse(response, ax=ax2, labels=labels)
    ax2.legend(*ax2.get_legend_handles_labels(), fontsize=7, loc="upper center",
               bbox_to_anchor=(0.5, -0.17), ncols=2, frameon=False)
    ax2.set_xlabel(axis_label(r"$x - x_{CoM}$", UNIT["length"]))
    ax2.set_ylabel(axis_label(r"$z - z_{CoM}$", UNIT["length"]))
    fig.suptitle("metacentric test: right stance after a body-pitch change, legs fixed in the "
                 "world (CoM at origin, hip: open circle)", fontsize="medium")
    return fig


def draw_biped(ax: Any, params: Any, y: np.ndarray) -> None:
    """Draw trunk, both legs (thigh, shank, foot) of a state onto ``ax``."""
    q = np.asarray(y)[:9]
    hip = hip_position(params, q)
    com = q[:2]
    ax.plot([com[0] - (hip[0] - com[0]), hip[0]], [com[1] - (hip[1] - com[1]), hip[1]],
            "k-", lw=5, solid_capstyle="round")
    ax.plot(com[0], com[1], "ko", ms=8)
    for leg, color in ((0, "C3"), (1, "C0")):
        b = 3 + 3 * leg
        gam = q[2] + q[b + 2]
        u = np.array([np.sin(gam), np.cos(gam)])
        knee = hip - q[b] * u
        foot = hip - (q[b] + q[b + 1]) * u
        ax.plot([hip[0], knee[0]], [hip[1], knee[1]], "-", color=color, lw=3)
        ax.plot([knee[0], foot[0]], [knee[1], foot[1]], ":", color=color, lw=2)
        ax.plot(foot[0], foot[1], "o", color=color, ms=4)


def animate_biped(tr: Trajectory, path: str | Path, fps: float = 30,
                  speed: float = 0.5) -> Path:
    """Write a GIF or MP4 of the run with both legs drawn (right red, left blue).

    Frames are encoded by :func:`tslip.plotting.animation.write_frames`: atomically,
    with ffmpeg's exit status and output checked for ``.mp4``.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from .animation import gif_fps, write_frames

    path = Path(path)
    if path.suffix.lower() not in (".gif", ".mp4"):
        raise ValueError(f"animation file must end in .gif or .mp4, got {str(path)!r}")
    rate = gif_fps(fps) if path.suffix.lower() == ".gif" else float(fps)
    t_frames = np.arange(tr.time[0], tr.time[-1], speed / rate)
    idx = np.searchsorted(tr.time, t_frames).clip(0, tr.time.size - 1)
    fig = Figure(figsize=(6, 3), dpi=80, layout="constrained")  # 480 x 240 pixels
    canvas = FigureCanvasAgg(fig)
    ax = fig.subplots()

    def frames() -> Iterator[np.ndarray]:
        for i in idx:
            ax.clear()
            y = tr.data[i, 1:19]
            ax.axhline(0.0, color="0.4", lw=1)
            draw_biped(ax, tr.params, y)
            ax.set_xlim(y[0] - 1.5, y[0] + 1.5)
            ax.set_ylim(-0.1, 1.4)
            ax.set_aspect("equal")
            ax.set_title(f"t = {tr.time[i]:.2f}")
            canvas.draw()
            yield np.asarray(canvas.buffer_rgba())[..., :3].copy()

    return write_frames(path, frames(), rate, total=len(idx))
