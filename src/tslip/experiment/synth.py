"""Synthetic high-speed treadmill video of a two-legged runner with known truth.

A simulated TSLIP run (thesis Chapter 2, in the robot's SI scale of Table 5.1)
is drawn as the side view of Section 5.4: a light uneven background, a moving
treadmill belt, the body plate with two circular disc markers (position and
pitch), and two legs whose feet carry a distinct colour. The model has one
leg that is reset at lift-off; the recording alternates a near and a hind
leg: each follows the simulated stance when it is on the ground and a smooth
half-elliptical swing (relative to the hip, like the mechanism of Figure D.2)
from its lift-off to its next touch-down. The hind leg is drawn behind the
body, so its foot is occluded when it passes behind it.

Drawing is plain NumPy (no OpenCV: :mod:`tslip.experiment.video` is the only
module that imports it); each shape is rasterised with an anti-aliased edge
inside its bounding box, and moving markers are swept over the exposure
(motion blur). Image coordinates: x to the right (running direction), y down.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..model.parameters import Params
from ..model.state import TouchdownState
from ..model.units import ROBOT_SCALING, Scaling

__all__ = [
    "Camera", "BodyGeometry", "RenderOptions", "SyntheticRun", "synthesize", "render_frames",
    "write_video", "FOOT_BGR",
]

#: Foot marker colour (B, G, R): a saturated magenta found nowhere else in the scene.
FOOT_BGR = (200, 40, 230)
_DISC = 245.0          # marker disc grey level
_BODY = (70.0, 75.0, 85.0)
_LEG = (40.0, 40.0, 45.0)


@dataclass(frozen=True, slots=True)
class Camera:
    """Fixed side-view camera of Section 5.4.

    Attributes
    ----------
    width, height : int
        Frame size [px] (default 1024 x 816).
    fps : float
        Frame rate [Hz] (default 1000).
    field_width : float
        Width of the scene covered by the frame at the robot's near side [m] (0.88).
    ground_y : float
        Row of the treadmill surface [px]; default 88 % of the height.
    hip_x : float
        Column about which the hip oscillates [px]; default 45 % of the width.
    """

    width: int = 1024
    height: int = 816
    fps: float = 1000.0
    field_width: float = 0.88
    ground_y: float | None = None
    hip_x: float | None = None

    def __post_init__(self) -> None:
        if self.width < 64 or self.height < 64:
            raise ValueError(f"frame size must be at least 64 x 64 px, got {self.width} x "
                             f"{self.height}")
        if not (math.isfinite(self.fps) and self.fps > 0):
            raise ValueError(f"fps [Hz] must be > 0, got {self.fps!r}")
        if not (math.isfinite(self.field_width) and self.field_width > 0):
            raise ValueError(f"field_width [m] must be > 0, got {self.field_width!r}")

    @property
    def px_per_m(self) -> float:
        """Image scale [px/m]."""
        return self.width / self.field_width

    @property
    def ground_px(self) -> float:
        """Row of the ground line [px]."""
        return 0.88 * self.height if self.ground_y is None else float(self.ground_y)

    @property
    def hip_px(self) -> float:
        """Mean hip column [px]."""
        return 0.45 * self.width if self.hip_x is None else float(self.hip_x)


@dataclass(frozen=True, slots=True)
class BodyGeometry:
    """Where the markers sit on the body [m].

    The trunk axis ``u = (sin phi, -cos phi)`` points from the hip to the CoM
    and ``w = (cos phi, sin phi)`` is perpendicular to it (forward at
    ``phi = 0``). The discs sit at ``hip + a u +- b w``, so their midpoint is
    ``hip + a u``, the CoM is ``midpoint + (r - a) u`` and the pitch is the
    angle of the rear-to-front line (conventions: eq. A.3).

    Attributes
    ----------
    r : float
        Hip-to-CoM distance [m] (Table 5.1: 0.15).
    a : float
        Hip-to-disc-midpoint distance along the trunk axis [m].
    b : float
        Half the disc spacing [m].
    marker_radius : float
        Disc radius [m].
    foot_radius : float
        Foot marker radius [m].
    """

    r: float = 0.15
    a: float = 0.06
    b: float = 0.09
    marker_radius: float = 0.025
    foot_radius: float = 0.016

    def com_from_discs(self, front: np.ndarray, rear: np.ndarray) -> tuple[np.ndarray, np.ndarray,
                                                                             np.ndarray]:
        """CoM, hip [m] and pitch [rad] from disc centres in metres (y up).

        Parameters
        ----------
        front, rear : ndarray, shape (n, 2)
            Front and rear disc centres [m].

        Returns
        -------
        com, hip : ndarray, shape (n, 2)
        phi : ndarray, shape (n,)
        """
        d = front - rear
        phi = np.arctan2(d[:, 1], d[:, 0])
        u = np.stack([np.sin(phi), -np.cos(phi)], axis=1)
        mid = 0.5 * (front + rear)
        return mid + (self.r - self.a) * u, mid - self.a * u, phi


@dataclass(frozen=True, slots=True)
class RenderOptions:
    """Image effects of the synthetic recording.

    Attributes
    ----------
    noise : float
        Sensor noise standard deviation [grey levels of 255].
    exposure : float
        Shutter time as a fraction of the frame interval (motion blur) [-].
    flicker : float
        Relative amplitude of the brightness flicker [-].
    swing_lift : float
        Height of the swing ellipse above the straight line between lift-off
        and touch-down foot positions [m].
    seed : int
        Seed of the noise.
    """

    noise: float = 3.0
    exposure: float = 0.3
    flicker: float = 0.03
    swing_lift: float = 0.2
    seed: int = 0


@dataclass(frozen=True)
class SyntheticRun:
    """A simulated run laid out frame by frame, with its ground truth.

    Attributes
    ----------
    truth : pandas.DataFrame
        One row per frame: ``frame``, ``t`` [s], then for each marker
        (``front``, ``rear``, ``near``, ``hind``) ``<m>_x_px, <m>_y_px`` [px]
        and ``<m>_x_m, <m>_y_m`` [m] (x in the camera frame, y up from the
        ground), ``hind_visible`` (visible fraction of the hind foot),
        ``near_stance``, ``hind_stance``, and the model states ``com_x_m``,
        ``com_y_m``, ``phi``, ``hip_x_m``, ``hip_y_m``.
    params : Params
        Model that generated the run (dimensionless, Table 3.1).
    state : TouchdownState
        Touch-down state of its periodic gait.
    scaling : Scaling
        Units (Table 5.1 by default).
    camera, geometry, options
        How it was drawn.
    belt_speed : float
        Treadmill speed [m/s] (the mean forward speed of the runner).
    stance_time, flight_time : float
        Model stride times [g^-1/2 L^1/2].
    touchdowns : pandas.DataFrame
        ``t`` [s], ``leg`` ("near"/"hind"), ``liftoff_t`` [s] of each stance.
    """

    truth: pd.DataFrame
    params: Params
    state: TouchdownState
    scaling: Scaling
    camera: Camera
    geometry: BodyGeometry
    options: RenderOptions
    belt_speed: float
    stance_time: float
    flight_time: float
    touchdowns: pd.DataFrame
    _poses: dict[str, np.ndarray] = field(repr=False, default_factory=dict)

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return len(self.truth)


def synthesize(params: Params, state: TouchdownState, duration: float, *,
               camera: Camera | None = None, geometry: BodyGeometry | None = None,
               options: RenderOptions | None = None,
               scaling: Scaling = ROBOT_SCALING) -> SyntheticRun:
    """Simulate a gait and lay it out as a two-legged recording.

    Parameters
    ----------
    params : Params
        Model, with the solved ``alpha_r`` and controller reference (e.g.
        ``tslip.find_gait(p).params``).
    state : TouchdownState
        Starting touch-down state (e.g. the gait's).
    duration : float
        Length of the recording [s].
    camera, geometry, options
        Frame size and rate, marker layout, image effects.
    scaling : Scaling
        Dimensionless -> SI units (Table 5.1 robot by default).

    Returns
    -------
    SyntheticRun

    Raises
    ------
    ValueError
        If the duration is not positive or the simulated run falls.
    """
    from ..simulation import simulate

    camera = camera or Camera()
    geometry = geometry or BodyGeometry(r=params.r * scaling.L)
    options = options or RenderOptions()
    if not (math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration [s] must be > 0, got {duration!r}")
    T = scaling.factor("time")
    L = scaling.L
    stride = None
    n_frames = max(int(round(duration * camera.fps)), 1)
    # two strides of lead-in so each leg has a previous lift-off, two after
    probe = simulate(params, state, 1, dt=0.01)
    stride = probe.steps[0].stance_time + probe.steps[0].flight_time
    n_steps = int(math.ceil(duration / (stride * T))) + 5
    dt = min(0.25 / (camera.fps * T), 0.002)
    traj = simulate(params, state, n_steps, dt=dt)
    if traj.status.value != 0 or len(traj.steps) < n_steps:
        raise ValueError(f"the simulated run failed: {traj.status.reason}")
    t_all = traj["t"] * T
    td = np.array([s_t for s_t in (e.t * T for e in traj.events if e.kind == "touchdown")])
    lo = np.array([e.t * T for e in traj.events if e.kind == "liftoff"])
    foot_x = np.array([s.foot_x for s in traj.steps]) * L
    t_start = td[2]
    x_mean_speed = (np.interp(td[-1], t_all, traj["x"]) - np.interp(td[2], t_all, traj["x"])) \
        * L / (td[-1] - td[2])

    def hip_at(t: np.ndarray) -> np.ndarray:
        return np.stack([np.interp(t, t_all, traj["hip_x"]) * L,
                         np.interp(t, t_all, traj["hip_y"]) * L], axis=1)

    def pose_at(t: np.ndarray) -> dict[str, np.ndarray]:
        hip = hip_at(t)
        phi = np.interp(t, t_all, traj["phi"])
        u = np.stack([np.sin(phi), -np.cos(phi)], axis=1)
        w = np.stack([np.cos(phi), np.sin(phi)], axis=1)
        mid = hip + geometry.a * u
        out = {"hip": hip, "phi": phi, "front": mid + geometry.b * w,
               "rear": mid - geometry.b * w, "com": hip + geometry.r * u}
        for leg in (0, 1):
            out[("near", "hind")[leg]], out[f"stance{leg}"] = _foot(
                t, leg, td, lo, foot_x, hip_at, options.swing_lift)
        return out

    def to_camera(p: np.ndarray, t: np.ndarray) -> np.ndarray:
        """World [m] -> camera-frame metres (the treadmill carries the scene back)."""
        return np.stack([p[:, 0] - x_mean_speed * (t - t_start) - x0, p[:, 1]], axis=1)

    t = t_start + np.arange(n_frames) / camera.fps
    if t[-1] > td[-3]:
        raise ValueError("internal: simulated run shorter than the recording")
    x0 = float(np.interp(t_start, t_all, traj["hip_x"]) * L)
    half = 0.5 * options.exposure / camera.fps
    poses = {}
    for key, tt in (("now", t), ("a", t - half), ("b", t + half)):
        p = pose_at(tt)
        for name in ("hip", "com", "front", "rear", "near", "hind"):
            p[name] = to_camera(p[name], tt)
        poses[key] = p
    s = camera.px_per_m

    def px(p: np.ndarray) -> np.ndarray:
        return np.stack([camera.hip_px + p[:, 0] * s, camera.ground_px - p[:, 1] * s], axis=1)

    now = poses["now"]
    cols: dict[str, np.ndarray] = {"frame": np.arange(n_frames), "t": t - t_start}
    for name in ("front", "rear", "near", "hind", "hip", "com"):
        cols[f"{name}_x_px"], cols[f"{name}_y_px"] = px(now[name]).T
        cols[f"{name}_x_m"], cols[f"{name}_y_m"] = now[name].T
    cols["phi"] = now["phi"]
    cols["near_stance"] = now["stance0"]
    cols["hind_stance"] = now["stance1"]
    img = {k: {n: px(v[n]) for n in ("hip", "front", "rear", "near", "hind")}
           for k, v in poses.items()}
    img["now"]["phi"] = now["phi"]
    cols["hind_visible"] = _hind_visible(img["now"], camera, geometry)
    truth = pd.DataFrame(cols)
    legs = ["near" if i % 2 == 0 else "hind" for i in range(len(lo))]
    tds = pd.DataFrame({"t": td[: len(lo)] - t_start, "leg": legs, "liftoff_t": lo - t_start})
    tds = tds[(tds["liftoff_t"] > 0) & (tds["t"] < t[-1] - t_start)].reset_index(drop=True)
    return SyntheticRun(truth=truth, params=params, state=state, scaling=scaling, camera=camera,
                        geometry=geometry, options=options, belt_speed=float(x_mean_speed),
                        stance_time=float(traj.steps[0].stance_time),
                        flight_time=float(traj.steps[0].flight_time), touchdowns=tds,
                        _poses=img)


def _foot(t: np.ndarray, leg: int, td: np.ndarray, lo: np.ndarray, foot_x: np.ndarray,
          hip_at: Callable[[np.ndarray], np.ndarray], lift: float) -> tuple[np.ndarray,
                                                                            np.ndarray]:
    """World foot position [m] of leg ``leg`` (strides ``leg``, ``leg + 2``, ...)."""
    out = np.empty((len(t), 2))
    stance = np.zeros(len(t), dtype=bool)
    n = len(lo)
    for i in range(leg, n, 2):
        m = (t >= td[i]) & (t < lo[i])
        out[m] = (foot_x[i], 0.0)
        stance |= m
        if i + 2 < len(td) and i + 2 < n:
            m = (t >= lo[i]) & (t < td[i + 2])
            if m.any():
                p0 = np.array([foot_x[i], 0.0]) - hip_at(np.array([lo[i]]))[0]
                p1 = np.array([foot_x[i + 2], 0.0]) - hip_at(np.array([td[i + 2]]))[0]
                sw = (t[m] - lo[i]) / (td[i + 2] - lo[i])
                ease = 0.5 * (1.0 - np.cos(np.pi * sw))
                rel = p0 + np.outer(ease, p1 - p0)
                rel[:, 1] += lift * np.sin(np.pi * sw)
                out[m] = hip_at(t[m]) + rel
    return out, stance


def _body_corners(hip: np.ndarray, phi: float, g: BodyGeometry, s: float) -> np.ndarray:
    """Corners [px] of the body plate: trunk-frame box around hip..CoM."""
    u = np.array([math.sin(phi), math.cos(phi)])     # image y points down
    w = np.array([math.cos(phi), -math.sin(phi)])
    top, bottom, half = -0.05 * s, (g.r + 0.06) * s, (g.b + g.marker_radius + 0.01) * s
    return np.array([hip + top * u - half * w, hip + top * u + half * w,
                     hip + bottom * u + half * w, hip + bottom * u - half * w])


def _hind_visible(img: dict[str, np.ndarray], camera: Camera, g: BodyGeometry) -> np.ndarray:
    """Visible fraction of the hind-foot disc (the body plate hides it)."""
    s = camera.px_per_m
    rf = g.foot_radius * s
    ang = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    rad = np.sqrt(np.linspace(0.05, 1.0, 6))
    pts = np.array([(rr * math.cos(a), rr * math.sin(a)) for rr in rad for a in ang]) * rf
    out = np.ones(len(img["hip"]))
    for k in range(len(out)):
        c = _body_corners(img["hip"][k], float(img["phi"][k]), g, s)
        out[k] = 1.0 - np.mean(_inside_quad(img["hind"][k] + pts, c))
    return out


def _inside_quad(p: np.ndarray, c: np.ndarray) -> np.ndarray:
    sign = None
    inside = np.ones(len(p), dtype=bool)
    for i in range(4):
        a, b = c[i], c[(i + 1) % 4]
        cross = (b[0] - a[0]) * (p[:, 1] - a[1]) - (b[1] - a[1]) * (p[:, 0] - a[0])
        sgn = cross >= 0
        if sign is None:
            sign = sgn
        inside &= sgn == sign
    return inside


# -- rendering ------------------------------------------------------------------------------


def render_frames(run: SyntheticRun, *, start: int = 0, stop: int | None = None
                  ) -> Iterator[np.ndarray]:
    """Yield the frames of ``run`` as BGR ``uint8`` arrays, shape (height, width, 3).

    Frames are produced one at a time (memory independent of length).
    """
    cam, g, opt = run.camera, run.geometry, run.options
    H, W, s = cam.height, cam.width, cam.px_per_m
    rng = np.random.default_rng(opt.seed)
    background = _background(cam, rng)
    belt, period = _belt(cam)
    gy = int(round(cam.ground_px))
    noise_bank = (rng.normal(0.0, opt.noise, size=(H + 97, W, 3))).astype(np.float32) \
        if opt.noise > 0 else None
    gains = 1.0 + opt.flicker * (0.6 * np.sin(2 * np.pi * 100.0 * run.truth["t"].to_numpy())
                                 + 0.4 * rng.uniform(-1, 1, run.n_frames))
    P = run._poses
    stop = run.n_frames if stop is None else min(stop, run.n_frames)
    leg_w = 0.012 * s
    for k in range(start, stop):
        f = background.copy()
        shift = int(round(run.belt_speed * run.truth["t"].iat[k] * s)) % period
        f[gy:, :] = belt[:, shift:shift + W]
        hip = P["now"]["hip"][k]
        phi = float(P["now"]["phi"][k])
        _capsule(f, hip, P["now"]["hind"][k], leg_w / 2, _LEG, 0.75)
        _capsule(f, P["a"]["hind"][k], P["b"]["hind"][k], g.foot_radius * s, FOOT_BGR, 1.0)
        _quad(f, _body_corners(hip, phi, g, s), _BODY)
        _capsule(f, hip, P["now"]["near"][k], leg_w / 2, _LEG, 1.0)
        for name in ("front", "rear"):
            _capsule(f, P["a"][name][k], P["b"][name][k], g.marker_radius * s,
                     (_DISC, _DISC, _DISC), 1.0)
        _capsule(f, hip, hip, 0.01 * s, (30.0, 30.0, 30.0), 1.0)
        _capsule(f, P["a"]["near"][k], P["b"]["near"][k], g.foot_radius * s, FOOT_BGR, 1.0)
        f *= gains[k]
        if noise_bank is not None:
            off = (k * 37) % 97
            f += noise_bank[off:off + H]
        np.clip(f, 0, 255, out=f)
        yield f.astype(np.uint8)


def _background(cam: Camera, rng: np.random.Generator) -> np.ndarray:
    H, W = cam.height, cam.width
    yy, xx = np.mgrid[0:H, 0:W].astype(np.float32)
    base = 205.0 + 20.0 * (xx / W) - 15.0 * (yy / H)
    for _ in range(6):
        cx, cy, rr = rng.uniform(0, W), rng.uniform(0, H), rng.uniform(0.1, 0.3) * W
        base += rng.uniform(-8, 8) * np.exp(-((xx - cx) ** 2 + (yy - cy) ** 2) / (2 * rr * rr))
    img = np.repeat(base[:, :, None], 3, axis=2)
    img[:, :, 0] -= 6.0  # slightly warm white paper
    # a dark vertical support post of the acrylic sheet (static scene element)
    x0 = int(0.05 * W)
    img[: int(0.88 * H), x0:x0 + max(int(0.02 * W), 2)] = (90.0, 110.0, 140.0)
    return img


def _belt(cam: Camera) -> tuple[np.ndarray, int]:
    H, W = cam.height, cam.width
    gy = int(round(cam.ground_px))
    period = max(int(0.08 * cam.px_per_m), 8)
    xs = np.arange(W + period)
    stripe = 60.0 + 25.0 * (np.sin(2 * np.pi * xs / period) > 0.6)
    rows = np.clip(np.arange(H - gy, dtype=np.float32)[:, None] / 4.0, 0, 1)
    belt = (stripe[None, :] * (0.8 + 0.2 * rows)).astype(np.float32)
    return np.repeat(belt[:, :, None], 3, axis=2), period


def _paint(f: np.ndarray, y0: int, x0: int, alpha: np.ndarray, color: tuple[float, ...]) -> None:
    roi = f[y0:y0 + alpha.shape[0], x0:x0 + alpha.shape[1]]
    a = alpha[:, :, None]
    roi *= 1.0 - a
    roi += a * np.asarray(color, dtype=np.float32)


def _bbox(f: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[int, int, int, int] | None:
    H, W = f.shape[:2]
    x0, y0 = max(int(math.floor(lo[0])), 0), max(int(math.floor(lo[1])), 0)
    x1, y1 = min(int(math.ceil(hi[0])) + 1, W), min(int(math.ceil(hi[1])) + 1, H)
    if x1 <= x0 or y1 <= y0:
        return None
    return x0, y0, x1, y1


def _capsule(f: np.ndarray, a: np.ndarray, b: np.ndarray, radius: float,
             color: tuple[float, ...], opacity: float) -> None:
    """Anti-aliased disc of ``radius`` [px] swept from ``a`` to ``b`` (pixel centres)."""
    box = _bbox(f, np.minimum(a, b) - radius - 2, np.maximum(a, b) + radius + 2)
    if box is None:
        return
    x0, y0, x1, y1 = box
    xs = np.arange(x0, x1, dtype=np.float32)[None, :]
    ys = np.arange(y0, y1, dtype=np.float32)[:, None]
    d = b - a
    dd = float(d @ d)
    if dd < 1e-9:
        dist = np.sqrt((xs - a[0]) ** 2 + (ys - a[1]) ** 2)
    else:
        tt = np.clip(((xs - a[0]) * d[0] + (ys - a[1]) * d[1]) / dd, 0.0, 1.0)
        dist = np.sqrt((xs - a[0] - tt * d[0]) ** 2 + (ys - a[1] - tt * d[1]) ** 2)
    alpha = np.clip(radius + 0.5 - dist, 0.0, 1.0) * opacity
    _paint(f, y0, x0, alpha, color)


def _quad(f: np.ndarray, c: np.ndarray, color: tuple[float, ...]) -> None:
    """Anti-aliased convex quadrilateral with corners ``c`` (order around the edge)."""
    box = _bbox(f, c.min(axis=0) - 1, c.max(axis=0) + 1)
    if box is None:
        return
    x0, y0, x1, y1 = box
    xs = np.arange(x0, x1, dtype=np.float32)[None, :]
    ys = np.arange(y0, y1, dtype=np.float32)[:, None]
    orient = np.sign((c[1, 0] - c[0, 0]) * (c[2, 1] - c[0, 1])
                     - (c[1, 1] - c[0, 1]) * (c[2, 0] - c[0, 0]))
    sd = None
    for i in range(4):
        p, q = c[i], c[(i + 1) % 4]
        e = q - p
        n = float(np.hypot(*e))
        side = orient * ((e[0]) * (ys - p[1]) - (e[1]) * (xs - p[0])) / n  # > 0 inside
        sd = side if sd is None else np.minimum(sd, side)
    _paint(f, y0, x0, np.clip(sd + 0.5, 0.0, 1.0), color)


def write_video(run: SyntheticRun, path: str | Path, *, quality: int = 16,
                progress: Callable[[int, int], None] | None = None) -> Path:
    """Render ``run`` to an ``.mp4`` (H.264 via imageio-ffmpeg) or a folder of PNG frames.

    Parameters
    ----------
    run : SyntheticRun
        What to draw.
    path : str or Path
        ``*.mp4`` file, or a directory (created) for ``frame_000000.png`` ...
    quality : int
        H.264 constant rate factor (lower is better; 0 is lossless).
    progress : callable, optional
        ``progress(done, total)`` after each frame.

    Returns
    -------
    Path
        The written file or folder (an ``.mp4`` is written atomically).
    """
    import imageio.v2 as iio

    from .._io import atomic_write

    path = Path(path)
    n = run.n_frames
    if path.suffix.lower() == ".mp4":
        def write(tmp: str) -> None:
            w = iio.get_writer(tmp, format="FFMPEG", mode="I", fps=run.camera.fps,
                               codec="libx264", quality=None, macro_block_size=1,
                               pixelformat="yuv420p", ffmpeg_log_level="error",
                               output_params=["-crf", str(quality), "-preset", "veryfast"])
            try:
                for k, frame in enumerate(render_frames(run)):
                    w.append_data(frame[:, :, ::-1])
                    if progress is not None:
                        progress(k + 1, n)
            finally:
                w.close()

        return atomic_write(path, write)
    if path.suffix:
        raise ValueError(f"video output must be a .mp4 file or a directory, got {str(path)!r}")
    path.mkdir(parents=True, exist_ok=True)
    for k, frame in enumerate(render_frames(run)):
        iio.imwrite(path / f"frame_{k:06d}.png", frame[:, :, ::-1])
        if progress is not None:
            progress(k + 1, n)
    return path
