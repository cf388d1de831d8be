"""A hash of the code that computes a result, for caches that never go stale.

A cached result is valid while the code that produced it is unchanged. That
code is a module and everything it imports from ``tslip``, found here by
reading the import statements of the sources (``ast``, nothing is
imported): :func:`module_closure` follows them transitively, and
:func:`code_hash` hashes those modules' code together with the versions of
Python and of the numerical libraries they call. So an edit to
:mod:`tslip.gait.robustness` invalidates the cached points that ran a
robustness analysis and no others, and an edit to the biped leaves every
TSLIP study cached.

What is hashed is what can change a number: each module's syntax tree
without its docstrings (:func:`module_digest`), so a comment, a docstring or
a reformatted line keeps every cached result, while a changed constant or
statement recomputes them. The tree's dump differs between Python versions,
and so may results: Python's major.minor version is in the key.

Imports inside functions count too (they run when the function does). A
``from package import name`` counts ``package/name.py`` when that file
exists, else the module the package's ``__init__`` takes ``name`` from, else
the ``__init__``'s own source (for a name it defines, like ``__version__``).

The version string is a label, not code: a module-level ``__version__ = ...``
is left out of the hashed trees, so a release that only bumps the version
keeps every cached result, while any other edit (the same file's included)
recomputes them.
"""

from __future__ import annotations

import ast
import functools
import hashlib
import sys
from importlib import metadata
from pathlib import Path

__all__ = ["module_closure", "module_digest", "code_hash", "cache_clear"]

_ROOT = Path(__file__).parent
_PKG = "tslip"

#: Third-party libraries whose version can change a computed number.
LIBRARIES: tuple[str, ...] = ("numpy", "scipy", "numba", "llvmlite", "cma")


def _file(module: str) -> Path | None:
    """Source file of a ``tslip`` module (dotted name), or None if there is none."""
    parts = module.split(".")
    if parts[0] != _PKG:
        return None
    base = _ROOT.joinpath(*parts[1:])
    for cand in (base.with_suffix(".py"), base / "__init__.py"):
        if cand.is_file():
            return cand
    return None


def _resolve(node: ast.ImportFrom, package: str) -> str:
    """The absolute module name an ``ImportFrom`` reads from."""
    if not node.level:
        return node.module or ""
    up = package.split(".")
    up = up[:len(up) - (node.level - 1)]
    return ".".join(up + ([node.module] if node.module else []))


def _package_of(module: str) -> str:
    path = _file(module)
    return module if path is not None and path.name == "__init__.py" else module.rpartition(".")[0]


@functools.cache
def _provider(package: str, name: str) -> str:
    """The module that defines ``name`` imported from ``package``.

    A submodule of that name; else the module the package's ``__init__``
    re-exports it from; else the ``__init__`` itself, as a leaf
    (``"<package>:self"``: its own source, not what it imports).
    """
    sub = f"{package}.{name}"
    if _file(sub) is not None:
        return sub
    init = _file(package)
    if init is None or init.name != "__init__.py":
        return package
    # walk, not just the top level: a lazy ``__init__`` (PEP 562) states its
    # names in an ``if TYPE_CHECKING:`` block
    for node in _nodes(init):
        if isinstance(node, ast.ImportFrom) and any((a.asname or a.name) == name
                                                     for a in node.names):
            base = _resolve(node, package)
            orig = next(a.name for a in node.names if (a.asname or a.name) == name)
            return _provider(base, orig) if _file(base) is not None else package
    return f"{package}:self"


def _is_docstring(node: ast.stmt) -> bool:
    return (isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant)
            and isinstance(node.value.value, str))


def _is_version(node: ast.stmt) -> bool:
    return (isinstance(node, ast.Assign)
            and any(isinstance(t, ast.Name) and t.id == "__version__" for t in node.targets))


@functools.cache
def _tree(path: Path) -> ast.Module:
    """The syntax tree of the source file ``path``, parsed once, without what computes nothing.

    The docstrings of the module, its classes and functions are dropped, and a
    module-level ``__version__ = ...`` (see the module docstring). The import
    scans and :func:`module_digest` share this one parse (parsing is most of
    the hash's cost).
    """
    tree = ast.parse(path.read_text(encoding="utf-8"))
    tree.body = [n for n in tree.body if not _is_version(n)]
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            if node.body and _is_docstring(node.body[0]):
                node.body = node.body[1:]
    return tree


@functools.cache
def _nodes(path: Path) -> tuple[ast.AST, ...]:
    """Every node of :func:`_tree` of ``path`` (``ast.walk`` order)."""
    return tuple(ast.walk(_tree(path)))


