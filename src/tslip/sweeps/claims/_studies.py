"""The parameter studies' claims (Figures 4.8-4.25): speed, damping, offsets, retraction, control.

One check function a claim: the results in, a :class:`Check` out.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
import pandas as pd

from ._rules import (
    CLOSE,
    MIN_POINTS,
    MULT_TOL,
    PRINTED,
    REL,
    TEND,
    Check,
    Numbers,
    Verdict,
    _abs,
    _corr,
    _frame,
    _judge,
    _n,
    _opt_frame,
    _r,
    _readings,
    _stable,
    _trend,
    stable_mask,
    stable_range,
)

_SPEED_READINGS = (("omega_r held (study velocity)", "velocity"),
                   ("omega_r_bar = omega_r l0 / v0 held (eq. 2.18, study velocity_bar)",
                    "velocity_bar"))


def _by_speed(d: Mapping[str, Any],
              fn: Callable[[pd.DataFrame], tuple[Numbers, bool | None]]) -> Check:
    parts = {}
    for label, name in _SPEED_READINGS:
        f = _opt_frame(d, name)
        parts[label] = None if f is None else fn(f)
    return _readings(parts)


_V = "[g^1/2 L^1/2]"


def _speed_minimum(f: pd.DataFrame) -> tuple[Numbers, bool]:
    """A minimum speed: no stable gait at the slowest speeds of the sweep, stable ones above."""
    lo, hi = stable_range(f, "v0")
    v = f["v0"].to_numpy(float)
    nums: Numbers = {f"min stable v0 {_V}": _r(lo), f"slowest v0 swept {_V}": _r(v.min())}
    return nums, bool(math.isfinite(lo) and lo > v.min())


def _speed_above(f: pd.DataFrame) -> tuple[Numbers, bool]:
    """Every speed from the minimum stable one to the fastest swept is stable."""
    lo, hi = stable_range(f, "v0")
    m = stable_mask(f)
    v = f["v0"].to_numpy(float)
    gaps = v[(v >= lo) & ~m] if math.isfinite(lo) else v[:0]
    nums: Numbers = {f"min stable v0 {_V}": _r(lo), f"stable up to {_V}": _r(hi),
                     f"fastest v0 swept {_V}": _r(v.max()),
                     f"unstable or no gait above the minimum at v0 {_V}": [_r(x) for x in gaps]}
    return nums, bool(math.isfinite(lo) and not gaps.size and hi == v.max())


def _speed_quickest(f: pd.DataFrame) -> tuple[Numbers, bool | None]:
    """'Most quickly just over the minimum': the slowest stable gait's max|lambda| smallest."""
    s = f[stable_mask(f)]
    vs, mnt = s["v0"].to_numpy(float), s["max_nontrivial"].to_numpy(float)
    if vs.size < 2:
        return {"stable points": int(vs.size)}, None
    i = int(np.argmin(mnt))
    rho = _trend(vs, mnt, +1)[0]
    nums: Numbers = {
        f"slowest stable v0 (just over the minimum) {_V}": _r(vs[0]),
        "max|lambda| there": _r(mnt[0], 4),
        f"fastest convergence (smallest max|lambda|) at v0 {_V}": _r(vs[i]),
        "smallest max|lambda|": _r(mnt[i], 4),
        "max|lambda| at the fastest stable v0": _r(mnt[-1], 4),
        f"fastest stable v0 {_V}": _r(vs[-1]),
        "rank corr(v0, max|lambda|), stable gaits": _r(rho)}
    return nums, bool(mnt[0] <= mnt[i] + MULT_TOL)


def _c48_minimum(d: Mapping[str, Any]) -> Check:
    return _by_speed(d, _speed_minimum)


def _c48_above(d: Mapping[str, Any]) -> Check:
    return _by_speed(d, _speed_above)


def _c48_quickest(d: Mapping[str, Any]) -> Check:
    return _by_speed(d, _speed_quickest)


#: "Increases almost linearly": the Pearson correlation of |push| with v0 at least this.
LINEAR = 0.98


