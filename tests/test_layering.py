"""Dependencies run one way: model -> simulation -> gait -> biped -> sweeps and experiment;
plotting and cli on top."""

import ast
from pathlib import Path

import tslip

ROOT = Path(tslip.__file__).parent
#: what each layer may import from inside tslip (besides itself and private helpers)
ALLOWED = {
    "model": set(),
    "simulation": {"model"},
    "gait": {"model", "simulation"},
    # spatial: the 3-D studies (issue 43) run on the sweep machinery; spatial itself builds on
    # model and simulation only, so this adds no cycle
    "sweeps": {"model", "simulation", "gait", "biped", "spatial"},
    "experiment": {"model", "simulation", "gait", "biped"},
    "biped": {"model", "simulation", "gait"},
    "spatial": {"model", "simulation"},
    "plotting": {"model", "simulation", "gait", "sweeps", "experiment", "biped", "spatial"},
}
TOP = {"_io", "_lines", "_safefile", "_results", "_checks", "_gridsize", "_kernel_cache",
       "_nrt", "_codehash", "_first_failure", "_conform", "_lazy",
       "_renamed", "protocols", "__init__", "__main__", "_typing", "__version__"}


def _top_level(name: str) -> str:
    """Where a name imported from the package itself (``from tslip import X``) lives.

    A public name re-exported by ``tslip/__init__.py`` counts as an import of
    the subpackage it comes from (``find_gait`` -> ``gait``); a subpackage or
    top-level module counts as itself.
    """
    return tslip._SUBPACKAGE.get(name, name)


def _imports(path: Path, plot_methods: bool = True) -> set[str]:
    """tslip subpackages a module imports (absolute or relative).

    ``from tslip import X`` and ``import tslip`` (then ``tslip.X``) count as
    imports of the subpackage ``X`` lives in (:func:`_top_level`).

    With ``plot_methods=False``, an import of ``tslip.plotting`` inside a
    function named ``plot`` (a result's ``.plot`` method) is not counted:
    the one import upwards the layering allows.
    """
    rel = path.relative_to(ROOT).parts
    out = set()
    tree = ast.parse(path.read_text())
    skip = set()
    if not plot_methods:
        for fn in ast.walk(tree):
            if isinstance(fn, ast.FunctionDef) and fn.name == "plot":
                for node in ast.walk(fn):
                    if isinstance(node, (ast.Import, ast.ImportFrom)):
                        only = _imports_of(node, rel)
                        if only == {"plotting"}:
                            skip.add(id(node))
    for node in ast.walk(tree):
        if id(node) not in skip:
            out |= _imports_of(node, rel)
    aliases = {a.asname or "tslip" for node in ast.walk(tree) if isinstance(node, ast.Import)
               for a in node.names
               if a.name == "tslip" or (a.name.startswith("tslip.") and not a.asname)}
    out |= {_top_level(node.attr) for node in ast.walk(tree) if isinstance(node, ast.Attribute)
            and isinstance(node.value, ast.Name) and node.value.id in aliases}
    return {m.removesuffix(".py") for m in out}


def _imports_of(node: ast.AST, rel: tuple[str, ...]) -> set[str]:
    """tslip subpackages one import statement reads from."""
    out = set()
    if isinstance(node, ast.ImportFrom):
        if node.level == 0 and node.module == "tslip":
            out.update(_top_level(a.name) for a in node.names)
        elif node.level == 0 and node.module and node.module.startswith("tslip."):
            out.add(node.module.split(".")[1])
        elif node.level > 0:
            base = list(rel[: len(rel) - node.level])
            parts = base + (node.module.split(".") if node.module else [])
            if parts:
                out.add(parts[0])
            else:  # "from .. import x", as "from tslip import x"
                out.update(_top_level(a.name) for a in node.names)
    elif isinstance(node, ast.Import):
        out.update(a.name.split(".")[1] for a in node.names if a.name.startswith("tslip."))
    return out


def test_import_layering():
    bad = []
    for layer, allowed in ALLOWED.items():
        for path in (ROOT / layer).rglob("*.py"):
            for dep in _imports(path, plot_methods=False) - {layer} - TOP:
                if dep not in allowed:
                    bad.append(f"{path.relative_to(ROOT)} imports tslip.{dep}")
    assert not bad, "\n".join(bad)


def test_nothing_below_cli_imports_cli():
    for path in ROOT.rglob("*.py"):
        if path.relative_to(ROOT).parts[0] not in ("cli", "__main__.py"):
            assert "cli" not in _imports(path), path


def test_plotting_is_imported_upwards_only_inside_plot_methods(tmp_path):
    """The exception is exactly an import of tslip.plotting in a function named plot."""
    src = tmp_path / "gait" / "x.py"
    src.parent.mkdir()
    src.write_text("def plot(self):\n    from ..plotting import f\n"
                   "def draw(self):\n    from ..plotting import g\n"
                   "def plot(self):\n    from ..sweeps import h\n")
    rel = Path("gait", "x.py")
    tree = ast.parse(src.read_text())
    fns = [n for n in tree.body if isinstance(n, ast.FunctionDef)]
    assert _imports_of(fns[0].body[0], rel.parts) == {"plotting"}
    global ROOT
    old, ROOT = ROOT, tmp_path
    try:
        assert _imports(src, plot_methods=False) == {"plotting", "sweeps"}  # draw's, plot's h
        assert _imports(src) == {"plotting", "sweeps"}
        src.write_text("def plot(self):\n    from ..plotting import f\n")
        assert _imports(src, plot_methods=False) == set()
        assert _imports(src) == {"plotting"}
    finally:
        ROOT = old


def test_imports_through_the_top_level_package_count(tmp_path):
    """``from tslip import X``, ``from .. import X`` and ``import tslip`` then ``tslip.X``
    are imports of the layer ``X`` lives in, so a lower layer cannot reach a higher one
    through the package's re-exports."""
    global ROOT
    old, ROOT = ROOT, tmp_path
    cases = {
        "from tslip import find_gait, Params\n": {"gait", "model"},
        "def f():\n    from tslip import gait, __version__\n": {"gait", "__version__"},
        "from .. import simulate, biped\n": {"simulation", "biped"},
        "import tslip as t\nimport numpy as np\nx = t.robustness(np.pi)\n": {"gait"},
        "import tslip\n\ndef f():\n    return tslip.sweeps.run, tslip.load\n": {"sweeps",
                                                                                  "_results"},
        "import tslip.plotting\n": {"plotting"},
        "import tslip.model\nf = tslip.find_gait\n": {"model", "gait"},
        "import tslip.model as m\nt = m.Params\ntslip = 1\n": {"model"},
    }
    try:
        for i, (code, expected) in enumerate(cases.items()):
            src = tmp_path / "model" / f"x{i}.py"
            src.parent.mkdir(exist_ok=True)
            src.write_text(code)
            assert _imports(src) == expected, code
    finally:
        ROOT = old
