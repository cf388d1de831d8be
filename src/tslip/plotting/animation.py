"""Animation of a run: the runner drawn frame by frame to a GIF or MP4.

Frames are rendered off-screen with matplotlib's Agg canvas and written with
Pillow (``.gif``) or imageio-ffmpeg / libx264 (``.mp4``).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Ellipse, FancyArrowPatch

from .._io import atomic_write, write_mp4
from ..simulation.result import TRAJECTORY_COLUMNS
from .trajectories import ground_profile

if TYPE_CHECKING:
    from ..model.parameters import Params
    from ..model.terrain import Terrain
    from ..simulation.result import Trajectory

__all__ = ["animate", "frame_times", "render_frames", "TIME_UNIT_1M", "Pose", "pose",
           "sample", "trunk_length", "TRUNK_WIDTH", "FORCE_SCALE"]

#: Seconds per model time unit g^-1/2 L^1/2 for a 1 m leg on Earth.
TIME_UNIT_1M = math.sqrt(1.0 / 9.81)

_SUFFIXES = (".gif", ".mp4")
_COL = {name: i for i, name in enumerate(TRAJECTORY_COLUMNS)}
#: The trunk's drawn width [l0] and the ground force arrow's length [l0 per Mg].
TRUNK_WIDTH = 0.26
FORCE_SCALE = 0.15


def frame_times(
    traj: Trajectory, fps: float = 30.0, speed: float = 0.25, time_unit: float = TIME_UNIT_1M
) -> np.ndarray:
    """Model times [g^-1/2 L^1/2] of the video frames.

    One second of video shows ``speed / time_unit`` model time units, so
    ``speed = 0.25`` is quarter speed for a runner with ``time_unit``
    seconds per model time unit (default: 1 m leg, Earth gravity).
    """
    for name, value in (("fps", fps), ("speed", speed), ("time_unit", time_unit)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    t = traj["t"]
    if len(t) == 0:
        raise ValueError("trajectory has no samples to animate")
    step = speed / (fps * time_unit)
    ts = np.arange(float(t[0]), float(t[-1]), step)
    return np.append(ts, float(t[-1])) if len(ts) == 0 or ts[-1] < t[-1] - 1e-12 else ts


def _sample(data: np.ndarray, t_frames: np.ndarray) -> np.ndarray:
    """Rows of ``data`` at ``t_frames``: linear in time within a phase.

    Across a touch-down or lift-off (where the leg is reset) the nearer
    sample is used instead, so the leg never sweeps through the reset.
    """
    t = data[:, _COL["t"]]
    n = len(t)
    if n == 1:
        return np.repeat(data, len(t_frames), axis=0)
    k = np.clip(np.searchsorted(t, t_frames, side="right") - 1, 0, n - 2)
    span = t[k + 1] - t[k]
    w = np.where(span > 0, (t_frames - t[k]) / np.where(span > 0, span, 1.0), 0.0)
    w = np.clip(w, 0.0, 1.0)
    stance = data[:, _COL["stance"]]
    jump = stance[k] != stance[k + 1]
    w = np.where(jump, np.round(w), w)
    return data[k] * (1.0 - w)[:, None] + data[k + 1] * w[:, None]


def sample(traj: Trajectory, t_frames: np.ndarray) -> np.ndarray:
    """The trajectory's rows (``TRAJECTORY_COLUMNS``) at ``t_frames``, as the frames show them."""
    return _sample(traj.data, np.asarray(t_frames, dtype=float))


def trunk_length(params: Params) -> float:
    """The drawn trunk's length [L]: ``|r| + l0 / 2``, hip and CoM inside it."""
    return abs(params.r) + 0.5 * params.l0


class Pose(NamedTuple):
    """The runner's drawing at one sample: points [L], the leg, the trunk and the force."""

    com: np.ndarray
    hip: np.ndarray
    foot: np.ndarray
    stance: bool
    spring: np.ndarray  #: (n, 2) zig-zag polyline from the hip to the foot
    centre: np.ndarray  #: the trunk's centre, midway between hip and CoM
    angle: float  #: the trunk's long axis from the x axis [rad]: phi + pi/2
    axis: np.ndarray  #: (2, 2) ends of the trunk's axis
    grf: np.ndarray | None  #: tip of the ground force arrow from the foot (stance, force > 0)


