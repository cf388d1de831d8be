"""The package imports only what pyproject.toml installs with it; the tests, what [test] adds."""

import ast
import re
import sys
import tomllib
from importlib.metadata import packages_distributions
from pathlib import Path

#: The checkout's files, not the installed package's (CI installs a copy in site-packages).
TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent / "src" / "tslip"
PYPROJECT = TESTS.parent / "pyproject.toml"


def _name(requirement: str) -> str:
    """The normalised distribution name of a requirement string (PEP 503)."""
    return re.sub(r"[-_.]+", "-", re.match(r"[A-Za-z0-9._-]+", requirement)[0]).lower()


def _third_party_imports(root: Path) -> dict[str, set[str]]:
    """Top-level module -> the files under ``root`` that import it (also inside functions)."""
    out: dict[str, set[str]] = {}
    for path in root.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for top in {n.split(".")[0] for n in names} - set(sys.stdlib_module_names):
                if top != "tslip":
                    out.setdefault(top, set()).add(str(path.relative_to(root)))
    return out


def _undeclared(root: Path, allowed: set[str]) -> list[str]:
    """Imports under ``root`` whose distribution is not in ``allowed`` (local modules skipped)."""
    dists = packages_distributions()
    bad = []
    for module, files in sorted(_third_party_imports(root).items()):
        if (root / module).is_dir() or (root / f"{module}.py").exists():
            continue  # the tests' own helpers (tests/ is on the path)
        names = {_name(d) for d in dists.get(module, [module])}
        if not names & allowed:
            bad.append(f"{module} ({', '.join(sorted(names))}) imported by {sorted(files)}")
    return bad


def _requirements(*extras: str) -> set[str]:
    """The runtime dependencies and those of ``extras`` (following ``tslip[...]``)."""
    project = tomllib.loads(PYPROJECT.read_text())["project"]
    reqs, todo = list(project["dependencies"]), list(extras)
    while todo:
        for r in project["optional-dependencies"][todo.pop()]:
            if _name(r) == "tslip":
                todo += re.search(r"\[(.*)\]", r)[1].split(",")
            else:
                reqs.append(r)
    return {_name(r) for r in reqs}


def test_every_module_the_package_imports_is_a_runtime_dependency():
    """The optional backends are the only imports from extras (``tslip[dask]``, the
    explorer's ``tslip[explore]``, the design search's ``tslip[design]``)."""
    bad = _undeclared(ROOT, _requirements("dask", "explore", "design"))
    assert not bad, "\n".join(bad)


def test_every_module_the_tests_import_is_installed_by_the_test_extra():
    """E.g. sympy (tests/biped/test_dynamics.py) is a test dependency, not a runtime one."""
    bad = _undeclared(TESTS, _requirements("test"))
    assert not bad, "\n".join(bad)
    assert "sympy" in _requirements("test") and "sympy" not in _requirements("dask")


def test_the_scan_sees_imports_inside_functions(tmp_path):
    (tmp_path / "m.py").write_text("import numpy\ndef f():\n    from sympy import Symbol\n"
                                   "    import os.path\n")
    (tmp_path / "helper.py").write_text("import pytest\n")
    assert _third_party_imports(tmp_path) == {"numpy": {"m.py"}, "sympy": {"m.py"},
                                              "pytest": {"helper.py"}}
    (tmp_path / "m2.py").write_text("import helper\n")  # a local module, not a dependency
    assert [b.split()[0] for b in _undeclared(tmp_path, {"numpy", "pytest"})] == ["sympy"]
