"""The packed-array path of gait search, Floquet and robustness (issue 12 item 3).

Each fast path is checked against the public, validating functions it replaces
(bit for bit where it calls the same kernel) or against an independent
computation written here: central differences, scipy least squares on the
residual, and a plain bisection over ``tslip.simulate``.
"""

import dataclasses
import itertools
import warnings

import numpy as np
import pytest
import scipy.optimize
from scipy.optimize import least_squares

import tslip
from tslip.gait import fixed_point as fp
from tslip.gait.fixed_point import GaitProblem, gait_residual, newton_solve
from tslip.gait.robustness import (
    GRID_STEPS,
    KINDS,
    limit_search,
    robustness_report,
    run_disturbed,
)
from tslip.gait.stability import floquet
from tslip.model import _pack as pk
from tslip.simulation import _packed

PRESETS = ["table2.1", "table2.1-local-velocity", "table2.1-constant-torque", "table6.1"]


@pytest.fixture(scope="module")
def fit():
    return tslip.find_gait(tslip.preset("table6.1"))


# ---------------------------------------------------------------------------
# the packed map == the public map
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["dopri5", "dop853"])
def test_packed_map_and_jacobian_equal_the_public_ones_bit_for_bit(fit, method):
    opts = tslip.IntegratorOptions(rtol=1e-10, atol=1e-10, method=method)
    P, O = pk.pack_params(fit.params), opts.packed()  # noqa: E741
    q0 = fit.state.section()
    rng = np.random.default_rng(3)
    for q, h in [(q0, 0.0), (q0 + 1e-3 * rng.standard_normal(5), 0.25),
                 (q0 + [0, 0, -1.5, 0, 0], -0.3)]:  # the last one falls
        ref = tslip.step_map(fit.params, q, h=h, options=opts)
        out = np.empty(pk.NOUT)
        st = _packed.stride_map(P, O, q, h, out)
        assert st == ref.status
        np.testing.assert_array_equal(out[pk.OUT_TD : pk.OUT_TD + 5], ref.q)
        assert (out[pk.OUT_TS], out[pk.OUT_TF]) == (ref.stance_time, ref.flight_time)
        if st != 0:
            continue
        rj, Jref = tslip.step_jacobian(fit.params, q, h=h, options=opts)
        for _ in range(2):  # computed, then kept
            J = np.empty((5, 5))
            assert _packed.stride_jacobian(P, O, q, h, J, out) == rj.status
            np.testing.assert_array_equal(J, Jref)
            np.testing.assert_array_equal(out[pk.OUT_TD : pk.OUT_TD + 5], rj.q)


@pytest.mark.parametrize("name", PRESETS + ["table2.1-global-pd", "undamped-torque"])
def test_packed_residual_equals_gait_residual_bit_for_bit(name):
    if name == "undamped-torque":  # no damping: the search sets tau_c = 0 (Section 2.4)
        p = dataclasses.replace(tslip.preset("table2.1"),
                                controller=tslip.ConstantTorque(tau_c=0.3, c_h=0.0))
        assert p.c_l == 0.0
    else:
        p = tslip.preset(name)
    prob = GaitProblem.from_params(p)
    z0 = next(prob.guesses())
    if name not in ("table2.1-global-pd", "undamped-torque"):
        z0 = prob.encode(tslip.find_gait(prob.params))
    for z in (z0, z0 + 1e-3, z0 - 0.3):
        p, s = prob.decode(z)
        r_old, ts, tf = gait_residual(p, s, prob.options)
        r_new, ts2, tf2 = prob.evaluate(z)
        np.testing.assert_array_equal(r_new, r_old)
        assert (ts2, tf2) == (ts, tf) or not np.isfinite(tf)


# ---------------------------------------------------------------------------
# the exact Jacobian of the residual
# ---------------------------------------------------------------------------


def _assert_jacobian_is_central_differences(prob: GaitProblem, z: np.ndarray) -> None:
    """``residual_jacobian`` at ``z``: its residual is ``residual``'s, its Jacobian central
    differences of ``residual`` (step 1e-6)."""
    r, J = prob.residual_jacobian(z)
    np.testing.assert_array_equal(r, prob.residual(z))
    h = 1e-6
    Jfd = np.column_stack([(prob.residual(z + h * e) - prob.residual(z - h * e)) / (2 * h)
                           for e in np.eye(prob.size)])
    np.testing.assert_allclose(J, Jfd, rtol=0, atol=2e-7 * max(1.0, np.abs(Jfd).max()))


