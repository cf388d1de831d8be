"""Appendix E's cache in a report folder is data only.

It reads back bit for bit; a crafted file (a pickle that would create a
marker file when loaded, under the old and the new name) or a damaged one is
neither run nor fatal: it is recomputed, with one warning line.
"""

from __future__ import annotations

import copy
import json
import logging
import pickle
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from _same import same
from tslip.sweeps import appendix_e, reproduce

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")

SETTINGS = reproduce.APPENDIX_E_SETTINGS["tiny"]


@pytest.fixture(scope="module")
def tiny() -> dict[str, Any]:
    """Appendix E's data at the tiny resolution, computed here (seconds)."""
    return appendix_e.fig_appendix_e(**SETTINGS)


class _Opens:
    """Unpickling this calls ``open(marker, "w")``, which creates the marker file."""

    def __init__(self, marker: Path) -> None:
        self.marker = marker

    def __reduce__(self) -> tuple[Any, ...]:
        return (open, (str(self.marker), "w"))


def _crafted(marker: Path) -> bytes:
    """A pickle that creates ``marker`` when loaded (checked here, in a scratch folder)."""
    blob = pickle.dumps(_Opens(marker))
    probe = marker.with_name("probe")
    pickle.loads(pickle.dumps(_Opens(probe))).close()
    assert probe.is_file()  # the crafted file is live: loading it would run code
    probe.unlink()
    return blob


def _plant(folder: Path, marker: Path) -> tuple[Path, Path]:
    """The crafted pickle under Appendix E's old (.pkl) and new (.json) cache names."""
    old = folder / "figures" / "appendix_e-tiny.pkl"
    new, _ = reproduce._appendix_e_entry(folder, "tiny")
    old.parent.mkdir(parents=True)
    for p in (old, new):
        p.write_bytes(_crafted(marker))
    return old, new


def _fake(monkeypatch: pytest.MonkeyPatch, data: dict[str, Any]) -> list[dict[str, Any]]:
    """Make ``fig_appendix_e`` return ``data``, recording its calls."""
    calls: list[dict[str, Any]] = []

    def fake(**settings: Any) -> dict[str, Any]:
        calls.append(settings)
        return data

    monkeypatch.setattr(appendix_e, "fig_appendix_e", fake)
    return calls


def _warnings(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]


def test_the_data_reads_back_bit_for_bit(tiny, tmp_path) -> None:
    path, key = reproduce._appendix_e_entry(tmp_path, "tiny")
    assert path.name == "appendix_e-tiny.json"
    reproduce._appendix_e_store(path, key, tiny)
    record = json.loads(path.read_text(encoding="utf-8"))  # plain JSON text
    assert record["key"] == key
    same(tiny, reproduce._appendix_e_load(path, key), "E")


def test_a_rerun_recomputes_over_a_crafted_pickle(tiny, tmp_path, monkeypatch,
                                                  caplog) -> None:
    marker = tmp_path / "marker"
    old, new = _plant(tmp_path / "report", marker)
    calls = _fake(monkeypatch, tiny)
    same(tiny, reproduce.appendix_e_cached(tmp_path / "report", "tiny"), "E")
    assert not marker.exists()
    assert calls == [SETTINGS]
    warned = _warnings(caplog)
    assert len(warned) == 1 and str(new) in warned[0] and "\n" not in warned[0]
    assert old.read_bytes() == _crafted(marker)  # the old name is never written (nor read)
    caplog.clear()
    same(tiny, reproduce.appendix_e_cached(tmp_path / "report", "tiny"), "E")
    assert len(calls) == 1 and not _warnings(caplog)  # the recomputed copy is reused


def _edit(record: dict[str, Any], how: str) -> Any:
    """A damaged copy of a valid cache record."""
    r = copy.deepcopy(record)
    e2, conv = r["data"]["e2"], r["data"]["converged"]
    if how == "wrong type":
        e2["strides"] = "3"
    elif how == "bool for an int":
        conv["strides"] = True
    elif how == "int for a float":
        conv["largest"] = 1
    elif how == "missing field":
        del conv["metacentric"]
    elif how == "extra field":
        e2["code"] = "print()"
    elif how == "missing section":
        del r["data"]["converged"]
    elif how == "foreign class":
        e2["tracking"]["__type__"] = "tslip.model.parameters:Params"
    elif how == "not a class":
        e2["tracking"]["__type__"] = "tslip._io:os.system"
    elif how == "object array":
        e2["run"]["fields"]["final_state"] = {"__ndarray__": "|O", "shape": [1],
                                              "data": [1.0]}
    elif how == "bad array":
        e2["run"]["fields"]["data"]["shape"] = [7, 7]
    elif how == "a path":
        e2["reason"] = {"__path__": "/etc/passwd"}
    elif how == "other format":
        r["format"]["version"] = 2
    elif how == "extra key":
        r["code"] = "x"
    else:
        raise AssertionError(how)
    return r


@pytest.mark.parametrize("how", [
    "wrong type", "bool for an int", "int for a float", "missing field", "extra field",
    "missing section", "foreign class", "not a class", "object array", "bad array", "a path",
    "other format", "extra key", "truncated", "not text", "a list", "deep", "a folder"])
