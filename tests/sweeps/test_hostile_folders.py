"""A copied, shared or downloaded study folder with links where tslip writes: nothing is
written through them (issue 40, section 1). Each target's bytes are compared before and
after; the design search's files are in tests/sweeps/test_design.py."""

from __future__ import annotations

import logging
import os

import pytest
from typer.testing import CliRunner

import tslip
from tslip._safefile import UnsafePath
from tslip.cli.main import app
from tslip.sweeps import Axis, StudySpec, run_study
from tslip.sweeps._lock import folder_lock, folder_locks
from tslip.sweeps.run import _cached_names, study_file

#: A user's file: a shell profile, its last line without a newline (a torn-line repair
#: would cut it; a lock would empty it; an append would grow it).
PRECIOUS = b"# ~/.profile\nexport SECRET_TOKEN=abc123\nalias ll='ls -l'"


def _spec():
    return StudySpec("line", tslip.preset("table2.1"), (Axis("v0", (4.0, 4.5)),),
                     analyses=("floquet",))


@pytest.fixture
def target(tmp_path):
    t = tmp_path / "home" / ".profile"
    t.parent.mkdir()
    t.write_bytes(PRECIOUS)
    return t


def _untouched(target):
    assert target.read_bytes() == PRECIOUS
    assert sorted(os.listdir(target.parent)) == [".profile"]


def test_a_study_cache_file_that_is_a_link_is_refused(tmp_path, target):
    out = tmp_path / "study"
    path = study_file(_spec(), out)
    path.parent.mkdir(parents=True)
    path.symlink_to(target)
    with pytest.raises(UnsafePath, match=rf"^refusing to write through {path}: it is a symbolic"):
        run_study(_spec(), out, workers=1)
    _untouched(target)


def test_a_cache_folder_that_is_a_link_is_refused(tmp_path, target):
    out = tmp_path / "study"
    out.mkdir()
    (out / "cache").symlink_to(target.parent)
    with pytest.raises(UnsafePath, match=rf"^refusing to write through {out / 'cache'}: "):
        run_study(_spec(), out, workers=1)
    with pytest.raises(UnsafePath):  # the viability runner's listing, which deletes dot-files
        _cached_names(out / "cache")
    _untouched(target)


def test_a_lock_that_is_a_link_is_refused_and_its_target_neither_emptied_nor_echoed(
        tmp_path, target, caplog):
    out = tmp_path / "study"
    out.mkdir()
    (out / ".lock").symlink_to(target)
    with caplog.at_level("DEBUG", logger="tslip"), pytest.raises(UnsafePath) as exc:
        with folder_lock(out):
            pass
    assert str(exc.value).startswith(f"refusing to write through {out / '.lock'}: it is a "
                                     "symbolic link")
    said = str(exc.value) + " ".join(r.getMessage() for r in caplog.records)
    assert "SECRET" not in said and "profile" not in said
    _untouched(target)


def test_a_studies_folder_that_is_a_link_is_refused_by_reproduce_locks(tmp_path, target):
    out = tmp_path / "report"
    out.mkdir()
    (out / "studies").symlink_to(target.parent)
    with pytest.raises(UnsafePath, match="studies: it is a symbolic link"):
        with folder_locks([out / "studies" / "fig4_8"], root=out):
            pass
    _untouched(target)


def test_the_cli_refuses_in_one_line_with_exit_2(tmp_path, target):
    spec = tmp_path / "s.toml"
    spec.write_text('name = "s"\npreset = "table2.1"\n[[axis]]\nparam = "v0"\nvalues = [4.0]\n')
    out = tmp_path / "o"
    out.mkdir()
    (out / ".lock").symlink_to(target)
    res = CliRunner().invoke(app, ["study", str(spec), "--out", str(out), "--workers", "1"])
    assert res.exit_code == 2, res.output
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: refusing to write through "
                                                   f"{out / '.lock'}"), lines
    assert "SECRET" not in res.output
    _untouched(target)


@pytest.mark.parametrize("link", ["cache", "file"])
def test_the_cli_refuses_a_cache_link_before_its_bar_is_drawn(tmp_path, target, link):
    """A link at ``cache/`` or at the study file is refused before any work: no progress
    bar, no compile announcement, one line, exit 2 (it was refused only once the bar ran)."""
    spec = tmp_path / "s.toml"
    spec.write_text('name = "s"\npreset = "table2.1"\n[[axis]]\nparam = "v0"\nvalues = [4.0]\n')
    out = tmp_path / "o"
    path = study_file(StudySpec.from_toml(spec), out)
    path.parent.parent.mkdir()
    if link == "cache":
        path.parent.symlink_to(target.parent, target_is_directory=True)
        where = path.parent
    else:
        path.parent.mkdir()
        path.symlink_to(target)
        where = path
    res = CliRunner().invoke(app, ["study", str(spec), "--out", str(out), "--workers", "1"])
    assert res.exit_code == 2, res.output
    assert res.stdout == "", res.stdout  # nothing drawn or announced before the refusal
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: refusing to write through "
                                                   f"{where}"), lines
    _untouched(target)


def test_a_stale_lock_message_names_the_holder_not_the_file_bytes(tmp_path, caplog):
    """A plain ``.lock`` of another program's text: the take-over line does not print it."""
    out = tmp_path / "study"
    out.mkdir()
    (out / ".lock").write_bytes(PRECIOUS)
    with caplog.at_level(logging.WARNING, logger="tslip"), folder_lock(out):
        pass
    (msg,) = [r.getMessage() for r in caplog.records]
    assert "taking over the stale lock" in msg and "SECRET" not in msg


def test_both_appenders_refuse_a_link_made_after_the_folder_was_read(tmp_path, target):
    """The study's and the design's appenders open the file themselves, without following."""
    from tslip.sweeps import _store
    from tslip.sweeps.pareto import _Store

    out = tmp_path / "o"
    (out / "cache").mkdir(parents=True)
    (out / "cache" / "s.jsonl").symlink_to(target)
    with pytest.raises(UnsafePath), _store.Writer(out / "cache" / "s.jsonl", root=out) as w:
        w.add("k", {"v0": 1.0})
    store = _Store(None, "code", None)  # read nothing
    store.path = out / "evaluations.jsonl"
    store.path.symlink_to(target)
    with pytest.raises(UnsafePath):
        store.add((1.0,), {"k": 1.0})
    _untouched(target)


def test_a_report_figures_folder_that_is_a_link_is_refused_before_any_work(tmp_path, target):
    from tslip.sweeps.reproduce import run_catalogue

    out = tmp_path / "report"
    out.mkdir()
    (out / "figures").symlink_to(target.parent)
    with pytest.raises(UnsafePath, match="figures: it is a symbolic link"):
        run_catalogue(out, False, workers=1)
    _untouched(target)
