"""Every gait at fixed energy (all_gaits) and the stable region, against the scipy SLIP.

The reference is the independent apex map of :mod:`tests.gait.test_section`
(scipy DOP853 at rtol 1e-12, flight in closed form). At energy 2.2 and
k = 25 the SLIP has two gaits for leg angles above a fold near 1.1615 rad:
a flat self-stable one and a steep unstable one, which close in as the angle
falls and merge there (a saddle-node: both multipliers go to 1).
"""

import dataclasses
import math

import pytest
from matplotlib.figure import Figure
from scipy.optimize import brentq, minimize_scalar

import tslip
from tslip.gait.allgaits import all_gaits, stable_region

from .test_section import ref_apex_fixed_point, ref_apex_map

E = 2.2


def ref_excess(y, beta, k=25.0):
    """``f(y) = P(y) - y`` of the reference apex map (NaN where it fails)."""
    r = ref_apex_map(y, E, beta, k)
    return math.nan if r is None else r[0] - y


@pytest.fixture(scope="module")
def slip():
    return tslip.preset("slip")


def test_the_two_fixed_points_and_their_labels(slip):
    s = all_gaits(slip, energy=E)
    assert len(s) == 2
    assert s.stability == ("asymptotic", "unstable")
    for g, f in zip(s.gaits, s.floquets):
        assert g.converged and g.energy == pytest.approx(E, abs=1e-12)
        y = g.apex.y
        y_ref, d_ref = ref_apex_fixed_point(E, slip.beta0, slip.k, y - 0.01, y + 0.01)
        assert y == pytest.approx(y_ref, abs=1e-9)
        assert f.max_nontrivial == pytest.approx(abs(d_ref), abs=1e-6)
        assert (abs(d_ref) < 1.0) == (f.stability == "asymptotic")
    # the two are distinct gaits: the flat one first
    assert s.gaits[0].state.delta > s.gaits[1].state.delta + 0.1
    df = s.to_dataframe()
    assert list(df["stability"]) == ["asymptotic", "unstable"]
    assert df.attrs["units"]["apex_y"] == "L"
    assert repr(s).count("\n") == 0 and "2 gaits" in repr(s)


def test_the_pair_closes_in_and_merges_at_a_fold(slip):
    heights = {}
    for beta in (1.175, 1.17, 1.165, 1.162):
        s = all_gaits(dataclasses.replace(slip, beta0=beta), energy=E)
        assert s.stability == ("asymptotic", "unstable"), beta
        heights[beta] = [g.apex.y for g in s]
    gaps = [hi - lo for lo, hi in heights.values()]
    assert all(a > b for a, b in zip(gaps, gaps[1:]))  # closing in as the angle falls
    # at 1.162 scipy has both, in two brackets around tslip's heights
    lo, hi = heights[1.162]
    mid = 0.5 * (lo + hi)
    assert ref_excess(mid, 1.162) < 0.0 < ref_excess(lo - 0.01, 1.162)
    assert ref_excess(hi + 0.01, 1.162) > 0.0
    for y, a, b in ((lo, lo - 0.01, mid), (hi, mid, hi + 0.01)):
        assert y == pytest.approx(brentq(ref_excess, a, b, args=(1.162,), xtol=1e-13),
                                  abs=1e-9)
    # past the fold: no gait, and the reference map stays above the diagonal
    for beta in (1.161, 1.16):
        assert len(all_gaits(dataclasses.replace(slip, beta0=beta), energy=E)) == 0
        low = minimize_scalar(ref_excess, bounds=(0.99, 1.09), args=(beta,), method="bounded",
                              options={"xatol": 1e-7})
        assert low.fun > 0.0


def test_stable_region_cells_against_the_reference(slip):
    r = stable_region(slip, {"k": [25.0, 35.0], "beta0": [1.19, 1.25]}, energy=E)
    assert r.n_gaits.shape == (2, 2) and r.names == ("k", "beta0")
    for i, k in enumerate((25.0, 35.0)):
        for j, beta in enumerate((1.19, 1.25)):
            p = dataclasses.replace(slip, k=k, beta0=beta)
            s = all_gaits(p, energy=E)
            assert r.n_gaits[i, j] == len(s)
            # each gait a fixed point of the reference, its label from the reference slope
            slopes = []
            for g in s:
                y = g.apex.y
                lo = max(math.sin(beta) + 1e-6, y - 0.01)
                y_ref, d_ref = ref_apex_fixed_point(E, beta, k, lo, y + 0.01)
                assert y == pytest.approx(y_ref, abs=1e-9)
                slopes.append(abs(d_ref))
            assert r.n_stable[i, j] == sum(d < 1.0 for d in slopes)
            if slopes:
                assert r.max_nontrivial[i, j] == pytest.approx(min(slopes), abs=1e-6)
            else:
                assert math.isnan(r.max_nontrivial[i, j])
    assert r.stable.any() and not r.stable.all()
    df = r.to_dataframe()
    assert len(df) == 4 and df.attrs["units"]["k"] == "MgL^-1"
    fig = Figure()
    ax = fig.add_subplot()
    assert r.plot(ax=ax) is fig and ax.get_xlabel().startswith(r"$\beta_{0}$ [rad]")
    assert repr(r).count("\n") == 0


def test_bad_inputs(slip):
    with pytest.raises(ValueError, match="exactly two parameter names"):
        stable_region(slip, {"k": [20.0]}, energy=E)
    with pytest.raises(ValueError, match="unknown parameter"):
        stable_region(slip, {"kk": [20.0], "beta0": [1.2]}, energy=E)
    with pytest.raises(ValueError, match="deltas must hold"):
        all_gaits(slip, energy=E, deltas=[0.1, 0.2])
    with pytest.raises(ValueError, match="energy"):
        tslip.find_gait(slip, energy=2.2)  # an energy without fix="energy"
    with pytest.raises(ValueError, match=r"energy must be in \(0.928"):
        all_gaits(slip, energy=0.5)  # below the touch-down potential sin(1.19)
    with pytest.raises(ValueError, match="fix must be"):
        tslip.find_gait(slip, fix="power")
