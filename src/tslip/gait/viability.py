"""Viability and basins of attraction on the apex section (as the *vibly* package).

Three results, all numpy arrays on a grid with its coordinates:

* :func:`state_action_map` -> :class:`StateActionMap`
  (:mod:`tslip.gait.statemap`): for every grid state at the apex (apex
  height ``y``; for the TSLIP up to three section variables,
  ``(y, phi, phid)``) and every grid action (a parameter, e.g. the touch-down
  angle ``alpha_r``), the next apex state after one stride at fixed total
  energy, or the reason it failed. All cells run in one call of the batched
  compiled kernels (:func:`tslip.simulation.step_batch`). A run's map on disk
  is a :class:`StoredMap` (:mod:`tslip.gait.mapstore`).
* :func:`viability` -> :class:`Viability` (this module): the viable
  state-action pairs and states, by the iteration of vibly's ``compute_QV``
  on a compact successor encoding held in chunks (:mod:`tslip.gait._viable`,
  which also states the cell rules: tslip's conservative ``"bracket"`` (the
  default), ``"nearest"``, and vibly's own ``"vibly"``); for a 3-D map its
  volume fraction, slices and projections (:class:`ViableSection`).
* :func:`basin` -> :class:`Basin` (:mod:`tslip.gait.basins`): from every grid
  start state at the apex, the strides until the runs reach a gait, or fall
  (:func:`tslip.simulation.run_batch`).

Every name of the three modules is importable from here, as before they were
split (after 0.3.0). A map of any discrete system can be built from arrays
(:meth:`StateActionMap.from_arrays`); :func:`viability` works on it the
same way. Each result is a :class:`tslip._results.Result`:
``to_dataframe()`` has one row per cell, grid coordinates first, units in
``df.attrs["units"]``; ``save``/``load`` (and ``tslip.load``) to
``.parquet`` (the table, with the grid and parameters in the ``.json``
record beside it), ``.csv`` or ``.json`` round-trip bit for bit.
"""

from __future__ import annotations

import dataclasses
import math
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._results import Result, with_units
from ..simulation.result import Status
from . import _viable
from .basins import Basin, basin
from .mapstore import StoredMap, read_chunk
from .statemap import (
    SECTION_UNITS,
    STATE_NAMES,
    StateActionMap,
    _short,
    _unit,
    check_map_inputs,
    grid_columns,
    map_cells,
    state_action_map,
)

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes

__all__ = ["StateActionMap", "StoredMap", "Viability", "ViableSection", "Basin",
           "state_action_map", "viability", "basin", "STATE_NAMES", "SECTION_UNITS",
           "check_map_inputs", "map_cells", "read_chunk"]


