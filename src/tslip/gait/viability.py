"""Viability and basins of attraction on the apex section (as the *vibly* package).

Three results, all numpy arrays on a grid with its coordinates:

* :func:`state_action_map` -> :class:`StateActionMap`: for every grid state
  at the apex (apex height ``y``; for the TSLIP up to three section
  variables, ``(y, phi, phid)``) and every grid action (a parameter, e.g. the touch-down
  angle ``alpha_r``), the next apex state after one stride at fixed total
  energy, or the reason it failed. All cells run in one call of the
  batched compiled kernels (:func:`tslip.simulation.step_batch`).
* :func:`viability` -> :class:`Viability`: the viable state-action pairs
  and states, by the iteration of vibly's ``compute_QV`` on a compact
  successor encoding held in chunks (:mod:`tslip.gait._viable`, which also
  states the cell rules: tslip's conservative ``"bracket"`` (the default),
  ``"nearest"``, and vibly's own ``"vibly"``); for a 3-D map its volume
  fraction, slices and projections (:class:`ViableSection`).
* :func:`basin` -> :class:`Basin`: from every grid start state at the
  apex, the strides until the runs reach a gait, or fall
  (:func:`tslip.simulation.run_batch`).

A map of any discrete system can be built from arrays
(:meth:`StateActionMap.from_arrays`); :func:`viability` works on it the
same way. Each result is a :class:`tslip._results.Result`:
``to_dataframe()`` has one row per cell, grid coordinates first, units in
``df.attrs["units"]``; ``save``/``load`` (and ``tslip.load``) to
``.parquet`` (the table, with the grid and parameters in the ``.json``
record beside it), ``.csv`` or ``.json`` round-trip bit for bit.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import math
import tempfile
import time
import zipfile
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import check_number
from .._results import Result, with_units
from ..model import _pack as pk
from ..model.parameters import Params
from ..model.units import COLUMN_UNITS, param_unit
from ..simulation.integrate import run_batch
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status
from . import _viable, section
from .continuation import set_param
from .stability import pitch_decoupled

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes

    from .fixed_point import Gait

__all__ = ["StateActionMap", "StoredMap", "Viability", "ViableSection", "Basin",
           "state_action_map", "viability", "basin", "STATE_NAMES", "SECTION_UNITS",
           "check_map_inputs", "map_cells", "read_chunk"]

#: Apex variables a grid can span (the forward speed follows from the energy).
STATE_NAMES = ("y", "phi", "phid")

#: Units of the apex-section variables a grid can span.
SECTION_UNITS = {n: COLUMN_UNITS[n] for n in ("y", "xd", "phi", "phid")}


def _unit(name: str) -> str:
    return SECTION_UNITS.get(name) or param_unit(name) or "-"


def _short(axes: Sequence[np.ndarray], names: Sequence[str]) -> str:
    return " x ".join(f"{n} {len(g)} [{g[0]:.4g}, {g[-1]:.4g}]" for n, g in zip(names, axes))


def grid_columns(axes: Sequence[np.ndarray]) -> list[np.ndarray]:
    """The coordinates of every cell of a grid, one column per axis (C order)."""
    return [m.ravel() for m in np.meshgrid(*axes, indexing="ij")]


# ---------------------------------------------------------------------------
# the state-action map
# ---------------------------------------------------------------------------


class _MapGrid:
    """The grid part of a state-action map, in memory or stored (names, grid, actions)."""

    __slots__ = ()
    names: tuple[str, ...]
    grid: tuple[np.ndarray, ...]
    action: str | tuple[str, ...]
    actions: np.ndarray | tuple[np.ndarray, ...]
    energy: float

    @property
    def action_names(self) -> tuple[str, ...]:
        """The action names, one or two, in the order of the map's action axes."""
        return (self.action,) if isinstance(self.action, str) else tuple(self.action)

    @property
    def action_grids(self) -> tuple[np.ndarray, ...]:
        """The action grids, one per name of :attr:`action_names`."""
        return (self.actions,) if isinstance(self.actions, np.ndarray) else tuple(self.actions)

    @property
    def shape(self) -> tuple[int, ...]:
        # (grid shape..., action shape...); no docstring, so the API docs leave it out: a
        # second documented ``shape`` makes numpydoc's "shape (n,)" type cross-references
        # ambiguous
        return tuple(len(g) for g in self.grid) + tuple(len(a) for a in self.action_grids)

    @property
    def n_actions(self) -> int:
        """Action grid points (the product over the action axes)."""
        return int(np.prod([len(a) for a in self.action_grids]))

    def _label(self) -> str:
        e = "" if math.isnan(self.energy) else f", energy {self.energy:.6g}"
        return (f"{_short(self.grid, self.names)} x "
                f"{_short(self.action_grids, self.action_names)}{e}")

    def _frame(self, start: int, nxt: np.ndarray, status: np.ndarray) -> pd.DataFrame:
        """The table rows of the states ``start, start + 1, ...`` (C order) x every action:
        ``nxt`` (n_points, n_actions, n_names) and ``status`` (n_points, n_actions)."""
        import pandas as pd

        n_a = self.n_actions
        idx = np.unravel_index(np.arange(start, start + len(status)),
                               tuple(len(g) for g in self.grid))
        data: dict[str, Any] = {n: np.repeat(g[i], n_a)
                                for n, g, i in zip(self.names, self.grid, idx)}
        data.update({n: np.tile(c, len(status))
                     for n, c in zip(self.action_names, grid_columns(self.action_grids))})
        for j, n in enumerate(self.names):
            data[f"next_{n}"] = nxt[..., j].ravel()
        data["status"] = np.asarray(status).ravel()
        units = {n: _unit(n) for n in list(self.names) + list(self.action_names)}
        units.update({f"next_{n}": _unit(n) for n in self.names}, status="-")
        return with_units(pd.DataFrame(data), units)


