"""What a new user meets first: every option explained in ``--help`` (flags without a
type), a parameter file saved with a byte-order mark, the progress bar's rate, and a
refused second run that draws no empty bar."""

import typer
from typer.testing import CliRunner

from tslip.cli._common import progress_bar
from tslip.cli.main import app
from tslip.sweeps._lock import folder_lock

runner = CliRunner()


def _commands(cmd, path=()):
    ctx = cmd.context_class(cmd, info_name=path[-1] if path else "tslip")
    if hasattr(cmd, "list_commands"):
        for name in cmd.list_commands(ctx):
            yield from _commands(cmd.get_command(ctx, name), (*path, name))
    else:
        yield path, cmd


def test_every_option_has_help_and_no_flag_shows_a_type():
    commands = list(_commands(typer.main.get_command(app)))
    assert len(commands) > 15
    for path, cmd in commands:
        missing = [p.opts[0] for p in cmd.params if p.param_type_name == "option" and not p.help]
        assert not missing, (path, missing)
        res = runner.invoke(app, [*path, "--help"], terminal_width=200)
        assert res.exit_code == 0, (path, res.output)
        assert "<bool>" not in res.output, path
        if any(getattr(p, "is_flag", False) for p in cmd.params):
            assert "--help" in res.output


def test_viability_help_describes_the_spec_and_names_its_page():
    out = runner.invoke(app, ["viability", "--help"], terminal_width=200).output
    for word in ("energy", "[[state]]", "[action]", "rule", "docs/analyses/viability.md"):
        assert word in out, word


def test_a_params_file_with_a_byte_order_mark_is_read(tmp_path):
    f = tmp_path / "p.toml"
    f.write_bytes("\ufeffk = 31.5\n".encode())
    assert f.read_bytes()[:3] == b"\xef\xbb\xbf"
    res = runner.invoke(app, ["simulate", "--params", str(f), "--steps", "1",
                              "--out", str(tmp_path / "run.csv")])
    assert res.exit_code == 0, res.output
    without = runner.invoke(app, ["simulate", "--set", "k=31.5", "--steps", "1",
                                  "--out", str(tmp_path / "ref.csv")])
    assert without.exit_code == 0
    assert (tmp_path / "run.csv").read_bytes() == (tmp_path / "ref.csv").read_bytes()


def test_the_rate_column_shows_a_rate_or_nothing():
    bar = progress_bar("cells")
    task = bar.add_task("x", total=10)
    rate = bar.columns[3]
    assert str(rate.render(bar.tasks[task])) == ""  # no estimate yet: no "--"
    bar.update(task, completed=10)  # all at once: rich has no speed either
    assert str(rate.render(bar.tasks[task])) == ""
    known = type("Task", (), {"finished_speed": None, "speed": 12.04})()
    assert str(rate.render(known)) == " 12.0 cells/s"


SPEC = 'name = "one"\npreset = "table2.1"\n[[axis]]\nparam = "v0"\nvalues = [5.0]\n'


def test_a_second_study_on_a_locked_folder_is_refused_before_any_bar(tmp_path):
    spec = tmp_path / "one.toml"
    spec.write_text(SPEC)
    out = tmp_path / "out"
    with folder_lock(out):
        res = runner.invoke(app, ["study", str(spec), "--out", str(out)])
    assert res.exit_code == 2, res.output
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: study folder "), res.stderr
    assert "0/1" not in res.stderr and "study one" not in res.stderr
