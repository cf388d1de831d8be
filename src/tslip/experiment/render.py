"""Drawing the frames of a :class:`~tslip.experiment.synth.SyntheticRun`, and writing them.

Plain NumPy (no OpenCV: :mod:`tslip.experiment.video` is the only module that
imports it): each shape is rasterised with an anti-aliased edge inside its
bounding box, and moving markers are swept over the exposure (motion blur).
Image coordinates: x to the right (running direction), y down.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np

from .._renamed import module_getattr
from .synth import Camera, SyntheticRun, _body_corners

__all__ = ["camera_frames", "write_video", "check_mp4_size", "FOOT_BGR"]


def check_mp4_size(width: int, height: int) -> None:
    """Refuse a frame size libx264 / yuv420p cannot encode (odd width or height)."""
    if width % 2 or height % 2:
        raise ValueError(f"--width and --height must be even for an .mp4 (libx264, yuv420p), "
                         f"got {width} x {height} px; use even sizes or a folder of PNGs")

#: Foot marker colour (B, G, R): a saturated magenta found nowhere else in the scene.
FOOT_BGR = (200, 40, 230)
_DISC = 245.0          # marker disc grey level
_BODY = (70.0, 75.0, 85.0)
_LEG = (40.0, 40.0, 45.0)


def camera_frames(run: SyntheticRun, *, start: int = 0, stop: int | None = None
                  ) -> Iterator[np.ndarray]:
    """Yield the frames of ``run`` as BGR ``uint8`` arrays, shape (height, width, 3).

    Frames are produced one at a time (memory independent of length). Named
    ``render_frames`` before 0.3, the name of :func:`tslip.plotting.render_frames`
    (RGB figures of a trajectory); the old name warns until 0.4.
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
    times = run.truth["t"].to_numpy(float)
    for k in range(start, stop):
        f = background.copy()
        shift = int(round(run.belt_speed * times[k] * s)) % period
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
    sd: np.ndarray | None = None
    for i in range(4):
        p, q = c[i], c[(i + 1) % 4]
        e = q - p
        n = float(np.hypot(*e))
        side = orient * ((e[0]) * (ys - p[1]) - (e[1]) * (xs - p[0])) / n  # > 0 inside
        sd = side if sd is None else np.minimum(sd, side)
    if sd is not None:  # always: the loop ran four times
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

    from .._io import write_mp4

    path = Path(path)
    n = run.n_frames
    if path.suffix.lower() == ".mp4":
        check_mp4_size(run.camera.width, run.camera.height)
        frames = (f[:, :, ::-1] for f in camera_frames(run))  # BGR -> RGB
        return write_mp4(path, frames, run.camera.fps, crf=quality, preset="veryfast",
                         progress=progress, total=n)
    if path.suffix:
        raise ValueError(f"video output must be a .mp4 file or a directory, got {str(path)!r}")
    path.mkdir(parents=True, exist_ok=True)
    for k, frame in enumerate(camera_frames(run)):
        iio.imwrite(path / f"frame_{k:06d}.png", frame[:, :, ::-1])
        if progress is not None:
            progress(k + 1, n)
    return path


#: Old names (deprecated, removed in 0.4).
__getattr__ = module_getattr(__name__, {
    "render_frames": ("tslip.experiment.render.camera_frames", lambda: camera_frames),
})