@dataclass(frozen=True, eq=False, repr=False)
class StateActionMap(_MapGrid, Result):
    """One stride from every grid state with every grid action.

    Attributes
    ----------
    names : tuple of str
        Names of the state variables (one to three), e.g. ``("y",)``.
    grid : tuple of ndarray
        The state grid axes (strictly increasing), one per name.
    action : str or tuple of two str
        Name of the action, e.g. ``"alpha_r"``; for two actions their names,
        e.g. ``("alpha_r", "k")`` (:attr:`action_names` is always a tuple).
    actions : ndarray or tuple of two ndarray
        The action grid (strictly increasing), or one per action
        (:attr:`action_grids` is always a tuple).
    next : ndarray, shape (grid shape..., action shape..., n_names)
        The next state; NaN where the stride failed.
    status : ndarray of int, shape (grid shape..., action shape...)
        :class:`tslip.Status` codes; 0 (``OK``) where the stride succeeded.
    energy : float
        Total energy of every cell [MgL] (NaN for a map built from arrays).
    params : Params or None
        The base parameters (None for a map built from arrays).
    meta : dict
        How it was computed (options, seconds, ...).
    """

    names: tuple[str, ...]
    grid: tuple[np.ndarray, ...]
    action: str | tuple[str, ...]
    actions: np.ndarray | tuple[np.ndarray, ...]
    next: np.ndarray
    status: np.ndarray
    energy: float = math.nan
    params: Params | None = None
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        shape = self.shape
        if self.next.shape != shape + (len(self.names),):
            raise ValueError(f"next must have shape {shape + (len(self.names),)}, got "
                             f"{self.next.shape}")
        if self.status.shape != shape:
            raise ValueError(f"status must have shape {shape}, got {self.status.shape}")

    @classmethod
    def from_arrays(cls, states: Mapping[str, Sequence[float] | np.ndarray],
                    actions: Any, next: np.ndarray,
                    failed: np.ndarray | None = None) -> StateActionMap:
        """A map of any discrete system: its grids, successors and failures.

        ``actions`` is ``(name, grid)`` or ``{name: grid}`` with one or two
        entries; ``next`` has shape ``(*grid shape, *action shape[, n_states])``
        (the last axis may be left out for one state variable); ``failed``
        (bool, same shape without that axis) marks the pairs that fail at
        once (status 1), default: where ``next`` is not finite.
        """
        names, grid = _state_grid(states)
        action, acts = _action_grid(actions)
        nxt = np.asarray(next, dtype=float)
        shape = tuple(len(g) for g in grid) + tuple(len(a) for a in acts)
        if nxt.shape == shape and len(names) == 1:
            nxt = nxt[..., None]
        if nxt.shape != shape + (len(names),):
            raise ValueError(f"next must have shape {shape + (len(names),)}, got {nxt.shape}")
        bad = ~np.all(np.isfinite(nxt), axis=-1)
        if failed is not None:
            f = np.asarray(failed, dtype=bool)
            if f.shape != shape:
                raise ValueError(f"failed must have shape {shape}, got {f.shape}")
            bad = bad | f
        nxt = np.where(bad[..., None], np.nan, nxt)
        return cls(names, grid, *_action_fields(action, acts), nxt, bad.astype(np.int64))

    @property
    def failed(self) -> np.ndarray:
        """Pairs whose stride failed (a fall, no apex, an error)."""
        return self.status != Status.OK

    def __repr__(self) -> str:
        return (f"StateActionMap({self._label()}; "
                f"{int(self.failed.sum())} of {self.failed.size} fail)")

    def to_dataframe(self) -> pd.DataFrame:
        """One row per (state, action) cell: coordinates, next state, status."""
        n = int(np.prod([len(g) for g in self.grid]))
        return self._frame(0, self.next.reshape(n, self.n_actions, -1),
                           self.status.reshape(n, -1))

    def _table_fields(self) -> tuple[str, ...]:
        return ("next", "status")

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        """``next`` and ``status`` back from the table; the grid comes from the record."""
        acts = fields["actions"]
        acts = (acts,) if isinstance(acts, np.ndarray) else acts
        shape = tuple(len(g) for g in fields["grid"]) + tuple(len(a) for a in acts)
        nxt = np.stack([df[f"next_{n}"].to_numpy(float).reshape(shape)
                        for n in fields["names"]], axis=-1)
        return dict(fields, next=nxt, status=df["status"].to_numpy(np.int64).reshape(shape))


