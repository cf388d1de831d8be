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


def test_spatial_run_writes_the_samples_and_the_plot(tmp_path):
    import tslip
    from tslip.spatial.trunk_run import TrunkRun

    out, plot = tmp_path / "r.parquet", tmp_path / "r.png"
    r = runner.invoke(app, ["spatial", "run", "-n", "3", "--out", str(out), "--plot",
                            str(plot)])
    assert r.exit_code == 0, r.output
    assert "status: OK, 3 strides" in r.output and plot.stat().st_size > 0
    run = tslip.load(out)
    assert isinstance(run, TrunkRun) and run.n_strides == 3
    # the printed rows are the gait's: the roll at the right touch-down, mirrored at the left
    rows = [ln.split() for ln in r.output.splitlines() if ln.strip().startswith(("0 ", "1 "))]
    assert rows[0][1] == "right" and rows[1][1] == "left"
    assert float(rows[0][2]) == -float(rows[1][2]) and float(rows[0][2]) > 0


def test_spatial_run_with_a_push_reports_the_fall(tmp_path):
    from tslip.spatial.lateral import TABLE21_3D_SECTION, table21_params
    from tslip.spatial.trunk_robustness import disturbed_run

    status, stride = disturbed_run(table21_params(), TABLE21_3D_SECTION, "lateral_push", 0.2,
                                   n_steps=30)
    r = runner.invoke(app, ["spatial", "run", "-n", "30", "--push", "0.2"])
    assert r.exit_code == 0, r.output
    assert f"status: {status.name} in stride {stride}" in r.output


def test_spatial_animate_writes_a_gif(tmp_path):
    out = tmp_path / "a.gif"
    r = runner.invoke(app, ["spatial", "animate", "-o", str(out), "-n", "1", "--fps", "10",
                            "--speed", "1"])
    assert r.exit_code == 0, r.output
    assert out.read_bytes()[:6] == b"GIF89a" and f"wrote {out}" in r.output.replace("\n", "")


def test_spatial_run_and_animate_bad_input_is_one_line_with_exit_2(tmp_path):
    for args, field in ((["run", "-n", "0"], "--steps"),
                        (["run", "--push", "nan"], "--push"),
                        (["run", "--splay", "3"], "TrunkParams.splay"),
                        (["run", "--out", str(tmp_path / "r.txt")], "--out"),
                        (["run", "--plot", str(tmp_path / "r.xyz")], "--plot"),
                        (["animate", "-o", str(tmp_path / "a.png")], "--out"),
                        (["animate", "-o", str(tmp_path / "a.gif"), "--fps", "0"], "--fps"),
                        (["animate", "-o", str(tmp_path / "a.gif"), "--dpi", "1"], "--dpi")):
        r = runner.invoke(app, ["spatial", *args])
        assert r.exit_code == 2, (args, r.output)
        lines = [ln for ln in r.output.splitlines() if ln.strip()]
        assert len(lines) == 1 and lines[0].startswith("error: ") and field in lines[0], r.output
