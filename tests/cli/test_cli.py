"""The ``tslip`` command line, run in-process with typer's CliRunner."""

import json
import re
import subprocess
import sys

import imageio.v3 as iio
import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import tslip
from tslip.cli.main import app
from tslip.simulation.result import TRAJECTORY_COLUMNS

runner = CliRunner()
ROW = re.compile(r"^\s*(\d+)\s+\d+\.\d{4}\s+[+-]\d+\.\d{4}\s")


def invoke(*args: str):
    return runner.invoke(app, [str(a) for a in args])


def ok(*args: str):
    result = invoke(*args)
    assert result.exit_code == 0, result.output
    assert "Traceback" not in result.output
    return result


def test_simulate_prints_one_row_per_stride():
    result = ok("simulate", "--steps", "20")
    steps = [int(m.group(1)) for line in result.stdout.splitlines() if (m := ROW.match(line))]
    assert steps == list(range(20))
    assert "periodic gait found" in result.stdout
    assert result.stdout.strip().splitlines()[-1].startswith("status: OK, 20 strides")


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_simulate_out_writes_reloadable_table(tmp_path, suffix):
    out = tmp_path / f"run{suffix}"
    ok("simulate", "--steps", "3", "--out", out)
    df = pd.read_csv(out) if suffix == ".csv" else pd.read_parquet(out)
    assert list(df.columns) == list(TRAJECTORY_COLUMNS)
    assert len(df) > 50
    assert np.all(np.diff(df["t"].to_numpy()) > 0)
    assert sorted(df["step"].unique()) == [0, 1, 2]
    meta = json.loads(out.with_suffix(".json").read_text())
    assert meta["status"] == "OK" and meta["n_steps"] == 3
    assert meta["gait"]["converged"] is True
    assert meta["options"] == {"rtol": 1e-8, "atol": 1e-8}


def test_simulate_plot_writes_png(tmp_path):
    png = tmp_path / "plots" / "run.png"
    ok("simulate", "--steps", "3", "--plot", png)
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(data) > 10_000


def test_overrides_from_set_and_toml_reach_the_run(tmp_path):
    toml = tmp_path / "p.toml"
    toml.write_text("[params]\nk = 28.0\nr = 0.2\n")
    out = tmp_path / "run.csv"
    ok(
        "simulate",
        "--steps",
        "2",
        "--params",
        toml,
        "--set",
        "r=0.25",
        "--set",
        "omega_r_bar=0.3",
        "--out",
        out,
    )
    params = json.loads(out.with_suffix(".json").read_text())["params"]
    assert params["k"] == 28.0  # from the file
    assert params["r"] == 0.25  # --set wins over the file
    assert params["omega_r"] == pytest.approx(0.3 * params["v0"] / params["l0"])


def test_controller_by_name_and_gain(tmp_path):
    out = tmp_path / "run.csv"
    result = ok(
        "simulate",
        "--steps",
        "2",
        "--set",
        "controller=local_velocity",
        "--set",
        "controller.Kd=0.3",
        "--out",
        out,
    )
    assert "periodic gait found" in result.stdout
    ctrl = json.loads(out.with_suffix(".json").read_text())["params"]["controller"]
    assert ctrl["type"] == "local_velocity" and ctrl["Kd"] == 0.3


def test_no_gait_starts_from_nominal_state(tmp_path):
    out = tmp_path / "run.csv"
    result = ok("simulate", "--steps", "2", "--no-gait", "--out", out)
    assert "gait:" not in result.stdout
    start = json.loads(out.with_suffix(".json").read_text())["start"]
    p = tslip.preset("table2.1")
    assert start["beta"] == p.beta0
    assert np.arctan2(start["yd"], start["xd"]) == pytest.approx(-0.1)
    assert np.hypot(start["xd"], start["yd"]) == pytest.approx(p.v0)


def test_animate_writes_gif(tmp_path):
    gif = tmp_path / "run.gif"
    result = ok("animate", "--steps", "2", "--fps", "10", "--out", gif)
    assert f"wrote {gif}" in result.stdout
    frames = iio.imread(gif, index=None)
    assert frames.shape[0] > 5
    assert frames.shape[1:3] == (360, 640)


