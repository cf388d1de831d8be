"""``tslip.gait.viability`` was split into statemap, mapstore, basins and viability
(issue 42): every name it had still imports from it, and files saved under the old class
names still load."""

import importlib
import json

import numpy as np
import pytest

import tslip
from tslip.model import preset

#: tslip.gait.viability's public names in 0.3.0 (its ``__all__`` and ``grid_columns``),
#: written out here, and the module each lives in now.
OLD_NAMES = {"StateActionMap": "statemap", "StoredMap": "mapstore", "Viability": "viability",
             "ViableSection": "viability", "Basin": "basins", "state_action_map": "statemap",
             "viability": "viability", "basin": "basins", "STATE_NAMES": "statemap",
             "SECTION_UNITS": "statemap", "check_map_inputs": "statemap",
             "map_cells": "statemap", "read_chunk": "mapstore", "grid_columns": "statemap"}


@pytest.mark.parametrize("name", sorted(OLD_NAMES))
def test_every_old_name_imports_from_viability_as_the_same_object(name):
    old = importlib.import_module("tslip.gait.viability")
    new = importlib.import_module(f"tslip.gait.{OLD_NAMES[name]}")
    assert getattr(old, name) is getattr(new, name)


def test_gait_exports_are_the_split_modules_objects():
    import tslip.gait as g

    for name in ("StateActionMap", "Viability", "Basin", "state_action_map", "viability",
                 "basin"):
        assert getattr(g, name) is getattr(
            importlib.import_module(f"tslip.gait.{OLD_NAMES[name]}"), name)


def _with_old_class_name(path, old: str) -> None:
    record = json.loads(path.read_text())
    new = record["result"]["__type__"]
    assert new != old  # the file was written under the new name
    record["result"]["__type__"] = old
    path.write_text(json.dumps(record))


def test_a_state_action_map_saved_before_the_split_loads(tmp_path):
    from tslip.gait.viability import StateActionMap

    x, a = np.linspace(-1.0, 1.0, 5), np.array([-0.25, 0.0, 0.25])
    nxt = 2 * x[:, None] + a[None, :]
    smap = StateActionMap.from_arrays({"x": x}, ("a", a), nxt, failed=np.abs(nxt) > 1)
    path = smap.save(tmp_path / "m.json")
    _with_old_class_name(path, "tslip.gait.viability:StateActionMap")
    back = tslip.load(path)
    assert type(back) is StateActionMap
    assert np.array_equal(back.next[..., 0], np.where(np.abs(nxt) > 1, np.nan, nxt),
                          equal_nan=True)
    assert np.array_equal(back.status, (np.abs(nxt) > 1).astype(np.int64))


def test_a_basin_saved_before_the_split_loads(tmp_path):
    from tslip.gait.viability import Basin

    y = np.array([1.0, 1.1])
    steps, done, status = np.array([3, -1]), np.array([10, 4]), np.array([0, 2])
    b = Basin(("y",), (y,), steps, done, status, 10, 1e-6, 2.2, preset("slip"),
              np.zeros(5))
    path = b.save(tmp_path / "b.parquet")
    _with_old_class_name(path.with_suffix(".json"), "tslip.gait.viability:Basin")
    back = tslip.load(path)
    assert type(back) is Basin
    assert np.array_equal(back.steps, steps) and np.array_equal(back.status, status)
    assert back.params == preset("slip")


def test_an_unknown_old_name_is_still_refused(tmp_path):
    from tslip.gait.viability import StateActionMap

    smap = StateActionMap.from_arrays({"x": [0.0, 1.0]}, ("a", [0.0]), [[0.0], [1.0]])
    path = smap.save(tmp_path / "m.json")
    _with_old_class_name(path, "tslip.gait.viability:np")
    with pytest.raises(ValueError, match="np"):
        tslip.load(path)
