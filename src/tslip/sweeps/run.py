"""Run a study: continuation lines in parallel, every point cached as it finishes.

Work is split into continuation lines (:meth:`StudySpec.lines`): each line's
gaits are found by :func:`tslip.sweeps.point.solve_gaits` (a 2-D study's
next line starts from them), and its points are analysed in chunks
(:func:`tslip.sweeps.point.analyse_point`); :class:`StudyJob` makes these
tasks and :mod:`tslip.sweeps._schedule` runs them, largest first, in worker
processes (:mod:`tslip.sweeps._pool`; as many as the work pays for, up to
all cores, unless ``workers`` is given), or on a Dask cluster given its
address. Each point is appended to the study's file in ``cache/``
(:mod:`tslip.sweeps._store`: one JSON line a point) the moment it is final,
by the process that computed it, and the progress callback advances with
it. The cache key is a hash of everything that can change a point's
numbers: the study's base parameters, its axes (every value: the
resolution), the point's axis values, the analyses, the gait and Floquet
tolerances, the strides of a robustness run, and the code that computes
them with the versions of Python and the numerical libraries
(:func:`tslip.sweeps.point.code_version`), so

* an interrupted study resumes with only the missing points, and ends
  bit-identical to an uninterrupted run (a continuation line replays its
  cached points; a point whose record a kill tore is computed again),
* a finished study reruns instantly,
* changing a parameter, or the code behind an analysis, recomputes the
  points it affects and no others.

One run at a time per output folder (``.lock``, :mod:`tslip.sweeps._lock`).
Ctrl-C stops the workers and raises :class:`StudyInterrupted` ("N of M
points saved"). A point without a periodic gait is a record with
``converged = False`` and ``stability = "none"``, not an error. On a Dask
cluster the points are cached here as their tasks return.

A study of a 3-D model (:mod:`tslip.sweeps.spatial_spec`) runs the same way;
its points are computed by :mod:`tslip.sweeps.spatial_point` (each from its own
parameters: its lines are independent), and its key holds the model and that
module's :func:`~tslip.sweeps.spatial_point.code_version`.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from collections.abc import Callable, Hashable
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from .. import __version__, _safefile
from .._io import git_hash, write_json, write_table
from .._results import FrameTable, Result, with_units
from ..gait.continuation import get_param
from ..gait.robustness import UNITS as ROBUSTNESS_UNITS
from ..model.units import COLUMN_UNITS, UNIT, param_unit
from . import _pool, _store, _warmup, spatial_spec
from ._lock import folder_lock
from ._schedule import Task, Timing, choose_workers, own_seconds, run_tasks
from .point import (
    Pending,
    Solved,
    analyse_point,
    code_version,
    floquet_tol,
    gait_tol,
    seeds_from_records,
    solve_gaits,
)
from .spec import StudySpec

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["StudyInterrupted", "StudyJob", "StudyResult", "run_study", "point_key",
           "saved_points", "study_file", "study_keys", "STUDY_UNITS"]

Progress = Callable[[int, int], None]


def _spatial_point() -> ModuleType:
    """:mod:`.spatial_point`, imported on first use: it loads the 3-D models' gait searches
    (1.4 s), which a planar study never needs."""
    from . import spatial_point

    return spatial_point


class StudyInterrupted(KeyboardInterrupt):
    """Ctrl-C during a study: how many of its points are saved."""

    def __init__(self, saved: int, total: int) -> None:
        super().__init__(saved, total)
        self.saved, self.total = saved, total

    def __str__(self) -> str:
        return f"{self.saved} of {self.total} points saved; rerun the same command to resume"


def _code(spec: StudySpec) -> str:
    """The code version of a study's points (:func:`tslip.sweeps.point.code_version`, or
    :func:`tslip.sweeps.spatial_point.code_version` for a 3-D model)."""
    if spec.model == "tslip":
        return code_version(spec.analyses)
    return _spatial_point().code_version(spec.model, spec.analyses)


def _key_prefix(spec: StudySpec) -> Any:
    """The hash state shared by a study's points: code, base parameters, analyses."""
    if spec.model != "tslip":  # a 3-D model: no tolerances in its spec
        return hashlib.sha256(json.dumps({
            "model": spec.model, "code": _code(spec), "base": spec.base.to_dict(),
            "axes": [[a.param, sorted(a.values)] for a in spec.axes],
            "analyses": sorted(spec.analyses),
            "n_steps": spec.n_steps if "lateral_robustness" in spec.analyses else None,
        }, sort_keys=True, default=float).encode())
    payload: dict[str, Any] = {
        "code": code_version(spec.analyses),
        "base": spec.base.to_dict(),
        # every axis's values, not only the point's: the continuation seeds a point
        # from its neighbours, so another resolution can converge elsewhere within tol
        "axes": [[a.param, sorted(a.values)] for a in spec.axes],
        "analyses": sorted(spec.analyses),
        "n_steps": spec.n_steps if "robustness" in spec.analyses else None,
        "tol": gait_tol(spec),
        "neutral_tol": floquet_tol(spec),
    }
    return hashlib.sha256(json.dumps(payload, sort_keys=True, default=float).encode())


