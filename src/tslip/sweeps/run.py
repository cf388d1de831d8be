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
from .._io import atomic_write, git_hash, write_json, write_table
from ..gait.continuation import continue_gait, get_param
from ..gait.fixed_point import Gait, GaitProblem, find_gait
from ..gait.robustness import KINDS, robustness_report
from ..gait.stability import floquet
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
    if "tol" in spec.meta:  # a non-default gait tolerance (e.g. global PD) changes results
        payload["tol"] = float(spec.meta["tol"])
    if "neutral_tol" in spec.meta:
        payload["neutral_tol"] = float(spec.meta["neutral_tol"])
    blob = json.dumps(payload, sort_keys=True, default=float).encode()
    return hashlib.sha256(blob).hexdigest()[:24]


def _num(x: Any) -> float:
    try:
        x = float(x)
    except (TypeError, ValueError):
        return math.nan
    return x


def _seeded_gaits(spec: StudySpec, assignment: dict[str, float], values: np.ndarray,
                  seeds: dict[float, list[float]], tol: float,
                  known: list[Gait | None] | None = None) -> list[Gait | None]:
    """Gaits along a line, grown from seeds (2-D continuation).

    First every point with a seed (its neighbour's unknowns in the previous
    line) starts once from it; then the solved points grow outward along the
    line, each unsolved neighbour starting once from an adjacent solution. No
    automatic guesses: a point without a gait costs one short least-squares run
    per attempt.
    """
    inner = spec.axes[-1].param
    n = len(values)
    gaits: list[Gait | None] = list(known) if known is not None else [None] * n
    problems = {}

    def attempt(i: int, z: list[float] | np.ndarray) -> bool:
        if i not in problems:
            p = spec.params_at({**assignment, inner: float(values[i])})
            problems[i] = (p, GaitProblem.from_params(p).names)
        p, names = problems[i]
        if len(z) != len(names) or not np.all(np.isfinite(z)):
            return False
        g = find_gait(p, guess=np.asarray(z, dtype=float), tol=tol)
        if g.converged:
            gaits[i] = g
        return g.converged

    for i in range(n):
        if gaits[i] is None and float(values[i]) in seeds:
            attempt(i, seeds[float(values[i])])
    tried: set[tuple[int, int]] = set()
    grown = True
    while grown:
        grown = False
        for i in range(n):
            if gaits[i] is None:
                continue
            for j in (i - 1, i + 1):
                if 0 <= j < n and gaits[j] is None and (i, j) not in tried:
                    tried.add((i, j))
                    names = problems[j][1] if j in problems else GaitProblem.from_params(
                        spec.params_at({**assignment, inner: float(values[j])})).names
                    grown |= attempt(j, _unknowns(gaits[i], names))
    return gaits


def _scan_line(spec: StudySpec, assignment: dict[str, float], values: np.ndarray,
               tol: float, n_probe: int = 10) -> list[Gait | None]:
    """Cold searches at ``n_probe`` evenly spread values, then grow from any found."""
    inner = spec.axes[-1].param
    gaits: list[Gait | None] = [None] * len(values)
    for i in np.unique(np.linspace(0, len(values) - 1, min(n_probe, len(values))).round()):
        i = int(i)
        g = find_gait(spec.params_at({**assignment, inner: float(values[i])}), tol=tol)
        if g.converged:
            gaits[i] = g
    if any(g is not None for g in gaits):
        gaits = _seeded_gaits(spec, assignment, values, {}, tol, known=gaits)
    return gaits


def _unknowns(g: Gait, names: tuple[str, ...]) -> list[float]:
    src = {"delta": g.state.delta, "phi": g.state.phi, "phid": g.state.phid,
           "alpha_r": g.params.alpha_r,
           "alphad_ref": getattr(g.params.controller, "alphad_ref", math.nan),
           "tau_c": getattr(g.params.controller, "tau_c", math.nan)}
    return [float(src[n]) for n in names]