@dataclass(frozen=True, eq=False, repr=False)
class StoredMap(_MapGrid):
    """A state-action map held on disk chunk by chunk, read on demand (a run's chunk store).

    What :func:`tslip.sweeps.viability.run_viability` with an output folder
    returns as its result's ``map``: the grid of a :class:`StateActionMap`
    and the files of its chunks (consecutive blocks of the grid's states in
    C order, each with every action; :func:`read_chunk`), never the whole
    map in memory. :func:`viability` works on it chunk by chunk. ``next``,
    ``status`` and :meth:`to_dataframe` read every chunk (the whole map in
    memory, once: for maps that fit), as does :meth:`load`.

    Attributes
    ----------
    names, grid, action, actions, energy, params, meta : as :class:`StateActionMap`
    folder : Path
        The chunk store (``cache/`` of the run's folder).
    files : tuple of str
        The chunk files in ``folder``, in the order of the states.
    points : tuple of int
        State points in each chunk.
    """

    names: tuple[str, ...]
    grid: tuple[np.ndarray, ...]
    action: str | tuple[str, ...]
    actions: np.ndarray | tuple[np.ndarray, ...]
    folder: Path
    files: tuple[str, ...]
    points: tuple[int, ...]
    energy: float = math.nan
    params: Params | None = None
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        n = int(np.prod([len(g) for g in self.grid]))
        if len(self.files) != len(self.points) or sum(self.points) != n:
            raise ValueError(f"the chunks must cover the {n} states of the grid, got "
                             f"{sum(self.points)} in {len(self.files)} files")

    def read(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Chunk ``k``: ``next`` (n_points, n_actions, n_names) and ``status``
        (n_points, n_actions); ``ValueError`` if the file is gone or not that data."""
        got = read_chunk(self.folder / self.files[k], self.points[k], self.n_actions,
                         len(self.names))
        if got is None:
            raise ValueError(f"chunk {self.folder / self.files[k]} is missing or damaged; rerun "
                             "the viability run to compute it again")
        return got

    def chunks(self) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """Every chunk in order, one read at a time."""
        return (self.read(k) for k in range(len(self.files)))

    @property
    def failed(self) -> np.ndarray:
        """Pairs whose stride failed (one byte a pair, read chunk by chunk)."""
        return np.concatenate([st != Status.OK for _, st in self.chunks()]).reshape(self.shape)

    @functools.cached_property
    def _loaded(self) -> StateActionMap:
        parts = list(self.chunks())
        shape = self.shape
        nxt = np.concatenate([p[0] for p in parts]).reshape(shape + (len(self.names),))
        status = np.concatenate([p[1] for p in parts]).reshape(shape)
        return StateActionMap(self.names, self.grid, self.action, self.actions, nxt, status,
                              self.energy, self.params, self.meta)

    def load(self) -> StateActionMap:
        """The whole map in memory (read once, then kept)."""
        return self._loaded

    @property
    def next(self) -> np.ndarray:
        """:attr:`StateActionMap.next`, read from the store (:meth:`load`)."""
        return self.load().next

    @property
    def status(self) -> np.ndarray:
        """:attr:`StateActionMap.status`, read from the store (:meth:`load`)."""
        return self.load().status

    def __repr__(self) -> str:
        return f"StoredMap({self._label()}; {len(self.files)} chunks in {self.folder})"

    def to_dataframe(self) -> pd.DataFrame:
        return self.load().to_dataframe()

    def _fields(self) -> dict[str, Any]:
        return self.load()._fields()

    def save(self, path: str | Path) -> Path:
        """The map in memory (:meth:`load`) saved as a :class:`StateActionMap`."""
        return self.load().save(path)


def read_chunk(path: str | Path, n_points: int, n_actions: int,
               n_names: int) -> tuple[np.ndarray, np.ndarray] | None:
    """A stored chunk's ``(next, status)``, or None if it is not exactly that data.

    Data only: read with ``allow_pickle=False`` (an object array is refused),
    the two arrays and nothing else, ``next`` float64 of shape
    ``(n_points, n_actions, n_names)`` and ``status`` an integer array of
    shape ``(n_points, n_actions)``. Anything else (damaged, foreign, a
    pickle) is None.
    """
    try:
        with open(path, "rb") as f, np.load(f, allow_pickle=False) as z:
            if sorted(z.files) != ["next", "status"]:
                return None
            nxt, status = z["next"], z["status"]
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
        return None
    if (nxt.dtype != np.float64 or status.dtype.kind not in "iu"
            or nxt.shape != (n_points, n_actions, n_names)
            or status.shape != (n_points, n_actions)):
        return None
    return nxt, status.astype(np.int64)


def _state_grid(states: Mapping[str, Any]) -> tuple[tuple[str, ...], tuple[np.ndarray, ...]]:
    if not isinstance(states, Mapping) or not 1 <= len(states) <= 3:
        raise ValueError("states must be a dict of one to three grids, e.g. {'y': grid}, got "
                         f"{states!r}")
    names = tuple(str(n) for n in states)
    return names, tuple(_viable.check_grid(states[n], f"states[{n!r}]") for n in names)


def _action_grid(actions: Any) -> tuple[tuple[str, ...], tuple[np.ndarray, ...]]:
    """``(name, grid)`` or ``{name: grid}`` (one or two entries) as names and checked grids."""
    if isinstance(actions, Mapping):
        if not 1 <= len(actions) <= 2:
            raise ValueError("actions must be a dict of one or two {name: grid} entries, got "
                             f"{len(actions)}")
        names = tuple(str(n) for n in actions)
        return names, tuple(_viable.check_grid(actions[n], f"actions[{n!r}]") for n in names)
    if not (isinstance(actions, tuple) and len(actions) == 2 and isinstance(actions[0], str)):
        raise ValueError("actions must be (name, grid) or {name: grid} (one or two entries), "
                         f"e.g. ('alpha_r', grid), got {actions!r}")
    return (actions[0],), (_viable.check_grid(actions[1], f"actions[{actions[0]!r}]"),)


def _action_fields(names: tuple[str, ...], grids: tuple[np.ndarray, ...]
                   ) -> tuple[str | tuple[str, ...], np.ndarray | tuple[np.ndarray, ...]]:
    """A map's ``action`` and ``actions``: a name and a grid for one action, tuples for two."""
    return (names[0], grids[0]) if len(names) == 1 else (names, grids)


# ---------------------------------------------------------------------------
# viability
# ---------------------------------------------------------------------------


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
                f"{int(self.s.sum())} of {self.s.size} states viable, {self.sweeps} sweeps)")

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


