"""``tslip spatial``: the symmetric gaits with their multipliers, the claims, and bad input
refused in one line with exit code 2."""

from __future__ import annotations

import re

from typer.testing import CliRunner

from tslip.cli.main import app

runner = CliRunner()


def test_spatial_gait_prints_the_gaits_and_the_feedback_stabilises_the_fast_one():
    r0 = runner.invoke(app, ["spatial", "gait", "--energy", "2.2"])
    r1 = runner.invoke(app, ["spatial", "gait", "--energy", "2.2", "--set", "k_lat=1.5"])
    assert r0.exit_code == 0 and r1.exit_code == 0, r0.output + r1.output
    fast0, fast1 = (re.findall(r"apex y [^\n]*", r.output)[0] for r in (r0, r1))
    assert fast0.endswith("(unstable)") and fast1.endswith("(stable)")


def test_spatial_claims_small_writes_markdown(tmp_path):
    out = tmp_path / "c.md"
    r = runner.invoke(app, ["spatial", "claims", "--small", "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert "Claim 2" in out.read_text()


def test_bad_input_is_one_line_with_exit_2(tmp_path):
    for args, field in ((["spatial", "gait", "--energy", "2.2", "--set", "k=-1"],
                         "SpatialParams.k"),
                        (["spatial", "gait", "--energy", "2.2", "--set", "heading=velocity",
                          "--set", "k_lat=1"], "SpatialParams.k_lat"),
                        (["spatial", "gait", "--energy", "2.2", "--set", "q=1"], "--set q"),
                        (["spatial", "gait", "--energy", "-1"], "energy"),
                        (["spatial", "gait", "--energy", "2", "--preset", "x"], "preset"),
                        (["spatial", "claims", "--out", str(tmp_path / "c.txt")], "--out")):
        r = runner.invoke(app, args)
        assert r.exit_code == 2, (args, r.output)
        lines = [ln for ln in r.output.splitlines() if ln.strip()]
        assert len(lines) == 1 and lines[0].startswith("error: ") and field in lines[0], r.output


def test_spatial_lateral_one_gait_and_small_tables(tmp_path):
    r = runner.invoke(app, ["spatial", "lateral", "--k-trail", "2"])
    assert r.exit_code == 0, r.output
    row = [ln for ln in r.output.splitlines() if ln.startswith("| 0.3 |")][0]
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[:4] == ["0.3", "0.05", "0", "2"] and cells[6] == "no"
    assert 1.0 < float(cells[4]) < 1.2  # the trail pulls the 1.75 of the uncoupled gait down
    out = tmp_path / "l.md"
    r = runner.invoke(app, ["spatial", "lateral", "--small", "--out", str(out)])
    assert r.exit_code == 0, r.output
    text = out.read_text()
    assert "### Mass offset r" in text and "| 0.3 | 0.05 | 0 | 0 | 1.7" in text


def test_spatial_lateral_bad_input_is_one_line_with_exit_2(tmp_path):
    for args, field in ((["--splay", "2"], "TrunkParams.splay"),
                        (["--splay", "0"], "splay must be in"),
                        (["--out", str(tmp_path / "l.txt")], "--out")):
        r = runner.invoke(app, ["spatial", "lateral", *args])
        assert r.exit_code == 2, (args, r.output)
        assert field in r.output and len(r.output.strip().splitlines()) == 1, r.output
