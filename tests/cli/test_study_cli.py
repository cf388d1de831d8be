"""``tslip study SPEC.toml``: what it refuses before any work, in one line."""

import pytest
from typer.testing import CliRunner

from tslip.cli.main import app

runner = CliRunner()

SPEC = 'name = "{name}"\npreset = "table2.1"\n[[axis]]\nparam = "r"\nvalues = [0.1]\n'


@pytest.mark.parametrize("name", ["..", ".", "../up", "a b"])
def test_a_name_that_is_no_plain_folder_name_is_refused(tmp_path, monkeypatch, name):
    """Without --out the results go to studies/<name>: ".." would be the current folder."""
    work = tmp_path / "work"
    work.mkdir()
    (tmp_path / "spec.toml").write_text(SPEC.format(name=name))
    monkeypatch.chdir(work)
    res = runner.invoke(app, ["study", str(tmp_path / "spec.toml")])
    assert res.exit_code == 2, res.output
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: study name must match "
                                                   "^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$"), lines
    assert list(work.iterdir()) == [] and sorted(p.name for p in tmp_path.iterdir()) == \
        ["spec.toml", "work"]
