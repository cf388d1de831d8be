"""The first-failure search ends: a bounded number of predicate calls (issue 40, section 6).

Its grid scan asks ``ladder`` points a call until one fails or the grid reaches
``max_magnitude``; with a step ``h`` far too fine for that range it would run for hours
where a user sees a hang, so such a grid is refused before the first call. (A search that
never advanced would hang the test suite; pytest-timeout's default in pyproject.toml turns
that into a failure, tests/test_timeout.py.)
"""

import math

import pytest

import tslip
from tslip._first_failure import MAX_GRID_POINTS, limit_search
from tslip.gait import robustness


def _never(m):
    raise AssertionError("the predicate was called")


def test_a_grid_finer_than_the_bound_is_refused_before_any_call():
    with pytest.raises(ValueError, match=r"h \(1e-06\) must be at least") as e:
        limit_search(_never, h=1e-6, max_magnitude=100.0)
    assert "\n" not in str(e.value) and "1e+08 points" in str(e.value)


def test_a_grid_just_within_the_bound_runs():
    h = 1.01 * 100.0 / MAX_GRID_POINTS
    s = limit_search(lambda m: m < 25.5 * h, h=h, tol=h / 10, max_magnitude=100.0)
    assert s.lo < 25.5 * h <= s.hi and s.n_calls < 10


@pytest.mark.parametrize("ladder", [1, 3, 8])
def test_surviving_everything_takes_one_call_per_ladder_of_the_grid(ladder):
    """Every call advances the grid: ``ceil(points / ladder)`` calls to its end."""
    s = limit_search(lambda m: m == m, h=0.25, max_magnitude=10.0, ladder=ladder)
    assert not s.bounded
    assert s.n_calls == math.ceil(40 / ladder) and s.n_evals == 40


def test_robustness_refuses_such_a_grid_in_one_line():
    g = tslip.find_gait(tslip.preset("slip"))
    with pytest.raises(ValueError, match=r"h \(1e-07\) must be at least") as e:
        robustness(g, "step_down", h=1e-7)
    assert "\n" not in str(e.value)
