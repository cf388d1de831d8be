"""``tslip viability`` (and ``study``, ``reproduce``) refuse what they cannot do before they
allocate or make a folder (issue 40): a grid that does not fit, two ``[[state]]`` tables of
one variable, a ``--scheduler`` that is empty, malformed or does not answer."""

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from tslip.cli import _common
from tslip.cli.main import app

runner = CliRunner()

GRID = """
name = "{name}"
preset = "slip"
energy = 2.6

[[state]]
name = "y"
{y}

[[state]]
name = "phi"
{phi}

[[state]]
name = "phid"
{phid}

[action]
name = "alpha_r"
from = 1.0
to = 1.45
points = {actions}
"""
HUGE = GRID.format(name="huge", y="from = 1.0\nto = 1.6\npoints = 100000",
                   phi="from = -0.2\nto = 0.2\npoints = 100000",
                   phid="from = -0.1\nto = 0.1\npoints = 100000", actions=3)
TEN = GRID.format(name="ten", y="values = [1.2]", phi="values = [0.0]", phid="values = [0.0]",
                  actions=10)


def _peak_rss(args: list[str], cwd, limit: float = 900.0) -> tuple[int, int, str]:
    """Exit code, peak resident memory [bytes] and output of ``tslip`` in a subprocess
    (``wait4``: the rusage of that child alone); killed, and the test failed, if it has
    not ended after ``limit`` seconds (a grid computed instead of refused runs for ever)."""
    out = cwd / f"out-{args[-1]}.txt"
    with open(out, "w") as fh:
        proc = subprocess.Popen([sys.executable, "-m", "tslip", *args], cwd=cwd, stdout=fh,
                                stderr=subprocess.STDOUT)
        end = time.monotonic() + limit
        while True:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() > end:
                proc.kill()
                proc.wait()
                pytest.fail(f"tslip {' '.join(args)} still running after {limit:.0f} s: "
                            f"{out.read_text()[-300:]}")
            time.sleep(0.05)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return proc.returncode, usage.ru_maxrss * 1024, out.read_text()


def test_a_grid_of_3e15_cells_is_refused_with_its_estimate_and_little_memory(tmp_path):
    """The done-when of issue 40: exit 2 with the estimate, peak memory at most 50 MB above
    the same command's on a 10-cell grid (which computes its cells)."""
    (tmp_path / "huge.toml").write_text(HUGE)
    (tmp_path / "ten.toml").write_text(TEN)
    code, huge_rss, text = _peak_rss(["viability", "huge.toml"], tmp_path, limit=120.0)
    assert code == 2, text
    line = text.strip()
    assert "\n" not in line and line.startswith("error: viability grid huge: ")
    assert "3000000000000000 cells (100000 x 100000 x 100000 states x 3 actions)" in line
    assert "need about" in line and "PB of memory" in line and "available" in line
    assert not (tmp_path / "viability").exists()  # no folder, no .lock
    code, ten_rss, text = _peak_rss(["viability", "ten.toml"], tmp_path)
    assert code == 0, text
    assert text.splitlines()[0] == "ten: 10 cells in 1 chunk"
    assert "ten: 10 cells, " in text
    assert huge_rss <= ten_rss + 50e6, (huge_rss / 1e6, ten_rss / 1e6)


def test_two_state_tables_of_one_variable_are_one_line(tmp_path):
    spec = tmp_path / "s.toml"
    spec.write_text(TEN.replace('name = "phi"', 'name = "y"'))
    res = runner.invoke(app, ["viability", str(spec), "--out", str(tmp_path / "o")])
    assert res.exit_code == 2
    assert "'y' 2 times" in res.output and "Traceback" not in res.output
    assert not (tmp_path / "o").exists()


STUDY = """
name = "s"
preset = "table2.1"
[[axis]]
param = "v0"
values = [5.0]
"""


DESIGN = Path(__file__).parents[2] / "examples" / "design.toml"


def _commands(tmp_path):
    (tmp_path / "v.toml").write_text(TEN)
    (tmp_path / "s.toml").write_text(STUDY)
    return {"viability": ["viability", str(tmp_path / "v.toml")],
            "study": ["study", str(tmp_path / "s.toml")],
            "reproduce": ["reproduce", "--quick"],
            "design": ["design", str(DESIGN)]}


@pytest.mark.parametrize("command", ["viability", "study", "reproduce", "design"])
@pytest.mark.parametrize("address, what", [
    ("", "--scheduler is empty"),
    ("  ", "--scheduler is empty"),
    ("foo", "--scheduler 'foo' is not a Dask scheduler's address"),
    ("http://127.0.0.1:1", "--scheduler 'http://127.0.0.1:1' is not a Dask scheduler's"),
    ("tcp://127.0.0.1:1", "--scheduler 'tcp://127.0.0.1:1': no Dask scheduler answered "
                          "within 0.5 s"),
])
def test_a_bad_scheduler_is_one_line_naming_it_and_leaves_no_folder(
        tmp_path, monkeypatch, command, address, what):
    monkeypatch.setattr(_common, "SCHEDULER_SECONDS", 0.5)
    out = tmp_path / "o"
    res = runner.invoke(app, [*_commands(tmp_path)[command], "--out", str(out),
                              "--scheduler", address])
    assert res.exit_code == 2, res.output
    error = [line for line in res.output.splitlines() if line.startswith("error:")]
    assert len(error) == 1 and what in error[0], res.output
    assert "Traceback" not in res.output
    if address.strip():  # the wait announced, with its bound
        assert "(giving up after 0.5 s)" in res.output
    assert not out.exists()
