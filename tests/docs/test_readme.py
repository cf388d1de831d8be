"""The README a newcomer reads in three minutes (issue 42): short, the Quickstart first,
and its lists of commands and parameters complete, each derived from the code.

Its Python snippets are run by tests/docs/test_recipes.py; the measurements it once held
are on docs/speed.md and the checks against the thesis on docs/reproducing.md.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
#: The Quickstart's commands, written out: the install-and-reproduce line that
#: benchmarks/bench_coldstart.py reads, and the test command of .ci/run.
QUICKSTART = ['python -m pip install -q -c constraints.txt . && tslip reproduce --quick --out '
              'report',
              'python -m pip install -q -c constraints.txt ".[test]" && python -m pytest -q']


@pytest.fixture(scope="module")
def text() -> str:
    return README.read_text(encoding="utf-8")


def _commands() -> dict[str, list[str]]:
    """The ``tslip`` commands of the typer app, each with its subcommands (a group's)."""
    import typer

    from tslip.cli.main import app

    root = typer.main.get_command(app)
    ctx = root.context_class(root, info_name="tslip")
    out = {}
    for name in root.list_commands(ctx):  # type: ignore[attr-defined]
        cmd = root.get_command(ctx, name)  # type: ignore[attr-defined]
        sub = getattr(cmd, "list_commands", None)  # a group's
        out[name] = sub(cmd.context_class(cmd, parent=ctx, info_name=name)) if sub else []
    return out


def test_short(text: str) -> None:
    assert len(text.splitlines()) <= 120


def test_quickstart_is_the_two_commands_on_the_first_screen(text: str) -> None:
    quick = text[text.index("## Quickstart"):]
    block = re.search(r"```bash\n(.*?)```", quick, re.S)
    assert block and block.group(1).splitlines() == QUICKSTART
    first_screen = "\n".join(text.splitlines()[:30])
    assert all(cmd in first_screen for cmd in QUICKSTART)
    assert "`tslip` simulates" in first_screen  # and what the package does, before them
    assert QUICKSTART[1] in (ROOT / ".ci" / "run").read_text()  # the command CI runs
    what = quick[block.end():].split("\n\n")[1].splitlines()  # the lines after the block
    assert len(what) == 3 and "report/index.html" in what[2]


def test_every_command_is_named(text: str) -> None:
    commands = _commands()
    assert len(commands) >= 17 and commands["biped"]
    missing = [name for name in commands if not re.search(rf"tslip {re.escape(name)}\b", text)]
    assert not missing, f"add to the README's command list: {missing}"
    for group, subs in commands.items():
        if subs:
            line = next(ln for ln in text.splitlines() if f"`tslip {group} " in ln)
            absent = [s for s in subs if not re.search(rf"\b{re.escape(s)}\b", line)]
            assert not absent, f"tslip {group}: {absent}"


def test_every_params_field_is_named(text: str) -> None:
    from tslip.model import Params

    prose = re.sub(r"```.*?```", "", text, flags=re.S)  # code spans, outside code blocks
    named = {w for span in re.findall(r"`([^`]+)`", prose) for w in re.findall(r"\w+", span)}
    missing = [f.name for f in dataclasses.fields(Params) if f.name not in named]
    assert not missing, f"add to the README's Params fields: {missing}"
    assert "docs/model.md" in text  # the table with each field's symbol, unit and range


def test_links_resolve_and_reach_the_pages_the_measurements_moved_to(text: str) -> None:
    links = re.findall(r"\]\(([^)#]+)\)", text)
    assert {"docs/speed.md", "docs/reproducing.md", "docs/model.md"} <= set(links)
    missing = [link for link in links if not (ROOT / link).is_file()]
    assert not missing


def test_measurements_live_on_the_docs_pages(text: str) -> None:
    """No dated measurement or benchmark command in the README; they are on the docs."""
    assert not re.search(r"\b20\d\d-\d\d-\d\d\b", text)
    assert "benchmarks/" not in text and "load average" not in text
    speed = (ROOT / "docs" / "speed.md").read_text(encoding="utf-8")
    for cmd in ("bench_coldstart.py --first-run --compile-log", "bench_step.py",
                "bench_reproduce.py --quick --no-baseline", "bench_gait.py --only-today"):
        assert cmd in speed, cmd
    checks = (ROOT / "docs" / "reproducing.md").read_text(encoding="utf-8")
    assert "| Table 6.1 fit, periodic gait (`tslip gait --preset table6.1`) |" in checks
