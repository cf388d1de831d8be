"""Robustness limits (thesis Section 3.1.3) against the thesis and simulate().

The search alone, on constructed survival curves: test_robustness_search.py.
"""

import dataclasses

import numpy as np
import pytest

import tslip
from tslip.gait.robustness import (
    KINDS,
    robustness,
    robustness_report,
    run_disturbed,
)

TOL = 1e-4  # thesis search accuracy (docs/conventions.md)
FIELD = {"step_down": "dh", "push": "dxd", "pitch_rate": "dphid"}


@pytest.fixture(scope="module")
def fit():
    return tslip.find_gait(tslip.preset("table6.1"))


@pytest.fixture(scope="module")
def report(fit):
    return robustness_report(fit, tol=TOL)


# ---------------------------------------------------------------------------
# Thesis numbers (Section 6.1, Table 6.1 model)
# ---------------------------------------------------------------------------


def test_table_6_1_step_down_and_push_limits(report):
    """Section 6.1: maximum step-down -0.12 L, maximum push -0.73 g^1/2 L^1/2 (within 0.01)."""
    assert report.step_down == pytest.approx(-0.12, abs=0.01)
    assert report.push == pytest.approx(-0.73, abs=0.01)


def _first_flight(p, lo):
    """First event of the flight after lift-off ``lo``, in closed form (eqs 2.7, 2.9, 2.17).

    ``"td"`` if the foot height crosses the ground downward (after first being
    above it) before the hip height reaches the ground, else ``"fall"``.
    """
    t = np.linspace(0.0, 3.0, 300_001)  # 1e-5 steps; the hip is down well before 3
    y = lo.y + lo.yd * t - 0.5 * p.g * t**2
    phi = lo.phi + lo.phid * t
    hip = y + p.r * np.cos(phi)
    beta = p.alpha_r + p.omega_r * t - phi  # local reset, clock from lift-off
    foot = hip - p.l0 * np.sin(beta)
    i_hip = np.flatnonzero(hip <= 0.0)[0]
    above = np.flatnonzero(foot > 0.0)
    down = np.flatnonzero((foot[:-1] > 0.0) & (foot[1:] <= 0.0) & (t[:-1] >= t[above[0]]))
    return "td" if down.size and down[0] < i_hip else "fall"


def test_table_6_1_pitch_rate_limit_measured(fit, report):
    """Pitch-rate limit: measured -0.7330 rad g^1/2 L^-1/2; the thesis reports -1.50.

    docs/conventions.md lists -1.50 among the numbers an independent implementation
    did not reproduce. Checked here without the search: ``simulate`` survives 25
    strides at 0.99 x the limit and falls at 1.01 x, and the closed-form first flight
    after each run's first lift-off says why: at 1.01 x the hip reaches the ground
    before the foot (the fall of stride 0), at 0.99 x the foot lands first.
    """
    lim = report.get("pitch_rate")
    assert lim.limit == pytest.approx(-0.7330, abs=2e-4)  # regression pin (thesis: -1.50)
    p = fit.params
    for factor, survives in ((0.99, True), (1.01, False)):
        tr = tslip.simulate(p, fit.state, 25,
                            disturbance=tslip.Disturbance(at_step=0, dphid=factor * lim.limit))
        assert (tr.status == tslip.Status.OK and len(tr.steps) == 25) is survives, factor
        assert _first_flight(p, tr.steps[0].liftoff) == ("td" if survives else "fall"), factor
    assert lim.fall_stride == 0 and lim.status == tslip.Status.FALL_NO_TOUCHDOWN


def test_report_records_why_and_where_the_first_failure_ends(report):
    for lim in report.limits:
        assert lim.sign == -1 and lim.kind in KINDS
        assert 0 < lim.limit - lim.first_failing <= TOL  # negative limits: failing is lower
        assert lim.status != tslip.Status.OK and lim.reason == lim.status.reason
        assert 0 <= lim.fall_stride < report.n_steps
        assert lim.n_batches >= 2 and lim.n_runs >= lim.n_batches
    assert report.n_batches == sum(lim.n_batches for lim in report.limits)


