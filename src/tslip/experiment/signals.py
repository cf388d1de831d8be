"""Position-data processing (thesis Section 5.6, Figures D.5-D.6) and fit scores.

Tracked marker positions are cleaned (outliers against a low-pass copy, then
low-pass filtered), turned into CoM position, pitch, leg length and leg angle,
differentiated with a Savitzky-Golay filter, split into steps from touch-down
to touch-down by comparing the feet with the ground, and the near-foot steps
are averaged on a normalised step time. Correlation (eq. 5.1) and VAF
(eq. 5.2) score a model against the averages.

All step quantities are in the dimensionless units of Table 3.1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from scipy.signal import butter, savgol_filter, sosfiltfilt

from .._results import Result, frame, with_units
from ..model.units import ROBOT_SCALING, UNIT, Scaling
from .synth import BodyGeometry

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "SIGNALS", "ProcessOptions", "StepData", "StepAverage", "correlation", "vaf", "lowpass",
    "reject_outliers", "process_tracks", "average_steps", "contact_events",
]

#: The signals of Table 6.3, in order, with their units.
SIGNALS = {
    "y": "L", "l": "L", "beta": "rad", "phi": "rad", "xd": "g^1/2 L^1/2", "yd": "g^1/2 L^1/2",
    "ld": "g^1/2 L^1/2", "betad": "rad g^1/2 L^-1/2", "phid": "rad g^1/2 L^-1/2",
}


def correlation(y: np.ndarray, yhat: np.ndarray) -> float:
    """Pearson correlation of measurement and model (eq. 5.1) [-].

    ``rho = cov(y, yhat) / (sigma_y sigma_yhat)``; NaN if either is constant.

    Examples
    --------
    >>> correlation(np.array([1.0, 2.0, 3.0]), np.array([3.0, 2.0, 1.0]))
    -1.0
    """
    y, yhat = np.asarray(y, float), np.asarray(yhat, float)
    sy, sh = np.std(y), np.std(yhat)
    if sy == 0 or sh == 0:
        return math.nan
    return float(np.mean((y - y.mean()) * (yhat - yhat.mean())) / (sy * sh))


def vaf(y: np.ndarray, yhat: np.ndarray, *, centred: bool = True) -> float:
    """Variance accounted for (eq. 5.2) [%].

    ``centred=True`` (default) is eq. 5.2 as printed in the thesis and used
    for Table 6.3::

        VAF = (1 - var(y - yhat) / var(y)) * 100

    The variance of the residual removes its mean, so a model that is off by
    a constant offset still scores 100 % (and correlation 1): this VAF
    measures the shape of the signal only.

    ``centred=False`` replaces the residual variance by its mean square::

        VAF = (1 - mean((y - yhat)^2) / var(y)) * 100

    so a constant offset ``d`` lowers it by ``100 d^2 / var(y)`` percentage
    points; this is the variant in which "a constant offset leaves correlation
    at 1 and lowers VAF". The two agree when the residual has zero mean.

    Parameters
    ----------
    y, yhat : ndarray, shape (n,)
        Measurement and model.
    centred : bool
        Use the residual's variance (eq. 5.2) or its mean square.

    Returns
    -------
    float
        VAF [%]; 100 for a perfect fit, NaN if ``y`` is constant; unbounded
        below.

    Examples
    --------
    >>> y = np.array([1.0, 2.0, 3.0, 4.0])
    >>> vaf(y, y + 1.0)
    100.0
    >>> round(vaf(y, y + 1.0, centred=False), 6)    # 1 - 1 / 1.25
    20.0
    """
    y, yhat = np.asarray(y, float), np.asarray(yhat, float)
    v = np.var(y)
    if v == 0:
        return math.nan
    r = y - yhat
    err = np.var(r) if centred else np.mean(r * r)
    return float((1.0 - err / v) * 100.0)


# -- filters ----------------------------------------------------------------------------------


def _fill(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Linearly interpolate NaN gaps (ends held); return filled copy and the NaN mask."""
    x = np.asarray(x, float)
    bad = ~np.isfinite(x)
    if bad.all():
        return np.zeros_like(x), bad
    if bad.any():
        i = np.arange(len(x))
        x = x.copy()
        x[bad] = np.interp(i[bad], i[~bad], x[~bad])
    return x, bad


