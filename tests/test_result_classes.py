"""Every result object saves, loads, tabulates, prints and plots the same way.

Bit-for-bit round trips through .json and .parquet (and .csv for the tables
that hold arrays), a unit for every column, ``.plot`` drawing on the axes it
is given, and a one-line repr.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import tslip
from _result_checks import check_frozen, check_plot, check_repr, check_round_trip, check_units
from experiment._truth import truth_tracks
from tslip import gait as tg
from tslip._results import Result

P = tslip.preset("table6.1")
SLIP = tslip.preset("slip")


@pytest.fixture(scope="module")
def gait():
    return tslip.find_gait(P)


def _objects(gait) -> dict[str, object]:
    """One instance of every result class (small runs: strides, not studies)."""
    tr = tslip.simulate(gait.params, gait.state, n_steps=3)
    rows = np.array([gait.state.as_array()] * 2)
    bad = rows.copy()
    bad[1, 2] = 0.1  # too slow: a fall
    lin = tg.impulse_linearisation(gait)
    pr = tg.pitch_disturbance_response(gait, (0.0, 0.2))
    branch = tslip.continue_gait(gait, "k", [P.k, P.k + 0.2])
    return {
        "Trajectory": tr,
        "Trajectory, a fall": tslip.simulate(gait.params, tslip.TouchdownState.from_section(
            bad[1, :5]), n_steps=3),
        "StepResult": tr.steps[1],
        "BatchStep": tslip.step_batch(gait.params, bad),
        "BatchRun": tslip.run_batch(gait.params, bad, 3),
        "Gait": gait,
        "Floquet": tslip.floquet(gait),
        "RobustnessResult": tslip.robustness_report(gait, n_steps=5, kinds=("step_down",)),
        "Impulse": lin.nominal,
        "ImpulseLinearisation": lin,
        "PitchResponse": pr,
        "Branch": branch,
        "StrideProperties": tg.stride_properties(gait),
        "FrictionCheck": tg.friction_ratio(gait.params, gait.state, mu=0.5),
        "HeightChangeResult": tg.velocity_after_height_change(gait, -0.05, n_steps=20,
                                                              n_average=5),
        "StepDownResponse": tg.step_down_response(gait, -0.05, n_steps=4),
        "VelocityAngleCase": tg.velocity_angle_effect(gait, (0.02,))[0],
        "GaitReport": tg.analyse(gait.params, gait=gait, n_steps=5),
        "GaitSet": tslip.all_gaits(SLIP, energy=2.2),
        "StableRegion": tslip.stable_region(SLIP, {"beta0": [1.17, 1.19], "k": [25.0, 27.0]},
                                            energy=2.2),
    }


def _study_and_experiment(gait) -> dict[str, object]:
    """A two-point study, and the video pipeline on a short synthetic run."""

    from tslip.experiment.fit import FitResult, fit_scores, model_curves, stride_table
    from tslip.experiment.render import camera_frames
    from tslip.experiment.signals import ProcessOptions, average_steps, process_tracks
    from tslip.experiment.synth import Camera, synthesize
    from tslip.experiment.video import Calibration, TrackerOptions, track_frames
    from tslip.sweeps.run import run_study
    from tslip.sweeps.spec import Axis, StudySpec

    study = run_study(StudySpec("two", P, (Axis("k", (P.k, P.k + 0.5)),),
                                analyses=("floquet", "stride")), workers=1)
    cam = Camera(width=512, height=408, fps=500.0)
    run = synthesize(gait.params, gait.state, 1.6, camera=cam)
    tracks = truth_tracks(run)
    data = process_tracks(tracks, cam.fps, run.geometry, options=ProcessOptions(near="foot1"))
    avg = average_steps(data.samples, data.steps)
    curves, ts, tf, _ = model_curves(gait.params, avg.tau)
    fit = FitResult(params=gait.params, values={"k": gait.params.k}, stance_time=ts,
                    flight_time=tf, curves=curves, scores=fit_scores(avg, curves),
                    times=stride_table(avg, ts, tf), cost=0.5, n_evals=1, converged=True,
                    message="built in the test")
    cal = Calibration(cam.px_per_m, cam.ground_px, cam.hip_px)
    track = track_frames(camera_frames(run, stop=6), cal, TrackerOptions.for_scale(
        cal.px_per_m), fps=cam.fps)
    return {"StudyResult": study, "SyntheticRun": run, "StepData": data, "StepAverage": avg,
            "FitResult": fit, "TrackResult": track}


@pytest.fixture(scope="module")
def objects(gait):
    objs = _objects(gait)
    objs["RobustnessLimit"] = objs["RobustnessResult"].limits[0]
    objs.update(_study_and_experiment(gait))
    return objs


NAMES = ["Trajectory", "Trajectory, a fall", "StepResult", "BatchStep", "BatchRun", "Gait",
         "Floquet", "RobustnessResult", "RobustnessLimit", "Impulse", "ImpulseLinearisation",
         "PitchResponse", "Branch", "StrideProperties", "FrictionCheck", "HeightChangeResult",
         "StepDownResponse", "VelocityAngleCase", "StudyResult", "SyntheticRun", "StepData",
         "StepAverage", "FitResult", "TrackResult", "GaitReport", "GaitSet", "StableRegion"]
#: Classes without a figure of their own.
NO_PLOT = {"BatchStep", "RobustnessLimit", "StrideProperties", "SyntheticRun", "TrackResult",
           "GaitSet"}


@pytest.mark.parametrize("name", NAMES)
def test_is_a_frozen_result_dataclass(objects, name):
    check_frozen(objects[name])


@pytest.mark.parametrize("suffix", [".json", ".parquet", ".csv"])
@pytest.mark.parametrize("name", NAMES)
def test_round_trip_is_bit_for_bit(objects, name, suffix, tmp_path):
    check_round_trip(objects[name], tmp_path / f"r{suffix}")


@pytest.mark.parametrize("name", NAMES)
def test_table_has_a_unit_for_every_column(objects, name):
    check_units(objects[name])


@pytest.mark.parametrize("name", NAMES)
def test_repr_is_one_short_line(objects, name):
    check_repr(objects[name])


@pytest.mark.parametrize("name", sorted(set(NAMES) - NO_PLOT))
def test_plot_draws_on_the_given_axes(objects, name):
    check_plot(objects[name])


@pytest.mark.parametrize("name", sorted(NO_PLOT))
def test_results_without_a_figure_have_no_plot(objects, name):
    assert not hasattr(objects[name], "plot")


def test_every_result_class_is_covered(objects):
    """Each Result subclass of the TSLIP's modules is in the table above."""

    import tslip.gait.viability  # noqa: F401 - its classes are Result subclasses too

    mods = ("tslip.simulation", "tslip.gait", "tslip.sweeps", "tslip.experiment")
    classes = {c.__name__ for c in _subclasses(Result) if c.__module__.startswith(mods)}
    assert classes - ELSEWHERE.keys() <= {type(o).__name__ for o in objects.values()}


