"""Figures 4.24-4.25's claims: the controllers compared over the mass offset r.

Figure 4.25 plots each controller's limit over r. A comparison of
controllers is made at each r (the limits at the same r), never by a
statistic that compares different r (a ratio of medians over r does):
:func:`_per_r` judges the median of the per-r comparisons and the comparison
at Table 2.1's offset, and shows the comparison at every r.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
import pandas as pd

from ._rules import (
    MIN_POINTS,
    MULT_TOL,
    REL,
    Check,
    Numbers,
    Verdict,
    _frame,
    _judge,
    _r,
    _readings,
    stable_mask,
    stable_range,
)

_CONTROLLERS = {"passive": "mass_offset", "global PD": "controller_global_pd",
                "local velocity": "controller_local_velocity",
                "constant torque": "controller_constant_torque"}


def _c424_passive(d: Mapping[str, Any]) -> Check:
    f = _frame(d, "mass_offset")
    lo, hi = stable_range(f, "r")
    nums = {"passive stable r [L]": [_r(lo), _r(hi)]}
    return Check(nums, Verdict.HOLDS if lo >= 0 else Verdict.FAILS)


def _c424_lv(d: Mapping[str, Any]) -> Check:
    lv = _frame(d, "controller_local_velocity")
    asym = lv[lv["stability"].eq("asymptotic") & stable_mask(lv)]
    n_pos = int((asym["r"] > 0).sum())
    nums = {"asymptotically stable points (r > 0 / all)": [n_pos, int(len(asym))]}
    ok = len(asym) >= 3 and n_pos > len(asym) / 2
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c424_pd(d: Mapping[str, Any]) -> Check:
    f = _frame(d, "controller_global_pd")
    g = f[f["converged"].astype(bool)]
    top = g["abs_lambda_1"].to_numpy(float)
    second = g["abs_lambda_2"].to_numpy(float)
    res = g["residual"].to_numpy(float)
    dev = np.abs(top - 1.0)
    rest_inside = bool(np.all(second < 1.0 - MULT_TOL)) if g.size else False
    nums: Numbers = {"global PD gaits": int(len(g)),
                     "max | |lambda_1| - 1 |": float(f"{dev.max():.1e}") if dev.size else math.nan,
                     "largest other |lambda|": _r(second.max(), 4) if second.size else math.nan,
                     "max periodicity residual": float(f"{res.max():.1e}") if res.size
                     else math.nan}
    exact = (nums, bool(dev.size) and bool(np.all(dev <= MULT_TOL)) and rest_inside)
    own = ({"points with | |lambda_1| - 1 | > max(1e-6, residual)":
            int(np.sum(dev > np.maximum(MULT_TOL, res)))},
           bool(dev.size) and bool(np.all(dev <= np.maximum(MULT_TOL, res))) and rest_inside)
    return _readings({"|lambda| = 1 within the multipliers' accuracy (1e-6)": exact,
                      "|lambda| = 1 within the gait's own periodicity residual": own}, nums)


def _by_r(d: Mapping[str, Any], col: str, names: Mapping[str, str]) -> pd.DataFrame:
    """|col| of each controller (columns) at the r > 0 that every one has a limit for (rows)."""
    out = {}
    for label, name in names.items():
        f = _frame(d, name)
        f = f[(f["r"] > 0) & np.isfinite(f[col].to_numpy(float))]
        out[label] = pd.Series(np.abs(f[col].to_numpy(float)), index=np.round(
            f["r"].to_numpy(float), 9))
    t = pd.DataFrame(out).dropna()
    return t.sort_index()


#: Table 2.1's mass offset [L], where Figure 4.25's controllers are usually compared.
R_TABLE21 = 0.3


def _near(t: pd.DataFrame, r: float) -> Any:
    return t.index[int(np.argmin(np.abs(t.index.to_numpy(float) - r)))] if len(t) else None


def _per_r(t: pd.DataFrame, stat: pd.Series, name: str, holds: Callable[[float], bool],
           headline: Numbers) -> Check:
    """A Figure 4.25 verdict from a statistic taken at each r, never across different r.

    ``stat`` is the comparison at each shared r (a ratio or a spread) and
    ``holds`` whether one value of it satisfies the claim. Two readings: over
    the shared r (the median of the per-r values), and at Table 2.1's offset
    (the shared r nearest :data:`R_TABLE21`). Both hold: ``HOLDS``; one:
    ``HOLDS_UNDER_READING``, the note naming which; neither: ``FAILS``.
    """
    r0 = _near(t, R_TABLE21)
    med = float(stat.median())
    at0 = float(stat.loc[r0])
    n_ok = int(sum(holds(float(x)) for x in stat))
    nums: Numbers = {**headline, f"median over r of the {name} at each r": _r(med),
                     f"r where the {name} satisfies the claim": f"{n_ok} of {len(stat)}",
                     f"{name} at r = {_r(r0)} L (nearest Table 2.1's {R_TABLE21})": _r(at0),
                     "shared r > 0 (every controller has a limit) [L]": [
                         _r(t.index.min()), _r(t.index.max())]}
    evidence: Numbers = {"r [L]": [_r(x) for x in t.index],
                         f"{name} at each r": [_r(x) for x in stat],
                         **{f"|limit| at each r: {k}": [_r(x) for x in t[k]] for k in t}}
    check = _readings({f"over the shared r (median of the {name} at each r)":
                       ({}, holds(med)),
                       f"at Table 2.1's offset r = {_r(r0)} L": ({}, holds(at0))}, nums)
    return Check(check.numbers, check.verdict, {**check.evidence, **evidence}, check.note)


def _shared(d: Mapping[str, Any], col: str, names: Mapping[str, str]) -> pd.DataFrame | Check:
    t = _by_r(d, col, names)
    if len(t) < MIN_POINTS:
        return _judge({}, False, {"r > 0 with a limit for every controller": len(t)})
    return t


def _c425_pitch(d: Mapping[str, Any]) -> Check:
    """'Significantly larger': global PD / the best other above 1 + REL, at each r."""
    t = _shared(d, "pitch_rate", _CONTROLLERS)
    if isinstance(t, Check):
        return t
    others = [k for k in _CONTROLLERS if k != "global PD"]
    ratio = t["global PD"] / t[others].max(axis=1)
    above = int((ratio > 1.0).sum())
    return _per_r(t, ratio, "global PD / best other", lambda x: x > 1 + REL,
                  {"bound ('significantly': beyond the quarter of 'similar')": 1 + REL,
                   "r where global PD exceeds the best other at all": f"{above} of {len(t)}"})


def _c425_similar(d: Mapping[str, Any]) -> Check:
    """'Similar': the relative spread of the other three below REL, at each r."""
    t = _shared(d, "pitch_rate", {k: n for k, n in _CONTROLLERS.items() if k != "global PD"})
    if isinstance(t, Check):
        return t
    spread = (t.max(axis=1) - t.min(axis=1)) / t.max(axis=1)
    return _per_r(t, spread, "relative spread (max - min) / max", lambda x: x < REL,
                  {"bound ('similar')": REL})


def _c425_push(d: Mapping[str, Any]) -> Check:
    """'Least robust': local velocity's |push| below each other's, at each r."""
    t = _shared(d, "push", _CONTROLLERS)
    if isinstance(t, Check):
        return t
    others = [k for k in _CONTROLLERS if k != "local velocity"]
    ratio = t["local velocity"] / t[others].min(axis=1)
    return _per_r(t, ratio, "local velocity / the least robust other", lambda x: x < 1.0,
                  {"bound (least: below every other)": 1.0})
