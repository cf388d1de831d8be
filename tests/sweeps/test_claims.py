"""Thesis claims checked on coarse study results (real runs, serial).

Each test runs the claim function of :mod:`tslip.sweeps.claims` on a small
study and asserts what the thesis states; tolerances are in the claims.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tslip.model.parameters import preset
from tslip.sweeps import catalogue, run_study
from tslip.sweeps.claims import (
    CLAIMS,
    ID_PATTERN,
    ClaimResult,
    Verdict,
    count_verdicts,
    evaluate,
    grid_stable_fractions,
)

HOLDING = (Verdict.HOLDS, Verdict.HOLDS_UNDER_READING)


def _claim(claim_id: str, data: dict):
    (c,) = [c for c in CLAIMS if c.id == claim_id]
    res = evaluate(data, (c,))
    assert res, f"claim {claim_id} needs {c.needs}"
    return res[0]


@pytest.fixture(scope="module")
def data() -> dict:
    out = {}
    for name, n in (("mass_offset", 21), ("velocity", 12), ("leg_damping", 7)):
        out[name] = run_study(catalogue.STUDIES[name].spec.with_resolution([n]), workers=1)
    return out


def test_r_threshold_located_by_bisection(data: dict) -> None:
    """Figure 4.16's boundary located to 1e-3: 0.849, as an independent scipy model of the
    Table 2.1 gait gives, so the printed 0.86 (+-0.005) does not hold; the grid's bracket
    (which met 0.86 at 21 points) is shown, not judged."""
    located = catalogue.fig_mass_offset_boundary()
    lo, hi = located["bracket"]
    assert hi - lo <= 1e-3 and lo <= located["boundary"] <= hi
    assert located["boundary"] == pytest.approx(0.849, abs=1e-3)
    c = _claim("4.16-stable-mass-offsets", {**data, "4.16": located})
    assert c.verdict is Verdict.FAILS, c.numbers
    assert c.numbers["located boundary (last stable r) [L]"] == round(located["boundary"], 4)
    assert 0.8 <= c.numbers["stable r on the grid [L]"][1] <= 0.9


def test_push_robustness_grows_with_v0(data: dict) -> None:
    c = _claim("4.9-push-linear-in-speed", data)
    assert c.verdict in HOLDING, c.numbers
    assert c.numbers["corr(v0, |push|)"] > 0.98


def test_minimum_running_speed(data: dict) -> None:
    c = _claim("4.8-minimum-speed", data)
    assert 3.0 < c.numbers["min stable v0 [g^1/2 L^1/2]"] < 5.0  # 3.99 at fine resolution


def test_leg_damping_lowers_max_multiplier(data: dict) -> None:
    c = _claim("4.12-leg-damping-stability", data)
    assert c.verdict in HOLDING, c.numbers


def test_stable_area_grows_with_v0() -> None:
    data = {}
    for v in (2.0, 5.0):
        spec = catalogue.STUDIES[f"grid_v{v:g}"].spec.with_resolution([5, 5])
        data[f"grid_v{v:g}"] = run_study(spec, workers=1)
    fr = {v: float((data[f"grid_v{v:g}"].frame["stability"] == "asymptotic").mean())
          for v in (2.0, 5.0)}
    assert fr[5.0] > fr[2.0], fr


def test_eq_3_8_velocity_change() -> None:
    from tslip.gait import expected_velocity_change, find_gait, velocity_after_height_change
    from tslip.model.parameters import preset

    g = find_gait(preset("table2.1"))
    for dh in (-0.1, 0.05):
        r = velocity_after_height_change(g, dh, n_steps=120, n_average=40)
        assert abs(r.dv - expected_velocity_change(g.state.v, dh)) < 1e-3


def test_grid_fraction_helper_uses_every_panel() -> None:
    assert len(catalogue.GRID_SPEEDS) == 4
    with pytest.raises(KeyError):
        grid_stable_fractions({})


def test_failing_claim_is_reported_not_raised() -> None:
    res = evaluate({"table6.1": {"max_nontrivial": 0.5}}, tuple(c for c in CLAIMS
                                                                 if c.figure == "6.1"))
    assert res[0].verdict is Verdict.FAILS and res[0].numbers["ours"] == 0.5
    assert res[1].verdict is Verdict.FAILS and res[1].error  # an error, not a crash
    assert res[1].evidence  # the error is the evidence


def test_appendix_e_claims() -> None:
    """Section E.4 on the biped: tracking (E.2), instability from Table E.2 (though
    not its 67.0), the metacentric test and the stable gait hold; 'falls after
    about 10 strides' holds exactly when our count is 8-12 (or under the
    perturbed-start reading) and is reported with our number either way."""
    e = catalogue.fig_appendix_e(n_strides=8, n_converged=10)
    res = evaluate({"E": e}, tuple(c for c in CLAIMS if c.figure in ("E.2", "E.4")))
    assert [r.figure for r in res] == ["E.2", "E.4", "E.4", "E.4", "E.4", "E.4"]
    tracking, unstable, largest, falls, meta, stable = res
    for r in (tracking, unstable, meta, stable):
        assert r.verdict is Verdict.HOLDS, (r.text, r.numbers, r.error)
    n = falls.numbers["strides until fall"]
    assert (falls.verdict in HOLDING) == (abs(n - 10) <= 2
                                          or falls.verdict is Verdict.HOLDS_UNDER_READING)
    # the thesis's 67.0 is a printed number: ours (about 1.2) does not round to it
    assert largest.verdict is Verdict.FAILS
    assert largest.numbers["ours"] == round(e["e2"]["largest"], 4) and \
        largest.numbers["thesis"] == 67.0
    assert largest.evidence["our largest |lambda| at Table E.2"] == round(e["e2"]["largest"], 3)
    assert stable.numbers["strides run"] == "10 of 10"


def test_velocity_bar_holds_the_normalised_retraction_rate() -> None:
    """The twin of the "velocity" study: same speeds, omega_r l0 / v0 (eq. 2.18) held."""
    base = preset("table2.1")
    twin, bar = catalogue.STUDIES["velocity"], catalogue.STUDIES["velocity_bar"]
    for quick in (True, False):
        a, b = twin.at(quick), bar.at(quick)
        assert b.axes[0].values == a.axes[0].values and b.shape == (len(a.axes[0].values), 1)
        for v in (b.axes[0].values[0], b.axes[0].values[-1]):
            p = b.params_at({"v0": v, "omega_r_bar": b.axes[1].values[0]})
            q = a.params_at({"v0": v})
            assert p.v0 == q.v0 == v
            assert p.omega_r * p.l0 / p.v0 == pytest.approx(base.omega_r * base.l0 / base.v0)
            assert q.omega_r == base.omega_r


#: Every claim id, in CLAIMS order: the release contract (ids never change once
#: released; claims.json and the docs name claims by them). A new claim appends its id.
RELEASED_IDS = (
    "4.1-x-p-gradient", "4.2-impulse-towards-hip", "4.3-pd-turns-impulse",
    "4.4-speed-after-ground-step", "4.5-opposite-phase", "4.6-touchdown-angle-changes",
    "4.7-touchdown-velocity-angle", "4.8-minimum-speed", "4.8-stable-above-minimum",
    "4.8-converge-most-quickly", "4.9-push-linear-in-speed", "4.9-step-down-peak",
    "4.9-pitch-rate-minimal", "4.10-stable-region-grows", "4.11-times-match-equations",
    "4.11-flight-time-trends", "4.11-stance-time-trends", "4.12-leg-damping-stability",
    "4.13-leg-damping-robustness", "4.14-hip-damping-stability", "4.15-hip-damping-robustness",
    "4.16-stable-mass-offsets", "4.17-mass-offset-robustness", "4.18-stiffness-stability",
    "4.19-push-falls-with-stiffness", "4.20-touchdown-angle-range", "4.20-flatter-more-stable",
    "4.21-touchdown-angle-robustness", "4.22-retraction-stability",
    "4.23-retraction-robustness", "4.24-passive-r-positive", "4.24-local-velocity-asymptotic",
    "4.24-global-pd-neutral", "4.25-pd-pitch-rate-larger", "4.25-others-pitch-rate-similar",
    "4.25-local-velocity-least-push", "6.1-largest-multiplier", "6.1-step-down-limit",
    "6.1-push-limit", "6.1-pitch-rate-limit", "6.1-alphad-ref", "6.2-stride-times",
    "6.2-impulse-towards-hip", "c.1-friction", "e.2-tracking", "e.4-unstable",
    "e.4-largest-multiplier-67", "e.4-falls-about-10-strides", "e.4-metacentric",
    "e.4-stable-gait-exists",
)


def test_claim_ids_are_the_released_ones() -> None:
    ids = [c.id for c in CLAIMS]
    assert tuple(ids) == RELEASED_IDS
    assert len(set(ids)) == len(ids)
    assert all(re.match(ID_PATTERN, i) for i in ids), ids
    assert all(i.split("-")[0] == c.figure.lower() for i, c in zip(ids, CLAIMS, strict=True))


def test_docs_list_every_claim_id() -> None:
    """docs/reproducing.md lists the ids, in CLAIMS order."""
    text = (Path(__file__).parents[2] / "docs" / "reproducing.md").read_text()
    listed = re.findall(r"^- `([a-z0-9.]+-[a-z0-9-]+)`", text, re.M)
    assert listed == [c.id for c in CLAIMS]


def test_holds_is_deprecated_with_its_old_meaning() -> None:
    for v in Verdict:
        r = ClaimResult("4.1", "t", {}, v)
        with pytest.warns(DeprecationWarning, match="read ClaimResult.verdict"):
            assert r.holds is (v is not Verdict.FAILS)


def test_count_verdicts_names_every_verdict() -> None:
    rs = [ClaimResult("x", "t", {}, v) for v in (Verdict.HOLDS, Verdict.FAILS, Verdict.HOLDS)]
    assert count_verdicts(rs) == {Verdict.HOLDS: 2, Verdict.HOLDS_UNDER_READING: 0,
                                  Verdict.FAILS: 1, Verdict.NOT_ASSESSED: 0}
    assert count_verdicts([{"verdict": "not assessed"}])[Verdict.NOT_ASSESSED] == 1
