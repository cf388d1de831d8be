"""The single-gait figures kept in a report folder (``sweeps/_figstore.py``).

Kept data read back bit for bit and under the same plot key as the data
computed; a file edited into another shape (a number turned text, a field
holding another class, an array of objects, a key missing or added), damaged,
of another format or through a link is never used: it is recomputed, with
one warning line (a stale key: silently).
"""

from __future__ import annotations

import copy
import json
import logging
from pathlib import Path
from typing import Any

import pytest

from _same import same
from tslip.plotting.report import _data_digest
from tslip.sweeps import _figstore, catalogue

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")

#: Cheap figures of every kind of data: a Result of Results with arrays (4.1), one with
#: a recorded run (4.5), a dict of Results (C.1), a TypedDict with a tuple (4.16).
FIGURES = {"4.1": catalogue.fig_impulse_linearisation, "4.5": catalogue.fig_step_down,
           "C.1": catalogue.fig_friction,
           "4.16": lambda: catalogue.fig_mass_offset_boundary(step=0.1, tol=0.05)}


@pytest.fixture(scope="module")
def computed() -> dict[str, Any]:
    return {k: fn() for k, fn in FIGURES.items()}


def _tree(folder: Path, key: str) -> dict[str, Any]:
    path, _ = _figstore._figure_entry(folder, "tiny", key)
    return json.loads(path.read_text())


def _put(folder: Path, key: str, record: dict[str, Any]) -> None:
    path, _ = _figstore._figure_entry(folder, "tiny", key)
    path.write_text(json.dumps(record))


def _warnings(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]


@pytest.mark.parametrize("key", list(FIGURES))
def test_kept_data_read_back_bit_for_bit_under_the_same_plot_key(key, computed,
                                                                 tmp_path) -> None:
    assert _figstore.figure_load(tmp_path, "tiny", key) is None  # nothing kept yet
    _figstore.figure_store(tmp_path, "tiny", key, computed[key])
    back = _figstore.figure_load(tmp_path, "tiny", key)
    same(computed[key], back, key)
    # the report's figure drawn from the computed data is reused for the data read back
    assert _data_digest(back) == _data_digest(computed[key])


def test_kept_returns_the_kept_copy_and_computes_once(computed, tmp_path) -> None:
    calls = []

    def compute() -> Any:
        calls.append(1)
        return computed["4.16"]

    first = _figstore.kept(tmp_path, "tiny", "4.16", compute)
    again = _figstore.kept(tmp_path, "tiny", "4.16", compute)
    assert len(calls) == 1 and first == again == computed["4.16"]
    assert _figstore.kept(tmp_path, "quick", "4.16", compute) == computed["4.16"]
    assert len(calls) == 2  # another resolution is another file


def _dI_x_text(t: dict) -> None:
    t["data"]["fields"]["dI_x"] = "0.5"


def _bool_for_float(t: dict) -> None:
    t["data"]["fields"]["dI_x"] = True


def _nominal_of_another_class(t: dict) -> None:
    t["data"]["fields"]["nominal"]["__type__"] = "tslip.gait.stride:FrictionCheck"


def _object_array(t: dict) -> None:
    arr = t["data"]["fields"]["nominal"]["fields"]["F_x"]
    arr.pop("b64", None)
    arr.update({"__ndarray__": "|O", "shape": [1], "data": ["text"]})


def _tuple_too_long(t: dict) -> None:
    t["data"]["fields"]["nominal"]["fields"]["hip_mean"]["__tuple__"].append(0.0)


def _missing_key(t: dict) -> None:
    del t["data"]["tol"]


def _extra_key(t: dict) -> None:
    t["data"]["boundary_sd"] = 0.1


def _bracket_of_three(t: dict) -> None:
    t["data"]["bracket"]["__tuple__"].append(1.0)


def _list_for_tuple(t: dict) -> None:
    t["data"]["bracket"] = t["data"]["bracket"]["__tuple__"]


def _other_format(t: dict) -> None:
    t["format"]["version"] = 0


def _not_a_record(t: dict) -> None:
    t.pop("key")


@pytest.mark.parametrize("key, edit", [
    ("4.1", _dI_x_text), ("4.1", _bool_for_float), ("4.1", _nominal_of_another_class),
    ("4.1", _object_array), ("4.1", _tuple_too_long), ("4.16", _missing_key),
    ("4.16", _extra_key), ("4.16", _bracket_of_three), ("4.16", _list_for_tuple),
    ("4.16", _other_format), ("4.16", _not_a_record)])
def test_an_edited_file_is_recomputed_with_one_warning(key, edit, computed, tmp_path,
                                                       caplog) -> None:
    _figstore.figure_store(tmp_path, "tiny", key, computed[key])
    tree = _tree(tmp_path, key)
    edited = copy.deepcopy(tree)
    edit(edited)
    assert edited != tree
    _put(tmp_path, key, edited)
    with caplog.at_level(logging.WARNING, logger="tslip"):
        assert _figstore.figure_load(tmp_path, "tiny", key) is None
    warned = _warnings(caplog)
    path, _ = _figstore._figure_entry(tmp_path, "tiny", key)
    assert len(warned) == 1 and warned[0].startswith(f"ignoring {path} ("), warned
    assert warned[0].endswith(f"recomputing figure {key}")
    # the same file unedited is read: the edit, not the writing, made the difference
    _put(tmp_path, key, tree)
    same(computed[key], _figstore.figure_load(tmp_path, "tiny", key), key)


@pytest.mark.parametrize("text", ["", "{", "[1, 2]", "null", '{"format": 1}', "1e999999"])
def test_a_damaged_file_is_recomputed_with_one_warning(text, tmp_path, caplog) -> None:
    path, _ = _figstore._figure_entry(tmp_path, "tiny", "4.16")
    path.parent.mkdir(parents=True)
    path.write_text(text)
    with caplog.at_level(logging.WARNING, logger="tslip"):
        assert _figstore.figure_load(tmp_path, "tiny", "4.16") is None
    assert len(_warnings(caplog)) == 1


def test_a_file_of_other_code_is_stale_quietly(computed, tmp_path, caplog) -> None:
    _figstore.figure_store(tmp_path, "tiny", "4.16", computed["4.16"])
    tree = _tree(tmp_path, "4.16")
    tree["key"] = "0" * 24 + ":tiny"
    _put(tmp_path, "4.16", tree)
    with caplog.at_level(logging.WARNING, logger="tslip"):
        assert _figstore.figure_load(tmp_path, "tiny", "4.16") is None
    assert _warnings(caplog) == []


def test_the_key_is_the_code_hash_of_the_figures_code(monkeypatch, computed, tmp_path) -> None:
    _figstore.figure_store(tmp_path, "tiny", "4.16", computed["4.16"])
    assert _figstore.figure_load(tmp_path, "tiny", "4.16") is not None
    monkeypatch.setattr(_figstore, "code_hash", lambda *modules: "another")
    assert _figstore.figure_load(tmp_path, "tiny", "4.16") is None


def test_a_link_at_the_file_is_replaced_not_written_through(computed, tmp_path) -> None:
    target = tmp_path / "elsewhere.txt"
    target.write_text("keep me")
    path, _ = _figstore._figure_entry(tmp_path / "report", "tiny", "4.16")
    path.parent.mkdir(parents=True)
    path.symlink_to(target)
    _figstore.figure_store(tmp_path / "report", "tiny", "4.16", computed["4.16"])
    assert target.read_text() == "keep me"
    assert not path.is_symlink()
    assert _figstore.figure_load(tmp_path / "report", "tiny", "4.16") == computed["4.16"]