@dataclass(frozen=True, eq=False, repr=False)
class Viability(Result):
    """The viable part of a state-action map.

    Attributes
    ----------
    map : StateActionMap or StoredMap
        The map; a :class:`StoredMap` (read from disk on demand) for a run
        with an output folder (:func:`tslip.sweeps.viability.run_viability`).
    rule : {"bracket", "nearest", "vibly"}
        The cell rule (:mod:`tslip.gait._viable`).
    q : ndarray of bool, shape map.shape
        Viable state-action pairs: the stride does not fail and leads to a
        state from which some action is again viable, for ever.
    s : ndarray of bool, shape (grid shape...)
        Viable states: some action is viable.
    sweeps : int
        Sweeps of the iteration that removed pairs.
    """

    map: StateActionMap | StoredMap
    rule: str
    q: np.ndarray
    s: np.ndarray
    sweeps: int

    def __repr__(self) -> str:
        m = self.map
        return (f"Viability({_short(m.grid, m.names)} x "
                f"{_short(m.action_grids, m.action_names)}, {self.rule}: "
                f"{int(self.q.sum())} of {self.q.size} pairs and "
                f"{int(self.s.sum())} of {self.s.size} states viable, "
                f"{self.sweeps} sweep{'' if self.sweeps == 1 else 's'})")

    @property
    def viable_fraction(self) -> float:
        """Share of the state-action grid that is viable."""
        return float(self.q.mean())

    @property
    def volume_fraction(self) -> float:
        """Share of the state grid that is viable: the viable set's volume on the grid."""
        return float(self.s.mean())

    def slice(self, name: str) -> ViableSection:
        """The viable states at the grid value of ``name`` nearest 0 (a 3-D map's section).

        The grid of ``name`` must reach 0 (its first value <= 0 <= its last).
        """
        j = self._third(name)
        g = self.map.grid[j]
        if not g[0] <= 0.0 <= g[-1]:
            raise ValueError(f"states[{name!r}] must contain 0 (first <= 0 <= last) to slice "
                             f"at 0, got [{g[0]:g}, {g[-1]:g}]")
        i = int(np.argmin(np.abs(g)))
        return self._section(j, "slice", float(g[i]), np.take(self.s, i, axis=j))

    def projection(self, name: str) -> ViableSection:
        """The states viable for some grid value of ``name`` (a 3-D map's shadow)."""
        j = self._third(name)
        return self._section(j, "projection", math.nan, np.asarray(self.s.any(axis=j)))

    def _third(self, name: str) -> int:
        names = self.map.names
        if len(names) != 3 or name == "y" or name not in names:
            raise ValueError(f"name must be one of {[n for n in names if n != 'y']} of a "
                             f"map over three state variables, got {name!r} of {list(names)}")
        return names.index(name)

    def _section(self, j: int, kind: str, at: float, s: np.ndarray) -> ViableSection:
        m = self.map
        keep = [k for k in range(3) if k != j]
        return ViableSection(tuple(m.names[k] for k in keep), tuple(m.grid[k] for k in keep),
                             s, kind, m.names[j], at, self.rule, m.energy)

    def to_dataframe(self) -> pd.DataFrame:
        """The map's table plus ``viable`` (the pair) and ``state_viable``."""
        df = self.map.to_dataframe()
        df["viable"] = self.q.ravel()
        df["state_viable"] = np.repeat(self.s.ravel(), self.map.n_actions)
        return with_units(df, dict(df.attrs["units"], viable="-", state_viable="-"))

    def save(self, path: str | Path) -> Path:
        """As :meth:`tslip._results.Result.save`; the ``.parquet`` table of a
        :class:`StoredMap` is written a block of chunks at a time (row groups), never
        the whole table in memory."""
        path = Path(path)
        if not isinstance(self.map, StoredMap) or path.suffix.lower() != ".parquet":
            return super().save(path)
        return _save_stored(self, self.map, path)

    def _fields(self) -> dict[str, Any]:
        """The map's fields (flat, so a table holds its arrays once) and the kernel's."""
        return dict(self.map._fields(), rule=self.rule, q=self.q, s=self.s,
                    sweeps=self.sweeps)

    @classmethod
    def _from_fields(cls, fields: dict[str, Any]) -> Viability:
        f = dict(fields)
        own = {k: f.pop(k) for k in ("rule", "q", "s", "sweeps")}
        return cls(StateActionMap(**f), **own)

    def _table_fields(self) -> tuple[str, ...]:
        return ("next", "status", "q", "s")

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        out = StateActionMap._from_table(df, fields)
        shape = out["status"].shape
        q = df["viable"].to_numpy(bool).reshape(shape)
        states = shape[:len(fields["names"])]
        s = df["state_viable"].to_numpy(bool).reshape(states + (-1,))[..., 0]
        return dict(out, q=q, s=s)

    def plot(self, ax: Axes | None = None) -> Any:
        """The viable set (:func:`tslip.plotting.viability.plot_viability`)."""
        from ..plotting.viability import plot_viability

        return plot_viability(self, ax=ax)


