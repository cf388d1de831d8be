"""The modules of tslip.cli import each other without a cycle (read with ast, nothing imported).

``main`` assembles the app from the subcommand modules; they share options
and error handling through ``_common`` and never import ``main`` or each other.
"""

import ast
from pathlib import Path

import tslip.cli

CLI = Path(tslip.cli.__file__).parent
PKG = "tslip.cli"


def _name(path: Path) -> str:
    return PKG if path.name == "__init__.py" else f"{PKG}.{path.stem}"


def _target(module: str, root: Path) -> str | None:
    """``module`` if it is a tslip.cli module (a file in ``root``), else None."""
    if module == PKG:
        return PKG
    if module.startswith(PKG + ".") and (root / f"{module[len(PKG) + 1:]}.py").is_file():
        return module
    return None


def cli_imports(path: Path, root: Path = CLI) -> set[str]:
    """The tslip.cli modules (files in ``root``) that ``path`` imports, anywhere in the file."""
    package = PKG
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out.update(filter(None, (_target(a.name, root) for a in node.names)))
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                base = ".".join(parts + ([node.module] if node.module else []))
            else:
                base = node.module or ""
            if base == PKG:  # `from . import gait` names a module; `from . import app` the package
                out.update(_target(f"{PKG}.{a.name}", root) or PKG for a in node.names)
            elif (t := _target(base, root)) is not None:
                out.add(t)
    return out


def import_graph(root: Path = CLI) -> dict[str, set[str]]:
    """Module -> the tslip.cli modules it imports, for every module in ``root``."""
    return {_name(p): cli_imports(p, root) - {_name(p)} for p in sorted(root.glob("*.py"))}


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` as a path ``[a, b, ..., a]``, or None (depth-first search)."""
    state: dict[str, int] = {}  # 1 on the current path, 2 finished
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return path[path.index(nxt):] + [nxt]
            if nxt not in state and (cycle := visit(nxt)) is not None:
                return cycle
        path.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)) is not None:
            return cycle
    return None


def test_the_cli_modules_import_each_other_without_a_cycle():
    graph = import_graph()
    assert find_cycle(graph) is None, " -> ".join(find_cycle(graph))


def test_subcommands_share_only_common_and_main_assembles_them():
    graph = import_graph()
    subcommands = {"biped", "experiment", "gait", "simulate", "studies", "viability"}
    assert {m.rsplit(".", 1)[1] for m in graph["tslip.cli.main"]} >= subcommands | {"_common"}
    for name in subcommands | {"_common"}:
        allowed = set() if name == "_common" else {f"{PKG}._common"}
        assert graph[f"{PKG}.{name}"] <= allowed, (name, graph[f"{PKG}.{name}"])


def test_the_cycle_finder_finds_the_old_layout(tmp_path):
    """The layout before issue 14: main imports the subcommands, they import main."""
    (tmp_path / "__init__.py").write_text("from .main import app, main\n")
    (tmp_path / "main.py").write_text("app = 1\nfrom . import gait as _g  # noqa\n")
    (tmp_path / "gait.py").write_text("from .main import app\n")
    (tmp_path / "studies.py").write_text("from ._common import errors\n")
    (tmp_path / "_common.py").write_text("import typer\n")
    graph = import_graph(tmp_path)
    assert graph["tslip.cli"] == {"tslip.cli.main"}
    cycle = find_cycle(graph)
    assert cycle is not None and cycle[0] == cycle[-1]
    assert set(cycle) == {"tslip.cli.gait", "tslip.cli.main"}
    (tmp_path / "gait.py").write_text("from ._common import errors\n")
    assert find_cycle(import_graph(tmp_path)) is None



#: What ``tslip --help`` must not wait for: each command imports its model code when it runs.
HEAVY = ("numba", "numpy", "pandas", "scipy", "matplotlib", "tslip.model", "tslip.simulation",
         "tslip.gait", "tslip.biped", "tslip.sweeps", "tslip.plotting", "tslip.experiment")


def test_importing_the_cli_imports_no_model_code():
    """``import tslip.cli.main`` (the console script) loads typer and rich, not the model.

    In a fresh interpreter, so that nothing imported by other tests counts; a
    top-level import of an analysis in any command module fails this.
    """
    import json
    import subprocess
    import sys

    code = ("import json, sys, tslip.cli.main; "
            "print(json.dumps(sorted(sys.modules)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    loaded = set(json.loads(out))
    assert "tslip.cli.biped" in loaded  # every command module was imported ...
    heavy = sorted(m for m in loaded if m.split(".")[0] in HEAVY
                   or ".".join(m.split(".")[:2]) in HEAVY)
    assert heavy == []  # ... and none of them imported its analyses at the top