def seeds_from_records(spec: StudySpec, records: list[dict[str, Any]]) -> dict[float, list]:
    """Unknowns of a solved line, by inner value, to seed its neighbour line."""
    inner = spec.axes[-1].param
    out = {}
    for rec in records:
        if rec.get("converged"):
            out[float(rec[inner])] = [rec.get(n, math.nan) for n in
                                      ("delta", "phi", "phid", "alpha_r", "alphad_ref",
                                       "tau_c")]
    return out


def solve_line(spec: StudySpec, assignment: dict[str, float], values: list[float],
               seeds: dict[float, list] | None = None) -> list[dict[str, Any]]:
    """Solve and analyse the points of one continuation line.

    Pure: returns one record (a flat dict of numbers and strings) per value;
    runs in worker processes. Without ``seeds`` the line is followed by
    :func:`continue_gait` from a cold start; with ``seeds`` (the unknowns of
    the neighbouring line, see :func:`seeds_from_records`) each point starts
    from its neighbour's solution, as 2-D continuation.
    """
    inner = spec.axes[-1].param
    params = spec.params_at(assignment)
    t0 = time.perf_counter()
    tol = float(spec.meta.get("tol", 1e-10))  # global PD has no exact fixed point
    vals = np.sort(np.asarray(values, dtype=float))
    if seeds is None:  # a 1-D study or the root line of a grid: cold start
        branch = continue_gait(params, inner, vals, tol=tol, max_failures=3, multipliers=False)
        gaits = list(branch.gaits)
        residual = list(branch.residual)
        messages = list(branch.messages)
        if len(spec.axes) == 2 and not any(g is not None for g in gaits):
            # the base value may lie outside the gait's band: probe along the line
            gaits = _scan_line(spec, assignment, vals, tol)
            residual = [g.residual if g is not None else math.nan for g in gaits]
            messages = ["found by probing the line" if g is not None else
                        "no periodic gait found along this line" for g in gaits]
    else:  # seeded from the neighbouring line (empty seeds: it had no gait)
        names = GaitProblem.from_params(params).names
        full = {v: [z[("delta", "phi", "phid", "alpha_r", "alphad_ref", "tau_c").index(n)]
                    for n in names] for v, z in seeds.items()}
        gaits = _seeded_gaits(spec, assignment, vals, full, tol)
        residual = [g.residual if g is not None else math.nan for g in gaits]
        messages = ["continued from the neighbouring line" if g is not None else
                    "no periodic gait continuing from the neighbouring line" for g in gaits]
    neutral_tol = float(spec.meta.get("neutral_tol", 1e-6))
    records = []
    for i, v in enumerate(vals):
        g = gaits[i]
        rec: dict[str, Any] = {**assignment, inner: float(v)}
        rec["converged"] = g is not None and bool(g.converged)
        rec["residual"] = _num(residual[i])
        fl = None
        if g is not None:
            try:
                fl = floquet(g, unit_tol=neutral_tol)
            except ValueError:
                fl = None
        rec["stability"] = (fl.stability if fl is not None else
                            ("unknown" if g is not None else "none"))
        mags = np.sort(np.abs(fl.multipliers))[::-1] if fl is not None else np.full(5, np.nan)
        for j in range(5):
            rec[f"abs_lambda_{j + 1}"] = _num(mags[j])
        rec["max_nontrivial"] = _num(fl.max_nontrivial) if fl is not None else math.nan
        rec["n_trivial"] = int(np.sum(fl.trivial)) if fl is not None else 0
        nt = np.abs(fl.multipliers[~fl.trivial]) if fl is not None else np.array([])
        rec["min_nontrivial"] = _num(nt.min()) if nt.size else math.nan
        rec["stance_time"] = _num(g.stance_time) if g is not None else math.nan
        rec["flight_time"] = _num(g.flight_time) if g is not None else math.nan
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
            if g is not None and rec["converged"] and rec["stability"] in ("asymptotic",
                                                                            "neutral"):
                rr = robustness_report(g, n_steps=spec.n_steps, check=False)
                for lim in rr.limits:
                    rec[lim.kind] = _num(lim.limit)
                    rec[f"{lim.kind}_status"] = lim.status.name if lim.status else ""
        rec["message"] = messages[i]
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
    missing: list[list[float]] = []
    for assignment, axis in lines:
        miss = []
        for v in axis.values:
            point = {**assignment, inner.param: v}
            key = point_key(spec, point)
            keys[tuple(point[a.param] for a in spec.axes)] = key
            f = cache / f"{key}.json" if cache is not None else None
            if f is not None and f.exists():
                records[key] = json.loads(f.read_text())
            else:
                miss.append(v)
        missing.append(miss)
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

    # 2-D studies: lines form two chains outward from the line nearest the base
    # value; each line is seeded with its predecessor's solutions.
    pred, succ = _chains(spec)

    def seeds(i: int) -> dict[float, list] | None:
        if pred[i] is None:
            return None
        assignment, axis = lines[pred[i]]
        recs = [records[keys[tuple({**assignment, inner.param: v}[a.param]
                                   for a in spec.axes)]] for v in axis.values]
        return seeds_from_records(spec, recs)

    n_workers = workers if workers is not None else (os.cpu_count() or 1)
    if n_workers < 1:
        raise ValueError(f"workers must be >= 1, got {n_workers}")
    ready = [i for i in range(len(lines)) if pred[i] is None]
    with _executor(scheduler, n_workers, len(lines)) as ex:
        running: dict[Any, int] = {}
        try:
            while ready or running:
                while ready:
                    i = ready.pop(0)
                    if missing[i]:
                        running[ex.submit(solve_line, spec, lines[i][0], missing[i],
                                          seeds(i))] = i
                    else:
                        ready.extend(succ[i])  # fully cached: its successors may start
                if running:
                    for fut in ex.wait_first(list(running)):
                        i = running.pop(fut)
                        store(fut.result())
                        ready.extend(succ[i])
        except BaseException:
            for fut in running:
                fut.cancel()
            raise
    rows = [records[keys[tuple(pt)]] for pt in _points(spec)]
    frame = pd.DataFrame(rows)
    meta = {
        "tslip_version": __version__, "git": git_hash(), "study": spec.to_dict(),
        "points": n_total, "computed": n_total - n_cached, "cached": n_cached,
        "seconds": time.perf_counter() - t_start, "workers": n_workers,
        "scheduler": scheduler, "tol": float(spec.meta.get("tol", 1e-10)),
    }
    if out_dir is not None:
        out = Path(out_dir)
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
    """Runs each task when submitted; same interface as the pools below."""

    def __enter__(self) -> _Serial:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def submit(self, fn: Callable, *args: Any) -> cf.Future:
        fut: cf.Future = cf.Future()
        fut.set_result(fn(*args))
        return fut

    @staticmethod
    def wait_first(futs: list) -> list:
        return futs