# ---------------------------------------------------------------------------
# the physical map: apex to apex at fixed energy (tslip.gait.section)
# ---------------------------------------------------------------------------


def _with_action(params: Params, name: str, value: float) -> Params:
    """``params`` with the action set: ``alpha_r`` directly, others by :func:`set_param`."""
    if name == "alpha_r":
        return dataclasses.replace(params, alpha_r=float(value))
    return set_param(params, name, value)


def _with_actions(params: Params, names: Sequence[str], values: Sequence[float]) -> Params:
    """``params`` with every action of ``names`` set to its value (:func:`_with_action`)."""
    for name, v in zip(names, values):
        params = _with_action(params, name, v)
    return params


def check_map_inputs(params: Params, states: Mapping[str, Any], actions: Any,
                     energy: float) -> tuple[tuple[str, ...], tuple[np.ndarray, ...], Any, Any,
                                             float]:
    """Check a physical map's inputs (one-line ``ValueError`` naming the field); return them
    as ``(names, grid, action, actions, energy)``, the actions as a map holds them
    (:class:`StateActionMap`: a name and a grid for one action, tuples for two)."""
    if not isinstance(params, Params):
        raise ValueError(f"params must be a tslip.Params, got {type(params).__name__}")
    names, grid = _state_grid(states)
    bad = [n for n in names if n not in STATE_NAMES]
    if bad:
        raise ValueError(f"states: unknown apex variable {bad[0]!r}; allowed: "
                         f"{list(STATE_NAMES)} (xd follows from the energy)")
    if "y" not in names:
        raise ValueError("states must include the apex height 'y'")
    anames, agrids = _action_grid(actions)
    corners = list(itertools.product(*[(g[0], g[-1]) for g in agrids]))
    for name, g in zip(anames, agrids):
        for v in (g[0], g[-1]):
            try:
                _with_action(params, name, v)
            except ValueError as exc:
                also = " (or 'alpha_r', the leg angle)" if "unknown parameter" in str(exc) else ""
                raise ValueError(f"actions[{name!r}]: {exc}{also}") from None
    E = float(check_number(energy, "energy [MgL]", lower=0.0, lower_open=True))
    j = names.index("y")
    phid_sq = max(float(np.max(grid[names.index("phid")] ** 2)) if "phid" in names else 0.0, 0.0)
    for vals in corners:
        try:
            p = _with_actions(params, anames, vals)
        except ValueError as exc:  # each action valid alone, not together
            raise ValueError(f"actions {list(anames)}: {exc}") from None
        if not section.apex_section_ok(p):
            raise ValueError("params: the apex is a Poincare section only if the touch-down "
                             "angle follows from the apex state (omega_r = 0, or retraction "
                             f"timed from the apex), got omega_r={p.omega_r!r} with the "
                             "lift-off clock")
        y_max = (E - 0.5 * p.J * phid_sq) / (p.m * p.g)
        if grid[j][-1] >= y_max:
            raise ValueError(f"states['y'] must stay below {y_max:.6g} L at energy {E:g} MgL "
                             f"(no forward speed left there), got up to {grid[j][-1]:g}")
    return (names, grid, *_action_fields(anames, agrids), E)