def _key(prefix: Any, point: tuple[float, ...]) -> str:
    h = prefix.copy()
    h.update(repr(tuple(float(x) for x in point)).encode())
    return h.hexdigest()[:24]


def point_key(spec: StudySpec, assignment: dict[str, float]) -> str:
    """Cache key of one point: base parameters, axis values, analyses, code version."""
    return _key(_key_prefix(spec), tuple(assignment[a.param] for a in spec.axes))


def study_keys(spec: StudySpec) -> list[tuple[dict[str, float], list[float], list[str]]]:
    """Per line: its assignment, its values (ascending) and their cache keys."""
    prefix = _key_prefix(spec)
    out = []
    for assignment, axis in spec.lines():
        values = sorted(float(v) for v in axis.values)
        outer = tuple(assignment[a.param] for a in spec.axes[:-1])
        keys = [_key(prefix, outer + (v,)) for v in values]
        out.append((assignment, values, keys))
    return out


def study_file(spec: StudySpec, out_dir: str | Path) -> Path:
    """The file of the study's point records in ``out_dir/cache`` (:mod:`._store`).

    Named by the hash its points' keys share (:func:`_key_prefix`), so another
    code version, base or resolution has a file of its own.
    """
    name = _key_prefix(spec).hexdigest()[:24] + _store.SUFFIX
    return Path(out_dir) / "cache" / name


def check_study_folder(spec: StudySpec, out_dir: str | Path) -> None:
    """Refuse (:class:`tslip._safefile.UnsafePath`, one line) a study folder whose
    ``cache/`` or study file (:func:`study_file`) is a link, before any work: the CLI
    calls it before its progress bar is drawn (the writer refuses it again when it
    opens the file)."""
    path = study_file(spec, out_dir)
    try:
        os.close(_safefile.open_below(out_dir, path, os.O_RDONLY))
    except FileNotFoundError:
        pass


def _writer(cache: str | Path | None) -> _store.Writer:
    """The appender of a study file (:func:`study_file`): nothing below the study
    folder (``cache/``, the file) is followed if it is a link."""
    return _store.Writer(cache, root=None if cache is None else Path(cache).parent.parent)


def _cached_names(cache: Path | None) -> set[str]:
    """File names in the cache; removes temporary files of interrupted writes.

    (The viability runner's chunk files; a study's points are in :func:`study_file`.)
    """
    if cache is None:
        return set()
    try:  # a link in its place is refused: never list or delete another folder's files
        _safefile.folder(cache.parent, cache, create=False)
    except FileNotFoundError:
        return set()
    names = set()
    for entry in os.scandir(cache):
        if entry.name.startswith("."):  # an atomic write that was killed midway
            Path(entry.path).unlink(missing_ok=True)
        else:
            names.add(entry.name)
    return names


