"""What the explorer computes: gaits, disturbed runs, the stability map and the exports."""

import dataclasses
import io

import numpy as np
import pandas as pd
import pytest

import tslip
from tslip.explore import compute


@pytest.fixture(scope="module")
def table61():
    return compute.solve(tslip.preset("table6.1"))


def test_solve_returns_the_periodic_gait_and_its_multipliers(table61):
    assert table61.ok
    # the thesis's Table 6.2: largest multiplier 0.92 (docs/conventions.md)
    assert abs(table61.floquet.max_nontrivial - 0.92) < 0.01
    tr = table61.trajectory
    td = tr.touchdowns  # periodic: each stride ends where it started
    assert np.allclose(td[-1].section(), td[0].section(), atol=1e-8)


def test_solve_says_why_there_is_no_gait():
    # v0 far below any hopping speed at a flat touch-down angle: no periodic gait
    p = dataclasses.replace(tslip.preset("table2.1"), v0=0.05, beta0=0.3)
    solved = compute.solve(p)
    assert not solved.ok
    assert solved.message.startswith("no gait")


def test_the_disturbance_lands_at_the_second_touchdown_with_the_asked_magnitude(table61):
    gait = table61.gait
    tr = compute.disturbed_run(gait, "push", -0.2, n_steps=4)
    starts = [s.start for s in tr.steps]
    assert starts[0].xd == pytest.approx(gait.state.xd, abs=1e-12)
    assert starts[1].xd == pytest.approx(gait.state.xd - 0.2, abs=1e-6)
    tr = compute.disturbed_run(gait, "pitch_rate", 0.3, n_steps=3)
    assert tr.steps[1].start.phid == pytest.approx(gait.state.phid + 0.3, abs=1e-6)


def test_a_step_down_lowers_the_ground_after_the_second_touchdown(table61):
    tr = compute.disturbed_run(table61.gait, "step_down", -0.05, n_steps=4)
    assert [round(s.start.h, 12) for s in tr.steps] == [0.0, 0.0, -0.05, -0.05]


def test_magnitude_is_the_fraction_of_a_finite_limit():
    assert compute.magnitude(-0.12, 0.5) == pytest.approx(-0.06)
    assert compute.magnitude(-np.inf, 0.5) == 0.0
    assert compute.magnitude(-0.12, 0.0) == 0.0


def test_magnitude_refuses_a_negative_fraction_that_would_turn_the_disturbance_around():
    with pytest.raises(ValueError, match="fraction"):
        compute.magnitude(-0.12, -0.5)  # +0.06: a step up, not a step down
    with pytest.raises(ValueError, match="fraction"):
        compute.magnitude(-0.12, np.nan)


def test_a_search_that_refuses_the_parameters_is_a_refused_solve_not_an_exception():
    """alpha_stop = 1.0 rad binds at the Table 6.1 gait (alpha_TD about 1.22, Section 7.5)."""
    p = dataclasses.replace(tslip.preset("table6.1"), alpha_stop=1.0)
    with pytest.raises(ValueError, match="alpha_stop binds"):
        tslip.find_gait(p)  # what the page and the exports meet
    solved = compute.solve(p)
    assert solved.refused and not solved.ok and solved.gait is None
    assert solved.message.startswith("no gait: alpha_stop binds at the periodic gait")
    assert not compute.solve(tslip.preset("table6.1")).refused


def test_limits_stop_between_searches_when_asked(table61):
    asked = []

    def run(gait, kind):
        asked.append(kind)
        return -1.0

    assert compute.limits(table61.gait, stop=lambda: len(asked) == 2, run=run) is None
    assert asked == ["step_down", "push"]
    assert compute.limits(table61.gait, run=run) == dict.fromkeys(compute.FIELDS, -1.0)


def test_the_toml_export_reads_back_as_the_gaits_parameters(table61, tmp_path):
    path = tmp_path / "p.toml"
    path.write_text(compute.params_toml(table61.gait.params))
    assert tslip.Params.from_toml(path) == table61.gait.params


def test_the_parquet_export_holds_the_trajectory(table61):
    df = pd.read_parquet(io.BytesIO(compute.trajectory_parquet(table61.trajectory)))
    assert list(df.columns) == list(tslip.simulation.result.TRAJECTORY_COLUMNS)
    assert np.array_equal(df.to_numpy(float), table61.trajectory.data)


def test_the_stability_map_gives_each_cells_largest_multiplier(table61):
    p = tslip.preset("table6.1")
    seen = []
    res = compute.stability_map(p, ("k", 7.0, 9.0), ("r", 0.2, 0.3), 2,
                                lambda done, total: seen.append((done, total)))
    assert seen and seen[-1] == (4, 4)
    f = res.frame
    for _, row in f.iterrows():  # each cell against its own gait search
        q = dataclasses.replace(p, k=row["k"], r=row["r"])
        want = tslip.floquet(tslip.find_gait(q)).max_nontrivial
        assert row["max_nontrivial"] == pytest.approx(want, abs=1e-6)
    assert sorted(set(f["k"])) == [7.0, 9.0] and sorted(set(f["r"])) == [0.2, 0.3]


def test_the_stability_map_stops_when_progress_cancels():
    def cancel(done, total):
        raise compute.MapCancelled

    with pytest.raises(compute.MapCancelled):
        compute.stability_map(tslip.preset("table6.1"), ("k", 7.0, 9.0), ("Kd", 0.3, 0.5), 3,
                              cancel)


