"""The guard that drops numba cache entries compiled against other kernel sources."""

from __future__ import annotations

import re
from types import SimpleNamespace

from tslip import _codehash as ch
from tslip import _kernel_cache as kc


def _fake(tmp_path):
    return SimpleNamespace(_cache=SimpleNamespace(cache_path=str(tmp_path)))


def test_stale_entries_are_deleted_and_fresh_ones_kept(tmp_path):
    mine = [tmp_path / "_kernels.run-10.py311.nbi", tmp_path / "_kernels.run-10.py311.1.nbc"]
    other = tmp_path / "_variational.stride-3.py311.nbi"
    for f in (*mine, other):
        f.write_text("x")
    kc.check(_fake(tmp_path), "/somewhere/_kernels.py")  # no marker yet: stale
    assert not any(f.exists() for f in mine) and other.exists()
    marker = tmp_path / "_kernels.tslip-sources"
    assert marker.read_text() == kc.sources_hash()
    for f in mine:  # entries compiled now, under the current sources, survive
        f.write_text("x")
    kc.check(_fake(tmp_path), "/somewhere/_kernels.py")
    assert all(f.exists() for f in mine)
    marker.write_text("an older hash")  # a source changed since
    kc.check(_fake(tmp_path), "/somewhere/_kernels.py")
    assert not any(f.exists() for f in mine)


def test_hash_covers_every_kernel_source():
    for rel in kc.SOURCES:
        assert (kc._ROOT / rel).is_file(), rel
    assert len(kc.sources_hash()) == 64


def _module(rel):
    return "tslip." + rel.removesuffix(".py").replace("/", ".")


def _hashed_gaps(sources):
    """Modules with compiled kernels, or imported by one, that ``sources`` leaves out.

    A kernel's cache must go stale when any source compiled into it changes:
    every module defining a jit function, and every private ``tslip`` module
    such a module imports, transitively (layouts, jit options, shared
    kernels), is in the hash; the cache guard itself aside (it compiles
    nothing). Public modules (parameters, states) are the Python side, which
    only the packing functions of the ``_pack`` modules read.
    """
    jit = re.compile(r"^\s*from numba import .*\bnjit\b|^@njit", re.MULTILINE)
    todo = [_module(str(f.relative_to(kc._ROOT))) for f in kc._ROOT.rglob("*.py")
            if jit.search(f.read_text(encoding="utf-8"))]
    seen: set[str] = set()
    while todo:
        m = todo.pop()
        if m not in seen:
            seen.add(m)
            todo.extend(i for i in ch._imports(m) if i.rpartition(".")[2].startswith("_"))
    return seen - {_module(r) for r in sources} - {"tslip._kernel_cache"}


def test_every_source_compiled_into_a_kernel_is_hashed():
    assert _hashed_gaps(kc.SOURCES) == set()
    # the check can fail: drop the jit options, the kernels of one concept, a layout
    for rel in ("_nrt.py", "biped/_jit.py", "biped/_stride.py", "biped/_pack.py",
                "simulation/_rk.py", "simulation/_stride.py"):
        assert _hashed_gaps(tuple(r for r in kc.SOURCES if r != rel)) == {_module(rel)}, rel


def test_an_unusable_cache_is_left_alone():
    kc.check(object(), "x.py")  # no _cache attribute: ignored, no exception


def test_a_kernel_compiled_without_cache_is_left_alone(tmp_path):
    """A dispatcher without ``cache=True`` has a cache object with no path: ignored."""
    from numba import njit

    @njit
    def f(x):
        return x + 1

    kc.check(f, str(tmp_path / "x.py"))
    assert not list(tmp_path.iterdir())



def _fabricate(dirs, families, digest, skip=()):
    """numba's index files (and the markers) of every kernel of ``families`` but ``skip``."""
    for package, kernels in families.values():
        folder = dirs[package]
        folder.mkdir(exist_ok=True)
        for kernel in kernels:
            stem = kernel.split(".")[0]
            (folder / f"{stem}.tslip-sources").write_text(digest)
            if kernel not in skip:
                (folder / f"{kernel}-12.py311.nbi").write_text("x")
                (folder / f"{kernel}-12.py311.1.nbc").write_text("x")


def test_missing_families_read_from_the_cache_folders(tmp_path):
    dirs = {"simulation": tmp_path / "sim", "biped": tmp_path / "biped", "spatial": tmp_path / "3d"}
    for d in dirs.values():
        d.mkdir()
    assert kc.missing_families(dirs, "h") == list(kc.FAMILIES)  # empty: every family
    _fabricate(dirs, kc.FAMILIES, "h")
    assert kc.missing_families(dirs, "h") == []  # warm: none
    assert kc.missing_families({"simulation": dirs["simulation"]}, "h") == []
    # one kernel of one family gone: that family alone
    name, (package, kernels) = next(iter(kc.FAMILIES.items()))
    for f in dirs[package].glob(f"{kernels[-1]}-*"):
        f.unlink()
    assert kc.missing_families(dirs, "h") == [name]
    # entries under another sources hash are stale (check() deletes them at import)
    _fabricate(dirs, kc.FAMILIES, "h")
    assert kc.missing_families(dirs, "other") == list(kc.FAMILIES)
    assert kc.missing_families(dirs) == []  # without a digest the entries count


def test_families_name_kernels_that_exist():
    import importlib

    for package, kernels in kc.FAMILIES.values():
        for kernel in kernels:
            module, name = kernel.split(".")
            mod = importlib.import_module(f"tslip.{package}.{module}")
            assert any(getattr(mod, n, None) is not None and getattr(
                getattr(mod, n), "__name__", n) == name for n in dir(mod)) or any(
                getattr(k, "__name__", "") == name for v in vars(mod).values()
                if isinstance(v, tuple) for k in v), kernel
