"""Every claim of :data:`tslip.sweeps.claims.CLAIMS` on constructed data.

Each claim's test function gets data built here from the thesis's wording
(not from our results): one set on which the claim must hold, one on which it
must fail and, for claims with two readings, one on which it holds under one
reading only. The cases are keyed by the test function's name and the test is
parametrised over CLAIMS, so a new claim without a case fails here.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from types import SimpleNamespace as NS
from typing import Any

import numpy as np
import pandas as pd
import pytest

from tslip.sweeps.claims import CLAIMS, Verdict, evaluate

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")

H, R, F = Verdict.HOLDS, Verdict.HOLDS_UNDER_READING, Verdict.FAILS


# -- builders ------------------------------------------------------------------

def study(axis: str, x: Any, *, mnt: Any = 0.9, v0: float = 5.0, **cols: Any) -> NS:
    """A StudyResult-like object: one row per ``x``; NaN ``mnt`` means no gait there.

    ``mnt`` is the largest non-trivial |lambda| (a stable gait below 1);
    other columns (limits, times) are given by keyword, scalars broadcast.
    """
    x = np.asarray(x, float)
    m = np.broadcast_to(np.asarray(mnt, float), x.shape).copy()
    conv = np.isfinite(m)
    stab = np.where(~conv, "none", np.where(m < 1.0, "neutral", "unstable"))
    f = pd.DataFrame({axis: x, "converged": conv, "stability": stab, "max_nontrivial": m,
                      "residual": np.where(conv, 0.0, np.nan)})
    for k, v in cols.items():
        f[k] = np.broadcast_to(np.asarray(v, dtype=float if k != "stability" else object),
                               x.shape).copy()
    for k in ("step_down", "push", "pitch_rate"):
        if k in f:
            f.loc[~(conv & (m < 1.0)), k] = np.nan  # limits only at stable gaits
    return NS(frame=f, spec=NS(base=NS(v0=v0, g=1.0)))


def pitch_response(turn: float = 0.01, hip: float = 0.01, restoring: bool = True,
                   magnitude_change: float = 0.01) -> NS:
    """Impulses after -0.5, 0, +0.5 rad of pitch."""
    imp = [NS(torque=0.06, magnitude=1.0 + magnitude_change), NS(torque=0.0, magnitude=1.0),
           NS(torque=-0.06, magnitude=1.0 - magnitude_change)]
    return NS(dphis=(-0.5, 0.0, 0.5), impulses=tuple(imp), nominal=imp[1],
              direction_change=(-turn, 0.0, turn), hip_distance=(hip, 0.0, hip),
              restoring=(restoring, None, restoring))


V = np.linspace(1.0, 10.0, 12)


def speed_line(good: bool, best_at: float = 4.2) -> NS:
    """Figure 4.8-4.9 shaped: no stable gait below 4; converges fastest at ``best_at``."""
    mnt = np.where(V < 4.0, np.nan, 0.99 + 0.0001 * (V - best_at) ** 2)
    if not good:
        mnt = np.where(V < 4.0, np.nan, 0.999 - 0.001 * (V - 4.0))  # fastest at the top
    push = -(V - 2.7) if good else -0.5 * V
    sd = -(0.25 - 0.02 * np.abs(V - 5.1)) if good else -(0.1 + 0.01 * V)
    pitch = -0.7 - 0.01 * np.sin(V) if good else -0.2 - 0.07 * V
    return study("v0", V, mnt=mnt, push=push, step_down=sd, pitch_rate=pitch)


def speed_data(good_a: bool, good_b: bool | None) -> dict:
    d = {"velocity": speed_line(good_a)}
    if good_b is not None:
        d["velocity_bar"] = speed_line(good_b)
    return d


def stride_lines(flight_factor: float = 1.01, k_variation: float = 0.0) -> dict:
    out = {}
    for name, col, x in (("stride_v0", "v0", np.linspace(2, 10, 8)),
                         ("stride_k", "k", np.linspace(5, 100, 8)),
                         ("stride_beta0", "beta0", np.linspace(0.8, 1.4, 8))):
        v0 = x if col == "v0" else np.full(8, 5.0)
        beta0 = x if col == "beta0" else np.full(8, 1.1)
        k = x if col == "k" else np.full(8, 20.0)
        delta = -0.05 * np.ones(8) - 0.001 * k
        ts_pred = 2 * (np.pi / 2 - beta0) / v0
        ts = ts_pred * (1.02 + k_variation * (k - 5) / 95)
        tf = 2 * v0 * np.abs(delta) * flight_factor
        out[name] = study(col, x, stance_time=ts, stance_time_predicted=ts_pred,
                          flight_time=tf, delta=delta)
    return out


def damping(limits_fall: bool = True, pitch_fall: bool = True, mnt: Any = None,
            pitch: Any = None) -> dict:
    c = np.linspace(0, 3, 12)
    m = 0.995 - 0.003 * c if mnt is None else mnt
    s = -1 if limits_fall else 1
    sp = -1 if pitch_fall else 1
    return {"leg_damping": study("c_l", c, mnt=m, step_down=-(0.2 + s * 0.04 * c),
                                 push=-(2.1 + s * 0.5 * c),
                                 pitch_rate=-(1.0 + sp * 0.2 * c) if pitch is None else pitch)}


def hip_damping(good: bool) -> dict:
    c = np.linspace(0, 3, 12)
    lam = 0.95 - 0.05 * c if good else 0.8 + 0.05 * c
    d = study("controller.c_h", c, mnt=np.maximum(lam, 0.5), push=-(2.2 - 0.5 * c),
              pitch_rate=-(1.0 + (0.8 if good else -0.2) * c))
    f = d.frame
    f["abs_lambda_1"] = 1.0  # a trivial multiplier, left out of the mean
    for j in range(2, 6):
        f[f"abs_lambda_{j}"] = lam / j
    return {"hip_damping": d}


RR = np.linspace(-1, 1, 50)


def mass_offset(top: float = 0.86, rising: bool = True, stable_neg: bool = False) -> NS:
    stable = (RR > 0) & (RR < top) | (stable_neg & (RR > -0.15) & (RR < 0))
    mnt = np.where(stable, 0.99, 1.5)
    up = np.minimum(RR, 0.5) if rising else -np.minimum(RR, 0.5)
    return study("r", RR, mnt=mnt, step_down=-(0.2 + 0.05 * up), push=-2.2,
                 pitch_rate=-(0.6 + 0.5 * up))


def controllers(pd_factor: float = 2.0, others: tuple = (1.0, 1.05, 0.95),
                lv_push: float = 1.2) -> dict:
    r = np.linspace(-1, 1, 12)
    out = {}
    pitch = {"mass_offset": others[0], "controller_global_pd": others[0] * pd_factor,
             "controller_local_velocity": others[1], "controller_constant_torque": others[2]}
    push = {"mass_offset": 2.1, "controller_global_pd": 1.9,
            "controller_local_velocity": lv_push, "controller_constant_torque": 2.3}
    for name in pitch:
        out[name] = study("r", r, mnt=np.where(r > 0, 0.95, 1.5), pitch_rate=-pitch[name],
                          push=-push[name],
                          stability=np.where(r > 0, "asymptotic", "unstable"))
    return out


def global_pd(lam1: float, residual: float) -> dict:
    r = np.linspace(-1, 1, 12)
    d = study("r", r, mnt=1.0)
    d.frame["abs_lambda_1"] = lam1
    d.frame["abs_lambda_2"] = 0.9
    d.frame["residual"] = residual
    return {"controller_global_pd": d}


K = np.linspace(1, 200, 50)


def stiffness(stable: tuple = (20.0, 60.0), push_falls: bool = True) -> dict:
    lo, hi = stable
    mnt = np.where(K < 15, np.nan, np.where(K <= hi, 1.0 - 0.002 * np.minimum(K, lo + 10),
                                            1.5))
    mnt = np.where((K >= 15) & (K < lo), 1.2, mnt)
    mnt = np.where(K > 150, np.nan, mnt)
    push = -(4.0 - 0.02 * K) if push_falls else -(1.0 + 0.02 * K)
    return {"stiffness": study("k", K, mnt=mnt, push=push)}


B = np.linspace(0.8, 1.5, 12)


def touchdown(flat_unstable: bool = True, sd_flat: bool = True) -> dict:
    mnt = np.where(B < 0.95, 1.5 if flat_unstable else np.nan,
                   np.where(B <= 1.2, 0.99, np.nan))
    sd = -(0.5 - 0.3 * B) if sd_flat else -(0.3 * B)
    return {"touchdown_angle": study("beta0", B, mnt=mnt, step_down=sd, push=-(1 + B))}


W = np.linspace(0, 2, 12)


def retraction(zero_stable: bool = False, pitch_up: bool = True, grows: bool = True) -> dict:
    mnt = 0.990 + 0.004 * W if grows else 0.999 - 0.004 * W
    mnt[0] = 0.99 if zero_stable else 1.7
    sd = -(0.22 - 0.04 * np.abs(W - 0.4))
    pitch = -(0.6 + 0.6 * W) if pitch_up else -(1.8 - 0.6 * W)
    return {"retraction": study("omega_r_bar", W, mnt=mnt, step_down=sd, pitch_rate=pitch)}


def grids(fractions: tuple) -> dict:
    out = {}
    for v, fr in zip((2, 3, 4, 5), fractions):
        n = 36
        mnt = np.where(np.arange(n) < round(fr * n), 0.9, 1.5)
        out[f"grid_v{v}"] = study("k", np.arange(n), mnt=mnt)
    return out


def table61(**kw: Any) -> dict:
    t = {"max_nontrivial": 0.92, "stability": "asymptotic", "step_down": -0.12,
         "push": -0.73, "pitch_rate": -1.50, "stance_time": 0.58, "flight_time": 0.13,
         "duty_factor": 0.82, "step_frequency": 1.41, "alphad_ref": 2.42, "alpha_r": 1.0}
    t.update(kw)
    return {"table6.1": t}


def height(lv_falls: bool) -> dict:
    dhs = (-0.2, -0.1, 0.05)
    pas = [NS(dh=h, dv=-h / 5, dv_expected=-h / 5) for h in dhs]
    lv = [NS(dh=h, dv=math.nan if (lv_falls and h == -0.2) else 1e-5) for h in dhs]
    return {"4.4": {"dh": dhs, "passive": pas, "local_velocity": lv}}


def step_down(corr: float, decay: float = 0.1, beta_const: bool = False) -> dict:
    n = np.arange(31)
    xd = 5.0 + 0.05 * np.exp(-decay * n) * np.cos(2.0 * n)
    beta = np.full(31, 1.1) if beta_const else 1.1 + 0.1 * np.cos(2.0 * n)
    return {"4.5": NS(xd=xd, beta=beta, phase_correlation=corr)}


def velocity_angle(forward: bool) -> dict:
    s = 1 if forward else -1
    cases = [NS(ddelta=-0.05, stance_time=0.215, impulse=NS(I_x=s * 0.02)),
             NS(ddelta=0.0, stance_time=0.2, impulse=NS(I_x=0.0)),
             NS(ddelta=0.05, stance_time=0.186, impulse=NS(I_x=-s * 0.015))]
    return {"4.7": cases}


def linearisation(y_p: float, ill: bool) -> dict:
    g = {"I_x": 0.001, "I_y": 0.01, "x_p": -0.3, "y_p": y_p}
    return {"4.1": NS(as_dict=lambda: g, y_p_ill_conditioned=ill)}


def friction(first_slip: float, slips_21: bool = False) -> dict:
    a = NS(slips=slips_21, slip_fraction=0.05 if slips_21 else 0.0, max_ratio=0.6)
    b = NS(slips=True, slip_fraction=1 - first_slip, first_slip=first_slip, max_ratio=40.0)
    return {"C.1": {"table2.1": a, "table6.1": b}}


def biped(*, largest: float = 67.0, strides: int = 10, perturbed: list | None = None,
          thigh: float = 0.001, meta: NS | None = None, c_largest: float = 0.79) -> dict:
    e2 = {"strides": strides, "of": 20, "reason": "fall", "largest": largest, "residual": 2.0,
          "tracking": NS(thigh_rms=thigh, hip_rms=0.15)}
    if perturbed is not None:
        e2.update(strides_perturbed=perturbed, min_contact=0.05)
    conv = {"largest": c_largest, "residual": 1e-10, "strides": 50, "of": 50,
            "metacentric": meta or pitch_response()}
    return {"E": {"e2": e2, "converged": conv}}


# -- cases: claim test name -> [(data, verdict), ...] --------------------------

Case = list[tuple[Callable[[], dict], Verdict]]

CASES: dict[str, Case] = {
    "_c41": [(lambda: linearisation(0.02, False), H), (lambda: linearisation(0.5, False), F),
             (lambda: linearisation(0.5, True), R)],
    "_c42": [(lambda: {"4.2": pitch_response()}, H),
             (lambda: {"4.2": pitch_response(turn=0.2)}, F),
             (lambda: {"4.2": pitch_response(hip=0.6)}, F),
             (lambda: {"4.2": pitch_response(restoring=False)}, F)],
    "_c43": [(lambda: {"4.2": pitch_response(), "4.3": pitch_response(turn=0.3, hip=1.5)}, H),
             (lambda: {"4.2": pitch_response(), "4.3": pitch_response(turn=0.05)}, F)],
    "_c62": [(lambda: {"6.2": pitch_response(turn=0.07, hip=0.3)}, H),
             (lambda: {"6.2": pitch_response(hip=0.55)}, F)],
    "_c44": [(lambda: height(False), H), (lambda: height(True), F)],
    "_c45": [(lambda: step_down(-0.9), H), (lambda: step_down(-0.6), F),
             (lambda: step_down(-0.9, decay=0.01), F)],
    "_c46": [(lambda: step_down(-0.9), H), (lambda: step_down(-0.9, beta_const=True), F)],
    "_c47": [(lambda: velocity_angle(True), H), (lambda: velocity_angle(False), F)],
    "_c48": [(lambda: speed_data(True, True), H), (lambda: speed_data(False, False), F),
             (lambda: speed_data(False, True), R), (lambda: speed_data(True, None), R),
             (lambda: {"velocity": speed_line(True, best_at=7.0),
                       "velocity_bar": speed_line(True, best_at=7.0)}, F)],
    "_c49_push": [(lambda: speed_data(True, True), H), (lambda: speed_data(False, False), F),
                  (lambda: speed_data(True, False), R)],
    "_c49_step": [(lambda: speed_data(True, True), H), (lambda: speed_data(False, False), F),
                  (lambda: speed_data(False, True), R)],
    "_c49_pitch": [(lambda: speed_data(True, True), H), (lambda: speed_data(False, False), F),
                   (lambda: speed_data(False, True), R)],
    "_c410": [(lambda: grids((0.0, 0.1, 0.15, 0.2)), H),
              (lambda: grids((0.2, 0.15, 0.1, 0.1)), F)],
    "_c411": [(lambda: stride_lines(), H), (lambda: stride_lines(flight_factor=1.3), F)],
    "_c411_k": [(lambda: stride_lines(), H), (lambda: stride_lines(k_variation=0.3), F)],
    "_c412": [(lambda: damping(), H),
              (lambda: damping(mnt=0.99 + 0.001 * np.linspace(0, 3, 12)), F),
              # one damped gait less stable than the undamped one, the last more stable
              (lambda: damping(mnt=np.array([0.99, 0.985, 0.992, 0.984, 0.991, 0.985, 0.99,
                                             0.984, 0.991, 0.985, 0.99, 0.989])), F),
              (lambda: damping(mnt=0.99 - 0.003 * np.sin(np.linspace(0, 3, 12))), R)],
    "_c413": [(lambda: damping(), H), (lambda: damping(pitch_fall=False), F),
              (lambda: damping(limits_fall=False), F),
              # high damping worse than none although the last point is better
              (lambda: damping(pitch=-np.array([1.0, 1.05, 1.1, 1.1, 1.05, 1.0, 1.05, 1.1, 1.15,
                                                1.2, 1.1, 0.95])), F)],
    "_c414": [(lambda: hip_damping(True), H), (lambda: hip_damping(False), F)],
    "_c415": [(lambda: hip_damping(True), H), (lambda: hip_damping(False), F)],
    "_c416": [(lambda: {"mass_offset": mass_offset()}, H),
              (lambda: {"mass_offset": mass_offset(top=0.7)}, F),
              (lambda: {"mass_offset": mass_offset(stable_neg=True)}, F)],
    "_c417": [(lambda: {"mass_offset": mass_offset()}, H),
              (lambda: {"mass_offset": mass_offset(rising=False)}, F)],
    "_c418": [(lambda: stiffness(), H), (lambda: stiffness(stable=(20.0, 30.0)), F)],
    "_c419": [(lambda: stiffness(), H), (lambda: stiffness(push_falls=False), F)],
    "_c420": [(lambda: touchdown(), H), (lambda: touchdown(flat_unstable=False), F)],
    "_c421": [(lambda: touchdown(), H), (lambda: touchdown(sd_flat=False), F)],
    "_c422": [(lambda: retraction(), H), (lambda: retraction(zero_stable=True), F),
              (lambda: retraction(grows=False), F)],
    "_c423": [(lambda: retraction(), H), (lambda: retraction(pitch_up=False), F)],
    "_c424_passive": [(lambda: {"mass_offset": mass_offset()}, H),
                      (lambda: {"mass_offset": mass_offset(stable_neg=True)}, F)],
    "_c424_lv": [(lambda: controllers(), H),
                 (lambda: {"controller_local_velocity": study(
                     "r", np.linspace(-1, 1, 12),
                     mnt=np.where(np.linspace(-1, 1, 12) < 0.3, 0.95, 1.5),
                     stability=np.where(np.linspace(-1, 1, 12) < 0.3, "asymptotic",
                                        "unstable"))}, F)],
    "_c424_pd": [(lambda: global_pd(1.0, 1e-4), H), (lambda: global_pd(1.01, 1e-4), F),
                 (lambda: global_pd(1.0005, 1e-3), R)],
    "_c425_pitch": [(lambda: controllers(), H), (lambda: controllers(pd_factor=1.1), F)],
    "_c425_similar": [(lambda: controllers(), H),
                      (lambda: controllers(others=(0.7, 1.25, 1.1)), F)],
    "_c425_push": [(lambda: controllers(), H), (lambda: controllers(lv_push=2.0), F)],
    "_c61": [(lambda: table61(max_nontrivial=0.922), H),
             (lambda: table61(max_nontrivial=0.93), F)],
    "_c61_step_down": [(lambda: table61(step_down=-0.121), H),
                       (lambda: table61(step_down=-0.128), F)],
    "_c61_push": [(lambda: table61(push=-0.7252), H), (lambda: table61(push=-0.738), F)],
    "_c61_pitch_rate": [(lambda: table61(pitch_rate=-1.502), H),
                        (lambda: table61(pitch_rate=-0.733), F)],
    "_c61_alphad": [(lambda: table61(alphad_ref=2.418), H),
                    (lambda: table61(alphad_ref=2.32), F),
                    (lambda: table61(alphad_ref=2.32, alphad_ref_forced={
                        "alphad_ref": 2.42, "residual": 1e-3, "free": 2.32}), F),
                    (lambda: table61(alphad_ref=2.32, alphad_ref_forced={
                        "alphad_ref": 2.42, "residual": 1e-11, "free": 2.32}), R)],
    "_c62_stride": [(lambda: table61(), H),
                    (lambda: table61(stance_time=0.60, flight_time=0.11), F),
                    (lambda: table61(stance_time=0.5869, flight_time=0.1244,
                                     duty_factor=0.8252, step_frequency=1.406), R)],
    "_cC1": [(lambda: friction(0.9), H), (lambda: friction(0.85), F),
             (lambda: friction(0.95, slips_21=True), F)],
    "_ce2": [(lambda: biped(), H), (lambda: biped(thigh=0.05), F)],
    "_ce4_unstable": [(lambda: biped(largest=67.02), H), (lambda: biped(largest=0.9), F),
                      (lambda: biped(largest=1.17), R)],
    "_ce4_falls": [(lambda: biped(strides=11), H), (lambda: biped(strides=5), F),
                   (lambda: biped(strides=5, perturbed=[4, 5, 6, 5]), F),
                   (lambda: biped(strides=5, perturbed=[9, 10, 11, 5]), R)],
    "_ce4_meta": [(lambda: biped(), H),
                  (lambda: biped(meta=pitch_response(magnitude_change=0.4)), F),
                  (lambda: biped(meta=pitch_response(turn=0.2)), F)],
    "_ce_stable": [(lambda: biped(), H), (lambda: biped(c_largest=1.1), F)],
}


def _name(claim: Any) -> str:
    return claim.test.__name__


@pytest.mark.parametrize("claim", CLAIMS, ids=[f"{c.figure}-{_name(c)}" for c in CLAIMS])
def test_claim_holds_and_fails_on_constructed_data(claim: Any) -> None:
    cases = CASES.get(_name(claim))
    assert cases, f"no constructed case for claim {claim.figure} ({_name(claim)})"
    verdicts = {v for _, v in cases}
    assert H in verdicts and F in verdicts, "each claim needs a holding and a failing case"
    for make, want in cases:
        (res,) = evaluate(make(), (claim,))
        assert not res.error, res.error
        assert res.verdict is want, (claim.figure, claim.text, want, res.numbers, res.evidence)
        if want is R:  # the other reading's numbers shown, and a note says which holds
            assert res.evidence and res.note, (res.evidence, res.note)


def test_every_case_names_a_claim() -> None:
    assert set(CASES) == {_name(c) for c in CLAIMS}


@pytest.mark.parametrize("claim", CLAIMS, ids=[f"{c.figure}-{_name(c)}" for c in CLAIMS])
def test_claim_states_quote_source_reading(claim: Any) -> None:
    for field in ("quote", "source", "reading", "text"):
        assert getattr(claim, field).strip(), f"{claim.figure}: empty {field}"


def _by_name(name: str) -> Any:
    return next(c for c in CLAIMS if _name(c) == name)


def test_failure_at_quick_resolution_says_so() -> None:
    claim = _by_name("_c419")
    data = stiffness(push_falls=False)
    (res,) = evaluate({**data, "quick": True}, (claim,))
    assert res.verdict is F
    assert "quick resolution" in res.note and "stiffness: 50 points" in res.note
    (full,) = evaluate(data, (claim,))
    assert full.verdict is F and "quick" not in full.note
    (ok,) = evaluate({**stiffness(), "quick": True}, (claim,))
    assert ok.verdict is H and ok.note == ""


def test_single_gait_failure_has_no_resolution_note() -> None:
    """Table 6.1 is one gait: quick resolution does not change it."""
    (res,) = evaluate({**table61(pitch_rate=-0.73), "quick": True},
                      (_by_name("_c61_pitch_rate"),))
    assert res.verdict is F and "quick" not in res.note


def test_pitch_rate_failure_lists_every_variant() -> None:
    variants = {"impulse at touch-down": -0.73, "at mid-stance": -1.1, "at apex": -0.9}
    (res,) = evaluate(table61(pitch_rate=-0.73, pitch_rate_variants=variants),
                      (_by_name("_c61_pitch_rate"),))
    assert res.verdict is F
    shown = res.evidence["pitch-rate limit per placement / variant"]
    assert shown == {k: round(v, 3) for k, v in variants.items()}
    (bare,) = evaluate(table61(pitch_rate=-0.73), (_by_name("_c61_pitch_rate"),))
    assert bare.evidence["pitch-rate limit per placement / variant"] == "not computed"


def test_forced_alphad_ref_residual_is_the_evidence() -> None:
    forced = {"alphad_ref": 2.42, "residual": 3.5e-3, "free": 2.3202}
    (res,) = evaluate(table61(alphad_ref=2.3202, alphad_ref_forced=forced),
                      (_by_name("_c61_alphad"),))
    assert res.verdict is F
    assert res.evidence["periodicity residual left"] == 3.5e-3
    assert res.evidence["our solved alphad_ref"] == 2.3202


def test_stride_count_failure_shows_perturbed_counts() -> None:
    (res,) = evaluate(biped(strides=5, perturbed=[4, 6, 5]), (_by_name("_ce4_falls"),))
    assert res.verdict is F
    assert res.evidence["strides under perturbations within Table E.2's rounding"] == [4, 6, 5]
    assert res.evidence["minimum contact time"] == 0.05


def test_two_readings_show_both_numbers() -> None:
    """4.9 pitch rate: omega_r held fails, omega_r_bar held holds; both numbers shown."""
    (res,) = evaluate(speed_data(False, True), (_by_name("_c49_pitch"),))
    assert res.verdict is R
    a, b = (f"{label}: relative variation" for label in (
        "omega_r held (study velocity)",
        "omega_r_bar = omega_r l0 / v0 held (eq. 2.18, study velocity_bar)"))
    assert res.evidence[a] > 0.25 > res.evidence[b]