def _speed_push(f: pd.DataFrame) -> tuple[Numbers, bool | None]:
    s = _stable(f)
    v, p = s["v0"].to_numpy(float), _abs(s, "push")
    ok = np.isfinite(p)
    if ok.sum() < MIN_POINTS:
        return {"points": int(ok.sum())}, None
    slope = float(np.polyfit(v[ok], p[ok], 1)[0])
    c = _corr(v, p)
    vmin = v[ok] - p[ok]
    nums = {"corr(v0, |push|)": _r(c, 4), "slope d|push|/dv0": _r(slope),
            "v0 - |push| (implied minimum speed) [g^1/2 L^1/2]": [_r(vmin.min(), 2),
                                                                  _r(vmin.max(), 2)]}
    return nums, bool(c >= LINEAR and abs(slope - 1.0) <= REL)


def _c49_push(d: Mapping[str, Any]) -> Check:
    return _by_speed(d, _speed_push)


def _speed_step(f: pd.DataFrame) -> tuple[Numbers, bool | None]:
    s = _stable(f)
    v, sd = s["v0"].to_numpy(float), _abs(s, "step_down")
    ok = np.isfinite(sd)
    if ok.sum() < MIN_POINTS:
        return {"points": int(ok.sum())}, None
    v, sd = v[ok], sd[ok]
    i = int(np.argmax(sd))
    rho, falls = _trend(v[i:], sd[i:], -1)
    nums = {f"best v0 {_V}": _r(v[i]), "max |step-down| [L]": _r(sd[i]),
            "|step-down| at slowest stable / fastest [L]": [_r(sd[0]), _r(sd[-1])],
            "rank corr(v0, |step-down|) above the best": _r(rho)}
    return nums, bool(0 < i < len(sd) - 1 and 3.5 <= v[i] <= 5.5 and falls)


def _c49_step(d: Mapping[str, Any]) -> Check:
    return _by_speed(d, _speed_step)


def _speed_pitch(f: pd.DataFrame) -> tuple[Numbers, bool | None]:
    p = _abs(_stable(f), "pitch_rate")
    p = p[np.isfinite(p)]
    if p.size < 2:
        return {"points": int(p.size)}, None
    rel = float((p.max() - p.min()) / p.max())
    return {"|pitch rate| min [rad g^1/2 L^-1/2]": _r(p.min()),
            "|pitch rate| max [rad g^1/2 L^-1/2]": _r(p.max()),
            "relative variation": _r(rel)}, rel < REL


def _c49_pitch(d: Mapping[str, Any]) -> Check:
    return _by_speed(d, _speed_pitch)


def grid_stable_fractions(d: Mapping[str, Any]) -> dict[float, float]:
    """Fraction of the k x beta0 grid with a stable gait, per Figure 4.10 panel."""
    from ..catalogue import GRID_SPEEDS

    return {v: float(stable_mask(_frame(d, f"grid_v{v:g}")).mean()) for v in GRID_SPEEDS}


def _c410(d: Mapping[str, Any]) -> Check:
    fr = grid_stable_fractions(d)
    vals = list(fr.values())
    nums = {f"stable area fraction at v0 = {v:g}": _r(x) for v, x in fr.items()}
    ok = all(b >= a for a, b in zip(vals, vals[1:])) and vals[-1] > vals[0]
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _v0_col(d: Mapping[str, Any], name: str, f: pd.DataFrame) -> np.ndarray:
    if "v0" in f:
        return f["v0"].to_numpy(float)
    return np.full(len(f), float(d[name].spec.base.v0))


#: Flight is ballistic: t_f = 2 |ydot| / g (eq. 3.11's exact form) to the event-location
#: accuracy of the integration (1e-10); a relative 1e-6 is far above that and far below
#: the 2 % a wrong flight gravity makes.
BALLISTIC = 1e-6
_STRIDE_LINES = (("stride_v0", "v0"), ("stride_k", "k"), ("stride_beta0", "beta0"))


def _converged(f: pd.DataFrame) -> pd.DataFrame:
    return f[f["converged"].astype(bool)]