def test_animate_writes_mp4(tmp_path):
    mp4 = tmp_path / "run.mp4"
    ok("animate", "--steps", "1", "--fps", "10", "--out", mp4)
    data = mp4.read_bytes()
    assert data[4:8] == b"ftyp" and len(data) > 1000


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["--set", "k=-1"], "k [MgL^-1]"),
        (["--set", "m=nan"], "m [M]"),
        (["--set", "beta0=2"], "beta0 [rad]"),
        (["--preset", "nope"], "preset"),
        (["--set", "controller=bogus"], "controller"),
        (["--set", "foo=1"], "'foo'"),
        (["--set", "k=abc"], "k [MgL^-1]"),
        (["--set", "k"], "--set"),
        (["--set", "controller.Kq=1"], "Kq"),
        (["--set", "leg_reset=up"], "leg_reset"),
        (["--out", "run.txt"], "--out"),
        (["--plot", "run.xyz"], "--plot"),
        (["--params", "missing.toml"], "missing.toml"),
        (["--steps", "0"], "--steps"),
        (["--dt", "-1"], "--dt"),
        (["--rtol", "0"], "rtol"),
    ],
)
def test_invalid_input_is_one_error_line_and_exit_2(tmp_path, args, expected):
    args = [str(tmp_path / a) if a.endswith((".txt", ".xyz", ".toml")) else a for a in args]
    result = invoke("simulate", "--steps", "2", *args)
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1, result.output
    assert lines[0].startswith("error: ")
    assert expected in lines[0]
    assert result.stderr.strip() == lines[0]


def test_invalid_toml_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("k = = 3\n")
    result = invoke("simulate", "--params", bad)
    assert result.exit_code == 2
    assert result.output.strip().startswith("error: parameter file")


def test_animate_rejects_bad_suffix(tmp_path):
    result = invoke("animate", "--out", tmp_path / "run.avi")
    assert result.exit_code == 2
    expected = f"error: --out must end in .gif or .mp4, got '{tmp_path / 'run.avi'}'"
    assert result.output.strip() == expected
    assert not (tmp_path / "run.avi").exists()


def test_presets_lists_every_preset():
    result = ok("presets")
    for name in tslip.presets():
        assert name in result.stdout
    assert "MgL^-1" in result.stdout  # units are shown


def test_preset_detail_and_unknown_name():
    result = ok("presets", "table6.1")
    assert "controller.alphad_ref" in result.stdout and "2.42" in result.stdout
    bad = invoke("presets", "nope")
    assert bad.exit_code == 2 and bad.output.startswith("error: preset")


def test_retraction_clock_from_the_command_line():
    assert re.search(r"retraction\s+liftoff", ok("presets", "slip").stdout)
    apex = tslip.find_gait(tslip.Params(retraction="apex"))
    result = ok("simulate", "--steps", "2", "--set", "retraction=apex")
    assert f"alpha_r = {apex.params.alpha_r:.6f}" in result.stdout
    assert f"alpha_r = {tslip.find_gait(tslip.Params()).params.alpha_r:.6f}" not in result.stdout


def test_demo_writes_all_outputs(tmp_path):
    out_dir = tmp_path / "demo"
    result = ok("demo", "--out-dir", out_dir, "--steps", "2")
    for name in ("run.csv", "run.json", "run.png", "run.gif"):
        assert (out_dir / name).stat().st_size > 0
        assert f"wrote {out_dir / name}" in result.stdout
    for text in ("stance time", "flight time", "duty factor", "step frequency", "energy drift"):
        assert text in result.stdout
    ts = float(re.search(r"stance time t_s\s+([\d.]+)", result.stdout).group(1))
    tf = float(re.search(r"flight time t_f\s+([\d.]+)", result.stdout).group(1))
    d = float(re.search(r"duty factor.*?\s([\d.]+)\s", result.stdout).group(1))
    assert d == pytest.approx(ts / (ts + tf), abs=2e-4)


def test_python_m_entry_point():
    proc = subprocess.run(
        [sys.executable, "-m", "tslip.cli", "--help"], capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 0
    assert "simulate" in proc.stdout and "demo" in proc.stdout