def _save_stored(res: Viability, m: StoredMap, path: Path) -> Path:
    """:meth:`Viability.save` to ``.parquet`` of a stored map: the same record and table
    as :meth:`tslip._results.Result.save`, the table written in row groups of about
    :data:`tslip.gait._viable.CHUNK_ROWS` rows, each from consecutive chunks."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from .. import _results as rs
    from .._io import atomic_write

    n_a = m.n_actions
    q, s = res.q.reshape(-1, n_a), res.s.ravel()
    table = sorted(res._table_fields())
    rest = {f.name: getattr(m, f.name) for f in dataclasses.fields(StateActionMap)
            if f.init and f.name not in table}
    rest.update(rule=res.rule, sweeps=res.sweeps)
    head: dict[str, Any] = {}

    def frame(start: int, parts: list[tuple[np.ndarray, np.ndarray]]) -> pd.DataFrame:
        nxt, st = (np.concatenate([p[i] for p in parts]) for i in (0, 1))
        df = m._frame(start, nxt, st)
        df["viable"] = q[start:start + len(st)].ravel()
        df["state_viable"] = np.repeat(s[start:start + len(st)], n_a)
        return df

    def write(tmp: str) -> None:
        writer, start, parts, rows = None, 0, [], 0
        for k, part in enumerate(m.chunks()):
            parts.append(part)
            rows += part[1].size
            if rows < _viable.CHUNK_ROWS and k + 1 < len(m.files):
                continue
            df = frame(start, parts)
            if writer is None:
                head["dtypes"] = {str(c): str(t) for c, t in df.dtypes.items()}
                head["units"] = dict(df.attrs["units"], viable="-", state_viable="-")
            df.attrs = {}
            t = pa.Table.from_pandas(df, preserve_index=False)
            writer = writer or pq.ParquetWriter(tmp, t.schema)
            writer.write_table(t)
            start += sum(len(p[1]) for p in parts)
            parts, rows = [], 0
        if writer is not None:
            writer.close()

    atomic_write(path, write)
    record: dict[str, Any] = {**rs.encode(res._summary(), "summary"), "format": rs.FORMAT,
                              "run": rs.run_record(res)}
    record["table"] = {"file": path.name, "fields": table, "units": head["units"],
                       "dtypes": head["dtypes"]}
    record["result"] = {"__type__": rs._name(Viability), "fields": rs._encode_fields(rest)}
    rs._write_text(path.with_suffix(".json"), record)
    return path


@dataclass(frozen=True, eq=False, repr=False)
class ViableSection(Result):
    """Viable states of a 3-D viability result over two of its variables.

    Attributes
    ----------
    names, grid : as :class:`StateActionMap`, the two variables kept
    s : ndarray of bool, shape (grid shape...)
        Viable states.
    kind : {"slice", "projection"}
        ``"slice"``: at the grid value ``at`` of ``over`` (the one nearest 0);
        ``"projection"``: viable for some grid value of ``over`` (``at`` NaN).
    over : str
        The variable left out.
    at : float
    rule : str
    energy : float
    """

    names: tuple[str, ...]
    grid: tuple[np.ndarray, ...]
    s: np.ndarray
    kind: str
    over: str
    at: float
    rule: str
    energy: float

    @property
    def label(self) -> str:
        """Which section it is, e.g. ``"slice at phi = 0"`` or ``"projection over phid"``."""
        if self.kind == "slice":
            return f"slice at {self.over} = {self.at:.4g}"
        return f"projection over {self.over} (viable for some {self.over})"

    @property
    def fraction(self) -> float:
        """Share of the section's grid that is viable."""
        return float(self.s.mean())

    def __repr__(self) -> str:
        return (f"ViableSection({_short(self.grid, self.names)}, {self.label}: "
                f"{int(self.s.sum())} of {self.s.size} viable)")

    def to_dataframe(self) -> pd.DataFrame:
        """One row per state of the section: its coordinates and ``viable``."""
        import pandas as pd

        data: dict[str, Any] = dict(zip(self.names, grid_columns(self.grid)))
        data["viable"] = self.s.ravel()
        return with_units(pd.DataFrame(data), {**{n: _unit(n) for n in self.names},
                                               "viable": "-"})

    def _table_fields(self) -> tuple[str, ...]:
        return ("s",)

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        shape = tuple(len(g) for g in fields["grid"])
        return dict(fields, s=df["viable"].to_numpy(bool).reshape(shape))

    def plot(self, ax: Axes | None = None) -> Any:
        """The section (:func:`tslip.plotting.viability.plot_section`)."""
        from ..plotting.viability import plot_section

        return plot_section(self, ax=ax)