#: Result classes whose round trips, tables and plots other test files check, and bases
#: checked through their subclasses.
ELSEWHERE = {**dict.fromkeys(("StateActionMap", "Viability", "Basin"),
                             "tests/gait/test_viability.py"),
             "ViableSection": "tests/gait/test_viability_3d.py",
             "RobustnessLimits": "RobustnessResult here and in tests/biped/test_results.py",
             "DesignResult": "tests/sweeps/test_design.py"}


def _subclasses(cls):
    for sub in cls.__subclasses__():
        yield sub
        yield from _subclasses(sub)


def test_trajectory_table_matches_its_samples(objects):
    """Independent check of the table: the trajectory's own columns, unchanged."""
    tr = objects["Trajectory"]
    df = tr.to_dataframe()
    assert np.array_equal(df["t"].to_numpy(), tr.data[:, 0])
    assert df.attrs["units"]["Fy"] == "Mg" and df.attrs["units"]["xd"] == "g^1/2 L^1/2"
    assert df.attrs["units"]["phid"] == "rad g^1/2 L^-1/2"


def test_loaded_trajectory_rebuilds_its_strides_and_events(objects, tmp_path):
    tr = objects["Trajectory"]
    back = tslip.load(tr.save(tmp_path / "t.parquet"))
    assert [e.kind for e in back.events] == [e.kind for e in tr.events]
    assert back.steps[2].state == tr.steps[2].state
    assert np.array_equal(back.steps[1].grf, tr.steps[1].grf)


def test_gait_report_dict_is_the_results_numbers(objects):
    """The JSON dict of the report holds the numbers of the result objects it keeps."""
    rep = objects["GaitReport"]
    d = rep.to_dict()
    json.dumps(d, allow_nan=False)  # plain JSON
    assert d["floquet"]["max_nontrivial"] == rep.floquet.max_nontrivial
    assert d["robustness"]["step_down"]["limit"] == rep.robustness.step_down
    assert d["stride"]["duty_factor"] == rep.stride.duty_factor
    assert d["gait"]["stance_time"] == rep.gait.stance_time
    assert d["impulse"]["nominal"]["I_y"] == rep.impulse.nominal.I_y
    assert not rep.errors


def test_gait_report_keeps_the_reason_of_a_refused_analysis(gait, tmp_path):
    """Robustness refuses an unconverged gait: the report keeps why, and still saves."""
    import dataclasses

    bad = dataclasses.replace(gait, converged=False)
    rep = tg.analyse(bad.params, gait=bad, n_steps=3)
    assert rep.robustness is None and "converge" in rep.errors["robustness"]
    assert rep.to_dict()["robustness"] == {"error": rep.errors["robustness"]}
    assert rep.to_dataframe()["step_down"].isna().all()
    check_round_trip(rep, tmp_path / "rep.json")