def _c411(d: Mapping[str, Any]) -> Check:
    nums: Numbers = {}
    worst_s = worst_f = worst_b = 0.0
    for name, _ in _STRIDE_LINES:
        f = _converged(d[name].frame)
        g = float(d[name].spec.base.g) if hasattr(d[name], "spec") else 1.0
        v0 = _v0_col(d, name, f)
        delta = np.abs(f["delta"].to_numpy(float))
        tf = f["flight_time"].to_numpy(float)
        exact = (f["flight_time_predicted"].to_numpy(float) if "flight_time_predicted" in f
                 else 2.0 * v0 * np.sin(delta) / g)
        es = np.abs(f["stance_time"].to_numpy(float) / f["stance_time_predicted"].to_numpy(float)
                    - 1)
        ef = np.abs(tf / (2.0 * v0 * delta / g) - 1)
        eb = np.abs(tf / exact - 1)
        ms, mf = float(np.nanmedian(es)), float(np.nanmedian(ef))
        mb = float(np.max(eb)) if eb.size else math.nan
        nums[f"{name}: median |t_s / eq.3.10 - 1|"] = _r(ms)
        nums[f"{name}: median |t_f / (2 v0 delta / g) - 1|"] = _r(mf)
        nums[f"{name}: max |t_f / (2 |ydot| / g) - 1|"] = float(f"{mb:.1e}")
        worst_s, worst_f, worst_b = max(worst_s, ms), max(worst_f, mf), max(worst_b, mb)
    nums["bound: eq. 3.10 and the approximation of eq. 3.11 (median)"] = CLOSE
    nums["bound: eq. 3.11's exact form (every gait)"] = BALLISTIC
    ok = worst_s < CLOSE and worst_f < CLOSE and worst_b < BALLISTIC  # NaN fails
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c411_flight(d: Mapping[str, Any]) -> Check:
    nums: Numbers = {}
    ok, points = True, {}
    for (name, col), sign in zip(_STRIDE_LINES, (-1, +1, -1), strict=True):
        f = _converged(d[name].frame)
        x, tf = f[col].to_numpy(float), f["flight_time"].to_numpy(float)
        rho, good = _trend(x, tf, sign)
        nums[f"rank corr({col}, flight time) (thesis: {'+' if sign > 0 else '-'})"] = _r(rho)
        points[f"rank corr({col}, flight time)"] = _n(x, tf)
        ok &= good
    return _judge(nums, ok, points)


def _c411_k(d: Mapping[str, Any]) -> Check:
    def rel_var(f: pd.DataFrame) -> tuple[Numbers, bool]:
        ts = f["stance_time"].to_numpy(float)
        if ts.size < 2:
            return {"points": int(ts.size)}, False
        rel = float(np.ptp(ts) / np.mean(ts))
        return {"k range [MgL^-1]": [_r(f["k"].min(), 1), _r(f["k"].max(), 1)],
                "stance time range [g^-1/2 L^1/2]": [_r(ts.min()), _r(ts.max())],
                "relative variation": _r(rel)}, rel < CLOSE

    trends: Numbers = {}
    ok_trend = True
    for name, col in (("stride_v0", "v0"), ("stride_beta0", "beta0")):
        f = d[name].frame
        f = f[f["converged"].astype(bool)]
        rho, ok = _trend(f[col].to_numpy(float), f["stance_time"].to_numpy(float), -1)
        trends[f"rank corr({col}, stance time)"] = _r(rho)
        ok_trend &= ok
    fk = d["stride_k"].frame
    parts: dict[str, tuple[Numbers, bool] | None] = {}
    for label, f in (("stable gaits (those Figure 4.18 analyses)", fk[stable_mask(fk)]),
                     ("every gait found", fk[fk["converged"].astype(bool)])):
        n, ok = rel_var(f)
        parts[label] = ({**n, **trends}, ok and ok_trend)
    return _readings(parts)


