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

Parsing is the cost (about 50 ms a module, 2-3 s for a study's closures), so
what a file's parse yields (its tree's digest and its import statements, as
plain data: :func:`_facts`) is kept on disk, keyed by the SHA-256 of the
file's bytes, in one JSON file next to numba's kernel cache
(:func:`_disk_path`): a warm process reads the sources' bytes and that file
and parses nothing. The entries are facts of the bytes alone, so the key is
the same with or without the file; the file is written atomically, read as
data only, and ignored whole when it was written by another Python or another
version of this module (or is damaged).
"""

from __future__ import annotations

import ast
import functools
import hashlib
import json
import os
import sys
from importlib import metadata
from pathlib import Path
from typing import Any

__all__ = ["module_closure", "module_digest", "code_hash", "cache_clear"]

_ROOT = Path(__file__).parent
_PKG = "tslip"

#: What a disk cache entry was computed by: this interpreter and this module's source.
_MAKER = f"{sys.version}|{hashlib.sha256(Path(__file__).read_bytes()).hexdigest()}"
#: The disk cache's file name (:func:`_disk_path`), by interpreter.
_DISK_NAME = f"tslip-codehash.{sys.implementation.cache_tag}.json"
#: Entries the disk cache keeps beyond those this process used (older sources' facts).
_DISK_ENTRIES = 1000

#: One import statement of a source, as data: ``(kind, module, level, names, in_plot)``;
#: ``kind`` "import" or "from", ``names`` ``((name, asname), ...)``, ``in_plot`` inside a
#: function named ``plot`` (:func:`_plot_imports`).
ImportFact = tuple[str, str | None, int, tuple[tuple[str, str | None], ...], bool]

#: Third-party libraries whose version can change a computed number.
LIBRARIES: tuple[str, ...] = ("numpy", "scipy", "numba", "llvmlite", "cma")


@functools.cache
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


def _resolve(module: str | None, level: int, package: str) -> str:
    """The absolute module name ``from <level dots><module> import ...`` reads from."""
    if not level:
        return module or ""
    up = package.split(".")
    up = up[:len(up) - (level - 1)]
    return ".".join(up + ([module] if module else []))


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
    # every import statement, not just the top level's: a lazy ``__init__`` (PEP 562)
    # states its names in an ``if TYPE_CHECKING:`` block
    for kind, module, level, names, _ in _facts(init)[1]:
        if kind == "from" and any((asname or n) == name for n, asname in names):
            base = _resolve(module, level, package)
            orig = next(n for n, asname in names if (asname or n) == name)
            return _provider(base, orig) if _file(base) is not None else package
    return f"{package}:self"


def _is_docstring(node: ast.stmt) -> bool:
    return (isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant)
            and isinstance(node.value.value, str))


def _is_version(node: ast.stmt) -> bool:
    return (isinstance(node, ast.Assign)
            and any(isinstance(t, ast.Name) and t.id == "__version__" for t in node.targets))


def _tree(source: bytes) -> ast.Module:
    """The syntax tree of a source, without what computes nothing.

    The docstrings of the module, its classes and functions are dropped, and a
    module-level ``__version__ = ...`` (see the module docstring).
    """
    tree = ast.parse(source.decode("utf-8"))
    tree.body = [n for n in tree.body if not _is_version(n)]
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            if node.body and _is_docstring(node.body[0]):
                node.body = node.body[1:]
    return tree


def _scan(source: bytes) -> tuple[str, tuple[ImportFact, ...]]:
    """What hashing needs of a source: its tree's digest and its import statements.

    The digest is the SHA-256 of ``ast.dump`` of :func:`_tree`; the imports are
    every ``import`` and ``from ... import`` anywhere in the tree, in ``ast.walk``
    order, as :data:`ImportFact`.
    """
    tree = _tree(source)
    nodes = tuple(ast.walk(tree))
    in_plot = _plot_imports(nodes)
    facts: list[ImportFact] = []
    for node in nodes:
        if isinstance(node, ast.Import):
            facts.append(("import", None, 0, tuple((a.name, a.asname) for a in node.names),
                          id(node) in in_plot))
        elif isinstance(node, ast.ImportFrom):
            facts.append(("from", node.module, node.level,
                          tuple((a.name, a.asname) for a in node.names), id(node) in in_plot))
    return hashlib.sha256(ast.dump(tree).encode()).hexdigest(), tuple(facts)


def _disk_path() -> Path | None:
    """The disk cache of :func:`_facts`: next to numba's cache of the kernels.

    As numba places it (``numba.core.caching``): under ``NUMBA_CACHE_DIR`` when
    that is set, in a folder named after this package's folder, else in the
    package's own ``__pycache__``. None when that cannot be written (then
    every process parses the sources).
    """
    name = _DISK_NAME
    pkg = Path(__file__).parent
    cache = os.environ.get("NUMBA_CACHE_DIR")
    if cache:
        sub = f"{pkg.name}_{hashlib.sha1(str(pkg.resolve()).encode()).hexdigest()}"  # noqa: S324
        return Path(cache) / sub / name
    folder = pkg / "__pycache__"
    return folder / name if os.access(folder if folder.is_dir() else pkg, os.W_OK) else None


def _fact_from_json(x: Any) -> ImportFact:
    kind, module, level, names, in_plot = x
    if (kind not in ("import", "from") or not isinstance(module, (str, type(None)))
            or type(level) is not int or type(in_plot) is not bool):
        raise ValueError("not an import")
    return (kind, module, level, tuple((str(n), None if a is None else str(a))
                                       for n, a in names), in_plot)


@functools.cache
def _disk() -> dict[str, tuple[str, tuple[ImportFact, ...]]]:
    """The disk cache's entries (source SHA-256 -> :func:`_scan`); empty if absent or unusable."""
    path = _disk_path()
    try:
        if path is None or not path.is_file():
            return {}
        doc = json.loads(path.read_text(encoding="utf-8"))
        if not isinstance(doc, dict) or doc.get("maker") != _MAKER:
            return {}
        out = {}
        for key, (digest, facts) in doc["files"].items():
            if not (isinstance(key, str) and isinstance(digest, str) and len(digest) == 64):
                raise ValueError("not a digest")
            out[key] = (digest, tuple(_fact_from_json(f) for f in facts))
        return out
    except (OSError, ValueError, TypeError, KeyError, AttributeError, RecursionError):
        return {}  # damaged or foreign: parse again, and rewrite it