def pose(row: np.ndarray, l0: float, trunk_len: float) -> Pose:
    """The :class:`Pose` of one trajectory row (``TRAJECTORY_COLUMNS``).

    The trunk lies along the hip-CoM axis, hip = CoM + r (-sin phi, cos phi)
    (docs/conventions.md); the leg is a spring from the hip to the foot.
    """
    c = _COL
    x, y, phi = row[c["x"]], row[c["y"]], row[c["phi"]]
    com = np.array([x, y])
    hip = np.array([row[c["hip_x"]], row[c["hip_y"]]])
    foot = np.array([row[c["foot_x"]], row[c["foot_y"]]])
    stance = bool(row[c["stance"]] > 0.5)
    up = np.array([-math.sin(phi), math.cos(phi)])
    centre = 0.5 * (hip + com)
    axis = np.array([centre - 0.5 * trunk_len * up, centre + 0.5 * trunk_len * up])
    fx, fy = row[c["Fx"]], row[c["Fy"]]
    grf = (foot + FORCE_SCALE * l0 * np.array([fx, fy])
           if stance and math.hypot(fx, fy) > 1e-3 else None)
    return Pose(com, hip, foot, stance, _spring(hip, foot, l0), centre,
                float(phi) + 0.5 * math.pi, axis, grf)


def _spring(hip: np.ndarray, foot: np.ndarray, l0: float, n_coils: int = 7) -> np.ndarray:
    """Zig-zag polyline from hip to foot, straight near both ends."""
    d = foot - hip
    length = float(np.hypot(*d))
    if length < 1e-12:
        return np.array([hip, foot])
    u = d / length
    nrm = np.array([-u[1], u[0]])
    lead = min(0.18 * l0, 0.3 * length)
    s = np.linspace(lead, length - lead, 2 * n_coils + 1)
    amp = 0.06 * l0 * np.ones_like(s)
    amp[0] = amp[-1] = 0.0
    amp[1:-1] *= np.where(np.arange(1, len(s) - 1) % 2 == 0, 1.0, -1.0)
    pts = hip + s[:, None] * u + amp[:, None] * nrm
    return np.vstack([hip, pts, foot])


class _Scene:
    """The matplotlib artists of one frame, updated in place."""

    def __init__(
        self,
        traj: Trajectory,
        width_px: int,
        height_px: int,
        dpi: float,
        terrain: Terrain | None,
        view_width: float | None,
    ) -> None:
        p = traj.params
        self.l0 = p.l0
        self.fig = Figure(figsize=(width_px / dpi, height_px / dpi), dpi=dpi)
        self.canvas = FigureCanvasAgg(self.fig)
        ax = self.fig.add_axes((0.0, 0.0, 1.0, 1.0))
        ax.set_axis_off()
        self.ax = ax
        gx, gy = ground_profile(traj, terrain, margin=4.0 * p.l0)
        self.gx, self.gy = gx, gy
        self.view_w = view_width or 4.0 * p.l0
        self.view_h = self.view_w * height_px / width_px
        # ground: filled, with tick marks that move with the camera
        ax.fill_between(gx, gy, float(np.min(gy)) - self.view_h, color="0.85", lw=0, zorder=0)
        ax.plot(gx, gy, color="k", lw=1.5, zorder=1)
        ticks_x = np.arange(gx[0], gx[-1], 0.25 * p.l0)
        ticks_h = np.interp(ticks_x, gx, gy)
        segs = np.stack(
            [
                np.column_stack([ticks_x, ticks_h]),
                np.column_stack([ticks_x - 0.08 * p.l0, ticks_h - 0.08 * p.l0]),
            ],
            axis=1,
        )
        ax.add_collection(LineCollection(list(segs), colors="0.45", lw=0.8, zorder=1))
        # footholds of the run (faint marks)
        feet = [(e.foot_x, e.foot_y) for e in traj.events if e.kind == "touchdown"]
        if feet:
            fx, fy = np.array(feet).T
            ax.plot(fx, fy, ls="none", marker="|", ms=8, color="0.5", zorder=1)
        (self.trail,) = ax.plot([], [], color="C0", lw=1, alpha=0.6, zorder=2)
        (self.leg,) = ax.plot([], [], color="0.15", lw=1.6, solid_joinstyle="miter", zorder=5)
        self.trunk_len = trunk_len = trunk_length(p)
        self.body = Ellipse(
            (0, 0), trunk_len, TRUNK_WIDTH * p.l0, angle=90.0, fc="#9ecae1", ec="#08519c", lw=1.5,
            zorder=3,
        )
        ax.add_patch(self.body)
        (self.axis,) = ax.plot([], [], color="#08519c", lw=1.2, zorder=4)
        self.hip = Circle((0, 0), 0.035 * p.l0, fc="white", ec="k", lw=1.2, zorder=6)
        ax.add_patch(self.hip)
        self.com = Circle((0, 0), 0.045 * p.l0, fc="k", ec="k", lw=1.0, zorder=6)
        ax.add_patch(self.com)
        self.foot = Circle((0, 0), 0.03 * p.l0, fc="C3", ec="k", lw=1.0, zorder=6)
        ax.add_patch(self.foot)
        self.grf = FancyArrowPatch(
            (0, 0),
            (0, 1),
            arrowstyle="-|>",
            mutation_scale=12,
            color="#e34a33",
            alpha=0.6,
            lw=3.0,
            zorder=7,
        )
        ax.add_patch(self.grf)
        self.text = ax.text(
            0.015,
            0.97,
            "",
            transform=ax.transAxes,
            va="top",
            ha="left",
            family="monospace",
            fontsize=9,
            zorder=8,
        )

    def update(self, row: np.ndarray, trail: np.ndarray, step_no: int) -> None:
        q = pose(row, self.l0, self.trunk_len)
        x = q.com[0]
        self.ax.set_xlim(x - 0.4 * self.view_w, x + 0.6 * self.view_w)
        ground = float(np.interp(x, self.gx, self.gy))
        self.ax.set_ylim(ground - 0.12 * self.view_h, ground + 0.88 * self.view_h)
        self.trail.set_data(trail[:, 0], trail[:, 1])
        self.leg.set_data(q.spring[:, 0], q.spring[:, 1])
        self.body.set_center(tuple(q.centre))
        self.body.set_angle(math.degrees(q.angle))
        self.axis.set_data(q.axis[:, 0], q.axis[:, 1])
        self.hip.set_center(tuple(q.hip))
        self.com.set_center(tuple(q.com))
        self.foot.set_center(tuple(q.foot))
        self.foot.set_facecolor("C3" if q.stance else "white")
        if q.grf is not None:
            self.grf.set_positions(tuple(q.foot), tuple(q.grf))
            self.grf.set_visible(True)
        else:
            self.grf.set_visible(False)
        self.text.set_text(
            f"t = {row[_COL['t']]:6.3f}  step {step_no:3d}  {'stance' if q.stance else 'flight'}"
        )

    def render(self) -> np.ndarray:
        self.canvas.draw()
        return np.asarray(self.canvas.buffer_rgba())[..., :3].copy()


