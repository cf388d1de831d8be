"""Claim types, verdicts and the thresholds every claim shares (see the package docstring)."""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np
import pandas as pd

Numbers = dict[str, Any]


class Verdict(StrEnum):
    """How a claim compares with our numbers.

    ``HOLDS``: under the plain reading of the thesis sentence.
    ``HOLDS_UNDER_READING``: the sentence allows more than one reading (or
    set-up) and it holds under the one named in the result's ``reading``;
    the numbers of every reading are shown. ``FAILS``: it does not hold; the
    result's ``evidence`` holds what the package computed to find out why.
    ``NOT_ASSESSED``: the data have fewer points than the check's statistic
    needs (3 for a rank correlation); the numbers say how many. Never a
    failure.
    """

    HOLDS = "holds"
    HOLDS_UNDER_READING = "holds under a stated reading"
    FAILS = "does not hold"
    NOT_ASSESSED = "not assessed"


@dataclass(frozen=True)
class Check:
    """What a claim's test returns.

    ``numbers``: our measured values (shown for every verdict);
    ``evidence``: further numbers that explain a ``FAILS`` or a
    ``HOLDS_UNDER_READING`` (each reading's result, variants tried);
    ``note``: one sentence for the reader, e.g. that the claim fails only at
    quick resolution.
    """

    numbers: Numbers
    verdict: Verdict
    evidence: Numbers = field(default_factory=dict)
    note: str = ""


@dataclass(frozen=True)
class Claim:
    """A thesis claim and its test.

    ``text`` is the claim in one short sentence (the summary table);
    ``quote`` the thesis's own words and ``source`` where they stand (section,
    figure or table); ``reading`` what the test checks and why its threshold
    is a fair reading of the wording; ``id`` a stable name (``<figure>-<words>``,
    :data:`ID_PATTERN`) that never changes once released.
    """

    figure: str
    text: str
    needs: tuple[str, ...]
    test: Callable[[Mapping[str, Any]], Check | tuple[Numbers, bool]] = field(repr=False)
    quote: str = ""
    source: str = ""
    reading: str = ""
    id: str = ""


#: What a claim id looks like: the figure, a dash, lower-case words joined by dashes.
ID_PATTERN = r"^[a-z0-9.]+-[a-z0-9-]+$"


@dataclass(frozen=True)
class ClaimResult:
    """A claim (by its ``id``) with the numbers we measured and its verdict."""

    figure: str
    text: str
    numbers: Numbers
    verdict: Verdict
    error: str = ""
    quote: str = ""
    source: str = ""
    reading: str = ""
    evidence: Numbers = field(default_factory=dict)
    note: str = ""
    id: str = ""

    @property
    def holds(self) -> bool:
        """Deprecated: read :attr:`verdict` (True unless it is ``FAILS``)."""
        warnings.warn("ClaimResult.holds is deprecated and will be removed; read "
                      "ClaimResult.verdict (a Verdict) instead", DeprecationWarning,
                      stacklevel=2)
        return self.verdict is not Verdict.FAILS


def count_verdicts(results: Iterable[Any]) -> dict[Verdict, int]:
    """Claims per verdict, every :class:`Verdict` present (0 if none), in enum order.

    ``results`` are :class:`ClaimResult` or anything with a ``verdict`` (a
    :class:`Verdict` or its value, as in ``claims.json``).
    """
    seen = [Verdict(getattr(r, "verdict", None) or r["verdict"]) for r in results]
    return {v: seen.count(v) for v in Verdict}


# -- helpers ------------------------------------------------------------------

def _frame(data: Mapping[str, Any], name: str) -> pd.DataFrame:
    return data[name].frame


def stable_mask(f: pd.DataFrame) -> np.ndarray:
    """Points with a gait whose non-trivial multipliers are all inside the unit circle."""
    return (f["converged"].to_numpy(bool)
            & f["stability"].isin(["asymptotic", "neutral"]).to_numpy()
            & (f["max_nontrivial"].to_numpy(float) < 1.0))


def stable_range(f: pd.DataFrame, col: str) -> tuple[float, float]:
    """Smallest and largest stable value of ``col`` (NaN if none)."""
    v = f[col].to_numpy(float)[stable_mask(f)]
    return (float(v.min()), float(v.max())) if v.size else (math.nan, math.nan)


def _stable(f: pd.DataFrame) -> pd.DataFrame:
    return f[stable_mask(f)]


def _abs(f: pd.DataFrame, col: str) -> np.ndarray:
    return np.abs(f[col].to_numpy(float))


def _corr(x: np.ndarray, y: np.ndarray) -> float:
    ok = np.isfinite(x) & np.isfinite(y)
    if ok.sum() < 3 or np.std(x[ok]) == 0 or np.std(y[ok]) == 0:
        return math.nan
    return float(np.corrcoef(x[ok], y[ok])[0, 1])


def _rank_corr(x: np.ndarray, y: np.ndarray) -> float:
    ok = np.isfinite(x) & np.isfinite(y)
    return _corr(pd.Series(x[ok]).rank().to_numpy(), pd.Series(y[ok]).rank().to_numpy())


def _r(x: float, d: int = 3) -> float:
    return round(float(x), d) if math.isfinite(float(x)) else math.nan


