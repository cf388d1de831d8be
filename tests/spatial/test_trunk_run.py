"""A recorded 3-D TSLIP run: physics of its samples (energy, ballistic flight, unit
quaternions), agreement with trunk_step stride by stride, its interpolation, a fall,
and its animation (front and side view) written atomically."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tslip.spatial import TRUNK_MIRROR, TrunkStatus, one_step_map, section, trunk_step
from tslip.spatial.lateral import OPTIONS, TABLE21_3D_SECTION, table21_params
from tslip.spatial.trunk_robustness import disturbed_run
from tslip.spatial.trunk_run import RUN_COLUMNS, trunk_run
from tslip.spatial.trunk_section import from_section

P = table21_params()


@pytest.fixture(scope="module")
def run():
    return trunk_run(P, from_section(P, TABLE21_3D_SECTION), 6)


def _flights(run):
    """(start, end) row indices of each flight block."""
    fl = run["stance"] < 0.5
    edges = np.flatnonzero(np.diff(np.concatenate([[0], fl.astype(int), [0]])))
    return list(zip(edges[::2], edges[1::2]))


def test_the_stored_gait_is_left_right_symmetric():
    f, st = one_step_map(P, TABLE21_3D_SECTION, options=OPTIONS)
    assert st == TrunkStatus.OK
    np.testing.assert_allclose(f, TRUNK_MIRROR * TABLE21_3D_SECTION, atol=1e-9)


def test_energy_is_conserved_along_the_passive_run(run):
    e = run["energy"]
    assert run.status == TrunkStatus.OK and run.n_strides == 6
    assert np.ptp(e) < 2e-7 * abs(e[0])  # the integrator's tolerance 1e-8, not the model's


def test_flight_is_ballistic(run):
    """CoM in flight: v(t) = v_lo - g t e_y and c(t) = c_lo + v_lo t - g t^2/2 e_y."""
    g = P.g
    for a, b in _flights(run):
        blk = run.data[a:b]
        dt = blk[:, 0] - blk[0, 0]
        c0, v0 = blk[0, 4:7], blk[0, 7:10]
        want_c = c0 + v0 * dt[:, None] - 0.5 * g * dt[:, None] ** 2 * np.array([0, 1, 0])
        want_v = v0 - g * dt[:, None] * np.array([0, 1, 0])
        np.testing.assert_allclose(blk[:, 4:7], want_c, atol=1e-9)
        np.testing.assert_allclose(blk[:, 7:10], want_v, atol=1e-9)
    assert len(_flights(run)) == 6


def test_rows_agree_with_trunk_step_stride_by_stride(run):
    state = from_section(P, TABLE21_3D_SECTION)
    t0 = 0.0
    for i in range(run.n_strides):
        r = trunk_step(P, state)
        assert r.stance_time == run.stance_times[i] and r.flight_time == run.flight_times[i]
        blk = run.data[run["stride"] == i]
        st = blk[blk[:, 2] > 0.5]
        fl = blk[blk[:, 2] < 0.5]
        assert st[0, 0] == pytest.approx(t0, abs=1e-12) and np.array_equal(st[0, 4:17], state.y)
        assert np.all(st[:, 3] == state.side) and np.all(fl[:, 3] == -state.side)
        assert np.all(st[:, -4:-1] == state.foot)  # the stance foot stays where it landed
        assert st[-1, 0] == pytest.approx(t0 + r.stance_time, abs=1e-12)
        np.testing.assert_allclose(st[-1, 4:17], r.liftoff, atol=1e-15)
        assert fl[-1, 0] == pytest.approx(t0 + r.stance_time + r.flight_time, abs=1e-12)
        np.testing.assert_allclose(fl[-1, 4:17], r.state.y, atol=1e-12)
        # the swing foot reaches the ground where trunk_step placed the next foot
        np.testing.assert_allclose(fl[-1, -4:-1], r.state.foot, atol=1e-9)
        np.testing.assert_allclose(run.touchdowns[i + 1, :13], r.state.y, atol=0)
        state, t0 = r.state, t0 + r.stance_time + r.flight_time


def test_attitude_and_hip_columns(run):
    col = {c: i for i, c in enumerate(RUN_COLUMNS)}
    q = run.data[:, col["qw"]:col["qz"] + 1]
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)
    # at each touch-down the yaw, pitch and roll are those of the section (trunk_section)
    for i, s in enumerate(run.states[:-1]):
        row = run.data[(run["stride"] == i) & (run["stance"] > 0.5)][0]
        x = section(P, s)
        np.testing.assert_allclose(row[[col["yaw"], col["pitch"], col["roll"]]], x[1:4],
                                   atol=1e-14)
    # the hip is r from the CoM, and the stance leg no longer than l0
    hip = run.data[:, col["hip_x"]:col["hip_z"] + 1]
    np.testing.assert_allclose(np.linalg.norm(hip - run.data[:, 4:7], axis=1), P.r, atol=1e-12)
    leg = np.linalg.norm(run.data[:, col["foot_x"]:col["foot_z"] + 1] - hip, axis=1)
    assert np.all(leg <= P.l0 + 1e-9)
    np.testing.assert_allclose(leg[run["stance"] < 0.5], P.l0, atol=1e-12)


def test_sample_hits_the_samples_and_the_parabola_between(run):
    t = run["t"]
    keep = np.concatenate([np.diff(t) > 0, [True]])  # a time shared by two rows: the later
    rows = run.sample(t[keep])
    np.testing.assert_allclose(rows[:, 4:17], run.data[keep, 4:17], atol=1e-12)
    a, b = _flights(run)[2]
    mid = 0.5 * (run.data[a:b - 1, 0] + run.data[a + 1:b, 0])
    s = run.sample(mid)
    dt = mid - run.data[a, 0]
    c0, v0 = run.data[a, 4:7], run.data[a, 7:10]
    want = c0 + v0 * dt[:, None] - 0.5 * P.g * dt[:, None] ** 2 * np.array([0, 1, 0])
    np.testing.assert_allclose(s[:, 4:7], want, atol=1e-12)  # Hermite is exact on a parabola
    np.testing.assert_allclose(np.linalg.norm(s[:, 10:14], axis=1), 1.0, atol=1e-14)


def test_a_push_ends_in_the_fall_the_robustness_loop_finds():
    x = np.array(TABLE21_3D_SECTION)
    x[6] += 0.3  # a strong lateral push right after the touch-down
    want = disturbed_run(P, TABLE21_3D_SECTION, "lateral_push", 0.3, n_steps=25)
    run = trunk_run(P, from_section(P, x), 25)
    assert want[0] != TrunkStatus.OK
    assert (run.status, run.fall_stride) == want and run.n_strides == want[1] + 1
    assert np.all(np.isfinite(run.data))


def test_bad_input_is_one_line():
    s = from_section(P, TABLE21_3D_SECTION)
    with pytest.raises(ValueError, match="n_steps") as err:
        trunk_run(P, s, 0)
    assert "\n" not in str(err.value)
    with pytest.raises(TypeError, match="params must be TrunkParams"):
        trunk_run(object(), s, 1)  # type: ignore[arg-type]
    with pytest.raises(KeyError, match="no column 'q'"):
        trunk_run(P, s, 1)["q"]


# -- the animation ------------------------------------------------------------------------


def test_views_show_the_runner_where_the_sample_puts_it(run):
    from tslip.plotting.spatial import draw_views

    t = 0.5 * (run.stance_times[0] + run.flight_times[0]) + run.stance_times[0]
    fig = draw_views(run, t)
    front, side = fig.axes[:2]
    row = run.sample(np.array([t]))[0]
    com_side = [ln for ln in side.lines if ln.get_marker() == "o" and ln.get_color() == "k"][0]
    com_front = [ln for ln in front.lines if ln.get_marker() == "o" and ln.get_color() == "k"][0]
    assert com_side.get_xdata()[0] == row[4] and com_side.get_ydata()[0] == row[5]
    assert com_front.get_xdata()[0] == row[6] and com_front.get_ydata()[0] == row[5]
    lo, hi = front.get_xlim()
    assert lo > hi  # seen from ahead: the runner's right (+z) on the viewer's left
    assert side.get_xlim()[0] < row[4] < side.get_xlim()[1]


def test_animation_writes_every_frame_and_replaces_a_link(run, tmp_path):
    import imageio.v3 as iio

    from tslip.plotting.animation import frame_times, gif_fps
    from tslip.plotting.spatial import animate_run

    short = trunk_run(P, from_section(P, TABLE21_3D_SECTION), 1)
    target = tmp_path / "target.gif"
    target.write_bytes(b"keep")
    link = tmp_path / "a.gif"
    link.symlink_to(target)
    out = animate_run(short, link, fps=10, speed=1.0, size=(320, 160))
    assert out == link and not link.is_symlink() and target.read_bytes() == b"keep"
    frames = iio.imread(link, index=None)
    assert frames.shape[0] == len(frame_times(short, gif_fps(10), 1.0))
    assert frames.shape[1:3] == (160, 320)
    assert math.isclose(gif_fps(10), 10.0)


@pytest.mark.parametrize("kwargs, why", [
    ({"path": "a.png"}, r"\.gif or \.mp4"),
    ({"fps": 0.0}, "fps must be"),
    ({"path": "a.mp4", "size": (322, 160)}, "multiples of 8"),
])
def test_animation_bad_input_is_one_line(run, tmp_path, kwargs, why):
    from tslip.plotting.spatial import animate_run

    kw = {"path": "a.gif", **kwargs}
    path = tmp_path / kw.pop("path")
    with pytest.raises(ValueError, match=why) as err:
        animate_run(run, path, **kw)
    assert "\n" not in str(err.value) and not path.exists()
