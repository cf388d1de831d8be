"""Nothing tslip reads from disk can run code: an AST scan of src/tslip for the calls that would.

Refused anywhere in the package: the builtins ``eval``, ``exec``, ``compile``;
any load from ``pickle``, ``cPickle``, ``_pickle``, ``dill``, ``cloudpickle``
(``load*``, ``Unpickler``), ``marshal``, ``shelve``, ``joblib``;
``pandas.read_pickle``; ``numpy.load`` with ``allow_pickle`` other than
``False`` (or not called directly, so that it cannot be checked);
``yaml.load`` without a safe loader, ``yaml.unsafe_load`` and ``full_load``;
an import of those modules by name (``importlib.import_module("pickle")``).
Import aliases are followed (``import pickle as p``, ``from pickle import
loads``). The one way to code that does is :data:`ALLOWED`: a function named
there with the reason.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import tslip

ROOT = Path(tslip.__file__).parent

#: ``module:function`` -> why it may load pickles. The worker pool (tslip.sweeps._pool) and
#: a Dask scheduler pass tasks between our own processes through multiprocessing's and
#: Dask's pickling, which is not our code; none of our functions unpickles anything, so this
#: is empty. A function of the pool that did would be named here, with its reason.
ALLOWED: dict[str, str] = {}

_PICKLERS = ("pickle", "cPickle", "_pickle", "dill", "cloudpickle")
#: Modules whose import by a computed name is refused.
_UNSAFE_MODULES = {*_PICKLERS, "marshal", "shelve", "joblib"}
_SAFE_YAML_LOADERS = {"yaml.SafeLoader", "yaml.CSafeLoader", "yaml.BaseLoader",
                      "yaml.CBaseLoader"}


def _forbidden(name: str) -> bool:
    """``name`` (fully qualified) runs code from bytes wherever it is used."""
    module, _, attr = name.rpartition(".")
    return (name in {"builtins.eval", "builtins.exec", "builtins.compile", "pandas.read_pickle",
                     "joblib.load", "shelve.open", "marshal.load", "marshal.loads"}
            or (module in _PICKLERS and (attr.startswith("load") or "Unpickler" in attr))
            or (module == "shelve" and attr.endswith("Shelf"))
            or (module == "yaml" and attr.startswith(("unsafe_load", "full_load"))))


class _Scanner(ast.NodeVisitor):
    """Findings ``(module:function, line, what)`` of one module's source."""

    def __init__(self, module: str, tree: ast.Module) -> None:
        self.module, self.scope, self.found = module, [], []
        self.names: dict[str, str] = {}  # local name -> what it is bound to by an import
        for node in ast.walk(tree):  # every import, at any depth: aliases anywhere count
            if isinstance(node, ast.Import):
                for a in node.names:
                    self.names[a.asname or a.name.split(".")[0]] = a.name if a.asname else \
                        a.name.split(".")[0]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                for a in node.names:
                    self.names[a.asname or a.name] = f"{node.module}.{a.name}"

    def _add(self, node: ast.AST, what: str) -> None:
        where = f"{self.module}:{'.'.join(self.scope) or '<module>'}"
        self.found.append((where, getattr(node, "lineno", 0), what))

    def resolve(self, node: ast.AST) -> str | None:
        """The qualified name an expression stands for, if it is an imported or builtin one."""
        if isinstance(node, ast.Name):
            if node.id in self.names:
                return self.names[node.id]
            return f"builtins.{node.id}" if node.id in {"eval", "exec", "compile"} else None
        if isinstance(node, ast.Attribute):
            base = self.resolve(node.value)
            return f"{base}.{node.attr}" if base else None
        return None

    def _scoped(self, node: ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef) -> None:
        self.scope.append(node.name)
        self.generic_visit(node)
        self.scope.pop()

    visit_FunctionDef = visit_AsyncFunctionDef = visit_ClassDef = _scoped

    def visit_ImportFrom(self, node: ast.ImportFrom) -> None:
        if node.level == 0 and node.module:
            for a in node.names:
                name = f"{node.module}.{a.name}"
                if _forbidden(name) or (a.name == "*" and node.module.split(".")[0]
                                        in _UNSAFE_MODULES):
                    self._add(node, f"from {node.module} import {a.name}")

    def _use(self, node: ast.Name | ast.Attribute) -> bool:
        """Report a use of a refused name; True if reported."""
        name = self.resolve(node)
        if name and _forbidden(name):
            self._add(node, name)
        elif name == "numpy.load" and not getattr(node, "_called", False):
            self._add(node, "numpy.load not called directly")
        else:
            return False
        return True

    def visit_Name(self, node: ast.Name) -> None:
        if isinstance(node.ctx, ast.Load):
            self._use(node)

    def visit_Attribute(self, node: ast.Attribute) -> None:
        if not self._use(node):
            self.generic_visit(node)

    def visit_Call(self, node: ast.Call) -> None:
        name = self.resolve(node.func)
        kw = {k.arg: k.value for k in node.keywords}
        if name == "numpy.load":
            node.func._called = True  # type: ignore[attr-defined]
            flag = kw.get("allow_pickle", node.args[2] if len(node.args) > 2 else None)
            if None in kw or not (flag is None or (isinstance(flag, ast.Constant)
                                                   and flag.value is False)):
                self._add(node, "numpy.load with allow_pickle")
        elif name in {"yaml.load", "yaml.load_all"}:
            loader = kw.get("Loader", node.args[1] if len(node.args) > 1 else None)
            if loader is None or self.resolve(loader) not in _SAFE_YAML_LOADERS:
                self._add(node, f"{name} without a safe loader")
        elif name in {"importlib.import_module", "builtins.__import__", "__import__"} or (
                isinstance(node.func, ast.Name) and node.func.id == "__import__"):
            arg = node.args[0] if node.args else None
            if isinstance(arg, ast.Constant) and str(arg.value).split(".")[0] in _UNSAFE_MODULES:
                self._add(node, f"import of {arg.value} by name")
        self.generic_visit(node)