def saved_points(spec: StudySpec, out_dir: str | Path) -> int:
    """How many of the study's points ``out_dir/cache`` holds."""
    stored = _store.read(study_file(spec, out_dir), root=out_dir)
    return sum(k in stored for _, _, keys in study_keys(spec) for k in keys)


def _save(writer: _store.Writer, key: str, rec: dict[str, Any]) -> None:
    """Cache one final point."""
    writer.add(key, rec)


def _solve_task(spec: StudySpec, assignment: dict[str, float], values: list[float],
                keys: list[str], cached: dict[float, dict[str, Any]],
                seeds: dict[float, dict[str, float]] | None, cache: str | None,
                tick: Callable[[int], None] | None = None) -> Solved:
    """Find one line's gaits; its points without a gait are cached as final (in workers)."""
    tick = tick or _pool.notify
    with _writer(cache) as writer:

        def emit(i: int, rec: dict[str, Any]) -> None:
            _save(writer, keys[i], rec)
            tick(1)

        solve = solve_gaits if spec.model == "tslip" else _spatial_point().solve_gaits
        return solve(spec, assignment, values, seeds=seeds, cached=cached,
                     emit=emit)


def _analyse_task(spec: StudySpec, items: list[Pending], keys: list[str], cache: str | None,
                  tick: Callable[[int], None] | None = None) -> list[dict[str, Any]]:
    """Analyse solved points, caching each record as it is final (in workers)."""
    tick = tick or _pool.notify
    out = []
    analyse: Callable[[StudySpec, Any], dict[str, Any]] = (
        analyse_point if spec.model == "tslip" else _spatial_point().analyse_point)
    with _writer(cache) as writer:
        for item, key in zip(items, keys):
            rec = analyse(spec, item)
            _save(writer, key, rec)
            tick(1)
            out.append(rec)
    return out


#: Units of a study's result columns (:func:`tslip.sweeps.point.analyse_point`), besides
#: its axes' parameters. ``seconds`` is wall time.
STUDY_UNITS: dict[str, str] = {
    **COLUMN_UNITS,
    **dict.fromkeys(("n_trivial", "max_nontrivial", "min_nontrivial", "duty_factor",
                     "fast_running_index", *(f"abs_lambda_{j}" for j in range(1, 6)),
                     *(f"{kind}_status" for kind in ROBUSTNESS_UNITS)), "-"),
    **dict.fromkeys(("stance_time_predicted", "flight_time_predicted", "bounce_time"),
                    UNIT["time"]),
    "step_frequency": UNIT["frequency"],
    **ROBUSTNESS_UNITS,
    "seconds": "s",
}


@dataclass(frozen=True, repr=False)
class StudyResult(FrameTable, Result):
    """A study's tidy results: one row per point, axes first."""

    spec: StudySpec
    frame: pd.DataFrame
    meta: dict[str, Any] = field(default_factory=dict)

    def _repr_fields(self) -> dict[str, Any]:
        f = self.frame
        conv = int(f["converged"].sum()) if "converged" in f else None
        return {"name": self.spec.name, "points": len(f),
                "axes": tuple(a.param for a in self.spec.axes), "converged": conv}

    def to_dataframe(self) -> pd.DataFrame:
        """The table: one row per point, axes first (units of the axes and the results)."""
        base = self.spec.base
        if isinstance(base, spatial_spec.SpatialBase):
            units = {**_spatial_point().UNITS, **{a.param: base.unit(a.param)
                                               for a in self.spec.axes}}
        else:
            units = {**STUDY_UNITS, **{a.param: param_unit(a.param) or "-"
                                       for a in self.spec.axes}}
        return with_units(self.frame.copy(), units)

    def plot(self, ax: Axes | None = None) -> Figure:
        """Non-trivial multiplier magnitudes against the last axis; stable domain shaded."""
        from ..plotting.studies import plot_study_multipliers

        return plot_study_multipliers(self, ax)

    def column(self, name: str) -> np.ndarray:
        """One result column as an array."""
        return self.frame[name].to_numpy()

    def grid(self, name: str) -> np.ndarray:
        """A column reshaped to the axes' shape (2-D studies)."""
        return self.frame[name].to_numpy().reshape(self.spec.shape)


