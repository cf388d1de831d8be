"""``tslip gait`` and ``tslip continue`` in-process."""

import json

import pandas as pd
import pytest
from typer.testing import CliRunner

from tslip.cli.main import app

runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def test_gait_json_report_has_thesis_numbers():
    """Table 6.1 fit: largest multiplier 0.92, step-down -0.12, push -0.73 (Section 6.1)."""
    res = invoke("gait", "--preset", "table6.1", "--json")
    assert res.exit_code == 0, res.output
    rep = json.loads(res.stdout)
    assert rep["gait"]["converged"] and rep["gait"]["residual"] < 1e-10
    assert rep["floquet"]["max_nontrivial"] == pytest.approx(0.92, abs=0.01)
    assert rep["floquet"]["stability"] == "asymptotic"
    assert rep["robustness"]["step_down"]["limit"] == pytest.approx(-0.12, abs=0.01)
    assert rep["robustness"]["push"]["limit"] == pytest.approx(-0.73, abs=0.01)
    assert rep["stride"]["duty_factor"] == pytest.approx(0.82, abs=0.01)
    assert 0.05 < rep["friction"]["slip_fraction"] < 0.15  # Figure C.1: last ~10% of stance


def test_gait_text_report_and_plots(tmp_path):
    res = invoke("gait", "--preset", "table2.1", "--no-robustness", "--plot", tmp_path)
    assert res.exit_code == 0, res.output
    assert "asymptotic" in res.stdout and "trivial (conserved energy)" in res.stdout
    for name in ("pitch_impulse.png", "impulse_linearisation.png", "friction.png"):
        data = (tmp_path / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000


def test_gait_without_fixed_point_exits_with_one_line():
    res = invoke("gait", "--preset", "table2.1-global-pd")
    assert res.exit_code == 1
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: no exact fixed point")


def test_continue_saves_branch_with_stability(tmp_path):
    out = tmp_path / "branch.csv"
    res = invoke("continue", "--preset", "table2.1", "--param", "r", "--from", "-0.2", "--to",
                 "1.0", "--points", "13", "--out", out, "--plot", tmp_path / "b.png")
    assert res.exit_code == 0, res.output
    df = pd.read_csv(out)
    assert len(df) == 13 and df["converged"].all()
    stab = dict(zip(df["value"].round(3), df["stability"]))
    assert stab[-0.2] == "unstable" and stab[0.5] == "asymptotic" and stab[1.0] == "unstable"
    assert (tmp_path / "b.png").stat().st_size > 5000
    # the run record beside the table: tslip.load gives the Branch back, table and all
    import tslip

    branch = tslip.load(out)
    assert type(branch).__name__ == "Branch" and len(branch) == 13
    assert list(branch.to_dataframe()["stability"]) == list(df["stability"])
    assert json.loads(out.with_suffix(".json").read_text())["run"]["params"]["r"] == 0.3


@pytest.mark.parametrize(
    ("args", "field"),
    [(["gait", "--method", "magic"], "--method"),
     (["gait", "--set", "k=-1"], "k ["),
     (["continue", "--param", "bogus", "--from", "0", "--to", "1"], "bogus"),
     (["continue", "--param", "r", "--from", "1", "--to", "0"], "--from"),
     (["continue", "--param", "r", "--from", "0", "--to", "1", "--points", "1"], "--points"),
     (["continue", "--param", "r", "--from", "0", "--to", "1", "--out", "x.txt"], "--out")],
)
def test_bad_input_exits_2_with_one_line(args, field):
    res = invoke(*args)
    assert res.exit_code == 2
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and field in lines[0]