def viability(smap: StateActionMap | StoredMap, rule: str = "bracket") -> Viability:
    """The viability kernel of a state-action map, by the iteration of vibly's ``compute_QV``.

    Starting from every pair whose stride does not fail, each sweep keeps a
    pair only if its successor lands in a viable state by ``rule``, and a
    state is viable while some action from it is, until nothing changes
    (:func:`tslip.gait._viable.viable_sets_chunked`, on the compact int32
    successor cells of :func:`tslip.gait._viable.encode_chunks`).

    Cell rule (``rule``), for a successor between grid points:

    * ``"bracket"`` (default, tslip's, conservative): viable only if every
      grid point of the cell around it (2 in 1-D, 4 in 2-D, 8 in 3-D) is a viable
      state; on a grid point (within 1e-9 of a spacing), only that point;
      outside the grid's range, never.
    * ``"nearest"``: viable if the nearest grid point is; outside the grid's
      range, never.
    * ``"vibly"`` (vibly's rule): per axis ``b = np.digitize(s', grid)``;
      viable if every grid point of the product of ``{b-1, b}`` that lies
      inside the grid is a viable state. On a grid point it needs that point
      and the next one up; above the top, the top point; below the bottom,
      the bottom point. Unlike vibly, which stores a failure as bin 0, a
      successor below the bottom on every axis is not taken for a failure.

    Under every rule a failed stride (a fall, a flight with no apex, an
    integration error) is not viable.

    Parameters
    ----------
    smap : StateActionMap or StoredMap
        A stored map is swept chunk by chunk from disk (its int32 cells through
        a memory-mapped file beside the store): memory is ``q``, one byte a pair.
    rule : {"bracket", "nearest", "vibly"}

    Returns
    -------
    Viability
    """
    if rule not in _viable.RULES:
        raise ValueError(f"rule must be one of {list(_viable.RULES)}, got {rule!r}")
    n_states = int(np.prod([len(g) for g in smap.grid]))
    states = smap.shape[:len(smap.names)]
    if isinstance(smap, StoredMap):
        q, s, sweeps = _stored_sets(smap, rule, n_states)
    else:
        d = len(smap.names)
        ok = ~smap.failed.ravel()
        chunks = _viable.encode_chunks(smap.grid, smap.next.reshape(-1, d), ok, rule)
        q, s, sweeps = _viable.viable_sets_chunked(chunks, n_states, smap.n_actions)
    return Viability(smap, rule, q.reshape(smap.shape), s.reshape(states), sweeps)


def _stored_sets(smap: StoredMap, rule: str, n_states: int) -> tuple[np.ndarray, np.ndarray, int]:
    """The iteration on a stored map: each chunk's int32 cells
    (:func:`tslip.gait._viable.encode_chunks`) written to one ``.npy`` file beside the
    store and swept through a memory map of it, so the process holds ``q`` and one
    block's temporaries, never the map (its floats or its cells)."""
    d, n = len(smap.names), n_states * smap.n_actions
    with tempfile.TemporaryDirectory(dir=smap.folder.parent, prefix=".cells-") as tmp:
        cells = None
        row = 0
        for nxt, status in smap.chunks():
            for c in _viable.encode_chunks(smap.grid, nxt.reshape(-1, d),
                                           status.ravel() == Status.OK, rule):
                if cells is None:
                    cells = np.lib.format.open_memmap(Path(tmp) / "cells.npy", mode="w+",
                                                      dtype=np.int32, shape=(n, c.shape[1]))
                cells[row:row + len(c)] = c
                row += len(c)
        if cells is None:
            raise ValueError("the stored map has no cells")
        cells.flush()
        rows = _viable.CHUNK_ROWS
        try:
            return _viable.viable_sets_chunked([cells[i:i + rows] for i in range(0, n, rows)],
                                               n_states, smap.n_actions)
        finally:
            del cells  # the memory map closes before its folder goes
