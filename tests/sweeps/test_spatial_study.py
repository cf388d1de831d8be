"""3-D studies (issue 43) on the sweep machinery: numbers against the docs and physics,
caching and resume, and the cache key following the spatial code."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import tslip
from tslip import _codehash as ch
from tslip.spatial.lateral import TABLE21_VX
from tslip.sweeps import StudySpec, run_study
from tslip.sweeps import spatial_point as sp
from tslip.sweeps.run import study_file, study_keys
from tslip.sweeps.spatial_spec import SpatialBase

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "lateral.toml"


def _spec(text: str) -> StudySpec:
    import tomllib

    return StudySpec.from_dict({"name": "t", **tomllib.loads(text)})


def test_tslip3d_study_gives_the_docs_table_and_resumes_bit_for_bit(tmp_path):
    """r 0.1 and 0.3 at splay 0.05: the largest non-trivial |multiplier| of
    docs/analyses/spatial_tslip.md (1.5220, 1.7495, real), the trivial ones 1 (energy,
    heading), the gait mirror-symmetric."""
    spec = _spec('model = "tslip3d"\n[[axis]]\nparam = "r"\nvalues = [0.3, 0.1]\n')
    res = run_study(spec, tmp_path / "s", workers=1)
    f = res.frame
    assert f["r"].tolist() == [0.1, 0.3]
    assert f["converged"].all()
    np.testing.assert_allclose(f["max_nontrivial"], [1.5220, 1.7495], atol=6e-5)
    assert (f["kind"] == "real").all() and (f["stability"] == "unstable").all()
    assert (f["trivial_error"] < 1e-6).all() and (f["residual"] < 1e-9).all()
    assert (f["vx"] == TABLE21_VX).all()  # held
    assert (tmp_path / "s" / "results.parquet").is_file()
    # resume: drop one point's line from the cache; only it is computed again
    cache = study_file(spec, tmp_path / "s")
    lines = cache.read_text().splitlines(keepends=True)
    assert len(lines) == 2
    cache.write_text(lines[0])
    again = run_study(spec, tmp_path / "s", workers=1)
    assert (again.meta["cached"], again.meta["computed"]) == (1, 1)
    assert len(cache.read_text().splitlines()) == 2  # the cached point was not computed again
    pd.testing.assert_frame_equal(again.frame.drop(columns="seconds"),
                                  f.drop(columns="seconds"))
    assert run_study(spec, tmp_path / "s", workers=1).meta["cached"] == 2


def test_tslip3d_lateral_limits_are_the_docs_table():
    """docs/analyses/spatial_tslip.md, r 0.3, splay 0.05, 25 strides: push
    +0.00033/-0.00025, roll rate +0.00025/-0.00019, yaw rate +0.000047/-0.000035, each a
    crossed leg in stride 23 (+) or 24 (-)."""
    spec = _spec('model = "tslip3d"\nanalyses = ["floquet", "lateral_robustness"]\n'
                 '[[axis]]\nparam = "r"\nvalues = [0.3]\n')
    row = run_study(spec, None, workers=1).frame.iloc[0]
    for col, docs in (("lateral_push_plus", 0.00033), ("lateral_push_minus", -0.00025),
                      ("roll_rate_plus", 0.00025), ("roll_rate_minus", -0.00019),
                      ("yaw_rate_plus", 0.000047), ("yaw_rate_minus", -0.000035)):
        assert row[col] == pytest.approx(docs, rel=0.04), col
        assert row[f"{col}_status"] == "FALL_CROSSED_LEG"
        assert row[f"{col}_stride"] == (23 if col.endswith("plus") else 24)


def test_tslip3d_continues_other_fields_and_holds_vx():
    """A point off the Table 2.1 path (another speed, a heavier roll inertia) is reached
    by continuation: the gait holds the asked vx, lands on its mirror image, and its
    three trivial multipliers are 1 (the conservative model's energy and heading)."""
    spec = _spec('model = "tslip3d"\n[params]\nJ_roll = 0.11\n'
                 '[[axis]]\nparam = "vx"\nvalues = [4.9]\n')
    f = run_study(spec, None, workers=1).frame
    assert f["converged"].all(), f["message"][0]
    assert f["vx"][0] == 4.9
    assert f["residual"][0] < 1e-9 and f["trivial_error"][0] < 3e-5  # central differences
    assert f["max_nontrivial"][0] > 1.0  # no coupling: laterally unstable (docs)


def test_slip3d_feedback_stabilises_the_fast_gait():
    """docs/analyses/spatial.md: at k 25, beta0 1.19, gamma0 0.05, energy 2.2 the fast
    symmetric gait (apex y 0.9389) has the largest non-trivial multiplier 1.466
    without feedback (Seipel and Holmes's first claim) and is stable at k_lat 1.5 (stable
    for k_lat in [0.7, 6]); each gait has the study's energy."""
    spec = _spec('preset = "slip3d"\n[[axis]]\nparam = "k_lat"\nvalues = [0.0, 1.5]\n')
    f = run_study(spec, None, workers=1).frame
    assert f["converged"].all()
    assert f["stability"].tolist() == ["unstable", "asymptotic"]
    assert f["max_nontrivial"][0] == pytest.approx(1.466, abs=6e-4)
    assert f["max_nontrivial"][1] < 1.0
    assert f["apex_y"][0] == pytest.approx(0.9389, abs=6e-5)
    energy = 0.5 * (f["apex_vx"] ** 2 + f["apex_vz"] ** 2) + f["apex_y"]  # m = g = 1
    np.testing.assert_allclose(energy, 2.2, atol=1e-9)
    assert (f["n_trivial"] == 1).all()  # the energy (fixed heading)
    assert (f["n_gaits"] >= 1).all() and f["n_stable"][1] >= 1


def test_slip3d_under_the_velocity_heading_is_stable_with_two_trivial_multipliers():
    """docs/analyses/spatial.md: the same gait with the leg placed relative to the
    velocity (apex y 0.9389, vx 1.5882) is stable, multiplier 0.0591; the heading is a
    second trivial multiplier."""
    spec = _spec('preset = "slip3d"\n[params]\nheading = "velocity"\n'
                 '[[axis]]\nparam = "energy"\nvalues = [2.2]\n')
    f = run_study(spec, None, workers=1).frame
    assert f["stability"][0] == "asymptotic"
    assert f["max_nontrivial"][0] == pytest.approx(0.0591, abs=6e-5)
    assert f["apex_y"][0] == pytest.approx(0.9389, abs=6e-5)
    assert f["apex_vx"][0] == pytest.approx(1.5882, abs=6e-5)
    assert f["n_trivial"][0] == 2 and f["apex_vz"][0] == 0.0


def test_a_point_without_a_gait_is_a_record_not_an_error():
    spec = _spec('model = "tslip3d"\n[[axis]]\nparam = "splay"\nvalues = [-0.05]\n')
    f = run_study(spec, None, workers=1).frame
    assert not f["converged"][0] and f["stability"][0] == "none"
    assert "splay must be in (0, pi/2)" in f["message"][0]


def test_the_example_grid_is_the_docs_gain_matrix(tmp_path):
    """examples/lateral.toml (k_splay x k_trail at splay 0.05, r 0.3): the largest
    non-trivial |multiplier| of docs/analyses/spatial_tslip.md's gain matrix (c: complex)."""
    spec = StudySpec.from_toml(EXAMPLE)
    assert spec.model == "tslip3d" and isinstance(spec.base, SpatialBase)
    f = run_study(spec, tmp_path / "lateral", workers=2).frame  # worker processes
    docs = {(0.0, 0.0): 1.750, (0.0, 1.0): 1.181, (0.0, 2.0): 1.091, (0.5, 0.0): 1.208,
            (0.5, 1.0): 1.097, (0.5, 2.0): 1.142, (1.0, 0.0): 1.105, (1.0, 1.0): 1.131,
            (1.0, 2.0): 1.203}
    complex_ = {(0.5, 2.0), (1.0, 1.0), (1.0, 2.0)}
    assert len(f) == len(docs)
    for _, row in f.iterrows():
        point = (row["k_splay"], row["k_trail"])
        assert row["max_nontrivial"] == pytest.approx(docs[point], abs=6e-4), point
        assert row["kind"] == ("complex" if point in complex_ else "real"), point
    assert f["k_trail"].tolist()[:3] == [0.0, 1.0, 2.0]  # axes order: the last inner


def test_a_spatial_preset_names_its_model_and_the_spec_round_trips():
    spec = _spec('preset = "slip3d-feedback"\n[params]\nenergy = 2.0\n'
                 '[[axis]]\nparam = "gamma0"\nvalues = [0.05]\n')
    assert spec.model == "slip3d"
    assert spec.base.get("k_lat") == 1.5 and spec.base.get("energy") == 2.0
    d = spec.to_dict()
    assert d["model"] == "slip3d" and d["params"]["heading"] == "fixed"
    # the planar form is unchanged: no model key
    assert "model" not in _spec('[[axis]]\nparam = "r"\nvalues = [0.1]\n').to_dict()


# --- the cache key ------------------------------------------------------------------------

def _key(spec):
    return study_keys(spec)[0][2][0]


def _tslip3d(**params):
    extra = "".join(f"{k} = {v!r}\n" for k, v in params.items())
    return _spec('model = "tslip3d"\nanalyses = ["floquet", "lateral_robustness"]\n'
                 f'[params]\n{extra}[[axis]]\nparam = "r"\nvalues = [0.3]\n')


def test_every_base_value_rekeys():
    for model, text in (("tslip3d", 'model = "tslip3d"\n'), ("slip3d", 'model = "slip3d"\n')):
        spec = _spec(text + '[[axis]]\nparam = "k"\nvalues = [25.0]\n')
        key = _key(spec)
        for name in spec.base.names():
            if name == "k":
                continue
            v = spec.base.get(name)
            if model == "slip3d" and name == "k_lat":
                v = 0.5
            changed = dataclasses.replace(spec, base=spec.base.set(name, v * 1.01 if v else 0.01))
            assert _key(changed) != key, (model, name)
    slip = _spec('model = "slip3d"\n[[axis]]\nparam = "k"\nvalues = [25.0]\n')
    turned = _spec('model = "slip3d"\n[params]\nheading = "velocity"\n'
                   '[[axis]]\nparam = "k"\nvalues = [25.0]\n')
    assert _key(slip) != _key(turned)
    base = _tslip3d()
    assert _key(dataclasses.replace(base, n_steps=10)) != _key(base)
    assert _key(dataclasses.replace(base, analyses=("floquet",))) != _key(base)


def test_the_code_table_covers_what_a_3d_point_runs():
    """Every module spatial_point reaches is hashed, but spatial_point itself (its own
    digest) and what it reaches only through the spec (parameters: in the key by value)."""
    hashed = set(ch.module_closure(*[m for code in sp.CODE.values() for mods in code.values()
                                     for m in mods]))
    unhashed = set(ch.module_closure("tslip.sweeps.spatial_point")) - hashed
    assert unhashed - set(ch.module_closure("tslip.sweeps.spec")) == {
        "tslip.sweeps.spatial_point"}
    assert {"tslip.spatial.trunk", "tslip.spatial._trunk_kernels", "tslip.simulation._rk",
            "tslip.simulation.options"} <= set(ch.module_closure(*sp.CODE["tslip3d"][None]))


@pytest.fixture()
def copied(tmp_path, monkeypatch):
    """The package copied, hashed from the copy: an edit there changes the hashes."""
    root = tmp_path / "tslip"
    shutil.copytree(Path(tslip.__file__).parent, root,
                    ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(ch, "_ROOT", root)
    ch.cache_clear()
    yield root
    ch.cache_clear()


def test_editing_spatial_code_rekeys_exactly_the_3d_points_it_computes(copied):
    specs = {"tslip3d": _tslip3d(),
             "tslip3d-floquet": dataclasses.replace(_tslip3d(), analyses=("floquet",)),
             "slip3d": _spec('model = "slip3d"\n[[axis]]\nparam = "k"\nvalues = [25.0]\n'),
             "planar": _spec('[[axis]]\nparam = "r"\nvalues = [0.3]\n')}

    def keys():
        ch.cache_clear()
        return {name: _key(s) for name, s in specs.items()}

    def edit(path):
        f = copied / path
        f.write_text(f.read_text() + "\n_EDIT = 1\n")
        return keys()

    before = keys()
    changed = {name for name, k in edit("spatial/trunk_section.py").items()
               if k != before[name]}
    assert changed == {"tslip3d", "tslip3d-floquet"}
    now = keys()
    changed = {name for name, k in edit("spatial/trunk_robustness.py").items() if k != now[name]}
    assert changed == {"tslip3d"}  # only the study with the lateral limits
    now = keys()
    changed = {name for name, k in edit("spatial/gait.py").items() if k != now[name]}
    assert changed == {"slip3d"}
    now = keys()
    changed = {name for name, k in edit("gait/robustness.py").items() if k != now[name]}
    assert changed == set()  # planar robustness: none of these points runs it
    now = keys()
    changed = {name for name, k in edit("gait/fixed_point.py").items() if k != now[name]}
    assert changed == {"planar"}
    now = keys()
    changed = {name for name, k in edit("sweeps/spatial_point.py").items() if k != now[name]}
    assert changed == {"tslip3d", "tslip3d-floquet", "slip3d"}
    now = keys()
    changed = {name for name, k in edit("simulation/_rk.py").items() if k != now[name]}
    assert changed == set(specs)  # the integrator core every model shares


def test_tslip_study_runs_a_3d_spec(tmp_path):
    from typer.testing import CliRunner

    from tslip.cli.main import app

    spec = tmp_path / "slip.toml"
    spec.write_text('preset = "slip3d"\n[[axis]]\nparam = "energy"\nvalues = [2.2]\n')
    res = CliRunner().invoke(app, ["study", str(spec), "--out", str(tmp_path / "o"),
                                   "--workers", "1"])
    assert res.exit_code == 0, res.output
    assert "slip: 1 points (0 cached), 1 with a periodic gait, 0 stable" in res.output
    f = pd.read_parquet(tmp_path / "o" / "results.parquet")
    assert f["stability"].tolist() == ["unstable"]  # fixed heading, no feedback (claim 1)


def test_a_3d_study_plots_its_multipliers():
    """StudyResult.plot on both 3-D models: the non-trivial multipliers and the trivial
    ones (3 of 10, or 1 of 3) as separate series; a point without a gait marked."""
    import matplotlib

    matplotlib.use("Agg")
    for text, n_trivial in (('model = "tslip3d"\n[[axis]]\nparam = "splay"\n'
                             'values = [-0.05, 0.05]\n', 3),
                            ('preset = "slip3d"\n[[axis]]\nparam = "energy"\n'
                             'values = [2.2]\n', 1)):
        res = run_study(_spec(text), None, workers=1)
        fig = res.plot()
        lines = {ln.get_label(): ln for ln in fig.axes[0].get_lines()}
        trivial = lines[next(k for k in lines if "trivial (energy)" in k)].get_ydata()
        assert np.sum(np.isfinite(trivial)) == n_trivial
        np.testing.assert_allclose(trivial[np.isfinite(trivial)], 1.0, atol=3e-5)