def _apex_rows(params: Params, names: Sequence[str], points: np.ndarray,
               energy: float) -> np.ndarray:
    """Apex rows ``(y, xd, phi, phid)`` at ``points`` (n, len(names)), ``xd`` from the energy."""
    cols = {n: points[:, j] for j, n in enumerate(names)}
    y = cols["y"]
    phi = cols.get("phi", np.zeros(len(y)))
    phid = cols.get("phid", np.zeros(len(y)))
    kin = energy - params.m * params.g * y - 0.5 * params.J * phid**2
    xd = np.sqrt(np.maximum(2.0 * kin / params.m, 0.0))
    return np.column_stack([y, xd, phi, phid])


def map_cells(params: Params, names: Sequence[str], points: np.ndarray, actions: Any,
              energy: float, options: IntegratorOptions | None = None
              ) -> tuple[np.ndarray, np.ndarray]:
    """The apex map at ``points`` (n, d) x every action: next states (n, n_a, d), status.

    ``actions`` as :func:`state_action_map` takes them (one or two); ``n_a``
    is the product of their grid sizes, the action columns in C order of the
    actions as given. One batched call (:func:`tslip.gait.section.apex_map_states`,
    whose stances run in one compiled :func:`tslip.step_batch` kernel) over
    the states and the ``alpha_r`` grid for each value of the other action (one
    call for an ``alpha_r`` action alone); without ``alpha_r``, one call per
    action value.
    """
    options = options or IntegratorOptions.tight("dop853")
    anames, agrids = _action_grid(actions)
    pts = np.asarray(points, dtype=float).reshape(-1, len(names))
    shape_a = tuple(len(g) for g in agrids)
    n, n_a, d = len(pts), int(np.prod(shape_a)), len(names)
    nxt = np.empty((n, n_a, d))
    status = np.empty((n, n_a), dtype=np.int64)
    columns = np.arange(n_a).reshape(shape_a)
    other = [k for k, a in enumerate(anames) if a != "alpha_r"]
    alphas = agrids[anames.index("alpha_r")] if "alpha_r" in anames else None
    for ix in itertools.product(*[range(shape_a[k]) for k in other]):
        p = _with_actions(params, [anames[k] for k in other],
                          [float(agrids[k][i]) for k, i in zip(other, ix)])
        pick: list[Any] = [slice(None)] * len(anames)
        for k, i in zip(other, ix):
            pick[k] = i
        cols = columns[tuple(pick)].ravel()
        rows = _apex_rows(p, names, pts, energy)
        if alphas is None:
            b = section.apex_map_states(p, rows, options=options)
        else:
            b = section.apex_map_states(p, np.repeat(rows, len(alphas), axis=0),
                                        np.tile(alphas, n), options=options)
        nxt[:, cols] = np.stack([getattr(b, c) for c in names], axis=-1).reshape(n, -1, d)
        status[:, cols] = np.asarray(b.status, dtype=np.int64).reshape(n, -1)
    nxt[status != Status.OK] = np.nan
    return nxt, status


