"""The Result base: encoding round trips, tables, run records and safe, strict loading."""

from __future__ import annotations

import dataclasses
import datetime
import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import tslip
from _same import same
from tslip import _results
from tslip._results import Result, decode, encode, with_units
from tslip.simulation.result import Status


@dataclasses.dataclass(frozen=True, repr=False)
class Box(Result):
    """A result holding anything: the round trip of its field is the encoder's."""

    value: Any
    x: float = 1.5

    def to_dataframe(self) -> pd.DataFrame:
        return with_units(pd.DataFrame({"x": [self.x]}), {"x": "L"})


@dataclasses.dataclass(frozen=True, repr=False)
class Series(Result):
    """A result whose arrays live in its table when saved as .parquet / .csv."""

    t: np.ndarray
    y: np.ndarray
    label: str = "run"

    def to_dataframe(self) -> pd.DataFrame:
        return with_units(pd.DataFrame({"t": self.t, "y": self.y}), {"t": "s", "y": "L"})

    def _table_fields(self) -> tuple[str, ...]:
        return ("t", "y")

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        return {**fields, "t": df["t"].to_numpy(), "y": df["y"].to_numpy()}


DTYPES = [np.float64, np.float32, np.int64, np.int32, np.uint8, np.bool_, np.complex128]

arrays = st.sampled_from(DTYPES).flatmap(
    lambda dt: hnp.arrays(dt, hnp.array_shapes(min_dims=0, max_dims=3, max_side=12)))
scalars = st.one_of(
    st.none(), st.booleans(), st.integers(), st.text(max_size=8),
    st.floats(allow_nan=True, allow_infinity=True),
    st.complex_numbers(allow_nan=True, allow_infinity=True),
    st.sampled_from(list(Status)),
    st.sampled_from(DTYPES[:-1]).flatmap(lambda dt: hnp.from_dtype(np.dtype(dt))
                                         .map(lambda v, dt=dt: np.dtype(dt).type(v))),
    arrays,
)
trees = st.recursive(
    scalars,
    lambda kids: st.one_of(
        st.lists(kids, max_size=4),
        st.lists(kids, max_size=4).map(tuple),
        st.dictionaries(st.text(max_size=6), kids, max_size=4),  # "__..." keys too
        st.dictionaries(st.integers(), kids, max_size=3),
    ),
    max_leaves=12,
)


@settings(max_examples=300, deadline=None)
@given(trees)
def test_encode_decode_round_trip_is_exact(value):
    text = json.dumps(encode(value), allow_nan=False)  # strict JSON
    same(value, decode(json.loads(text)))


@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(value=trees)
def test_saved_result_loads_back_exact(tmp_path, value):
    box = Box(value)
    path = box.save(tmp_path / "box.json")
    same(box, tslip.load(path))
    same(box, Box.load(path))


