"""The eigenvalue rule: claims about stability or convergence read off an eigenvalue figure.

Figures 4.8, 4.14, 4.18, 4.20 and 4.22 plot every multiplier's magnitude,
and the thesis reads them collectively ("the eigenvalue magnitudes are lower
for slower retraction rates", Section 4.5.4; Section 7.4 on eigenvalues
exceeding 1 as a whole). One rule for every such sentence
(:func:`_eigen_rule`): the statement is evaluated on both the largest and the
mean non-trivial |lambda|, both are shown; it "holds" if it holds on both,
"holds under a stated reading" if on one, and "does not hold" if on neither.
A sentence that itself sets the dominant mode aside (Figure 4.14: "not
necessarily the most unstable mode") is judged on the mean, the largest
shown. Figure 4.12 keeps its element-wise reading (``_studies._c412``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
import pandas as pd

from ._rules import (
    _TOO_FEW,
    MIN_POINTS,
    MULT_TOL,
    Check,
    Numbers,
    Verdict,
    _frame,
    _judge,
    _n,
    _r,
    _readings,
    _trend,
    stable_mask,
    stable_range,
)

#: The two measures of the rule, by label: the largest and the mean non-trivial |lambda|.
LARGEST = "largest non-trivial |lambda|"
MEAN = "mean non-trivial |lambda|"


def _mean_nontrivial(g: pd.DataFrame) -> np.ndarray:
    """Mean of each gait's non-trivial |lambda| (those not 1 to :data:`MULT_TOL`)."""
    mags = g[[f"abs_lambda_{j}" for j in range(1, 6)]].to_numpy(float)
    mags = np.where(np.abs(mags - 1) < MULT_TOL, np.nan, mags)  # trivial multipliers
    if not mags.size:
        return np.array([])
    n = np.isfinite(mags).sum(axis=1)
    return np.where(n > 0, np.nansum(mags, axis=1) / np.maximum(n, 1), np.nan)


def _measures(g: pd.DataFrame) -> dict[str, np.ndarray]:
    """Both measures of the rule for each row of ``g``."""
    return {LARGEST: g["max_nontrivial"].to_numpy(float), MEAN: _mean_nontrivial(g)}


Statement = Callable[[str, np.ndarray], tuple[Numbers, bool | None]]


def _eigen_rule(g: pd.DataFrame, statement: Statement, common: Numbers | None = None,
                common_ok: bool = True) -> Check:
    """Judge ``statement`` (label, measure per row of ``g`` -> numbers, holds) on both measures.

    Both hold: ``HOLDS``; one: ``HOLDS_UNDER_READING`` (the note names it);
    neither: ``FAILS``; a measure with too few points (``None``) is not
    assessed. ``common`` numbers and ``common_ok`` (the parts of the claim
    that are not about the multipliers) go with both.
    """
    parts: dict[str, tuple[Numbers, bool | None] | None] = {}
    for label, y in _measures(g).items():
        nums, ok = statement(label, y)
        parts[f"on the {label}"] = ({**(common or {}), **nums},
                                    None if ok is None else bool(ok and common_ok))
    return _readings(parts)


def _speed_quickest(f: pd.DataFrame) -> Check:
    """'Most quickly just over the minimum': the slowest stable gait's measure is the smallest."""
    s = f[stable_mask(f)].sort_values("v0")
    vs = s["v0"].to_numpy(float)

    def statement(label: str, y: np.ndarray) -> tuple[Numbers, bool | None]:
        if vs.size < 2:
            return {"stable points": int(vs.size)}, None
        i = int(np.nanargmin(y))
        rho = _trend(vs, y, +1)[0]
        return {f"{label} at the slowest stable v0 ({_r(vs[0])})": _r(y[0], 4),
                f"smallest {label}, at v0": [_r(y[i], 4), _r(vs[i])],
                f"{label} at the fastest stable v0 ({_r(vs[-1])})": _r(y[-1], 4),
                f"rank corr(v0, {label}), stable gaits": _r(rho)}, bool(
                    y[0] <= y[i] + MULT_TOL)

    return _eigen_rule(s, statement)


def _c414(d: Mapping[str, Any]) -> Check:
    """Figure 4.14's caption sets the dominant mode aside: judged on the mean, largest shown."""
    g = _frame(d, "hip_damping")
    g = g[g["converged"].astype(bool)]
    c = g["controller.c_h"].to_numpy(float)
    m = _measures(g)
    rho, ok = _trend(c, m[MEAN], -1)
    rho_l = _trend(c, m[LARGEST], -1)[0]
    nums = {f"{MEAN} at c_h = 0 / largest c_h": [_r(m[MEAN][0], 4), _r(m[MEAN][-1], 4)]
            if c.size else [], f"rank corr(c_h, {MEAN})": _r(rho)}
    evidence = {f"rank corr(c_h, {LARGEST}) (not judged: 'not necessarily the most "
                "unstable mode')": _r(rho_l),
                f"{LARGEST} at c_h = 0 / largest c_h": [_r(m[LARGEST][0], 4),
                                                        _r(m[LARGEST][-1], 4)]
                if c.size else []}
    return _judge(nums, ok, {f"rank corr(c_h, {MEAN})": _n(c, m[MEAN])}, evidence)


