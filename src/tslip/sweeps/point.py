"""The points of one study line: solved in continuation order, analysed, handed over one by one.

A line is the last axis of a study at fixed values of the others
(:meth:`StudySpec.lines`). Its gaits are found by natural continuation
(thesis Section 3.4; :func:`tslip.gait.continuation.continue_gait`'s walk:
outward from the base value, each point warm-started by the secant through
its last two neighbours) or, on a 2-D study's later lines, from the
neighbouring line's solutions. Solving and analysing are two steps, so
that a line's analyses (Floquet multipliers, eq. 3.4, always; stride
properties and robustness, Section 6.1, when the spec asks: most of a
point's cost) can run in parallel while the next line is solved from this
one's gaits: :func:`solve_gaits` walks the line and returns its gaits to
analyse (:class:`Solved`), :func:`analyse_point` analyses each; the
runner caches each record as it is final, so an interrupted line loses at
most the points in progress. :func:`solve_line` does both in
turn.

Resuming is a replay. The walk's path depends only on which attempts
succeeded and on the gaits found, so a line given its cached records
(``cached``) walks the same path without recomputing them: an attempt on a
cached point succeeds exactly when it succeeded originally (the record keeps
its attempt number, ``_attempt``), and the neighbours are seeded from the
record's unknowns ``(delta, phi, phid, alpha_r, alphad_ref | tau_c)``, the
same numbers, bit for bit, that a fresh run seeds them with (a fresh run
seeds from the stored record too). So a resumed line equals an uninterrupted
one exactly. A point without a gait is final only when the line is: its
record (``converged = False``, ``stability = "none"``) is emitted last.

:func:`code_version` is the hash of the code that computes a point with
given analyses: the cache key holds it, so editing e.g.
:mod:`tslip.gait.robustness` recomputes the points with a robustness
analysis, and only those.
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

import numpy as np

from .._codehash import code_hash, module_digest
from ..gait.continuation import _solve_point, get_param, set_param
from ..gait.fixed_point import Gait, GaitProblem, _search, find_gait
from ..gait.problem import thrust_solved
from ..gait.robustness import KINDS, robustness_report
from ..gait.stability import Floquet, floquet
from ..gait.stride import stride_properties
from ..model.parameters import Params
from .spec import StudySpec

__all__ = ["CODE", "MAX_FAILURES", "Pending", "Solved", "analyse_point", "code_version",
           "floquet_tol", "gait_tol", "seeds_from_records", "solve_gaits", "solve_line"]

#: The modules whose code computes a point, by analysis (``None``: every
#: point). Their import closures are hashed by :func:`code_version`; a test
#: checks that this module imports nothing else that computes.
CODE: dict[str | None, tuple[str, ...]] = {
    None: ("tslip.gait.continuation", "tslip.gait.fixed_point", "tslip.gait.stability"),
    "floquet": (),
    "stride": ("tslip.gait.stride",),
    "robustness": ("tslip.gait.robustness",),
}

#: Consecutive failures that end a continuation walk in one direction.
MAX_FAILURES = 3

#: Unknowns of the gait search (Section 2.8) a record keeps to seed its neighbours.
UNKNOWNS = ("delta", "phi", "phid", "alpha_r", "alphad_ref", "tau_c", "leg_thrust")

#: ``emit(index, record)``: a point of the line is final.
Emit = Callable[[int, dict[str, Any]], None]


def code_version(analyses: Sequence[str]) -> str:
    """Hash of the code computing a point with ``analyses`` (this module included)."""
    mods = CODE[None] + tuple(m for a in sorted(set(analyses)) for m in CODE[a])
    return f"{code_hash(*mods)}-{module_digest(__name__)[:24]}"


def gait_tol(spec: StudySpec) -> float:
    """The gait search's tolerance of a study: ``spec.meta["tol"]``, else 1e-10.

    The global PD controller has no exact fixed point (docs/conventions.md),
    so its studies accept a larger residual.
    """
    return float(spec.meta.get("tol", 1e-10))


def floquet_tol(spec: StudySpec) -> float:
    """The band around 1 of a study's trivial Floquet multipliers: ``spec.meta``'s, else 1e-6."""
    return float(spec.meta.get("neutral_tol", 1e-6))


def _num(x: Any) -> float:
    try:
        return float(x)
    except (TypeError, ValueError):
        return math.nan


class _Seed:
    """A solved point as its neighbours see it: the record's unknowns.

    Duck-types the two things a warm start (:meth:`GaitProblem.encode`) reads
    from a :class:`Gait`: ``state.delta/phi/phid`` and, of ``params``, the
    solved ``alpha_r`` and controller reference (``controller.alphad_ref`` or
    ``controller.tau_c``) or ``leg_thrust``: the record's numbers, which the gait's
    parameters hold.
    """

    def __init__(self, z: dict[str, float]) -> None:
        self.z = z
        self.state = SimpleNamespace(**z)
        self.params = SimpleNamespace(
            alpha_r=z["alpha_r"], leg_thrust=z["leg_thrust"],
            controller=SimpleNamespace(alphad_ref=z["alphad_ref"], tau_c=z["tau_c"]))


def seeds_from_records(records: Sequence[dict[str, Any] | None],
                       inner: str) -> dict[float, dict[str, float]]:
    """The unknowns of a line's solved points, by inner value (seeds for the next line)."""
    return {float(r[inner]): {n: r.get(n, math.nan) for n in UNKNOWNS}
            for r in records if r is not None and r.get("converged")}


