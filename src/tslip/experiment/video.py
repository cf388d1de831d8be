"""Marker tracking in side-view video (thesis Section 5.5, Figures D.3-D.4).

Body: a region of interest around the last known position, grey scale, Canny
edges and a Hough circle transform tuned to the disc size; each circle is
refined to sub-pixel accuracy by a least-squares circle through its Canny
edge pixels, and the two discs give position and pitch. Feet: a MOG2
background subtractor masks the static scene, an HSV range keeps the foot
colour, ellipses are fitted to the blobs and the two largest are the feet
(coarse to fine: the moving foot-coloured blobs are found in a down-sampled
frame, the HSV mask and ellipse fits run at full resolution in crops around
them).
Each new point joins the series whose last known point is nearest; gaps stay
gaps. Frames are processed as a stream, so memory does not grow with length.

This is the only module of :mod:`tslip` that imports OpenCV (lazily, inside
functions), so ``import tslip`` stays fast.

Over 600 lines: one concept, marker tracking on one frame stream (body, feet, linking).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .._results import Result, with_units
from .synth import recording_units

# libav's own messages (e.g. "moov atom not found") would go straight to stderr beside
# our one-line error; OpenCV reads this before it first opens a file.
os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")

__all__ = [
    "Calibration", "TrackerOptions", "TrackResult", "VideoError", "open_video",
    "measure_calibration", "track_video", "track_frames", "QUALITY",
]

#: Detection-quality flags of the tracks table.
QUALITY = {"missing": 0, "ok": 1, "partial": 2}


class VideoError(ValueError):
    """The video is missing, unreadable or has no usable frames."""


@dataclass(frozen=True, slots=True)
class Calibration:
    """Pixel -> metre mapping of a fixed camera.

    Attributes
    ----------
    px_per_m : float
        Image scale [px/m].
    ground_y : float
        Image row of the ground (treadmill surface) [px].
    x0 : float
        Image column of x = 0 [px].
    """

    px_per_m: float
    ground_y: float
    x0: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.px_per_m) and self.px_per_m > 0):
            raise ValueError(f"calibration scale [px/m] must be > 0, got {self.px_per_m!r}")

    def to_metres(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Image (x right, y down) [px] -> (x forward, y up from the ground) [m]."""
        return (np.asarray(x) - self.x0) / self.px_per_m, \
            (self.ground_y - np.asarray(y)) / self.px_per_m


