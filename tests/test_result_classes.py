"""Every result object saves, loads, tabulates, prints and plots the same way.

Bit-for-bit round trips through .json and .parquet (and .csv for the tables
that hold arrays), a unit for every column, ``.plot`` drawing on the axes it
is given, and a one-line repr.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from matplotlib.figure import Figure

import tslip
from _same import same
from tslip import gait as tg
from tslip._results import Result

P = tslip.preset("table6.1")


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
    }


def _study_and_experiment(gait) -> dict[str, object]:
    """A two-point study, and the video pipeline on a short synthetic run."""
    import pandas as pd

    from tslip.experiment.fit import FitResult, fit_scores, model_curves, stride_table
    from tslip.experiment.render import render_frames
    from tslip.experiment.signals import ProcessOptions, average_steps, process_tracks
    from tslip.experiment.synth import Camera, synthesize
    from tslip.experiment.video import Calibration, TrackerOptions, track_frames
    from tslip.sweeps.run import run_study
    from tslip.sweeps.spec import Axis, StudySpec

    study = run_study(StudySpec("two", P, (Axis("k", (P.k, P.k + 0.5)),),
                                analyses=("floquet", "stride")), workers=1)
    cam = Camera(width=512, height=408, fps=500.0)
    run = synthesize(gait.params, gait.state, 1.6, camera=cam)
    tru = run.truth
    tracks = pd.DataFrame({"frame": tru["frame"], "t": tru["t"], "body_q": 1, "foot1_q": 1,
                           "foot2_q": 1})
    for m, src in (("front", "front"), ("rear", "rear"), ("foot1", "near"), ("foot2", "hind")):
        tracks[f"{m}_x_m"] = tru[f"{src}_x_m"]
        tracks[f"{m}_y_m"] = tru[f"{src}_y_m"]
    data = process_tracks(tracks, cam.fps, run.geometry, options=ProcessOptions(near="foot1"))
    avg = average_steps(data.samples, data.steps)
    curves, ts, tf, _ = model_curves(gait.params, avg.tau)
    fit = FitResult(params=gait.params, values={"k": gait.params.k}, stance_time=ts,
                    flight_time=tf, curves=curves, scores=fit_scores(avg, curves),
                    times=stride_table(avg, ts, tf), cost=0.5, n_evals=1, converged=True,
                    message="built in the test")
    cal = Calibration(cam.px_per_m, cam.ground_px, cam.hip_px)
    track = track_frames(render_frames(run, stop=6), cal, TrackerOptions.for_scale(
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
         "StepAverage", "FitResult", "TrackResult"]
#: Classes without a figure of their own.
NO_PLOT = {"BatchStep", "RobustnessLimit", "StrideProperties", "SyntheticRun", "TrackResult"}


@pytest.mark.parametrize("name", NAMES)
def test_is_a_frozen_result_dataclass(objects, name):
    obj = objects[name]
    assert isinstance(obj, Result) and dataclasses.is_dataclass(obj)
    f = dataclasses.fields(obj)[0].name
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(obj, f, None)


@pytest.mark.parametrize("suffix", [".json", ".parquet", ".csv"])
@pytest.mark.parametrize("name", NAMES)
def test_round_trip_is_bit_for_bit(objects, name, suffix, tmp_path):
    obj = objects[name]
    path = obj.save(tmp_path / f"r{suffix}")
    back = tslip.load(path)
    same(obj, back)
    same(obj, type(obj).load(path))
    rec = json.loads(path.with_suffix(".json").read_text())
    run = rec["run"]
    assert run["tslip_version"] == tslip.__version__ and len(run["code_hash"]) == 24
    assert run["class"] == f"{type(obj).__module__}:{type(obj).__qualname__}"
    if hasattr(obj, "params"):
        assert run["params"] == obj.params.to_dict()
    if suffix != ".json":  # the table beside the record is to_dataframe()
        import pandas as pd

        df = pd.read_parquet(path) if suffix == ".parquet" else pd.read_csv(path)
        want = obj.to_dataframe()
        assert list(df.columns) == list(want.columns) and len(df) == len(want)
        assert rec["table"]["units"] == want.attrs["units"]


@pytest.mark.parametrize("name", NAMES)
def test_table_has_a_unit_for_every_column(objects, name):
    df = objects[name].to_dataframe()
    units = df.attrs["units"]
    assert list(units) == [str(c) for c in df.columns]
    assert all(isinstance(u, str) and u for u in units.values())
    assert len(df.columns) > 0 and df.columns.is_unique


@pytest.mark.parametrize("name", NAMES)
def test_repr_is_one_short_line(objects, name):
    text = repr(objects[name])
    assert "\n" not in text and len(text) <= 200
    assert text.startswith(type(objects[name]).__name__ + "(")


@pytest.mark.parametrize("name", sorted(set(NAMES) - NO_PLOT))
def test_plot_draws_on_the_given_axes(objects, name):
    fig = Figure()
    ax = fig.add_subplot()
    assert objects[name].plot(ax=ax) is fig
    assert ax.lines or ax.patches or ax.collections  # something was drawn there
    assert len(fig.axes) <= 2  # on ax (a twin axis at most), not on new axes
    own = objects[name].plot()
    assert isinstance(own, Figure) and own is not fig and own.axes


@pytest.mark.parametrize("name", sorted(NO_PLOT))
def test_results_without_a_figure_have_no_plot(objects, name):
    assert not hasattr(objects[name], "plot")


def test_every_result_class_is_covered(objects):
    """Each Result subclass of the TSLIP's modules is in the table above."""

    mods = ("tslip.simulation", "tslip.gait", "tslip.sweeps", "tslip.experiment")
    classes = {c.__name__ for c in _subclasses(Result) if c.__module__.startswith(mods)}
    assert classes <= {type(o).__name__ for o in objects.values()}


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
