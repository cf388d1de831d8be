"""Run a study: continuation lines in parallel, every point cached as it finishes.

Work is split into continuation lines (:meth:`StudySpec.lines`), solved
point by point by :func:`tslip.sweeps.point.solve_line`. Lines run in worker
processes (all cores by default; see :mod:`tslip.sweeps._pool`), or on a
Dask cluster given its address. Each point is written to ``cache/`` the
moment it is final, atomically, by the process that computed it, and the
progress callback advances with it. The cache key is a hash of the study's
base parameters, the point's axis values, the analyses and the code that
computes them (:func:`tslip.sweeps.point.code_version`), so

* an interrupted study resumes with only the missing points, and ends
  bit-identical to an uninterrupted run (a line replays its cached points),
* a finished study reruns instantly,
* changing a parameter, or the code behind an analysis, recomputes the
  points it affects and no others.

One run at a time per output folder (``.lock``, :mod:`tslip.sweeps._lock`).
Ctrl-C stops the workers and raises :class:`StudyInterrupted` ("N of M
points saved"). A point without a periodic gait is a record with
``converged = False`` and ``stability = "none"``, not an error. On a Dask
cluster the points of a line are cached when the line is done.
"""

from __future__ import annotations

import concurrent.futures as cf
import hashlib
import json
import os
import queue as queue_mod
import time
from collections.abc import Callable
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .. import __version__
from .._io import atomic_write, git_hash, write_json, write_table
from ..gait.continuation import get_param
from . import _pool
from ._lock import folder_lock
from .point import code_version, seeds_from_records, solve_line
from .spec import StudySpec

__all__ = ["StudyInterrupted", "StudyResult", "run_study", "point_key", "saved_points",
           "study_keys"]

Progress = Callable[[int, int], None]


class StudyInterrupted(KeyboardInterrupt):
    """Ctrl-C during a study: how many of its points are saved."""

    def __init__(self, saved: int, total: int) -> None:
        super().__init__(saved, total)
        self.saved, self.total = saved, total

    def __str__(self) -> str:
        return f"{self.saved} of {self.total} points saved; rerun the same command to resume"


def _key_prefix(spec: StudySpec) -> Any:
    """The hash state shared by a study's points: code, base parameters, analyses."""
    payload: dict[str, Any] = {
        "code": code_version(spec.analyses),
        "base": spec.base.to_dict(),
        "axes": [a.param for a in spec.axes],
        "analyses": sorted(spec.analyses),
        "n_steps": spec.n_steps if "robustness" in spec.analyses else None,
    }
    if "tol" in spec.meta:  # a non-default gait tolerance (e.g. global PD) changes results
        payload["tol"] = float(spec.meta["tol"])
    if "neutral_tol" in spec.meta:
        payload["neutral_tol"] = float(spec.meta["neutral_tol"])
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


def _cached_names(cache: Path | None) -> set[str]:
    """File names in the cache; removes temporary files of interrupted writes."""
    if cache is None or not cache.is_dir():
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
    names = _cached_names(Path(out_dir) / "cache")
    return sum(f"{k}.json" in names for _, _, keys in study_keys(spec) for k in keys)


def _save(cache: Path, key: str, rec: dict[str, Any]) -> None:
    text = json.dumps(rec)
    atomic_write(cache / f"{key}.json", lambda tmp: Path(tmp).write_text(text))


def _line_task(spec: StudySpec, assignment: dict[str, float], values: list[float],
               keys: list[str], cached: dict[float, dict[str, Any]],
               seeds: dict[float, dict[str, float]] | None, cache: str | None,
               tick: Callable[[int], None] | None = None) -> list[dict[str, Any]]:
    """Solve one line, caching each point as it is final (runs in workers)."""
    tick = tick or _pool.notify

    def emit(i: int, rec: dict[str, Any]) -> None:
        if cache is not None:
            _save(Path(cache), keys[i], rec)
        tick(1)

    return solve_line(spec, assignment, values, seeds=seeds, cached=cached, emit=emit)


