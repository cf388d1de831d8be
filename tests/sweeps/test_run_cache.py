"""The cache key follows the code behind each analysis (not the package version)."""

import tslip
from tslip._codehash import code_hash, module_closure
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