def state_action_map(params: Params, states: Mapping[str, Sequence[float] | np.ndarray],
                     actions: tuple[str, Sequence[float] | np.ndarray]
                     | Mapping[str, Sequence[float] | np.ndarray], *, energy: float,
                     options: IntegratorOptions | None = None) -> StateActionMap:
    """The apex return map at fixed total energy over a grid of apex states and actions.

    Parameters
    ----------
    params : Params
        Model whose apex is a Poincare section (no retraction clock from
        lift-off; :func:`tslip.gait.section.apex_section_ok`), e.g.
        ``preset("slip")``.
    states : dict
        One to three apex variables and their grids: ``{"y": heights}`` [L]
        for the SLIP; for the TSLIP e.g. ``{"y": ..., "phid": ...}`` or all
        three ``{"y": ..., "phi": ..., "phid": ...}`` (:data:`STATE_NAMES`;
        any left out is 0 at the apex, so a map over fewer variables is the
        slice of the 3-D map at 0, bit for bit).
    actions : (str, array) or {str: array}
        The action and its grid: ``("alpha_r", angles)`` or
        ``{"alpha_r": angles}`` (the leg angle set
        at lift-off, the SLIP's touch-down angle [rad]) or any parameter
        :func:`tslip.gait.continuation.set_param` accepts (e.g. ``"k"``);
        a dict may hold two actions, e.g. ``{"alpha_r": angles, "omega_r":
        rates}`` (with ``retraction="apex"``: the lift-off clock is not an
        apex section): the map's last axes are the actions in that order.
    energy : float
        Total energy [MgL] (:func:`tslip.gait.section.energy`): the forward
        speed at each apex is ``xd = sqrt(2 (E - m g y - J phid^2 / 2) / m)``.
    options : IntegratorOptions, optional
        Default ``IntegratorOptions.tight("dop853")`` (tolerance 1e-12).

    Returns
    -------
    StateActionMap
        A stride fails (status not OK) for a fall, an apex too low for the
        leg to reach the ground (``FALL_NO_TOUCHDOWN``), a lift-off moving
        down (``NO_APEX``) or an integration error.
    """
    names, grid, action, acts, E = check_map_inputs(params, states, actions, energy)
    anames, agrids = _action_grid(actions)
    options = options or IntegratorOptions.tight("dop853")
    t0 = time.perf_counter()
    pts = np.stack(grid_columns(grid), axis=1)
    nxt, status = map_cells(params, names, pts, dict(zip(anames, agrids)), E, options)
    shape = tuple(len(g) for g in grid) + tuple(len(g) for g in agrids)
    return StateActionMap(names, grid, action, acts, nxt.reshape(shape + (len(names),)),
                          status.reshape(shape), E, params,
                          {"options": dataclasses.asdict(options),
                           "seconds": time.perf_counter() - t0})