class _Line:
    """One line's replayable solve (see the module docstring)."""

    def __init__(self, spec: StudySpec, assignment: dict[str, float], values: Sequence[float],
                 cached: dict[float, dict[str, Any]], emit: Emit | None) -> None:
        self.spec, self.assignment = spec, dict(assignment)
        self.inner = spec.axes[-1].param
        self.params = spec.params_at(assignment)
        self.values = np.sort(np.asarray(values, dtype=float))
        n = len(self.values)
        self.tol = gait_tol(spec)
        self.neutral_tol = floquet_tol(spec)
        self.emit = emit
        self.cached = {i: cached[float(v)] for i, v in enumerate(self.values)
                       if float(v) in cached}
        self.records: list[dict[str, Any] | None] = [self.cached.get(i) for i in range(n)]
        self.gaits: list[_Seed | None] = [None] * n
        self.tries = [0] * n
        self.spent = [0.0] * n
        self.failed: list[tuple[float, str]] = [
            (math.nan, "not attempted: past the end of the branch")] * n
        self.pending: dict[int, Pending] = {}

    # -- points -----------------------------------------------------------------
    def point_params(self, i: int) -> Any:
        """``spec.params_at`` of point ``i``: the line's parameters with the inner value set."""
        return set_param(self.params, self.inner, float(self.values[i]))

    def seed(self, rec: dict[str, Any]) -> _Seed:
        return _Seed({n: _num(rec.get(n)) for n in UNKNOWNS})

    def attempt(self, i: int, solve: Callable[[], tuple[Gait, str]],
                keep_failure: bool) -> _Seed | None:
        """One attempt at point ``i``: its seed if it succeeded, else None.

        A cached point is not recomputed: the attempt succeeds if it is the
        one that succeeded when the point was computed.
        """
        self.tries[i] += 1
        rec = self.cached.get(i)
        if rec is None:
            t0 = time.perf_counter()
            g, message = solve()
            self.spent[i] += time.perf_counter() - t0
            if not g.converged:
                if keep_failure:
                    self.failed[i] = (_num(g.residual), message)
                return None
            rec = self.finish(i, g, _num(g.residual), message)
        elif not (rec["converged"] and rec["_attempt"] == self.tries[i]):
            return None
        self.gaits[i] = self.seed(rec)
        return self.gaits[i]

    def attempt_from(self, i: int, z: dict[str, float], message: str) -> bool:
        """Attempt point ``i`` from a neighbour's unknowns ``z``."""
        prob = GaitProblem.from_params(self.point_params(i))
        guess = [_num(z.get(n)) for n in prob.names]
        if not all(map(math.isfinite, guess)):
            return False
        return self.attempt(i, lambda: (_search(prob, np.array(guess), self.tol), message),
                            keep_failure=False) is not None

    # -- strategies -------------------------------------------------------------
    def walk(self) -> None:
        """Natural continuation outward from the base value (as :func:`continue_gait`)."""
        base_value = get_param(self.params, self.inner)
        anchor = find_gait(self.params, tol=self.tol)
        start: list[tuple[float, Any]] = [(base_value, anchor)] if anchor.converged else []
        n = len(self.values)
        i0 = int(np.argmin(np.abs(self.values - base_value)))
        self._walk(range(i0, n), list(start))
        g0 = self.gaits[i0]
        first = [(float(self.values[i0]), g0)] if g0 is not None else []
        self._walk(range(i0 - 1, -1, -1), (start + first)[-2:] if first else list(start))

    def _walk(self, indices: range, history: list[tuple[float, Any]]) -> None:
        failures = 0
        for i in indices:
            if failures >= MAX_FAILURES:
                break
            v = float(self.values[i])
            g = self.attempt(i, lambda h=history, v=v: _solve_point(  # type: ignore[misc]
                self.params, self.inner, v, h, self.tol, None, "secant"), keep_failure=True)
            if g is not None:
                history = (history + [(v, g)])[-2:]
                failures = 0
            else:
                failures += 1

    def probe(self, n_probe: int = 10) -> None:
        """Cold searches at ``n_probe`` evenly spread values, then grow from any found."""
        message = "found by probing the line"
        n = len(self.values)
        self.failed = [(math.nan, "no periodic gait found along this line")] * n
        for i in np.unique(np.linspace(0, n - 1, min(n_probe, n)).round()):
            p = self.point_params(int(i))
            self.attempt(int(i), functools.partial(self._probe, p, message), keep_failure=False)
        self.grow(message)

    def continue_from(self, seeds: dict[float, dict[str, float]]) -> None:
        """2-D continuation: every point from its neighbour line's solution, then grow."""
        message = "continued from the neighbouring line"
        self.failed = [(math.nan, "no periodic gait continuing from the neighbouring line")] \
            * len(self.values)
        for i, v in enumerate(self.values):
            if self.gaits[i] is None and float(v) in seeds:
                self.attempt_from(i, seeds[float(v)], message)
        self.grow(message)

    def grow(self, message: str) -> None:
        """Solved points seed their unsolved neighbours, once per pair, until none succeeds."""
        n = len(self.values)
        tried: set[tuple[int, int]] = set()
        grown = True
        while grown:
            grown = False
            for i in range(n):
                gi = self.gaits[i]
                if gi is None:
                    continue
                for j in (i - 1, i + 1):
                    if 0 <= j < n and self.gaits[j] is None and (i, j) not in tried:
                        tried.add((i, j))
                        grown |= self.attempt_from(j, gi.z, message)

    # -- records ----------------------------------------------------------------
    def finish(self, i: int, g: Gait | None, residual: float, message: str) -> dict[str, Any]:
        """Point ``i`` is solved: queue its analysis (or, without a gait, emit its record).

        Returns what seeds its neighbours: the point and its unknowns, the
        same numbers the analysed record will hold.
        """
        point = {**self.assignment, self.inner: float(self.values[i])}
        if g is None:
            return self.record(Pending(i, point, None, residual, message, self.tries[i],
                                       self.spent[i]))
        self.pending[i] = Pending(i, point, g, _num(residual), message, self.tries[i],
                                  self.spent[i])
        return {**point, "converged": True, **_unknowns(g)}

    def record(self, item: Pending) -> dict[str, Any]:
        """Analyse one solved point and emit its record."""
        rec = analyse_point(self.spec, item, self.neutral_tol)
        self.records[item.index] = rec
        if self.emit is not None:
            self.emit(item.index, rec)
        return rec

    def close(self) -> Solved:
        """Emit the points without a gait; the solved points still to analyse."""
        for i, rec in enumerate(self.records):
            if rec is None and i not in self.pending:
                self.finish(i, None, *self.failed[i])
        heads = [self.head(i) for i in range(len(self.values))]
        return Solved(list(self.records), [self.pending[i] for i in sorted(self.pending)],
                      seeds_from_records(heads, self.inner))

    def _probe(self, p: Params, message: str) -> tuple[Gait, str]:
        return find_gait(p, tol=self.tol), message

    def head(self, i: int) -> dict[str, Any] | None:
        """The record of point ``i`` as far as seeding goes (its unknowns)."""
        if i in self.pending:
            item = self.pending[i]
            known = _unknowns(item.gait) if item.gait is not None else {}
            return {**item.point, "converged": True, **known}
        return self.records[i]