#: Entries of :func:`_facts` this process used, and whether one was not on disk.
_used: dict[str, tuple[str, tuple[ImportFact, ...]]] = {}
_dirty: list[bool] = []


def _save() -> None:
    """Write the disk cache (atomically) if this process scanned a source it did not hold."""
    path = _disk_path()
    if not _dirty or path is None:
        return
    entries = {**_disk(), **_used}
    if len(entries) > _DISK_ENTRIES + len(_used):
        entries = dict(_used)
    text = json.dumps({"maker": _MAKER, "files": entries}, separators=(",", ":"))
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)
        _disk.cache_clear()
        _dirty.clear()
    except OSError:
        return


@functools.cache
def _facts(path: Path) -> tuple[str, tuple[ImportFact, ...]]:
    """:func:`_scan` of the source file ``path``: from the disk cache, else parsed.

    Read once a process (the import scans and :func:`module_digest` share it).
    """
    source = path.read_bytes()
    key = hashlib.sha256(source).hexdigest()
    found = _disk().get(key)
    if found is None:
        found = _scan(source)
        _dirty.append(True)
    _used[key] = found
    return found


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
    for fact in _facts(path)[1]:
        kind, mod, level, names, in_plot = fact
        if in_plot and _targets(fact, package) <= {f"{_PKG}.plotting"}:
            continue
        if kind == "import":
            out.update(n for n, _ in names if n.split(".")[0] == _PKG)
            continue
        base = _resolve(mod, level, package)
        if base.split(".")[0] != _PKG:
            continue
        init = _file(base)
        if init is not None and init.name == "__init__.py":
            out.update(_provider(base, n) for n, _ in names if n != "*")
            if any(n == "*" for n, _ in names):
                out.add(base)
        else:
            out.add(base)
    return frozenset(m for m in out if _file(m.removesuffix(":self")) is not None)


def _targets(fact: ImportFact, package: str) -> set[str]:
    """The ``tslip`` subpackages (``tslip.x``) an import statement reads from."""
    kind, module, level, names, _ = fact
    if kind == "import":
        mods = [n for n, _ in names]
    else:
        base = _resolve(module, level, package)
        mods = [base] if module or base != _PKG else [f"{base}.{n}" for n, _ in names]
    return {".".join(m.split(".")[:2]) for m in mods}


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


@functools.cache
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
    return _facts(path)[0]


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
    _save()
    return h.hexdigest()[:24]


def cache_clear() -> None:
    """Forget every scan and hash of this process (for a caller that edits sources)."""
    for f in (_file, _facts, _disk, _provider, _imports, module_closure, module_digest,
              code_hash):
        f.cache_clear()
    _used.clear()