def lowpass(x: np.ndarray, fs: float, cutoff: float, order: int = 2) -> np.ndarray:
    """Zero-phase Butterworth low-pass; gaps (NaN) are bridged, then restored.

    Parameters
    ----------
    x : ndarray, shape (n,)
        Signal sampled at ``fs`` [Hz].
    cutoff : float
        Cut-off frequency [Hz].
    """
    xf, bad = _fill(x)
    if len(x) < 16 or cutoff >= 0.5 * fs:
        out = xf
    else:
        sos = butter(order, cutoff / (0.5 * fs), output="sos")
        out = sosfiltfilt(sos, xf)
    out = np.asarray(out, float)
    out[bad] = np.nan
    return out


def reject_outliers(x: np.ndarray, fs: float, cutoff: float, threshold: float) -> np.ndarray:
    """Mask of outliers: points farther than ``threshold`` from a low-pass copy.

    Parameters
    ----------
    x : ndarray, shape (n,)
        Signal (NaN = missing).
    fs, cutoff : float
        Sample rate and low-pass cut-off [Hz].
    threshold : float
        Allowed distance, in the units of ``x``.

    Returns
    -------
    ndarray of bool, shape (n,)
        True where the sample is rejected (Figure D.5).
    """
    smooth = lowpass(x, fs, cutoff)
    with np.errstate(invalid="ignore"):
        return np.abs(np.asarray(x, float) - smooth) > threshold


def _savgol(x: np.ndarray, fs: float, window: int, deriv: int) -> np.ndarray:
    xf, bad = _fill(x)
    w = min(window | 1, (len(x) - 1) | 1 if len(x) % 2 == 0 else len(x))
    if w < 5:
        out = np.gradient(xf, 1.0 / fs) if deriv else xf
    else:
        out = savgol_filter(xf, w, 3, deriv=deriv, delta=1.0 / fs)
    out = np.asarray(out, float)
    out[bad] = np.nan
    return out


# -- processing ------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class ProcessOptions:
    """Settings of the position-data processing.

    Attributes
    ----------
    outlier_cutoff : float
        Low-pass cut-off of the outlier reference [Hz].
    outlier_threshold : float
        Distance from the reference beyond which a point is rejected [m].
    foot_outlier_cutoff, foot_outlier_threshold : float
        The same for the feet [Hz], [m] (their touch-downs are sharp corners).
    cutoff : float
        Low-pass cut-off of the positions [Hz].
    savgol_window : float
        Savitzky-Golay window for velocities [s] (cubic).
    contact_height : float
        Foot height above the ground level below which the foot is in stance [m].
    n_tau : int
        Points of the normalised step time [-].
    min_steps : int
        Fewest near-foot steps that can be averaged [-].
    near : {"auto", "foot1", "foot2"}
        Which foot series is the near foot (``auto``: the one detected more often).
    belt_speed : float or None
        Treadmill speed [m/s]; ``None`` measures it from the stance feet.
    """

    outlier_cutoff: float = 20.0
    outlier_threshold: float = 0.004
    foot_outlier_cutoff: float = 60.0
    foot_outlier_threshold: float = 0.008
    cutoff: float = 40.0
    savgol_window: float = 0.031
    contact_height: float = 0.004
    n_tau: int = 101
    min_steps: int = 3
    near: str = "auto"
    belt_speed: float | None = None