@dataclass(frozen=True)
class Pending:
    """A point solved and not yet analysed: what :func:`analyse_point` needs."""

    index: int
    point: dict[str, float]
    gait: Gait | None
    residual: float
    message: str
    attempt: int
    seconds: float


@dataclass(frozen=True)
class Solved:
    """A line after :func:`solve_gaits`.

    ``records``: the final records by index (cached points and points
    without a gait; None for the points still to analyse), ``pending``: the
    solved points to analyse (:func:`analyse_point`), ``seeds``: the
    unknowns of every solved point (:func:`seeds_from_records`), for the
    next line.
    """

    records: list[dict[str, Any] | None]
    pending: list[Pending]
    seeds: dict[float, dict[str, float]]


def _unknowns(g: Gait) -> dict[str, float]:
    """The unknowns a record keeps of gait ``g`` (:data:`UNKNOWNS`), as :func:`_analyse`."""
    s, ctrl = g.state, g.params.controller
    return {"delta": _num(s.delta), "phi": _num(s.phi), "phid": _num(s.phid),
            "alpha_r": _num(g.params.alpha_r),
            "alphad_ref": _num(getattr(ctrl, "alphad_ref", math.nan)),
            "tau_c": _num(getattr(ctrl, "tau_c", math.nan)),
            **_thrust(g)}