# ---------------------------------------------------------------------------
# basins of attraction
# ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False, repr=False)
class Basin(Result):
    """Where runs from a grid of apex states go under a gait's parameters.

    Attributes
    ----------
    names, grid : as :class:`StateActionMap`
        The start states at the apex, at the gait's energy.
    steps : ndarray of int, shape (grid shape...)
        Strides until the touch-down state is within ``tol`` of the gait's
        (0: it starts there); -1 if it never was.
    n_done : ndarray of int
        Strides completed (``n_steps`` unless it fell).
    status : ndarray of int
        :class:`tslip.Status` of the last stride (OK if it did not fall).
    n_steps : int
    tol : float
    energy : float
    params : Params
    gait : ndarray
        The gait's touch-down section ``(beta, phi, xd, yd, phid)``.
    """

    names: tuple[str, ...]
    grid: tuple[np.ndarray, ...]
    steps: np.ndarray
    n_done: np.ndarray
    status: np.ndarray
    n_steps: int
    tol: float
    energy: float
    params: Params
    gait: np.ndarray
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def converged(self) -> np.ndarray:
        """Starts whose run reached the gait."""
        return self.steps >= 0

    @property
    def fell(self) -> np.ndarray:
        """Starts whose run fell (or failed) within ``n_steps``."""
        return self.status != Status.OK

    def __repr__(self) -> str:
        return (f"Basin({_short(self.grid, self.names)}, {self.n_steps} strides: "
                f"{int(self.converged.sum())} reach the gait, {int(self.fell.sum())} fall, of "
                f"{self.steps.size})")

    def to_dataframe(self) -> pd.DataFrame:
        """One row per start: its coordinates, ``steps``, ``n_done``, ``status``."""
        import pandas as pd

        data: dict[str, Any] = dict(zip(self.names, grid_columns(self.grid)))
        data.update(steps=self.steps.ravel(), n_done=self.n_done.ravel(),
                    status=self.status.ravel())
        return with_units(pd.DataFrame(data), {**{n: _unit(n) for n in self.names},
                                               "steps": "-", "n_done": "-", "status": "-"})

    def _table_fields(self) -> tuple[str, ...]:
        return ("steps", "n_done", "status")

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        shape = tuple(len(g) for g in fields["grid"])
        return dict(fields, **{c: df[c].to_numpy(np.int64).reshape(shape)
                               for c in ("steps", "n_done", "status")})

    def plot(self, ax: Axes | None = None) -> Any:
        """Strides to the gait over the start grid (:func:`tslip.plotting.viability.plot_basin`)."""
        from ..plotting.viability import plot_basin

        return plot_basin(self, ax=ax)


