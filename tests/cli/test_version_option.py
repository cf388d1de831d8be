"""``tslip --version``, and the version and code hash in the run.json files the CLI writes."""

import json
import re
import subprocess
import sys

import pytest
from typer.testing import CliRunner

import tslip
from tslip._codehash import module_closure
from tslip.cli.main import app, main

runner = CliRunner()


def test_version_option_prints_the_version_and_exits_0():
    res = runner.invoke(app, ["--version"])
    assert res.exit_code == 0, res.output
    assert res.output == f"tslip {tslip.__version__}\n"
    assert re.fullmatch(r"tslip \d+\.\d+\.\d+\n", res.output)


def test_version_from_the_console_script_entry_point(monkeypatch, capsys):
    monkeypatch.setattr("sys.argv", ["tslip", "--version"])
    with pytest.raises(SystemExit) as info:
        main()
    assert info.value.code == 0
    assert capsys.readouterr().out == f"tslip {tslip.__version__}\n"


@pytest.mark.parametrize("module", ["tslip", "tslip.cli"])
def test_python_m_version(module):
    res = subprocess.run([sys.executable, "-m", module, "--version"], capture_output=True,
                         text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    assert res.stdout == f"tslip {tslip.__version__}\n"


def test_help_lists_the_version_option_and_every_command():
    res = runner.invoke(app, ["--help"])
    assert res.exit_code == 0
    for name in ("--version", "presets", "simulate", "animate", "demo", "synth-video", "track",
                 "process", "fit", "experiment", "gait", "continue", "study", "reproduce",
                 "biped"):
        assert re.search(rf"(^|\s){re.escape(name)}\s", res.output), name


def _hashed(meta):
    assert meta["tslip_version"] == tslip.__version__
    assert re.fullmatch(r"[0-9a-f]{24}(-[0-9a-f]{24})?", meta["code"]), meta["code"]


def test_simulate_json_records_the_version_and_the_code_hash(tmp_path):
    from tslip.cli.simulate import CODE

    out = tmp_path / "run.csv"
    res = runner.invoke(app, ["simulate", "--steps", "2", "--out", str(out)])
    assert res.exit_code == 0, res.output
    meta = json.loads(out.with_suffix(".json").read_text())
    _hashed(meta)
    # the hashed modules are the ones that ran: the gait search and the simulation
    closure = module_closure(*CODE)
    assert {"tslip.gait.fixed_point", "tslip.simulation.integrate",
            "tslip.simulation._kernels"} <= set(closure)


def test_study_run_json_records_the_version_and_the_code_hash(tmp_path):
    spec = tmp_path / "s.toml"
    spec.write_text('name = "one"\n[[axis]]\nparam = "r"\nvalues = [0.2]\n')
    res = runner.invoke(app, ["study", str(spec), "--out", str(tmp_path / "s"),
                              "--workers", "1"])
    assert res.exit_code == 0, res.output
    _hashed(json.loads((tmp_path / "s" / "run.json").read_text()))