def run_study(
    spec: StudySpec,
    out_dir: str | Path | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Progress | None = None,
    csv: bool = False,
    wait: bool = False,
) -> StudyResult:
    """Run (or resume) a study and return its results.

    Parameters
    ----------
    spec : StudySpec
    out_dir : path, optional
        Study folder: ``cache/`` (a JSON line per point, :mod:`tslip.sweeps._store`),
        ``results.parquet``
        (and ``results.csv`` with ``csv=True``), ``run.json`` and ``.lock``.
        Without it nothing is cached or written.
    workers : int, optional
        Worker processes (1 runs in this process). Default: by the work
        left, up to all cores (:func:`tslip.sweeps._schedule.choose_workers`).
    scheduler : str, optional
        Address of a Dask distributed scheduler (``tslip[dask]``); the same
        lines then run on that cluster.
    progress : callable, optional
        ``progress(points_done, points_total)`` as points finish.
    wait : bool
        If another run holds ``out_dir``, wait for it instead of raising.

    Returns
    -------
    StudyResult

    Raises
    ------
    StudyInterrupted
        On Ctrl-C, after stopping the workers; the finished points stay cached.
    tslip.sweeps._lock.FolderLocked
        If another live run holds ``out_dir`` (a ValueError).
    """
    if workers is not None and workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    try:
        if out_dir is None:
            return _run(spec, None, workers, scheduler, progress, csv)
        with folder_lock(out_dir, wait=wait):
            return _run(spec, Path(out_dir), workers, scheduler, progress, csv)
    except KeyboardInterrupt:  # the workers are stopped by now
        saved = saved_points(spec, out_dir) if out_dir is not None else 0
        raise StudyInterrupted(saved, spec.n_points) from None


def _run(spec: StudySpec, out: Path | None, n_workers: int | None, scheduler: str | None,
         progress: Progress | None, csv: bool) -> StudyResult:
    job = StudyJob(spec, out, progress, writes=scheduler is None)
    workers = 1 if scheduler is not None else choose_workers(job.cost, n_workers)
    timing: dict[Hashable, tuple[float, float, Hashable]] = {}
    if spec.model != "tslip" and job.missing and scheduler is None:  # 3-D: compiled here
        _warmup.ensure(_warmup.MODEL_FAMILIES[spec.model])  # once, before any worker needs them
    run_tasks(job.start(), job.on_done, workers, tick=job.tick, timing=timing,
              scheduler=scheduler,
              # compiles the planar kernels missing from numba's cache once, pre-fork (a 3-D
              # study runs none of them)
              preload=["tslip.sweeps._prewarm"] if spec.model == "tslip" else [])
    return job.result(workers, scheduler, csv, timing)


#: Estimated seconds per point (warm compile cache, one core): its gait
#: solve, and each analysis. They order the tasks (largest first) and size
#: the analysis chunks and the worker count; they need not be exact, but
#: within about 2x: ``benchmarks/bench_study_costs.py`` prints each catalogue
#: study's CPU seconds against its estimate (a 40 x 40 grid with multipliers
#: 2.7-3.9 s, 1.7-2.4 ms a point; a 50-point line with robustness 0.55-2.1 s).
COST_SECONDS: dict[str, float] = {"solve": 0.002, "floquet": 0.0003, "stride": 0.002,
                                  "robustness": 0.02}
#: Aimed-at seconds of one task of analyses: points are analysed in chunks
#: about this long (one point at least).
CHUNK_SECONDS = 0.4


