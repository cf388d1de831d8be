"""One check function a claim: the results in, a :class:`Check` out."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
import pandas as pd

from ._rules import (
    CLOSE,
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
    _opt_frame,
    _printed,
    _r,
    _readings,
    _stable,
    _trend,
    stable_mask,
    stable_range,
)

# -- claims -------------------------------------------------------------------

def _c41(d: Mapping[str, Any]) -> Check:
    lin = d["4.1"]
    g = {k: float(lin.as_dict()[k]) for k in ("I_x", "I_y", "x_p", "y_p")}
    nums: Numbers = {f"d{k}/dphi": _r(v, 4) for k, v in g.items()}
    nums["y_p ill-conditioned"] = bool(lin.y_p_ill_conditioned)

    def reading(others: tuple[str, ...]) -> tuple[Numbers, bool]:
        ratio = max(abs(g[k]) for k in others) / abs(g["x_p"]) if g["x_p"] else math.inf
        return {"largest other gradient / |dx_p/dphi|": _r(ratio)}, bool(ratio < REL)

    parts = {"all four gradients": reading(("I_x", "I_y", "y_p"))}
    if lin.y_p_ill_conditioned:
        parts["y_p left out (undefined: the impulse is vertical)"] = reading(("I_x", "I_y"))
    return _readings(parts, nums)


def _pitch_parts(resp: Any) -> tuple[Numbers, bool, bool, bool]:
    """Numbers of a pitch response; restoring, direction unchanged, towards the hip."""
    idx = [i for i, x in enumerate(resp.dphis) if x != 0.0]
    dphi = [float(resp.dphis[i]) for i in idx]
    turn = [abs(float(resp.direction_change[i])) / abs(resp.dphis[i]) for i in idx]
    hip = [float(resp.hip_distance[i]) for i in idx]
    rest = [resp.restoring[i] for i in idx]
    nums = {"dphi": dphi, "torque": [_r(resp.impulses[i].torque, 4) for i in idx],
            "restoring": rest,
            "|direction change| / |dphi|": [_r(t, 4) for t in turn],
            "hip distance / r": [_r(h) for h in hip]}
    restoring = bool(rest) and all(r is True for r in rest)
    unchanged = bool(turn) and all(t < REL for t in turn)
    towards = bool(hip) and all(h < 0.5 for h in hip)
    return nums, restoring, unchanged, towards


def _c42(d: Mapping[str, Any]) -> Check:
    nums, rest, same, hip = _pitch_parts(d["4.2"])
    return Check(nums, Verdict.HOLDS if rest and same and hip else Verdict.FAILS)


def _c43(d: Mapping[str, Any]) -> Check:
    nums = _pitch_parts(d["4.3"])[0]
    turn = nums["|direction change| / |dphi|"]
    nums["passive |direction change| / |dphi|"] = _pitch_parts(d["4.2"])[0][
        "|direction change| / |dphi|"]
    large = bool(turn) and max(turn) >= REL
    return Check(nums, Verdict.HOLDS if large else Verdict.FAILS)


def _c62(d: Mapping[str, Any]) -> Check:
    nums, rest, _, hip = _pitch_parts(d["6.2"])
    return Check(nums, Verdict.HOLDS if rest and hip else Verdict.FAILS)


def _c44(d: Mapping[str, Any]) -> Check:
    h = d["4.4"]
    pas, lv = h["passive"], h["local_velocity"]
    err = [abs(r.dv - r.dv_expected) for r in pas]
    lv_dv = [abs(r.dv) for r in lv]
    nums = {"dh": list(h["dh"]), "passive dv": [_r(r.dv, 4) for r in pas],
            "eq. 3.8 dv": [_r(r.dv_expected, 4) for r in pas],
            "max |dv - eq. 3.8|": float(f"{np.nanmax(err):.2e}") if pas else math.nan,
            "local velocity max |dv| (runs without a fall)":
                float(f"{np.nanmax(lv_dv):.2e}") if np.isfinite(lv_dv).any() else math.nan,
            "falls (passive, local velocity) at dh": [
                [r.dh for r in pas if not math.isfinite(r.dv)],
                [r.dh for r in lv if not math.isfinite(r.dv)]]}
    ok = (bool(pas) and bool(lv) and all(e < 1e-3 for e in err)
          and all(x < 1e-3 for x in lv_dv))  # a fall (NaN) fails
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c45(d: Mapping[str, Any]) -> Check:
    r = d["4.5"]
    xd = np.asarray(r.xd, float)[1:]
    early, late = float(np.ptp(xd[:5])), float(np.ptp(xd[-5:]))
    corr = float(r.phase_correlation)
    nums = {"corr(height, xd)": _r(corr), "bound (opposite phase within 45 deg)":
            _r(-math.cos(math.pi / 4)), "xd spread first 5": _r(early, 4),
            "xd spread last 5": _r(late, 4), "strides": int(len(r.xd))}
    ok = corr <= -math.cos(math.pi / 4) and late < REL * early
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c46(d: Mapping[str, Any]) -> Check:
    beta = np.asarray(d["4.5"].beta, float)[1:6]
    steps = np.abs(np.diff(beta))
    smallest = float(steps.min()) if steps.size else math.nan
    nums = {"touch-down beta, strides 1-5 [rad]": [_r(b, 4) for b in beta],
            "smallest stride-to-stride change [rad]": float(f"{smallest:.2e}")}
    return Check(nums, Verdict.HOLDS if smallest > 1e-6 else Verdict.FAILS)


def _c47(d: Mapping[str, Any]) -> Check:
    cases = sorted(d["4.7"], key=lambda c: c.ddelta)
    down, mid, up = cases[0], cases[len(cases) // 2], cases[-1]
    nums = {"ddelta": [c.ddelta for c in cases],
            "stance time": [_r(c.stance_time, 4) for c in cases],
            "I_x": [_r(c.impulse.I_x, 4) for c in cases]}
    ok = (down.stance_time > mid.stance_time > up.stance_time
          and down.impulse.I_x > 0 > up.impulse.I_x)
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


_SPEED_READINGS = (("omega_r held (study velocity)", "velocity"),
                   ("omega_r_bar = omega_r l0 / v0 held (eq. 2.18, study velocity_bar)",
                    "velocity_bar"))


def _by_speed(d: Mapping[str, Any],
              fn: Callable[[pd.DataFrame], tuple[Numbers, bool]]) -> Check:
    parts = {}
    for label, name in _SPEED_READINGS:
        f = _opt_frame(d, name)
        parts[label] = None if f is None else fn(f)
    return _readings(parts)


def _speed_stability(f: pd.DataFrame) -> tuple[Numbers, bool]:
    lo, hi = stable_range(f, "v0")
    m = stable_mask(f)
    v = f["v0"].to_numpy(float)
    nums: Numbers = {"min stable v0": _r(lo), "stable up to": _r(hi)}
    if not m.any():
        return nums, False
    s = f[m]
    vs, mnt = s["v0"].to_numpy(float), s["max_nontrivial"].to_numpy(float)
    i = int(np.argmin(mnt))
    all_above = bool(m[v >= lo].all())
    rho, slower = _trend(vs[i:], mnt[i:], +1)
    quick = vs[i] <= lo + 0.25 * (hi - lo)
    nums.update({"stable everywhere above the minimum": all_above,
                 "fastest convergence (min max|lambda|) at v0": _r(vs[i]),
                 "lowest quarter of the stable range up to": _r(lo + 0.25 * (hi - lo)),
                 "min max|lambda|": _r(mnt[i], 4), "max|lambda| at fastest": _r(mnt[-1], 4),
                 "rank corr(v0, max|lambda|) above the fastest convergence": _r(rho)})
    ok = lo > v.min() and all_above and hi == v.max() and quick and slower
    return nums, bool(ok)


def _c48(d: Mapping[str, Any]) -> Check:
    return _by_speed(d, _speed_stability)


def _speed_push(f: pd.DataFrame) -> tuple[Numbers, bool]:
    s = _stable(f)
    v, p = s["v0"].to_numpy(float), _abs(s, "push")
    ok = np.isfinite(p)
    if ok.sum() < 3:
        return {"points": int(ok.sum())}, False
    slope = float(np.polyfit(v[ok], p[ok], 1)[0])
    c = _corr(v, p)
    vmin = v[ok] - p[ok]
    nums = {"corr(v0, |push|)": _r(c, 4), "slope d|push|/dv0": _r(slope),
            "v0 - |push| (implied minimum speed)": [_r(vmin.min(), 2), _r(vmin.max(), 2)]}
    return nums, bool(c >= 0.98 and abs(slope - 1.0) <= REL)


def _c49_push(d: Mapping[str, Any]) -> Check:
    return _by_speed(d, _speed_push)


def _speed_step(f: pd.DataFrame) -> tuple[Numbers, bool]:
    s = _stable(f)
    v, sd = s["v0"].to_numpy(float), _abs(s, "step_down")
    ok = np.isfinite(sd)
    if ok.sum() < 3:
        return {"points": int(ok.sum())}, False
    v, sd = v[ok], sd[ok]
    i = int(np.argmax(sd))
    rho, falls = _trend(v[i:], sd[i:], -1)
    nums = {"best v0": _r(v[i]), "max |step-down|": _r(sd[i]),
            "|step-down| at slowest stable / fastest": [_r(sd[0]), _r(sd[-1])],
            "rank corr(v0, |step-down|) above the best": _r(rho)}
    return nums, bool(0 < i < len(sd) - 1 and 3.5 <= v[i] <= 5.5 and falls)


def _c49_step(d: Mapping[str, Any]) -> Check:
    return _by_speed(d, _speed_step)


def _speed_pitch(f: pd.DataFrame) -> tuple[Numbers, bool]:
    p = _abs(_stable(f), "pitch_rate")
    p = p[np.isfinite(p)]
    if not p.size:
        return {"points": 0}, False
    rel = float((p.max() - p.min()) / p.max())
    return {"|pitch rate| min": _r(p.min()), "max": _r(p.max()),
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


def _c411(d: Mapping[str, Any]) -> Check:
    nums: Numbers = {}
    worst_s = worst_f = 0.0
    for name in ("stride_v0", "stride_k", "stride_beta0"):
        f = d[name].frame
        f = f[f["converged"].astype(bool)]
        g = float(d[name].spec.base.g) if hasattr(d[name], "spec") else 1.0
        tf_eq = 2.0 * _v0_col(d, name, f) * np.abs(f["delta"].to_numpy(float)) / g
        es = np.abs(f["stance_time"].to_numpy(float) / f["stance_time_predicted"].to_numpy(float)
                    - 1)
        ef = np.abs(f["flight_time"].to_numpy(float) / tf_eq - 1)
        ms, mf = float(np.nanmedian(es)), float(np.nanmedian(ef))
        nums[f"{name}: median |t_s / eq.3.10 - 1|"] = _r(ms)
        nums[f"{name}: median |t_f / (2 v0 delta / g) - 1|"] = _r(mf)
        worst_s, worst_f = max(worst_s, ms), max(worst_f, mf)
    ok = worst_s < CLOSE and worst_f < CLOSE  # NaN fails
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c411_k(d: Mapping[str, Any]) -> Check:
    def rel_var(f: pd.DataFrame) -> tuple[Numbers, bool]:
        ts = f["stance_time"].to_numpy(float)
        if ts.size < 2:
            return {"points": int(ts.size)}, False
        rel = float(np.ptp(ts) / np.mean(ts))
        return {"k range": [_r(f["k"].min(), 1), _r(f["k"].max(), 1)],
                "stance time range": [_r(ts.min()), _r(ts.max())],
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
    f = _frame(d, "leg_damping")
    g = f[f["converged"].astype(bool)]
    m, c = g["max_nontrivial"].to_numpy(float), g["c_l"].to_numpy(float)
    nums: Numbers = {"max|lambda| at c_l = 0": _r(m[0], 4) if c.size and c[0] == 0 else math.nan,
                     "largest max|lambda| with damping":
                         _r(np.nanmax(m[c > 0]), 4) if (c > 0).any() else math.nan}
    has_zero = bool(c.size and c[0] == 0 and (c > 0).any())
    added = has_zero and bool(np.all(m[c > 0] < m[0] - MULT_TOL))
    rho, more = _trend(c, m, -1)
    return _readings({"adding damping (every c_l > 0 below c_l = 0)": (nums, added),
                      "more damping, more stable": ({"rank corr(c_l, max|lambda|)": _r(rho)},
                                                    more)})


def _c413(d: Mapping[str, Any]) -> Check:
    f = _frame(d, "leg_damping")
    s = _stable(f)
    c = s["c_l"].to_numpy(float)
    top = float(f["c_l"].max())
    high = c >= 2.0 / 3.0 * top
    high_n: Numbers = {"high damping: c_l >=": _r(2.0 / 3.0 * top)}
    trend_n: Numbers = {}
    ok_high = ok_trend = bool(c.size) and c[0] == 0 and high.any()
    for k in ("step_down", "push", "pitch_rate"):
        v = _abs(s, k)
        none = float(v[0]) if c.size and c[0] == 0 else math.nan
        med = float(np.nanmedian(v[high])) if high.any() else math.nan
        high_n[f"|{k}| at c_l = 0 / median high"] = [_r(none), _r(med)]
        ok_high &= med < none
        rho, ok = _trend(c, v, -1)
        trend_n[f"rank corr(c_l, |{k}|)"] = _r(rho)
        ok_trend &= ok
    return _readings({"high damping against none (caption)": (high_n, bool(ok_high)),
                      "more damping, less robust (text)": (trend_n, bool(ok_trend))})


def _c414(d: Mapping[str, Any]) -> Check:
    f = _frame(d, "hip_damping")
    g = f[f["converged"].astype(bool)]
    cols = [f"abs_lambda_{j}" for j in range(1, 6)]
    mags = g[cols].to_numpy(float)
    mags = np.where(np.abs(mags - 1) < MULT_TOL, np.nan, mags)  # trivial multipliers
    with np.errstate(all="ignore"):
        mean = np.nanmean(mags, axis=1) if mags.size else np.array([])
    rho, ok = _trend(g["controller.c_h"].to_numpy(float), mean, -1)
    nums = {"mean non-trivial |lambda| at c_h = 0 / largest": [_r(mean[0], 4), _r(mean[-1], 4)]
            if mean.size else [], "rank corr(c_h, mean non-trivial |lambda|)": _r(rho)}
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c415(d: Mapping[str, Any]) -> Check:
    s = _stable(_frame(d, "hip_damping"))
    c = s["controller.c_h"].to_numpy(float)
    r_push, ok_push = _trend(c, _abs(s, "push"), -1)
    r_pitch, ok_pitch = _trend(c, _abs(s, "pitch_rate"), +1)
    nums = {"rank corr(c_h, |push|)": _r(r_push), "rank corr(c_h, |pitch_rate|)": _r(r_pitch)}
    return Check(nums, Verdict.HOLDS if ok_push and ok_pitch else Verdict.FAILS)


def _c416(d: Mapping[str, Any]) -> Check:
    f = _frame(d, "mass_offset")
    lo, hi = stable_range(f, "r")
    m = stable_mask(f)
    r = f["r"].to_numpy(float)
    neg = int(m[r < 0].sum())
    nxt = r[r > hi].min() if math.isfinite(hi) and (r > hi).any() else math.nan
    gaps = int(((r > 0) & (r <= hi) & ~m).sum()) if math.isfinite(hi) else 0
    nums = {"stable r": [_r(lo), _r(hi)], "boundary between r": [_r(hi), _r(nxt)],
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
    nums = {"stable r in (0, 0.5]": [_r(x) for x in r],
            "rank corr(r, |step_down|)": _r(r_sd), "rank corr(r, |pitch_rate|)": _r(r_p)}
    return Check(nums, Verdict.HOLDS if ok_sd and ok_p else Verdict.FAILS)


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
    rho, improves = _trend(s["k"].to_numpy(float), s["max_nontrivial"].to_numpy(float), -1)
    nums = {"stable k": [_r(lo, 1), _r(hi, 1)], "stable k max / min": _r(hi / lo)
            if math.isfinite(lo) and lo > 0 else math.nan,
            f"no gait at k = {k[0]:g}": low_none,
            "unstable gait just above the stable range": unstable_next,
            "rank corr(k, max|lambda|), lower half of the stable range": _r(rho)}
    ok = math.isfinite(lo) and hi >= 2 * lo and low_none and unstable_next and improves
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c419(d: Mapping[str, Any]) -> Check:
    s = _stable(_frame(d, "stiffness"))
    rc, ok = _trend(s["k"].to_numpy(float), _abs(s, "push"), -1)
    return Check({"rank corr(k, |push|)": _r(rc), "stable points": int(len(s))},
                 Verdict.HOLDS if ok else Verdict.FAILS)


def _c420(d: Mapping[str, Any]) -> Check:
    f = _frame(d, "touchdown_angle")
    lo, hi = stable_range(f, "beta0")
    b = f["beta0"].to_numpy(float)
    conv = f["converged"].to_numpy(bool)
    steep_none = bool(math.isfinite(hi) and (b > hi).any() and not conv[b > hi][-1])
    flat_unstable = bool((conv & ~stable_mask(f) & (b < lo)).any()) if math.isfinite(lo) \
        else False
    nums = {"stable beta0": [_r(lo), _r(hi)], f"no gait at beta0 = {b[-1]:g}": not conv[-1],
            "unstable gaits flatter than the stable range": flat_unstable}
    ok = math.isfinite(lo) and lo > b[0] and steep_none and flat_unstable
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c421(d: Mapping[str, Any]) -> Check:
    s = _stable(_frame(d, "touchdown_angle"))
    b = s["beta0"].to_numpy(float)
    c_sd, ok_sd = _trend(b, _abs(s, "step_down"), -1, TEND)
    c_p, ok_p = _trend(b, _abs(s, "push"), +1, TEND)
    return Check({"rank corr(beta0, |step_down|)": _r(c_sd), "rank corr(beta0, |push|)":
                  _r(c_p)}, Verdict.HOLDS if ok_sd and ok_p else Verdict.FAILS)


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
    nums = {"|step_down| without retraction (0 if no stable gait)": _r(sd0),
            "best |step_down| / at best omega_r_bar": [_r(sp[i]), _r(wp[i])],
            "rank corr(omega_r_bar, |step_down|) above the best": _r(r_sd),
            "rank corr(omega_r_bar, |pitch_rate|)": _r(r_p)}
    ok = sp[i] > sd0 and falls and ok_p
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


_CONTROLLERS = {"passive": "mass_offset", "global PD": "controller_global_pd",
                "local velocity": "controller_local_velocity",
                "constant torque": "controller_constant_torque"}


def _c424_passive(d: Mapping[str, Any]) -> Check:
    f = _frame(d, "mass_offset")
    lo, hi = stable_range(f, "r")
    nums = {"passive stable r": [_r(lo), _r(hi)]}
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


def _median_abs(d: Mapping[str, Any], name: str, col: str) -> float:
    """Median |limit| over r > 0 where the limit was computed (stable or neutral gaits)."""
    f = _frame(d, name)
    f = f[f["r"] > 0]
    v = _abs(f, col)
    v = v[np.isfinite(v)]
    return float(np.median(v)) if v.size else math.nan


def _c425_pitch(d: Mapping[str, Any]) -> Check:
    med = {k: _median_abs(d, n, "pitch_rate") for k, n in _CONTROLLERS.items()}
    nums: Numbers = {f"median |pitch_rate|, r > 0: {k}": _r(v) for k, v in med.items()}
    pd_ = med["global PD"]
    best_other = max((v for k, v in med.items() if k != "global PD"), default=math.nan)
    nums["global PD / best other"] = _r(pd_ / best_other)
    ok = math.isfinite(pd_) and pd_ > (1 + REL) * best_other
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c425_similar(d: Mapping[str, Any]) -> Check:
    med = {k: _median_abs(d, n, "pitch_rate") for k, n in _CONTROLLERS.items()
           if k != "global PD"}
    nums: Numbers = {f"median |pitch_rate|, r > 0: {k}": _r(v) for k, v in med.items()}
    v = np.array(list(med.values()))
    rel = float((v.max() - v.min()) / v.max()) if np.isfinite(v).all() else math.nan
    nums["relative spread"] = _r(rel)
    return Check(nums, Verdict.HOLDS if rel < REL else Verdict.FAILS)


def _c425_push(d: Mapping[str, Any]) -> Check:
    med = {k: _median_abs(d, n, "push") for k, n in _CONTROLLERS.items()}
    nums = {f"median |push|, r > 0: {k}": _r(v) for k, v in med.items()}
    lv = med["local velocity"]
    others = [v for k, v in med.items() if k != "local velocity"]
    ok = math.isfinite(lv) and all(math.isfinite(v) and lv < v for v in others)
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c61(d: Mapping[str, Any]) -> Check:
    nums, ok = _printed(d["table6.1"]["max_nontrivial"], 0.92)
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c61_limit(kind: str, thesis: float) -> Callable[[Mapping[str, Any]], Check]:
    def test(d: Mapping[str, Any]) -> Check:
        t = d["table6.1"]
        nums, ok = _printed(t[kind], thesis)
        evidence: Numbers = {}
        if kind == "pitch_rate":
            var = t.get("pitch_rate_variants")
            evidence["pitch-rate limit per placement / variant"] = (
                {k: _r(v) for k, v in var.items()} if var else "not computed")
        return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS, evidence)

    test.__name__ = f"_c61_{kind}"
    return test


def _c61_alphad(d: Mapping[str, Any]) -> Check:
    t = d["table6.1"]
    nums, ok = _printed(t["alphad_ref"], 2.42)
    forced = t.get("alphad_ref_forced")
    if ok:
        return Check(nums, Verdict.HOLDS)
    if not forced:
        return Check(nums, Verdict.FAILS, {"residual with alphad_ref = 2.42": "not computed"})
    res = float(forced["residual"])
    evidence = {"alphad_ref forced": forced.get("alphad_ref", 2.42),
                "periodicity residual left": float(f"{res:.2e}"),
                "our solved alphad_ref": _r(forced.get("free", t["alphad_ref"]), 4)}
    if res <= 1e-8:  # a fixed point with the printed reference exists as well
        return Check(nums, Verdict.HOLDS_UNDER_READING, evidence,
                     "a periodic gait with alphad_ref = 2.42 exists too (residual <= 1e-8); "
                     "our solver found another")
    return Check(nums, Verdict.FAILS, evidence)


def _c62_stride(d: Mapping[str, Any]) -> Check:
    t = d["table6.1"]
    printed = {"stance_time": 0.58, "flight_time": 0.13, "duty_factor": 0.82,
               "step_frequency": 1.41}
    rounding = {k: [_r(t[k], 4), v] for k, v in printed.items()}
    ok_round = all(abs(t[k] - v) <= PRINTED for k, v in printed.items())
    runner = {"stance_time": 0.58, "flight_time": 0.13}
    tuned = {f"{k} (ours, runner)": [_r(t[k], 4), v] for k, v in runner.items()}
    ok_tuned = all(abs(t[k] - v) <= 0.01 for k, v in runner.items())
    return _readings({"printed TSLIP values are ours rounded (within 0.005)":
                      (rounding, ok_round),
                      "t_s, t_f within 0.01 of the runner's (the stated tuning)":
                      (tuned, ok_tuned)})


def _cC1(d: Mapping[str, Any]) -> Check:
    a, b = d["C.1"]["table2.1"], d["C.1"]["table6.1"]
    nums = {"Table 2.1 slip fraction": _r(a.slip_fraction), "Table 2.1 max |F_x|/F_y":
            _r(a.max_ratio), "Table 6.1 slip fraction": _r(b.slip_fraction),
            "Table 6.1 first slip (t / t_s)": _r(b.first_slip, 4)}
    ok = not a.slips and b.slips and b.first_slip >= 0.9 - PRINTED
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _ce2(d: Mapping[str, Any]) -> Check:
    te = d["E"]["e2"]["tracking"]
    ratio = te.thigh_rms / te.hip_rms
    return Check({"thigh RMS [L]": _r(te.thigh_rms, 5), "hip RMS [rad]": _r(te.hip_rms, 4),
                  "ratio": _r(ratio, 4)}, Verdict.HOLDS if ratio < 0.1 else Verdict.FAILS)


def _ce4_unstable(d: Mapping[str, Any]) -> Check:
    e = d["E"]["e2"]
    big = float(e["largest"])
    base = {"largest |lambda| at Table E.2": _r(big, 3),
            "periodicity residual there": _r(e["residual"], 3)}
    value = {"ours": _r(big, 3), "thesis": 67.0}
    return _readings({"numerically unstable (largest |lambda| > 1)": (base, big > 1.0),
                      "largest |lambda| 67.0 (to the printed 0.05)":
                      (value, abs(big - 67.0) <= 0.05)}, base)


def _ce4_falls(d: Mapping[str, Any]) -> Check:
    e = d["E"]["e2"]
    n = int(e["strides"])
    nums = {"strides until fall": n, "thesis": "about 10", "reason": e["reason"]}
    pert = e.get("strides_perturbed")
    evidence: Numbers = {
        "strides under perturbations within Table E.2's rounding":
            list(pert) if pert else "not computed",
        "minimum contact time": e.get("min_contact", "not computed")}
    if abs(n - 10) <= 2:
        return Check(nums, Verdict.HOLDS, evidence)
    if pert:
        med = float(np.median(pert))
        evidence["median over perturbations"] = med
        if abs(med - 10) <= 2:
            return Check(nums, Verdict.HOLDS_UNDER_READING, evidence,
                         "the printed start gives another count, but the median over starts "
                         "within its rounding is about 10")
    return Check(nums, Verdict.FAILS, evidence)


def _ce4_meta(d: Mapping[str, Any]) -> Check:
    resp = d["E"]["converged"]["metacentric"]
    nums, rest, same, _ = _pitch_parts(resp)
    nums["dtheta_b"] = nums.pop("dphi")
    nums["hip distance / r_1"] = nums.pop("hip distance / r")
    nom = resp.nominal.magnitude
    mag = [abs(resp.impulses[i].magnitude / nom - 1) for i, x in enumerate(resp.dphis)
           if x != 0.0]
    nums["|magnitude change| / magnitude"] = [_r(m, 4) for m in mag]
    ok = rest and same and bool(mag) and all(m < REL for m in mag)
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _ce_stable(d: Mapping[str, Any]) -> Check:
    c = d["E"]["converged"]
    ok = c["largest"] < 1.0 and c["residual"] < 1e-8 and c["strides"] == c["of"]
    return Check({"largest |lambda|": _r(c["largest"], 4), "periodicity residual": float(
        f"{c['residual']:.1e}"), "strides run": f"{c['strides']} of {c['of']}"},
        Verdict.HOLDS if ok else Verdict.FAILS)
