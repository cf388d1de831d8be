"""Continuation along the thesis's parameter sweeps (Sections 3.4-3.7, 4.3-4.6)."""

import dataclasses

import numpy as np
import pytest

import tslip
from tslip.gait.continuation import (
    Branch,
    continue_gait,
    get_param,
    set_param,
    stability_boundaries,
)
from tslip.gait.fixed_point import find_gait
from tslip.gait.stability import floquet

PASSIVE = tslip.preset("table2.1")


@pytest.fixture(scope="module")
def v0_branch() -> Branch:
    return continue_gait(PASSIVE, "v0", np.linspace(1.0, 10.0, 19))


@pytest.fixture(scope="module")
def r_branch() -> Branch:
    return continue_gait(PASSIVE, "r", np.linspace(-1.0, 1.0, 21))


def test_minimum_running_speed_then_stable_above_it(v0_branch):
    """Figure 4.8: a minimum running velocity; stable above a threshold.

    Measured: the branch folds between v0 = 2.0 and 2.5 (about 2.33), is unstable
    up to 3.99 and asymptotic on the energy level (the energy multiplier at 1 is
    trivial) above it, to v0 = 10.
    """
    b = v0_branch
    v = b.values
    assert b.base == 5.0 and len(b) == 19
    assert not b.converged[v < 2.25].any()  # no gait at low speed
    assert b.converged[v > 2.25].all()
    assert np.all(b.residual[v > 2.25] < 1e-10)
    lo, hi = b.exists()
    assert (lo, hi) == (2.5, 10.0)
    # past the end of the branch: two failures, then the rest is not attempted
    assert "not attempted" in b.messages[0] and "no periodic gait" in b.messages[2]
    (v_s,) = stability_boundaries(b)
    assert 3.5 < v_s < 4.0
    assert np.all(b.stable[v > v_s]) and not np.any(b.stable[v < v_s])
    assert set(np.array(b.stability)[v > v_s]) == {"asymptotic"}
    assert np.all(b.trivial[b.converged].sum(axis=1) == 1)  # the energy multiplier
    assert np.all(b.max_nontrivial[v < v_s][b.converged[v < v_s]] > 1.0 + 1e-6)
    # the linear estimate brackets the refined one to the grid spacing
    assert stability_boundaries(b, refine=False)[0] == pytest.approx(v_s, abs=0.05)


def test_mass_offset_threshold_near_0_86(r_branch):
    """Section 4.5.1: stable for a mass below the hip, unstable over about 0.86 L.

    Measured with the exact fixed points: the complex pair leaves the unit circle at
    r = 0.849 (docs/conventions.md reports an independent reproduction near 0.86).
    """
    b = r_branch
    assert b.converged.all() and np.all(b.residual < 1e-10)
    bounds = stability_boundaries(b, xtol=1e-6)
    upper = bounds[-1]
    assert abs(upper - 0.86) < 0.02
    r = b.values
    assert np.all(b.stable[(r > 0.0) & (r < upper)])
    assert not np.any(b.stable[r > upper]) and not np.any(b.stable[r < 0.0])
    assert bounds[0] == pytest.approx(0.0, abs=1e-6)  # the lower boundary is r = 0


def test_continued_point_equals_a_cold_solve(v0_branch, r_branch):
    for branch, value in ((v0_branch, 3.0), (v0_branch, 8.5), (r_branch, -0.6), (r_branch, 0.9)):
        i = int(np.argmin(np.abs(branch.values - value)))
        g = branch.gaits[i]
        cold = find_gait(set_param(PASSIVE, branch.param, branch.values[i]))
        assert cold.converged and g is not None
        np.testing.assert_allclose(g.state.section(), cold.state.section(), atol=1e-8)
        assert g.params.alpha_r == pytest.approx(cold.params.alpha_r, abs=1e-8)
        assert g.params == dataclasses.replace(cold.params, alpha_r=g.params.alpha_r)


def test_constant_torque_grows_with_leg_damping():
    """Figure 4.12 text: the torque balancing the leg damper grows with c_l."""
    b = continue_gait(tslip.preset("table2.1-constant-torque"), "c_l", np.linspace(0, 3, 13))
    assert b.converged.all() and b.base == 0.5
    tau = b.to_dataframe()["tau_c"].to_numpy()
    assert tau[0] == 0.0  # no damping: the torque vanishes (eq. 2.15 text)
    assert np.all(np.diff(tau) > 0.0)
    # leg damping makes the gait asymptotically stable (Figure 4.12): without it the
    # energy multiplier is 1 (trivial; stable on the energy level), with it inside
    assert set(b.stability) == {"asymptotic"}
    assert b.trivial[0].sum() == 1 and not b.trivial[1:].any()