@dataclass(frozen=True)
class StudyResult:
    """A study's tidy results: one row per point, axes first."""

    spec: StudySpec
    frame: pd.DataFrame
    meta: dict[str, Any] = field(default_factory=dict)

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
        Study folder: ``cache/`` (one JSON per point), ``results.parquet``
        (and ``results.csv`` with ``csv=True``), ``run.json`` and ``.lock``.
        Without it nothing is cached or written.
    workers : int, optional
        Worker processes (default: all cores; 1 runs in this process).
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
    n_workers = workers if workers is not None else (os.cpu_count() or 1)
    if n_workers < 1:
        raise ValueError(f"workers must be >= 1, got {n_workers}")
    try:
        if out_dir is None:
            return _run(spec, None, n_workers, scheduler, progress, csv)
        with folder_lock(out_dir, wait=wait):
            return _run(spec, Path(out_dir), n_workers, scheduler, progress, csv)
    except KeyboardInterrupt:  # the workers are stopped by now
        saved = saved_points(spec, out_dir) if out_dir is not None else 0
        raise StudyInterrupted(saved, spec.n_points) from None


def _run(spec: StudySpec, out: Path | None, n_workers: int, scheduler: str | None,
         progress: Progress | None, csv: bool) -> StudyResult:
    t_start = time.perf_counter()
    cache = out / "cache" if out is not None else None
    plan = study_keys(spec)
    n_total = spec.n_points
    names = _cached_names(cache)
    records: list[list[dict[str, Any] | None]] = []
    n_cached = 0
    for _, _, keys in plan:
        line: list[dict[str, Any] | None] = []
        for k in keys:
            rec = None
            if f"{k}.json" in names:
                try:
                    rec = json.loads((cache / f"{k}.json").read_text())  # type: ignore[operator]
                except ValueError:  # unreadable: compute it again
                    rec = None
            line.append(rec)
            n_cached += rec is not None
            if progress and n_cached % 5000 == 1:
                progress(n_cached, n_total)
        records.append(line)
    done = n_cached
    if progress:
        progress(done, n_total)

    def tick(n: int) -> None:
        nonlocal done
        done += n
        if progress:
            progress(min(done, n_total), n_total)

    # 2-D studies: lines form two chains outward from the line nearest the base
    # value; each line is seeded with its predecessor's solutions.
    pred, succ = _chains(spec)
    inner = spec.axes[-1].param

    def task(i: int, ex: _Serial) -> tuple:
        assignment, values, keys = plan[i]
        cached = {v: r for v, r in zip(values, records[i]) if r is not None}
        seeds = None if pred[i] is None else seeds_from_records(records[pred[i]], inner)
        return (_line_task, spec, assignment, values, keys, cached, seeds,
                str(cache) if cache is not None and ex.writes else None)

    ready = [i for i in range(len(plan)) if pred[i] is None]
    with _executor(scheduler, n_workers, len(plan), tick) as ex:
        running: dict[Any, int] = {}
        while ready or running:
            while ready:
                i = ready.pop(0)
                if any(r is None for r in records[i]):
                    running[ex.submit(*task(i, ex))] = i
                else:
                    ready.extend(succ[i])  # fully cached: its successors may start
            if running:
                for fut in ex.wait_first(list(running)):
                    i = running.pop(fut)
                    recs = fut.result()
                    if not ex.writes:
                        _keep(cache, plan[i][2], records[i], recs, tick)
                    records[i] = recs
                    ready.extend(succ[i])
            ex.poll()
    if progress:
        progress(n_total, n_total)
    by_point = {tuple(r[a.param] for a in spec.axes): r for line in records for r in line}
    frame = pd.DataFrame([by_point[pt] for pt in _points(spec)])  # type: ignore[index]
    frame = frame.drop(columns=[c for c in frame.columns if c.startswith("_")])
    meta = {
        "tslip_version": __version__, "code": code_version(spec.analyses), "git": git_hash(),
        "study": spec.to_dict(), "points": n_total, "computed": n_total - n_cached,
        "cached": n_cached, "seconds": time.perf_counter() - t_start, "workers": n_workers,
        "scheduler": scheduler, "tol": float(spec.meta.get("tol", 1e-10)),
    }
    if out is not None:
        write_table(frame, out / "results.parquet")
        if csv:
            write_table(frame, out / "results.csv")
        write_json(out / "run.json", meta)
    return StudyResult(spec, frame, meta)


