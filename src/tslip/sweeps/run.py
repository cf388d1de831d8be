"""Run a study: continuation lines in parallel, a resumable per-point cache.

Work is split into continuation lines (:meth:`StudySpec.lines`). Each line is
solved by :func:`tslip.gait.continue_gait` (warm starts from neighbours) and
each of its gaits is analysed (multipliers, robustness, stride). Lines run in
worker processes (all cores by default), or on a Dask cluster given its
address, and return plain records; the calling process writes every point to
the cache as soon as its line is done, atomically. The cache key is a hash of
the point's full parameters, the analyses and the package version, so

* an interrupted study resumes with only the missing points,
* a finished study reruns instantly,
* changing a parameter or upgrading the package recomputes.

A point without a periodic gait is a record with ``converged = False`` and
``stability = "none"``, not an error.
"""

from __future__ import annotations

import concurrent.futures as cf
import hashlib
import json
import math
import multiprocessing as mp
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .. import __version__
from .._io import atomic_write, write_table
from ..gait.continuation import continue_gait
from ..gait.robustness import KINDS, robustness_report
from ..gait.stride import stride_properties
from .spec import StudySpec

__all__ = ["StudyResult", "run_study", "point_key", "solve_line"]

Progress = Callable[[int, int], None]


def point_key(spec: StudySpec, assignment: dict[str, float]) -> str:
    """Cache key of one point: its full parameters, the analyses, the version."""
    payload = {
        "version": __version__,
        "params": spec.params_at(assignment).to_dict(),
        "analyses": sorted(spec.analyses),
        "n_steps": spec.n_steps if "robustness" in spec.analyses else None,
    }
    blob = json.dumps(payload, sort_keys=True, default=float).encode()
    return hashlib.sha256(blob).hexdigest()[:24]


def _num(x: Any) -> float:
    try:
        x = float(x)
    except (TypeError, ValueError):
        return math.nan
    return x


def solve_line(spec: StudySpec, assignment: dict[str, float],
               values: list[float]) -> list[dict[str, Any]]:
    """Solve and analyse the points of one continuation line.

    Pure: returns one record (a flat dict of numbers and strings) per value;
    runs in worker processes.
    """
    inner = spec.axes[-1].param
    params = spec.params_at(assignment)
    t0 = time.perf_counter()
    branch = continue_gait(params, inner, np.asarray(values, dtype=float), max_failures=3)
    records = []
    for i, v in enumerate(branch.values):
        g = branch.gaits[i]
        rec: dict[str, Any] = {**assignment, inner: float(v)}
        rec["converged"] = bool(branch.converged[i])
        rec["residual"] = _num(branch.residual[i])
        rec["stability"] = branch.stability[i] if g is not None else "none"
        mags = np.sort(np.abs(branch.multipliers[i]))[::-1]
        mags_nt = np.abs(branch.multipliers[i])[~branch.trivial[i]]
        for j in range(5):
            rec[f"abs_lambda_{j + 1}"] = _num(mags[j]) if j < len(mags) else math.nan
        rec["max_nontrivial"] = _num(branch.max_nontrivial[i])
        rec["n_trivial"] = int(np.sum(branch.trivial[i]))
        rec["min_nontrivial"] = _num(mags_nt.min()) if mags_nt.size and g else math.nan
        rec["stance_time"] = _num(branch.stance_time[i])
        rec["flight_time"] = _num(branch.flight_time[i])
        if g is not None:
            s = g.state
            rec.update(delta=s.delta, phi=s.phi, phid=s.phid, alpha_r=g.params.alpha_r)
            ctrl = g.params.controller
            rec["alphad_ref"] = _num(getattr(ctrl, "alphad_ref", math.nan))
            rec["tau_c"] = _num(getattr(ctrl, "tau_c", math.nan))
        if "stride" in spec.analyses and g is not None:
            sp = stride_properties(g)
            rec.update(duty_factor=sp.duty_factor, step_frequency=sp.step_frequency,
                       stance_time_predicted=sp.stance_time_predicted,
                       flight_time_predicted=sp.flight_time_predicted,
                       fast_running_index=sp.fast_running_index, bounce_time=sp.bounce_time)
        if "robustness" in spec.analyses:
            for kind in KINDS:
                rec[kind] = math.nan
                rec[f"{kind}_status"] = ""
            if g is not None and g.converged and rec["stability"] in ("asymptotic", "neutral"):
                rr = robustness_report(g, n_steps=spec.n_steps, check=False)
                for lim in rr.limits:
                    rec[lim.kind] = _num(lim.limit)
                    rec[f"{lim.kind}_status"] = lim.status.name if lim.status else ""
        rec["message"] = branch.messages[i]
        records.append(rec)
    dt = (time.perf_counter() - t0) / max(len(records), 1)
    for rec in records:
        rec["seconds"] = dt
    return records


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