def scan(source: str, module: str) -> list[tuple[str, int, str]]:
    """What in ``source`` (the module ``module``) could run code read from disk."""
    tree = ast.parse(source)
    s = _Scanner(module, tree)
    s.visit(tree)
    return s.found


def _package() -> dict[str, str]:
    """Every module of the package: dotted name -> source."""
    out = {}
    for path in sorted(ROOT.rglob("*.py")):
        parts = path.relative_to(ROOT.parent).with_suffix("").parts
        out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path.read_text(
            encoding="utf-8")
    return out


def _refused(found: list[tuple[str, int, str]]) -> list[str]:
    return [f"{where} (line {line}): {what}" for where, line, what in found
            if where not in ALLOWED]


def test_nothing_in_the_package_runs_code_from_disk() -> None:
    found = [f for module, src in _package().items() for f in scan(src, module)]
    assert not _refused(found), "\n".join(_refused(found))
    used = {where for where, _, _ in found}
    assert set(ALLOWED) <= used, f"allowed but unused: {sorted(set(ALLOWED) - used)}"


def test_the_appendix_e_pickle_put_back_is_refused() -> None:
    """The reader this scan replaced, put back into the real reproduce.py, is found."""
    src = (ROOT / "sweeps" / "reproduce.py").read_text(encoding="utf-8")
    assert scan(src, "tslip.sweeps.reproduce") == []
    head = "def _appendix_e_load(path: Path, key: str) -> dict[str, Any] | None:\n"
    assert head in src
    back = "import pickle\n" + src.replace(
        head, head + "    cached = pickle.loads(path.read_bytes())\n")
    assert scan(back, "tslip.sweeps.reproduce") == [
        ("tslip.sweeps.reproduce:_appendix_e_load", src[:src.index(head)].count("\n") + 3,
         "pickle.loads")]


