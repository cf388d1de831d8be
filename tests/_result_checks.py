"""The checks every result object passes (shared by the TSLIP's and the biped's tests)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pandas as pd
import pytest
from matplotlib.figure import Figure

import tslip
from _same import same
from tslip._results import Result


def check_frozen(obj: object) -> None:
    """A frozen dataclass deriving from Result."""
    assert isinstance(obj, Result) and dataclasses.is_dataclass(obj)
    f = dataclasses.fields(obj)[0].name
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(obj, f, None)


def check_round_trip(obj: Result, path: Path) -> None:
    """Saved to ``path`` and loaded back (by tslip.load and the class) bit for bit."""
    path = obj.save(path)
    same(obj, tslip.load(path))
    same(obj, type(obj).load(path))
    rec = json.loads(path.with_suffix(".json").read_text())
    run = rec["run"]
    assert run["tslip_version"] == tslip.__version__ and len(run["code_hash"]) == 24
    assert run["class"] == f"{type(obj).__module__}:{type(obj).__qualname__}"
    if hasattr(obj, "params"):
        assert run["params"] == obj.params.to_dict()  # type: ignore[attr-defined]
    if path.suffix != ".json":  # the table beside the record is to_dataframe()
        df = pd.read_parquet(path) if path.suffix == ".parquet" else pd.read_csv(path)
        want = obj.to_dataframe()
        assert list(df.columns) == list(want.columns) and len(df) == len(want)
        assert rec["table"]["units"] == want.attrs["units"]


def check_units(obj: Result) -> None:
    """to_dataframe() names a unit for each of its (unique) columns."""
    df = obj.to_dataframe()
    units = df.attrs["units"]
    assert list(units) == [str(c) for c in df.columns]
    assert all(isinstance(u, str) and u for u in units.values())
    assert len(df.columns) > 0 and df.columns.is_unique


def check_repr(obj: object) -> None:
    """One line, at most 200 characters, starting with the class name."""
    text = repr(obj)
    assert "\n" not in text and len(text) <= 200
    assert text.startswith(type(obj).__name__ + "(")


def check_plot(obj: Result) -> None:
    """.plot(ax) draws on ax and returns its figure; .plot() makes a new one."""
    fig = Figure()
    ax = fig.add_subplot()
    assert obj.plot(ax=ax) is fig  # type: ignore[attr-defined]
    assert ax.lines or ax.patches or ax.collections  # something was drawn there
    assert len(fig.axes) <= 2  # on ax (a twin axis at most), not on new axes
    own = obj.plot()  # type: ignore[attr-defined]
    assert isinstance(own, Figure) and own is not fig and own.axes
