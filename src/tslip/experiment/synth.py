"""Synthetic high-speed treadmill video of a two-legged runner with known truth.

A simulated run, in the robot's SI scale of Table 5.1, is drawn as the side
view of Section 5.4: a light uneven background, a moving treadmill belt, the
body plate with two circular disc markers (position and pitch), and two legs
whose feet carry a distinct colour. The hind leg is drawn behind the body, so
its foot is occluded when it passes behind it. Two models can be recorded:

* :func:`synthesize`: TSLIP (thesis Chapter 2). The model has one leg that is
  reset at lift-off; the recording alternates a near and a hind leg: each
  follows the simulated stance when it is on the ground and a smooth
  half-elliptical swing (relative to the hip, like the mechanism of Figure
  D.2) from its lift-off to its next touch-down.
* :func:`synthesize_biped`: the two-legged model with massed legs (Appendix
  E). Both legs, their feet and contacts come from the simulation: the right
  leg is the near one, the left leg the hind one; the plate follows the trunk.

Each model only supplies world-frame functions of time (hip, pitch, CoM, both
feet and their stance flags) plus its touch-downs and mean speed; one shared
layout turns them into the camera frame, the markers and the truth table, so
the renderer and the tracking pipeline treat both recordings alike.

:mod:`tslip.experiment.render` draws the frames. Image coordinates: x to the
right (running direction), y down.

Over 600 lines: one concept, a recording's truth: two models' motion in one camera layout.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from .._checks import check_fits, check_number
from .._results import Result, with_units
from ..model.parameters import Params
from ..model.state import TouchdownState
from ..model.units import ROBOT_SCALING, Scaling

if TYPE_CHECKING:
    from ..biped.parameters import BipedParams, BipedState
    from ..biped.simulate import BipedOptions

__all__ = [
    "Camera", "BodyGeometry", "RenderOptions", "SyntheticRun", "synthesize", "synthesize_biped",
]

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
        for name in ("width", "height"):
            check_number(getattr(self, name), name, unit="px", lower=64, upper=8192,
                         integer=True)
        object.__setattr__(self, "fps", check_number(self.fps, "fps", unit="Hz", lower=0.0,
                                                     upper=1e5, lower_open=True))
        object.__setattr__(self, "field_width", check_number(
            self.field_width, "field_width", unit="m", lower=0.0, lower_open=True))

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
        and touch-down foot positions [m] (TSLIP only: the biped's swing is
        simulated).
    seed : int
        Seed of the noise.
    """

    noise: float = 3.0
    exposure: float = 0.3
    flicker: float = 0.03
    swing_lift: float = 0.2
    seed: int = 0

    def __post_init__(self) -> None:
        for name, unit, lo, hi in (("noise", "grey levels", 0.0, 255.0),
                                   ("exposure", "-", 0.0, 1.0), ("flicker", "-", 0.0, 0.5),
                                   ("swing_lift", "m", 0.0, 1.0)):
            object.__setattr__(self, name, check_number(getattr(self, name), name, unit=unit,
                                                        lower=lo, upper=hi))
        check_number(self.seed, "seed", lower=0, integer=True)


def recording_units(columns: Any) -> dict[str, str]:
    """Units of a recording's per-frame columns, by name: ``*_px`` [px], ``*_m`` [m], ``t`` [s].

    ``frame``, quality flags (``*_q``), stance flags and visible fractions
    are ``"-"``; ``phi`` is in rad.
    """
    out = {}
    for c in columns:
        name = str(c)
        if name.endswith("_px"):
            out[name] = "px"
        elif name.endswith("_m"):
            out[name] = "m"
        elif name in ("t", "liftoff_t"):
            out[name] = "s"
        elif name == "phi":
            out[name] = "rad"
        else:
            out[name] = "-"
    return out