def _thrust(g: Gait) -> dict[str, float]:
    """``leg_thrust`` where the gait search solved it (passive hip, leg damping), else
    nothing: the other studies' records keep their columns."""
    return {"leg_thrust": _num(g.params.leg_thrust)} if thrust_solved(g.params) else {}


def analyse_point(spec: StudySpec, item: Pending, neutral_tol: float | None = None
                  ) -> dict[str, Any]:
    """The record of one solved point (exactly what the cache holds: plain numbers and text)."""
    if neutral_tol is None:
        neutral_tol = floquet_tol(spec)
    t0 = time.perf_counter()
    rec = _analyse(spec, item.point, item.gait, item.residual, item.message, neutral_tol)
    rec["seconds"] = item.seconds + time.perf_counter() - t0
    rec["_attempt"] = item.attempt
    return rec


#: The multiplier columns of a point without them (no gait, or its multipliers failed).
_NO_MULTIPLIERS: dict[str, Any] = {
    **{f"abs_lambda_{j + 1}": math.nan for j in range(5)},
    "max_nontrivial": math.nan, "n_trivial": 0, "min_nontrivial": math.nan}


def _multipliers(fl: Floquet) -> dict[str, Any]:
    """The multiplier columns of a record: magnitudes in descending order, the largest and
    smallest non-trivial one, how many are trivial."""
    mags = np.abs(fl.multipliers)
    nt = mags[~fl.trivial]
    desc = np.sort(mags)[::-1].tolist()
    return {**{f"abs_lambda_{j + 1}": desc[j] for j in range(5)},
            "max_nontrivial": _num(fl.max_nontrivial), "n_trivial": int(fl.trivial.sum()),
            "min_nontrivial": float(nt.min()) if nt.size else math.nan}


