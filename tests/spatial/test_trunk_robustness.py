"""Lateral disturbances of the 3-D TSLIP gait: the limit found by the search survives
``n_steps`` strides and its first failing neighbour falls (both run here by hand, from
the touch-down state built in the test), and the limits scale with the units of
dimensional similarity (parameters away from 1)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from tslip.spatial import TRUNK_MIRROR, TrunkStatus, from_section, one_step_map, trunk_step
from tslip.spatial.lateral import OPTIONS, table21_gait, table21_params
from tslip.spatial.trunk_robustness import lateral_limit

N = 12


@pytest.fixture(scope="module")
def gait():
    p = table21_params()
    return p, table21_gait(p)


def _run(p, x, component, value):
    """N strides by hand: ``value`` added to state component ``component`` of y."""
    s = from_section(p, x, 1)
    y = s.y.copy()
    y[component] += value
    s = dataclasses.replace(s, y=y)
    for i in range(N):
        r = trunk_step(p, s)
        if not r.ok:
            return r.status, i
        s = r.state
    return TrunkStatus.OK, -1


@pytest.mark.parametrize(("kind", "component", "sign"), [
    ("lateral_push", 5, 1), ("lateral_push", 5, -1), ("roll_rate", 10, 1), ("yaw_rate", 11, -1)])
def test_limit_survives_and_first_failure_falls(gait, kind, component, sign):
    p, x = gait
    lim = lateral_limit(p, x, kind, sign=sign, n_steps=N, h=5e-4)
    # bisected to the default tol h / 10
    assert np.sign(lim.limit) in (0, sign) and 0 < abs(lim.first_failing - lim.limit) <= 5e-5
    assert lim.limit != 0.0  # a finite limit: the unstable mode needs time to grow
    assert _run(p, x, component, lim.limit) == (TrunkStatus.OK, -1)
    status, stride = _run(p, x, component, lim.first_failing)
    assert status == lim.status and status.is_fall and stride == lim.fall_stride < N
    # a disturbance twice the limit falls earlier or at the same stride
    assert _run(p, x, component, 2 * lim.first_failing)[1] <= stride


def test_limits_scale_with_the_units(gait):
    # the same runner in other units: lengths 0.9, masses 1.3, gravity 1.2
    p, x = gait
    L, M, G = 0.9, 1.3, 1.2
    v, w = math.sqrt(G * L), math.sqrt(G / L)  # velocity and rate units
    q = dataclasses.replace(p, l0=L, m=M, g=G, r=p.r * L, k=p.k * M * G / L, J=p.J * M * L**2,
                            J_roll=p.J_roll * M * L**2, J_yaw=p.J_yaw * M * L**2,
                            omega_r=p.omega_r * w)
    xq = x * np.array([1, 1, 1, 1, v, v, v, w, w, w])
    f, st = one_step_map(q, xq, options=OPTIONS)
    assert st == TrunkStatus.OK
    np.testing.assert_allclose(f, TRUNK_MIRROR * xq, atol=1e-9)  # still the gait
    a = lateral_limit(p, x, "roll_rate", n_steps=N, h=5e-4, tol=1e-7)
    b = lateral_limit(q, xq, "roll_rate", n_steps=N, h=5e-4 * w, tol=1e-7 * w)
    assert a.status == b.status and a.fall_stride == b.fall_stride
    assert abs(b.limit - a.limit * w) <= 2e-7 * w
    c = lateral_limit(p, x, "lateral_push", n_steps=N, h=5e-4, tol=1e-7)
    d = lateral_limit(q, xq, "lateral_push", n_steps=N, h=5e-4 * v, tol=1e-7 * v)
    assert abs(d.limit - c.limit * v) <= 2e-7 * v


@pytest.mark.parametrize(("kw", "match"), [
    ({"kind": "push"}, "kind must be one of"), ({"sign": 0}, "sign must be 1 or -1"),
    ({"n_steps": 0}, "n_steps must be an integer"), ({"h": -1.0}, "h must be in")])
def test_bad_input_is_refused_in_one_line(gait, kw, match):
    p, x = gait
    args = {"kind": "roll_rate", **kw}
    kind = args.pop("kind")
    with pytest.raises(ValueError, match=match):
        lateral_limit(p, x, kind, **args)


def test_a_failing_start_is_refused(gait):
    p, x = gait
    with pytest.raises(ValueError, match="undisturbed gait fails"):
        lateral_limit(p, x + np.array([0, 0, 0, 0.5, 0, 0, 0, 0, 0, 0]), "roll_rate", n_steps=N)
