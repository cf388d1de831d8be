"""The code hash that keys cached results: which sources it covers, and that edits change it."""

import shutil
from pathlib import Path
from types import SimpleNamespace

import pytest

import tslip
from tslip import _codehash as ch


def test_closure_follows_imports_and_reexports():
    rob = ch.module_closure("tslip.gait.robustness")
    stab = ch.module_closure("tslip.gait.stability")
    # what robustness calls (through `from ..gait import floquet` style re-exports) ...
    assert {"tslip.gait.stability", "tslip.simulation._kernels", "tslip.model.parameters",
            "tslip.simulation._variational"} <= set(rob)
    # ... and not what it does not
    assert "tslip.gait.robustness" not in stab
    assert not any(m.startswith(("tslip.biped", "tslip.sweeps", "tslip.plotting")) for m in rob)
    assert not any(m.startswith("tslip.gait") for m in ch.module_closure("tslip.biped._kernels"))


def test_names_of_the_lazy_top_level_package_resolve_to_their_modules():
    # tslip/__init__ imports its public names on first use; the TYPE_CHECKING
    # block still tells the hash where `from tslip import simulate` comes from
    assert ch._provider("tslip", "simulate") == "tslip.simulation.integrate"
    assert ch._provider("tslip", "robustness_report") == "tslip.gait.robustness"
    assert ch._provider("tslip", "__version__") == "tslip:self"
    assert {"tslip.simulation._kernels", "tslip.simulation._variational",
            "tslip.simulation._rk"} <= set(ch.module_closure("tslip"))


def test_unknown_module_is_an_error():
    with pytest.raises(ValueError, match="not a tslip module: tslip.nope"):
        ch.module_closure("tslip.nope")


