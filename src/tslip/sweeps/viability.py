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
gives the same bytes (every cell is computed on its own). The viability
iteration then runs here on the whole map (it is cheap) and the result is
written to ``results.parquet`` and its record ``results.json``
(:meth:`tslip.gait.viability.Viability.save`)
with ``run.json``; one run at a time per folder (``.lock``)::

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
or ``from``/``to``/``points`` (one action).
"""

from __future__ import annotations

import dataclasses
import hashlib
import io
import json
import time
import zipfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from .._checks import check_name, check_number
from .._codehash import code_hash
from .._io import atomic_write, git_hash, write_json
from ..gait._viable import RULES
from ..gait.viability import StateActionMap, Viability, check_map_inputs, map_cells, viability
from ..model.parameters import Params, preset
from ..simulation.options import IntegratorOptions
from . import _pool
from ._lock import folder_lock
from ._schedule import Task, choose_workers, run_tasks
from .run import StudyInterrupted, _cached_names
from .spec import Axis, read_spec

__all__ = ["CHUNK_CELLS", "ViabilityInterrupted", "ViabilitySpec", "chunk_keys", "run_viability",
           "saved_cells", "read_chunk"]

Progress = Callable[[int, int], None]

#: Cells (state points x actions) per task and cache file.
CHUNK_CELLS = 2000
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
    action: Axis
    energy: float
    rule: str = "bracket"
    options: IntegratorOptions = field(default_factory=lambda: IntegratorOptions.tight("dop853"))
    description: str = ""

    def __post_init__(self) -> None:
        check_name(self.name, "viability name")
        if self.rule not in RULES:
            raise ValueError(f"rule must be one of {list(RULES)}, got {self.rule!r}")
        check_number(self.energy, "energy [MgL]", lower=0.0, lower_open=True)
        check_map_inputs(self.base, {a.param: a.values for a in self.states},
                         (self.action.param, self.action.values), self.energy)

    @property
    def shape(self) -> tuple[int, ...]:
        """(*state grid shape, n_actions)."""
        return tuple(len(a.values) for a in self.states) + (len(self.action.values),)

    @property
    def n_cells(self) -> int:
        return int(np.prod(self.shape))

    def points(self) -> np.ndarray:
        """Every state point of the grid, C order, shape (n_states, n_names)."""
        mesh = np.meshgrid(*[np.asarray(a.values) for a in self.states], indexing="ij")
        return np.stack([m.ravel() for m in mesh], axis=1)

    def chunks(self) -> list[slice]:
        """Slices of :meth:`points`, about :data:`CHUNK_CELLS` cells each."""
        n = len(self.points())
        per = max(1, CHUNK_CELLS // len(self.action.values))
        return [slice(i, min(i + per, n)) for i in range(0, n, per)]

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "description": self.description, "energy": self.energy,
                "rule": self.rule, "params": self.base.to_dict(),
                "options": dataclasses.asdict(self.options),
                "state": [{"name": a.param, "values": list(a.values)} for a in self.states],
                "action": {"name": self.action.param, "values": list(self.action.values)}}

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


def _action(data: dict[str, Any]) -> Axis:
    """The action: ``[action]`` (with a name) or ``[actions.<name>]`` (one entry)."""
    if ("action" in data) == ("actions" in data):
        raise ValueError("give the action as [action] (name and values) or as "
                         "[actions.<name>] (values), one of the two")
    if "action" in data:
        return _grid(data["action"], "[action]")
    acts = data["actions"]
    if not isinstance(acts, dict) or len(acts) != 1:
        got = len(acts) if isinstance(acts, dict) else repr(acts)
        raise ValueError("[actions] must hold one [actions.<name>] table (two actions are "
                         f"not supported yet), got {got}")
    (name, table), = acts.items()
    if not isinstance(table, dict) or "name" in table:
        raise ValueError(f"[actions.{name}] must be a table of values or from/to/points")
    return _grid({"name": name, **table}, f"[actions.{name}]")


def _prefix(spec: ViabilitySpec) -> Any:
    d = spec.to_dict()
    payload = {"code": code_hash("tslip.gait.viability"), "params": d["params"],
               "energy": spec.energy, "options": d["options"], "action": d["action"],
               "names": [a.param for a in spec.states]}
    return hashlib.sha256(json.dumps(payload, sort_keys=True, default=float).encode())


def chunk_keys(spec: ViabilitySpec) -> list[str]:
    """Cache key of each chunk of :meth:`ViabilitySpec.chunks`."""
    prefix, pts = _prefix(spec), spec.points()
    out = []
    for sl in spec.chunks():
        h = prefix.copy()
        h.update(np.ascontiguousarray(pts[sl]).tobytes())
        out.append(h.hexdigest()[:24])
    return out


def saved_cells(spec: ViabilitySpec, out_dir: str | Path) -> int:
    """How many of the spec's cells ``out_dir/cache`` holds."""
    names = _cached_names(Path(out_dir) / "cache")
    n_a = len(spec.action.values)
    return sum((sl.stop - sl.start) * n_a for sl, k in zip(spec.chunks(), chunk_keys(spec))
               if f"{k}.npz" in names)


