"""Shared classes and protocols of the two models: Floquet, robustness, tslip.protocols."""

import numpy as np
import pytest

import tslip
from tslip import protocols as pr
from tslip.biped import BipedState, simulate, step
from tslip.biped.gait import Floquet, Gait, floquet, to_section
from tslip.biped.robustness import RobustnessResult, robustness, robustness_report
from tslip.biped.stored import load_gait
from tslip.gait.robustness import RobustnessLimits


@pytest.fixture(scope="module")
def stored():
    p, y, t0, _ = load_gait("converged-e2")
    return p, y, t0, to_section(p, y, t0)


@pytest.fixture(scope="module")
def biped_gait(stored):
    p, _, _, z = stored
    return Gait(True, 0.0, z, p, "stored gait converged-e2", 0)


@pytest.fixture(scope="module")
def tslip_side():
    gait = tslip.find_gait(tslip.preset("table6.1"))
    rob = tslip.robustness_report(gait, tol=1e-2)  # all three: isinstance reads each property
    tr = tslip.simulate(gait.params, gait.state, 2)
    return gait, tslip.floquet(gait), rob, tr


def test_the_biped_floquet_is_the_tslips_with_its_stability_rule(stored):
    p, _, _, z = stored
    f = floquet(p, z)
    assert isinstance(f, tslip.Floquet) and isinstance(f, Floquet)
    # the multipliers are the eigenvalues of the Jacobian it reports, largest first
    ev = np.linalg.eigvals(f.jacobian)
    np.testing.assert_allclose(np.sort(np.abs(ev))[::-1], f.magnitudes, rtol=1e-12)
    assert f.max_nontrivial == f.magnitudes.max() and not f.trivial.any()
    # stated rule: asymptotic below 1 - 1e-6, unstable above 1 + 1e-6
    assert f.stability == ("asymptotic" if f.max_nontrivial < 1 - 1e-6 else
                           "unstable" if f.max_nontrivial > 1 + 1e-6 else "neutral")
    assert f.stable == (f.stability != "unstable") and f.residual < 1e-7


def test_a_fallen_floquet_is_unstable_not_asymptotic():
    from tslip.gait.stability import classify_stability

    assert classify_stability(float("nan")) == "unstable"
    assert classify_stability(0.5) == "asymptotic" and classify_stability(1.0) == "neutral"
    assert classify_stability(1.01) == "unstable"


def test_biped_push_limit_survives_and_its_bound_fails(stored, biped_gait):
    """The limit of a backward push, checked by runs written here (push: xd_b += d)."""
    p, y, t0, _ = stored
    res = robustness_report(biped_gait, kinds=("push",), n_steps=3, tol=0.02, check=False)
    assert isinstance(res, RobustnessResult) and isinstance(res, RobustnessLimits)
    lim = res.get("push")
    assert lim is res.limits[0] and res.push == lim.limit < 0
    assert 0 < lim.limit - lim.first_failing <= 0.02 and lim.unit == "g^1/2 L^1/2"

    def run(d):
        yd = np.array(y, dtype=float)
        yd[9] += d
        return simulate(p, yd, 3, t0=t0)

    ok = run(lim.limit)
    assert ok.status == tslip.Status.OK and ok.n_steps == 3
    bad = run(lim.first_failing)
    assert bad.status == lim.status and bad.status.fell and bad.n_steps == lim.fall_stride < 3
    assert lim.reason == bad.status.reason
    assert robustness(biped_gait, "push", n_steps=3, tol=0.02, check=False) == lim.limit


def test_biped_robustness_refuses_an_unconverged_gait_and_a_bad_kind(biped_gait):
    from dataclasses import replace

    with pytest.raises(ValueError, match="not converged"):
        robustness(replace(biped_gait, converged=False), "push")
    with pytest.raises(ValueError, match="kind must be one of"):
        robustness(biped_gait, "shove", check=False)
    with pytest.raises(ValueError, match="sign must be -1 or \\+1"):
        robustness(biped_gait, "push", sign=2, check=False)


def test_both_models_satisfy_the_shared_protocols(stored, biped_gait, tslip_side):
    p, y, t0, z = stored
    gait, fl, rob, tr = tslip_side
    one = step(p, BipedState.from_array(y).to_array(), t0)
    brob = robustness_report(biped_gait, n_steps=2, tol=0.05, check=False)
    pairs = [
        (pr.StepLike, tr.steps[0], one),
        (pr.RunLike, tr, simulate(p, y, 1, t0=t0)),
        (pr.GaitLike, gait, biped_gait),
        (pr.FloquetLike, fl, floquet(p, z)),
        (pr.LimitLike, rob.limits[0], brob.limits[0]),
        (pr.RobustnessLike, rob, brob),
    ]
    for proto, a, b in pairs:
        assert isinstance(a, proto) and isinstance(b, proto), proto.__name__
    assert not isinstance(gait, pr.FloquetLike) and not isinstance(fl, pr.RobustnessLike)
    assert type(rob).__mro__[1] is RobustnessLimits is type(brob).__mro__[1]