def _c412(d: Mapping[str, Any]) -> Check:
    f = _converged(_frame(d, "leg_damping"))
    c = f["c_l"].to_numpy(float)
    mags = f[[f"abs_lambda_{j}" for j in range(1, 6)]].to_numpy(float)
    mags = -np.sort(-mags, axis=1)  # each gait's five |lambda|, largest first
    nums: Numbers = {}
    if not (c.size and c[0] == 0 and (c > 0).any()):
        return Check({"undamped gait and damped gaits": False}, Verdict.FAILS)
    base = mags[0]  # the undamped model keeps its trivial energy multiplier 1
    damped = mags[c > 0]
    not_above = bool(np.all(damped <= base + MULT_TOL))
    below = bool(np.all(np.any(damped < base - MULT_TOL, axis=1)))
    worse = c[c > 0][np.any(damped > base + MULT_TOL, axis=1)]
    nums["sorted |lambda| at c_l = 0 (trivial 1 included)"] = [_r(x, 4) for x in base]
    nums["sorted |lambda| at the largest c_l"] = [_r(x, 4) for x in damped[-1]]
    nums["largest rise of a sorted |lambda| over c_l = 0"] = float(
        f"{np.max(damped - base):.1e}")
    nums["c_l with a sorted |lambda| above the undamped one [Mg^1/2 L^-1/2]"] = [
        _r(x) for x in worse]
    nums["every damped gait has a sorted |lambda| below the undamped one"] = below
    rho, more = _trend(c, mags[:, 0], -1)
    return _readings({"adding damping (every c_l > 0: each sorted |lambda| at most the "
                      "undamped one's, one lower)": (nums, not_above and below),
                      "more damping, more stable": (
                          {"rank corr(c_l, largest |lambda|, the undamped trivial 1 counted)":
                           _r(rho)}, more)})


_LIMIT_UNITS = {"step_down": "L", "push": "g^1/2 L^1/2", "pitch_rate": "rad g^1/2 L^-1/2"}


def _c413(d: Mapping[str, Any]) -> Check:
    f = _frame(d, "leg_damping")
    s = _stable(f)
    c = s["c_l"].to_numpy(float)
    top = float(f["c_l"].max())
    high = c >= 2.0 / 3.0 * top
    high_n: Numbers = {"high damping: c_l >= [Mg^1/2 L^-1/2]": _r(2.0 / 3.0 * top)}
    best_n: Numbers = dict(high_n)
    trend_n: Numbers = {}
    ok_high = ok_best = ok_trend = bool(c.size) and c[0] == 0 and bool(high.any())
    for k in ("step_down", "push", "pitch_rate"):
        v = _abs(s, k)
        u = _LIMIT_UNITS[k]
        none = float(v[0]) if c.size and c[0] == 0 else math.nan
        med = float(np.nanmedian(v[high])) if high.any() else math.nan
        best = float(np.nanmax(v)) if np.isfinite(v).any() else math.nan
        i = int(np.nanargmax(v)) if np.isfinite(v).any() else 0
        high_n[f"|{k}| at c_l = 0, median high [{u}]"] = [_r(none), _r(med)]
        best_n[f"|{k}| best, median high [{u}]"] = [_r(best), _r(med)]
        best_n[f"|{k}| best at c_l [Mg^1/2 L^-1/2]"] = _r(c[i]) if c.size else math.nan
        ok_high &= med < none
        ok_best &= bool(c.size) and c[i] < 2.0 / 3.0 * top and med < best
        rho, ok = _trend(c, v, -1)
        trend_n[f"rank corr(c_l, |{k}|)"] = _r(rho)
        ok_trend &= ok
    return _readings({"high damping against none (caption)": (high_n, bool(ok_high)),
                      "more damping, less robust (text)": (trend_n, bool(ok_trend)),
                      "high damping lowers each limit from its best value":
                      (best_n, bool(ok_best))})


def _mean_nontrivial(g: pd.DataFrame) -> np.ndarray:
    """Mean of each gait's non-trivial |lambda| (those not 1 to :data:`MULT_TOL`)."""
    mags = g[[f"abs_lambda_{j}" for j in range(1, 6)]].to_numpy(float)
    mags = np.where(np.abs(mags - 1) < MULT_TOL, np.nan, mags)  # trivial multipliers
    if not mags.size:
        return np.array([])
    n = np.isfinite(mags).sum(axis=1)
    return np.where(n > 0, np.nansum(mags, axis=1) / np.maximum(n, 1), np.nan)


