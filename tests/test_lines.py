"""The one strict reader of JSON-lines stores (tslip._lines): a bad line is missing, with
one warning naming the file and the line; nothing in a line raises out of the reader."""

from __future__ import annotations

import json
import logging
import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tslip._lines import (
    BOOL,
    NUMBER,
    NUMBER_OR_NULL,
    SCALAR,
    STRING,
    ListOf,
    MapOf,
    Schema,
    read_lines,
)

SCHEMA = Schema({"code": STRING, "x": ListOf(NUMBER, 2),
                 "row": Schema({"k": NUMBER, "f": NUMBER_OR_NULL, "ok": BOOL}),
                 "rec": MapOf(SCALAR)})
GOOD = {"code": "c", "x": [1.0, 2], "row": {"k": 3.0, "f": None, "ok": True},
        "rec": {"a": "s", "b": 1, "c": None, "d": False}}


def _line(**change) -> bytes:
    return json.dumps({**GOOD, **change}).encode()


def _warnings(caplog) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]


# one of each fault; each alone is a bad line (the third of three)
BAD = {
    "deep": b"[" * 100_000 + b"]" * 100_000,
    "deep object": b'{"a":' * 100_000 + b"1" + b"}" * 100_000,
    "row a number": _line(row=5),
    "x of a string": _line(x=["a", 1.0]),
    "x too short": _line(x=[1.0]),
    "bool for a number": _line(x=[True, 1.0]),
    "NaN literal": _line()[:-1] + b', "n": NaN}',
    "unknown field": _line(extra=1),
    "missing field": json.dumps({k: v for k, v in GOOD.items() if k != "rec"}).encode(),
    "nested in a scalar map": _line(rec={"a": [1]}),
    "not utf-8": _line(code="cX").replace(b"cX", b"c\xff"),
    "not json": b"{not json",
    "a list": json.dumps(list(GOOD.values())).encode(),
    "huge int": b'{"code": "c", "x": [' + b"9" * 5000 + b', 1], "row": {}, "rec": {}}',
    "empty": b"",
}


@pytest.mark.parametrize("name", list(BAD))
def test_a_bad_line_is_missing_with_one_warning_naming_file_and_line(tmp_path, caplog, name):
    path = tmp_path / "s.jsonl"
    good2 = _line(code="d")
    path.write_bytes(_line() + b"\n" + good2 + b"\n" + BAD[name] + b"\n")
    with caplog.at_level("WARNING", logger="tslip"):
        recs = read_lines(tmp_path, path, SCHEMA)
    assert [r["code"] for r in recs] == ["c", "d"]
    msgs = _warnings(caplog)
    assert len(msgs) == 1 and str(path) in msgs[0] and "line 3:" in msgs[0], msgs
    assert len(msgs[0]) < 400  # one line, not the line's text


def test_a_torn_last_line_warns_and_is_cut_off_only_with_repair(tmp_path, caplog):
    path = tmp_path / "s.jsonl"
    data = _line() + b"\n" + _line(code="d")[:25]
    path.write_bytes(data)
    with caplog.at_level("WARNING", logger="tslip"):
        assert len(read_lines(tmp_path, path, SCHEMA)) == 1
    assert path.read_bytes() == data
    with caplog.at_level("WARNING", logger="tslip"):
        assert len(read_lines(tmp_path, path, SCHEMA, repair=True)) == 1
    assert path.read_bytes() == _line() + b"\n"
    msgs = _warnings(caplog)
    assert len(msgs) == 2 and all("line 2: torn" in m for m in msgs)


def test_good_lines_read_back_as_written_and_skip_is_silent(tmp_path, caplog):
    path = tmp_path / "s.jsonl"
    path.write_bytes(_line() + b"\n" + _line(code="old", row=5) + b"\n")
    with caplog.at_level("WARNING", logger="tslip"):
        recs = read_lines(tmp_path, path, SCHEMA, skip=lambda v: v.get("code") == "old")
    assert recs == [GOOD] and not _warnings(caplog)


def test_constants_only_where_asked(tmp_path):
    path = tmp_path / "s.jsonl"
    path.write_bytes(_line(rec={"v": math.nan}) + b"\n")  # json.dumps writes NaN
    assert read_lines(tmp_path, path, SCHEMA) == []
    assert math.isnan(read_lines(tmp_path, path, SCHEMA, constants=True)[0]["rec"]["v"])


