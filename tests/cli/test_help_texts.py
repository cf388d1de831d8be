"""Help texts and messages that contradicted each other or said too little (issue 40)."""

import re
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from tslip.cli.main import app
from tslip.gait._viable import RULES

runner = CliRunner()
ROOT = Path(__file__).resolve().parents[2]


def _help(*command: str) -> str:
    res = runner.invoke(app, [*command, "--help"], env={"COLUMNS": "200"})
    assert res.exit_code == 0, res.output
    return " ".join(res.output.replace("│", " ").split())


def test_viability_help_lists_every_rule_in_the_spec_text_and_the_option():
    text = _help("viability")
    spec_text = text[text.index("The spec (TOML)"):text.index("Example and meaning")]
    option = text[text.index("--rule"):text.index("--plot")]
    for rule in RULES:
        assert f'"{rule}"' in spec_text and f'"{rule}"' in option, rule


def test_reproduce_help_and_docs_give_one_time_for_a_warm_quick_run():
    text = _help("reproduce")
    option = text[text.index("--quick"):text.index("--out")]
    times = set(re.findall(r"(\d+-\d+ s|about \d+ s)", option))
    described = set(re.findall(r"--quick takes (\d+-\d+ s|about \d+ s)", text))
    doc = (ROOT / "docs" / "reproducing.md").read_text()
    line = next(s for s in doc.splitlines() if s.startswith("tslip reproduce --quick"))
    assert len(times) == 1 and times == described == set(re.findall(r"\d+-\d+ s", line))


def test_experiment_options_say_what_they_are_as_track_does():
    for command in (("experiment", "track"), ("experiment",)):
        text = _help(*command)
        assert re.search(r"--scale <float> Image scale \[px/m\] \(default: measured", text)
        assert re.search(r"--fps <float> Frame rate \[Hz\] \(default: from the file\)", text)
        assert "--ground <float> Ground row [px] (give --scale with it)" in text


def test_biped_simulate_says_what_its_rms_errors_are_measured_from(tmp_path):
    from tslip import load
    from tslip.biped.dynamics import controller_references, leg_phase

    out = tmp_path / "run.csv"
    res = runner.invoke(app, ["biped", "simulate", "-n", "1", "--out", str(out)])
    assert res.exit_code == 0, res.output
    tr = load(out)
    for leg, side, name in ((0, "R", "right"), (1, "L", "left")):
        m = tr.time <= tr.strides[0, 0]
        ref = controller_references(tr.params, leg_phase(tr.params, tr.time[m], leg))
        thigh = np.sqrt(np.mean((tr[f"l_t{side}"][m] - ref[:, 0]) ** 2))
        hip = np.sqrt(np.mean((tr[f"theta_h{side}"][m] - ref[:, 2]) ** 2))
        assert (f"{name} leg, stride 1: RMS error from the controller's references "
                f"(eqs E.29, E.32): thigh length {thigh:.2e} L, hip angle {hip:.3f} rad"
                ) in res.output