@dataclass(frozen=True, repr=False)
class StepData(Result):
    """Processed recording split into steps.

    Attributes
    ----------
    samples : pandas.DataFrame
        Long table: ``step``, ``tau`` (normalised step time, 0..1), ``t``
        (time since touch-down), ``stance``, and the :data:`SIGNALS`, all
        dimensionless (Table 3.1).
    steps : pandas.DataFrame
        One row per near-foot step: ``step``, ``frame_td``, ``frame_end``,
        ``t_td`` [s], ``stance_time``, ``flight_time`` [g^-1/2 L^1/2].
    frames : pandas.DataFrame
        Per-frame processed signals in SI: ``t`` [s], ``com_x``, ``com_y``,
        ``phi``, ``l``, ``beta``, velocities, ``foot_rel_x``, ``foot_rel_y``
        (near foot relative to the CoM [m]), ``near_stance``.
    belt_speed : float
        Treadmill speed used for the horizontal velocity [m/s].
    scaling : Scaling
    problems : list of str
    meta : dict
    """

    samples: pd.DataFrame
    steps: pd.DataFrame
    frames: pd.DataFrame
    belt_speed: float
    scaling: Scaling
    problems: list[str] = field(default_factory=list)
    meta: dict = field(default_factory=dict)

    def _repr_fields(self) -> dict[str, Any]:
        return {"steps": len(self.steps), "samples": len(self.samples),
                "frames": len(self.frames), "belt_speed": self.belt_speed,
                "problems": len(self.problems)}

    def to_dataframe(self) -> pd.DataFrame:
        """The long table of step samples (dimensionless, Table 3.1)."""
        return with_units(self.samples.copy(), {"step": "-", "tau": "-", "t": UNIT["time"],
                                                "stance": "-", **SIGNALS})

    def plot(self, ax: Axes | None = None) -> Figure:
        """The near foot's path relative to the CoM, every frame."""
        from ..plotting.experiment import plot_foot_trajectory

        return plot_foot_trajectory(self, ax)


@dataclass(frozen=True, repr=False)
class StepAverage(Result):
    """Step-averaged measurement (the data behind Figure 6.1).

    Attributes
    ----------
    tau : ndarray, shape (n_tau,)
        Normalised step time [-].
    mean, std : pandas.DataFrame
        Per-signal mean and standard deviation over steps (columns :data:`SIGNALS`).
    stance_time, flight_time : ndarray, shape (n_steps,)
        Per-step durations [g^-1/2 L^1/2].
    n_steps : int
    """

    tau: np.ndarray
    mean: pd.DataFrame
    std: pd.DataFrame
    stance_time: np.ndarray
    flight_time: np.ndarray
    n_steps: int

    def to_dataframe(self) -> pd.DataFrame:
        """One row per ``tau``: the mean and std of every signal (``<signal>_mean``, ``_std``)."""
        cols: dict[str, Any] = {"tau": self.tau}
        units = {"tau": "-"}
        for name in self.mean.columns:
            cols[f"{name}_mean"] = self.mean[name].to_numpy()
            cols[f"{name}_std"] = self.std[name].to_numpy()
            units[f"{name}_mean"] = units[f"{name}_std"] = SIGNALS.get(name, "-")
        return frame(cols, units)

    def plot(self, ax: Axes | None = None) -> Figure:
        """Figure 6.1's layout (3 x 3); on ``ax`` the CoM height ``y`` only."""
        from ..plotting.experiment import plot_step_average

        return plot_step_average(self, ax=ax)

    @property
    def duty_factor(self) -> np.ndarray:
        """Per-step duty factor t_s / (t_s + t_f) [-]."""
        return self.stance_time / (self.stance_time + self.flight_time)

    @property
    def step_frequency(self) -> np.ndarray:
        """Per-step frequency 1 / (t_s + t_f) [g^1/2 L^-1/2]."""
        return 1.0 / (self.stance_time + self.flight_time)


