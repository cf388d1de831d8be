"""A start where Newton stalls far from a root is given up without least squares.

The old search (least squares from every start Newton failed on) is the same
code with ``STALL_GIVE_UP = inf``: both must find the same gaits, bit for
bit, and the new one must run least squares less often where there is none.
"""

import dataclasses
import itertools

import numpy as np
import pytest
import scipy.optimize

import tslip
from tslip.gait import fixed_point as fp
from tslip.gait.fixed_point import GaitProblem, newton_solve


@pytest.fixture
def lsq_calls(monkeypatch):
    calls: list[int] = []
    real = scipy.optimize.least_squares  # fixed_point imports it where it is called

    def counted(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(scipy.optimize, "least_squares", counted)
    return calls


def test_same_gaits_as_least_squares_from_every_failed_start(lsq_calls, monkeypatch):
    """Touch-down angle across the edge of Table 2.1's gait band (no gait above about 1.25)."""
    p = tslip.preset("table2.1")
    found: dict[float, list] = {}
    n_lsq: dict[float, list[int]] = {}
    for give_up in (fp.STALL_GIVE_UP, np.inf):
        monkeypatch.setattr(fp, "STALL_GIVE_UP", give_up)
        for beta0 in np.linspace(0.8, 1.5, 8):
            lsq_calls.clear()
            g = tslip.find_gait(dataclasses.replace(p, beta0=float(beta0)))
            found.setdefault(float(beta0), []).append(
                (g.converged, g.state.section() if g.converged else None,
                 g.params.alpha_r if g.converged else None))
            n_lsq.setdefault(float(beta0), []).append(len(lsq_calls))
    converged = [b for b, (new, old) in found.items() if old[0]]
    assert 3 <= len(converged) < len(found)  # the line crosses the edge of the band
    for beta0, (new, old) in found.items():
        assert new[0] == old[0], beta0
        if old[0]:
            np.testing.assert_array_equal(new[1], old[1])
            assert new[2] == old[2]
    failed = [b for b in found if not found[b][1][0]]
    assert all(n_lsq[b][0] < n_lsq[b][1] for b in failed)  # fewer least-squares runs


@pytest.mark.parametrize(("stalled_at", "runs_lsq"), [(1e-7, True), (1e-3, False)])
def test_only_a_stall_far_from_a_root_skips_least_squares(lsq_calls, monkeypatch, stalled_at,
                                                          runs_lsq):
    prob = GaitProblem.from_params(tslip.preset("table2.1"))
    z0 = next(prob.guesses())
    monkeypatch.setattr(fp, "_newton", lambda residual, fj, z, tol: (z, stalled_at))
    z, err, n = newton_solve(prob.residual, [z0], tol=1e-10, jacobian=prob.residual_jacobian)
    assert n == 1 and bool(lsq_calls) is runs_lsq
    if runs_lsq:  # least squares from the start finds the gait, as before
        assert err <= 1e-10
    else:  # the stalled point is the best found
        np.testing.assert_array_equal(z, z0)
        assert err == stalled_at


def test_a_stalled_start_moves_on_to_the_next(lsq_calls, monkeypatch):
    prob = GaitProblem.from_params(tslip.preset("table2.1"))
    first, second = list(itertools.islice(prob.guesses(), 2))
    real = fp._newton

    def stalls_first(residual, fj, z, tol):
        return (z, 1e-3) if z is first else real(residual, fj, z, tol)

    monkeypatch.setattr(fp, "_newton", stalls_first)
    z, err, n = newton_solve(prob.residual, iter([first, second]), tol=1e-10,
                             jacobian=prob.residual_jacobian)
    assert n == 2 and err <= 1e-10 and not lsq_calls
    np.testing.assert_array_equal(z, real(prob.residual, prob.residual_jacobian, second,
                                          1e-10)[0])