def test_many_bad_lines_are_one_warning(tmp_path, caplog):
    path = tmp_path / "s.jsonl"
    path.write_bytes(b"x\n" * 50 + _line() + b"\n")
    with caplog.at_level("WARNING", logger="tslip"):
        assert len(read_lines(tmp_path, path, SCHEMA)) == 1
    (msg,) = _warnings(caplog)
    assert msg.startswith(f"ignoring 50 bad lines of {path}") and "and 45 more" in msg


def _matches(v) -> bool:
    """An independent check of SCHEMA, written out."""
    def num(x):
        return type(x) in (int, float) and math.isfinite(x)

    return (type(v) is dict and set(v) == {"code", "x", "row", "rec"}
            and type(v["code"]) is str
            and type(v["x"]) is list and len(v["x"]) == 2 and all(num(x) for x in v["x"])
            and type(v["row"]) is dict and set(v["row"]) == {"k", "f", "ok"}
            and num(v["row"]["k"]) and (v["row"]["f"] is None or num(v["row"]["f"]))
            and type(v["row"]["ok"]) is bool
            and type(v["rec"]) is dict
            and all(x is None or type(x) in (str, bool, int, float) for x in v["rec"].values()))


_json = st.recursive(st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=5),
                     lambda kids: st.lists(kids, max_size=3)
                     | st.dictionaries(st.sampled_from(["code", "x", "row", "rec", "k", "f", "ok",
                                                        "z"]), kids, max_size=5),
                     max_leaves=12)
_scalar = st.one_of(st.none(), st.booleans(), st.integers(), st.floats(), st.text(max_size=3))
_finite = st.integers() | st.floats(allow_nan=False, allow_infinity=False)
_good_x = st.lists(_finite, min_size=2, max_size=2)
_good_row = st.fixed_dictionaries({"k": _finite, "f": st.none() | _finite, "ok": st.booleans()})
_good = st.fixed_dictionaries({"code": st.text(max_size=3), "x": _good_x, "row": _good_row,
                               "rec": st.dictionaries(st.text(max_size=2), _scalar, max_size=3)})


def _mutate(rec, how, where, value):
    """One change of a good record: a field, an item of ``x``, a field of ``row`` or of
    ``rec`` set to ``value``, a field dropped or one added (or none)."""
    rec = json.loads(json.dumps(rec))
    if how == "field":
        rec[where] = value
    elif how == "x":
        rec["x"][len(where) % 2] = value
    elif how in ("row", "rec"):
        rec[how][where] = value
    elif how == "drop":
        rec.pop(where, None)
    elif how == "add":
        rec[where + "_"] = value
    return rec


# records near the schema: a good one, or one with a single change (often a wrong type)
_near = st.builds(_mutate, _good,
                  st.sampled_from(["none", "field", "x", "row", "rec", "drop", "add"]),
                  st.sampled_from(["code", "x", "row", "rec", "k", "f", "ok"]),
                  st.one_of(_scalar, st.lists(_scalar, max_size=2),
                            st.dictionaries(st.text(max_size=2), _scalar, max_size=2), _json))
_near_line = _near.map(lambda v: json.dumps(v).encode())
_lines = st.lists(st.one_of(_near_line, _near_line, _near_line, st.binary(max_size=40),
                            _json.map(lambda v: json.dumps(v).encode()),
                            _near_line.map(lambda b: b[:-3])),
                  min_size=1, max_size=12)


@settings(max_examples=300, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(lines=_lines, end=st.sampled_from([b"", b"\n"]))
def test_fuzzed_lines_never_raise_and_only_schema_records_come_back(tmp_path, lines, end):
    lines = [x.replace(b"\n", b" ") for x in lines]
    path = tmp_path / "fuzz.jsonl"
    path.write_bytes(b"\n".join(lines) + end)
    recs = read_lines(tmp_path, path, SCHEMA, repair=True)
    expected = []
    whole = lines if end else lines[:-1]
    for raw in whole:
        try:
            v = json.loads(raw.decode("utf-8"), parse_constant=lambda c: 1 / 0)
        except (ValueError, ZeroDivisionError, RecursionError):
            continue
        if _matches(v):
            expected.append(v)
    assert recs == expected
    assert path.read_bytes().endswith(b"\n") or path.read_bytes() == b""