def _c414(d: Mapping[str, Any]) -> Check:
    g = _converged(_frame(d, "hip_damping"))
    mean = _mean_nontrivial(g)
    c = g["controller.c_h"].to_numpy(float)
    rho, ok = _trend(c, mean, -1)
    nums = {"mean non-trivial |lambda| at c_h = 0 / largest": [_r(mean[0], 4), _r(mean[-1], 4)]
            if mean.size else [], "rank corr(c_h, mean non-trivial |lambda|)": _r(rho)}
    return _judge(nums, ok, {"rank corr(c_h, mean non-trivial |lambda|)": _n(c, mean)})


def _c415(d: Mapping[str, Any]) -> Check:
    s = _stable(_frame(d, "hip_damping"))
    c = s["controller.c_h"].to_numpy(float)
    r_push, ok_push = _trend(c, _abs(s, "push"), -1)
    r_pitch, ok_pitch = _trend(c, _abs(s, "pitch_rate"), +1)
    nums = {"rank corr(c_h, |push|)": _r(r_push), "rank corr(c_h, |pitch_rate|)": _r(r_pitch)}
    return _judge(nums, ok_push and ok_pitch, {"rank corr(c_h, |push|)": _n(c, _abs(s, "push")),
                                               "rank corr(c_h, |pitch_rate|)":
                                               _n(c, _abs(s, "pitch_rate"))})


def _c416(d: Mapping[str, Any]) -> Check:
    f = _frame(d, "mass_offset")
    lo, hi = stable_range(f, "r")
    m = stable_mask(f)
    r = f["r"].to_numpy(float)
    neg = int(m[r < 0].sum())
    nxt = r[r > hi].min() if math.isfinite(hi) and (r > hi).any() else math.nan
    gaps = int(((r > 0) & (r <= hi) & ~m).sum()) if math.isfinite(hi) else 0
    nums = {"stable r [L]": [_r(lo), _r(hi)], "boundary between r [L]": [_r(hi), _r(nxt)],
            "stable points with r < 0": neg, "unstable points inside (0, last stable r]": gaps}
    # the boundary lies in [hi, nxt]; 0.86 is printed to two decimals
    ok = (neg == 0 and lo >= 0 and gaps == 0 and math.isfinite(nxt)
          and hi <= 0.86 + PRINTED and nxt >= 0.86 - PRINTED)
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c417(d: Mapping[str, Any]) -> Check:
    s = _stable(_frame(d, "mass_offset"))
    s = s[(s["r"] > 0) & (s["r"] <= 0.5)]
    r = s["r"].to_numpy(float)
    r_sd, ok_sd = _trend(r, _abs(s, "step_down"), +1)
    r_p, ok_p = _trend(r, _abs(s, "pitch_rate"), +1)
    nums = {"stable r in (0, 0.5] [L]": [_r(x) for x in r],
            "rank corr(r, |step_down|)": _r(r_sd), "rank corr(r, |pitch_rate|)": _r(r_p)}
    return _judge(nums, ok_sd and ok_p,
                  {"rank corr(r, |step_down|)": _n(r, _abs(s, "step_down")),
                   "rank corr(r, |pitch_rate|)": _n(r, _abs(s, "pitch_rate"))})


def _c418(d: Mapping[str, Any]) -> Check:
    f = _frame(d, "stiffness")
    lo, hi = stable_range(f, "k")
    k = f["k"].to_numpy(float)
    conv = f["converged"].to_numpy(bool)
    m = stable_mask(f)
    low_none = bool(not conv[0])
    above = np.flatnonzero(k > hi) if math.isfinite(hi) else np.array([], int)
    unstable_next = bool(above.size and conv[above[0]] and not m[above[0]])
    s = f[m & (k <= (lo + hi) / 2)] if math.isfinite(lo) else f[m]
    ks = s["k"].to_numpy(float)
    common: Numbers = {"stable k [MgL^-1]": [_r(lo, 1), _r(hi, 1)],
                       "stable k max / min": _r(hi / lo) if math.isfinite(lo) and lo > 0
                       else math.nan,
                       f"no gait at k = {k[0]:g} [MgL^-1]": low_none,
                       "unstable gait just above the stable range": unstable_next,
                       "stable points in the lower half": int(len(s))}
    ok = bool(math.isfinite(lo) and hi >= 2 * lo and low_none and unstable_next)
    if not ok or len(s) < MIN_POINTS:  # a part failing decides; else too few points
        return _judge(common, ok, {} if not ok else {"a rank correlation over the lower half":
                                                     len(s)})
    parts: dict[str, tuple[Numbers, bool | None] | None] = {}
    for label, y in (("largest non-trivial |lambda|", s["max_nontrivial"].to_numpy(float)),
                     ("mean non-trivial |lambda| (the measure of 4.14)",
                      _mean_nontrivial(s))):
        rho, improves = _trend(ks, y, -1)
        parts[label] = ({**common, f"rank corr(k, {label}), lower half of the stable range":
                         _r(rho), f"{label} at the lowest / highest k of the lower half":
                         [_r(y[0], 4), _r(y[-1], 4)]}, ok and improves)
    return _readings(parts)


