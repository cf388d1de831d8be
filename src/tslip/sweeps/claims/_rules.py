"""Claim types, verdicts and the thresholds every claim shares (see the package docstring)."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
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
    """

    HOLDS = "holds"
    HOLDS_UNDER_READING = "holds under a stated reading"
    FAILS = "does not hold"


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
    is a fair reading of the wording.
    """

    figure: str
    text: str
    needs: tuple[str, ...]
    test: Callable[[Mapping[str, Any]], Check | tuple[Numbers, bool]] = field(repr=False)
    quote: str = ""
    source: str = ""
    reading: str = ""


@dataclass(frozen=True)
class ClaimResult:
    """A claim with the numbers we measured and its verdict."""

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

    @property
    def holds(self) -> bool:
        """True for ``HOLDS`` and ``HOLDS_UNDER_READING``."""
        return self.verdict is not Verdict.FAILS


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


def _ends(f: pd.DataFrame, col: str) -> tuple[float, float]:
    """|col| at the first and the last stable point with a finite value."""
    s = _stable(f)
    v = _abs(s, col)
    v = v[np.isfinite(v)]
    return (float(v[0]), float(v[-1])) if v.size else (math.nan, math.nan)


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


def _readings(parts: Mapping[str, tuple[Numbers, bool] | None],
              numbers: Numbers | None = None) -> Check:
    """One verdict from the readings of an ambiguous sentence.

    ``parts`` maps each reading (the plain one first) to its numbers and
    whether the claim holds under it, or to None if it was not computed. All
    hold: ``HOLDS``; some: ``HOLDS_UNDER_READING``; none: ``FAILS``. Every
    reading's numbers go to the evidence.
    """
    evidence: Numbers = {}
    for name, part in parts.items():
        if part is None:
            evidence[name] = "not computed"
        else:
            evidence.update(_flat(name, part[0]))
            evidence[f"{name}: holds"] = bool(part[1])
    done = {k: v for k, v in parts.items() if v is not None}
    held = [k for k, (_, ok) in done.items() if ok]
    if numbers is None:
        numbers = next(iter(done.values()))[0] if done else {}
    if held and len(held) == len(parts):
        return Check(numbers, Verdict.HOLDS, evidence)
    if held:
        missed = [k for k in parts if k not in held]
        return Check(numbers, Verdict.HOLDS_UNDER_READING, evidence,
                     f"holds under: {'; '.join(held)}; not under: {'; '.join(missed)}")
    return Check(numbers, Verdict.FAILS, evidence)


def _printed(ours: float, thesis: float, tol: float = PRINTED) -> tuple[Numbers, bool]:
    return {"ours": _r(ours, 4), "thesis": thesis, "|difference|": _r(abs(ours - thesis), 4),
            "tolerance": tol}, bool(abs(ours - thesis) <= tol)
