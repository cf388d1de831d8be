"""Kernel numerics: tolerance proportionality, dense output, closed-form flight events."""

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import tslip
from tslip.model import _pack as pk
from tslip.model import dynamics as dyn
from tslip.simulation import _kernels as kn


@pytest.fixture(scope="module")
def gait():
    return tslip.gait.find_gait(tslip.preset("table2.1"))


def _stance_reference(p, y0, t_end):
    sol = solve_ivp(lambda t, y: dyn.stance_rhs(p, y), (0, t_end), y0, method="DOP853",
                    rtol=1e-13, atol=1e-13, dense_output=True)
    return sol.sol


def test_global_error_is_proportional_to_tolerance(gait):
    """Errors at the end of a fixed stance span fall about tenfold per decade of tol."""
    p = gait.params
    P = pk.pack_params(p)
    y0 = np.empty(6)
    kn.stance_initial(P, gait.state.as_array(), y0)
    errs = []
    for tol in (1e-6, 1e-8, 1e-10):
        O = tslip.IntegratorOptions(rtol=tol, atol=tol).packed()
        rec = np.empty((20000, pk.NREC))
        stats = np.empty(5)
        yout = np.empty(6)
        kn.integrate_stance(P, O, y0, yout, rec, 0.0, stats)
        rows = rec[: int(stats[3])]
        ref = _stance_reference(p, y0, rows[-1, 0])
        errs.append(max(np.max(np.abs(r[1:7] - ref(r[0]))) for r in rows))
    ratios = [errs[i] / errs[i + 1] for i in range(2)]
    for e, tol in zip(errs, (1e-6, 1e-8, 1e-10)):
        assert e < 100 * tol
    for ratio in ratios:  # one decade of error per decade of tolerance, loosely
        assert 10 < ratio < 1000


def test_dense_output_matches_reference_between_steps(gait):
    p = gait.params
    P = pk.pack_params(p)
    y0 = np.empty(6)
    kn.stance_initial(P, gait.state.as_array(), y0)
    O = tslip.IntegratorOptions(rtol=1e-10, atol=1e-10).packed()
    rec = np.empty((5000, pk.NREC))
    stats = np.empty(5)
    yout = np.empty(6)
    kn.integrate_stance(P, O, y0, yout, rec, 0.0013, stats)  # uniform grid via dense output
    rows = rec[: int(stats[3])]
    assert np.allclose(np.diff(rows[:-1, 0]), 0.0013)
    ref = _stance_reference(p, y0, rows[-1, 0])
    err = max(np.max(np.abs(r[1:7] - ref(r[0]))) for r in rows)
    assert err < 1e-8


def test_liftoff_event_is_where_fy_vanishes(gait):
    res = tslip.step(gait.params, gait.state, options=tslip.IntegratorOptions.tight())
    lo = res.liftoff
    y = np.array([lo.l, lo.beta, lo.phi, lo.ld, lo.betad, lo.phid])
    fx, fy = dyn.ground_reaction_force(gait.params, y)
    assert abs(fy) < 1e-10
    assert res.grf[-2, 2] > 0  # F_y was positive just before


def test_flight_time_against_closed_form_parabola():
    """Global reset, no retraction, no pitch rate: the foot follows a parabola."""
    p = dataclasses.replace(tslip.preset("table2.1"), leg_reset="global", omega_r=0.0,
                            alpha_r=1.1)
    P = pk.pack_params(p)
    lo = np.array([0.0, 1.2, 3.0, 0.7, 0.2, 0.0])  # x, y, xd, yd, phi, phid
    res = np.empty(3)
    st = kn.find_touchdown(P, tslip.IntegratorOptions().packed(), lo, np.empty(0),
                           np.zeros(1), res)
    assert st == pk.ST_OK
    c = lo[1] + p.r * math.cos(lo[4]) - p.l0 * math.sin(p.alpha_r)  # foot height at t = 0
    t_exact = (lo[3] + math.sqrt(lo[3] ** 2 + 2 * p.g * c)) / p.g
    assert res[0] == pytest.approx(t_exact, abs=1e-12)
    assert res[2] == pytest.approx(c, abs=1e-14)


def test_foot_starting_below_ground_must_rise_first():
    """A reset foot below ground touches down only after rising above it."""
    p = dataclasses.replace(tslip.preset("table2.1"), leg_reset="global", omega_r=0.0,
                            alpha_r=1.3)
    P = pk.pack_params(p)
    # foot height at t=0: y + r - l0 sin(1.3) = 0.9 + 0.3 - 0.9636 > 0? choose y lower:
    lo = np.array([0.0, 0.6, 3.0, 1.5, 0.0, 0.0])
    c = lo[1] + p.r - p.l0 * math.sin(p.alpha_r)
    assert c < 0  # starts below ground
    res = np.empty(3)
    st = kn.find_touchdown(P, tslip.IntegratorOptions().packed(), lo, np.empty(0),
                           np.zeros(1), res)
    assert st == pk.ST_OK
    t_second_root = (lo[3] + math.sqrt(lo[3] ** 2 + 2 * p.g * c)) / p.g
    assert res[0] == pytest.approx(t_second_root, abs=1e-12)
    assert res[2] == pytest.approx(c)


def test_touchdown_never_skips_a_brief_crossing():
    """Fast retraction makes the foot dip below ground briefly: the first dip is found."""
    p = dataclasses.replace(tslip.preset("table2.1"), omega_r=6.0, alpha_r=0.6)
    P = pk.pack_params(p)
    lo = np.array([0.0, 0.75, 3.0, 0.5, 0.0, 0.0])
    res = np.empty(3)
    st = kn.find_touchdown(P, tslip.IntegratorOptions().packed(), lo, np.empty(0),
                           np.zeros(1), res)
    assert st == pk.ST_OK
    # brute-force scan of the closed-form foot height on a fine grid
    ts = np.linspace(0, res[0] + 0.5, 200001)
    out = np.empty((len(ts), 10))
    kn.flight_samples(P, lo, ts, out)
    below = np.nonzero(out[:, 8] <= 0)[0]
    assert out[0, 8] > 0
    assert res[0] == pytest.approx(ts[below[0]], abs=ts[1] - ts[0])