# ---------------------------------------------------------------------------
# Batch evaluation == tslip.simulate with a Disturbance
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("kind", KINDS)
def test_limit_survives_and_beyond_falls_in_simulate(fit, report, kind):
    """Just inside survives 25 strides in simulate(); limit + 2 tol (in magnitude) does not.

    simulate() and the batch agree on the outcome and on the stride it ends in.
    """
    lim = report.get(kind)
    inside, beyond = lim.limit, lim.limit - 2 * TOL
    batch = run_disturbed(fit.params, fit.state, kind, [inside, beyond])
    for i, d in enumerate((inside, beyond)):
        tr = tslip.simulate(fit.params, fit.state, 25,
                            disturbance=tslip.Disturbance(at_step=0, **{FIELD[kind]: d}))
        assert tr.status == batch.status[i]
        if i == 0:
            assert tr.status == tslip.Status.OK and len(tr.steps) == 25
            assert batch.n_done[i] == 25
        else:
            assert tr.status != tslip.Status.OK and len(tr.steps) <= 25
            assert len(tr.steps) - 1 == batch.n_done[i]  # strides completed before the fall


@pytest.mark.parametrize("kind", ["step_down", "push"])
def test_reported_limit_is_within_tol_of_the_true_boundary(fit, report, kind):
    """A grid of spacing tol/10 around the limit: all below it survive, one within tol fails."""
    m = abs(report.get(kind).limit)
    grid = m + TOL * np.linspace(-2.0, 2.0, 41)
    run = run_disturbed(fit.params, fit.state, kind, -grid)
    ok = (run.status == 0) & (run.n_done == 25)
    assert ok[grid <= m].all()
    first_fail = grid[np.flatnonzero(~ok)[0]]
    assert m < first_fail <= m + TOL * (1 + 1e-9)


def _survives_simulate(gait, field, d):
    tr = tslip.simulate(gait.params, gait.state, 25, dt=10.0,
                        disturbance=tslip.Disturbance(at_step=0, **{field: d}))
    return tr.status == tslip.Status.OK and len(tr.steps) == 25


def test_step_down_limit_is_the_first_failure_where_survival_has_islands():
    """Figure 4.23's fast retraction (Table 2.1, omega_r_bar 1.96): step-downs past the
    first failure survive again in patches (there the old doubling-and-bisection search
    returned -0.179 against a first failure near -0.141). Checked in simulate(): every
    step-down on a 0.001 grid from 0 to the limit (5 points per grid step h = 0.005)
    survives, the failing bound within tol of it falls, and a larger one survives."""
    g = tslip.find_gait(tslip.preset("table2.1").with_omega_r_bar(1.96))
    lim = robustness_report(g, kinds=("step_down",), tol=TOL).get("step_down")
    assert 0 < lim.limit - lim.first_failing <= TOL
    inside = np.append(np.arange(0.0, -lim.limit, 0.001), -lim.limit)
    assert all(_survives_simulate(g, "dh", -m) for m in inside)
    assert not _survives_simulate(g, "dh", lim.first_failing)
    beyond = -lim.first_failing + np.arange(1, 41) * 0.0005  # up to 0.02 past the failure
    assert any(_survives_simulate(g, "dh", -m) for m in beyond)  # an island: not monotone


def _failing_gaps(m, ok, step):
    """The failing runs of a grid ``m`` (step ``step``) as intervals ``[a, b)``."""
    fail = np.r_[False, ~ok, False].astype(int)
    starts, ends = np.flatnonzero(np.diff(fail) == 1), np.flatnonzero(np.diff(fail) == -1)
    return [(m[i], m[j - 1] + step) for i, j in zip(starts, ends)]