@settings(max_examples=30, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(y=hnp.arrays(np.float64, st.integers(0, 300)))
@pytest.mark.parametrize("suffix", [".parquet", ".csv"])
def test_table_result_round_trip(tmp_path, suffix, y):
    s = Series(np.arange(len(y), dtype=float) * 0.1, y)
    path = s.save(tmp_path / f"s{suffix}")
    record = json.loads(path.with_suffix(".json").read_text())
    assert "y" not in json.dumps(record["result"]["fields"])  # the table holds the arrays
    back = tslip.load(path)
    same(s, back)
    same(s, tslip.load(path.with_suffix(".json")))  # the record finds its table
    assert back.to_dataframe().attrs["units"] == {"t": "s", "y": "L"}


def test_large_arrays_are_bytes_and_small_ones_readable():
    small, large = encode(np.arange(5.0)), encode(np.arange(500.0))
    assert small["data"] == [0.0, 1.0, 2.0, 3.0, 4.0] and "b64" not in small
    assert "b64" in large and "data" not in large
    big_endian = np.arange(200.0).astype(">f8")
    back = decode(json.loads(json.dumps(encode(big_endian))))
    assert np.array_equal(back, big_endian) and back.dtype == np.dtype("<f8")


def test_a_tslip_dataclass_inside_a_result_round_trips(tmp_path):
    p = dataclasses.replace(tslip.preset("table6.1"), controller=tslip.GlobalPD(Kp=1.0))
    state = tslip.TouchdownState(0.4, -0.0, 1.1, -0.2, 1e-300, x=2.0)
    box = Box({"params": p, "state": state, "status": Status.FALL_TRIP})
    back = tslip.load(box.save(tmp_path / "b.json"))
    same(box, back)
    assert back.value["params"] == p and back.value["state"] == state


def test_repr_is_one_short_line():
    r = repr(Series(np.zeros(10_000), np.ones(10_000), label="x" * 300))
    assert "\n" not in r and len(r) <= 200 and r.startswith("Series(")
    assert "10000" in r  # the arrays by shape, not their values
    assert repr(Box(1.0, x=0.1234567891)) == "Box(value=1, x=0.123457)"


def test_with_units_names_a_column_without_unit():
    with pytest.raises(ValueError, match="no unit for the column.*b"):
        with_units(pd.DataFrame({"a": [1], "b": [2]}), {"a": "L"})


@dataclasses.dataclass(frozen=True, repr=False)
class WithParams(Result):
    params: Any


def test_run_record(tmp_path):
    before = datetime.datetime.now(datetime.UTC).replace(microsecond=0)
    rec = json.loads(Box(1).save(tmp_path / "b.json").read_text())["run"]
    after = datetime.datetime.now(datetime.UTC)
    assert rec["tslip_version"] == tslip.__version__
    assert before <= datetime.datetime.fromisoformat(rec["date"]) <= after
    git = subprocess.run(["git", "rev-parse", "HEAD"], cwd=Path(tslip.__file__).parent,
                         capture_output=True, text=True)
    assert rec["git"] == (git.stdout.strip() if git.returncode == 0 else None)
    assert rec["code_hash"] is None  # Box is not tslip's: no code to hash
    assert rec["params"] is None  # Box has no params
    assert rec["class"] == f"{__name__}:Box"
    p = tslip.preset("table6.1")
    assert _results.run_record(WithParams(p))["params"] == p.to_dict()


def test_run_record_of_a_tslip_result_has_its_modules_code_hash():
    from tslip._codehash import code_hash

    fl = tslip.Floquet.__new__(tslip.Floquet)
    h = _results.run_record(fl)["code_hash"]
    assert h == code_hash("tslip.gait.stability") and len(h) == 24


# -- safe and strict loading ------------------------------------------------------
def _crafted(tmp_path, result) -> Path:
    path = tmp_path / "crafted.json"
    path.write_text(json.dumps({"format": _results.FORMAT, "run": {}, "result": result}))
    return path


@pytest.mark.parametrize("name", [
    "tslip._io:os.system",           # a function reached through a tslip module
    "tslip._io:Path",                # a class that is not tslip's
    "tslip.simulation.result:StepList",  # tslip's, but not a dataclass or enum
    "os:system", "builtins:eval", "subprocess:Popen",
    "tslip._io:os.system.__call__", "tslip._results:Result.__subclasses__",
    "tslip.model:Params ; os", "tslip", "",
])
def test_a_crafted_file_builds_nothing_else(tmp_path, name):
    marker = tmp_path / "ran"
    path = _crafted(tmp_path, {"__type__": name, "fields": {"command": f"touch {marker}",
                                                            "args": f"touch {marker}"}})
    with pytest.raises(ValueError) as err:
        tslip.load(path)
    assert "\n" not in str(err.value) and "crafted.json" in str(err.value)
    assert not marker.exists()
    path = _crafted(tmp_path, {"__enum__": name, "value": f"touch {marker}"})
    with pytest.raises(ValueError):
        tslip.load(path)
    assert not marker.exists()


def test_a_module_outside_tslip_is_never_imported(tmp_path):
    assert "antigravity" not in sys.modules
    path = _crafted(tmp_path, {"__type__": "antigravity:X", "fields": {}})
    with pytest.raises(ValueError, match="not imported"):
        tslip.load(path)
    assert "antigravity" not in sys.modules


def test_a_result_subclass_outside_tslip_loads(tmp_path):
    """A user's Result subclass (this test module's) loads: its module is imported."""
    same(Box(3), tslip.load(Box(3).save(tmp_path / "b.json")))


@pytest.mark.parametrize("text, why", [
    ("", "Expecting value"),
    ('{"format": {"name": "tslip-result", "version": 1}, "result": {"__type__"', "Expecting"),
    ('{"a": 1}', "not a saved tslip result"),
    ('{"format": {"name": "tslip-result", "version": 99}, "result": 1}', "newer"),
    ('{"format": {"name": "tslip-result", "version": 1}}', "result"),
    ('{"format": {"name": "tslip-result", "version": 1}, "result": '
     '{"__ndarray__": "<f8", "shape": [3], "b64": "!!!"}}', "cannot load"),
    ('{"format": {"name": "tslip-result", "version": 1}, "result": '
     '{"__ndarray__": "<f8", "shape": [4], "data": [1.0]}}', "cannot load"),
    ('{"format": {"name": "tslip-result", "version": 1}, "result": '
     '{"__ndarray__": "<M8[s]", "shape": [1], "data": [1]}}', "bad dtype"),
    ('{"format": {"name": "tslip-result", "version": 1}, "result": '
     '{"__type__": "tslip.model.parameters:Params", "fields": {"k": -1.0}}}', "k"),
    ('{"format": {"name": "tslip-result", "version": 1}, "result": '
     '{"__type__": "tslip.model.parameters:Params", "fields": {"nope": 1}}}', "nope"),
    ('{"format": {"name": "tslip-result", "version": 1}, "result": '
     '{"__enum__": "tslip.simulation.result:Status", "value": 12345}}', "12345"),
])
def test_a_damaged_file_is_a_one_line_value_error(tmp_path, text, why):
    path = tmp_path / "bad.json"
    path.write_text(text)
    with pytest.raises(ValueError, match=why) as err:
        tslip.load(path)
    assert "\n" not in str(err.value) and str(path) in str(err.value)


def test_damaged_or_missing_tables(tmp_path):
    s = Series(np.arange(3.0), np.arange(3.0))
    path = s.save(tmp_path / "s.parquet")
    path.write_bytes(path.read_bytes()[:40])
    with pytest.raises(ValueError, match="cannot load") as err:
        tslip.load(path)
    assert "\n" not in str(err.value)
    path.unlink()
    with pytest.raises(ValueError, match="cannot load"):
        tslip.load(path)
    with pytest.raises(ValueError, match="does not exist"):
        tslip.load(tmp_path / "nothing.json")
    with pytest.raises(ValueError, match=r"\.json, \.parquet, \.csv"):
        tslip.load(tmp_path / "s.npz")
    with pytest.raises(ValueError, match=r"\.json, \.parquet, \.csv"):
        s.save(tmp_path / "s.txt")


def test_load_checks_the_class(tmp_path):
    path = Box(1).save(tmp_path / "b.json")
    with pytest.raises(ValueError, match="holds a Box, not a Series"):
        Series.load(path)


def test_a_value_that_cannot_be_saved_is_named(tmp_path):
    with pytest.raises(TypeError, match=r"cannot save value\.f: a builtin_function"):
        Box({"f": print}).save(tmp_path / "b.json")
    assert not (tmp_path / "b.json").exists()


@pytest.mark.parametrize("name, why", [
    ("tslip._io:write_json", "not a class"),  # tslip's own function, by its own name
    ("tslip.simulation.result:StepList", "not a tslip dataclass, enum or Result"),
    ("tslip.simulation.result:Status", None),
    ("tslip.model.parameters:Params", None),
    (f"{__name__}:Box", None),
])
def test_which_classes_a_file_may_name(name, why):
    if why is None:
        assert _results._resolve(name).__name__ == name.rpartition(":")[2]
    else:
        with pytest.raises(ValueError, match=why):
            _results._resolve(name)