def _c419(d: Mapping[str, Any]) -> Check:
    s = _stable(_frame(d, "stiffness"))
    k, push = s["k"].to_numpy(float), _abs(s, "push")
    rc, ok = _trend(k, push, -1)
    return _judge({"rank corr(k, |push|)": _r(rc), "stable points": int(len(s))}, ok,
                  {"rank corr(k, |push|)": _n(k, push)})


def _c420(d: Mapping[str, Any]) -> Check:
    f = _frame(d, "touchdown_angle")
    lo, hi = stable_range(f, "beta0")
    b = f["beta0"].to_numpy(float)
    conv = f["converged"].to_numpy(bool)
    steep_none = bool(math.isfinite(hi) and (b > hi).any() and not conv[b > hi][-1])
    flat_unstable = bool((conv & ~stable_mask(f) & (b < lo)).any()) if math.isfinite(lo) \
        else False
    nums = {"stable beta0 [rad]": [_r(lo), _r(hi)],
            f"no gait at beta0 = {b[-1]:g} rad": not conv[-1],
            "unstable gaits flatter than the stable range": flat_unstable}
    ok = math.isfinite(lo) and lo > b[0] and steep_none and flat_unstable
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c421(d: Mapping[str, Any]) -> Check:
    s = _stable(_frame(d, "touchdown_angle"))
    b = s["beta0"].to_numpy(float)
    c_sd, ok_sd = _trend(b, _abs(s, "step_down"), -1, TEND)
    c_p, ok_p = _trend(b, _abs(s, "push"), +1, TEND)
    return _judge({"rank corr(beta0, |step_down|)": _r(c_sd), "rank corr(beta0, |push|)":
                   _r(c_p)}, ok_sd and ok_p,
                  {"rank corr(beta0, |step_down|)": _n(b, _abs(s, "step_down")),
                   "rank corr(beta0, |push|)": _n(b, _abs(s, "push"))})


def _c422(d: Mapping[str, Any]) -> Check:
    f = _frame(d, "retraction")
    lo, hi = stable_range(f, "omega_r_bar")
    w = f["omega_r_bar"].to_numpy(float)
    m = stable_mask(f)
    zero_stable = bool(m[w == 0].any())
    g = f[f["converged"].to_numpy(bool) & (w > 0)]
    wg, mg = g["omega_r_bar"].to_numpy(float), g["max_nontrivial"].to_numpy(float)
    i = int(np.nanargmin(mg)) if np.isfinite(mg).any() else 0
    rho, grows = _trend(wg[i:], mg[i:], +1)
    nums = {"stable omega_r_bar": [_r(lo), _r(hi)], "stable without retraction": zero_stable,
            "most stable rate": _r(wg[i]) if wg.size else math.nan,
            "rank corr(omega_r_bar, max|lambda|) above it": _r(rho)}
    ok = bool(m.any()) and (w == 0).any() and not zero_stable and grows
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c423(d: Mapping[str, Any]) -> Check:
    f = _frame(d, "retraction")
    s = _stable(f)
    w, sd = s["omega_r_bar"].to_numpy(float), _abs(s, "step_down")
    zero = sd[w == 0]
    # an unstable gait (or none) without retraction withstands no step-down
    sd0 = float(zero[0]) if zero.size and math.isfinite(zero[0]) else 0.0
    pos = (w > 0) & np.isfinite(sd)
    if not pos.any():
        return Check({"stable points with retraction": 0}, Verdict.FAILS)
    wp, sp = w[pos], sd[pos]
    i = int(np.argmax(sp))
    r_sd, falls = _trend(wp[i:], sp[i:], -1)
    r_p, ok_p = _trend(w, _abs(s, "pitch_rate"), +1)
    nums = {"|step_down| without retraction (0 if no stable gait) [L]": _r(sd0),
            "best |step_down| [L]": _r(sp[i]), "at omega_r_bar": _r(wp[i]),
            "rank corr(omega_r_bar, |step_down|) above the best": _r(r_sd),
            "rank corr(omega_r_bar, |pitch_rate|)": _r(r_p)}
    ok = sp[i] > sd0 and falls and ok_p
    evidence = {"omega_r_bar from the best rate up": [_r(x) for x in wp[i:]],
                "|step_down| there [L]": [_r(x) for x in sp[i:]]}
    return _judge(nums, bool(ok), {"rank corr(omega_r_bar, |pitch_rate|)":
                                   _n(w, _abs(s, "pitch_rate"))}, evidence)


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