def _analyse(spec: StudySpec, point: dict[str, float], g: Gait | None, residual: float,
             message: str, neutral_tol: float) -> dict[str, Any]:
    """The record of one point: multipliers, stride, robustness (as the spec asks)."""
    rec: dict[str, Any] = dict(point)
    rec["converged"] = g is not None and bool(g.converged)
    rec["residual"] = _num(residual)
    fl = None
    if g is not None:
        try:
            fl = floquet(g, unit_tol=neutral_tol)
        except ValueError:
            fl = None
    rec["stability"] = fl.stability if fl is not None else ("unknown" if g is not None
                                                            else "none")
    rec.update(_multipliers(fl) if fl is not None else _NO_MULTIPLIERS)
    rec["stance_time"] = _num(g.stance_time) if g is not None else math.nan
    rec["flight_time"] = _num(g.flight_time) if g is not None else math.nan
    if g is not None:
        s = g.state
        rec.update(delta=_num(s.delta), phi=_num(s.phi), phid=_num(s.phid),
                   alpha_r=_num(g.params.alpha_r))
        ctrl = g.params.controller
        rec["alphad_ref"] = _num(getattr(ctrl, "alphad_ref", math.nan))
        rec["tau_c"] = _num(getattr(ctrl, "tau_c", math.nan))
        rec.update(_thrust(g))
    if "stride" in spec.analyses and g is not None:
        sp = stride_properties(g)
        rec.update(duty_factor=_num(sp.duty_factor), step_frequency=_num(sp.step_frequency),
                   stance_time_predicted=_num(sp.stance_time_predicted),
                   flight_time_predicted=_num(sp.flight_time_predicted),
                   fast_running_index=_num(sp.fast_running_index),
                   bounce_time=_num(sp.bounce_time))
    if "robustness" in spec.analyses:
        for kind in KINDS:
            rec[kind] = math.nan
            rec[f"{kind}_status"] = ""
        if g is not None and rec["converged"] and rec["stability"] in ("asymptotic", "neutral"):
            rr = robustness_report(g, n_steps=spec.n_steps, check=False)
            for lim in rr.limits:
                rec[lim.kind] = _num(lim.limit)
                rec[f"{lim.kind}_status"] = lim.status.name if lim.status else ""
    rec["message"] = message
    return rec


def solve_gaits(spec: StudySpec, assignment: dict[str, float], values: Sequence[float], *,
                seeds: dict[float, dict[str, float]] | None = None,
                cached: dict[float, dict[str, Any]] | None = None,
                emit: Emit | None = None) -> Solved:
    """Find the gaits of one line; the points without a gait are emitted as final.

    Parameters as :func:`solve_line`; the solved points come back unanalysed
    (:class:`Solved`).
    """
    line = _Line(spec, assignment, values, cached or {}, emit)
    if seeds is not None:
        line.continue_from(seeds)
    else:
        line.walk()
        if len(spec.axes) == 2 and not any(g is not None for g in line.gaits):
            line.probe()  # the base value may lie outside the gait's band
    return line.close()


def solve_line(spec: StudySpec, assignment: dict[str, float], values: Sequence[float], *,
               seeds: dict[float, dict[str, float]] | None = None,
               cached: dict[float, dict[str, Any]] | None = None,
               emit: Emit | None = None) -> list[dict[str, Any]]:
    """Solve and analyse the points of one line; one record per value, ascending.

    Parameters
    ----------
    spec : StudySpec
    assignment : dict
        Values of the other axes (empty for a 1-D study).
    values : sequence of float
        All values of the line's axis.
    seeds : dict, optional
        The neighbouring line's unknowns (:func:`seeds_from_records`): the
        points start from them (2-D continuation). Without, the line is
        walked from the base value; a 2-D study's line without any gait on
        that walk is probed at ten values.
    cached : dict, optional
        Records of points already computed, by value: replayed, not
        recomputed (the result is the same as without them).
    emit : callable, optional
        ``emit(index, record)`` as soon as each point is final.
    """
    solved = solve_gaits(spec, assignment, values, seeds=seeds, cached=cached, emit=emit)
    records = list(solved.records)
    for item in solved.pending:
        rec = analyse_point(spec, item)
        records[item.index] = rec
        if emit is not None:
            emit(item.index, rec)
    return records  # type: ignore[return-value]
