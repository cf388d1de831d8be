"""The response claims (Figures 4.1-4.7, 6.2): one gait's response to a disturbance or a change.

One check function a claim: the results in, a :class:`Check` out.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ._rules import (
    MULT_TOL,
    REL,
    Check,
    Numbers,
    Verdict,
    _r,
    _readings,
)


def _c41(d: Mapping[str, Any]) -> Check:
    lin = d["4.1"]
    g = {k: float(lin.as_dict()[k]) for k in ("I_x", "I_y", "x_p", "y_p")}
    units = {"I_x": "M g^1/2 L^1/2 rad^-1", "I_y": "M g^1/2 L^1/2 rad^-1", "x_p": "L rad^-1",
             "y_p": "L rad^-1"}
    nums: Numbers = {f"d{k}/dphi [{units[k]}]": _r(v, 4) for k, v in g.items()}
    nums["y_p ill-conditioned"] = bool(lin.y_p_ill_conditioned)
    # the moment of the vertical impulse about the CoM, x_p I_y, changes by I_y dx_p/dphi
    # per rad of pitch (positive counter-clockwise): negative counteracts the pitch
    i_y = float(getattr(getattr(lin, "nominal", None), "I_y", 1.0))
    moment = i_y * g["x_p"]
    nums["I_y dx_p/dphi [M g^1/2 L^3/2 rad^-1]"] = _r(moment, 4)
    restoring = moment < 0

    def reading(others: tuple[str, ...]) -> tuple[Numbers, bool]:
        ratio = max(abs(g[k]) for k in others) / abs(g["x_p"]) if g["x_p"] else math.inf
        return ({"largest other gradient / |dx_p/dphi|": _r(ratio),
                 "x_p shift counteracts the pitch": bool(restoring)},
                bool(ratio < REL and restoring))

    parts = {"all four gradients": reading(("I_x", "I_y", "y_p"))}
    if lin.y_p_ill_conditioned:
        parts["y_p left out (undefined: the impulse is vertical)"] = reading(("I_x", "I_y"))
    return _readings(parts, nums)


#: A line of action within this many r of the CoM passes through it: the undisturbed
#: gait's moment about the CoM is zero at a periodic gait (Section 3.2), to the gait's
#: and the quadrature's accuracy (about 1e-8 r at Tables 2.1 and 6.1), the same
#: numerical zero as the multipliers' (claims.MULT_TOL).
AT_COM = MULT_TOL


def _pitch_parts(resp: Any) -> tuple[Numbers, bool, bool]:
    """Numbers of a pitch response; restoring, direction unchanged."""
    idx = [i for i, x in enumerate(resp.dphis) if x != 0.0]
    dphi = [float(resp.dphis[i]) for i in idx]
    turn = [abs(float(resp.direction_change[i])) / abs(resp.dphis[i]) for i in idx]
    rest = [resp.restoring[i] for i in idx]
    nums = {"dphi [rad]": dphi, "torque [M g^1/2 L^3/2]": [_r(resp.impulses[i].torque, 4)
                                                         for i in idx],
            "restoring": rest,
            "|direction change| / |dphi|": [_r(t, 4) for t in turn]}
    restoring = bool(rest) and all(r is True for r in rest)
    unchanged = bool(turn) and all(t < REL for t in turn)
    return nums, restoring, unchanged


def _towards_hip(resp: Any) -> tuple[Numbers, bool]:
    """Section 7.1's test: the line of action passes between the hip and the CoM.

    For each impulse, the signed distances [r] of the CoM and of the
    ``F_y``-weighted mean hip from its line of action: the line crosses the
    CoM-hip segment when they differ in sign (or one is zero). Allowed too: a
    line passing beyond the hip end by at most :data:`REL` r ("approximately
    towards the hip"), and one within :data:`AT_COM` r of the CoM (through it,
    to numerical accuracy). The offset r is the hip's distance from the CoM
    at touch-down (``Impulse.hip_touchdown``).
    """
    dphi = [float(x) for x in resp.dphis]
    com, hip, beyond = [], [], []
    ok = bool(resp.impulses)
    for imp in resp.impulses:
        r = math.hypot(*imp.hip_touchdown)
        dc = imp.line_distance(0.0, 0.0) / r if r > 0 else math.nan
        dh = imp.line_distance(*imp.hip_mean) / r if r > 0 else math.nan
        between = dc * dh <= 0 or abs(dc) <= AT_COM  # NaN: False
        past_hip = dc * dh > 0 and abs(dh) < abs(dc)  # same side, the hip nearer the line
        com.append(_r(dc, 4))
        hip.append(_r(dh, 4))
        beyond.append(_r(abs(dh), 4) if past_hip and not between else 0.0)
        ok &= bool(between or (past_hip and abs(dh) <= REL))
    nums = {"line of action, at dphi [rad]": dphi,
            "signed distance of the CoM / r": com,
            "signed distance of the mean hip / r": hip,
            "beyond the hip end by / r (0: crosses the hip-CoM segment)": beyond,
            "tolerance beyond the hip end / r": REL}
    return nums, ok


def _c42(d: Mapping[str, Any]) -> Check:
    nums, rest, same = _pitch_parts(d["4.2"])
    hip_n, hip = _towards_hip(d["4.2"])
    return Check({**nums, **hip_n}, Verdict.HOLDS if rest and same and hip else Verdict.FAILS)


def _c43(d: Mapping[str, Any]) -> Check:
    nums = _pitch_parts(d["4.3"])[0]
    turn = nums["|direction change| / |dphi|"]
    nums["passive |direction change| / |dphi|"] = _pitch_parts(d["4.2"])[0][
        "|direction change| / |dphi|"]
    large = bool(turn) and max(turn) >= REL
    return Check(nums, Verdict.HOLDS if large else Verdict.FAILS)


def _c62(d: Mapping[str, Any]) -> Check:
    nums, rest, _ = _pitch_parts(d["6.2"])
    hip_n, hip = _towards_hip(d["6.2"])
    return Check({**nums, **hip_n}, Verdict.HOLDS if rest and hip else Verdict.FAILS)


def _c44(d: Mapping[str, Any]) -> Check:
    h = d["4.4"]
    limits = h.get("step_down_limit") or {}
    nums: Numbers = {"dh [L]": list(h["dh"])}
    ok = True
    for key, label in (("passive", "passive"), ("local_velocity", "local velocity")):
        runs = h[key]
        lim = float(limits.get(key, -math.inf))
        inside = [r for r in runs if r.dh >= lim]  # a step down within the gait's limit
        if key == "passive":
            err = [abs(r.dv - r.dv_expected) for r in inside]
            nums["passive dv [g^1/2 L^1/2]"] = [_r(r.dv, 4) for r in runs]
            nums["eq. 3.8 dv [g^1/2 L^1/2]"] = [_r(r.dv_expected, 4) for r in runs]
            what = "max |dv - eq. 3.8|"
        else:
            err = [abs(r.dv) for r in inside]
            nums["local velocity dv [g^1/2 L^1/2]"] = [_r(r.dv, 4) for r in runs]
            what = "local velocity max |dv|"
        nums[f"{label} step-down limit [L]"] = _r(lim, 4) if math.isfinite(lim) \
            else "not computed"
        nums[f"{what} within the limit [g^1/2 L^1/2]"] = (
            float(f"{np.max(err):.2e}") if err and np.isfinite(err).all() else
            ("a fall" if err else math.nan))
        nums[f"{label} falls at dh [L] (within / beyond the limit)"] = [
            [r.dh for r in inside if not math.isfinite(r.dv)],
            [r.dh for r in runs if r not in inside and not math.isfinite(r.dv)]]
        ok &= bool(inside) and all(e < 1e-3 for e in err)  # a fall (NaN) fails
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)


def _c45(d: Mapping[str, Any]) -> Check:
    r = d["4.5"]
    xd = np.asarray(r.xd, float)[1:]
    early, late = float(np.ptp(xd[:5])), float(np.ptp(xd[-5:]))
    corr = float(r.phase_correlation)
    nums = {"corr(height, xd)": _r(corr), "bound (opposite phase within 45 deg)":
            _r(-math.cos(math.pi / 4)), "xd spread first 5 [g^1/2 L^1/2]": _r(early, 4),
            "xd spread last 5 [g^1/2 L^1/2]": _r(late, 4), "strides": int(len(r.xd))}
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
    nums = {"ddelta [rad]": [c.ddelta for c in cases],
            "stance time [g^-1/2 L^1/2]": [_r(c.stance_time, 4) for c in cases],
            "I_x [M g^1/2 L^1/2]": [_r(c.impulse.I_x, 4) for c in cases]}
    ok = (down.stance_time > mid.stance_time > up.stance_time
          and down.impulse.I_x > 0 > up.impulse.I_x)
    return Check(nums, Verdict.HOLDS if ok else Verdict.FAILS)
