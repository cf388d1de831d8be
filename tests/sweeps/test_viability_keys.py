"""The chunk cache key of ``run_viability`` covers every field of the spec that the map
depends on (issue 40): a change of energy, options, base parameters, actions or state
grid changes every chunk's key, as ``test_run_cache.py`` asserts for studies; the rule,
the name and the description change none (the map serves every rule)."""

import dataclasses
import json

import numpy as np
import pytest

import tslip
from tslip.model.parameters import Params
from tslip.simulation.options import IntegratorOptions
from tslip.sweeps import viability as sv
from tslip.sweeps.spec import Axis


@pytest.fixture(autouse=True)
def _small_chunks(monkeypatch):
    monkeypatch.setattr(sv, "CHUNK_CELLS", 8)  # 6 x 2 states x 4 actions: 6 chunks of 2 states


def _spec(**change) -> sv.ViabilitySpec:
    base = dict(name="k", base=tslip.preset("slip"),
                states=(Axis("y", (0.9, 1.0, 1.1, 1.2, 1.3, 1.4)), Axis("phi", (-0.1, 0.1))),
                action=Axis("alpha_r", (1.1, 1.2, 1.3, 1.4)), energy=2.6)
    return sv.ViabilitySpec(**{**base, **change})


def _all_new(spec: sv.ViabilitySpec, ref: list[str]) -> None:
    keys = sv.chunk_keys(spec)
    assert len(keys) == len(set(keys)) == len(spec.chunks())
    assert not set(keys) & set(ref)


def test_energy_changes_every_key():
    ref = sv.chunk_keys(_spec())
    assert len(ref) == 6
    _all_new(_spec(energy=3.2), ref)
    _all_new(_spec(energy=np.nextafter(2.6, 3.0)), ref)  # one ulp: another map


@pytest.mark.parametrize("field, value", [("rtol", 1e-10), ("atol", 1e-10), ("h0", 1e-3),
                                          ("max_steps", 50000), ("t_max_stance", 20.0),
                                          ("t_max_flight", 500.0), ("h_min", 1e-12),
                                          ("method", "dopri5")])
def test_every_integrator_option_changes_every_key(field, value):
    ref = sv.chunk_keys(_spec())
    tight = IntegratorOptions.tight("dop853")
    assert getattr(tight, field) != value
    _all_new(_spec(options=dataclasses.replace(tight, **{field: value})), ref)


def test_every_base_parameter_changes_every_key():
    ref = sv.chunk_keys(_spec())
    base = tslip.preset("slip")
    others = {"leg_reset": "local", "retraction": "apex",
              "controller": {"type": "global_pd"}}
    changed = []
    for name, value in base.to_dict().items():
        new = others.get(name, value * 1.1 + 0.01 if isinstance(value, float) else None)
        try:
            params = Params.from_dict({name: new}, base=base)
            spec = _spec(base=params)
        except ValueError:  # a value this grid refuses (e.g. a swing-leg speed with the
            continue        # lift-off clock: the apex is then no Poincare section)
        _all_new(spec, ref)
        changed.append(name)
    # every number the map's strides depend on is among those tried
    assert {"m", "J", "r", "k", "l0", "g", "c_l", "leg_reset", "retraction",
            "controller"} <= set(changed), changed


def test_actions_change_every_key():
    ref = sv.chunk_keys(_spec())
    _all_new(_spec(action=Axis("alpha_r", (1.1, 1.2, 1.3, 1.41))), ref)  # one value
    _all_new(_spec(action=Axis("alpha_r", (1.1, 1.2, 1.3))), ref)  # fewer values
    _all_new(_spec(action=Axis("alpha_r", (1.0, 1.1, 1.2, 1.3))), ref)  # shifted by one
    _all_new(_spec(action=Axis("k", (20.0, 25.0, 30.0, 35.0))), ref)  # another parameter
    _all_new(_spec(action=(Axis("alpha_r", (1.1, 1.2, 1.3, 1.4)), Axis("k", (25.0,)))), ref)


def test_state_grids_change_every_key_and_a_chunk_of_the_same_points_keeps_its_own():
    ref = sv.chunk_keys(_spec())
    y = (0.9, 1.0, 1.1, 1.2, 1.3, 1.4)
    _all_new(_spec(states=(Axis("y", tuple(v + 0.01 for v in y)), Axis("phi", (-0.1, 0.1)))),
             ref)
    _all_new(_spec(states=(Axis("y", y), Axis("phi", (-0.1, 0.2)))), ref)
    _all_new(_spec(states=(Axis("y", y), Axis("phid", (-0.1, 0.1)))), ref)  # another variable
    # the same points in another order of variables are other cells of another map
    _all_new(_spec(states=(Axis("phi", (-0.1, 0.1)), Axis("y", y))), ref)
    # one height changed: only the chunk holding it (chunk 2: states 4 and 5) is new
    moved = list(y)
    moved[2] = 1.15
    keys = sv.chunk_keys(_spec(states=(Axis("y", tuple(moved)), Axis("phi", (-0.1, 0.1)))))
    assert [k == r for k, r in zip(keys, ref)] == [True, True, False, True, True, True]


def test_the_rule_name_and_description_change_no_key():
    ref = sv.chunk_keys(_spec())
    for rule in ("nearest", "vibly"):  # the map serves every rule: only the iteration reruns
        assert sv.chunk_keys(_spec(rule=rule)) == ref
    assert sv.chunk_keys(_spec(name="other", description="another folder")) == ref


def test_a_run_at_another_energy_into_the_same_folder_reuses_no_cell(tmp_path):
    """The audit's mutant: the energy left out of the key reused all 72 cells of a run at
    2.6 for a run at 3.2. Here: nothing is reused, and the map equals a fresh run's."""
    out = tmp_path / "o"
    sv.run_viability(_spec(energy=2.6), out, workers=1)
    again = sv.run_viability(_spec(energy=3.2), out, workers=1)
    meta = json.loads((out / "run.json").read_text())
    assert (meta["computed"], meta["cached"]) == (48, 0)
    fresh = sv.run_viability(_spec(energy=3.2), tmp_path / "fresh", workers=1)
    assert again.map.next.tobytes() == fresh.map.next.tobytes()
    # and the energy matters to the map: the two runs' successors differ
    first = sv.run_viability(_spec(energy=2.6), tmp_path / "first", workers=1)
    ok = np.isfinite(first.map.next) & np.isfinite(again.map.next)
    assert ok.any() and not np.allclose(first.map.next[ok], again.map.next[ok])