def basin(params: Params, gait: Gait, states: Mapping[str, Sequence[float] | np.ndarray],
          n_steps: int, *, tol: float = 1e-6,
          options: IntegratorOptions | None = None) -> Basin:
    """Strides to reach ``gait`` (or to fall) from every grid start state at its energy.

    The start states are apexes at the gait's total energy
    (:func:`tslip.gait.section.energy` of its touch-down); each descends to
    its touch-down under ``gait.params`` and runs ``n_steps`` strides, all
    rows in one compiled :func:`tslip.run_batch` call. A run has reached the
    gait at the first touch-down whose section ``(beta, phi, xd, yd, phid)``
    is within ``tol`` (max norm) of the gait's, leaving out ``phi`` when the
    pitch is decoupled (:func:`tslip.gait.stability.pitch_decoupled`: every
    pitch is then a fixed point).

    Parameters
    ----------
    params : Params
        Checked against ``gait.params`` (the gait's solved ``alpha_r`` is used).
    gait : Gait
    states : dict
        One or two apex variables and their grids (as :func:`state_action_map`).
    n_steps : int
    tol : float
    options : IntegratorOptions, optional
        Default ``IntegratorOptions.tight("dop853")``.
    """
    n_steps = int(check_number(n_steps, "n_steps", lower=1, integer=True))
    tol = float(check_number(tol, "tol", lower=0.0, lower_open=True))
    p = gait.params
    if dataclasses.replace(params, alpha_r=p.alpha_r) != p:
        raise ValueError("params must be the gait's parameters (gait.params) up to alpha_r")
    E = section.total_energy(p, gait.state)
    names, grid, _, _, _ = check_map_inputs(p, states, ("alpha_r", [p.alpha_r]), E)
    options = options or IntegratorOptions.tight("dop853")
    t0 = time.perf_counter()
    pts = np.stack(grid_columns(grid), axis=1)
    rows = _apex_rows(p, names, pts, E)
    A = np.hstack([rows, np.zeros((len(rows), 2))])
    td, st, _ = section._touchdowns(np.tile(pk.pack_params(p), (len(A), 1)), A,
                                    options.packed())
    shape = tuple(len(g) for g in grid)
    steps = np.full(len(A), -1, dtype=np.int64)
    n_done = np.zeros(len(A), dtype=np.int64)
    status = st.astype(np.int64)
    go = np.flatnonzero(st == Status.OK)
    target = gait.state.section()
    if go.size:
        run = run_batch(p, td[go], n_steps, options=options)
        hist = run.touchdowns[:, :, :5]
        err = np.abs(hist - target)
        if pitch_decoupled(p):
            err[:, :, 1] = 0.0
        near = np.all(err <= tol, axis=-1)  # NaN rows (after a fall) are never near
        first = np.where(near.any(axis=1), np.argmax(near, axis=1), -1)
        steps[go], n_done[go], status[go] = first, run.n_done, run.status
    return Basin(names, grid, steps.reshape(shape), n_done.reshape(shape),
                 status.reshape(shape), n_steps, tol, E, p, target,
                 {"options": dataclasses.asdict(options), "seconds": time.perf_counter() - t0})