def render_frames(
    traj: Trajectory,
    t_frames: np.ndarray,
    *,
    size: tuple[int, int] = (640, 360),
    dpi: float = 100.0,
    terrain: Terrain | None = None,
    view_width: float | None = None,
    trail_time: float = 3.0,
) -> Iterator[np.ndarray]:
    """Yield RGB frames, ``uint8`` arrays of shape ``(height, width, 3)``.

    Parameters
    ----------
    traj : Trajectory
    t_frames : ndarray
        Model times [g^-1/2 L^1/2] of the frames (see :func:`frame_times`).
    size : (int, int)
        Frame width and height in pixels.
    dpi : float
        Resolution; the figure is ``size / dpi`` inches, so a larger ``dpi``
        draws thicker lines and larger text in the same frame.
    terrain : Terrain, optional
        Ground to draw; rebuilt from the touch-downs by default.
    view_width : float, optional
        Width of the camera view [L], default ``4 l0``.
    trail_time : float
        Length of the CoM trail [g^-1/2 L^1/2].
    """
    width, height = (int(v) for v in size)
    if width < 16 or height < 16:
        raise ValueError(f"size must be at least 16 x 16 pixels, got {size!r}")
    if not (math.isfinite(dpi) and dpi > 0):
        raise ValueError(f"dpi must be a finite number > 0, got {dpi!r}")
    scene = _Scene(traj, width, height, dpi, terrain, view_width)
    rows = _sample(traj.data, np.asarray(t_frames, dtype=float))
    t = traj["t"]
    com = traj.data[:, [_COL["x"], _COL["y"]]]
    step_col = traj["step"]
    for tf, row in zip(t_frames, rows, strict=True):
        k = int(np.searchsorted(t, tf, side="right"))
        k0 = int(np.searchsorted(t, tf - trail_time, side="left"))
        trail = np.vstack([com[k0:k], row[[_COL["x"], _COL["y"]]]])
        scene.update(row, trail, int(step_col[max(k - 1, 0)]))
        frame = scene.render()
        if frame.shape[:2] != (height, width):  # dpi rounding: pad/crop to size
            out = np.full((height, width, 3), 255, dtype=np.uint8)
            h, w = min(height, frame.shape[0]), min(width, frame.shape[1])
            out[:h, :w] = frame[:h, :w]
            frame = out
        yield frame


