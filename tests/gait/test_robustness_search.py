"""The limit search alone (tslip.gait.robustness.limit_search) on constructed survival curves.

The predicate is written here, so the expected limit is known exactly: the
first failure of a curve, whatever survives beyond it (module notes of
tslip.gait.robustness).
"""

import math

import numpy as np
import pytest

import tslip
from tslip.gait.robustness import GRID_STEPS, KINDS, limit_search, robustness

TOL = 1e-4


def _grid_up_to_lo_survived(s, h):
    """Every grid point j*h <= lo was asked and survived (the definition of the limit)."""
    grid = h * np.arange(1, int(s.lo / h) + 1)
    asked = dict(zip(s.magnitudes.tolist(), s.survived.tolist()))
    return all(asked.get(float(m)) is True for m in grid)


@pytest.mark.parametrize("h", [0.005, 0.02])
def test_an_island_beyond_the_first_failure_is_not_the_limit(rng, h):
    """Survive [0, thr), fail on a gap [thr, thr + gap) wider than h, survive an island to 5.

    The island covers every rung of the old doubling ladder past thr
    (0.01 * 2**j up to 2.56), so bracketing would return ~5; the limit is thr.
    """
    for thr in rng.uniform(0.03, 1.5, 8):
        gap = rng.uniform(1.05, 3.0) * h

        def survives(m, thr=thr, gap=gap):
            return (m < thr) | ((m >= thr + gap) & (m < 5.0))

        s = limit_search(survives, h=h, tol=TOL)
        assert s.lo < thr <= s.hi and s.hi - s.lo <= TOL
        assert _grid_up_to_lo_survived(s, h)
        assert s.survived[s.magnitudes < thr].all()  # nothing below the boundary failed
        plain = limit_search(lambda m, thr=thr: m < thr, h=h, tol=TOL)
        assert (s.lo, s.hi) == (plain.lo, plain.hi)  # as if there were no island


@pytest.mark.parametrize("k", [1, 2, 3, 7])
@pytest.mark.parametrize("ladder", [1, 4, 8])
def test_a_monotone_curve_gives_the_exact_boundary_within_tol(rng, k, ladder):
    for thr in rng.uniform(0.003, 3.0, 5):
        s = limit_search(lambda m, t=thr: m < t, h=0.02, tol=TOL, k=k, ladder=ladder)
        assert s.lo < thr <= s.hi and s.hi - s.lo <= TOL
        assert s.n_evals == len(s.magnitudes) == len(s.survived)
        assert np.array_equal(s.survived, s.magnitudes < thr)


def test_calls_grid_batches_then_k_sections():
    """thr 0.7317, h 0.02, 8 grid points a call: the first failure 0.74 is the 37th point
    (5 calls); the bracket (0.72, 0.74] shrinks to 1e-4 in 8 bisections (0.02/2**8),
    4 quadrisections (0.02/4**4) or 3 octasections (0.02/8**3)."""
    calls = {k: limit_search(lambda m: m < 0.7317, h=0.02, tol=TOL, k=k).n_calls
             for k in (1, 3, 7)}
    assert calls == {1: 5 + 8, 3: 5 + 4, 7: 5 + 3}


def test_the_first_grid_point_failing_puts_the_limit_below_h():
    h = 0.005
    s = limit_search(lambda m: m < 0.3 * h, h=h, tol=TOL)
    assert 0 <= s.lo < 0.3 * h <= s.hi <= h and s.hi - s.lo <= TOL
    s = limit_search(lambda m: np.zeros(m.shape, bool), h=h, tol=TOL)  # nothing survives
    assert s.lo == 0.0 and 0 < s.hi <= TOL


def test_surviving_the_whole_range_gives_inf_after_every_grid_point():
    s = limit_search(lambda m: np.ones(m.shape, bool), h=0.5, tol=TOL, max_magnitude=50.0)
    assert not s.bounded and s.lo == s.hi == math.inf
    assert s.magnitudes.max() == 50.0 and s.n_evals == 100 and s.survived.all()


def test_a_failing_sliver_narrower_than_h_between_grid_points_is_not_seen():
    """Documented resolution: the limit is the first failure on the grid of step h."""
    h = 0.005
    s = limit_search(lambda m: ~((m > 0.1001) & (m < 0.1002)) & (m < 0.2), h=h, tol=TOL)
    assert 0.2 - TOL <= s.lo < 0.2 <= s.hi
    s = limit_search(lambda m: ~((m > 0.1001) & (m < 0.1002)) & (m < 0.2), h=2e-5, tol=1e-5)
    assert s.lo <= 0.1001 < s.hi  # a grid finer than the sliver finds it


def test_bad_settings():
    with pytest.raises(ValueError, match=r"tol must be in \(0, inf\)"):
        limit_search(lambda m: m < 1, h=0.01, tol=0.0)
    with pytest.raises(ValueError, match=r"h must be in \(0, inf\)"):
        limit_search(lambda m: m < 1, h=-0.01)
    with pytest.raises(ValueError, match="h .* must be given"):
        limit_search(lambda m: m < 1)
    with pytest.raises(ValueError, match="not both"):
        limit_search(lambda m: m < 1, h=0.01, start=0.02)
    with pytest.raises(ValueError, match="ladder must be an integer >= 1"):
        limit_search(lambda m: m < 1, h=0.01, ladder=0)
    with pytest.raises(ValueError, match="survives must return shape"):
        limit_search(lambda m: True, h=0.01)


def test_start_is_the_old_name_of_h():
    a = limit_search(lambda m: m < 0.123, h=0.01)
    b = limit_search(lambda m: m < 0.123, start=0.01)
    assert (a.lo, a.hi, a.n_calls) == (b.lo, b.hi, b.n_calls)


def test_grid_steps_are_stated_per_kind_and_used_by_default():
    assert set(GRID_STEPS) == set(KINDS) and all(v > 0 for v in GRID_STEPS.values())
    g = tslip.find_gait(tslip.preset("table6.1"))
    assert robustness(g, "step_down") == robustness(g, "step_down", h=GRID_STEPS["step_down"])
    with pytest.warns(DeprecationWarning, match=r"start= .*use h="):
        old = robustness(g, "step_down", start=GRID_STEPS["step_down"])
    assert old == robustness(g, "step_down")
    with pytest.raises(ValueError, match="h must map kinds among"):
        tslip.robustness_report(g, h={"shove": 0.1})
