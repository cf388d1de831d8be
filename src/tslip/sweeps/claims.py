"""The thesis's claims, one sentence each, tested on our results.

Each :class:`Claim` carries its figure, the claim as the thesis states it
(Chapter 4 text and captions, Section 6.1, Appendix C) and a function of the
results that returns the measured numbers and whether the claim holds. The
tests are written from the claims, never from our numbers: a claim that
fails is reported as failing, with the numbers.

``data`` maps a study name (:data:`tslip.sweeps.catalogue.STUDIES`) to its
:class:`~tslip.sweeps.StudyResult`, and a figure key ("4.1", "4.2", "4.3",
"6.2", "4.4", "4.5", "4.7", "C.1", "table6.1") to the analysis object that
:mod:`tslip.sweeps.reproduce` computed for it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np
import pandas as pd

__all__ = ["Check", "Claim", "ClaimResult", "CLAIMS", "Verdict", "evaluate", "stable_mask",
           "stable_range"]

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


# -- claims -------------------------------------------------------------------

def _c41(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    lin = d["4.1"]
    g = {k: lin.as_dict()[k] for k in ("I_x", "I_y", "x_p", "y_p")}
    others = [abs(g["I_x"]), abs(g["I_y"])] + ([] if lin.y_p_ill_conditioned else [abs(g["y_p"])])
    nums = {f"d{k}/dphi": _r(v, 4) for k, v in g.items()}
    nums["y_p ill-conditioned"] = bool(lin.y_p_ill_conditioned)
    return nums, abs(g["x_p"]) > max(others)


def _pitch(d: Mapping[str, Any], key: str) -> tuple[Numbers, bool]:
    resp = d[key]
    rest = [r for r in resp.restoring if r is not None]
    ddir = max(abs(x) for x in resp.direction_change)
    nums = {"dphi": [x for x in resp.dphis if x != 0.0],
            "torque": [_r(i.torque, 4) for i, x in zip(resp.impulses, resp.dphis) if x != 0.0],
            "restoring": rest, "max |direction change| [rad]": _r(ddir, 4),
            "hip distance / r": [_r(h, 3) for h, x in zip(resp.hip_distance, resp.dphis)
                                 if x != 0.0]}
    return nums, bool(rest) and all(rest)


def _c42(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    nums, ok = _pitch(d, "4.2")
    return nums, ok and nums["max |direction change| [rad]"] < 0.1


def _c43(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    nums, _ = _pitch(d, "4.3")
    passive = max(abs(x) for x in d["4.2"].direction_change)
    nums["passive max |direction change| [rad]"] = _r(passive, 4)
    return nums, nums["max |direction change| [rad]"] > 2.0 * passive


def _c62(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    return _pitch(d, "6.2")


def _c44(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    h = d["4.4"]
    pas = [r for r in h["passive"] if math.isfinite(r.dv)]
    lv = [r for r in h["local_velocity"] if math.isfinite(r.dv)]
    err = max((abs(r.dv - r.dv_expected) for r in pas), default=math.nan)
    lv_dv = max((abs(r.dv) for r in lv), default=math.nan)
    nums = {"dh": list(h["dh"]), "passive dv": [_r(r.dv, 4) for r in h["passive"]],
            "eq. 3.8 dv": [_r(r.dv_expected, 4) for r in h["passive"]],
            "max |dv - eq. 3.8|": float(f"{err:.2e}"),
            "local velocity max |dv| (runs without a fall)": float(f"{lv_dv:.2e}"),
            "falls (passive, local velocity) at dh": [
                [r.dh for r in h["passive"] if not math.isfinite(r.dv)],
                [r.dh for r in h["local_velocity"] if not math.isfinite(r.dv)]]}
    ok = len(pas) == len(h["passive"]) and err < 1e-3 and len(lv) >= 3 and lv_dv < 1e-3
    return nums, bool(ok)


def _c45(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    r = d["4.5"]
    xd = r.xd[1:]
    early, late = np.ptp(xd[:5]), np.ptp(xd[-5:])
    nums = {"corr(height, xd)": _r(r.phase_correlation), "xd spread first 5": _r(early, 4),
            "xd spread last 5": _r(late, 4), "strides": int(len(r.xd))}
    return nums, bool(r.phase_correlation < 0 and late < early)


def _c46(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    r = d["4.5"]
    spread = float(np.ptp(r.beta[1:6]))
    return {"touch-down beta spread, strides 1-5 [rad]": _r(spread, 4)}, spread > 1e-3


def _c47(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    cases = sorted(d["4.7"], key=lambda c: c.ddelta)
    down, mid, up = cases[0], cases[len(cases) // 2], cases[-1]
    nums = {"ddelta": [c.ddelta for c in cases],
            "stance time": [_r(c.stance_time, 4) for c in cases],
            "I_x": [_r(c.impulse.I_x, 4) for c in cases]}
    ok = (down.stance_time > mid.stance_time > up.stance_time
          and down.impulse.I_x > 0 > up.impulse.I_x)
    return nums, bool(ok)


def _c48(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    f = _frame(d, "velocity")
    lo, hi = stable_range(f, "v0")
    s = _stable(f)
    mnt = s["max_nontrivial"].to_numpy(float)
    vmax = float(f["v0"].max())
    above = f[f["v0"] >= lo]
    all_stable = bool(stable_mask(above).all()) if math.isfinite(lo) else False
    nums = {"min stable v0": _r(lo), "stable up to": _r(hi),
            "min max|lambda|": _r(mnt.min(), 4) if mnt.size else math.nan,
            "max|lambda| at fastest": _r(mnt[-1], 4) if mnt.size else math.nan,
            "stable everywhere above the minimum": all_stable}
    ok = (math.isfinite(lo) and lo > f["v0"].min() and all_stable and hi == vmax
          and mnt[-1] > mnt.min())
    return nums, bool(ok)


def _c49_push(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    s = _stable(_frame(d, "velocity"))
    v, p = s["v0"].to_numpy(float), _abs(s, "push")
    ok = np.isfinite(p)
    slope = float(np.polyfit(v[ok], p[ok], 1)[0]) if ok.sum() >= 2 else math.nan
    c = _corr(v, p)
    lo = stable_range(_frame(d, "velocity"), "v0")[0]
    vmin_implied = v[ok] - p[ok]
    nums = {"corr(v0, |push|)": _r(c, 4), "slope": _r(slope),
            "v0 - |push| (implied minimum speed)": [_r(x, 2) for x in
                                                    (vmin_implied.min(), vmin_implied.max())]
            if ok.any() else [], "min stable v0": _r(lo)}
    return nums, bool(c > 0.98 and slope > 0)


def _c49_step(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    s = _stable(_frame(d, "velocity"))
    v, sd = s["v0"].to_numpy(float), _abs(s, "step_down")
    ok = np.isfinite(sd)
    if ok.sum() < 3:
        return {"points": int(ok.sum())}, False
    v, sd = v[ok], sd[ok]
    i = int(np.argmax(sd))
    nums = {"best v0": _r(v[i]), "max |step-down|": _r(sd[i]), "|step-down| at fastest": _r(sd[-1]),
            "|step-down| at slowest stable": _r(sd[0])}
    return nums, bool(0 < i < len(sd) - 1 and sd[-1] < sd[i])


def _c49_pitch(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    s = _stable(_frame(d, "velocity"))
    p = _abs(s, "pitch_rate")
    p = p[np.isfinite(p)]
    if not p.size:
        return {}, False
    rel = float((p.max() - p.min()) / p.max())
    return {"|pitch rate| min": _r(p.min()), "max": _r(p.max()),
            "relative variation": _r(rel)}, rel < 0.25


def grid_stable_fractions(d: Mapping[str, Any]) -> dict[float, float]:
    """Fraction of the k x beta0 grid with a stable gait, per Figure 4.10 panel."""
    from .catalogue import GRID_SPEEDS

    return {v: float(stable_mask(_frame(d, f"grid_v{v:g}")).mean()) for v in GRID_SPEEDS}


def _c410(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    fr = grid_stable_fractions(d)
    vals = list(fr.values())
    nums = {f"stable area fraction at v0 = {v:g}": _r(x) for v, x in fr.items()}
    ok = all(b >= a for a, b in zip(vals, vals[1:])) and vals[-1] > vals[0]
    return nums, bool(ok)


def _c411(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    nums: Numbers = {}
    worst_s = worst_f = 0.0
    for name in ("stride_v0", "stride_k", "stride_beta0"):
        f = d[name].frame
        f = f[f["converged"].astype(bool)]
        es = np.abs(f["stance_time"] / f["stance_time_predicted"] - 1).to_numpy(float)
        ef = np.abs(f["flight_time"] - f["flight_time_predicted"]).to_numpy(float)
        nums[f"{name}: median |t_s / eq.3.10 - 1|"] = _r(np.nanmedian(es))
        nums[f"{name}: max |t_f - eq.3.11|"] = float(f"{np.nanmax(ef):.2e}")
        worst_s = max(worst_s, float(np.nanmedian(es)))
        worst_f = max(worst_f, float(np.nanmax(ef)))
    return nums, bool(worst_s < 0.1 and worst_f < 1e-3)


def _c411_k(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    f = d["stride_k"].frame
    f = f[f["converged"].astype(bool)]
    ts = f["stance_time"].to_numpy(float)
    rel = float(np.ptp(ts) / np.mean(ts)) if ts.size else math.nan
    return {"k range with gaits": [_r(f["k"].min(), 1), _r(f["k"].max(), 1)],
            "stance time range": [_r(ts.min()), _r(ts.max())],
            "relative variation": _r(rel)}, bool(rel < 0.1)


def _c412(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    f = _frame(d, "leg_damping")
    g = f[f["converged"].astype(bool)]
    m = g["max_nontrivial"].to_numpy(float)
    c = g["c_l"].to_numpy(float)
    nums = {"max|lambda| at c_l = 0": _r(m[0], 4) if c.size and c[0] == 0 else math.nan,
            "max|lambda| at largest c_l": _r(m[-1], 4) if m.size else math.nan,
            "largest c_l with gait": _r(c.max()) if c.size else math.nan,
            "corr(c_l, max|lambda|)": _r(_rank_corr(c, m))}
    return nums, bool(m.size >= 2 and m[-1] < m[0])


def _decrease(d: Mapping[str, Any], name: str, col: str,
              kinds: tuple[str, ...]) -> tuple[Numbers, list[bool]]:
    f = _frame(d, name)
    s = _stable(f)
    nums: Numbers = {}
    res = []
    for k in kinds:
        a, b = _ends(f, k)
        rc = _rank_corr(s[col].to_numpy(float), _abs(s, k))
        nums[f"|{k}| first -> last stable"] = [_r(a), _r(b)]
        nums[f"rank corr({col}, |{k}|)"] = _r(rc)
        res.append(b < a)
    lo, hi = stable_range(f, col)
    nums[f"stable {col}"] = [_r(lo), _r(hi)]
    return nums, res


def _c413(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    nums, res = _decrease(d, "leg_damping", "c_l", ("step_down", "push", "pitch_rate"))
    return nums, all(res)


def _c414(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    f = _frame(d, "hip_damping")
    g = f[f["converged"].astype(bool)]
    cols = [f"abs_lambda_{j}" for j in range(1, 6)]
    mags = g[cols].to_numpy(float)
    # drop trivial multipliers (|lambda| = 1 to 1e-6) and take the mean of the rest
    mags = np.where(np.abs(mags - 1) < 1e-6, np.nan, mags)
    mean = np.nanmean(mags, axis=1)
    nums = {"mean non-trivial |lambda| at c_h = 0": _r(mean[0], 4) if mean.size else math.nan,
            "at largest c_h": _r(mean[-1], 4) if mean.size else math.nan,
            "max|lambda| at c_h = 0 / largest": [_r(g["max_nontrivial"].iloc[0], 4),
                                                  _r(g["max_nontrivial"].iloc[-1], 4)]
            if len(g) else []}
    return nums, bool(mean.size >= 2 and mean[-1] < mean[0])


def _c415(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    nums, res = _decrease(d, "hip_damping", "controller.c_h", ("push", "pitch_rate"))
    return nums, bool(res[0] and not res[1])


def _c416(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    f = _frame(d, "mass_offset")
    lo, hi = stable_range(f, "r")
    neg = int(stable_mask(f[f["r"] < 0]).sum())
    # the boundary lies between the last stable and the next point
    r = f["r"].to_numpy(float)
    nxt = r[r > hi].min() if math.isfinite(hi) and (r > hi).any() else math.nan
    nums = {"stable r": [_r(lo), _r(hi)], "next r (unstable or none)": _r(nxt),
            "stable points with r < 0": neg}
    return nums, bool(neg == 0 and lo >= 0 and 0.8 <= hi <= 0.9)


def _c417(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    s = _stable(_frame(d, "mass_offset"))
    s = s[s["r"] > 0]
    r = s["r"].to_numpy(float)
    if not r.size:
        return {}, False
    near = s.iloc[int(np.argmin(np.abs(r - 0.5)))]
    first = s.iloc[0]
    nums = {"r (smallest stable > 0, ~0.5)": [_r(first["r"]), _r(near["r"])],
            "|step_down|": [_r(abs(first["step_down"])), _r(abs(near["step_down"]))],
            "|pitch_rate|": [_r(abs(first["pitch_rate"])), _r(abs(near["pitch_rate"]))]}
    ok = (abs(near["step_down"]) > abs(first["step_down"])
          and abs(near["pitch_rate"]) > abs(first["pitch_rate"]))
    return nums, bool(ok)


def _c418(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    f = _frame(d, "stiffness")
    lo, hi = stable_range(f, "k")
    k = f["k"].to_numpy(float)
    conv = f["converged"].to_numpy(bool)
    low_none = bool(not conv[0])
    unstable_above = bool(((k > hi) & conv & ~stable_mask(f)).any()) if math.isfinite(hi) \
        else False
    nums = {"stable k": [_r(lo, 1), _r(hi, 1)], f"no gait at k = {k[0]:g}": low_none,
            "unstable gaits above the stable range": unstable_above}
    return nums, bool(math.isfinite(lo) and hi >= 2 * lo and low_none and unstable_above)


def _c419(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    s = _stable(_frame(d, "stiffness"))
    rc = _rank_corr(s["k"].to_numpy(float), _abs(s, "push"))
    return {"rank corr(k, |push|)": _r(rc), "|push| first -> last stable":
            [_r(x) for x in _ends(_frame(d, "stiffness"), "push")]}, bool(rc < -0.8)


def _c420(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    f = _frame(d, "touchdown_angle")
    lo, hi = stable_range(f, "beta0")
    b = f["beta0"].to_numpy(float)
    steep_none = bool(not f["converged"].to_numpy(bool)[-1])
    flat_unstable = bool((f["converged"].to_numpy(bool) & ~stable_mask(f) & (b < lo)).any()) \
        if math.isfinite(lo) else False
    nums = {"stable beta0": [_r(lo), _r(hi)], f"no gait at beta0 = {b[-1]:g}": steep_none,
            "unstable gaits flatter than the stable range": flat_unstable}
    return nums, bool(math.isfinite(lo) and lo > b[0] and hi < b[-1] and steep_none
                      and flat_unstable)


def _c421(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    s = _stable(_frame(d, "touchdown_angle"))
    b = s["beta0"].to_numpy(float)
    c_sd, c_p = _rank_corr(b, _abs(s, "step_down")), _rank_corr(b, _abs(s, "push"))
    return {"rank corr(beta0, |step_down|)": _r(c_sd), "rank corr(beta0, |push|)": _r(c_p)}, \
        bool(c_sd < 0 and c_p > 0)


def _c422(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    f = _frame(d, "retraction")
    lo, hi = stable_range(f, "omega_r_bar")
    w = f["omega_r_bar"].to_numpy(float)
    zero_stable = bool(stable_mask(f)[0]) if w[0] == 0 else False
    top_stable = bool(stable_mask(f)[-1])
    nums = {"stable omega_r_bar": [_r(lo), _r(hi)], "stable without retraction": zero_stable,
            f"stable at omega_r_bar = {w[-1]:g}": top_stable}
    return nums, bool(math.isfinite(lo) and not zero_stable and not top_stable)


def _c423(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    f = _frame(d, "retraction")
    s = _stable(f)
    sd = _abs(s, "step_down")
    pr = _ends(f, "pitch_rate")
    i = int(np.nanargmax(sd)) if np.isfinite(sd).any() else -1
    nums = {"|step_down| first stable / best / last": [_r(sd[0]), _r(sd[i]), _r(sd[-1])]
            if i >= 0 else [], "best omega_r_bar": _r(s["omega_r_bar"].iloc[i]) if i >= 0
            else math.nan, "|pitch_rate| first -> last stable": [_r(x) for x in pr]}
    return nums, bool(i >= 0 and sd[i] > sd[0] and sd[-1] < sd[i] and pr[1] > pr[0])


_CONTROLLERS = {"passive": "mass_offset", "global PD": "controller_global_pd",
                "local velocity": "controller_local_velocity",
                "constant torque": "controller_constant_torque"}


def _c424(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    nums: Numbers = {}
    pas = _frame(d, "mass_offset")
    nums["passive stable r"] = [_r(x) for x in stable_range(pas, "r")]
    lv = _frame(d, "controller_local_velocity")
    asym = lv[lv["stability"].eq("asymptotic") & stable_mask(lv)]
    nums["local velocity asymptotically stable points (r > 0 / all)"] = \
        [int((asym["r"] > 0).sum()), int(len(asym))]
    pd_ = _frame(d, "controller_global_pd")
    g = pd_[pd_["converged"].astype(bool)]
    m = g["max_nontrivial"].to_numpy(float)
    nums["global PD gaits (residual <= tol)"] = int(len(g))
    nums["global PD max residual"] = float(f"{g['residual'].max():.1e}") if len(g) else math.nan
    nums["global PD max|lambda| range"] = [_r(m.min(), 4), _r(m.max(), 4)] if m.size else []
    ok_pas = stable_range(pas, "r")[0] >= 0
    ok_lv = len(asym) >= 3 and (asym["r"] > 0).mean() > 0.5
    ok_pd = m.size > 0 and bool(np.all(np.abs(m - 1) < 0.01))
    return nums, bool(ok_pas and ok_lv and ok_pd)


def _median_abs(d: Mapping[str, Any], name: str, col: str) -> float:
    """Median |limit| over r > 0 where the limit was computed (stable or neutral gaits)."""
    f = _frame(d, name)
    f = f[f["r"] > 0]
    v = _abs(f, col)
    v = v[np.isfinite(v)]
    return float(np.median(v)) if v.size else math.nan


def _c425_pitch(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    med = {k: _median_abs(d, n, "pitch_rate") for k, n in _CONTROLLERS.items()}
    nums = {f"median |pitch_rate|, r > 0: {k}": _r(v) for k, v in med.items()}
    pd_ = med["global PD"]
    others = [v for k, v in med.items() if k != "global PD"]
    return nums, bool(math.isfinite(pd_) and all(pd_ > v for v in others if math.isfinite(v)))


def _c425_push(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    med = {k: _median_abs(d, n, "push") for k, n in _CONTROLLERS.items()}
    nums = {f"median |push|, r > 0: {k}": _r(v) for k, v in med.items()}
    lv = med["local velocity"]
    others = [v for k, v in med.items() if k != "local velocity"]
    return nums, bool(math.isfinite(lv) and all(lv < v for v in others if math.isfinite(v)))


def _c61(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    t = d["table6.1"]
    nums = {"max|lambda|": _r(t["max_nontrivial"]), "thesis": 0.92}
    return nums, abs(t["max_nontrivial"] - 0.92) < 0.01


def _c61_rob(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    t = d["table6.1"]
    thesis = {"step_down": -0.12, "push": -0.73, "pitch_rate": -1.50}
    nums = {k: [_r(t[k]), v] for k, v in thesis.items()}
    nums["(ours, thesis)"] = "per limit"
    return nums, all(abs(t[k] - v) <= 0.01 + 1e-12 for k, v in thesis.items())


def _c62_stride(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    t = d["table6.1"]
    thesis = {"stance_time": 0.58, "flight_time": 0.13, "duty_factor": 0.82,
              "step_frequency": 1.41}
    nums = {k: [_r(t[k]), v] for k, v in thesis.items()}
    return nums, all(abs(t[k] - v) <= 0.01 for k, v in thesis.items())


def _cC1(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    a, b = d["C.1"]["table2.1"], d["C.1"]["table6.1"]
    nums = {"Table 2.1 slip fraction": _r(a.slip_fraction), "Table 2.1 max |F_x|/F_y":
            _r(a.max_ratio), "Table 6.1 slip fraction": _r(b.slip_fraction),
            "Table 6.1 first slip (t / t_s)": _r(b.first_slip)}
    return nums, bool(not a.slips and b.slips and b.first_slip >= 0.8)


def _ce2(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    te = d["E"]["e2"]["tracking"]
    return {"thigh RMS [L]": _r(te.thigh_rms, 5), "hip RMS [rad]": _r(te.hip_rms, 4),
            "ratio": _r(te.thigh_rms / te.hip_rms, 4)}, te.thigh_rms < 0.1 * te.hip_rms


def _ce4_unstable(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    e = d["E"]["e2"]
    return {"largest |lambda| at Table E.2": _r(e["largest"], 3), "thesis": 67.0,
            "periodicity residual there": _r(e["residual"], 3)}, e["largest"] > 1.0


def _ce4_falls(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    e = d["E"]["e2"]
    return {"strides until fall": e["strides"], "thesis": "about 10",
            "reason": e["reason"]}, abs(e["strides"] - 10) <= 2


def _ce4_meta(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    nums, ok = _pitch(d["E"]["converged"], "metacentric")
    nums["dtheta_b"] = nums.pop("dphi")
    nums["hip distance / r_1"] = nums.pop("hip distance / r")
    return nums, ok and nums["max |direction change| [rad]"] < 0.1


def _ce_stable(d: Mapping[str, Any]) -> tuple[Numbers, bool]:
    c = d["E"]["converged"]
    return {"largest |lambda|": _r(c["largest"], 4), "periodicity residual": float(
        f"{c['residual']:.1e}"), "strides run": f"{c['strides']} of {c['of']}"}, bool(
        c["largest"] < 1.0 and c["residual"] < 1e-8 and c["strides"] == c["of"])


def _claim(figure: str, text: str, needs: tuple[str, ...], fn: Callable) -> Claim:
    return Claim(figure, text, needs, fn)


#: Every claim, in figure order.
CLAIMS: tuple[Claim, ...] = (
    _claim("4.1", "For small pitch disturbances the steepest impulse gradient is in x_p, the "
           "horizontal point of application.", ("4.1",), _c41),
    _claim("4.2", "Passive: the impulse stays directed at the hip, so its torque opposes the "
           "pitch disturbance (metacentric), and its direction hardly changes.", ("4.2",), _c42),
    _claim("4.3", "Global PD: the hip torque turns the impulse strongly (unlike the passive "
           "model).", ("4.2", "4.3"), _c43),
    _claim("4.4", "Passive: the speed settles at the eq. 3.8 energy-balance value after a ground "
           "step; local velocity control returns to v0.", ("4.4",), _c44),
    _claim("4.5", "After a 0.2 L step down, speed and height oscillate in opposite phase and "
           "converge.", ("4.5",), _c45),
    _claim("4.6", "The touch-down leg angle changes from stride to stride after the step.",
           ("4.5",), _c46),
    _claim("4.7", "A more downward touch-down velocity lengthens stance and turns the impulse "
           "forward (upward: shorter stance, impulse backward).", ("4.7",), _c47),
    _claim("4.8", "There is a minimum speed for stable running; above it gaits stay stable and "
           "faster running converges more slowly.", ("velocity",), _c48),
    _claim("4.9", "Push robustness grows about linearly with v0.", ("velocity",), _c49_push),
    _claim("4.9", "Step-down robustness peaks at an intermediate speed (about 4-5).",
           ("velocity",), _c49_step),
    _claim("4.9", "Pitch-rate robustness varies only minimally with speed.", ("velocity",),
           _c49_pitch),
    _claim("4.10", "The stable region in k x beta0 grows with v0 (2, 3, 4, 5).",
           tuple(f"grid_v{v:g}" for v in (2.0, 3.0, 4.0, 5.0)), _c410),
    _claim("4.11", "Stance and flight times match eqs. 3.10 and 3.11 closely.",
           ("stride_v0", "stride_k", "stride_beta0"), _c411),
    _claim("4.11", "Stance time is not affected by leg stiffness.", ("stride_k",), _c411_k),
    _claim("4.12", "Leg damping lowers the largest multiplier (better height and speed "
           "stability).", ("leg_damping",), _c412),
    _claim("4.13", "Leg damping lowers all three robustness limits.", ("leg_damping",), _c413),
    _claim("4.14", "Hip damping improves stability (the non-trivial multipliers shrink).",
           ("hip_damping",), _c414),
    _claim("4.15", "Hip damping raises pitch-rate robustness and lowers push robustness.",
           ("hip_damping",), _c415),
    _claim("4.16", "Passive gaits are stable for 0 < r up to about 0.86 (none with r < 0).",
           ("mass_offset",), _c416),
    _claim("4.17", "Raising r towards 0.5 improves step-down and pitch-rate robustness.",
           ("mass_offset",), _c417),
    _claim("4.18", "Stable over a wide range of k; no gaits at too low k; unstable gaits above "
           "the stable range.", ("stiffness",), _c418),
    _claim("4.19", "Push robustness decreases with stiffness.", ("stiffness",), _c419),
    _claim("4.20", "Stable for a range of beta0; flatter angles become unstable, too steep "
           "ones have no gait.", ("touchdown_angle",), _c420),
    _claim("4.21", "Flatter legs resist step-downs better; steeper legs resist pushes better.",
           ("touchdown_angle",), _c421),
    _claim("4.22", "Some retraction is needed for stability; high rates destabilise.",
           ("retraction",), _c422),
    _claim("4.23", "Some retraction improves step-down robustness (high rates reduce it) and "
           "retraction improves pitch-rate robustness.", ("retraction",), _c423),
    _claim("4.24", "Passive gaits stable only for r > 0; local velocity control asymptotically "
           "stable mostly for r > 0; global PD gaits neutrally stable (|lambda| ~ 1).",
           tuple(_CONTROLLERS.values()), _c424),
    _claim("4.25", "Global PD handles the largest pitch-rate disturbances.",
           tuple(_CONTROLLERS.values()), _c425_pitch),
    _claim("4.25", "Local velocity control is the least robust to a push.",
           tuple(_CONTROLLERS.values()), _c425_push),
    _claim("6.1", "The Table 6.1 gait's largest multiplier is 0.92.", ("table6.1",), _c61),
    _claim("6.1", "Table 6.1 robustness: step-down -0.12, push -0.73, pitch rate -1.50 "
           "(within 0.01).", ("table6.1",), _c61_rob),
    _claim("6.2", "Table 6.2 stride: t_s 0.58, t_f 0.13, duty factor 0.82, frequency 1.41 "
           "(within 0.01).", ("table6.1",), _c62_stride),
    _claim("6.2", "Table 6.1 model: the impulse torque opposes the pitch disturbance.",
           ("6.2",), _c62),
    _claim("C.1", "Table 2.1 never exceeds friction mu = 1; Table 6.1 exceeds it slightly in "
           "the last part of stance.", ("C.1",), _cC1),
    _claim("E.2", "Biped: the thigh length tracks its reference far more closely than the hip "
           "angle (Figure E.2).", ("E",), _ce2),
    _claim("E.4", "Biped from Table E.2: numerically unstable (largest multiplier 67.0).",
           ("E",), _ce4_unstable),
    _claim("E.4", "Biped from Table E.2: falls after about 10 strides (within 2).", ("E",),
           _ce4_falls),
    _claim("E.4", "Biped: after +-0.5 rad of body pitch the impulse's moment about the CoM "
           "restores the pitch and its direction hardly changes (metacentric, Figure E.4).",
           ("E",), _ce4_meta),
    _claim("E.4", "Beyond the thesis: a periodic biped gait with all multipliers inside the unit "
           "circle exists (the thesis found none).", ("E",), _ce_stable),
)


def _as_check(out: Check | tuple[Numbers, bool]) -> Check:
    if isinstance(out, Check):
        return out
    nums, ok = out
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def evaluate(data: Mapping[str, Any],
             claims: tuple[Claim, ...] = CLAIMS) -> list[ClaimResult]:
    """Test every claim whose data is present; a failing computation counts as not holding."""
    out = []
    for c in claims:
        if not all(n in data for n in c.needs):
            continue
        common = {"quote": c.quote, "source": c.source, "reading": c.reading}
        try:
            k = _as_check(c.test(data))
            out.append(ClaimResult(c.figure, c.text, k.numbers, k.verdict, evidence=k.evidence,
                                   note=k.note, **common))
        except Exception as exc:  # noqa: BLE001 - shown in the report as a failure
            out.append(ClaimResult(c.figure, c.text, {}, Verdict.FAILS,
                                   f"{type(exc).__name__}: {exc}", **common))
    return out