def _init_worker() -> None:  # pragma: no cover - runs in worker processes
    import numba

    numba.set_num_threads(1)  # one process per core; no nested threads


def _git_hash() -> str | None:
    from ..simulation.result import _git_hash as gh

    return gh()


def run_study(
    spec: StudySpec,
    out_dir: str | Path | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Progress | None = None,
    csv: bool = False,
) -> StudyResult:
    """Run (or resume) a study and return its results.

    Parameters
    ----------
    spec : StudySpec
    out_dir : path, optional
        Study folder: ``cache/`` (one JSON per point), ``results.parquet``
        (and ``results.csv`` with ``csv=True``) and ``run.json``. Without it
        nothing is cached or written.
    workers : int, optional
        Worker processes (default: all cores; 1 runs in this process).
    scheduler : str, optional
        Address of a Dask distributed scheduler (``tslip[dask]``); the same
        lines then run on that cluster.
    progress : callable, optional
        ``progress(points_done, points_total)`` after each line.

    Returns
    -------
    StudyResult
    """
    t_start = time.perf_counter()
    cache = Path(out_dir) / "cache" if out_dir is not None else None
    lines = spec.lines()
    inner = spec.axes[-1]
    keys: dict[tuple, str] = {}
    records: dict[str, dict[str, Any]] = {}
    tasks: list[tuple[dict[str, float], list[float]]] = []
    for assignment, axis in lines:
        missing = []
        for v in axis.values:
            point = {**assignment, inner.param: v}
            key = point_key(spec, point)
            keys[tuple(point[a.param] for a in spec.axes)] = key
            f = cache / f"{key}.json" if cache is not None else None
            if f is not None and f.exists():
                records[key] = json.loads(f.read_text())
            else:
                missing.append(v)
        if missing:
            tasks.append((assignment, missing))
    n_total = spec.n_points
    n_cached = len(records)
    done = n_cached
    if progress:
        progress(done, n_total)

    def store(recs: list[dict[str, Any]]) -> None:
        nonlocal done
        for rec in recs:
            key = keys[tuple(rec[a.param] for a in spec.axes)]
            records[key] = rec
            if cache is not None:
                text = json.dumps(rec, default=float)
                atomic_write(cache / f"{key}.json", lambda tmp, t=text: Path(tmp).write_text(t))
        done += len(recs)
        if progress:
            progress(done, n_total)

    n_workers = workers if workers is not None else (os.cpu_count() or 1)
    if n_workers < 1:
        raise ValueError(f"workers must be >= 1, got {n_workers}")
    if scheduler is not None:
        _run_dask(scheduler, spec, tasks, store)
    elif n_workers == 1 or len(tasks) <= 1:
        for assignment, values in tasks:
            store(solve_line(spec, assignment, values))
    else:
        ctx = mp.get_context("spawn")  # numba threads and fork do not mix
        with cf.ProcessPoolExecutor(max_workers=min(n_workers, len(tasks)), mp_context=ctx,
                                    initializer=_init_worker) as pool:
            futures = [pool.submit(solve_line, spec, a, v) for a, v in tasks]
            try:
                for fut in cf.as_completed(futures):
                    store(fut.result())
            except BaseException:
                for fut in futures:
                    fut.cancel()
                raise
    rows = [records[keys[tuple(pt)]] for pt in _points(spec)]
    frame = pd.DataFrame(rows)
    meta = {
        "tslip_version": __version__, "git": _git_hash(), "study": spec.to_dict(),
        "points": n_total, "computed": n_total - n_cached, "cached": n_cached,
        "seconds": time.perf_counter() - t_start, "workers": n_workers,
        "scheduler": scheduler,
    }
    if out_dir is not None:
        out = Path(out_dir)
        write_table(frame, out / "results.parquet")
        if csv:
            write_table(frame, out / "results.csv")
        atomic_write(out / "run.json", lambda tmp: Path(tmp).write_text(
            json.dumps(meta, indent=2, default=float)))
    return StudyResult(spec, frame, meta)


def _points(spec: StudySpec) -> list[tuple[float, ...]]:
    if len(spec.axes) == 1:
        return [(v,) for v in spec.axes[0].values]
    return [(a, b) for a in spec.axes[0].values for b in spec.axes[1].values]


def _run_dask(address: str, spec: StudySpec, tasks: list, store: Callable) -> None:
    try:
        from dask.distributed import Client, as_completed
    except ImportError:
        raise ValueError("--scheduler needs Dask: pip install 'tslip[dask]'") from None
    with Client(address) as client:
        futures = [client.submit(solve_line, spec, a, v, pure=False) for a, v in tasks]
        for fut in as_completed(futures):
            store(fut.result())
