"""The cache key follows the code behind each analysis (not the package version)."""

import dataclasses
import shutil
from pathlib import Path
from types import SimpleNamespace

import pytest

import tslip
from tslip import _codehash as ch
from tslip._codehash import code_hash, module_closure
from tslip.model.controllers import ConstantTorque, GlobalPD, LocalVelocity, Passive
from tslip.model.parameters import Params
from tslip.sweeps import Axis, StudySpec
from tslip.sweeps import point as point_mod
from tslip.sweeps.run import point_key, study_keys


def _spec(*analyses):
    return StudySpec("s", tslip.preset("table2.1"), (Axis("v0", (4.0, 5.0)),),
                     analyses=analyses)


def _keys(spec):
    return [k for _, _, keys in study_keys(spec) for k in keys]


def test_editing_robustness_recomputes_exactly_the_points_with_robustness(monkeypatch):
    specs = {a: _spec(*a) for a in [("floquet",), ("floquet", "stride"),
                                    ("floquet", "robustness"), ("robustness", "stride")]}
    before = {a: _keys(s) for a, s in specs.items()}

    def edited(*modules):  # as if tslip/gait/robustness.py had changed on disk
        real = code_hash(*modules)
        return real + "-edited" if "tslip.gait.robustness" in module_closure(*modules) else real

    monkeypatch.setattr(point_mod, "code_hash", edited)
    for a, s in specs.items():
        after = _keys(s)
        if "robustness" in a:
            assert not set(after) & set(before[a]), a
        else:
            assert after == before[a], a


def test_code_table_covers_what_the_point_module_imports():
    """Every module point.py runs is hashed by code_version (else an edit would go unseen)."""
    hashed = set(module_closure(*[m for mods in point_mod.CODE.values() for m in mods]))
    unhashed = set(module_closure("tslip.sweeps.point")) - hashed
    # the point module is hashed by its own source; spec only builds parameters (in the key);
    # tslip._codehash is hashed too: the result classes' run records call it
    assert unhashed == {"tslip.sweeps.point", "tslip.sweeps.spec"}
    for optional in ("tslip.gait.robustness", "tslip.gait.stride"):
        assert optional not in module_closure(*point_mod.CODE[None])


def test_keys_are_per_point_and_match_point_key():
    grid = StudySpec("g", tslip.preset("table2.1"),
                     (Axis("k", (20.0, 25.0)), Axis("v0", (5.0, 4.0, 6.0))))
    plan = study_keys(grid)
    keys = [k for _, _, ks in plan for k in ks]
    assert len(set(keys)) == 6
    assignment, values, ks = plan[1]
    assert values == [4.0, 5.0, 6.0]  # ascending, aligned with the keys
    assert ks[2] == point_key(grid, {**assignment, "v0": 6.0})
    # a changed base parameter changes every key
    other = StudySpec("g", tslip.preset("table2.1").with_omega_r_bar(0.5), grid.axes)
    assert not set(keys) & {k for _, _, ks in study_keys(other) for k in ks}



# --- every input that can change a point's numbers re-keys it ------------------------------

def _one_key(spec):
    """The key of the point v0 = 5 (every spec below has it)."""
    return next(k for a, vs, ks in study_keys(spec) for v, k in zip(vs, ks) if v == 5.0)


def _rob(base=None, **meta):
    return StudySpec("s", base or tslip.preset("table2.1"), (Axis("v0", (4.0, 5.0, 6.0)),),
                     analyses=("floquet", "robustness"), meta=meta)


def _changed(value):
    return value * 1.01 if value else 0.01


def test_every_params_field_rekeys():
    base = tslip.preset("table2.1")
    key = _one_key(_rob(base))
    other = {"controller": LocalVelocity(Kd=0.5, alphad_ref=2.0), "leg_reset": "global",
             "retraction": "apex", "alpha_stop": 1.5}
    fields = dataclasses.fields(Params)
    # a field added to Params must be added here (else its effect on the key goes untested)
    assert {f.name for f in fields if not isinstance(getattr(base, f.name), float)} == set(other)
    for f in fields:
        if f.name == "v0":
            continue  # the axis: its value is the point's own
        value = other.get(f.name) or _changed(getattr(base, f.name))
        assert _one_key(_rob(dataclasses.replace(base, **{f.name: value}))) != key, f.name


@pytest.mark.parametrize("controller", [Passive(), GlobalPD(), LocalVelocity(Kd=0.5,
                                                                              alphad_ref=2.0),
                                        ConstantTorque(tau_c=0.1, c_h=0.2)])
def test_every_controller_gain_rekeys(controller):
    base = dataclasses.replace(tslip.preset("table2.1"), controller=controller)
    key = _one_key(_rob(base))
    for f in dataclasses.fields(controller):
        gain = dataclasses.replace(controller, **{f.name: _changed(getattr(controller, f.name))})
        assert _one_key(_rob(dataclasses.replace(base, controller=gain))) != key, f.name
    others = {type(c) for c in (Passive(), GlobalPD(), LocalVelocity(), ConstantTorque())}
    for cls in others - {type(controller)}:
        assert _one_key(_rob(dataclasses.replace(base, controller=cls()))) != key, cls


def test_tolerances_strides_analyses_and_resolution_rekey():
    key = _one_key(_rob())
    assert _one_key(_rob(tol=1e-10)) == key  # the default, stated or not
    assert _one_key(_rob(tol=1e-6)) != key  # global PD studies and TOML specs set their own
    assert _one_key(_rob(neutral_tol=0.01)) != key
    assert _one_key(dataclasses.replace(_rob(), n_steps=10)) != key
    assert _one_key(dataclasses.replace(_rob(), analyses=("floquet",))) != key
    # another resolution: the continuation seeds the point from other neighbours
    finer = _rob().with_resolution([5])
    assert 5.0 in finer.axes[0].values
    assert _one_key(finer) != key


def test_the_integrator_options_are_in_the_hashed_code(tmp_path, monkeypatch):
    """A study runs the default IntegratorOptions: a changed default re-keys every point."""
    assert "tslip.simulation.options" in module_closure(*point_mod.CODE[None])
    root = tmp_path / "tslip"
    shutil.copytree(Path(tslip.__file__).parent, root,
                    ignore=shutil.ignore_patterns("__pycache__"))
    spec = _rob()
    try:
        monkeypatch.setattr(ch, "_ROOT", root)
        ch.cache_clear()
        key = _one_key(spec)
        opts = root / "simulation" / "options.py"
        text = opts.read_text()
        assert text.count("default=1e-8") == 2  # rtol and atol
        opts.write_text(text.replace("default=1e-8", "default=1e-9", 1))
        ch.cache_clear()
        assert _one_key(spec) != key
    finally:
        ch.cache_clear()


def test_python_and_library_versions_rekey(monkeypatch):
    spec = _rob()
    ch.cache_clear()
    key = _one_key(spec)
    real = ch._version
    for lib in ("numpy", "scipy", "numba", "llvmlite", "cma"):  # not read from ch.LIBRARIES
        monkeypatch.setattr(ch, "_version", lambda name, lib=lib: "0.0" if name == lib
                            else real(name))
        ch.cache_clear()
        assert _one_key(spec) != key, lib
    monkeypatch.setattr(ch, "_version", real)
    monkeypatch.setattr(ch, "sys", SimpleNamespace(version_info=(3, 99, 0)))
    ch.cache_clear()
    assert _one_key(spec) != key, "python"
    monkeypatch.undo()
    ch.cache_clear()
    assert _one_key(spec) == key