def _c418(d: Mapping[str, Any]) -> Check:
    """Stability improves with stiffness over the lower half of the stable range, both measures."""
    f = _frame(d, "stiffness")
    m = stable_mask(f)
    if int(m.sum()) < MIN_POINTS:  # a stable range needs points to be judged at all
        return Check({"stable points": int(m.sum()), "points needed": MIN_POINTS},
                     Verdict.NOT_ASSESSED, {"stable points": int(m.sum())}, _TOO_FEW)
    lo, hi = stable_range(f, "k")
    k = f["k"].to_numpy(float)
    conv = f["converged"].to_numpy(bool)
    low_none = bool(not conv[0])
    above = np.flatnonzero(k > hi)
    unstable_next = bool(above.size and conv[above[0]] and not m[above[0]])
    s = f[m & (k <= (lo + hi) / 2)]
    ks = s["k"].to_numpy(float)
    common: Numbers = {"stable k [MgL^-1]": [_r(lo, 1), _r(hi, 1)],
                       "stable k max / min": _r(hi / lo) if lo > 0 else math.nan,
                       f"no gait at k = {k[0]:g} [MgL^-1]": low_none,
                       "unstable gait just above the stable range": unstable_next,
                       "stable points in the lower half": int(len(s))}
    ok = bool(hi >= 2 * lo and low_none and unstable_next)
    if not ok or len(s) < MIN_POINTS:  # a part failing decides; else too few points
        return _judge(common, ok, {} if not ok else {"a rank correlation over the lower half":
                                                     len(s)})

    def statement(label: str, y: np.ndarray) -> tuple[Numbers, bool | None]:
        rho, improves = _trend(ks, y, -1)
        return {f"rank corr(k, {label}), lower half of the stable range": _r(rho),
                f"{label} at the lowest / highest k of the lower half":
                [_r(y[0], 4), _r(y[-1], 4)]}, improves

    return _eigen_rule(s, statement, common, ok)


def _c420_flatter(d: Mapping[str, Any]) -> Check:
    """'Flatter leg angles demonstrate better stability within the stable range' (Section 4.5.3).

    Flatter is a smaller beta0 (beta0 = pi/2 is a vertical leg), better
    stability a smaller |lambda|: Spearman(beta0, measure) >= 0.8 over the
    stable gaits (a plain monotone statement), on both measures.
    """
    f = _frame(d, "touchdown_angle")
    s = f[stable_mask(f)]
    b = s["beta0"].to_numpy(float)
    if b.size < MIN_POINTS:
        return Check({"stable points": int(b.size), "points needed": MIN_POINTS},
                     Verdict.NOT_ASSESSED, {"stable points": int(b.size)}, _TOO_FEW)
    lo, hi = stable_range(f, "beta0")

    def statement(label: str, y: np.ndarray) -> tuple[Numbers, bool | None]:
        rho, ok = _trend(b, y, +1)
        return {f"rank corr(beta0, {label}), stable gaits": _r(rho),
                f"{label} at the flattest / steepest stable beta0": [_r(y[0], 4),
                                                                     _r(y[-1], 4)]}, ok

    return _eigen_rule(s, statement, {"stable beta0 [rad]": [_r(lo), _r(hi)],
                                      "stable points": int(b.size)})


def _c422(d: Mapping[str, Any]) -> Check:
    """Some retraction needed; above the most stable rate the multipliers grow, both measures."""
    f = _frame(d, "retraction")
    lo, hi = stable_range(f, "omega_r_bar")
    w = f["omega_r_bar"].to_numpy(float)
    m = stable_mask(f)
    zero_stable = bool(m[w == 0].any())
    g = f[f["converged"].to_numpy(bool) & (w > 0)]
    wg = g["omega_r_bar"].to_numpy(float)
    common: Numbers = {"stable omega_r_bar": [_r(lo), _r(hi)],
                       "stable without retraction": zero_stable}
    ok = bool(m.any()) and bool((w == 0).any()) and not zero_stable

    def statement(label: str, y: np.ndarray) -> tuple[Numbers, bool | None]:
        i = int(np.nanargmin(y)) if np.isfinite(y).any() else 0
        rho, grows = _trend(wg[i:], y[i:], +1)
        return {f"most stable rate ({label})": _r(wg[i]) if wg.size else math.nan,
                f"rank corr(omega_r_bar, {label}) above it": _r(rho)}, grows

    return _eigen_rule(g, statement, common, ok)