def test_a_map_cell_the_continuation_missed_gets_the_gait_find_gait_finds():
    """The SLIP's branch through k = 25 ends (a fold) before k = 17.75, so the study's
    line at 17.75, continued from the line at 25, has no gait; find_gait finds another
    gait there (delta near -0.8 instead of -0.09), and the map now shows it."""
    p = tslip.preset("slip")
    res = compute.stability_map(p, ("r", -0.1, 0.1), ("k", 17.75, 25.0), 2, lambda d, t: None)
    f = res.frame
    low = f[f["k"] == 17.75]
    assert len(low) == 2 and (low["message"] == compute.FRESH).all()
    for _, row in low.iterrows():
        g = tslip.find_gait(dataclasses.replace(p, k=17.75, r=row["r"]))
        assert g.converged
        assert row["converged"]
        assert row["delta"] == pytest.approx(g.state.delta, abs=1e-8)
        assert row["max_nontrivial"] == pytest.approx(tslip.floquet(g).max_nontrivial, abs=1e-6)


def _fine(gait, disturbance=None):
    """The test's own run of six strides, sampled every 0.001 (frames interpolate dt = 0.01)."""
    return tslip.simulate(gait.params, gait.state, 6, disturbance=disturbance, dt=0.001)


def _at(run, t, col):
    return np.interp(t, run["t"], run[col])


def test_the_animation_frames_show_the_disturbed_run_at_their_times(table61):
    gait = table61.gait
    frames = compute.runner_frames(compute.disturbed_run(gait, "push", -0.2))
    t = frames["t"]
    # a quarter of real time at 30 frames a second, for a 1 m leg: g^-1/2 L^1/2 = 0.3193 s
    assert np.diff(t)[:-1] == pytest.approx(0.25 / (30 * np.sqrt(1 / 9.81)))
    run = _fine(gait, tslip.Disturbance(at_step=1, dxd=-0.2))
    assert t[-1] == pytest.approx(run["t"][-1], abs=1e-9)
    events = np.array([e.t for e in run.events])
    near = np.min(np.abs(t[:, None] - events[None, :]), axis=1) < 0.011  # a frame by an event
    for col in ("x", "y"):  # CoM; by an event a frame shows the nearer sample (dt = 0.01)
        err = np.abs(frames[f"com_{col}"] - _at(run, t, col))
        assert err[~near].max() < 1e-4
        assert err[near].max() < 0.03
    # the hip and the trunk (docs/conventions.md): hip = CoM + r (-sin phi, cos phi)
    phi = frames["angle"] - np.pi / 2
    r = gait.params.r
    assert frames["hip_x"] == pytest.approx(frames["com_x"] - r * np.sin(phi), abs=1e-5)
    assert frames["hip_y"] == pytest.approx(frames["com_y"] + r * np.cos(phi), abs=1e-5)
    assert np.abs(phi - _at(run, t, "phi"))[~near].max() < 1e-4
    # the leg is drawn from the hip to the foot; the foot is on the ground in stance
    assert all(lx[0] == hx and lx[-1] == fx for lx, hx, fx in
               zip(frames["leg_x"], frames["hip_x"], frames["foot_x"], strict=True))
    stance = frames["stance"] > 0.5
    assert stance.any() and (~stance).any()
    assert np.abs(frames["foot_y"][stance]).max() < 1e-9


def test_the_animation_is_disturbed_at_the_second_touchdown(table61):
    gait = table61.gait
    frames = compute.runner_frames(compute.disturbed_run(gait, "push", -0.2))
    t, x = frames["t"], frames["com_x"]
    calm = _fine(gait)  # undisturbed: the periodic gait
    td = [e.t for e in calm.events if e.kind == "touchdown"]
    t2 = td[1]  # the second touch-down (the first is t = 0)
    assert td[0] == 0.0 and t2 > 0.3
    dev = np.abs(x - _at(calm, t, "x"))
    assert dev[t < t2 - 0.011].max() < 1e-4  # as the gait until the second touch-down
    # then 0.2 slower (the push): behind the gait by about 0.2 (t - t2) early on
    late = (t > t2 + 0.1) & (t < t2 + 0.2)
    assert late.any()
    assert dev[late] == pytest.approx(0.2 * (t[late] - t2), rel=0.25)


def test_the_animations_ground_steps_down_after_the_second_touchdown(table61):
    gait = table61.gait
    tr = compute.disturbed_run(gait, "step_down", -0.05)
    gx, gy = compute.ground(tr)
    run = _fine(gait, tslip.Disturbance(at_step=1, dh=-0.05))
    feet = [e.foot_x for e in run.events if e.kind == "touchdown"]
    step = gx[np.flatnonzero(np.diff(gy) < 0)[0]]  # where the ground drops
    assert gy[0] == 0.0 and gy[-1] == -0.05
    # the ground drops past the second foothold: the third and later touch down 0.05 lower
    assert step == pytest.approx(feet[1], abs=1e-9)
    assert [e.foot_y for e in run.events if e.kind == "touchdown"][1:4] == pytest.approx(
        [0.0, -0.05, -0.05], abs=1e-12)
    frames = compute.runner_frames(tr)  # the feet in stance stand on that ground
    stance = frames["stance"] > 0.5
    ground = np.where(frames["foot_x"] > step + 1e-9, -0.05, 0.0)  # the 2nd foot is at step
    assert np.abs(frames["foot_y"] - ground)[stance].max() < 1e-9