@pytest.mark.parametrize("source, what", [
    ("import pickle\npickle.loads(b)", "pickle.loads"),
    ("import pickle as p\np.load(f)", "pickle.load"),
    ("from pickle import loads\nloads(b)", "pickle.loads"),
    ("from pickle import loads as l\nl(b)", "pickle.loads"),
    ("import pickle\nclass U(pickle.Unpickler): pass", "pickle.Unpickler"),
    ("import pickle\nf = map(pickle.loads, blobs)", "pickle.loads"),
    ("import _pickle\n_pickle.loads(b)", "_pickle.loads"),
    ("import dill\ndill.load_session(f)", "dill.load_session"),
    ("import cloudpickle as cp\ncp.loads(b)", "cloudpickle.loads"),
    ("import marshal\nmarshal.loads(b)", "marshal.loads"),
    ("import shelve\nshelve.open(p)", "shelve.open"),
    ("import joblib\njoblib.load(p)", "joblib.load"),
    ("import pandas as pd\npd.read_pickle(p)", "pandas.read_pickle"),
    ("from pandas import read_pickle\nread_pickle(p)", "pandas.read_pickle"),
    ("eval(text)", "builtins.eval"),
    ("exec(text)", "builtins.exec"),
    ("compile(text, 'f', 'exec')", "builtins.compile"),
    ("import builtins as b\nb.exec(text)", "builtins.exec"),
    ("import numpy as np\nnp.load(p, allow_pickle=True)", "numpy.load with allow_pickle"),
    ("from numpy import load\nload(p, None, True)", "numpy.load with allow_pickle"),
    ("import numpy\nnumpy.load(p, **options)", "numpy.load with allow_pickle"),
    ("import numpy as np\nf = np.load", "numpy.load not called directly"),
    ("import yaml\nyaml.load(s)", "yaml.load without a safe loader"),
    ("import yaml\nyaml.load(s, Loader=yaml.Loader)", "yaml.load without a safe loader"),
    ("import yaml\nyaml.unsafe_load(s)", "yaml.unsafe_load"),
    ("import yaml\nyaml.full_load(s)", "yaml.full_load"),
    ("import importlib\nimportlib.import_module('pickle')", "import of pickle by name"),
    ("def f():\n    from pickle import loads\n    return loads(b)", "pickle.loads"),
    ("from pickle import *", "from pickle import *"),
])
def test_the_scan_finds(source: str, what: str) -> None:
    assert what in [w for _, _, w in scan(source, "tslip.x")], scan(source, "tslip.x")


@pytest.mark.parametrize("source", [
    "import numpy as np\nnp.load(p)",
    "import numpy as np\nwith np.load(p, allow_pickle=False) as z: pass",
    "import yaml\nyaml.safe_load(s)",
    "import yaml\nyaml.load(s, Loader=yaml.SafeLoader)",
    "from yaml import CSafeLoader, load\nload(s, CSafeLoader)",
    "import pickle\npickle.dumps(x)",  # writing a pickle runs nothing
    "import json\njson.loads(s)",
    "import re\nre.compile('a+')",
    "import ast\nast.literal_eval(s)",
    "self.compile()\nobj.loads(b)",
    "import pandas as pd\npd.read_parquet(p)",
])
def test_the_scan_passes(source: str) -> None:
    assert scan(source, "tslip.x") == []


def test_an_allowed_function_is_allowed_there_only(monkeypatch) -> None:
    src = ("import pickle\n"
           "def _receive(b):\n    return pickle.loads(b)\n"
           "def _other(b):\n    return pickle.loads(b)\n")
    found = scan(src, "tslip.sweeps._pool")
    assert [w for w, _, _ in found] == ["tslip.sweeps._pool:_receive",
                                        "tslip.sweeps._pool:_other"]
    monkeypatch.setitem(ALLOWED, "tslip.sweeps._pool:_receive", "our own processes")
    assert _refused(found) == ["tslip.sweeps._pool:_other (line 5): pickle.loads"]