def test_a_damaged_file_is_recomputed(how, tiny, tmp_path, monkeypatch, caplog) -> None:
    path, key = reproduce._appendix_e_entry(tmp_path, "tiny")
    reproduce._appendix_e_store(path, key, tiny)
    text = path.read_text(encoding="utf-8")
    if how == "truncated":
        path.write_text(text[: len(text) // 2], encoding="utf-8")
    elif how == "not text":
        path.write_bytes(b"\x80\xff" + text.encode()[:100])
    elif how == "a list":
        path.write_text("[]", encoding="utf-8")
    elif how == "deep":
        path.write_text("[" * 100_000 + "]" * 100_000, encoding="utf-8")
    elif how == "a folder":
        path.unlink()
        path.mkdir()
    else:
        path.write_text(json.dumps(_edit(json.loads(text), how)), encoding="utf-8")
    calls = _fake(monkeypatch, tiny)
    if how == "a folder":  # read: refused; then written over: an OSError, as before
        assert reproduce._appendix_e_load(path, key) is None
    else:
        same(tiny, reproduce.appendix_e_cached(tmp_path, "tiny"), "E")
        assert calls == [SETTINGS]
        same(tiny, reproduce._appendix_e_load(path, key), "E")  # rewritten, valid
    warned = _warnings(caplog)
    assert len(warned) == 1 and str(path) in warned[0] and "\n" not in warned[0], warned


def test_a_stale_file_is_recomputed_quietly(tiny, tmp_path, monkeypatch, caplog) -> None:
    path, key = reproduce._appendix_e_entry(tmp_path, "tiny")
    reproduce._appendix_e_store(path, key + "-other-code", tiny)
    calls = _fake(monkeypatch, tiny)
    reproduce.appendix_e_cached(tmp_path, "tiny")
    assert calls == [SETTINGS] and not _warnings(caplog)


def test_the_cache_is_reused_until_the_code_changes(tiny, tmp_path, monkeypatch) -> None:
    calls: list[dict[str, Any]] = []

    def fake(**settings: Any) -> dict[str, Any]:
        calls.append(settings)
        return {**tiny, "e2": {**tiny["e2"], "strides": len(calls)}}

    monkeypatch.setattr(appendix_e, "fig_appendix_e", fake)
    first = reproduce.appendix_e_cached(tmp_path, "tiny")
    assert calls == [reproduce.APPENDIX_E_SETTINGS["tiny"]]
    assert (tmp_path / "figures" / "appendix_e-tiny.json").is_file()
    same(first, reproduce.appendix_e_cached(tmp_path, "tiny"))  # reused
    assert len(calls) == 1
    # another resolution is another entry
    reproduce.appendix_e_cached(tmp_path, "quick")
    assert len(calls) == 2
    # an edit to the biped code changes the hash: recomputed
    monkeypatch.setattr(reproduce, "code_hash", lambda *modules: "edited")
    again = reproduce.appendix_e_cached(tmp_path, "tiny")
    assert len(calls) == 3 and again["e2"]["strides"] == 3
    assert reproduce.appendix_e_cached(tmp_path, "tiny")["e2"]["strides"] == 3
    assert len(calls) == 3


def test_the_parallel_reproduction_ignores_a_crafted_pickle(tiny, tmp_path) -> None:
    """``run_all``'s figures (:class:`_Figures`) schedule Appendix E over a crafted file."""
    marker = tmp_path / "marker"
    _, new = _plant(tmp_path / "report", marker)
    figs = reproduce._Figures("tiny", tmp_path / "report", None, lambda: None, {})
    assert not marker.exists()
    assert "E" not in figs.data and set(figs.e_pieces) == set(appendix_e.pieces(**SETTINGS))
    _, key = reproduce._appendix_e_entry(tmp_path, "tiny")
    reproduce._appendix_e_store(new, key, tiny)
    figs = reproduce._Figures("tiny", tmp_path / "report", None, lambda: None, {})
    assert figs.e_pieces == {}
    same(tiny, figs.data["E"], "E")


def test_a_rerun_in_a_new_process_recomputes_and_reads_back_exactly(tiny, tmp_path) -> None:
    """End to end: the crafted pickle planted, Appendix E computed for real in a new process."""
    marker = tmp_path / "marker"
    report = tmp_path / "report"
    _, new = _plant(report, marker)
    code = ("import sys; from tslip.sweeps.reproduce import appendix_e_cached; "
            "appendix_e_cached(sys.argv[1], 'tiny')")
    out = subprocess.run([sys.executable, "-W", "ignore::RuntimeWarning", "-c", code,
                          str(report)], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    assert not marker.exists()
    lines = [line for line in out.stderr.splitlines() if "appendix_e" in line]
    assert len(lines) == 1 and lines[0].startswith(f"ignoring {new} ("), out.stderr
    assert "Traceback" not in out.stderr
    _, key = reproduce._appendix_e_entry(report, "tiny")
    same(tiny, reproduce._appendix_e_load(new, key), "E")  # recomputed here == read back