def _chunk_task(spec: ViabilitySpec, points: np.ndarray, key: str, cache: str | None,
                tick: Callable[[int], None] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """One chunk's cells (in a worker or here), cached as soon as they are done."""
    nxt, status = map_cells(spec.base, [a.param for a in spec.states], points,
                            (spec.action.param, np.asarray(spec.action.values)), spec.energy,
                            spec.options)
    if cache is not None:
        _write_chunk(Path(cache) / f"{key}.npz", nxt, status)
    (tick or _pool.notify)(int(status.size))
    return nxt, status


def _write_chunk(path: Path, nxt: np.ndarray, status: np.ndarray) -> None:
    buf = io.BytesIO()
    np.savez(buf, next=np.asarray(nxt, dtype=np.float64),
             status=np.asarray(status, dtype=np.int64))
    atomic_write(path, lambda tmp: Path(tmp).write_bytes(buf.getvalue()))


def read_chunk(path: str | Path, n_points: int, n_actions: int,
               n_names: int) -> tuple[np.ndarray, np.ndarray] | None:
    """A cached chunk's ``(next, status)``, or None if it is not exactly that data.

    Data only: read with ``allow_pickle=False`` (an object array is refused),
    the two arrays and nothing else, ``next`` float64 of shape
    ``(n_points, n_actions, n_names)`` and ``status`` an integer array of
    shape ``(n_points, n_actions)``. Anything else (damaged, foreign, a
    pickle) is None: the chunk is computed again.
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


def run_viability(spec: ViabilitySpec, out_dir: str | Path | None = None, *,
                  workers: int | None = None, progress: Progress | None = None,
                  wait: bool = False, scheduler: str | None = None) -> Viability:
    """Compute (or resume) the spec's state-action map and its viability kernel.

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
    StudyInterrupted
        On Ctrl-C ("N of M cells saved"); the finished chunks stay cached.
    """
    if workers is not None and workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
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
    t0 = time.perf_counter()
    cache = out / "cache" if out is not None else None
    names = _cached_names(cache)
    pts, n_a, total = spec.points(), len(spec.action.values), spec.n_cells
    d = len(spec.states)
    nxt = np.full((len(pts), n_a, d), np.nan)
    status = np.zeros((len(pts), n_a), dtype=np.int64)
    state = {"done": 0}

    def tick(n: int) -> None:
        state["done"] += n
        if progress:
            progress(min(state["done"], total), total)

    tasks = []
    for sl, key in zip(spec.chunks(), chunk_keys(spec)):
        got = (read_chunk(cache / f"{key}.npz", sl.stop - sl.start, n_a, d)  # type: ignore[operator]
               if f"{key}.npz" in names else None)
        if got is not None:
            nxt[sl], status[sl] = got
            state["done"] += got[1].size
            continue
        n = (sl.stop - sl.start) * n_a
        here = cache is not None and scheduler is None  # on Dask: cached here, on arrival
        tasks.append(Task((spec.name, sl.start), _chunk_task,
                          (spec, pts[sl], key, str(cache) if here else None),
                          cost=n * CELL_SECONDS, meta={"slice": sl, "key": key}))
    n_cached = state["done"]
    if progress:
        progress(n_cached, total)

    def on_done(task: Task, result: tuple[np.ndarray, np.ndarray]) -> list[Task]:
        sl = task.meta["slice"]
        nxt[sl], status[sl] = result
        if scheduler is not None:
            if cache is not None:
                _write_chunk(cache / f"{task.meta['key']}.npz", *result)
            tick(int(result[1].size))
        return []

    workers = (1 if scheduler is not None else
               choose_workers(sum(t.cost for t in tasks), n_workers, width=len(tasks)))
    run_tasks(tasks, on_done, workers, tick=tick, scheduler=scheduler)
    smap = StateActionMap(tuple(a.param for a in spec.states),
                          tuple(np.asarray(a.values, dtype=float) for a in spec.states),
                          spec.action.param, np.asarray(spec.action.values, dtype=float),
                          nxt.reshape(spec.shape + (d,)), status.reshape(spec.shape),
                          spec.energy, spec.base, {"options": spec.to_dict()["options"]})
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