def test_secant_and_constant_predictors_agree():
    vals = np.linspace(0.2, 1.6, 8)
    a = continue_gait(PASSIVE, "omega_r_bar", vals)
    c = continue_gait(PASSIVE, "omega_r_bar", vals, predictor="constant")
    assert a.converged.all() and c.converged.all()
    for ga, gc in zip(a.gaits, c.gaits):
        np.testing.assert_allclose(ga.state.section(), gc.state.section(), atol=1e-9)
        assert ga.params.omega_r == pytest.approx(gc.params.omega_r, rel=1e-15)
    # omega_r_bar is eq. 2.18 at the gait's speed
    np.testing.assert_allclose([g.params.omega_r_bar for g in a.gaits], vals, rtol=1e-12)


def test_no_stable_gait_without_retraction():
    """Section 4.5.4: 'there are no stable limit cycles without swing-leg retraction'."""
    b = continue_gait(PASSIVE, "omega_r_bar", [0.0, 0.2, 0.4])
    assert b.converged.all()
    assert b.stability[0] == "unstable" and b.stable[1:].all()


def test_controller_gain_by_dotted_name_and_from_a_gait():
    p = tslip.preset("table2.1-local-velocity")
    g = find_gait(p)
    seen = []
    b = continue_gait(g, "controller.Kd", [0.3, 0.5, 0.7],
                      progress=lambda done, total, v, gait: seen.append((done, total, v)))
    assert b.converged.all() and sorted(seen) == [(1, 3, 0.5), (2, 3, 0.7), (3, 3, 0.3)]
    assert [gg.params.controller.Kd for gg in b.gaits] == [0.3, 0.5, 0.7]
    np.testing.assert_allclose(b.gaits[1].state.section(), g.state.section(), atol=1e-10)
    assert get_param(p, "controller.Kd") == 0.5


def test_to_dataframe_is_tidy(v0_branch):
    df = v0_branch.to_dataframe()
    assert len(df) == len(v0_branch) and (df["param"] == "v0").all()
    for col in ("value", "converged", "residual", "delta", "phi", "phid", "alpha_r",
                "stance_time", "flight_time", "abs_lambda_1", "abs_lambda_5", "max_nontrivial",
                "stability"):
        assert col in df.columns
    assert "tau_c" not in df.columns and "alphad_ref" not in df.columns  # passive
    ok = df[df["converged"]]
    mags = ok[[f"abs_lambda_{j}" for j in range(1, 6)]].to_numpy()
    assert np.all(np.diff(mags, axis=1) <= 0)
    assert df.loc[~df["converged"], "delta"].isna().all()
    row = ok[ok["value"] == 5.0].iloc[0]
    ref = floquet(find_gait(PASSIVE))
    assert row["max_nontrivial"] == pytest.approx(ref.max_nontrivial, abs=1e-10)
    assert row["stability"] == "asymptotic"


def test_cold_solves_agree_with_the_branch_across_the_mass_offset_range(r_branch):
    """The automatic guesses find the same gait as continuation (r = 0 is degenerate)."""
    for value, g in zip(r_branch.values, r_branch.gaits):
        if abs(value) < 1e-12:
            continue  # the pitch is undetermined at r = 0
        cold = find_gait(set_param(PASSIVE, "r", value))
        assert cold.converged
        np.testing.assert_allclose(cold.state.section(), g.state.section(), atol=1e-8)


def test_missing_gaits_are_reported_not_forced():
    """Section 4.5.2: no periodic limit cycles when the stiffness is too low."""
    g = find_gait(PASSIVE, v0=1.0)
    assert not g.converged and "no periodic gait found" in g.message and g.residual > 1e-2
    g = find_gait(dataclasses.replace(PASSIVE, k=5.0))
    assert not g.converged and "no periodic gait found" in g.message


def test_bad_names_and_values():
    with pytest.raises(ValueError, match="solved for"):
        continue_gait(PASSIVE, "alpha_r", [0.5, 0.6])
    with pytest.raises(ValueError, match="solved for"):
        continue_gait(tslip.preset("table2.1-local-velocity"), "controller.alphad_ref", [1.0])
    with pytest.raises(ValueError, match="unknown parameter"):
        continue_gait(PASSIVE, "speed", [1.0])
    with pytest.raises(ValueError, match="has no field"):
        continue_gait(PASSIVE, "controller.Kd", [1.0])
    with pytest.raises(ValueError, match="repeat"):
        continue_gait(PASSIVE, "v0", [4.0, 4.0])
    with pytest.raises(ValueError, match="finite"):
        continue_gait(PASSIVE, "v0", [])
