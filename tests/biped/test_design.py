"""Stable-gait design search (beyond the thesis) and the optimised gait it found."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tslip.biped import BipedParams
from tslip.biped.design import DESIGN_BOUNDS, apply_design, design_objective
from tslip.biped.stored import gait_path


def _load(name):
    data = json.loads(gait_path(name).read_text())
    return data, BipedParams.from_dict(data["params"]), np.array(data["z"])


def test_apply_design_keeps_unit_mass_and_scales_inertias():
    p = apply_design(BipedParams(), {"m_t": 0.05, "m_s": 0.02, "m_f": 0.01, "Kp_h": 1.0})
    assert p.total_mass == pytest.approx(1.0)
    assert p.m_b == pytest.approx(0.84)
    assert p.J_b == pytest.approx(0.125 * 0.84) and p.J_t == pytest.approx(0.125 * 0.05)
    assert p.J_s == pytest.approx(0.5 * 0.02) and p.Kp_h == 1.0
    assert apply_design(BipedParams(), {}).J_b == pytest.approx(0.1)  # Table E.1 unchanged
    # the heaviest legs within the bounds leave m_b = 0.54 >= 0.5
    assert apply_design(BipedParams(), {"m_t": 0.15, "m_s": 0.05, "m_f": 0.03}).m_b == \
        pytest.approx(0.54)
    with pytest.raises(ValueError, match="Kp_t must be in"):
        apply_design(BipedParams(), {"Kp_t": DESIGN_BOUNDS["Kp_t"][1] + 1})
    with pytest.raises(ValueError, match="unknown design"):
        apply_design(BipedParams(), {"k": 9.0})


def test_design_objective_penalises_infeasible_designs():
    _, p, z = _load("converged-e2")
    out = design_objective(p, z, {"d": 0.9})
    assert out["score"] == 20.0 and "d must be in" in out["message"]


def test_optimised_gait_is_periodic_and_uses_a_feasible_design():
    """The gait of `tslip biped optimise`, its numbers recomputed rather than read
    from the file: periodic (stride-map residual < 1e-8), asymptotically stable
    with a largest multiplier far below the Table 6.1 TSLIP's 0.92 (Section 6.1;
    0.101 claimed), and running 50 strides. The multiplier the file records must
    be the one the package computes."""
    from tslip.biped.gait import REFINE_OPTIONS, _wrap, floquet, step_map, survives_disturbance

    data, p, z = _load("optimised")
    z1, st = step_map(p, z, REFINE_OPTIONS)
    assert st.name == "OK" and np.linalg.norm(_wrap(z1 - z)) < 1e-8
    assert apply_design(BipedParams(), data["design"]).replace(
        T=p.T, theta_f=p.theta_f) == p
    fr = floquet(p, z)
    assert np.all(np.isfinite(fr.multipliers)) and fr.max_nontrivial < 0.2
    assert data["largest_multiplier"] == pytest.approx(fr.max_nontrivial, abs=1e-3)
    ok, status = survives_disturbance(p, z, "push", 0.0, n_steps=50)
    assert ok, status


def test_search_interrupt_keeps_the_best_and_checkpoints_it(monkeypatch):
    """Ctrl-C (here raised from the progress log after the third generation) ends
    the search with the best design so far instead of losing it. The gait solve
    is replaced by a cheap bowl so that only the search loop is under test."""
    import tslip.biped.design as design

    def bowl(base, z_warm, values, **kw):
        score = (values["Kp_h"] - 1.0) ** 2 + (values["Kd_h"] - 0.5) ** 2
        return {"score": score, "residual": 0.0, "z": list(z_warm), "params": {}}

    monkeypatch.setattr(design, "design_objective", bowl)
    _, p, z = _load("optimised")
    calls, saved = [], []

    def log(msg):
        calls.append(msg)
        if len(calls) == 4:
            raise KeyboardInterrupt

    r = design.stable_gait_search(p, z, names=("Kp_h", "Kd_h"), popsize=4, sigma0=0.3,
                                  seed=1, log=log, on_improve=saved.append)
    assert r["interrupted"] and r["evaluations"] == 1 + 3 * 4
    assert "interrupted" in calls[-1] and len(r["history"]) == 4
    start = (p.Kp_h - 1.0) ** 2 + (p.Kd_h - 0.5) ** 2
    assert r["best"]["score"] == min(r["history"]) and r["best"]["score"] <= start
    assert saved and [b["score"] for b in saved] == sorted((b["score"] for b in saved),
                                                           reverse=True)
    assert saved[-1]["score"] == r["best"]["score"] and saved[-1]["evaluations"] <= 13


@pytest.mark.parametrize(("kind", "tslip_limit"), [("step_down", -0.12), ("push", -0.73),
                                                   ("pitch_rate", -1.50)])
def test_optimised_gait_outlasts_the_tslip_limits(kind, tslip_limit):
    """Beyond the thesis: the optimised biped survives 25 strides after disturbances
    past the limits of the Table 6.1 TSLIP (Section 6.1: step-down -0.12 L, push
    -0.73, pitch rate -1.50; this package measures -0.119, -0.725, -0.733). The
    limit the file records (bisection by `tslip biped report --robustness`:
    -0.1625, -0.8237, -3.2556; regression pins, this package's own output) is
    recomputed to 3 %: the gait survives 0.97 of it and falls at 1.03 of it. The
    independent source is the thesis's TSLIP limit, which the biped must exceed."""
    from tslip.biped.gait import survives_disturbance

    data, p, z = _load("optimised")
    limit = data["robustness_25_strides"][kind]
    ok, status = survives_disturbance(p, z, kind, 0.97 * limit)
    assert ok, status
    ok, status = survives_disturbance(p, z, kind, 1.03 * limit)
    assert not ok, status
    assert 0.97 * limit < tslip_limit