class StudyJob:
    """A study as scheduler tasks (:mod:`tslip.sweeps._schedule`).

    Each line is a solve task (:func:`tslip.sweeps.point.solve_gaits`); when
    it is done its successors in the 2-D continuation are ready (seeded with
    its gaits) and its solved points are analysed in chunks of about
    :data:`CHUNK_SECONDS`, each point cached the moment it is final by the
    process that computed it (``writes``; else here, as it arrives). Cached
    points are replayed, not recomputed. :meth:`result` assembles and writes
    the study's table.
    """

    def __init__(self, spec: StudySpec, out: Path | None, progress: Progress | None = None,
                 writes: bool = True) -> None:
        t0 = time.perf_counter()
        self.spec, self.out, self.writes = spec, out, writes
        self.cache = study_file(spec, out) if out is not None else None
        self.plan = study_keys(spec)
        self.progress = progress
        self.n_total = spec.n_points
        # this run holds the folder's lock: a line torn by a killed run is cut off
        stored = (_store.read(self.cache, repair=True, root=out)
                  if self.cache is not None and out is not None else {})
        self.records: list[list[dict[str, Any] | None]] = [
            [stored.get(k) for k in keys] for _, _, keys in self.plan]
        n_cached = sum(r is not None for line in self.records for r in line)
        self.n_cached = self.done = n_cached
        if progress:
            progress(n_cached, self.n_total)
        self.pred, self.succ = _chains(spec)
        self.inner = spec.axes[-1].param
        self.seeds: list[dict[float, dict[str, float]] | None] = [None] * len(self.plan)
        self.costs = (COST_SECONDS if spec.model == "tslip"
                      else _spatial_point().COST_SECONDS[spec.model])
        self.per_point = sum(self.costs[a] for a in set(spec.analyses))
        self.depth = [0] * len(self.plan)
        for i in sorted(range(len(self.plan)), key=self._chain_index, reverse=True):
            self.depth[i] = 1 + max((self.depth[j] for j in self.succ[i]), default=0)
        self.load_seconds = time.perf_counter() - t0  # reading the cache

    def _chain_index(self, i: int) -> int:
        """Distance of line ``i`` from its chain's root."""
        n = 0
        while self.pred[i] is not None:
            i, n = self.pred[i], n + 1  # type: ignore[assignment]
        return n

    @property
    def missing(self) -> int:
        """Points not cached yet."""
        return sum(r is None for line in self.records for r in line)

    @property
    def cost(self) -> float:
        """Estimated seconds of the work left."""
        return self.missing * (self.costs["solve"] + self.per_point)

    def tick(self, n: int) -> None:
        """``n`` more points are final."""
        self.done += n
        if self.progress:
            self.progress(min(self.done, self.n_total), self.n_total)

    @property
    def finished(self) -> bool:
        return self.missing == 0

    def start(self) -> list[Task]:
        """The tasks ready at the start: the roots of the continuation chains."""
        return self._ready([i for i in range(len(self.plan)) if self.pred[i] is None])

    def _ready(self, lines: list[int]) -> list[Task]:
        out: list[Task] = []
        while lines:
            i = lines.pop(0)
            if any(r is None for r in self.records[i]):
                out.append(self._solve(i))
            else:  # fully cached: its successors may start
                self.seeds[i] = seeds_from_records(self.records[i], self.inner)
                lines.extend(self.succ[i])
        return out

    def _cache_arg(self) -> str | None:
        return str(self.cache) if self.cache is not None and self.writes else None

    def _solve(self, i: int) -> Task:
        assignment, values, keys = self.plan[i]
        cached = {v: r for v, r in zip(values, self.records[i]) if r is not None}
        p = self.pred[i]
        seeds = None if p is None else self.seeds[p]
        n_new = len(values) - len(cached)
        cost = n_new * self.costs["solve"]
        chunk = min(n_new * self.per_point, max(CHUNK_SECONDS, self.per_point))
        return Task((self.spec.name, "solve", i), _solve_task,
                    (self.spec, assignment, values, keys, cached, seeds, self._cache_arg()),
                    cost, priority=cost * self.depth[i] + chunk)

    def on_done(self, task: Task, result: Any) -> list[Task]:
        """A task of this study is done: keep its records; the tasks it made ready."""
        i = task.key[1 + 1]
        line = self.records[i]
        if task.key[1] == "solve":
            fresh = [(k, r) for k, o, r in zip(self.plan[i][2], line, result.records)
                     if o is None and r is not None]
            self._keep(fresh)
            for j, r in enumerate(result.records):
                if r is not None:
                    line[j] = r
            self.seeds[i] = result.seeds
            return self._chunks(i, result.pending) + self._ready(list(self.succ[i]))
        items = task.args[1]
        keys = self.plan[i][2]
        self._keep([(keys[it.index], r) for it, r in zip(items, result)])
        for it, r in zip(items, result):
            line[it.index] = r
        return []

    def _keep(self, fresh: list[tuple[str, dict[str, Any]]]) -> None:
        """Records computed where the cache is not (Dask): cache them here."""
        if self.writes:
            return
        if self.cache is not None:
            with _writer(self.cache) as writer:
                for k, r in fresh:
                    _save(writer, k, r)
        self.tick(len(fresh))

    def _chunks(self, i: int, pending: list[Pending]) -> list[Task]:
        size = max(1, int(CHUNK_SECONDS // max(self.per_point, 1e-9)))
        keys = self.plan[i][2]
        out = []
        for c in range(0, len(pending), size):
            items = pending[c:c + size]
            cost = len(items) * self.per_point
            out.append(Task((self.spec.name, "analyse", i, c), _analyse_task,
                            (self.spec, items, [keys[it.index] for it in items],
                             self._cache_arg()), cost))
        return out

    def result(self, workers: int, scheduler: str | None = None, csv: bool = False,
               timing: Timing | None = None) -> StudyResult:
        """The study's table (written to its folder, with ``run.json``).

        ``meta["seconds"]`` is the study's own time: reading its cache and the wall
        seconds of its tasks in ``timing`` (:func:`tslip.sweeps._schedule.run_tasks`).
        """
        spec, out = self.spec, self.out
        if self.progress:
            self.progress(self.n_total, self.n_total)
        by_point = {tuple(r[a.param] for a in spec.axes): r for line in self.records
                    for r in line if r is not None}
        frame = pd.DataFrame([by_point[pt] for pt in _points(spec)])
        frame = frame.drop(columns=[c for c in frame.columns if c.startswith("_")])
        meta = {
            "tslip_version": __version__, "code": _code(spec), "git": git_hash(),
            "study": spec.to_dict(), "points": self.n_total,
            "computed": self.n_total - self.n_cached, "cached": self.n_cached,
            "seconds": self.load_seconds + own_seconds(timing or {}, (spec.name,)),
            "workers": workers,
            "scheduler": scheduler,
            **({"tol": gait_tol(spec)} if spec.model == "tslip" else {"model": spec.model}),
        }
        if out is not None:
            write_table(frame, out / "results.parquet")
            if csv:
                write_table(frame, out / "results.csv")
            write_json(out / "run.json", meta)
        return StudyResult(spec, frame, meta)


def _points(spec: StudySpec) -> list[tuple[float, ...]]:
    if len(spec.axes) == 1:
        return [(v,) for v in spec.axes[0].values]
    return [(a, b) for a in spec.axes[0].values for b in spec.axes[1].values]


def _chains(spec: StudySpec) -> tuple[list[int | None], list[list[int]]]:
    """Predecessor and successors of each line (2-D continuation order)."""
    n = len(spec.lines())
    if len(spec.axes) == 1:
        return [None], [[]]
    if spec.model != "tslip":  # 3-D points are independent: so are the lines
        return [None] * n, [[] for _ in range(n)]
    outer = np.asarray(spec.axes[0].values)
    i0 = int(np.argmin(np.abs(outer - get_param(spec.base, spec.axes[0].param))))  # type: ignore[arg-type]
    pred: list[int | None] = [i + 1 if i < i0 else i - 1 for i in range(n)]
    pred[i0] = None
    succ: list[list[int]] = [[] for _ in range(n)]
    for i, p in enumerate(pred):
        if p is not None:
            succ[p].append(i)
    return pred, succ
