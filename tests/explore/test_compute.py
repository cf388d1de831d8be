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