class _Pool(_Serial):
    def __init__(self, n: int) -> None:
        ctx = mp.get_context("spawn")  # numba threads and fork do not mix
        self.pool = cf.ProcessPoolExecutor(max_workers=n, mp_context=ctx,
                                           initializer=_init_worker)

    def __enter__(self) -> _Pool:
        return self

    def __exit__(self, *exc: object) -> None:
        self.pool.shutdown(wait=True, cancel_futures=True)

    def submit(self, fn: Callable, *args: Any) -> cf.Future:
        return self.pool.submit(fn, *args)

    @staticmethod
    def wait_first(futs: list) -> list:
        return list(cf.wait(futs, return_when=cf.FIRST_COMPLETED).done)


class _Dask(_Serial):
    def __init__(self, address: str) -> None:
        try:
            from dask.distributed import Client
        except ImportError:
            raise ValueError("--scheduler needs Dask: pip install 'tslip[dask]'") from None
        self.client = Client(address)

    def __enter__(self) -> _Dask:
        return self

    def __exit__(self, *exc: object) -> None:
        self.client.close()

    def submit(self, fn: Callable, *args: Any) -> Any:
        return self.client.submit(fn, *args, pure=False)

    @staticmethod
    def wait_first(futs: list) -> list:
        from dask.distributed import wait

        return list(wait(futs, return_when="FIRST_COMPLETED").done)


def _executor(scheduler: str | None, workers: int, n_lines: int) -> _Serial:
    if scheduler is not None:
        return _Dask(scheduler)
    if workers == 1 or n_lines <= 1:
        return _Serial()
    return _Pool(min(workers, n_lines))
