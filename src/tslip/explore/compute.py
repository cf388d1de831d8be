"""What the explorer computes, as plain functions of the parameters (no web code).

The gait and its multipliers (:func:`solve`), the three robustness limits
(:func:`limits`, stoppable between limits), the runner after a disturbance at
the second touch-down (:func:`disturbed_run`) and its animation frames
(:func:`runner_frames`), the stability map over two
parameters through the study machinery (:func:`stability_map`), and the
exports (:func:`params_toml`, :func:`trajectory_parquet`).
"""

from __future__ import annotations

import io
import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..gait import Floquet, Gait, find_gait, floquet, robustness
from ..model.parameters import Params
from ..simulation import Disturbance, Trajectory, simulate
from ..sweeps import Axis, StudyResult, StudySpec, run_study
from ..sweeps.point import Pending, analyse_point, gait_tol
from .state import check_fraction

__all__ = ["Solved", "solve", "limit", "limits", "disturbed_run", "stability_map", "MapCancelled",
           "params_toml", "trajectory_parquet", "FIELDS", "FRESH", "magnitude", "unit_circle",
           "runner_frames", "ground", "FPS", "SPEED"]

#: The disturbance field of :class:`tslip.Disturbance` for each robustness kind.
FIELDS = {"step_down": "dh", "push": "dxd", "pitch_rate": "dphid"}


@dataclass(frozen=True, slots=True)
class Solved:
    """A gait search's outcome: the gait, its multipliers and two strides, or why not."""

    gait: Gait | None
    floquet: Floquet | None
    trajectory: Trajectory | None
    message: str
    #: The gait search refused the parameters (a ValueError, e.g. a binding ``alpha_stop``):
    #: ``message`` says why, and the page and the exports show it as a refused input.
    refused: bool = False

    @property
    def ok(self) -> bool:
        """A converged gait with multipliers and a recorded run."""
        return self.floquet is not None and self.trajectory is not None


def solve(params: Params, n_steps: int = 2) -> Solved:
    """The periodic gait of ``params`` (Section 2.8), its multipliers and ``n_steps`` strides.

    A search that refuses ``params`` (a ValueError: a retraction stop that binds at
    the periodic gait, Section 7.5) is a :class:`Solved` with ``refused`` set.
    """
    try:
        gait = find_gait(params)
    except ValueError as exc:
        return Solved(None, None, None, f"no gait: {exc}", refused=True)
    if not gait.converged:
        return Solved(gait, None, None, f"no gait: {gait.message}")
    fl = floquet(gait)
    traj = simulate(gait.params, gait.state, n_steps)
    if traj.status.fell or traj.status.is_error:
        return Solved(gait, fl, None, f"no gait: the periodic run ended in {traj.status.name}")
    return Solved(gait, fl, traj, "gait found")


def limit(gait: Gait, kind: str) -> float:
    """One robustness limit of ``gait`` (Section 3.1.3, 25 strides): :func:`tslip.robustness`."""
    return robustness(gait, kind)  # type: ignore[arg-type]


def limits(gait: Gait, stop: Callable[[], bool] = lambda: False,
           run: Callable[[Gait, str], float] = limit) -> dict[str, float] | None:
    """The step-down, push and pitch-rate limits (Section 3.1.3); None if ``stop()`` turns true.

    ``stop`` is asked before each limit, so a newer request ends this one
    after at most one limit's search (about 0.1 s). ``run(gait, kind)``
    computes one limit (the explorer runs :func:`limit` in a worker process).
    """
    out = {}
    for kind in FIELDS:
        if stop():
            return None
        out[kind] = run(gait, kind)
    return out


def disturbed_run(gait: Gait, kind: str, magnitude: float, n_steps: int = 6) -> Trajectory:
    """``n_steps`` strides of ``gait`` with a ``kind`` disturbance at the second touch-down."""
    dist = Disturbance(at_step=1, **{FIELDS[kind]: float(magnitude)})
    return simulate(gait.params, gait.state, n_steps, disturbance=dist)


#: The runner's animation: frames a second, and playback speed for a 1 m leg on Earth
#: (a quarter of real time, as ``tslip animate``).
FPS = 30.0
SPEED = 0.25


def runner_frames(traj: Trajectory, fps: float = FPS, speed: float = SPEED) -> dict[str, Any]:
    """The animation of a run as columns, one row a frame (the page plays them).

    Frame times are :func:`tslip.plotting.animation.frame_times` (``speed``
    times real time for a 1 m leg), each frame the runner's
    :func:`~tslip.plotting.animation.pose` there: the drawing of ``tslip
    animate`` (trunk ellipse along the hip-CoM axis, spring leg, ground force
    arrow at 0.15 l0 per Mg), in L.
    """
    from ..plotting.animation import TRUNK_WIDTH, frame_times, pose, sample, trunk_length

    t = frame_times(traj, fps, speed)
    p = traj.params
    length = trunk_length(p)
    poses = [pose(row, p.l0, length) for row in sample(traj, t)]
    none = np.full((2, 2), np.nan)
    grf = [np.array([q.foot, q.grf]) if q.grf is not None else none for q in poses]
    n = max(len(q.spring) for q in poses)  # a spring of zero length is two points: pad it
    legs = np.array([np.vstack([q.spring, np.repeat(q.spring[-1:], n - len(q.spring), 0)])
                     for q in poses])
    axes, arrows = np.array([q.axis for q in poses]), np.array(grf)
    return {
        "t": t, "stance": np.array([q.stance for q in poses], dtype=float),
        **{f"{name}_{xy}": np.array([getattr(q, name)[j] for q in poses])
           for name in ("com", "hip", "foot", "centre") for j, xy in enumerate("xy")},
        "angle": np.array([q.angle for q in poses]),
        "body_w": np.full(len(t), length), "body_h": np.full(len(t), TRUNK_WIDTH * p.l0),
        # polylines, one row a frame (one array each: the page reads row i)
        "leg_x": legs[:, :, 0], "leg_y": legs[:, :, 1], "axis_x": axes[:, :, 0],
        "axis_y": axes[:, :, 1], "grf_x": arrows[:, :, 0], "grf_y": arrows[:, :, 1],
    }


