"""A synthetic recording of the two-legged model (Appendix E) against the biped simulation."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import tslip.cli.experiment  # noqa: F401  (registers the commands)
from tslip.biped import BipedParams, simulate
from tslip.biped.dynamics import foot_position, hip_position
from tslip.biped.gait import from_section
from tslip.biped.stored import gait_path
from tslip.cli.main import app
from tslip.experiment.render import camera_frames
from tslip.experiment.synth import Camera, synthesize_biped
from tslip.experiment.video import Calibration, TrackerOptions, track_frames
from tslip.model.units import ROBOT_SCALING

GAIT = gait_path("converged-e2")
CAM = Camera(width=512, height=408, fps=500.0)
L = ROBOT_SCALING.L
T = ROBOT_SCALING.factor("time")


@pytest.fixture(scope="module")
def gait():  # noqa: ANN201
    data = json.loads(GAIT.read_text())
    p = BipedParams.from_dict(data["params"])
    y, t0 = from_section(p, np.asarray(data["z"]))
    return p, y, t0


@pytest.fixture(scope="module")
def run(gait):  # noqa: ANN001, ANN201
    p, y, t0 = gait
    return synthesize_biped(p, y, 0.4, t0=t0, camera=CAM)


@pytest.fixture(scope="module")
def reference(gait):  # noqa: ANN001, ANN201
    """An independent run: the first right touch-down after t0 and the mean speed."""
    p, y, t0 = gait
    tr = simulate(p, y, 4, t0=t0)
    s = tr.strides
    speed = (s[-1, 1] - s[0, 1]) / (s[-1, 0] - s[0, 0]) * L / T
    x0 = hip_position(p, s[0, 1:10])[0] * L
    return tr, s[0, 0], speed, x0


def _state_at(gait, t_model: float) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001
    """State and contact flags at ``t_model``, integrated to exactly that time."""
    p, y, t0 = gait
    tr = simulate(p, y, 10, t0=t0, t_end=t_model)
    assert tr.time[-1] == pytest.approx(t_model, abs=1e-12)
    return tr.final_state[:9], tr.final_contact[:2]


def test_recording_starts_at_right_touchdown_and_belt_is_mean_speed(run, reference) -> None:  # noqa: ANN001
    tr, t_td, speed, _ = reference
    assert run.belt_speed == pytest.approx(speed, rel=1e-9)
    tds = run.touchdowns
    assert tds["leg"].iloc[0] == "near" and abs(tds["t"].iloc[0]) < 1e-12
    assert list(tds["leg"]) == ["near", "hind"] * (len(tds) // 2) + ["near"] * (len(tds) % 2)
    # stance and flight time of the right foot, from the independent run's events
    ev = [(e.t, e.kind) for e in tr.events if e.t >= t_td - 1e-12]
    lo_r = next(t for t, k in ev if k == "liftoff_R")
    td_l = next(t for t, k in ev if k == "touchdown_L" and t > lo_r)
    assert run.stance_time == pytest.approx(lo_r - t_td, abs=1e-6)
    assert run.flight_time == pytest.approx(td_l - lo_r, abs=1e-6)
    assert run.flight_time > 0                      # a running gait: both feet off the ground
    assert tds["liftoff_t"].iloc[0] == pytest.approx(run.stance_time * T, abs=1e-6)


@pytest.mark.parametrize("k", [17, 50, 69, 77, 101, 150, 199])
def test_truth_is_biped_kinematics_at_frame_times(gait, run, reference, k: int) -> None:  # noqa: ANN001
    p = gait[0]
    _, t_td, speed, x0 = reference
    row = run.truth.iloc[k]
    t = row["t"]
    q, on = _state_at(gait, t_td + t / T)
    shift = speed * t + x0                          # world -> camera frame [m]
    tol = 2e-5                                      # linear interpolation of the rows [m]
    for name, leg in (("near", 0), ("hind", 1)):
        f = foot_position(p, q, leg) * L
        assert row[f"{name}_x_m"] == pytest.approx(f[0] - shift, abs=tol)
        assert row[f"{name}_y_m"] == pytest.approx(f[1], abs=tol)
        assert bool(row[f"{name}_stance"]) == bool(on[leg])
    hip = hip_position(p, q) * L
    assert row["hip_x_m"] == pytest.approx(hip[0] - shift, abs=tol)
    assert row["hip_y_m"] == pytest.approx(hip[1], abs=tol)
    assert row["com_x_m"] == pytest.approx(q[0] * L - shift, abs=tol)
    assert row["com_y_m"] == pytest.approx(q[1] * L, abs=tol)
    assert row["phi"] == pytest.approx(-q[2], abs=1e-5)     # phi counter-clockwise, theta_b not


def test_stance_feet_on_the_ground_and_flags_match_touchdowns(run) -> None:  # noqa: ANN001
    tru, tds = run.truth, run.touchdowns
    t = tru["t"].to_numpy()
    for name in ("near", "hind"):
        on = tru[f"{name}_stance"].to_numpy()
        y = tru[f"{name}_y_m"].to_numpy()
        assert on.any() and (~on).any()
        # compliant ground (Table E.3: k_z = 100 M g / L): a stance foot sinks in, up to
        # 0.02 L for a peak force of 2 M g, and never stands above the surface
        assert y[on].max() < 1e-9 and y[on].min() > -0.02 * L
        assert y[~on].max() > 0.05                  # the swing lifts the foot
        expect = np.zeros(len(t), dtype=bool)
        for _, s in tds[tds["leg"] == name].iterrows():
            expect |= (t >= s["t"]) & (t < s["liftoff_t"])
        assert np.array_equal(on, expect)
        # a stance foot stays put on the belt, which carries it back at the belt speed
        v = np.diff(tru[f"{name}_x_m"].to_numpy()) * CAM.fps
        both = on[1:] & on[:-1]
        assert np.median(v[both]) == pytest.approx(-run.belt_speed, rel=0.02)
    flight = ~(tru["near_stance"] | tru["hind_stance"])
    assert flight.any()                             # aerial phases are recorded


def test_near_and_hind_are_distinct_legs_half_a_stride_apart(run, gait) -> None:  # noqa: ANN001
    tru = run.truth
    t = tru["t"].to_numpy()
    near = tru[["near_x_m", "near_y_m"]].to_numpy()
    hind = tru[["hind_x_m", "hind_y_m"]].to_numpy()
    gap = np.hypot(*(near - hind).T)
    assert gap.min() > 0.05 and np.sqrt(np.mean(gap ** 2)) > 0.1
    # symmetric gait, controller phases half a period apart (eq. E.27): the hind foot
    # repeats the near foot's path half a stride later
    half = 0.5 * gait[0].T * T
    later = t >= t[0] + half
    for j in (0, 1):
        shifted = np.interp(t[later] - half, t, near[:, j])
        assert np.max(np.abs(hind[later, j] - shifted)) < 5e-4


def test_pixels_agree_with_metres_and_disc_geometry(run, gait) -> None:  # noqa: ANN001
    tru, g = run.truth, run.geometry
    s = CAM.px_per_m
    assert g.r == pytest.approx(gait[0].r_1 * L)
    for m in ("front", "rear", "near", "hind", "hip", "com"):
        np.testing.assert_allclose(tru[f"{m}_x_px"], CAM.hip_px + s * tru[f"{m}_x_m"], atol=1e-9)
        np.testing.assert_allclose(tru[f"{m}_y_px"], CAM.ground_px - s * tru[f"{m}_y_m"],
                                   atol=1e-9)
    front = tru[["front_x_m", "front_y_m"]].to_numpy()
    rear = tru[["rear_x_m", "rear_y_m"]].to_numpy()
    np.testing.assert_allclose(np.hypot(*(front - rear).T), 2 * g.b, atol=1e-12)
    com, hip, phi = g.com_from_discs(front, rear)
    np.testing.assert_allclose(phi, tru["phi"], atol=1e-12)
    np.testing.assert_allclose(hip, tru[["hip_x_m", "hip_y_m"]], atol=1e-12)
    # the trunk CoM of the biped is where the discs put it
    np.testing.assert_allclose(com, tru[["com_x_m", "com_y_m"]], atol=1e-12)


def test_tracking_recovers_the_markers(run) -> None:  # noqa: ANN001
    """First 100 frames. Measured: discs 0.065 (front) and 0.098 (rear) px RMS,
    every frame detected; feet 0.10 and 0.12 px RMS on their legs. Tolerances
    about 1.5-2x that: 0.15 px for the discs, 0.25 px for the feet. Without
    the sub-pixel circle fit the discs are 0.38 and 0.45 px RMS off."""
    cal = Calibration(CAM.px_per_m, CAM.ground_px, CAM.hip_px)
    res = track_frames(camera_frames(run, stop=100), cal, TrackerOptions.for_scale(cal.px_per_m),
                       fps=CAM.fps)
    tr, tru = res.tracks, run.truth.iloc[:100]
    assert not res.fatal and res.body_detection_rate == 1.0
    ok = tr["body_q"] == 1
    for m in ("front", "rear"):
        e = np.hypot(tr[f"{m}_x_px"] - tru[f"{m}_x_px"], tr[f"{m}_y_px"] - tru[f"{m}_y_px"])
        assert np.sqrt(np.mean(e[ok] ** 2)) < 0.15, m
    # each foot series follows one leg of the model, and the two series follow different legs
    err = {}
    for f in ("foot1", "foot2"):
        okf = tr[f"{f}_q"] == 1
        assert okf.mean() > 0.9
        for leg in ("near", "hind"):
            e = np.hypot(tr[f"{f}_x_px"] - tru[f"{leg}_x_px"], tr[f"{f}_y_px"] - tru[f"{leg}_y_px"])
            err[f, leg] = np.sqrt(np.mean(e[okf] ** 2))
    best = {f: min(("near", "hind"), key=lambda leg: err[f, leg]) for f in ("foot1", "foot2")}
    assert set(best.values()) == {"near", "hind"}
    assert max(err[f, leg] for f, leg in best.items()) < 0.25


def test_falls_and_bad_input_raise(gait) -> None:  # noqa: ANN001
    p, y, t0 = gait
    low = y.copy()
    low[1] = 0.25                                   # trunk CoM far too low: the legs collapse
    with pytest.raises(ValueError, match="failed at t = .*fall") as exc:
        synthesize_biped(p, low, 0.1, t0=t0, camera=CAM)
    assert "\n" not in str(exc.value)
    with pytest.raises(ValueError, match="duration"):
        synthesize_biped(p, y, 0.0, t0=t0, camera=CAM)
    with pytest.raises(ValueError, match="shape"):
        synthesize_biped(p, y[:9], 0.1, t0=t0, camera=CAM)


def test_cli_biped_gait_writes_frames_and_truth(gait, tmp_path: Path) -> None:  # noqa: ANN001
    out = tmp_path / "clip"
    res = CliRunner().invoke(app, ["synth-video", "--biped-gait", str(GAIT), "-o", str(out),
                                   "--duration", "0.01", "--width", "128", "--height", "102",
                                   "--fps", "500", "--noise", "0"])
    assert res.exit_code == 0, res.output
    assert len(list(out.glob("frame_*.png"))) == 5
    truth = pd.read_csv(out / "truth.csv")
    meta = json.loads((out / "truth.json").read_text())
    assert meta["model"] == "biped" and meta["params"]["T"] == gait[0].T
    p, y, t0 = gait
    direct = synthesize_biped(p, y, 0.01, t0=t0, camera=Camera(width=128, height=102, fps=500.0))
    np.testing.assert_allclose(truth["near_x_m"], direct.truth["near_x_m"], atol=1e-9)
    np.testing.assert_allclose(truth["hind_y_px"], direct.truth["hind_y_px"], atol=1e-6)


@pytest.mark.parametrize("content", [None, "{not json", '{"params": {}, "z": [0.5]}'])
def test_cli_bad_biped_gait_exits_2(tmp_path: Path, content: str | None) -> None:
    path = tmp_path / "gait.json"
    if content is not None:
        path.write_text(content)
    res = CliRunner().invoke(app, ["synth-video", "--biped-gait", str(path), "-o",
                                   str(tmp_path / "v.mp4"), "--duration", "0.01"])
    assert res.exit_code == 2
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and "gait file" in lines[0]
    assert not (tmp_path / "v.mp4").exists()


def test_contact_events_find_the_biped_stances_on_its_compliant_ground(gait):
    """The biped's stance foot sinks up to 7 mm into the Table E.3 ground, deeper
    than the contact threshold: the stance must still start at touch-down and end
    at lift-off (the corner of the height trace), not where the foot crosses
    the threshold. Heights from the truth plus 0.3 mm of noise."""
    from tslip.experiment.signals import contact_events

    p, y, t0 = gait
    r = synthesize_biped(p, y, 1.2, t0=t0, camera=CAM)
    tt = r.truth["t"].to_numpy()
    h = r.truth["near_y_m"].to_numpy() + np.random.default_rng(0).normal(0.0, 3e-4, len(tt))
    assert h.min() < -0.006  # the foot does sink below the threshold
    level = float(np.percentile(np.r_[h, r.truth["hind_y_m"].to_numpy()], 5))
    ev = contact_events(h, tt, level, 0.004)
    want = r.touchdowns[(r.touchdowns["leg"] == "near") & (r.touchdowns["t"] > 0.005)
                        & (r.touchdowns["liftoff_t"] < tt[-1] - 0.005)]
    assert len(ev) == len(want) >= 2
    frame = 1.0 / CAM.fps
    d_lo = []
    for (t_td, t_lo, _, _), (_, row) in zip(ev, want.iterrows(), strict=True):
        assert abs(t_td - row["t"]) < 1.0 * frame  # a sharp corner: 0.1-0.5 frame seen
        d_lo.append(t_lo - row["liftoff_t"])
    # lift-off is a gentle corner (the unloading foot rises before the force is zero):
    # -2.8 to +1.2 frames seen over 3 noise seeds and 48 stances
    assert np.max(np.abs(d_lo)) < 3.0 * frame and abs(np.mean(d_lo)) < 1.0 * frame