def _keep(cache: Path | None, keys: list[str], old: list[dict[str, Any] | None],
          new: list[dict[str, Any]], tick: Callable[[int], None]) -> None:
    """Cache the new points of a line that ran where the cache is not (Dask)."""
    fresh = [(k, r) for k, o, r in zip(keys, old, new) if o is None]
    if cache is not None:
        for k, r in fresh:
            _save(cache, k, r)
    tick(len(fresh))


def _points(spec: StudySpec) -> list[tuple[float, ...]]:
    if len(spec.axes) == 1:
        return [(v,) for v in spec.axes[0].values]
    return [(a, b) for a in spec.axes[0].values for b in spec.axes[1].values]


def _chains(spec: StudySpec) -> tuple[list[int | None], list[list[int]]]:
    """Predecessor and successors of each line (2-D continuation order)."""
    n = len(spec.lines())
    if len(spec.axes) == 1:
        return [None], [[]]
    outer = np.asarray(spec.axes[0].values)
    i0 = int(np.argmin(np.abs(outer - get_param(spec.base, spec.axes[0].param))))
    pred: list[int | None] = [i + 1 if i < i0 else i - 1 for i in range(n)]
    pred[i0] = None
    succ: list[list[int]] = [[] for _ in range(n)]
    for i, p in enumerate(pred):
        if p is not None:
            succ[p].append(i)
    return pred, succ


class _Serial:
    """Runs each line when submitted, in this process."""

    writes = True  #: the tasks write the cache themselves

    def __init__(self, tick: Callable[[int], None]) -> None:
        self.tick = tick

    def __enter__(self) -> _Serial:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def submit(self, fn: Callable, *args: Any) -> cf.Future:
        fut: cf.Future = cf.Future()
        fut.set_result(fn(*args, self.tick))
        return fut

    def wait_first(self, futs: list) -> list:
        return futs

    def poll(self) -> None:
        return None


class _Pool(_Serial):
    """Worker processes (:func:`tslip.sweeps._pool.process_pool`); progress by queue."""

    def __init__(self, n: int, tick: Callable[[int], None]) -> None:
        super().__init__(tick)
        self.n = n
        self.stack = ExitStack()

    def __enter__(self) -> _Pool:
        self.queue = _pool.progress_queue()
        self.pool = self.stack.enter_context(_pool.process_pool(self.n, self.queue))
        return self

    def __exit__(self, *exc: Any) -> None:
        self.stack.__exit__(*exc)
        self.queue.close()

    def submit(self, fn: Callable, *args: Any) -> cf.Future:
        return self.pool.submit(fn, *args)

    def wait_first(self, futs: list) -> list:
        return list(cf.wait(futs, timeout=0.2, return_when=cf.FIRST_COMPLETED).done)

    def poll(self) -> None:
        n = 0
        try:
            while True:
                n += self.queue.get_nowait()
        except (queue_mod.Empty, OSError, ValueError):
            pass
        if n:
            self.tick(n)


class _Dask(_Serial):
    writes = False  # the cluster may not see the cache: this process writes it

    def __init__(self, address: str, tick: Callable[[int], None]) -> None:
        super().__init__(tick)
        try:
            from dask.distributed import Client
        except ImportError:
            raise ValueError("--scheduler needs Dask: pip install 'tslip[dask]'") from None
        self.client = Client(address)
        self.futures: list = []

    def __enter__(self) -> _Dask:
        return self

    def __exit__(self, *exc: object) -> None:
        if exc[0] is not None:
            self.client.cancel(self.futures)
        self.client.close()

    def submit(self, fn: Callable, *args: Any) -> Any:
        fut = self.client.submit(fn, *args, pure=False)
        self.futures.append(fut)
        return fut

    def wait_first(self, futs: list) -> list:
        from dask.distributed import wait

        return list(wait(futs, return_when="FIRST_COMPLETED").done)


def _executor(scheduler: str | None, workers: int, n_lines: int,
              tick: Callable[[int], None]) -> _Serial:
    if scheduler is not None:
        return _Dask(scheduler, tick)
    if workers == 1 or n_lines <= 1:
        return _Serial(tick)
    return _Pool(min(workers, n_lines), tick)