@dataclass(frozen=True, repr=False)
class SyntheticRun(Result):
    """A simulated run laid out frame by frame, with its ground truth.

    Attributes
    ----------
    truth : pandas.DataFrame
        One row per frame: ``frame``, ``t`` [s], then for each marker
        (``front``, ``rear``, ``near``, ``hind``) ``<m>_x_px, <m>_y_px`` [px]
        and ``<m>_x_m, <m>_y_m`` [m] (x in the camera frame, y up from the
        ground), ``hind_visible`` (visible fraction of the hind foot),
        ``near_stance``, ``hind_stance``, and the model states ``com_x_m``,
        ``com_y_m``, ``phi``, ``hip_x_m``, ``hip_y_m``. For the biped the
        CoM is the trunk's and the near/hind feet are the right/left feet.
    params : Params or BipedParams
        Model that generated the run (dimensionless, Table 3.1).
    state : TouchdownState or BipedState
        Touch-down state of the TSLIP gait, or the biped's start state at
        ``t0``.
    scaling : Scaling
        Units (Table 5.1 by default).
    camera, geometry, options
        How it was drawn.
    belt_speed : float
        Treadmill speed [m/s] (the mean forward speed of the runner).
    stance_time, flight_time : float
        Model stride times [g^-1/2 L^1/2]: TSLIP's first stance and flight;
        for the biped the right foot's first stance in the recording and the
        time from its lift-off to the next left touch-down.
    touchdowns : pandas.DataFrame
        ``t`` [s], ``leg`` ("near"/"hind"), ``liftoff_t`` [s] of each stance.
    t0 : float
        Start time of the simulation [g^-1/2 L^1/2] (the biped controller's
        clock; 0 for TSLIP).
    """

    truth: pd.DataFrame
    params: Params | BipedParams
    state: TouchdownState | BipedState
    scaling: Scaling
    camera: Camera
    geometry: BodyGeometry
    options: RenderOptions
    belt_speed: float
    stance_time: float
    flight_time: float
    touchdowns: pd.DataFrame
    t0: float = 0.0
    _poses: dict[str, dict[str, np.ndarray]] = field(repr=False, default_factory=dict)

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return len(self.truth)

    def _repr_fields(self) -> dict[str, Any]:
        return {"frames": self.n_frames, "belt_speed": self.belt_speed,
                "stance_time": self.stance_time, "flight_time": self.flight_time}

    def to_dataframe(self) -> pd.DataFrame:
        """The ground truth, one row per frame (markers in px and m, model states)."""
        return with_units(self.truth.copy(), recording_units(self.truth.columns))