def _c425_pitch(d: Mapping[str, Any]) -> Check:
    t = _by_r(d, "pitch_rate", _CONTROLLERS)
    u = "[rad g^1/2 L^-1/2]"
    if len(t) < MIN_POINTS:
        return _judge({}, False, {"r > 0 with a limit for every controller": len(t)})
    med = t.median()
    others = [k for k in _CONTROLLERS if k != "global PD"]
    best_other = float(med[others].max())
    ratio = float(med["global PD"]) / best_other
    nums: Numbers = {f"median |pitch_rate| over the shared r {u}: {k}": _r(v)
                     for k, v in med.items()}
    nums["shared r > 0 (every controller has a limit) [L]"] = [_r(t.index.min()),
                                                               _r(t.index.max())]
    nums["shared r points"] = int(len(t))
    nums["global PD / best other (medians)"] = _r(ratio)
    per_r = t["global PD"] / t[others].max(axis=1)
    r0 = _near(t, R_TABLE21)
    evidence: Numbers = {
        "r [L]": [_r(x) for x in t.index],
        "global PD / best other at each r": [_r(x) for x in per_r],
        f"global PD / best other at r = {_r(r0)} L (nearest Table 2.1's {R_TABLE21})":
            _r(per_r.loc[r0])}
    return _judge(nums, ratio > 1 + REL, evidence=evidence)


def _c425_similar(d: Mapping[str, Any]) -> Check:
    names = {k: n for k, n in _CONTROLLERS.items() if k != "global PD"}
    t = _by_r(d, "pitch_rate", names)
    u = "[rad g^1/2 L^-1/2]"
    if len(t) < MIN_POINTS:
        return _judge({}, False, {"r > 0 with a limit for every controller": len(t)})
    med = t.median()
    nums: Numbers = {f"median |pitch_rate| over the shared r {u}: {k}": _r(v)
                     for k, v in med.items()}
    rel = float((med.max() - med.min()) / med.max())
    nums["relative spread of the medians"] = _r(rel)
    spread = (t.max(axis=1) - t.min(axis=1)) / t.max(axis=1)
    evidence: Numbers = {
        "r [L]": [_r(x) for x in t.index],
        "relative spread at each r": [_r(x) for x in spread],
        "r where similar (spread < 0.25) [L]": [_r(x) for x in t.index[spread < REL]],
        "r where not similar [L]": [_r(x) for x in t.index[spread >= REL]]}
    return _judge(nums, rel < REL, evidence=evidence)


def _c425_push(d: Mapping[str, Any]) -> Check:
    t = _by_r(d, "push", _CONTROLLERS)
    if len(t) < MIN_POINTS:
        return _judge({}, False, {"r > 0 with a limit for every controller": len(t)})
    med = t.median()
    nums: Numbers = {f"median |push| over the shared r [g^1/2 L^1/2]: {k}": _r(v)
                     for k, v in med.items()}
    lv = float(med["local velocity"])
    ok = all(lv < float(v) for k, v in med.items() if k != "local velocity")
    return _judge(nums, ok)
