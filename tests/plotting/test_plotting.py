"""Plots return Figures holding the trajectory's data; animations write frames."""

import doctest

import imageio.v3 as iio
import numpy as np
import pytest
from matplotlib.figure import Figure

import tslip
import tslip.plotting.trajectories as trajectories_module
from tslip.gait import find_gait
from tslip.plotting import (
    animate,
    flight_intervals,
    frame_times,
    ground_profile,
    plot_touchdowns,
    plot_trajectory,
    render_frames,
)
from tslip.plotting.animation import _sample, _spring


@pytest.fixture(scope="module")
def traj() -> tslip.Trajectory:
    gait = find_gait(tslip.preset("table2.1"))
    return tslip.simulate(gait.params, gait.state, 3)


def _line(ax, label):
    (line,) = [ln for ln in ax.get_lines() if ln.get_label() == label]
    return line


def test_plot_trajectory_has_four_axes_with_the_data(traj):
    fig = plot_trajectory(traj)
    assert isinstance(fig, Figure)
    assert len(fig.axes) == 4
    path, phi, leg, force = fig.axes
    com = _line(path, "CoM")
    np.testing.assert_array_equal(com.get_xdata(), traj["x"])
    np.testing.assert_array_equal(com.get_ydata(), traj["y"])
    np.testing.assert_array_equal(_line(phi, r"$\phi$").get_ydata(), traj["phi"])
    np.testing.assert_array_equal(_line(leg, r"$l$").get_ydata(), traj["l"])
    np.testing.assert_array_equal(_line(force, r"$F_y$").get_ydata(), traj["Fy"])
    np.testing.assert_array_equal(_line(force, r"$F_x$").get_xdata(), traj["t"])
    assert "[L]" in path.get_xlabel() and "[Mg]" in force.get_ylabel()
    assert "g$^{-1/2}$ L$^{1/2}$" in phi.get_xlabel()


def test_plot_trajectory_into_given_figure(traj):
    fig = Figure()
    assert plot_trajectory(traj, fig) is fig
    assert len(fig.axes) == 4


def test_flight_intervals_match_the_events(traj):
    intervals = flight_intervals(traj)
    liftoffs = [e.t for e in traj.events if e.kind == "liftoff"]
    touchdowns = [e.t for e in traj.events if e.kind == "touchdown"][1:]
    assert len(intervals) == len(traj.steps) == 3
    np.testing.assert_allclose([a for a, _ in intervals], liftoffs, atol=1e-9)
    np.testing.assert_allclose([b for _, b in intervals], touchdowns, atol=1e-9)


def test_ground_profile_follows_terrain(traj):
    gx, gy = ground_profile(traj)
    assert np.all(gy == 0.0) and gx[0] < traj["x"].min() and gx[-1] > traj["x"].max()
    terrain = tslip.Terrain.step(x=2.0, dh=-0.2)
    gx, gy = ground_profile(traj, terrain)
    assert np.interp(1.0, gx, gy) == 0.0 and np.interp(3.0, gx, gy) == -0.2


def test_plot_touchdowns(traj):
    fig = plot_touchdowns(traj)
    assert len(fig.axes) == 5
    v = fig.axes[0].get_lines()[0].get_ydata()
    np.testing.assert_allclose(v, [s.v for s in traj.touchdowns])
    fig2 = Figure()
    ax = fig2.add_subplot()
    assert plot_touchdowns(traj, ax, quantities=["stance_time", "flight_time"]) is fig2
    assert len(ax.get_lines()) == 2
    with pytest.raises(ValueError, match="quantities"):
        plot_touchdowns(traj, quantities=["bogus"])


def test_docstring_example():
    result = doctest.testmod(trajectories_module)
    assert result.attempted > 0 and result.failed == 0


def test_spring_runs_from_hip_to_foot():
    hip, foot = np.array([0.0, 1.0]), np.array([0.3, 0.1])
    pts = _spring(hip, foot, 1.0)
    np.testing.assert_array_equal(pts[0], hip)
    np.testing.assert_array_equal(pts[-1], foot)
    # zig-zags stay within the coil amplitude of the hip-foot line
    d = (foot - hip) / np.linalg.norm(foot - hip)
    off = (pts - hip) @ np.array([-d[1], d[0]])
    assert np.max(np.abs(off)) <= 0.06 + 1e-12


def test_frames_never_interpolate_across_the_leg_reset(traj):
    lo = next(e.t for e in traj.events if e.kind == "liftoff")
    rows = _sample(traj.data, np.array([lo + 1e-4, lo + 0.009]))
    foot_y = rows[:, list(tslip.simulation.result.TRAJECTORY_COLUMNS).index("foot_y")]
    stance = rows[:, list(tslip.simulation.result.TRAJECTORY_COLUMNS).index("stance")]
    for s, fy in zip(stance, foot_y, strict=True):
        assert s in (0.0, 1.0)
        assert (fy == 0.0) if s == 1.0 else (fy > 0.05)


def test_render_frames_shape(traj):
    ts = frame_times(traj, fps=10)
    assert ts[0] == traj["t"][0] and ts[-1] == traj["t"][-1]
    frames = list(render_frames(traj, ts[:3], size=(320, 184), dpi=60))
    assert len(frames) == 3
    assert frames[0].shape == (184, 320, 3) and frames[0].dtype == np.uint8
    assert frames[0].min() < 50 and frames[0].max() == 255  # something dark drawn on white


def test_animate_gif_writes_frames_and_reports_progress(tmp_path, traj):
    calls = []
    path = animate(traj, tmp_path / "a.gif", fps=10, progress=lambda i, n: calls.append((i, n)))
    frames = iio.imread(path, index=None)
    assert frames.shape[0] > 5 and frames.shape[1:] == (360, 640, 3)
    assert len(calls) == frames.shape[0] and calls[-1] == (frames.shape[0], frames.shape[0])
    assert [p.name for p in tmp_path.iterdir()] == ["a.gif"]  # no temporary left behind


def test_animate_mp4(tmp_path, traj):
    path = animate(traj, tmp_path / "a.mp4", fps=10, speed=1.0)
    assert path.read_bytes()[4:8] == b"ftyp"


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"path": "a.avi"}, r"\.gif or \.mp4"),
        ({"fps": 0.0}, "fps"),
        ({"speed": -1.0}, "speed"),
        ({"path": "a.mp4", "size": (330, 180)}, "multiples of 8"),
    ],
)
def test_animate_rejects_bad_arguments(tmp_path, traj, kwargs, match):
    kwargs = {"path": "a.gif", **kwargs}
    kwargs["path"] = tmp_path / kwargs["path"]
    with pytest.raises(ValueError, match=match):
        animate(traj, **kwargs)
    assert list(tmp_path.iterdir()) == []