def test_an_edit_changes_exactly_the_hashes_that_depend_on_it(tmp_path, monkeypatch):
    root = tmp_path / "tslip"
    shutil.copytree(Path(tslip.__file__).parent, root,
                    ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(ch, "_ROOT", root)

    def hashes():
        ch.cache_clear()
        return {m: ch.code_hash(m) for m in ("tslip.gait.robustness", "tslip.gait.stability",
                                             "tslip.biped.simulate")}

    before = hashes()
    f = root / "gait" / "robustness.py"
    f.write_text(f.read_text() + "\n_EDIT = 1\n")
    after = hashes()
    assert after["tslip.gait.robustness"] != before["tslip.gait.robustness"]
    assert after["tslip.gait.stability"] == before["tslip.gait.stability"]
    assert after["tslip.biped.simulate"] == before["tslip.biped.simulate"]
    k = root / "simulation" / "_kernels.py"
    k.write_text(k.read_text() + "\n_EDIT = 1\n")
    again = hashes()
    assert again["tslip.gait.stability"] != after["tslip.gait.stability"]
    assert again["tslip.biped.simulate"] == after["tslip.biped.simulate"]
    k = root / "simulation" / "_rk.py"  # the integrator core every kernel shares
    k.write_text(k.read_text() + "\n_EDIT = 1\n")
    core = hashes()
    assert all(core[m] != again[m] for m in core)
    # an added import is followed once the scans are forgotten (they are kept a process)
    assert "tslip.biped.simulate" not in ch.module_closure("tslip.gait.robustness")
    f.write_text(f.read_text() + "\nfrom ..biped import simulate\n")
    hashes()
    assert "tslip.biped.simulate" in ch.module_closure("tslip.gait.robustness")
    ch.cache_clear()


def test_a_plot_method_importing_plotting_is_not_followed(tmp_path, monkeypatch):
    """A result's .plot imports tslip.plotting; a figure changes no number, so no hash."""
    root = tmp_path / "tslip"
    (root / "gait").mkdir(parents=True)
    (root / "plotting").mkdir()
    for init in ("__init__.py", "gait/__init__.py", "plotting/__init__.py"):
        (root / init).write_text("")
    (root / "plotting" / "fig.py").write_text("X = 1\n")
    (root / "gait" / "a.py").write_text(
        "class R:\n    def plot(self, ax=None):\n        from ..plotting.fig import X\n")
    (root / "gait" / "b.py").write_text(
        "class R:\n    def draw(self, ax=None):\n        from ..plotting.fig import X\n")
    (root / "gait" / "c.py").write_text(  # a plot method importing something else
        "class R:\n    def plot(self, ax=None):\n        from . import b\n")
    monkeypatch.setattr(ch, "_ROOT", root)
    ch.cache_clear()
    try:
        assert ch.module_closure("tslip.gait.a") == ("tslip.gait.a",)
        assert "tslip.plotting.fig" in ch.module_closure("tslip.gait.b")
        assert {"tslip.gait.b", "tslip.plotting.fig"} <= set(ch.module_closure("tslip.gait.c"))
    finally:
        ch.cache_clear()


_MODULE = '''"""A module docstring."""

# a comment
RATE = 1.5


class Law:
    """A class docstring."""

    def f(self, x):
        """A method docstring."""
        return RATE * x  # why
'''


@pytest.mark.parametrize("edit, rekeys", [
    (lambda s: s.replace("# a comment", "# another comment"), False),
    (lambda s: s.replace("# why", ""), False),
    (lambda s: s.replace("A module docstring.", "Reworded."), False),
    (lambda s: s.replace('    """A class docstring."""\n\n', ""), False),
    (lambda s: s.replace('"""A method docstring."""', ""), False),
    (lambda s: s.replace("RATE = 1.5", "\n\nRATE = (\n    1.5)"), False),  # layout only
    (lambda s: s.replace("RATE = 1.5", "RATE = 1.25"), True),  # a changed constant
    (lambda s: s.replace("RATE * x", "x * RATE"), True),
    (lambda s: s.replace("A method docstring.", "Reworded,\n        over two lines."), False),
    (lambda s: s + "\nSTRING = 'a string constant, not a docstring'\n", True),
])
def test_only_what_can_change_a_number_rekeys(tmp_path, monkeypatch, edit, rekeys):
    """A comment, a docstring or layout keeps the hash; a changed constant or statement does not."""
    root = tmp_path / "tslip"
    (root / "gait").mkdir(parents=True)
    (root / "__init__.py").write_text('__version__ = "0.1.0"\n')
    (root / "gait" / "__init__.py").write_text("")
    (root / "gait" / "b.py").write_text(_MODULE)
    (root / "gait" / "a.py").write_text("from .b import Law\n")  # b reached through the closure
    monkeypatch.setattr(ch, "_ROOT", root)

    def key():
        ch.cache_clear()
        return ch.code_hash("tslip.gait.a")

    try:
        before = key()
        edited = edit(_MODULE)
        assert edited != _MODULE
        (root / "gait" / "b.py").write_text(edited)
        assert (key() != before) is rekeys
    finally:
        ch.cache_clear()


def test_the_key_holds_python_and_each_numerical_library(monkeypatch):
    """Python's version (the trees' dump differs between versions) and each library's re-key."""
    ch.cache_clear()
    before = ch.code_hash("tslip.gait.stability")
    real = ch._version
    # listed here, not read from ch.LIBRARIES: dropping one from the hash must fail
    for lib in ("numpy", "scipy", "numba", "llvmlite", "cma"):
        monkeypatch.setattr(ch, "_version", lambda name, lib=lib: "0.0" if name == lib
                            else real(name))
        ch.cache_clear()
        assert ch.code_hash("tslip.gait.stability") != before, lib
    monkeypatch.setattr(ch, "_version", real)
    monkeypatch.setattr(ch, "sys", SimpleNamespace(version_info=(3, 99, 0)))
    ch.cache_clear()
    assert ch.code_hash("tslip.gait.stability") != before, "python"
    monkeypatch.undo()
    ch.cache_clear()
    assert ch.code_hash("tslip.gait.stability") == before


_SETS = (("tslip.gait.continuation", "tslip.gait.fixed_point", "tslip.gait.stability",
          "tslip.gait.robustness"), ("tslip.sweeps.appendix_e",), ("tslip.gait.viability",))


def test_the_disk_cache_gives_the_parsed_key_and_parses_nothing(tmp_path, monkeypatch):
    """A warm process reads each source's facts from the disk cache: same keys, no parse."""
    disk = tmp_path / "codehash.json"
    monkeypatch.setattr(ch, "_disk_path", lambda: disk)
    ch.cache_clear()
    parsed = [ch.code_hash(*s) for s in _SETS]  # an empty cache: every source parsed
    assert disk.is_file()
    ch.cache_clear()

    def no_parse(source):
        raise AssertionError("parsed a source the disk cache holds")

    monkeypatch.setattr(ch, "_scan", no_parse)
    assert [ch.code_hash(*s) for s in _SETS] == parsed
    monkeypatch.undo()
    ch.cache_clear()


def test_the_disk_cache_keys_on_the_source_bytes(tmp_path, monkeypatch):
    """An edit that changes a number re-keys with a warm disk cache too; a comment does not."""
    root = tmp_path / "tslip"
    (root / "gait").mkdir(parents=True)
    (root / "__init__.py").write_text("")
    (root / "gait" / "__init__.py").write_text("")
    (root / "gait" / "b.py").write_text(_MODULE)
    monkeypatch.setattr(ch, "_ROOT", root)
    monkeypatch.setattr(ch, "_disk_path", lambda: tmp_path / "codehash.json")

    def key():
        ch.cache_clear()
        return ch.code_hash("tslip.gait.b")

    try:
        before = key()
        assert key() == before  # from the disk cache
        (root / "gait" / "b.py").write_text(_MODULE.replace("# why", "# because"))
        assert key() == before
        (root / "gait" / "b.py").write_text(_MODULE.replace("RATE = 1.5", "RATE = 1.25"))
        assert key() != before
        (root / "gait" / "b.py").write_text(_MODULE)
        assert key() == before
    finally:
        ch.cache_clear()


@pytest.mark.parametrize("content", ["{not json", '{"maker": "%s", "files": {"k": ["short", []]}}',
                                     '{"maker": "%s", "files": {"k": ["%s", [[1]]]}}', "[]",
                                     "another maker"])
def test_a_damaged_or_foreign_disk_cache_is_ignored_and_rewritten(tmp_path, monkeypatch,
                                                                   content):
    disk = tmp_path / "codehash.json"
    monkeypatch.setattr(ch, "_disk_path", lambda: disk)
    ch.cache_clear()
    import json

    want = ch.code_hash("tslip.gait.stability")
    if content == "another maker":  # another Python or hasher: its entries (here all wrong)
        doc = json.loads(disk.read_text())
        doc = {"maker": "another", "files": {k: ["0" * 64, v[1]]
                                             for k, v in doc["files"].items()}}
        disk.write_text(json.dumps(doc))
    else:
        disk.write_text(content.replace("%s", ch._MAKER, 1).replace("%s", "0" * 64))
    ch.cache_clear()
    assert ch.code_hash("tslip.gait.stability") == want
    assert json.loads(disk.read_text())["maker"] == ch._MAKER  # rewritten whole
    ch.cache_clear()