@pytest.mark.parametrize("name", PRESETS + ["global-reset"])
def test_residual_jacobian_agrees_with_central_differences(name):
    if name == "global-reset":
        p = dataclasses.replace(tslip.preset("table2.1"), leg_reset="global", omega_r=0.0)
    else:
        p = tslip.preset(name)
    g = tslip.find_gait(p)
    assert g.converged
    prob = GaitProblem.from_params(g.params)
    _assert_jacobian_is_central_differences(prob, prob.encode(g) + 2e-3)  # off the gait


@pytest.mark.parametrize(("name", "kw"), [
    ("table2.1", {"fix": "energy"}), ("table2.1", {"section": "apex"}),
    ("table2.1-local-velocity", {"fix": "energy"}),
    ("table2.1-constant-torque", {"section": "apex"}), ("leg-thrust", {})])
def test_residual_jacobian_of_every_held_quantity_agrees_with_central_differences(name, kw):
    """The energy or the apex speed held moves the touch-down speed with ``z`` (its
    gradient enters ``dq/dz`` and ``r``'s last row); with leg damping the passive hip's
    search solves the leg thrust (its column by the reference's central difference)."""
    if name == "leg-thrust":
        p = dataclasses.replace(tslip.preset("table2.1"), c_l=0.3)
    else:
        p = tslip.preset(name)
    g = tslip.find_gait(p, **kw)
    assert g.converged
    prob = GaitProblem.from_params(g.params, fix=g.fix, section=g.section,
                                   energy=g.energy if g.fix == "energy" else None)
    assert name != "leg-thrust" or prob.names[-1] == "leg_thrust"
    _assert_jacobian_is_central_differences(prob, prob.encode(g) + 2e-3)


def test_finite_is_numpys_isfinite_all():
    """``problem._finite`` against ``np.isfinite(a).all()``, on the Jacobians' shapes, huge
    finite entries included, and each kind of non-finite entry, with every floating-point
    warning an error: a non-finite Jacobian is an answer (False), not a warning."""
    from tslip.gait.problem import _finite

    rng = np.random.default_rng(5)
    for shape in [(5, 5), (5, 3), (5, 4), (5, 6), (5,)]:
        a = rng.standard_normal(shape) * 1e307  # finite, and 0 * a is 0
        assert _finite(a) is True and np.isfinite(a).all()
        for bad in (np.nan, np.inf, -np.inf):
            for i in (0, a.size - 1):
                b = a.copy()
                b.flat[i] = bad
                with np.errstate(all="raise"), warnings.catch_warnings():
                    warnings.simplefilter("error")
                    assert _finite(b) is False


# ---------------------------------------------------------------------------
# Newton: stops at the requested residual, same fixed point as least squares
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("name", PRESETS)
def test_newton_fixed_point_agrees_with_least_squares(name):
    prob = GaitProblem.from_params(tslip.preset(name))
    starts = list(itertools.islice(prob.guesses(), 5))
    z_n, err_n, _ = newton_solve(prob.residual, starts, tol=1e-10,
                                 jacobian=prob.residual_jacobian)
    assert err_n <= 1e-10
    assert np.max(np.abs(prob.residual(z_n))) == err_n
    # the old method, written out: least squares from the start Newton used, to rounding
    for z0 in starts:
        sol = least_squares(prob.residual, z0, method="lm", xtol=1e-15, ftol=1e-15,
                            gtol=1e-15, max_nfev=2000, diff_step=1e-7)
        if np.max(np.abs(sol.fun)) <= 1e-10:
            break
    np.testing.assert_allclose(z_n, sol.x, rtol=0, atol=1e-10)


def test_newton_stops_at_the_gait_without_least_squares(fit, monkeypatch):
    """Started at a solution, one residual and Jacobian; least squares never runs."""
    prob = GaitProblem.from_params(fit.params)
    z = prob.encode(fit)
    calls = []

    def fj(zz):
        calls.append(zz)
        return prob.residual_jacobian(zz)

    monkeypatch.setattr(scipy.optimize, "least_squares",  # imported by fixed_point on use
                        lambda *a, **k: pytest.fail("least squares ran"))
    z2, err, n = newton_solve(prob.residual, [z], tol=1e-10, jacobian=fj)
    assert n == 1 and len(calls) == 1 and err <= 1e-10
    np.testing.assert_array_equal(z2, z)
    # from a neighbour's gait (speed + 2 %): a few Newton steps, quadratic convergence
    prob2 = GaitProblem.from_params(dataclasses.replace(fit.params, v0=fit.params.v0 * 1.02))
    errs = []
    newton_solve(prob2.residual, [z], tol=1e-12,
                 jacobian=lambda zz: (lambda rj: (errs.append(np.abs(rj[0]).max()), rj)[1])(
                     prob2.residual_jacobian(zz)))
    assert len(errs) <= 6 and errs[-1] <= 1e-12
    assert all(b < a for a, b in zip(errs, errs[1:]))
    # a loose tolerance stops earlier, at the first iterate that meets it
    loose = []
    z3, err3, _ = newton_solve(
        prob2.residual, [z], tol=1e-3,
        jacobian=lambda zz: (lambda rj: (loose.append(np.abs(rj[0]).max()), rj)[1])(
            prob2.residual_jacobian(zz)))
    k = next(i for i, e in enumerate(errs) if e <= 1e-3)
    assert loose == errs[: k + 1] and err3 <= 1e-3