def checked_output(path: str | os.PathLike[str], fps: float, size: tuple[int, int]
                   ) -> tuple[Path, float]:
    """The animation file and its frame rate, checked (one-line ``ValueError``): a ``.gif``
    or ``.mp4`` suffix, ``fps`` finite and > 0 (a ``.gif``'s as :func:`gif_fps` rounds it),
    an ``.mp4``'s ``size`` in multiples of 8 pixels. Shared by every animation writer."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in _SUFFIXES:
        raise ValueError(f"animation file must end in .gif or .mp4, got {str(path)!r}")
    if not (math.isfinite(fps) and fps > 0):
        raise ValueError(f"fps must be a finite number > 0, got {fps!r}")
    if suffix == ".gif":
        fps = gif_fps(fps)
    elif size[0] % 8 or size[1] % 8:
        raise ValueError(f"size must be multiples of 8 pixels for .mp4, got {size!r}")
    return path, fps


def animate(
    traj: Trajectory,
    path: str | os.PathLike[str],
    fps: float = 30.0,
    speed: float = 0.25,
    dpi: float = 100.0,
    *,
    size: tuple[int, int] = (640, 360),
    time_unit: float = TIME_UNIT_1M,
    terrain: Terrain | None = None,
    view_width: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Write an animation of the runner to ``.gif`` or ``.mp4``.

    The trunk is drawn as an ellipse along the hip-CoM axis with the hip
    (white) and CoM (black) marked, the leg as a zig-zag spring from the hip
    to the foot (at rest length ``l0`` in flight), the ground reaction force
    as a red arrow at the foot in stance (0.15 l0 per Mg), and the CoM trail.
    The camera follows the CoM. GIFs are written with Pillow (each frame
    quantised to 64 colours, which is about five times faster than letting
    the encoder choose), MP4s with imageio-ffmpeg (libx264, yuv420p).

    Parameters
    ----------
    traj : Trajectory
    path : str or PathLike
        Output file, ending in ``.gif`` or ``.mp4``; written atomically.
    fps : float
        Frames per second. GIF frame delays are whole hundredths of a
        second, so for ``.gif`` the rate is rounded to ``100 / round(100 / fps)``.
    speed : float
        Playback speed relative to real time (0.25: four times slower).
    dpi : float
        Figure resolution (scales lines and text; the frame stays ``size``).
    size : (int, int)
        Frame width and height in pixels (``.mp4`` needs multiples of 8).
    time_unit : float
        Seconds per model time unit g^-1/2 L^1/2 (default: 1 m leg, 9.81 m/s^2).
    terrain : Terrain, optional
        Ground to draw; rebuilt from the touch-downs by default.
    view_width : float, optional
        Width of the camera view [L], default ``4 l0``.
    progress : callable, optional
        Called as ``progress(done, total)`` after each frame.

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    ValueError
        For a bad suffix, a non-positive ``fps``/``speed``/``dpi``, or an
        empty trajectory.
    """
    path, fps = checked_output(path, fps, size)
    t_frames = frame_times(traj, fps, speed, time_unit)
    frames = render_frames(
        traj, t_frames, size=size, dpi=dpi, terrain=terrain, view_width=view_width
    )
    return write_frames(path, frames, fps, total=len(t_frames), progress=progress)


def gif_fps(fps: float) -> float:
    """The frame rate a GIF can show: a whole number of centiseconds a frame, at least 2."""
    return 100.0 / max(2, round(100.0 / fps))  # browsers treat < 2 cs as 10 cs


def write_frames(
    path: str | Path,
    frames: Iterable[np.ndarray],
    fps: float,
    *,
    total: int = 0,
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Write RGB frames to ``.gif`` (Pillow) or ``.mp4`` (:func:`tslip._io.write_mp4`)."""
    path = Path(path)
    if path.suffix.lower() == ".gif":
        delay_ms = 10 * max(2, round(100.0 / fps))
        atomic_write(path, lambda tmp: _write_gif(tmp, frames, delay_ms, total, progress))
        return path
    return write_mp4(path, frames, fps, progress=progress, total=total)


def _write_gif(
    path: str,
    frames: Iterable[np.ndarray],
    duration_ms: int,
    total: int,
    progress: Callable[[int, int], None] | None,
) -> None:
    from PIL import Image

    def quantised() -> Iterator[Image.Image]:
        for i, frame in enumerate(frames):
            yield Image.fromarray(frame).quantize(
                colors=64, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE
            )
            if progress is not None:
                progress(i + 1, total)

    images = quantised()
    first = next(images)
    first.save(
        path,
        format="GIF",
        save_all=True,
        append_images=images,
        duration=duration_ms,
        loop=0,
        disposal=1,
    )

