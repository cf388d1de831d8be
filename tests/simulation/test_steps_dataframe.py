"""``Trajectory.steps_dataframe`` (issue 42: it was never called or tested).

Each row is checked against the run's recorded samples (the compiled recording, a
different path from the stride results the table is built from): touch-down and
lift-off instants are always samples, so the touch-down state, the stance and flight
times and the foot are read off the recorded table; the ground height against the
terrain written here; and the flat-ground stride against thesis Table 6.2.
"""

import math

import numpy as np
import pytest

import tslip
from tslip.model.terrain import Terrain

STEP_AT, DROP = 2.0, -0.05  # a step down at x = 2 L


@pytest.fixture(scope="module")
def run():
    gait = tslip.find_gait(tslip.preset("table6.1"))
    tr = tslip.simulate(gait.params, gait.state, n_steps=6,
                        terrain=Terrain((STEP_AT,), (0.0, DROP)), dt=0.01)
    return tr, tr.to_dataframe(), tr.steps_dataframe()


def test_one_row_a_stride_with_the_recorded_touchdown_state(run):
    tr, rec, steps = run
    assert list(steps["step"]) == list(range(6)) == sorted(set(rec["step"]))
    for i, row in steps.iterrows():
        td = rec[rec["step"] == i].iloc[0]  # the touch-down instant, a sample
        assert td["stance"]
        for c in ("x", "xd", "yd", "phi", "phid", "beta", "foot_x"):
            assert row[c] == pytest.approx(td[c], abs=1e-9), (i, c)
        assert row["v"] == pytest.approx(math.hypot(td["xd"], td["yd"]), abs=1e-12)
        assert row["delta"] == pytest.approx(math.atan2(td["yd"], td["xd"]), abs=1e-12)
        assert row["status"] == "OK"


def test_ground_height_is_the_terrain_under_the_foot(run):
    _, rec, steps = run
    assert set(steps["h"]) == {0.0, DROP}  # the run crosses the step
    for i, row in steps.iterrows():
        assert row["h"] == (0.0 if row["foot_x"] < STEP_AT else DROP)
        stance = rec[(rec["step"] == i) & rec["stance"]]
        assert np.allclose(stance["foot_y"], row["h"], atol=1e-12)  # the foot stays put


def test_stance_and_flight_times_are_the_recorded_intervals(run):
    _, rec, steps = run
    t_td = [rec.loc[rec["step"] == i, "t"].iloc[0] for i in steps["step"]]
    t_lo = [rec.loc[(rec["step"] == i) & rec["stance"], "t"].iloc[-1] for i in steps["step"]]
    t_next = [*t_td[1:], rec["t"].iloc[-1]]  # the run ends at its last touch-down
    assert np.allclose(steps["stance_time"], np.subtract(t_lo, t_td), atol=1e-12)
    assert np.allclose(steps["flight_time"], np.subtract(t_next, t_lo), atol=1e-12)
    assert steps["stance_time"].nunique() > 1  # the step down changes them


def test_flat_ground_stride_is_thesis_table_6_2(run):
    _, _, steps = run
    first = steps.iloc[0]  # before the step: the periodic gait
    assert first["stance_time"] == pytest.approx(0.58, abs=0.01)  # Table 6.2: t_s 0.58
    assert first["flight_time"] == pytest.approx(0.13, abs=0.01)  # t_f 0.13


def test_columns_carry_units(run):
    _, _, steps = run
    units = steps.attrs["units"]
    assert units["stance_time"] == "g^-1/2 L^1/2" and units["x"] == "L"
    assert units["xd"] == "g^1/2 L^1/2" and units["beta"] == "rad"