@dataclass(frozen=True, slots=True)
class TrackerOptions:
    """Tuning of the tracker.

    Attributes
    ----------
    marker_radius : float
        Disc marker radius [px].
    marker_spacing : float
        Centre distance of the two discs [px].
    foot_radius : float
        Foot marker radius [px] (for the expected blob area).
    roi_margin : float
        Margin of the body region of interest around the predicted discs
        [px]; it grows by this much per frame while the discs are lost.
    canny_low, canny_high : float
        Canny hysteresis thresholds [grey levels].
    hough_votes : float
        Hough accumulator threshold (``param2``).
    foot_hsv_low, foot_hsv_high : tuple of int
        HSV range of the foot colour (OpenCV ranges: H 0-179).
    bg_scale : int
        Down-sampling of the background subtractor's input and of the first,
        coarse foot-colour search [-].
    bg_history : int
        MOG2 history [frames].
    bg_ratio : float
        MOG2 background ratio: weight of the modes that count as background [-].
    bg_warmup : int
        Frames during which the background model is still being learned and
        the colour mask is used alone [frames].
    partial_area : float
        A foot blob smaller than this fraction of the expected area is flagged
        partial (occluded) and not used as a position [-].
    """

    marker_radius: float
    marker_spacing: float
    foot_radius: float
    roi_margin: float = 40.0
    canny_low: float = 40.0
    canny_high: float = 120.0
    hough_votes: float = 14.0
    foot_hsv_low: tuple[int, int, int] = (140, 100, 80)
    foot_hsv_high: tuple[int, int, int] = (170, 255, 255)
    bg_scale: int = 4
    bg_history: int = 300
    bg_ratio: float = 0.7
    bg_warmup: int = 30
    partial_area: float = 0.9

    @classmethod
    def for_scale(cls, px_per_m: float, *, marker_radius: float = 0.025,
                  marker_spacing: float = 0.18, foot_radius: float = 0.016,
                  **kw: Any) -> TrackerOptions:
        """Options from marker sizes in metres [m] and an image scale [px/m].

        The body search margin is 15 mm (at least 12 px) beyond the predicted
        discs, and the background model's down-sampling keeps about three
        samples per foot-marker radius (``bg_scale = foot radius / 3``, 1-8),
        unless given in ``kw``.
        """
        foot_px = foot_radius * px_per_m
        kw.setdefault("roi_margin", max(0.015 * px_per_m, 12.0))
        kw.setdefault("bg_scale", int(min(max(foot_px // 3, 1), 8)))
        return cls(marker_radius=marker_radius * px_per_m,
                   marker_spacing=marker_spacing * px_per_m,
                   foot_radius=foot_px, **kw)


@dataclass(frozen=True, repr=False)
class TrackResult(Result):
    """Per-frame marker positions and what went wrong.

    Attributes
    ----------
    tracks : pandas.DataFrame
        One row per frame: ``frame``, ``t`` [s]; for ``front``, ``rear``
        (discs) and ``foot1``, ``foot2`` (foot series): ``<m>_x_px``,
        ``<m>_y_px`` [px], ``<m>_x_m``, ``<m>_y_m`` [m], and ``body_q``,
        ``foot1_q``, ``foot2_q`` (:data:`QUALITY`). Missing points are NaN.
    calibration : Calibration
    fps : float
        Frame rate [Hz].
    problems : list of str
        One line per problem, naming the frame range.
    fatal : bool
        True if tracking could not complete (truncated or unreadable video,
        no markers): ``tracks`` then holds what was tracked before.
    """

    tracks: pd.DataFrame
    calibration: Calibration
    fps: float
    problems: list[str] = field(default_factory=list)
    fatal: bool = False

    def _repr_fields(self) -> dict[str, Any]:
        return {"frames": len(self.tracks), "fps": self.fps, "problems": len(self.problems),
                "fatal": self.fatal}

    def to_dataframe(self) -> pd.DataFrame:
        """The tracks, one row per frame (px and m; quality flags)."""
        return with_units(self.tracks.copy(), recording_units(self.tracks.columns))

    @property
    def body_detection_rate(self) -> float:
        """Fraction of frames with both discs found [-]."""
        if len(self.tracks) == 0:
            return 0.0
        return float(np.mean(self.tracks["body_q"].to_numpy() == QUALITY["ok"]))


# -- video input ----------------------------------------------------------------------------


def open_video(path: str | Path, *,
               reuse_buffer: bool = False) -> tuple[Iterator[np.ndarray], float, int]:
    """Open an ``.mp4``/``.avi`` file or a folder of PNG/JPEG frames.

    Parameters
    ----------
    path : str or Path
    reuse_buffer : bool
        Decode every frame of a video file into the same array (faster; each
        yielded frame is overwritten by the next, so do not keep references).

    Returns
    -------
    frames : iterator of ndarray, shape (height, width, 3), uint8 BGR
    fps : float
        Frame rate from the file [Hz] (NaN for a folder).
    n_frames : int
        Frame count the container reports (-1 if unknown).

    Raises
    ------
    VideoError
        If the path is missing or cannot be opened.
    """
    import cv2

    path = Path(path)
    if not path.exists():
        raise VideoError(f"video not found: {str(path)!r}")
    if path.is_dir():
        files = sorted(p for p in path.iterdir()
                       if p.suffix.lower() in (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff"))
        if not files:
            raise VideoError(f"no image frames (.png, .jpg) in folder {str(path)!r}")

        def gen_files() -> Iterator[np.ndarray]:
            for k, p in enumerate(files):
                img = cv2.imread(str(p), cv2.IMREAD_COLOR)
                if img is None:
                    raise VideoError(f"unreadable frame {k} ({p.name}) in {str(path)!r}")
                yield img

        return gen_files(), math.nan, len(files)
    cap = cv2.VideoCapture(str(path))
    if not cap.isOpened():
        raise VideoError(f"cannot open video {str(path)!r}: not a readable video file")
    fps = float(cap.get(cv2.CAP_PROP_FPS) or math.nan)
    n = int(cap.get(cv2.CAP_PROP_FRAME_COUNT) or -1)

    def gen_cap() -> Iterator[np.ndarray]:
        try:
            buf = None
            while True:
                ok, img = cap.read(buf) if buf is not None else cap.read()
                if not ok:
                    return
                if reuse_buffer:
                    buf = img
                yield img
        finally:
            cap.release()

    return gen_cap(), fps, n


# -- calibration ----------------------------------------------------------------------------


def measure_calibration(frame: np.ndarray, marker_spacing_m: float,
                        options: TrackerOptions | None = None,
                        marker_radius_m: float = 0.025) -> Calibration:
    """Measure scale and ground line from one frame.

    The scale comes from the known distance of the two body discs
    ``marker_spacing_m`` [m] (found by a Hough search over the frame for
    circles of ``marker_radius_m``, trying scales), the ground line from the
    strongest horizontal edge of the row means (the treadmill surface) in the
    lower half of the frame, and x = 0 at the frame centre.
    """
    import cv2

    grey = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY).astype(np.float32)
    prof = grey.mean(axis=1)
    H = len(prof)
    grad = np.abs(np.diff(prof))
    lower = H // 2
    gy = float(lower + np.argmax(grad[lower:]) + 0.5)
    ratio = marker_spacing_m / marker_radius_m
    g8 = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
    g8 = cv2.GaussianBlur(g8, (5, 5), 1.2)
    circles = cv2.HoughCircles(g8, cv2.HOUGH_GRADIENT, dp=1, minDist=8, param1=120,
                               param2=20, minRadius=5, maxRadius=H // 8)
    if circles is None:
        raise VideoError("calibration: no circular markers found in the first frame")
    c = circles[0][:12]
    best = None
    for i in range(len(c)):
        for j in range(i + 1, len(c)):
            r = 0.5 * (c[i][2] + c[j][2])
            if abs(c[i][2] - c[j][2]) > 0.15 * r:
                continue
            d = float(np.hypot(c[i][0] - c[j][0], c[i][1] - c[j][1]))
            err = abs(d / r - ratio) / ratio
            if err < 0.25 and (best is None or err < best[0]):
                best = (err, d)
    if best is None:
        raise VideoError("calibration: no pair of equal discs at the expected spacing in the "
                         "first frame; give --scale and --ground")
    return Calibration(px_per_m=best[1] / marker_spacing_m, ground_y=gy,
                       x0=frame.shape[1] / 2.0)


# -- tracking -------------------------------------------------------------------------------


def track_video(path: str | Path, calibration: Calibration, options: TrackerOptions, *,
                fps: float | None = None, max_frames: int | None = None,
                progress: Callable[[int, int], None] | None = None) -> TrackResult:
    """Track body discs and feet through a video (stream, frame by frame).

    Parameters
    ----------
    path : str or Path
        ``.mp4`` file or folder of frames.
    calibration : Calibration
        Pixel -> metre mapping.
    options : TrackerOptions
        Marker sizes and thresholds.
    fps : float, optional
        Frame rate [Hz]; required for a folder of frames, else from the file.
    max_frames : int, optional
        Stop after this many frames.
    progress : callable, optional
        ``progress(done, total)`` every 100 frames.

    Returns
    -------
    TrackResult
        With ``fatal=True`` (and the frames tracked so far) if the video ends
        before its reported length or a frame cannot be decoded.

    Raises
    ------
    VideoError
        If the video is missing or cannot be opened at all.
    """
    frames, file_fps, n = open_video(path, reuse_buffer=True)
    rate = fps if fps is not None else file_fps
    if not (rate is not None and math.isfinite(rate) and rate > 0):
        raise VideoError(f"frame rate unknown for {str(path)!r}; give --fps")
    res = track_frames(frames, calibration, options, fps=rate, n_expected=n,
                       max_frames=max_frames, progress=progress)
    if len(res.tracks) == 0 and not res.fatal:
        return TrackResult(res.tracks, calibration, rate,
                           [f"no frames could be decoded from {str(path)!r}"], True)
    return res


def track_frames(frames: Iterator[np.ndarray], calibration: Calibration,
                 options: TrackerOptions, *, fps: float, n_expected: int = -1,
                 max_frames: int | None = None,
                 progress: Callable[[int, int], None] | None = None) -> TrackResult:
    """Track an iterator of BGR frames; see :func:`track_video`."""
    tracker = _Tracker(options)
    rows: list[tuple[float, ...]] = []
    problems: list[str] = []
    fatal = False
    k = -1
    total = n_expected if n_expected > 0 else 0
    try:
        for k, frame in enumerate(frames):
            if max_frames is not None and k >= max_frames:
                k -= 1
                break
            rows.append(tracker.step(frame))
            if progress is not None and (k + 1) % 100 == 0:
                progress(k + 1, total)
    except VideoError as exc:
        problems.append(f"{exc}; tracks kept for frames 0-{k}")
        fatal = True
    n_done = len(rows)
    if progress is not None:
        progress(n_done, total)
    if (not fatal and n_expected > 0 and n_done < n_expected - 1
            and (max_frames is None or n_done < max_frames)):
        problems.append(f"video truncated: decoded {n_done} of {n_expected} frames; frames "
                        f"{n_done}-{n_expected - 1} missing, tracks kept for frames 0-"
                        f"{n_done - 1}")
        fatal = True
    tracks = _table(rows, calibration, fps)
    problems += _gap_report(tracks)
    if n_done > 0 and not np.any(tracks["body_q"].to_numpy() == QUALITY["ok"]):
        problems.append(f"no body markers detected in frames 0-{n_done - 1} (expected two "
                        f"discs of radius {options.marker_radius:.1f} px)")
        fatal = True
    return TrackResult(tracks=tracks, calibration=calibration, fps=fps, problems=problems,
                       fatal=fatal)


_COLS = ("front_x_px", "front_y_px", "rear_x_px", "rear_y_px", "body_q",
         "foot1_x_px", "foot1_y_px", "foot1_q", "foot2_x_px", "foot2_y_px", "foot2_q")


def _table(rows: list[tuple[float, ...]], cal: Calibration, fps: float) -> pd.DataFrame:
    arr = np.asarray(rows, dtype=float).reshape(-1, len(_COLS))
    df = pd.DataFrame(arr, columns=list(_COLS))
    df.insert(0, "t", np.arange(len(df)) / fps)
    df.insert(0, "frame", np.arange(len(df)))
    for m in ("front", "rear", "foot1", "foot2"):
        df[f"{m}_x_m"], df[f"{m}_y_m"] = cal.to_metres(df[f"{m}_x_px"].to_numpy(),
                                                       df[f"{m}_y_px"].to_numpy())
    for q in ("body_q", "foot1_q", "foot2_q"):
        df[q] = df[q].astype(int)
    return df


def _ranges(mask: np.ndarray) -> list[tuple[int, int]]:
    """Inclusive (start, stop) index ranges where ``mask`` is True."""
    if not mask.any():
        return []
    d = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1))


def _fmt_ranges(r: list[tuple[int, int]], limit: int = 4) -> str:
    parts = [f"{a}-{b}" if b > a else f"{a}" for a, b in r[:limit]]
    more = f" and {len(r) - limit} more" if len(r) > limit else ""
    return ", ".join(parts) + more


def _gap_report(df: pd.DataFrame) -> list[str]:
    out: list[str] = []
    n = len(df)
    if n == 0:
        return out
    miss = df["body_q"].to_numpy() != QUALITY["ok"]
    if miss.any() and not miss.all():
        r = _ranges(miss)
        out.append(f"body markers not detected in {int(miss.sum())} of {n} frames: frames "
                   f"{_fmt_ranges(r)}")
    return out


class _Tracker:
    """State carried from frame to frame (last points, background model).

    Per-frame work is kept to small regions: the body Hough search runs in the
    bounding box of the predicted disc positions (whole frame only when lost),
    the background model and a first colour mask run on a ``bg_scale``
    down-sampled frame, and the full-resolution HSV mask, morphology and
    ellipse fits run only in crops around the foot-coloured moving blobs found
    there.
    """

    def __init__(self, opt: TrackerOptions) -> None:
        import cv2

        self.cv2 = cv2
        self.opt = opt
        self.body: np.ndarray | None = None      # last (front, rear) [px], shape (2, 2)
        self.vel = np.zeros((2, 2))              # last frame-to-frame body motion [px]
        self.lost = 0
        self.feet: list[np.ndarray | None] = [None, None]
        self.bg = cv2.createBackgroundSubtractorMOG2(history=opt.bg_history,
                                                     detectShadows=False)
        # only the dominant modes are background: a foot that passes the same
        # pixels every stride must not become part of the scene
        self.bg.setBackgroundRatio(opt.bg_ratio)
        self.n = 0
        self.lo = np.array(opt.foot_hsv_low, dtype=np.uint8)
        self.hi = np.array(opt.foot_hsv_high, dtype=np.uint8)
        self.kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (5, 5))
        self.kernel3 = np.ones((3, 3), np.uint8)
        self.area_full = math.pi * opt.foot_radius ** 2

    def step(self, frame: np.ndarray) -> tuple[float, ...]:
        body = self._body(frame)
        if body is None:
            self.lost += 1
            self.vel[:] = 0.0
            b = (math.nan,) * 4 + (QUALITY["missing"],)
        else:
            if self.body is not None and self.lost == 0:
                self.vel = body - self.body
            else:
                self.vel[:] = 0.0
            self.body, self.lost = body, 0
            b = (float(body[0, 0]), float(body[0, 1]), float(body[1, 0]), float(body[1, 1]),
                 QUALITY["ok"])
        f = self._feet(frame)
        return b + f

    # body: ROI, grey, Canny, Hough (Figure D.3)
    def _body(self, frame: np.ndarray) -> np.ndarray | None:
        cv2, o = self.cv2, self.opt
        H, W = frame.shape[:2]
        R = o.marker_radius
        if self.body is not None and self.lost < 20:
            # bounding box of the predicted discs, grown while the markers stay lost
            pred = self.body + self.vel
            m = R + o.roi_margin * (1 + self.lost) + float(np.abs(self.vel).max())
            x0, x1 = max(int(pred[:, 0].min() - m), 0), min(int(pred[:, 0].max() + m) + 1, W)
            y0, y1 = max(int(pred[:, 1].min() - m), 0), min(int(pred[:, 1].max() + m) + 1, H)
        else:
            x0, y0, x1, y1 = 0, 0, W, H
        if x1 - x0 < 2 * R or y1 - y0 < 2 * R:
            return None
        grey = cv2.cvtColor(frame[y0:y1, x0:x1], cv2.COLOR_BGR2GRAY)
        grey = cv2.GaussianBlur(grey, (5, 5), 1.0)
        circles = cv2.HoughCircles(grey, cv2.HOUGH_GRADIENT, dp=1,
                                   minDist=max(0.5 * o.marker_spacing, R),
                                   param1=o.canny_high, param2=o.hough_votes,
                                   minRadius=max(int(R * 0.85), 3),
                                   maxRadius=int(math.ceil(R * 1.15)) + 1)
        if circles is None:
            return None
        cand = circles[0][:8, :2].astype(float)
        best = None
        for i in range(len(cand)):
            for j in range(i + 1, len(cand)):
                d = float(np.hypot(*(cand[i] - cand[j])))
                err = abs(d - o.marker_spacing) / o.marker_spacing
                if err > 0.2:
                    continue
                pair = np.array([cand[i], cand[j]]) if cand[i][0] >= cand[j][0] else \
                    np.array([cand[j], cand[i]])
                score = err
                if self.body is not None:
                    score += float(np.abs(pair + (x0, y0) - self.body).sum()) / (4 * R)
                if best is None or score < best[0]:
                    best = (score, pair)
        if best is None:
            return None
        out = np.array([_refine_circle(grey, p, R, o.canny_low, o.canny_high, cv2)
                        for p in best[1]])
        return out + (x0, y0)

    # feet: background subtraction, HSV mask, ellipses (Figure D.4)
    def _feet(self, frame: np.ndarray) -> tuple[float, ...]:
        cv2, o = self.cv2, self.opt
        H, W = frame.shape[:2]
        s = max(int(o.bg_scale), 1)
        hs, ws = H // s, W // s
        # point sampling at pixel (s*i, s*j): cheap, and the full-resolution pass
        # below decides the blob outline
        small = cv2.resize(frame[: hs * s, : ws * s], (ws, hs), interpolation=cv2.INTER_NEAREST)
        fg_small = self.bg.apply(small)
        self.n += 1
        use_fg = self.n > o.bg_warmup
        y0 = 0
        if self.body is not None:
            y0 = min(max(int(self.body[:, 1].min() - o.marker_spacing * 0.5), 0), H - 1)
        ys0 = y0 // s
        col_small = cv2.inRange(cv2.cvtColor(small[ys0:], cv2.COLOR_BGR2HSV), self.lo, self.hi)
        gate = None
        if use_fg:
            # moving pixels, grown by one sample so the gate covers the blob edges
            gate = cv2.dilate(fg_small[ys0:], self.kernel3)
            cand = cv2.bitwise_and(col_small, gate)
        else:
            cand = col_small
        cand = cv2.dilate(cand, self.kernel3)
        n_lab, _, stats, _ = cv2.connectedComponentsWithStats(cand, connectivity=8)
        # expected full-size area in samples (dilated): keep anything that could
        # hold a blob of at least 0.15 of the foot area
        min_samples = max(0.15 * self.area_full / (s * s), 1.0)
        pad = 2 * s + 4
        boxes = []
        for lab in range(1, n_lab):
            bx, by, bw, bh, area = (int(v) for v in stats[lab])
            if area < min_samples:
                continue
            boxes.append([max(bx * s - pad, 0), max((by + ys0) * s - pad, y0),
                          min((bx + bw) * s + pad, W), min((by + bh + ys0) * s + pad, H)])
        boxes = _merge_boxes(boxes)
        blobs = []
        for bx0, by0, bx1, by1 in boxes:
            hsv = cv2.cvtColor(frame[by0:by1, bx0:bx1], cv2.COLOR_BGR2HSV)
            mask = cv2.inRange(hsv, self.lo, self.hi)
            if gate is not None:
                # sample (i, j) covers full-resolution pixels [s*i - s/2, s*i + s/2)
                gy0, gx0 = (by0 + s // 2) // s - ys0, (bx0 + s // 2) // s
                gy1, gx1 = (by1 - 1 + s // 2) // s - ys0 + 1, (bx1 - 1 + s // 2) // s + 1
                g = gate[gy0:gy1, gx0:gx1]
                g = cv2.resize(g, (g.shape[1] * s, g.shape[0] * s),
                               interpolation=cv2.INTER_NEAREST)
                oy, ox = by0 - (gy0 + ys0) * s + s // 2, bx0 - gx0 * s + s // 2
                g = g[oy: oy + by1 - by0, ox: ox + bx1 - bx0]
                if g.shape != mask.shape:    # frame edge: pad the gate with "moving"
                    gg = np.full_like(mask, 255)
                    gg[: g.shape[0], : g.shape[1]] = g
                    g = gg
                mask = cv2.bitwise_and(mask, g)
            mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, self.kernel)
            contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE,
                                           offset=(bx0, by0))
            for c in contours:
                a = cv2.contourArea(c)
                if a < 0.15 * self.area_full:
                    continue
                if len(c) >= 5:
                    (cx, cy), _, _ = cv2.fitEllipse(c)
                else:
                    mo = cv2.moments(c)
                    cx, cy = mo["m10"] / mo["m00"], mo["m01"] / mo["m00"]
                blobs.append((a, np.array([cx, cy])))
        blobs.sort(key=lambda b: -b[0])
        blobs = blobs[:2]
        assign = self._assign([b[1] for b in blobs])
        out: list[float] = []
        for series in (0, 1):
            k = assign.get(series)
            if k is None:
                out += [math.nan, math.nan, QUALITY["missing"]]
                continue
            a, p = blobs[k]
            self.feet[series] = p
            if a < o.partial_area * self.area_full:
                out += [math.nan, math.nan, QUALITY["partial"]]
            else:
                out += [float(p[0]), float(p[1]), QUALITY["ok"]]
        return tuple(out)

    def _assign(self, pts: list[np.ndarray]) -> dict[int, int]:
        """Series index -> detection index, nearest last known point (joint for two)."""
        last = self.feet
        if not pts:
            return {}
        if len(pts) == 1:
            known = [i for i in (0, 1) if last[i] is not None]
            if not known:
                return {0: 0}
            if len(known) == 1:
                return {known[0]: 0}
            d = [float(np.hypot(*(pts[0] - last[i]))) for i in (0, 1)]
            return {int(np.argmin(d)): 0}
        if last[0] is None and last[1] is None:
            order = sorted((0, 1), key=lambda i: pts[i][0])   # first seen: left to right
            return {0: order[0], 1: order[1]}

        def dist(i: int, j: int) -> float:
            return 0.0 if last[i] is None else float(np.hypot(*(pts[j] - last[i])))

        straight = dist(0, 0) + dist(1, 1)
        crossed = dist(0, 1) + dist(1, 0)
        return {0: 0, 1: 1} if straight <= crossed else {0: 1, 1: 0}


def _merge_boxes(boxes: list[list[int]]) -> list[list[int]]:
    """Union of overlapping (x0, y0, x1, y1) boxes until none overlap."""
    merged = True
    while merged and len(boxes) > 1:
        merged = False
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                a, b = boxes[i], boxes[j]
                if a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]:
                    boxes[i] = [min(a[0], b[0]), min(a[1], b[1]), max(a[2], b[2]),
                                max(a[3], b[3])]
                    del boxes[j]
                    merged = True
                    break
            if merged:
                break
    return boxes


def _refine_circle(grey: np.ndarray, c: np.ndarray, R: float, canny_low: float,
                   canny_high: float, cv2: Any) -> np.ndarray:
    """Least-squares (Kasa) circle through the Canny edge pixels near a Hough circle.

    ``grey`` is the blurred grey region; the Canny edges are computed only in
    a window of the circle (plus a border so the window edge adds no edges).
    """
    h, w = grey.shape
    x0, y0 = max(int(c[0] - R - 8), 0), max(int(c[1] - R - 8), 0)
    x1, y1 = min(int(c[0] + R + 9), w), min(int(c[1] + R + 9), h)
    if x1 - x0 < 8 or y1 - y0 < 8:
        return c
    edges = cv2.Canny(grey[y0:y1, x0:x1], canny_low, canny_high)
    iy, ix = np.nonzero(edges)
    if len(ix) < 12:
        return c
    xs = ix + float(x0)
    ys = iy + float(y0)
    for _ in range(2):
        keep = np.abs(np.hypot(xs - c[0], ys - c[1]) - R) < 3.0
        n = int(keep.sum())
        if n < 12:
            return c
        x, y = xs[keep], ys[keep]
        mx, my = x.mean(), y.mean()
        u, v = x - mx, y - my
        z = u * u + v * v
        # normal equations of min sum (z - a u - b v - e)^2 with centred u, v
        suu, svv, suv = float(u @ u), float(v @ v), float(u @ v)
        suz, svz = float(u @ z), float(v @ z)
        det = suu * svv - suv * suv
        if det <= 0:
            return c
        a = (suz * svv - svz * suv) / det
        b = (svz * suu - suz * suv) / det
        e = float(z.mean())
        c = np.array([mx + a / 2, my + b / 2])
        R = math.sqrt(max(e + (a / 2) ** 2 + (b / 2) ** 2, 1.0))
    return c
