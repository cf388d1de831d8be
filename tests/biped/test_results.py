"""The biped's results save, load, tabulate, print and plot as the TSLIP's do."""

from __future__ import annotations

import numpy as np
import pytest

import tslip
from _result_checks import check_frozen, check_plot, check_repr, check_round_trip, check_units
from tslip.biped import BipedOptions, BipedParams, BipedState, Status, simulate, step
from tslip.biped.design import DesignSearch
from tslip.biped.gait import find_periodic_gait, floquet, to_section
from tslip.biped.metacentre import metacentric_test
from tslip.biped.robustness import RobustnessResult
from tslip.biped.stored import load_gait
from tslip.gait.robustness import RobustnessLimit


@pytest.fixture(scope="module")
def objects():
    p, y, t0, _ = load_gait("converged-e2")
    tr = simulate(p, y, 2, t0=t0)
    z = to_section(p, y, t0)
    fell = simulate(BipedParams(), BipedState.thesis(), 3)
    return {
        "Trajectory": tr,
        "Trajectory, short": fell,
        "StepResult": step(p, y, t0),
        "Gait": find_periodic_gait(p, z, cma_evals=0, lsq_evals=2),
        "Floquet": floquet(p, z),
        "PitchResponse": metacentric_test(p, BipedState.from_array(y), t0,
                                          pitches=(0.0, 0.1)),
        "RobustnessResult": RobustnessResult(
            limits=(RobustnessLimit("step_down", -1, -0.1625, -0.1626, 3, Status.FALL_TRIP, 9,
                                    40, 0),
                    RobustnessLimit("push", -1, -0.8237, -0.8238, 1, Status.FALL_BACKWARD, 8,
                                    35, 1)),
            params=p, z=z, n_steps=25, tol=1e-3, options=BipedOptions()),
        "DesignSearch": DesignSearch(
            best={"score": 0.81, "residual": 3e-9, "params": p.to_dict(), "z": z.tolist(),
                  "largest": 0.81, "message": "ok", "design": {"Kp_h": 1.25}},
            evaluations=17, history=(0.93, 0.88, 0.81), seconds=12.5, interrupted=True),
    }


NAMES = ["Trajectory", "Trajectory, short", "StepResult", "Gait", "Floquet", "PitchResponse",
         "RobustnessResult", "DesignSearch"]
NO_PLOT = {"StepResult"}


@pytest.mark.parametrize("name", NAMES)
def test_is_a_frozen_result(objects, name):
    check_frozen(objects[name])


@pytest.mark.parametrize("suffix", [".json", ".parquet", ".csv"])
@pytest.mark.parametrize("name", NAMES)
def test_round_trip_is_bit_for_bit(objects, name, suffix, tmp_path):
    check_round_trip(objects[name], tmp_path / f"r{suffix}")


@pytest.mark.parametrize("name", NAMES)
def test_units(objects, name):
    check_units(objects[name])


@pytest.mark.parametrize("name", NAMES)
def test_repr(objects, name):
    check_repr(objects[name])


@pytest.mark.parametrize("name", sorted(set(NAMES) - NO_PLOT))
def test_plot(objects, name):
    check_plot(objects[name])


def test_the_classes_are_the_biped_ones(objects):
    import importlib

    from tslip.biped import gait as bg

    bs = importlib.import_module("tslip.biped.simulate")  # the function shadows the module

    assert type(objects["Trajectory"]) is bs.Trajectory
    assert type(objects["StepResult"]) is bs.StepResult
    assert type(objects["Gait"]) is bg.Gait and type(objects["Floquet"]) is bg.Floquet
    assert isinstance(objects["PitchResponse"].nominal.params, BipedParams)


def test_state_units_follow_the_coordinates(objects):
    """Angles (theta_*) in rad, lengths and positions in L; rates per g^-1/2 L^1/2."""
    u = objects["Trajectory"].to_dataframe().attrs["units"]
    assert u["theta_b"] == "rad" and u["theta_hR_d"] == "rad g^1/2 L^-1/2"
    assert u["l_tR"] == "L" and u["x_b_d"] == "g^1/2 L^1/2" and u["Fz_R"] == "Mg"
    assert u["tau_L"] == "MgL" and u["t"] == "g^-1/2 L^1/2"


def test_loaded_trajectory_works_like_the_original(objects, tmp_path):
    tr = objects["Trajectory"]
    back = tslip.load(tr.save(tmp_path / "b.parquet"))
    assert back.n_steps == tr.n_steps and back.count_strides() == tr.count_strides()
    assert np.array_equal(back["Fz_R"], tr["Fz_R"])


def test_design_search_reads_as_the_dict_it_replaced(objects):
    r = objects["DesignSearch"]
    assert r["best"]["score"] == 0.81 and r["history"] == (0.93, 0.88, 0.81)
    assert r["interrupted"] is True and r["evaluations"] == 17
    with pytest.raises(KeyError):
        r["nope"]
    df = r.to_dataframe()
    assert list(df["best_score"]) == [0.93, 0.88, 0.81] and list(df["generation"]) == [0, 1, 2]