def contact_events(height: np.ndarray, t: np.ndarray, level: float, threshold: float
                   ) -> list[tuple[float, float, int, int]]:
    """Stance intervals of a foot from its height above the ground.

    A sample is in stance when ``height < level + threshold`` (the core of a
    stance). Each edge of a core is then refined to the contact instant: the
    corner between the flight samples and the stance samples, found as the
    best two-line fit (:func:`_corner`). On a rigid ground the stance line is
    flat at ``level`` and this is where the flight line reaches it; on a
    compliant ground (the biped's, Table E.3) the foot keeps sinking through
    the stance, and the corner also catches the start and end of the stance
    that lie above the core threshold.

    Returns
    -------
    list of (t_touchdown, t_liftoff, first_frame, last_frame)
        Only complete intervals (two flight samples before and after); the
        frames are those between the contact instants. Cores that refine
        to touching intervals (noise around the threshold) are merged.
    """
    h = np.asarray(height, float)
    with np.errstate(invalid="ignore"):
        st = h < level + threshold
    runs: list[tuple[float, float, int, int]] = []
    d = np.diff(np.concatenate([[0], st.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1
    for a, b in zip(starts.tolist(), stops.tolist()):
        if b - a < 2 or a < 2 or b > len(h) - 3:
            continue
        if not (np.isfinite(h[a - 1]) and np.isfinite(h[b + 1])):
            continue
        t_td, a2 = _corner(h, t, level, threshold, a, b, -1)
        t_lo, b2 = _corner(h, t, level, threshold, b, a, 1)
        if runs and a2 <= runs[-1][3] + 1:  # noise split one stance into two cores
            runs[-1] = (runs[-1][0], t_lo, runs[-1][2], b2)
        else:
            runs.append((t_td, t_lo, a2, b2))
    return [r for r in runs if math.isfinite(r[0]) and math.isfinite(r[1])]


def _fit(tt: np.ndarray, hh: np.ndarray, deg: int) -> tuple[np.ndarray, float]:
    """Least-squares polynomial (highest power first) and its sum of squared residuals."""
    c = np.polyfit(tt, hh, deg)
    return c, float(np.sum((np.polyval(c, tt) - hh) ** 2))


def _corner(h: np.ndarray, t: np.ndarray, level: float, thr: float, i: int, j: int,
            direction: int) -> tuple[float, int]:
    """Contact instant at the edge ``i`` of the stance core ``[i, j]`` (either order).

    The samples outward from ``i`` (``direction``) below ``level + 8 thr``
    and up to 6 core samples form one sequence from flight to stance. For
    each split of it, a parabola is fitted to the samples before the split
    (flight: ballistic or accelerating) and a line to those after it
    (stance: flat on a rigid ground, sinking on a compliant one); the split
    with the smallest total squared residual wins, and the contact instant
    is where the two curves meet, clipped to the samples either side of the
    split. Returns the instant and the outermost stance frame; the instant
    is NaN when the samples run out (recording edge or a tracking gap)
    before the foot is clear of the ground, as the stance is then incomplete.
    """
    out: list[int] = []
    k = i + direction
    while (0 <= k < len(h) and len(out) < 40 and np.isfinite(h[k])
           and h[k] < level + 8 * thr):
        out.append(k)
        k += direction
    if len(out) < 2 or not (0 <= k < len(h) and np.isfinite(h[k])):
        return math.nan, int(i)  # no flight on this side within the recording
    core = list(range(i, j - direction, -direction))[:6]  # from the edge inward
    seq = np.array(out[::-1] + core)
    best = None
    for p in range(2, len(seq) - 1):
        fl, st = seq[:p], seq[p:]
        cf, e1 = _fit(t[fl], h[fl], 2 if len(fl) >= 4 else 1)
        cs, e2 = _fit(t[st], h[st], 1)
        if best is None or e1 + e2 < best[0]:
            best = (e1 + e2, p, cf, cs)
    if best is None:
        return float(t[i]), int(i)
    _, p, cf, cs = best
    edge, last_flight = int(seq[p]), int(seq[p - 1])
    lo_t, hi_t = sorted((t[edge], t[last_flight]))
    roots = np.roots(np.polysub(cf, cs))
    roots = roots[np.isreal(roots)].real
    if not len(roots):
        return float(t[edge]), edge
    tc = roots[np.argmin(np.abs(roots - 0.5 * (lo_t + hi_t)))]
    return float(np.clip(tc, lo_t, hi_t)), edge


def process_tracks(tracks: pd.DataFrame, fps: float, geometry: BodyGeometry | None = None, *,
                   scaling: Scaling = ROBOT_SCALING,
                   options: ProcessOptions | None = None) -> StepData:
    """Clean the tracks, compute the states and split the near-foot steps.

    Parameters
    ----------
    tracks : pandas.DataFrame
        Output of :func:`tslip.experiment.video.track_video` (``*_m`` columns).
    fps : float
        Frame rate [Hz].
    geometry : BodyGeometry, optional
        Marker-to-CoM geometry [m].
    scaling : Scaling
        SI -> dimensionless (Table 5.1 robot by default).
    options : ProcessOptions, optional

    Returns
    -------
    StepData

    Raises
    ------
    ValueError
        If fewer than ``options.min_steps`` complete near-foot steps are found,
        naming the frame range searched.
    """
    geometry = geometry or BodyGeometry()
    o = options or ProcessOptions()
    n = len(tracks)
    if n < 10:
        raise ValueError(f"too few frames to process: {n} (frames 0-{max(n - 1, 0)})")
    t = np.arange(n) / fps
    problems: list[str] = []
    body_ok = tracks["body_q"].to_numpy() == 1

    def clean(col: str, ok: np.ndarray, filt: bool = True) -> np.ndarray:
        x = np.where(ok, tracks[col].to_numpy(float), np.nan)
        if np.isfinite(x).sum() < 10:
            return x
        is_foot = col.startswith("foot")
        bad = reject_outliers(x, fps, o.foot_outlier_cutoff if is_foot else o.outlier_cutoff,
                              o.foot_outlier_threshold if is_foot else o.outlier_threshold)
        x = np.where(bad, np.nan, x)
        return lowpass(x, fps, o.cutoff) if filt else x

    front = np.stack([clean("front_x_m", body_ok), clean("front_y_m", body_ok)], axis=1)
    rear = np.stack([clean("rear_x_m", body_ok), clean("rear_y_m", body_ok)], axis=1)
    com, hip, phi = geometry.com_from_discs(front, rear)
    counts = {f: int((tracks[f"{f}_q"] == 1).sum()) for f in ("foot1", "foot2")}
    near = o.near if o.near != "auto" else max(counts, key=lambda f: counts[f])
    hind = "foot2" if near == "foot1" else "foot1"
    feet = {}
    raw_h = {}
    for f in (near, hind):
        ok = tracks[f"{f}_q"].to_numpy() == 1
        feet[f] = np.stack([clean(f"{f}_x_m", ok), clean(f"{f}_y_m", ok)], axis=1)
        raw_h[f] = clean(f"{f}_y_m", ok, filt=False)
    both = np.concatenate([raw_h[near], raw_h[hind]])
    if not np.isfinite(both).any():
        raise ValueError(f"no foot positions tracked in frames 0-{n - 1}")
    level = float(np.nanpercentile(both, 5))
    events = {f: contact_events(raw_h[f], t, level, o.contact_height) for f in (near, hind)}
    win = max(int(round(o.savgol_window * fps)), 5)
    foot = feet[near]
    l_ = np.hypot(foot[:, 0] - hip[:, 0], foot[:, 1] - hip[:, 1])
    beta = np.arctan2(hip[:, 1] - foot[:, 1], foot[:, 0] - hip[:, 0])
    stance_near = np.zeros(n, dtype=bool)
    for _, _, a, b in events[near]:
        stance_near[a:b + 1] = True
    fx_vel = _savgol(feet[near][:, 0], fps, win, 1)
    if o.belt_speed is not None:
        belt = float(o.belt_speed)
    else:
        v = fx_vel[stance_near]
        v = v[np.isfinite(v)]
        belt = float(-np.median(v)) if len(v) else 0.0
        if not len(v):
            problems.append("no near-foot stance found to measure the belt speed; using 0 m/s")
    vel = {
        "xd": _savgol(com[:, 0], fps, win, 1) + belt, "yd": _savgol(com[:, 1], fps, win, 1),
        "ld": _savgol(l_, fps, win, 1), "betad": _savgol(beta, fps, win, 1),
        "phid": _savgol(phi, fps, win, 1),
    }
    frames = pd.DataFrame({
        "frame": np.arange(n), "t": t, "com_x": com[:, 0], "com_y": com[:, 1], "phi": phi,
        "l": l_, "beta": beta, **vel, "foot_rel_x": foot[:, 0] - com[:, 0],
        "foot_rel_y": foot[:, 1] - com[:, 1], "near_stance": stance_near,
    })
    # steps: near touch-down -> near lift-off -> next (hind) touch-down
    L, T, V = scaling.L, scaling.factor("time"), scaling.factor("speed")
    W = scaling.factor("angular_velocity")
    hind_td = np.array([e[0] for e in events[hind]])
    near_ev = events[near]
    tau = np.linspace(0.0, 1.0, o.n_tau)
    sig_si = {"y": com[:, 1], "l": l_, "beta": beta, "phi": phi, **vel}
    unit = {"y": L, "l": L, "beta": 1.0, "phi": 1.0, "xd": V, "yd": V, "ld": V, "betad": W,
            "phid": W}
    rows: list[pd.DataFrame] = []
    srows: list[dict[str, Any]] = []
    for k, (t_td, t_lo, a, b) in enumerate(near_ev):
        later = hind_td[hind_td > t_lo]
        nxt = near_ev[k + 1][0] if k + 1 < len(near_ev) else math.inf
        if not len(later) or later[0] >= nxt:
            continue
        t_end = float(later[0])
        i0, i1 = int(math.floor(t_td * fps)), int(math.ceil(t_end * fps))
        if i0 < 0 or i1 >= n:
            continue
        if body_ok[i0:i1 + 1].mean() < 0.9 or not np.isfinite(l_[a:b + 1]).all():
            problems.append(f"step at frames {i0}-{i1} skipped: markers missing in more "
                            f"than 10 % of its frames")
            continue
        tt = t_td + tau * (t_end - t_td)
        j = len(srows)
        srows.append({"step": j, "frame_td": i0, "frame_end": i1, "t_td": t_td,
                      "stance_time": (t_lo - t_td) / T, "flight_time": (t_end - t_lo) / T})
        d = {"step": np.full(o.n_tau, j), "tau": tau, "t": (tt - t_td) / T,
             "stance": tt <= t_lo}
        for name, x in sig_si.items():
            xf, _ = _fill(x)
            d[name] = np.interp(tt, t, xf) / unit[name]
        rows.append(pd.DataFrame(d))
    if len(srows) < o.min_steps:
        raise ValueError(f"too few steps to average: found {len(srows)} complete near-foot "
                         f"step(s) in frames 0-{n - 1}, need at least {o.min_steps}")
    samples = pd.concat(rows, ignore_index=True) if rows else pd.DataFrame()
    return StepData(samples=samples, steps=pd.DataFrame(srows),
                    frames=frames, belt_speed=belt, scaling=scaling, problems=problems,
                    meta={"near": near, "ground_level_m": level, "fps": fps,
                          "n_near_stances": len(near_ev), "n_hind_stances": len(hind_td)})


def average_steps(samples: pd.DataFrame, steps: pd.DataFrame) -> StepAverage:
    """Mean and standard deviation over steps on the normalised step time.

    Parameters
    ----------
    samples, steps : pandas.DataFrame
        :attr:`StepData.samples` and :attr:`StepData.steps` (or the same
        tables read back from the file ``tslip process`` writes).
    """
    g = samples.groupby("tau")
    mean = g[list(SIGNALS)].mean()
    std = g[list(SIGNALS)].std(ddof=0)
    return StepAverage(tau=mean.index.to_numpy(float), mean=mean.reset_index(drop=True),
                       std=std.reset_index(drop=True),
                       stance_time=steps["stance_time"].to_numpy(float),
                       flight_time=steps["flight_time"].to_numpy(float), n_steps=len(steps))