def synthesize(params: Params, state: TouchdownState, duration: float, *,
               camera: Camera | None = None, geometry: BodyGeometry | None = None,
               options: RenderOptions | None = None,
               scaling: Scaling = ROBOT_SCALING) -> SyntheticRun:
    """Simulate a TSLIP gait and lay it out as a two-legged recording.

    The one TSLIP leg alternates between the near and the hind leg of the
    drawing; between its stances each leg follows a half-elliptical swing
    (:attr:`RenderOptions.swing_lift`). The recording starts at the third
    touch-down, a near one.

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
        Frame size and rate, marker layout (default ``r = params.r * L``),
        image effects.
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
    camera = camera or Camera()
    geometry = geometry or BodyGeometry(r=params.r * scaling.L)
    options = options or RenderOptions()
    _check_duration(duration, camera)
    motion = _tslip_motion(params, state, duration, camera, options, scaling)
    return _layout(motion, duration, camera, geometry, options, scaling)


def synthesize_biped(params: BipedParams, state: BipedState | np.ndarray, duration: float, *,
                     t0: float = 0.0, camera: Camera | None = None,
                     geometry: BodyGeometry | None = None, options: RenderOptions | None = None,
                     scaling: Scaling = ROBOT_SCALING,
                     biped_options: BipedOptions | None = None) -> SyntheticRun:
    """Simulate the two-legged model and lay it out as a recording.

    Both legs and feet come from :func:`tslip.biped.simulate` (thesis
    Appendix E): the right leg is drawn as the near leg, the left one as the
    hind leg; stance flags are the simulator's contact flags. The body plate
    follows the trunk: its CoM is the trunk CoM ``(x_b, z_b)`` and its pitch
    ``phi = -theta_b`` (the biped's pitch is clockwise positive, eq. E.2;
    the plate's counter-clockwise, eq. A.3). The recorded rows (one per
    accepted integrator step) are interpolated linearly onto the frame times;
    the recording starts at the first right touch-down after ``t0``.

    Parameters
    ----------
    params : BipedParams
        Model (dimensionless, Table 3.1 units).
    state : BipedState or array_like, shape (18,)
        ``(q, qd)`` at ``t0``, e.g. from :func:`tslip.biped.gait.from_section`.
    duration : float
        Length of the recording [s].
    t0 : float
        Start time of the simulation [g^-1/2 L^1/2]; sets the controller phase
        (eq. E.25).
    camera, geometry, options
        Frame size and rate, marker layout (default ``r = params.r_1 * L``),
        image effects (``swing_lift`` is not used).
    scaling : Scaling
        Dimensionless -> SI units (Table 5.1 robot by default).
    biped_options : BipedOptions, optional
        Integrator options; by default those of the simulator with recorded
        rows at most a quarter frame interval apart.

    Returns
    -------
    SyntheticRun
        ``stance_time`` is the right foot's first stance in the recording and
        ``flight_time`` the time from its lift-off to the next left
        touch-down (negative: double support), both in model units.

    Raises
    ------
    ValueError
        If the duration or ``t0`` is invalid, the state has the wrong shape,
        or the simulated run falls or ends before the recording.

    References
    ----------
    Thesis Appendix E, eqs E.5 and E.8 (hip and foot positions).
    """
    camera = camera or Camera()
    geometry = geometry or BodyGeometry(r=params.r_1 * scaling.L)
    options = options or RenderOptions()
    _check_duration(duration, camera)
    if not math.isfinite(t0):
        raise ValueError(f"t0 [g^-1/2 L^1/2] must be finite, got {t0!r}")
    motion = _biped_motion(params, state, duration, t0, camera, scaling, biped_options)
    return _layout(motion, duration, camera, geometry, options, scaling)


# -- model-specific motion ------------------------------------------------------------------


@dataclass(frozen=True)
class _Motion:
    """A simulated run as world-frame functions of time, in SI units.

    ``pose(t)`` maps times ``t`` [s], shape (n,), to ``hip``, ``com``,
    ``near``, ``hind`` [m], shape (n, 2) (x forward, y up from the ground),
    ``phi`` [rad] (counter-clockwise, eq. A.3) and the boolean
    ``near_stance``, ``hind_stance``. ``touchdowns`` has ``t``, ``leg``,
    ``liftoff_t`` [s] of every stance; ``speed`` is the mean forward speed
    [m/s]; frames start at ``t_start`` [s] and ``pose`` is valid up to
    ``t_last`` [s].
    """

    params: Any
    state: Any
    t0: float
    pose: Callable[[np.ndarray], dict[str, np.ndarray]]
    touchdowns: pd.DataFrame
    speed: float
    t_start: float
    t_last: float
    stance_time: float
    flight_time: float


#: Memory a recorded frame holds before rendering: its ground truth row and the
#: marker poses (about 100 numbers), plus the simulation sampled at a quarter frame.
_FRAME_BYTES = 2000.0


def check_recording(duration: float, camera: Camera) -> None:
    """Refuse a recording that is not positive or whose frames cannot fit in memory."""
    check_number(duration, "duration", unit="s", lower=0.0, lower_open=True)
    check_fits(int(math.ceil(duration * camera.fps)), _FRAME_BYTES,
               f"duration {duration:g} s at {camera.fps:g} Hz: frames", "the recording")


def _check_duration(duration: float, camera: Camera | None = None) -> None:
    check_recording(duration, camera or Camera())


def _tslip_motion(params: Params, state: TouchdownState, duration: float, camera: Camera,
                  options: RenderOptions, scaling: Scaling) -> _Motion:
    """TSLIP run: its one leg alternates near and hind, with an invented swing."""
    from ..simulation import simulate

    T = scaling.factor("time")
    L = scaling.L
    # two strides of lead-in so each leg has a previous lift-off, two after
    probe = simulate(params, state, 1, dt=0.01)
    stride = probe.steps[0].stance_time + probe.steps[0].flight_time
    n_steps = int(math.ceil(duration / (stride * T))) + 5
    dt = min(0.25 / (camera.fps * T), 0.002)
    traj = simulate(params, state, n_steps, dt=dt)
    if traj.status.value != 0 or len(traj.steps) < n_steps:
        raise ValueError(f"the simulated run failed: {traj.status.reason}")
    t_all = traj["t"] * T
    td = np.array([e.t * T for e in traj.events if e.kind == "touchdown"])
    lo = np.array([e.t * T for e in traj.events if e.kind == "liftoff"])
    foot_x = np.array([s.foot_x for s in traj.steps]) * L
    speed = (np.interp(td[-1], t_all, traj["x"]) - np.interp(td[2], t_all, traj["x"])) \
        * L / (td[-1] - td[2])
    r = params.r * L

    def hip_at(t: np.ndarray) -> np.ndarray:
        return np.stack([np.interp(t, t_all, traj["hip_x"]) * L,
                         np.interp(t, t_all, traj["hip_y"]) * L], axis=1)

    def pose(t: np.ndarray) -> dict[str, np.ndarray]:
        hip = hip_at(t)
        phi = np.interp(t, t_all, traj["phi"])
        u = np.stack([np.sin(phi), -np.cos(phi)], axis=1)
        out = {"hip": hip, "phi": phi, "com": hip + r * u}
        for leg, name in enumerate(("near", "hind")):
            out[name], out[f"{name}_stance"] = _foot(t, leg, td, lo, foot_x, hip_at,
                                                     options.swing_lift)
        return out

    legs = ["near" if i % 2 == 0 else "hind" for i in range(len(lo))]
    tds = pd.DataFrame({"t": td[: len(lo)], "leg": legs, "liftoff_t": lo})
    return _Motion(params=params, state=state, t0=0.0, pose=pose, touchdowns=tds,
                   speed=float(speed), t_start=float(td[2]), t_last=float(td[-3]),
                   stance_time=float(traj.steps[0].stance_time),
                   flight_time=float(traj.steps[0].flight_time))


def _biped_motion(params: BipedParams, state: BipedState | np.ndarray, duration: float,
                  t0: float, camera: Camera, scaling: Scaling,
                  biped_options: BipedOptions | None) -> _Motion:
    """Biped run (Appendix E): right leg near, left leg hind, both simulated."""
    from ..biped.dynamics import foot_position, hip_position
    from ..biped.parameters import BipedState
    from ..biped.simulate import BipedOptions, simulate

    T = scaling.factor("time")
    L = scaling.L
    start = state if isinstance(state, BipedState) else BipedState.from_array(state)
    if biped_options is None:
        biped_options = BipedOptions(h_max=min(BipedOptions().h_max, 0.25 / (camera.fps * T)))
    # one stride of lead-in (the recording starts at the next right touch-down), then the
    # recording, then two strides so its last stances and the mean speed are complete
    t_end = t0 + duration / T + 3.0 * params.T
    n_strides = int(math.ceil((t_end - t0) / params.T)) + 3
    traj = simulate(params, start, n_strides, t0=t0, t_end=t_end, options=biped_options)
    if traj.status.fell or traj.status.is_error:
        raise ValueError(f"the simulated biped run failed at t = {traj.stats['t_end']:.3f} "
                         f"g^-1/2 L^1/2: {traj.status.reason}")
    if traj.stats["records_full"]:
        raise ValueError(f"the biped run needs more than max_records = "
                         f"{biped_options.max_records} rows; raise BipedOptions.max_records")
    strides = traj.strides
    t_all = traj.time * T
    if traj.n_steps < 2 or t_all[-1] < strides[0, 0] * T + duration:
        raise ValueError(f"the simulated biped run is too short for a {duration:g} s "
                         f"recording: it ended after {traj.n_steps} stride(s) at t = "
                         f"{traj.time[-1]:.3f} g^-1/2 L^1/2")
    speed = (strides[-1, 1] - strides[0, 1]) * L / ((strides[-1, 0] - strides[0, 0]) * T)
    q_all = traj.data[:, 1:10]
    contact = {"near": traj["contact_R"] > 0.5, "hind": traj["contact_L"] > 0.5}

    def pose(t: np.ndarray) -> dict[str, np.ndarray]:
        q = np.stack([np.interp(t, t_all, q_all[:, j]) for j in range(9)], axis=1)
        row = np.clip(np.searchsorted(t_all, t, side="right") - 1, 0, len(t_all) - 1)
        out = {"hip": hip_position(params, q) * L, "phi": -q[:, 2], "com": q[:, :2] * L}
        for leg, name in enumerate(("near", "hind")):
            out[name] = foot_position(params, q, leg) * L
            out[f"{name}_stance"] = contact[name][row]    # contact of the last row <= t
        return out

    stances = _biped_stances(traj.events, contact["near"][0], contact["hind"][0], traj.time[0])
    right = stances[(stances["leg"] == "near") & (stances["t"] >= strides[0, 0])].iloc[0]
    left_td = stances.loc[(stances["leg"] == "hind") & (stances["t"] > right["t"]), "t"]
    if not len(left_td):
        raise ValueError("the simulated biped run is too short: no left touch-down after the "
                         "first right stance")
    tds = stances.assign(t=stances["t"] * T, liftoff_t=stances["liftoff_t"] * T)
    return _Motion(params=params, state=start, t0=float(t0), pose=pose, touchdowns=tds,
                   speed=float(speed), t_start=float(strides[0, 0] * T), t_last=float(t_all[-1]),
                   stance_time=float(right["liftoff_t"] - right["t"]),
                   flight_time=float(left_td.iloc[0] - right["liftoff_t"]))


def _biped_stances(events: list[Any], on_r: bool, on_l: bool, t0: float) -> pd.DataFrame:
    """``t``, ``leg``, ``liftoff_t`` [model time] of each completed stance of the biped."""
    rows = []
    for leg, side, on in (("near", "R", on_r), ("hind", "L", on_l)):
        tds = ([t0] if on else []) + [e.t for e in events if e.kind == f"touchdown_{side}"]
        los = np.array([e.t for e in events if e.kind == f"liftoff_{side}"])
        for t in tds:
            later = los[los > t]
            if len(later):
                rows.append((t, leg, float(later[0])))
    return pd.DataFrame(rows, columns=["t", "leg", "liftoff_t"]).sort_values(
        "t", kind="stable").reset_index(drop=True)


# -- shared layout ---------------------------------------------------------------------------


def _layout(motion: _Motion, duration: float, camera: Camera, geometry: BodyGeometry,
            options: RenderOptions, scaling: Scaling) -> SyntheticRun:
    """Camera frame, markers, motion-blur poses and the truth table of a simulated run."""
    n_frames = max(int(round(duration * camera.fps)), 1)
    t_start = motion.t_start
    t = t_start + np.arange(n_frames) / camera.fps
    half = 0.5 * options.exposure / camera.fps
    if t[-1] + half > motion.t_last:
        raise ValueError("internal: simulated run shorter than the recording")
    x0 = float(motion.pose(np.array([t_start]))["hip"][0, 0])

    def to_camera(p: np.ndarray, t: np.ndarray) -> np.ndarray:
        """World [m] -> camera-frame metres (the treadmill carries the scene back)."""
        return np.stack([p[:, 0] - motion.speed * (t - t_start) - x0, p[:, 1]], axis=1)

    poses = {}
    for key, tt in (("now", t), ("a", t - half), ("b", t + half)):
        p = motion.pose(tt)
        u = np.stack([np.sin(p["phi"]), -np.cos(p["phi"])], axis=1)
        w = np.stack([np.cos(p["phi"]), np.sin(p["phi"])], axis=1)
        mid = p["hip"] + geometry.a * u
        p["front"], p["rear"] = mid + geometry.b * w, mid - geometry.b * w
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
    cols["near_stance"] = now["near_stance"]
    cols["hind_stance"] = now["hind_stance"]
    img = {k: {n: px(v[n]) for n in ("hip", "front", "rear", "near", "hind")}
           for k, v in poses.items()}
    img["now"]["phi"] = now["phi"]
    cols["hind_visible"] = _hind_visible(img["now"], camera, geometry)
    truth = pd.DataFrame(cols)
    st = motion.touchdowns
    tds = pd.DataFrame({"t": st["t"].to_numpy() - t_start, "leg": st["leg"].to_numpy(),
                        "liftoff_t": st["liftoff_t"].to_numpy() - t_start})
    tds = tds[(tds["liftoff_t"] > 0) & (tds["t"] < t[-1] - t_start)].reset_index(drop=True)
    return SyntheticRun(truth=truth, params=motion.params, state=motion.state, scaling=scaling,
                        camera=camera, geometry=geometry, options=options,
                        belt_speed=motion.speed, stance_time=motion.stance_time,
                        flight_time=motion.flight_time, touchdowns=tds, t0=motion.t0,
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
