"""End to end through the CLI: synth-video -> experiment on a small, short clip."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
from typer.testing import CliRunner

import tslip.cli.experiment  # noqa: F401  (registers the commands)
from tslip.cli.main import app


def test_chain_recovers_model(tmp_path: Path) -> None:
    """docs/reproducing.md's run (1.6 s, 512 x 408 px, 500 fps). Measured: markers 0.066 and
    0.076 px RMS; t_s 0.5876 and t_f 0.1231 against 0.5869 and 0.1244; k 7.97,
    beta0 0.929, c_l 0.329 against 8, 0.93, 0.32 (0.4, 0.1, 2.9 %); stance VAF
    >= 99.1 % for all but ld and betad (85, 92 %). Tolerances about twice the
    errors; VAF at least 98 % (75 % for ld and betad)."""
    r = CliRunner()
    video = tmp_path / "v.mp4"
    res = r.invoke(app, ["synth-video", "-o", str(video), "--duration", "1.6", "--width", "512",
                         "--height", "408", "--fps", "500"])
    assert res.exit_code == 0, res.output
    out = tmp_path / "exp"
    res = r.invoke(app, ["experiment", str(video), "-o", str(out)])
    assert res.exit_code == 0, res.output
    tracks = pd.read_csv(out / "tracks.csv")
    truth_px = pd.read_csv(tmp_path / "v.truth.csv")
    ok = tracks["body_q"] == 1
    assert ok.all()
    for m in ("front", "rear"):
        e = np.hypot(tracks[f"{m}_x_px"] - truth_px[f"{m}_x_px"],
                     tracks[f"{m}_y_px"] - truth_px[f"{m}_y_px"])
        assert np.sqrt(np.mean(e ** 2)) < 0.15, m
    fit = json.loads((out / "fit.json").read_text())
    truth = json.loads((tmp_path / "v.truth.json").read_text())
    p = truth["params"]
    for name, tol in (("k", 0.02), ("beta0", 0.01), ("c_l", 0.06)):
        assert abs(fit["values"][name] / p[name] - 1) < tol, (name, fit["values"][name], p[name])
    times = pd.read_csv(out / "table6_2.csv").set_index("quantity")
    assert abs(times.loc["stance_time", "measured_mean"] - truth["stance_time"]) < 0.003
    assert abs(times.loc["flight_time", "measured_mean"] - truth["flight_time"]) < 0.003
    scores = pd.read_csv(out / "table6_3.csv").set_index("signal")
    for s in ("y", "l", "beta", "phi", "xd", "yd", "phid"):
        assert scores.loc[s, "vaf_stance"] > 98.0, s
    for s in ("ld", "betad"):
        assert scores.loc[s, "vaf_stance"] > 75.0, s
    assert (out / "figure6_1.png").stat().st_size > 10_000
    assert (out / "figureD_2.png").exists()


def test_track_missing_video_exits_nonzero(tmp_path: Path) -> None:
    res = CliRunner().invoke(app, ["track", str(tmp_path / "none.mp4")])
    assert res.exit_code != 0
    assert "video not found" in res.output
