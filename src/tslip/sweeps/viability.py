"""``tslip viability SPEC.toml``: a state-action map and its viability kernel, cached by chunk.

A :class:`ViabilitySpec` is a grid of apex states and actions at fixed
energy (TOML below). :func:`run_viability` splits the state grid into
chunks of about :data:`CHUNK_CELLS` cells (state points times actions, in
C order, fixed by the spec alone), computes each chunk's cells in one
batched call (:func:`tslip.gait.viability.map_cells`) as a task of the
study scheduler (:mod:`tslip.sweeps._schedule`, worker processes from
:mod:`tslip.sweeps._pool`, or a Dask cluster given its scheduler's
address), and writes each chunk to ``cache/`` atomically the moment it is
done, by the process that computed it (on Dask, by this process as the
chunk arrives: the workers need not share its disk). A chunk is data only:
one ``.npz`` of a float64 ``next`` and an integer ``status`` array, read
with ``allow_pickle=False`` and its dtypes and shapes checked (anything
else is computed again). The cache key
hashes the base parameters, energy, options, the chunk's states and
actions and the code behind them, so an interrupted run resumes with the
missing chunks, a finished one reruns instantly, and any worker count
gives the same bytes (every cell is computed on its own). The map then
stays on disk: the result's ``map`` is a
:class:`tslip.gait.viability.StoredMap` of ``cache/`` (chunks read on
demand), the viability iteration sweeps its int32 successor cells through a
memory-mapped file, and the result is written to ``results.parquet`` (a
block of chunks at a time) and its record ``results.json``
(:meth:`tslip.gait.viability.Viability.save`) with ``run.json``: this
process holds the viable pairs (one byte a pair), never the map. One run at
a time per folder (``.lock``)::

    name = "slip"
    preset = "slip"
    energy = 2.6              # total energy of every cell [MgL]
    rule = "bracket"          # tslip's default; or "nearest", or "vibly" (vibly's
                              # rule; tslip.gait.viability.viability)

    [params]                  # overrides of the preset
    k = 25.0

    [options]                 # tslip.IntegratorOptions
    rtol = 1e-12
    atol = 1e-12
    method = "dop853"

    [[state]]                 # one to three apex variables: y, phi, phid
    name = "y"
    from = 1.0
    to = 1.6
    points = 100              # or: values = [...]

    [action]
    name = "alpha_r"
    from = 1.0
    to = 1.45
    points = 100

The action may also be written ``[actions.alpha_r]`` with ``values = [...]``
or ``from``/``to``/``points``; two such tables give two actions (the map's
last axes, in the order written), e.g. ``[actions.alpha_r]`` and
``[actions.omega_r]`` with ``[params] retraction = "apex"``.
"""

from __future__ import annotations

import dataclasses
import hashlib
import io
import itertools
import json
import math
import os
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__, _gridsize
from .._checks import check_name, check_number
from .._codehash import code_hash
from .._io import atomic_write, git_hash, write_json
from ..gait._viable import RULES
from ..gait.viability import (
    StateActionMap,
    StoredMap,
    Viability,
    check_map_inputs,
    map_cells,
    read_chunk,
    viability,
)
from ..model.parameters import Params, preset
from ..simulation.options import IntegratorOptions
from . import _pool
from ._lock import folder_lock
from ._schedule import STARTUP_SECONDS, Task, choose_workers, run_tasks
from .run import StudyInterrupted, _cached_names
from .spec import Axis, read_spec

__all__ = ["CHUNK_CELLS", "ViabilityInterrupted", "ViabilitySpec", "chunk_keys", "run_viability",
           "saved_cells", "read_chunk"]

Progress = Callable[[int, int], None]

#: Cells (state points x actions) per task and cache file.
CHUNK_CELLS = _gridsize.CHUNK_CELLS
#: Estimated seconds per cell at tolerance 1e-12 (warm cache), for the worker count.
CELL_SECONDS = 2e-5


class ViabilityInterrupted(StudyInterrupted):
    """Ctrl-C during :func:`run_viability`: how many of its cells are saved."""

    def __str__(self) -> str:
        return f"{self.saved} of {self.total} cells saved; rerun the same command to resume"


def _grid(data: Any, what: str) -> Axis:
    """``{name, from, to, points}`` or ``{name, values}`` as an :class:`Axis`."""
    if not isinstance(data, dict):
        raise ValueError(f"{what} must be a table with name and from/to/points or values")
    data = dict(data)
    name = data.pop("name", None)
    if not isinstance(name, str) or not name:
        raise ValueError(f"every {what} needs a name")
    try:
        return Axis.from_dict({"param": name, **data})
    except ValueError as exc:
        raise ValueError(f"{what} {str(exc).removeprefix('axis ')}") from None


