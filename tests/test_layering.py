"""Dependencies run one way: model -> simulation -> gait -> sweeps; plotting and cli on top."""

import ast
from pathlib import Path

import tslip

ROOT = Path(tslip.__file__).parent
#: what each layer may import from inside tslip (besides itself and private helpers)
ALLOWED = {
    "model": set(),
    "simulation": {"model"},
    "gait": {"model", "simulation"},
    "sweeps": {"model", "simulation", "gait", "biped"},
    "experiment": {"model", "simulation", "gait", "biped"},
    "biped": {"model", "simulation", "gait"},
    "plotting": {"model", "simulation", "gait", "sweeps", "experiment", "biped"},
}
TOP = {"_io", "_checks", "_kernel_cache", "_codehash", "_renamed", "protocols", "__init__",
       "__main__", "_typing",
       "__version__"}


#: what a layer may import only inside a function (a result's ``.plot`` method)
IN_FUNCTIONS = {"gait": {"plotting"}}


def _imports(path: Path, in_functions: bool = True) -> set[str]:
    """tslip subpackages a module imports (absolute or relative); without
    ``in_functions`` only those imported outside function bodies."""
    rel = path.relative_to(ROOT).parts
    out = set()
    tree = ast.parse(path.read_text())
    skip: set[int] = set()
    if not in_functions:
        for fn in ast.walk(tree):
            if isinstance(fn, ast.FunctionDef | ast.AsyncFunctionDef):
                skip.update(id(n) for n in ast.walk(fn) if n is not fn)
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.ImportFrom):
            if node.level == 0 and node.module and node.module.startswith("tslip."):
                out.add(node.module.split(".")[1])
            elif node.level > 0:
                base = list(rel[: len(rel) - node.level])
                parts = base + (node.module.split(".") if node.module else [])
                if parts:
                    out.add(parts[0])
                else:  # "from .. import x"
                    out.update(a.name for a in node.names)
        elif isinstance(node, ast.Import):
            out.update(a.name.split(".")[1] for a in node.names if a.name.startswith("tslip."))
    return {m.removesuffix(".py") for m in out}


def test_import_layering():
    bad = []
    for layer, allowed in ALLOWED.items():
        for path in (ROOT / layer).rglob("*.py"):
            for dep in _imports(path) - {layer} - TOP:
                if dep in IN_FUNCTIONS.get(layer, set()):
                    if dep in _imports(path, in_functions=False):
                        bad.append(f"{path.relative_to(ROOT)} imports tslip.{dep} "
                                   "outside a function")
                    continue
                if dep not in allowed:
                    bad.append(f"{path.relative_to(ROOT)} imports tslip.{dep}")
    assert not bad, "\n".join(bad)


def test_nothing_below_cli_imports_cli():
    for path in ROOT.rglob("*.py"):
        if path.relative_to(ROOT).parts[0] not in ("cli", "__main__.py"):
            assert "cli" not in _imports(path), path
