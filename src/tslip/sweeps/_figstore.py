"""Computed figure data kept in a report folder, keyed by the code that computes it.

``tslip reproduce`` keeps each single-gait figure's data, Table 6.1's and
Appendix E's in ``out_dir/figures/`` (the studies are kept in
``out_dir/studies/``), so a rerun into the same folder computes only what
changed. Each file is one JSON record ``{"format", "key", "data"}``:

* ``key`` is the hash of the code that computes the data
  (:func:`tslip._codehash.code_hash`: the modules' sources, everything they
  import from ``tslip``, the numerical libraries' versions) and its settings,
  so a change to that code makes the file stale (silently: it is recomputed);
* ``data`` is decoded as data only (:func:`tslip._results.decode`: nothing in
  the file can run) and checked against the shape the code would compute
  (``read``, e.g. :func:`tslip._conform.check` of the figure's annotation)
  before it is used. A damaged, foreign or edited file is recomputed, with
  one warning line;
* written atomically (:func:`tslip._io.atomic_write`: a temporary file renamed
  over the name, never written through a link there).
"""

from __future__ import annotations

import functools
import json
import logging
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypedDict

from .._codehash import code_hash
from .._conform import check
from .._io import atomic_write
from .._results import decode, encode
from ..gait.energy import HeightChangeResult, StepDownResponse, VelocityAngleCase
from ..gait.impulse import ImpulseLinearisation, PitchResponse
from ..gait.stride import FrictionCheck
from .catalogue import MassOffsetBoundary

__all__ = ["FIGURE_TYPES", "AlphadRefForced", "HeightChange", "Table61", "figure_load",
           "figure_store", "kept", "load", "store"]

#: Why a stored record is refused (and recomputed): whatever reading, decoding or
#: checking it can raise.
_BAD = (OSError, ValueError, TypeError, KeyError, IndexError, AttributeError, OverflowError,
        RecursionError)


def load(path: Path, key: str, fmt: dict[str, Any], read: Callable[[Any], Any],
         what: str) -> Any:
    """The data stored at ``path`` under ``key``, or None (missing or stale: recompute).

    ``read`` turns the record's JSON ``data`` into the data, raising ``ValueError``
    for anything else. A file that is not a record of format ``fmt``, or whose data
    ``read`` refuses, logs one warning naming ``what`` and returns None.
    """
    if not path.exists():
        return None
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
        if not (isinstance(record, dict) and set(record) == {"format", "key", "data"}
                and record["format"] == fmt):
            raise ValueError(f"not a {fmt.get('name')} record of this format")
        return read(record["data"]) if record["key"] == key else None
    except _BAD as exc:
        why = " ".join(str(exc).split()) or type(exc).__name__
        logging.getLogger("tslip").warning("ignoring %s (%s); recomputing %s", path, why[:200],
                                           what)
        return None


def store(path: Path, key: str, fmt: dict[str, Any], tree: Any) -> None:
    """Keep the JSON values ``tree`` at ``path`` under ``key`` (atomically)."""
    text = json.dumps({"format": fmt, "key": key, "data": tree}, allow_nan=False)
    atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


class HeightChange(TypedDict):
    """Figure 4.4's data (:func:`tslip.sweeps.reproduce.height_change`)."""

    dh: tuple[float, ...]
    passive: list[HeightChangeResult]
    local_velocity: list[HeightChangeResult]
    step_down_limit: dict[str, float]


class AlphadRefForced(TypedDict):
    """:func:`tslip.sweeps.reproduce.alphad_ref_forced`'s result."""

    alphad_ref: float
    residual: float
    c1: float
    free: float
    stride: dict[str, float]


class Table61(TypedDict):
    """Table 6.1's data (:func:`tslip.sweeps.reproduce.table61`)."""

    max_nontrivial: float
    stability: str
    step_down: float
    push: float
    pitch_rate: float
    stance_time: float
    flight_time: float
    duty_factor: float
    step_frequency: float
    alphad_ref: float
    alpha_r: float
    pitch_rate_variants: dict[str, float]
    alphad_ref_forced: AlphadRefForced


#: What each single-gait figure's data and Table 6.1's is: a copy kept in a report folder
#: must be exactly that (:func:`tslip._conform.check`) to be used.
FIGURE_TYPES: dict[str, Any] = {
    "4.1": ImpulseLinearisation, "4.2": PitchResponse, "4.3": PitchResponse,
    "6.2": PitchResponse, "4.4": HeightChange, "4.5": StepDownResponse,
    "4.7": tuple[VelocityAngleCase, ...], "C.1": dict[str, FrictionCheck],
    "4.16": MassOffsetBoundary, "table6.1": Table61,
}
#: The format of a kept figure's file (:mod:`._figstore`), stored in it.
FIGURE_FORMAT = {"name": "tslip-figure", "version": 1}
#: The modules whose code computes the figures: their code hash (with everything they
#: import from tslip) keys the kept copies, so a change to that code recomputes them.
FIGURE_MODULES: tuple[str, ...] = ("tslip.sweeps.reproduce",)


def _figure_entry(out_dir: str | Path, res: str, key: str) -> tuple[Path, str]:
    """Figure ``key``'s file in report folder ``out_dir`` and the key its content must carry."""
    return (Path(out_dir) / "figures" / f"data-{key}-{res}.json",
            f"{code_hash(*FIGURE_MODULES)}:{res}")


def _figure_read(key: str, tree: Any) -> Any:
    data = decode(tree)
    check(data, FIGURE_TYPES[key], f"figure {key}")
    return data


def figure_load(out_dir: str | Path, res: str, key: str) -> Any:
    """Figure ``key``'s data kept in ``out_dir`` at resolution ``res``, or None (compute it)."""
    path, ckey = _figure_entry(out_dir, res, key)
    return load(path, ckey, FIGURE_FORMAT, functools.partial(_figure_read, key),
                f"figure {key}")


def figure_store(out_dir: str | Path, res: str, key: str, data: Any) -> None:
    """Keep figure ``key``'s data in ``out_dir`` (:func:`figure_load` reads it back)."""
    path, ckey = _figure_entry(out_dir, res, key)
    store(path, ckey, FIGURE_FORMAT, encode(data, f"figure {key}"))


def kept(out_dir: str | Path | None, res: str, key: str, compute: Callable[[], Any]) -> Any:
    """Figure ``key`` from ``out_dir`` if kept there, else computed (and kept)."""
    if out_dir is None:
        return compute()
    data = figure_load(out_dir, res, key)
    if data is None:
        data = compute()
        figure_store(out_dir, res, key, data)
    return data