def _plot_imports(nodes: tuple[ast.AST, ...]) -> set[int]:
    """``id``s of the import statements inside a function named ``plot``.

    A result's ``.plot`` method imports :mod:`tslip.plotting` when called
    (the one import upwards the layering allows): figures do not change a
    computed number, so those imports are not followed.
    """
    out: set[int] = set()
    for node in nodes:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.name == "plot":
            out.update(id(n) for n in ast.walk(node) if isinstance(n, (ast.Import,
                                                                         ast.ImportFrom)))
    return out


@functools.cache
def _imports(module: str) -> frozenset[str]:
    """The ``tslip`` modules that ``module``'s source imports (anywhere in the file).

    Except :mod:`tslip.plotting` imported inside a ``plot`` method (:func:`_plot_imports`).
    Scanned once a process, as :func:`code_hash` reads the sources once: the
    closures of different module sets share the scans of their common modules
    (a sweep's cache keys take several; parsing costs about 7 ms a file).
    """
    path = _file(module)
    if path is None:
        return frozenset()
    package = _package_of(module)
    out: set[str] = set()
    nodes = _nodes(path)
    in_plot = _plot_imports(nodes)
    for node in nodes:
        if id(node) in in_plot and _targets(node, package) <= {f"{_PKG}.plotting"}:
            continue
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.split(".")[0] == _PKG)
        elif isinstance(node, ast.ImportFrom):
            base = _resolve(node, package)
            if base.split(".")[0] != _PKG:
                continue
            if _file(base) is not None and _file(base).name == "__init__.py":  # type: ignore
                out.update(_provider(base, a.name) for a in node.names if a.name != "*")
                if any(a.name == "*" for a in node.names):
                    out.add(base)
            else:
                out.add(base)
    return frozenset(m for m in out if _file(m.removesuffix(":self")) is not None)


def _targets(node: ast.AST, package: str) -> set[str]:
    """The ``tslip`` subpackages (``tslip.x``) an import statement reads from."""
    if isinstance(node, ast.Import):
        names = [a.name for a in node.names]
    elif isinstance(node, ast.ImportFrom):
        base = _resolve(node, package)
        names = [base] if node.module or base != _PKG else [f"{base}.{a.name}"
                                                              for a in node.names]
    else:
        return set()
    return {".".join(n.split(".")[:2]) for n in names}


@functools.cache
def module_closure(*modules: str) -> tuple[str, ...]:
    """Every ``tslip`` module that ``modules`` import, transitively, themselves included."""
    seen: set[str] = set()
    todo = list(modules)
    unknown = [m for m in modules if _file(m) is None]
    if unknown:
        raise ValueError(f"not a tslip module: {', '.join(unknown)}")
    while todo:
        m = todo.pop()
        if m in seen:
            continue
        seen.add(m)
        if not m.endswith(":self"):
            todo.extend(_imports(m) - seen)
    return tuple(sorted(seen))


def _version(lib: str) -> str:
    try:
        return metadata.version(lib)
    except metadata.PackageNotFoundError:
        return "absent"


@functools.cache
def module_digest(module: str) -> str:
    """SHA-256 (hex) of a ``tslip`` module's code: its syntax tree without docstrings.

    Comments and layout never reach the tree; the docstrings of the module,
    its classes and functions are dropped from it, and so is a module-level
    ``__version__ = ...``. ``ast.dump`` leaves out line and column numbers, so
    moving code by a line changes nothing. A leaf ``"<package>:self"`` is
    its ``__init__``'s code.
    """
    path = _file(module.removesuffix(":self"))
    if path is None:
        raise ValueError(f"not a tslip module: {module}")
    return hashlib.sha256(ast.dump(_tree(path)).encode()).hexdigest()


@functools.cache
def code_hash(*modules: str) -> str:
    """SHA-256 (hex, 24 characters) of the code of ``module_closure(*modules)``.

    Each module by :func:`module_digest`; Python's major.minor version (the
    trees' dump differs between versions) and the versions of
    :data:`LIBRARIES` are part of the hash. Computed once a process per set
    of modules.
    """
    h = hashlib.sha256(f"python={sys.version_info[0]}.{sys.version_info[1]}\n".encode())
    for lib in LIBRARIES:
        h.update(f"{lib}={_version(lib)}\n".encode())
    for m in module_closure(*modules):
        h.update(f"{m}\n{module_digest(m)}\n".encode())
    return h.hexdigest()[:24]


def cache_clear() -> None:
    """Forget every scan and hash of this process (for a caller that edits sources)."""
    for f in (_tree, _nodes, _provider, _imports, module_closure, module_digest, code_hash):
        f.cache_clear()