def test_the_step_down_grid_step_sees_a_failing_gap_wider_than_it():
    """Figure 4.23's fast retraction (Table 2.1, omega_r_bar 1.88): on a 0.0005 L grid of
    step-downs, each run in simulate(), the first failing gap wider than 0.006 L is about
    0.012 L wide (near 0.156 L; narrower slivers before it fall between grid points, module
    notes) and survival returns past it. No multiple of 0.05 L lies in it, so a 0.05 L grid
    steps over it onto the island; a grid of step h <= 0.005 L has a point inside, and the
    first-failure limit lies below the gap (guards GRID_STEPS["step_down"])."""
    fine = 0.0005
    g = tslip.find_gait(tslip.preset("table2.1").with_omega_r_bar(1.88))
    m = fine * np.arange(1, 401)  # up to 0.2 L
    ok = np.array([_survives_simulate(g, "dh", -x) for x in m])
    a, b = next((a, b) for a, b in _failing_gaps(m, ok, fine) if b - a >= 0.006)
    assert b - a <= 0.05  # the premise: narrower than 0.05 L ...
    assert not any(a - fine < c < b for c in 0.05 * np.arange(1, 5))  # ... between its points
    assert ok[m > b - fine / 2][0]  # and survived again after it: an island
    assert -robustness(g, "step_down", tol=TOL) < a


# ---------------------------------------------------------------------------
# Refusals and options
# ---------------------------------------------------------------------------


def test_refuses_an_unstable_gait():
    g = tslip.find_gait(dataclasses.replace(tslip.preset("table2.1"), r=-0.3))
    assert g.converged
    with pytest.raises(ValueError, match=r"only for at least neutrally stable gaits.*unstable"):
        robustness(g, "step_down")
    with pytest.raises(ValueError, match="neutrally stable"):
        robustness_report(g)


def test_refuses_an_unconverged_gait_unless_check_false():
    g = tslip.find_gait(tslip.preset("table2.1-global-pd"))
    assert not g.converged
    with pytest.raises(ValueError, match=r"not converged \(residual .*check=False"):
        robustness(g, "push")
    lim = robustness(g, "step_down", tol=1e-2, check=False)
    assert -1.0 < lim < 0.0


def test_bad_kind_and_sign():
    g = tslip.find_gait(tslip.preset("table2.1"))
    with pytest.raises(ValueError, match="kind must be one of"):
        robustness(g, "shove")
    with pytest.raises(ValueError, match="sign must be -1 or"):
        robustness(g, "push", sign=0)


def test_integration_errors_fail_but_are_not_reported_as_falls(fit):
    """A flight limit below the stepped-down flight time makes the first failure an error."""
    opts = tslip.IntegratorOptions(t_max_flight=1.5 * fit.flight_time)
    r = robustness_report(fit, kinds=("step_down",), options=opts, tol=1e-3)
    lim = r.get("step_down")
    assert lim.status == tslip.Status.FLIGHT_TIMEOUT and not lim.status.fell
    assert lim.reason.startswith("error:") and lim.n_errors >= 1
    assert robustness(fit, "step_down", tol=1e-3) < lim.limit < 0  # the cap lowers the limit


def test_both_signs_give_opposite_directions():
    g = tslip.find_gait(tslip.preset("table2.1-local-velocity"))
    r = robustness_report(g, both_signs=True, tol=1e-3)
    for kind in KINDS:
        assert r.get(kind, -1).limit < 0 < r.get(kind, +1).limit
        assert r.get(kind, +1).limit == pytest.approx(robustness(g, kind, sign=1, tol=1e-3))


def test_push_limit_tracks_a_minimum_speed_over_velocity():
    """Thesis Fig. 4.9: push limit ~ linear in v0; step-down limit falls above v0 = 5.

    The push limit keeps a constant minimum speed ``v0 + push``.
    """
    p = tslip.preset("table2.1")
    rows = [robustness_report(tslip.find_gait(p, v0=v), kinds=("step_down", "push"), tol=1e-3)
            for v in (5.0, 6.0, 7.0, 8.0)]
    v_min = np.array([v + r.push for v, r in zip((5.0, 6.0, 7.0, 8.0), rows)])
    assert np.ptp(v_min) < 0.4 and 2.4 < v_min.mean() < 3.0
    drops = [r.step_down for r in rows]
    assert all(a < b for a, b in zip(drops, drops[1:]))  # less negative: smaller step-down
