"""One version: pyproject reads ``tslip.__version__``; cache keys ignore the version string."""

import re
import shutil
import tomllib
from pathlib import Path

import pytest

import tslip
from tslip import _codehash as ch
from tslip.sweeps.point import code_version
from tslip.sweeps.reproduce import APPENDIX_E_MODULES

REPO = Path(__file__).parents[1]
SRC = Path(tslip.__file__).parent


def test_version_is_semver():
    assert re.fullmatch(r"\d+\.\d+\.\d+", tslip.__version__), tslip.__version__


def test_pyproject_takes_the_version_from_the_package():
    project = tomllib.loads((REPO / "pyproject.toml").read_text())
    assert "version" not in project["project"], "give the version once, in tslip/__init__.py"
    assert "version" in project["project"]["dynamic"]
    assert project["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "tslip.__version__"}


def test_setuptools_resolves_the_same_version():
    """What a build writes into the package metadata: setuptools' own ``attr:`` expansion."""
    expand = pytest.importorskip("setuptools.config.expand")
    project = tomllib.loads((REPO / "pyproject.toml").read_text())
    attr = project["tool"]["setuptools"]["dynamic"]["version"]["attr"]
    where = project["tool"]["setuptools"]["packages"]["find"]["where"]
    version = expand.read_attr(attr, package_dir={"": where[0]}, root_dir=REPO)
    assert version == tslip.__version__


def test_changelog_has_this_version_and_an_unreleased_section():
    text = (REPO / "CHANGELOG.md").read_text()
    headings = re.findall(r"^## \[([^\]]+)\]", text, flags=re.MULTILINE)
    assert headings[:2] == ["Unreleased", tslip.__version__], headings


@pytest.fixture
def tree(tmp_path, monkeypatch):
    """A copy of the package that the code hash reads instead of the real sources."""
    root = tmp_path / "tslip"
    shutil.copytree(SRC, root, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(ch, "_ROOT", root)
    yield root
    ch.cache_clear()


def _edit(path: Path) -> None:
    """Change the code in place (a statement: comments and docstrings do not count)."""
    path.write_text(path.read_text() + "\n_AN_EDIT = 1\n")


def _keys() -> dict[str, str]:
    """The keys of the study point cache (every analysis) and the Appendix E cache."""
    ch.cache_clear()
    return {"points": code_version(["floquet", "stride", "robustness"]),
            "appendix_e": ch.code_hash(*APPENDIX_E_MODULES)}


def test_a_version_bump_keeps_the_caches_and_a_code_edit_does_not(tree):
    init = tree / "__init__.py"
    # the package's own __init__ (where __version__ lives) is part of both keys
    for mods in (("tslip.gait.fixed_point", "tslip.gait.stability"), APPENDIX_E_MODULES):
        assert "tslip:self" in ch.module_closure(*mods)
    before = _keys()
    source = init.read_text()
    bumped, n = re.subn(r'^__version__ = "[^"]*"', '__version__ = "99.0.0"', source,
                        flags=re.MULTILINE)
    assert n == 1
    init.write_text(bumped)
    assert _keys() == before
    _edit(init)  # code in the same file, version unchanged
    edited = _keys()
    assert all(edited[k] != before[k] for k in before)
    init.write_text(bumped)
    assert _keys() == before
    _edit(tree / "gait" / "fixed_point.py")
    assert _keys()["points"] != before["points"]


def test_changelog_lists_the_r0_guess_change_with_its_migration():
    """Issue 23 s5: the held-pitch guess at r = 0 is a user-visible change since 0.2."""
    text = (REPO / "CHANGELOG.md").read_text()
    unreleased = text.split("## [Unreleased]", 1)[1].split("\n## [", 1)[0]
    changed = unreleased.split("### Changed", 1)[1].split("\n### ", 1)[0]
    entries = [" ".join(e.split()) for e in changed.split("\n- ")]
    entry = next(e for e in entries if "r = 0" in e and "guess" in e)
    for part in ("`(delta, phi, phid, alpha_r)`", "`DeprecationWarning`", "`(delta, alpha_r)`",
                 '"Held pitch"', "Migration:"):
        assert part in entry, part