@dataclass(frozen=True)
class ViabilitySpec:
    """A state-action grid at fixed energy (see the module docstring)."""

    name: str
    base: Params
    states: tuple[Axis, ...]
    action: Axis | tuple[Axis, ...]
    energy: float
    rule: str = "bracket"
    options: IntegratorOptions = field(default_factory=lambda: IntegratorOptions.tight("dop853"))
    description: str = ""

    def __post_init__(self) -> None:
        check_name(self.name, "viability name")
        if self.rule not in RULES:
            raise ValueError(f"rule must be one of {list(RULES)}, got {self.rule!r}")
        check_number(self.energy, "energy [MgL]", lower=0.0, lower_open=True)
        if isinstance(self.action, tuple):
            names = [a.param for a in self.action]
            if not 1 <= len(names) <= 2 or len(set(names)) != len(names):
                raise ValueError(f"action must be one or two axes of different parameters, "
                                 f"got {names}")
            if len(names) == 1:
                object.__setattr__(self, "action", self.action[0])
        names = [a.param for a in self.states]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise ValueError(f"[[state]] tables must name different apex variables, got "
                             f"{twice[0]!r} {names.count(twice[0])} times")
        check_map_inputs(self.base, {a.param: a.values for a in self.states},
                         self.actions(), self.energy)

    @property
    def action_axes(self) -> tuple[Axis, ...]:
        """The actions (one or two), in the order of the map's action axes."""
        return self.action if isinstance(self.action, tuple) else (self.action,)

    def actions(self) -> dict[str, np.ndarray]:
        """The actions as :func:`tslip.gait.viability.state_action_map` takes them."""
        return {a.param: np.asarray(a.values, dtype=float) for a in self.action_axes}

    @property
    def shape(self) -> tuple[int, ...]:
        """(*state grid shape, *action grid shape)."""
        return tuple(len(a.values) for a in self.states + self.action_axes)

    @property
    def n_cells(self) -> int:
        return math.prod(self.shape)  # Python integers: no overflow however large the grid

    @property
    def n_actions(self) -> int:
        """Action grid points (the product over the actions)."""
        return math.prod(len(a.values) for a in self.action_axes)

    @property
    def n_states(self) -> int:
        return math.prod(len(a.values) for a in self.states)

    def points(self, rows: slice | None = None) -> np.ndarray:
        """State points of the grid, C order, shape (n, n_names): all, or the ``rows``
        (a slice with step 1; only its points are made, not the grid's)."""
        shape = tuple(len(a.values) for a in self.states)
        start, stop, _ = (rows or slice(None)).indices(self.n_states)
        idx = np.unravel_index(np.arange(start, max(start, stop)), shape)
        return np.stack([np.asarray(a.values, dtype=float)[i]
                         for a, i in zip(self.states, idx)], axis=1)

    def chunks(self) -> Sequence[slice]:
        """Slices of :meth:`points`, about :data:`CHUNK_CELLS` cells each, made on demand
        (a sequence: ``len``, indexing and iteration, however many chunks the grid has)."""
        return _Chunks(self.n_states, max(1, CHUNK_CELLS // self.n_actions))

    def memory(self, stored: bool = True) -> int:
        """Estimated bytes :func:`run_viability` holds in memory for this grid
        (:func:`tslip._gridsize.run_bytes`; ``stored``: with an output folder)."""
        return _gridsize.run_bytes(self._points(), self._action_points(), self.rule, stored,
                                   CHUNK_CELLS)

    def check_fits(self, stored: bool = True) -> None:
        """Refuse (one-line ``ValueError``: cells, estimated bytes, available memory) a grid
        whose run (:meth:`memory`) does not fit in the memory available, before any work."""
        _gridsize.check_run_fits(self.name, self._points(), self._action_points(), self.rule,
                                 stored, CHUNK_CELLS)

    def _points(self) -> list[int]:
        return [len(a.values) for a in self.states]

    def _action_points(self) -> list[int]:
        return [len(a.values) for a in self.action_axes]

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "description": self.description, "energy": self.energy,
                "rule": self.rule, "params": self.base.to_dict(),
                "options": dataclasses.asdict(self.options),
                "state": [{"name": a.param, "values": list(a.values)} for a in self.states],
                "action": (_axis_dict(self.action) if isinstance(self.action, Axis) else
                           [_axis_dict(a) for a in self.action])}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> ViabilitySpec:
        data = dict(data)
        allowed = {"name", "description", "preset", "params", "options", "state", "action",
                   "actions", "energy", "rule"}
        unknown = set(data) - allowed
        if unknown:
            raise ValueError(f"unknown key {sorted(unknown)[0]!r}; allowed: {sorted(allowed)}")
        for key in ("name", "preset", "description", "rule"):
            if key in data and not isinstance(data[key], str):
                raise ValueError(f"{key} must be a string, got {data[key]!r}")
        if "energy" not in data:
            raise ValueError("energy [MgL] is missing: the total energy of every cell")
        base = preset(data.get("preset", "slip"))
        overrides = data.get("params", {})
        if not isinstance(overrides, dict):
            raise ValueError("[params] must be a table")
        base = Params.from_dict(overrides, base=base)
        opts = data.get("options", {})
        if not isinstance(opts, dict):
            raise ValueError("[options] must be a table")
        known = {f.name for f in dataclasses.fields(IntegratorOptions)}
        if set(opts) - known:
            raise ValueError(f"unknown option {sorted(set(opts) - known)[0]!r} in [options]; "
                             f"allowed: {sorted(known)}")
        options = IntegratorOptions(**{**_TIGHT, **opts})
        states = data.get("state")
        if not isinstance(states, list) or not 1 <= len(states) <= 3:
            raise ValueError("give one to three [[state]] tables (apex variables)")
        return cls(name=str(data.get("name", "viability")), base=base,
                   states=tuple(_grid(s, "[[state]]") for s in states),
                   action=_action(data),
                   energy=check_number(data["energy"], "energy [MgL]", lower=0.0,
                                       lower_open=True),
                   rule=data.get("rule", "bracket"), options=options,
                   description=str(data.get("description", "")))

    @classmethod
    def from_toml(cls, path: str | Path) -> ViabilitySpec:
        return cls.from_dict(read_spec(path, "viability spec"))


_TIGHT = {"rtol": 1e-12, "atol": 1e-12, "method": "dop853"}
#: Chunks handed to a Dask cluster ahead of its results (it takes at most
#: :data:`tslip.sweeps._schedule.DASK_IN_FLIGHT` per worker thread of them at a time).
_DASK_WINDOW = 1024


class _Chunks(Sequence[slice]):
    """The chunk slices of ``n`` state points, ``per`` a chunk, each made when asked for."""

    def __init__(self, n: int, per: int) -> None:
        self.n, self.per = n, per

    def __len__(self) -> int:
        return -(-self.n // self.per)

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            return [self[j] for j in range(len(self))[i]]
        k = range(len(self))[i]  # IndexError out of range, negatives from the end
        return slice(k * self.per, min((k + 1) * self.per, self.n))

    def __iter__(self) -> Iterator[slice]:
        return (slice(i, min(i + self.per, self.n)) for i in range(0, self.n, self.per))


def _axis_dict(a: Axis) -> dict[str, Any]:
    return {"name": a.param, "values": list(a.values)}


def _action(data: dict[str, Any]) -> Axis | tuple[Axis, ...]:
    """The action: ``[action]`` (with a name), one or two ``[[action]]`` tables (as
    :meth:`ViabilitySpec.to_dict` writes two), or one or two ``[actions.<name>]`` tables
    (two: a tuple of axes, in the order written)."""
    if ("action" in data) == ("actions" in data):
        raise ValueError("give the action as [action] (name and values) or as "
                         "[actions.<name>] (values), one of the two")
    if "action" in data:
        act = data["action"]
        if isinstance(act, list) and 1 <= len(act) <= 2:  # [[action]] tables, as to_dict
            return tuple(_grid(a, "[[action]]") for a in act)  # one: the spec's Axis
        return _grid(act, "[action]")
    acts = data["actions"]
    if not isinstance(acts, dict) or not 1 <= len(acts) <= 2:
        got = len(acts) if isinstance(acts, dict) else repr(acts)
        raise ValueError(f"[actions] must hold one or two [actions.<name>] tables, got {got}")
    axes = []
    for name, table in acts.items():
        if not isinstance(table, dict) or "name" in table:
            raise ValueError(f"[actions.{name}] must be a table of values or from/to/points")
        axes.append(_grid({"name": name, **table}, f"[actions.{name}]"))
    return axes[0] if len(axes) == 1 else tuple(axes)


def _prefix(spec: ViabilitySpec) -> Any:
    d = spec.to_dict()
    payload = {"code": code_hash("tslip.gait.viability"), "params": d["params"],
               "energy": spec.energy, "options": d["options"], "action": d["action"],
               "names": [a.param for a in spec.states]}
    return hashlib.sha256(json.dumps(payload, sort_keys=True, default=float).encode())


def _keys(spec: ViabilitySpec) -> Iterator[str]:
    """Cache key of each chunk of :meth:`ViabilitySpec.chunks`, one at a time."""
    prefix = _prefix(spec)
    for sl in spec.chunks():
        h = prefix.copy()
        h.update(np.ascontiguousarray(spec.points(sl)).tobytes())
        yield h.hexdigest()[:24]


def chunk_keys(spec: ViabilitySpec) -> list[str]:
    """Cache key of each chunk of :meth:`ViabilitySpec.chunks`."""
    return list(_keys(spec))


def saved_cells(spec: ViabilitySpec, out_dir: str | Path) -> int:
    """How many of the spec's cells ``out_dir/cache`` holds."""
    names = {n for n in _cached_names(Path(out_dir) / "cache") if n.endswith(".npz")}
    saved = found = 0
    for sl, k in zip(spec.chunks(), _keys(spec)):
        if found == len(names):  # every file matched: the rest of the grid is not saved
            break
        if f"{k}.npz" in names:
            found += 1
            saved += (sl.stop - sl.start) * spec.n_actions
    return saved


def _chunk_task(spec: ViabilitySpec, rows: slice, key: str, cache: str | None,
                tick: Callable[[int], None] | None = None
                ) -> tuple[np.ndarray, np.ndarray] | None:
    """One chunk's cells (in a worker or here): written to ``cache`` as soon as they are
    done (then None comes back: the parent reads the store), else returned."""
    nxt, status = map_cells(spec.base, [a.param for a in spec.states], spec.points(rows),
                            spec.actions(), spec.energy, spec.options)
    (tick or _pool.notify)(int(status.size))
    if cache is not None:
        _write_chunk(Path(cache) / f"{key}.npz", nxt, status)
        return None
    return nxt, status


def _write_chunk(path: Path, nxt: np.ndarray, status: np.ndarray) -> None:
    buf = io.BytesIO()
    np.savez(buf, next=np.asarray(nxt, dtype=np.float64),
             status=np.asarray(status, dtype=np.int64))
    atomic_write(path, lambda tmp: Path(tmp).write_bytes(buf.getvalue()))


def run_viability(spec: ViabilitySpec, out_dir: str | Path | None = None, *,
                  workers: int | None = None, progress: Progress | None = None,
                  wait: bool = False, scheduler: str | None = None) -> Viability:
    """Compute (or resume) the spec's state-action map and its viability kernel.

    With ``out_dir`` the map stays on disk: the result's ``map`` is a
    :class:`tslip.gait.viability.StoredMap` of ``out_dir/cache`` (chunks read
    on demand), the iteration sweeps the map's int32 cells from a memory-mapped
    file, and ``results.parquet`` is written a block of chunks at a time, so
    this process holds the viable pairs (one byte a pair) and a block's
    temporaries, not the map. Without ``out_dir`` the map is held in memory
    (a :class:`tslip.gait.viability.StateActionMap`), as for small grids.

    Parameters
    ----------
    spec : ViabilitySpec
    out_dir : path, optional
        Folder for ``cache/`` (one ``.npz`` per chunk), ``results.parquet``,
        ``run.json`` and ``.lock``; without it nothing is cached or written.
    workers : int, optional
        Worker processes (1: this process); default by the work left.
    progress : callable, optional
        ``progress(cells_done, cells_total)``.
    wait : bool
        Wait for another run holding ``out_dir`` instead of raising.
    scheduler : str, optional
        Address of a Dask distributed scheduler (``tslip[dask]``): the chunks
        run on its cluster (``workers`` is then ignored) and are cached here
        as they arrive; the result is the same, bit for bit.

    Raises
    ------
    ValueError
        If the run would not fit in memory (:meth:`ViabilitySpec.check_fits`),
        before anything is allocated or written.
    StudyInterrupted
        On Ctrl-C ("N of M cells saved"); the finished chunks stay cached.
    """
    if workers is not None and workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    spec.check_fits(stored=out_dir is not None)
    try:
        if out_dir is None:
            return _run(spec, None, workers, progress, scheduler)
        with folder_lock(out_dir, wait=wait):
            return _run(spec, Path(out_dir), workers, progress, scheduler)
    except KeyboardInterrupt:
        saved = saved_cells(spec, out_dir) if out_dir is not None else 0
        raise ViabilityInterrupted(saved, spec.n_cells) from None


def _run(spec: ViabilitySpec, out: Path | None, n_workers: int | None,
         progress: Progress | None, scheduler: str | None = None) -> Viability:
    """The run: the chunks' keys made and their cache read one at a time, as the tasks are
    handed out (a window of them ahead of the workers), never all at once."""
    t0 = time.perf_counter()
    cache = out / "cache" if out is not None else None
    names = _cached_names(cache)
    n_a, total, d = spec.n_actions, spec.n_cells, len(spec.states)
    slices = spec.chunks()
    keys: list[str] = []  # made by pending(), in the order of the chunks
    held: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # the map, without a store only
    state = {"done": 0, "cached": 0}

    def tick(n: int) -> None:
        state["done"] += n
        if progress:
            progress(min(state["done"], total), total)

    here = cache is not None and scheduler is None  # on Dask: cached here, on arrival

    def pending() -> Iterator[Task]:
        for i, (sl, key) in enumerate(zip(slices, _keys(spec))):
            keys.append(key)
            n = (sl.stop - sl.start) * n_a
            if cache is not None and f"{key}.npz" in names and read_chunk(
                    cache / f"{key}.npz", sl.stop - sl.start, n_a, d) is not None:
                state["cached"] += n
                tick(n)
                continue
            yield Task((spec.name, sl.start), _chunk_task,
                       (spec, sl, key, str(cache) if here else None),
                       cost=n * CELL_SECONDS, meta={"i": i, "key": key})

    feed = pending()

    def on_done(task: Task, result: tuple[np.ndarray, np.ndarray] | None) -> Iterator[Task]:
        if result is not None:  # else in the store already
            if cache is None:
                held[task.meta["i"]] = result
            else:
                _write_chunk(cache / f"{task.meta['key']}.npz", *result)
            if scheduler is not None:
                tick(int(result[1].size))
        return itertools.islice(feed, 1)  # the next chunk to compute, in place of this one

    if progress:
        progress(0, total)
    # the first tasks, as many as tell the worker count (choose_workers: every core only
    # when each gets 4 start-ups of work); the others are made as these finish
    enough = (os.cpu_count() or 1) * 4 * STARTUP_SECONDS
    first: list[Task] = []
    cost = 0.0
    for task in feed:
        first.append(task)
        cost += task.cost
        if cost >= enough:
            break
    more = cost >= enough  # else every chunk left is in ``first``
    workers = (1 if scheduler is not None else
               choose_workers(cost, n_workers, width=None if more else len(first)))
    window = _DASK_WINDOW if scheduler is not None else 2 * (workers + 1)
    first += itertools.islice(feed, max(0, window - len(first)))
    run_tasks(first, on_done, workers, tick=tick, scheduler=scheduler)
    if len(keys) != len(slices):  # pragma: no cover - every task's on_done pulls the next
        raise RuntimeError(f"{len(slices) - len(keys)} chunks were never handed out")
    n_cached = state["cached"]
    grid = tuple(np.asarray(a.values, dtype=float) for a in spec.states)
    anames = tuple(a.param for a in spec.action_axes)
    agrids = tuple(np.asarray(a.values, dtype=float) for a in spec.action_axes)
    action: Any = anames[0] if len(anames) == 1 else anames
    actions: Any = agrids[0] if len(agrids) == 1 else agrids
    meta = {"options": spec.to_dict()["options"]}
    smap: StateActionMap | StoredMap
    if cache is None:
        parts = [held[i] for i in range(len(slices))]
        smap = StateActionMap(tuple(a.param for a in spec.states), grid, action, actions,
                              np.concatenate([p[0] for p in parts]).reshape(spec.shape + (d,)),
                              np.concatenate([p[1] for p in parts]).reshape(spec.shape),
                              spec.energy, spec.base, meta)
    else:
        smap = StoredMap(tuple(a.param for a in spec.states), grid, action, actions,
                         cache, tuple(f"{k}.npz" for k in keys),
                         tuple(sl.stop - sl.start for sl in slices), spec.energy, spec.base,
                         meta)
    result = viability(smap, spec.rule)
    if out is not None:
        result.save(out / "results.parquet")
        write_json(out / "run.json", {
            "tslip_version": __version__, "code": code_hash("tslip.gait.viability"),
            "git": git_hash(), "spec": spec.to_dict(), "cells": total,
            "computed": total - n_cached, "cached": n_cached, "workers": workers,
            "scheduler": scheduler,
            "seconds": time.perf_counter() - t0})
    return result
