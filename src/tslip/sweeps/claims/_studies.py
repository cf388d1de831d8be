"""The parameter studies' claims (Figures 4.8-4.25): speed, damping, offsets, retraction, control.

One check function a claim: the results in, a :class:`Check` out.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
import pandas as pd

from ._eigen import _measures, _speed_quickest
from ._rules import (
    _TOO_FEW,
    CLOSE,
    MIN_POINTS,
    MULT_TOL,
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
    _printed,
    _r,
    _readings,
    _stable,
    _trend,
    stable_mask,
    stable_range,
)

#: Figures 4.8-4.9's set-up, Section 3.4.1: v0 varied with "the passive TSLIP model with
#: the configuration in Table 2.1", whose retraction is the absolute rate omega_r = 1.0.
THESIS_SPEED = ("omega_r held (Section 3.4.1's set-up, study velocity)", "velocity")
#: The other set-up, shown as evidence only: omega_r_bar = omega_r l0 / v0 held (eq. 2.18).
OTHER_SPEED = ("omega_r_bar = omega_r l0 / v0 held (eq. 2.18, study velocity_bar; evidence, "
               "not judged)", "velocity_bar")


def _as_check(out: Check | tuple[Numbers, bool | None]) -> Check:
    if isinstance(out, Check):
        return out
    nums, ok = out
    if ok is None:
        return Check(nums, Verdict.NOT_ASSESSED, {}, _TOO_FEW)
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _by_speed(d: Mapping[str, Any],
              fn: Callable[[pd.DataFrame], Check | tuple[Numbers, bool | None]]) -> Check:
    """Judge a Figure 4.8-4.9 claim in the thesis's set-up; the other set-up's numbers beside.

    Every 4.8-4.9 claim is judged with omega_r held (:data:`THESIS_SPEED`),
    never with whichever set-up favours it; the omega_r_bar-held study's
    numbers and verdict are in the evidence.
    """
    main = _as_check(fn(_frame(d, THESIS_SPEED[1])))
    evidence: Numbers = {f"{THESIS_SPEED[0]}: {k}": v for k, v in main.evidence.items()}
    other = _opt_frame(d, OTHER_SPEED[1])
    if other is None:
        evidence[OTHER_SPEED[0]] = "not computed"
    else:
        o = _as_check(fn(other))
        evidence.update({f"{OTHER_SPEED[0]}: {k}": v for k, v in o.numbers.items()})
        evidence[f"{OTHER_SPEED[0]}: verdict"] = o.verdict.value
    note = f"judged with {THESIS_SPEED[0]}; the other set-up's numbers are in the evidence"
    return Check(main.numbers, main.verdict, evidence,
                 f"{main.note}; {note}" if main.note else note)


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
    shown: Numbers = {}  # the eigenvalue rule's two measures, shown beside (not judged)
    for label, y in _measures(f).items():
        shown[f"{label} at c_l = 0 / the largest c_l (shown, not judged)"] = [
            _r(y[0], 4), _r(y[-1], 4)]
        shown[f"rank corr(c_l, {label}) (shown, not judged)"] = _r(_trend(c, y, -1)[0])
    check = _readings({"adding damping (every c_l > 0: each sorted |lambda| at most the "
                      "undamped one's, one lower)": (nums, not_above and below),
                      "more damping, more stable": (
                          {"rank corr(c_l, largest |lambda|, the undamped trivial 1 counted)":
                           _r(rho)}, more)})
    return Check(check.numbers, check.verdict, {**check.evidence, **shown}, check.note)


_LIMIT_UNITS = {"step_down": "L", "push": "g^1/2 L^1/2", "pitch_rate": "rad g^1/2 L^-1/2"}


def _c413(d: Mapping[str, Any]) -> Check:
    f = _frame(d, "leg_damping")
    s = _stable(f)
    c = s["c_l"].to_numpy(float)
    top = float(f["c_l"].max())
    high = c >= 2.0 / 3.0 * top
    high_n: Numbers = {"high damping: c_l >= [Mg^1/2 L^-1/2]": _r(2.0 / 3.0 * top)}
    best_n: Numbers = {}
    trend_n: Numbers = {}
    ok_high = ok_best = ok_trend = bool(c.size) and c[0] == 0 and bool(high.any())
    for k in ("step_down", "push", "pitch_rate"):
        v = _abs(s, k)
        u = _LIMIT_UNITS[k]
        none = float(v[0]) if c.size and c[0] == 0 else math.nan
        med = float(np.nanmedian(v[high])) if high.any() else math.nan
        i = int(np.nanargmax(v)) if np.isfinite(v).any() else 0
        high_n[f"|{k}| at c_l = 0, median high [{u}]"] = [_r(none), _r(med)]
        ok_high &= med < none
        # from the best value on, the limit falls with damping: the trend form of 4.9, 4.23
        rho_b, falls = _trend(c[i:], v[i:], -1)
        best_n[f"|{k}| best at c_l [Mg^1/2 L^-1/2]"] = _r(c[i]) if c.size else math.nan
        best_n[f"rank corr(c_l, |{k}|) at and above the best c_l"] = _r(rho_b)
        best_n[f"points at and above the best c_l ({k})"] = int(np.isfinite(v[i:]).sum())
        ok_best &= falls
        rho, ok = _trend(c, v, -1)
        trend_n[f"rank corr(c_l, |{k}|)"] = _r(rho)
        ok_trend &= ok
    return _readings({"high damping against none (caption)": (high_n, bool(ok_high)),
                      "more damping, less robust (text)": (trend_n, bool(ok_trend)),
                      "damping beyond each limit's best value lowers it (rank corr <= -0.8)":
                      (best_n, bool(ok_best))})


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
    """Stable for 0 < r up to the boundary located by bisection, matched to the printed 0.86.

    The boundary comes from ``d["4.16"]`` (:func:`tslip.sweeps.reproduce.mass_offset_boundary`:
    the largest r with a stable gait, bisected to ``tol``), never from the grid's bracket,
    which is shown.
    """
    f = _frame(d, "mass_offset")
    located = d["4.16"]
    lo, hi = stable_range(f, "r")
    m = stable_mask(f)
    r = f["r"].to_numpy(float)
    neg = int(m[r < 0].sum())
    nxt = r[r > hi].min() if math.isfinite(hi) and (r > hi).any() else math.nan
    gaps = int(((r > 0) & (r <= hi) & ~m).sum()) if math.isfinite(hi) else 0
    boundary = float(located["boundary"])
    printed, ok_printed = _printed(boundary, 0.86, unit="L")
    nums: Numbers = {"located boundary (last stable r) [L]": _r(boundary, 4),
                     "bisection bracket [L]": [_r(x, 4) for x in located["bracket"]],
                     "bisection tolerance [L]": located["tol"],
                     **{f"boundary against the printed 0.86: {k}": v for k, v in
                        printed.items()},
                     "stable r on the grid [L]": [_r(lo), _r(hi)],
                     "grid bracket of the boundary [L]": [_r(hi), _r(nxt)],
                     "stable points with r < 0": neg,
                     "unstable points inside (0, last stable r]": gaps}
    ok = neg == 0 and lo >= 0 and gaps == 0 and ok_printed
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
