"""``all_gaits``'s scan at the edge of the defined domain, in both orders, and its
de-duplication (issue 40, section 6).

The reference is the independent SLIP of ``test_allgaits_complete`` (scipy's DOP853 on a
point mass, apex section at fixed energy). On ``slip-human`` at ``k = 50``, ``beta0 =
1.33`` strides are defined for touch-down angles ``delta`` in (-0.00677, 0) and
(-1.178, -0.2448) rad: the flat, strongly unstable gait (multiplier -11.2) lies 3e-4 rad
from the first stretch's edge, the steep one at -0.750 rad in the second stretch. At
``k = 20``, ``beta0 = 1.4`` strides fail from 0 down to about -0.91 rad and the one gait
lies at -1.231 rad, below that edge.
"""

import dataclasses
import functools
import math

import numpy as np
import pytest

import tslip
from tslip.gait.allgaits import DEFAULT_DELTAS, _brackets, all_gaits
from tslip.gait.problem import _FALL_PENALTY, GaitProblem, nominal_energy

from .test_allgaits_complete import HUMAN, E, reference_gaits

K, BETA = 50.0, 1.33
P = dataclasses.replace(HUMAN, k=K, beta0=BETA, alpha_r=BETA)


@functools.cache
def ref(k, beta):
    """The reference's gaits at ``(k, beta)`` as ``(delta, apex height)``, flattest first."""
    y_td = math.sin(beta)
    v = math.sqrt(2.0 * (E - y_td))  # m = g = l0 = 1: the touch-down speed at energy E
    out = [(-math.asin(math.sqrt(2.0 * (y - y_td)) / v), y) for y, _ in reference_gaits(k, beta)]
    return sorted(out, reverse=True)


def _defined(prob, d):
    return not np.all(prob.residual(prob._guess(d)) == _FALL_PENALTY)


def _edge(d_ok, d_fail):
    """The edge of the defined domain between ``d_ok`` and ``d_fail``, to 1e-12 rad."""
    prob = GaitProblem.from_params(P, None, fix="energy", energy=E)
    assert _defined(prob, d_ok) and not _defined(prob, d_fail)
    while abs(d_ok - d_fail) > 1e-12:
        d = 0.5 * (d_ok + d_fail)
        d_ok, d_fail = (d, d_fail) if _defined(prob, d) else (d_ok, d)
    return d_ok, d_fail


def _only(s, gait):
    assert len(s) == 1, [g.state.delta for g in s]
    assert s[0].apex.y == pytest.approx(gait[1], abs=1e-8)
    assert s[0].state.delta == pytest.approx(gait[0], abs=1e-7)


def test_a_gait_within_5e_4_rad_of_the_edge_is_found():
    """Two scan points: a defined one and one just past the edge. The bisection toward
    the edge must come within 2.9e-4 rad of it to see the residual's sign change: a scan
    refined only to 1e-3 rad stops 5e-4 rad short."""
    flat = ref(K, BETA)[0]
    e_ok, e_fail = _edge(-0.005, -0.01)
    assert len(ref(K, BETA)) == 2
    assert 0.0 < flat[0] - e_ok < 5e-4  # the gait lies that close to the edge
    s = all_gaits(P, energy=E, deltas=[-0.003, e_fail - 1e-9], multipliers=False)
    _only(s, flat)


@pytest.mark.parametrize("k, beta, deltas, which", [
    # defined (above the steep gait), then failing past the edge at -1.178 rad
    (K, BETA, [-0.3, -1.19], 1),
    # failing (from 0 to the edge near -0.91 rad), then defined just past the gait: the
    # first midpoint fails, so the bisection must move the failing end, not the defined one
    (20.0, 1.4, [-0.01, -1.25], 0),
], ids=["defined-then-failing", "failing-then-defined"])
def test_the_edge_bisection_starts_from_the_defined_end_in_either_order(k, beta, deltas, which):
    """A sign change between a defined scan point and a failing one is bracketed by
    bisecting from the defined end, whichever of the two comes first in the scan."""
    gaits = ref(k, beta)
    assert len(gaits) == (2 if k == K else 1)
    gait = gaits[which]
    assert deltas[-1] < gait[0] < deltas[0]
    p = dataclasses.replace(HUMAN, k=k, beta0=beta, alpha_r=beta)
    s = all_gaits(p, energy=E, deltas=deltas, multipliers=False)
    _only(s, gait)


def test_a_gait_reached_from_two_brackets_is_returned_once():
    """A TSLIP scan (Table 2.1 at 0.8 of its nominal energy) has three sign changes of the
    level-trunk residual, two of which lead Newton to the one gait there: it is returned
    once, and it is a gait (its stride returns to its touch-down state)."""
    p = tslip.preset("table2.1")
    energy = 0.8 * nominal_energy(p)
    prob = GaitProblem.from_params(p, None, fix="energy", energy=energy)
    starts = _brackets(prob, np.sort(DEFAULT_DELTAS)[::-1])
    assert len(starts) == 3  # more seeds than gaits
    s = all_gaits(p, energy=energy, multipliers=False)
    assert len(s) == 1
    g = s[0]
    nxt = tslip.step_map(g.params, g.state.section(),
                         options=tslip.IntegratorOptions(rtol=1e-12, atol=1e-12))
    np.testing.assert_allclose(nxt.q, g.state.section(), rtol=0, atol=1e-8)
