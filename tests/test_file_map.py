"""CONTRIBUTING.md's file map names every module of the package, and only files that exist."""

import re
from pathlib import Path

#: The checkout's files, not the installed package's (CI installs a copy in site-packages).
REPO = Path(__file__).resolve().parents[1]
ROOT = REPO / "src" / "tslip"


def _map_paths(text: str) -> set[str]:
    """The paths in the first column of the file map's rows (``where``)."""
    section = text[text.index("## File map"):]
    section = section[:section.index("\n## ", 1)]
    out = set()
    for line in section.splitlines():
        cells = line.split("|")
        if len(cells) > 2 and "`" in cells[1]:
            out |= set(re.findall(r"`([^`]+)`", cells[1]))
    return out


def _unmapped(modules: list[str], paths: set[str]) -> list[str]:
    """Modules (paths relative to the package) with neither their own row nor a folder row."""
    bad = []
    for module in modules:
        parts = module.split("/")
        folders = {"/".join(parts[:i]) + "/" for i in range(1, len(parts))}
        if module not in paths and not folders & paths:
            bad.append(module)
    return bad


def test_every_module_is_in_the_file_map():
    paths = _map_paths((REPO / "CONTRIBUTING.md").read_text())
    modules = sorted(p.relative_to(ROOT).as_posix() for p in ROOT.rglob("*.py"))
    bad = _unmapped(modules, paths)
    assert not bad, f"add these to CONTRIBUTING.md's file map (or a folder row): {bad}"


def test_every_file_in_the_map_exists():
    paths = _map_paths((REPO / "CONTRIBUTING.md").read_text())
    assert len(paths) > 50
    bad = [p for p in sorted(paths) if not (ROOT / p).exists() and not (REPO / p).exists()]
    assert not bad, f"the file map names files that do not exist: {bad}"


def test_a_folder_row_covers_its_subfolders_and_only_the_first_column_counts():
    text = ("# x\n## File map\n| where | what |\n| --- | --- |\n"
            "| `a.py`, `sub/` | not `b.py` |\n| `other/c.py` | c |\n## Rules\n| `d.py` | d |\n")
    paths = _map_paths(text)
    assert paths == {"a.py", "sub/", "other/c.py"}
    assert _unmapped(["a.py", "b.py", "sub/x/y.py", "other/c.py", "other/e.py", "d.py"],
                     paths) == ["b.py", "other/e.py", "d.py"]
