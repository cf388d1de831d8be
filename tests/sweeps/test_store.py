"""The study's point store: a JSON line per point; a torn or foreign line is computed again."""

import json

import pandas as pd
import pytest

import tslip
from tslip.sweeps import Axis, StudySpec, _store, run_study
from tslip.sweeps.run import saved_points, study_file


def _spec():
    return StudySpec("line", tslip.preset("table2.1"), (Axis("v0", (4.0, 4.5, 5.0, 5.5)),),
                     analyses=("floquet",))


def _exact(a, b):
    pd.testing.assert_frame_equal(a.drop(columns="seconds"), b.drop(columns="seconds"),
                                  check_exact=True)


def _lines(path):
    return path.read_bytes().split(b"\n")


def test_one_line_per_point_read_back_exactly(tmp_path):
    spec = _spec()
    full = run_study(spec, tmp_path, workers=1)
    lines = _lines(study_file(spec, tmp_path))
    assert lines[-1] == b"" and len(lines) == spec.n_points + 1  # each ends in a newline
    stored = _store.read(study_file(spec, tmp_path))
    assert sorted(r["v0"] for r in stored.values()) == [4.0, 4.5, 5.0, 5.5]
    again = run_study(spec, tmp_path, workers=1)
    assert again.meta["computed"] == 0
    _exact(full.frame, again.frame)


def test_a_torn_last_line_is_ignored_cut_off_and_its_point_recomputed(tmp_path):
    spec = _spec()
    full = run_study(spec, tmp_path / "full", workers=1)
    run_study(spec, tmp_path / "cut", workers=1)
    path = study_file(spec, tmp_path / "cut")
    *whole, last, _ = _lines(path)
    path.write_bytes(b"\n".join(whole) + b"\n" + last[: len(last) // 2])  # killed mid-write
    assert saved_points(spec, tmp_path / "cut") == spec.n_points - 1
    resumed = run_study(spec, tmp_path / "cut", workers=1)
    assert resumed.meta["computed"] == 1 and resumed.meta["cached"] == spec.n_points - 1
    _exact(full.frame, resumed.frame)
    # the torn half is gone: every line is a whole record again
    lines = _lines(path)
    assert lines[-1] == b"" and all(json.loads(x)["key"] for x in lines[:-1])
    assert len(lines) == spec.n_points + 1


def test_lines_that_are_not_point_records_are_ignored(tmp_path):
    spec = _spec()
    run_study(spec, tmp_path, workers=1)
    path = study_file(spec, tmp_path)
    whole = _lines(path)[:-1]
    first = json.loads(whole[0])
    bad = [b"not json",
           json.dumps({"key": first["key"], "record": {"v0": [4.0]}}).encode(),  # not a scalar
           json.dumps({"key": first["key"], "record": first["record"], "x": 1}).encode(),
           json.dumps([first["key"], first["record"]]).encode()]
    path.write_bytes(b"\n".join(bad + whole[1:]) + b"\n")  # the first point only as bad lines
    assert saved_points(spec, tmp_path) == spec.n_points - 1
    assert run_study(spec, tmp_path, workers=1).meta["computed"] == 1


def test_another_configuration_has_its_own_file(tmp_path, monkeypatch):
    from tslip.sweeps import run as run_mod

    spec = _spec()
    run_study(spec, tmp_path, workers=1)
    before = study_file(spec, tmp_path)
    monkeypatch.setattr(run_mod, "code_version", lambda analyses: "edited")
    assert study_file(spec, tmp_path) != before
    assert run_study(spec, tmp_path, workers=1).meta["computed"] == spec.n_points
    assert before.exists()  # the old configuration's records stay


_BAD = {
    "nested too deep": lambda rec: b"[" * 100_000 + b"]" * 100_000,
    "record a number": lambda rec: json.dumps({**rec, "record": 5}).encode(),
    "a value a list": lambda rec: json.dumps(
        {**rec, "record": {**rec["record"], "v0": ["a"]}}).encode(),
    "key a number": lambda rec: json.dumps({**rec, "key": 5}).encode(),
    "not UTF-8": lambda rec: json.dumps({**rec, "key": "X" + rec["key"]}).encode().replace(
        b'"X', b'"\xff'),
}


@pytest.mark.parametrize("fault", [*_BAD, "torn"])
def test_a_bad_line_warns_once_naming_it_and_its_point_is_recomputed(tmp_path, caplog, fault):
    spec = _spec()
    full = run_study(spec, tmp_path / "full", workers=1)
    run_study(spec, tmp_path / "bad", workers=1)
    path = study_file(spec, tmp_path / "bad")
    lines = _lines(path)[:-1]
    if fault == "torn":
        data, where = b"\n".join(lines[:-1]) + b"\n" + lines[-1][:30], len(lines)
    else:
        lines[1] = _BAD[fault](json.loads(lines[1]))
        data, where = b"\n".join(lines) + b"\n", 2
    path.write_bytes(data)
    with caplog.at_level("WARNING", logger="tslip"):
        again = run_study(spec, tmp_path / "bad", workers=1)
    msgs = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert len(msgs) == 1 and str(path) in msgs[0] and f"line {where}:" in msgs[0], msgs
    assert again.meta["computed"] == 1 and again.meta["cached"] == spec.n_points - 1
    _exact(full.frame, again.frame)
