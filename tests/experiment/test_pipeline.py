"""End to end through the CLI: synth-video -> experiment on a small, short clip."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
from typer.testing import CliRunner

import tslip.cli.experiment  # noqa: F401  (registers the commands)
from tslip.cli.main import app


def test_chain_recovers_model(tmp_path: Path) -> None:
    r = CliRunner()
    video = tmp_path / "v.mp4"
    res = r.invoke(app, ["synth-video", "-o", str(video), "--duration", "1.6", "--width", "512",
                         "--height", "408", "--fps", "500"])
    assert res.exit_code == 0, res.output
    out = tmp_path / "exp"
    res = r.invoke(app, ["experiment", str(video), "-o", str(out)])
    assert res.exit_code == 0, res.output
    fit = json.loads((out / "fit.json").read_text())
    truth = json.loads((tmp_path / "v.truth.json").read_text())
    p = truth["params"]
    for name, true in (("k", p["k"]), ("beta0", p["beta0"]), ("c_l", p["c_l"])):
        assert abs(fit["values"][name] / true - 1) < 0.10, (name, fit["values"][name], true)
    times = pd.read_csv(out / "table6_2.csv").set_index("quantity")
    assert abs(times.loc["stance_time", "measured_mean"] - truth["stance_time"]) < 0.01
    assert abs(times.loc["flight_time", "measured_mean"] - truth["flight_time"]) < 0.01
    scores = pd.read_csv(out / "table6_3.csv").set_index("signal")
    assert scores.loc["l", "vaf_stance"] > 95.0
    assert (out / "figure6_1.png").stat().st_size > 10_000
    assert (out / "figureD_2.png").exists()


def test_track_missing_video_exits_nonzero(tmp_path: Path) -> None:
    res = CliRunner().invoke(app, ["track", str(tmp_path / "none.mp4")])
    assert res.exit_code != 0
    assert "video not found" in res.output