def test_newton_failure_falls_back_to_least_squares(monkeypatch):
    """With Newton failing on every start, the least-squares path still finds the gait."""
    p = tslip.preset("table2.1")
    monkeypatch.setattr(fp, "_newton", lambda *a, **k: (None, float("inf")))
    g = tslip.find_gait(p)
    monkeypatch.undo()
    ref = tslip.find_gait(p)
    assert g.converged and ref.converged
    np.testing.assert_allclose(g.state.section(), ref.state.section(), atol=1e-9)


def test_floquet_of_a_found_gait_reuses_its_jacobian_bit_for_bit(fit):
    f_kept = floquet(fit)
    _packed._JACOBIANS.clear()
    f_new = floquet(fit)
    np.testing.assert_array_equal(f_kept.jacobian, f_new.jacobian)
    np.testing.assert_array_equal(f_kept.multipliers, f_new.multipliers)
    fd = floquet(fit, method="fd")
    np.testing.assert_allclose(fd.jacobian, f_new.jacobian, atol=1e-6)


# ---------------------------------------------------------------------------
# robustness: the same limits as the old batched search and a plain bisection
# ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def report(fit):
    return robustness_report(fit)


@pytest.mark.parametrize("kind", KINDS)
def test_robustness_equals_the_batched_search(fit, report, kind):
    """The old implementation: every grid point and k-section point run as one batch."""

    def survives(m):
        run = run_disturbed(fit.params, fit.state, kind, -m)
        return (run.status == 0) & (run.n_done == 25)

    s = limit_search(survives, h=GRID_STEPS[kind], tol=1e-4)
    lim = report.get(kind)
    assert (lim.limit, lim.first_failing) == (-s.lo, -s.hi)
    assert lim.n_runs < s.n_evals  # the runs past the first failure were skipped


def _survives_simulate(fit, kind, d):
    field = {"step_down": "dh", "push": "dxd", "pitch_rate": "dphid"}[kind]
    tr = tslip.simulate(fit.params, fit.state, 25, dt=10.0,
                        disturbance=tslip.Disturbance(at_step=0, **{field: d}))
    return tr.status == tslip.Status.OK and len(tr.steps) == 25


@pytest.mark.parametrize("kind", KINDS)
def test_robustness_limit_matches_a_plain_bisection_over_simulate(fit, report, kind):
    lo, hi = 0.0, 0.01
    while _survives_simulate(fit, kind, -hi):
        lo, hi = hi, 2 * hi
    while hi - lo > 1e-4:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _survives_simulate(fit, kind, -mid) else (lo, mid)
    lim = report.get(kind).limit
    assert abs(lim + lo) <= 1e-4 and _survives_simulate(fit, kind, lim)


def test_continuation_multipliers_equal_fresh_floquet_bit_for_bit():
    """Multipliers taken right after each solve (kept Jacobians) == a cold floquet."""
    from tslip.gait.continuation import continue_gait

    b = continue_gait(tslip.preset("table2.1"), "omega_r_bar", np.linspace(0.4, 1.0, 4))
    assert b.converged.all()
    _packed._JACOBIANS.clear()
    for i, g in enumerate(b.gaits):
        f = floquet(g)
        np.testing.assert_array_equal(b.multipliers[i], f.multipliers)
        assert b.stability[i] == f.stability


def test_problem_refuses_unknowns_in_another_order():
    """The packed residual reads z by position: names must keep the documented order."""
    with pytest.raises(ValueError, match="names must be"):
        GaitProblem(params=tslip.preset("table2.1"), options=fp.TIGHT,
                    names=("phi", "delta", "phid", "alpha_r"))
    forced = GaitProblem(params=tslip.preset("table6.1"), options=fp.TIGHT,
                         names=("delta", "phi", "phid", "alpha_r"))  # as reproduce's forced search
    assert forced.size == 4