#: Relative size under which the thesis's "minimally", "little", "similar",
#: "approximately zero" and "does not change" hold, and over which
#: "significantly larger" does: one quarter, the same bound for every claim.
REL = 0.25
#: Spearman rank correlation that a plain monotone statement ("decreases",
#: "improves", "grows with") needs over the stated range: most pairs of points
#: follow it, a few at the noise level need not.
TREND = 0.8
#: ... and a hedged one ("tend to").
TEND = 0.5
#: Half a unit in the last digit of a number printed with two decimals.
PRINTED = 0.005
#: Accuracy of our Floquet multipliers: the exact Jacobian agrees with finite
#: differences to 1e-6 (tests/gait/test_stability.py), so |lambda| = 1 to
#: this accuracy is neutral.
MULT_TOL = 1e-6
#: "Match closely": median relative error of an approximation (eqs. 3.10-3.11).
CLOSE = 0.1


def _opt_frame(data: Mapping[str, Any], name: str) -> pd.DataFrame | None:
    res = data.get(name)
    return None if res is None else res.frame


def _trend(x: np.ndarray, y: np.ndarray, sign: int, bound: float = TREND,
           min_points: int = 3) -> tuple[float, bool]:
    """Spearman rho of ``y`` on ``x`` and whether ``sign * rho >= bound``."""
    ok = np.isfinite(x) & np.isfinite(y)
    rho = _rank_corr(x[ok], y[ok]) if ok.sum() >= min_points else math.nan
    return rho, bool(math.isfinite(rho) and sign * rho >= bound)


def _flat(prefix: str, nums: Numbers) -> Numbers:
    return {f"{prefix}: {k}": v for k, v in nums.items()}


def _readings(parts: Mapping[str, tuple[Numbers, bool | None] | None],
              numbers: Numbers | None = None) -> Check:
    """One verdict from the readings of an ambiguous sentence.

    ``parts`` maps each reading (the plain one first) to its numbers and
    whether the claim holds under it (None: not assessed, too few points),
    or to None if it was not computed. All hold: ``HOLDS``; some:
    ``HOLDS_UNDER_READING``; none, with one not assessed: ``NOT_ASSESSED``;
    none: ``FAILS``. Every reading's numbers go to the evidence; the headline
    ``numbers`` (unless given) are those of the reading the verdict rests on:
    the first that holds, else the plain one.
    """
    evidence: Numbers = {}
    for name, part in parts.items():
        if part is None:
            evidence[name] = "not computed"
        else:
            evidence.update(_flat(name, part[0]))
            evidence[f"{name}: holds"] = ("not assessed" if part[1] is None
                                          else bool(part[1]))
    done = {k: v for k, v in parts.items() if v is not None}
    held = [k for k, (_, ok) in done.items() if ok]
    if numbers is None:
        first = held[0] if held else next(iter(done), None)
        numbers = done[first][0] if first is not None else {}
    if held and len(held) == len(parts):
        return Check(numbers, Verdict.HOLDS, evidence)
    if held:
        missed = [k for k in parts if k not in held]
        return Check(numbers, Verdict.HOLDS_UNDER_READING, evidence,
                     f"holds under: {'; '.join(held)}; not under: {'; '.join(missed)}")
    if any(ok is None for _, ok in done.values()):
        return Check(numbers, Verdict.NOT_ASSESSED, evidence, _TOO_FEW)
    return Check(numbers, Verdict.FAILS, evidence)


#: Points a rank correlation needs.
MIN_POINTS = 3
_TOO_FEW = (f"not assessed: fewer than {MIN_POINTS} points for the check's rank correlation "
            "(the numbers give the count)")


def _judge(numbers: Numbers, ok: bool, points: Mapping[str, int] | None = None,
           evidence: Numbers | None = None) -> Check:
    """``HOLDS`` or ``FAILS`` by ``ok``; ``NOT_ASSESSED`` if a statistic has too few points.

    ``points`` maps each statistic the verdict needs to the points it had;
    below :data:`MIN_POINTS` the claim is not assessed (the counts are added
    to the numbers).
    """
    short = {k: n for k, n in (points or {}).items() if n < MIN_POINTS}
    if short:
        counts = {f"points for {k}": n for k, n in short.items()}
        return Check({**numbers, **counts}, Verdict.NOT_ASSESSED,
                     {**(evidence or {}), **counts, "points needed": MIN_POINTS}, _TOO_FEW)
    return Check(numbers, Verdict.HOLDS if ok else Verdict.FAILS, evidence or {})


def _n(x: np.ndarray, y: np.ndarray) -> int:
    """Points where both ``x`` and ``y`` are finite (what a correlation of them uses)."""
    return int((np.isfinite(np.asarray(x, float)) & np.isfinite(np.asarray(y, float))).sum())


def _printed(ours: float, thesis: float, tol: float = PRINTED,
             unit: str = "") -> tuple[Numbers, bool]:
    u = f" [{unit}]" if unit else ""
    return {f"ours{u}": _r(ours, 4), f"thesis{u}": thesis,
            f"|difference|{u}": _r(abs(ours - thesis), 4), f"tolerance{u}": tol}, bool(
        abs(ours - thesis) <= tol)