def ground(traj: Trajectory) -> tuple[np.ndarray, np.ndarray]:
    """The ground under a run as a polyline, its step-down drawn (``tslip animate``'s)."""
    from ..plotting.trajectories import ground_profile

    return ground_profile(traj, margin=0.5 * traj.params.l0)


def magnitude(limit: float, fraction: float) -> float:
    """The disturbance ``fraction`` of a signed ``limit``; 0 for an infinite or missing one.

    Raises ValueError for a ``fraction`` outside [0, 2] (:func:`.state.check_fraction`):
    a negative one would turn the disturbance the other way.
    """
    check_fraction(fraction)
    return fraction * limit if math.isfinite(limit) else 0.0


class MapCancelled(Exception):
    """The stability map was cancelled."""


def stability_map(params: Params, x: tuple[str, float, float], y: tuple[str, float, float],
                  points: int, progress: Callable[[int, int], None]) -> StudyResult:
    """Largest non-trivial multiplier over a ``points`` x ``points`` grid of two parameters.

    ``x`` and ``y`` are ``(name, from, to)``; the study runs in this process
    (:func:`tslip.sweeps.run_study` with one worker), and ``progress`` may
    raise :class:`MapCancelled` to stop it. The result's ``grid`` has the
    shape ``(points of y, points of x)``.

    The study continues each line of y from its neighbour's gaits (Newton from
    that gait only), so a cell beyond the end of the neighbour's branch (a fold)
    has no gait there even where :func:`tslip.find_gait` finds one, and a line
    with no gait leaves the next line without seeds. Those cells are searched
    afresh, as a click on the cell would (:func:`_fresh`); ``progress`` counts
    these searches as further points.
    """
    spec = StudySpec(name="explore-map", base=params,
                     axes=(Axis.linspace(_axis(y[0]), y[1], y[2], points),
                           Axis.linspace(_axis(x[0]), x[1], x[2], points)))
    res = run_study(spec, workers=1, progress=progress)
    return _fresh(res, progress)


#: The study's message of a cell its neighbour line's gait did not continue to.
NOT_CONTINUED = "no periodic gait continuing from the neighbouring line"
#: The message of a cell found by a fresh search after that.
FRESH = "found by a fresh search (the neighbouring line's gait did not continue here)"


def _fresh(res: StudyResult, progress: Callable[[int, int], None]) -> StudyResult:
    """``res`` with each cell the continuation missed searched afresh by :func:`find_gait`."""
    frame, spec = res.frame.copy(), res.spec
    rows = np.flatnonzero((~frame["converged"].astype(bool)
                           & (frame["message"] == NOT_CONTINUED)).to_numpy())
    axes = {a.param: frame[a.param].to_numpy(float) for a in spec.axes}
    done, total = len(frame), len(frame) + len(rows)
    for n, j in enumerate(rows):
        point = {name: float(values[j]) for name, values in axes.items()}
        gait = find_gait(spec.params_at(point), tol=gait_tol(spec))
        if gait.converged:
            rec = analyse_point(spec, Pending(int(j), point, gait, gait.residual, FRESH, 1, 0.0))
            for key, value in rec.items():
                if key in frame.columns:
                    frame.at[frame.index[int(j)], key] = value
        progress(done + n + 1, total)
    return replace(res, frame=frame)


def _axis(name: str) -> str:
    """A study's name of a control: Params fields as they are, gains as ``controller.<gain>``."""
    return name if name in Params.__dataclass_fields__ else f"controller.{name}"


def params_toml(params: Params) -> str:
    """The parameters as a TOML file that :meth:`tslip.Params.from_toml` reads back."""
    data = params.to_dict()
    ctrl = data.pop("controller")
    lines = ["# tslip explore: parameters of the current gait", "[params]"]
    lines += [f"{k} = {_toml(v)}" for k, v in data.items()]
    lines += ["", "[params.controller]"]
    lines += [f"{k} = {_toml(v)}" for k, v in ctrl.items()]
    return "\n".join(lines) + "\n"


def _toml(value: object) -> str:
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return repr(float(value))  # type: ignore[arg-type]


def trajectory_parquet(traj: Trajectory) -> bytes:
    """The trajectory's table (:meth:`Trajectory.to_dataframe`) as parquet bytes."""
    buf = io.BytesIO()
    traj.to_dataframe().to_parquet(buf, index=False)
    return buf.getvalue()


def unit_circle(n: int = 181) -> tuple[np.ndarray, np.ndarray]:
    """Points on the unit circle, for the multiplier plot."""
    t = np.linspace(0.0, 2.0 * np.pi, n)
    return np.cos(t), np.sin(t)
