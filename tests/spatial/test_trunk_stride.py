"""The 3-D TSLIP's stride as one compiled kernel (issue 43, Part 2: speed).

* the touch-down's falls are decided in the documented order (crossed leg, hip at the
  ground, backward, lengthening), each with nothing integrated;
* the stance with leg thrust records on across the switch: the energy with rest length
  ``l0`` is conserved before the switch and with ``l0 (1 + d)`` after it;
* the packed parameters and options kept between calls follow the objects passed.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import tslip
from tslip.spatial.lateral import TABLE21_SECTION, table21_params
from tslip.spatial.trunk import TrunkStatus, trunk_energy, trunk_stance, trunk_step
from tslip.spatial.trunk_section import from_section

OPT = tslip.IntegratorOptions(rtol=1e-11, atol=1e-11)
# section (a, yaw, pitch, roll, vx, vy, vz, w_roll, w_yaw, w_pitch) changes from the gait's
BACKWARD = {4: -6.0}  # vx < 0 along the heading
LENGTHENING = {5: 3.5}  # rising fast at touch-down: the leg lengthens
HIP_LOW = {0: -1.3}  # hip angle < 0: the leg points up, the hip is below the ground
CROSSED = {3: 0.3}  # rolled towards the leg: its foot across the mid-plane
# (at splay 0 the foot of the gait is on the mid-plane, and a hip angle < 0 does not
# move it across as a splayed leg's would)


def _state(side, *changes, splay=0.05):
    p = table21_params(splay=splay)
    x = TABLE21_SECTION.copy()
    for ch in changes:
        for i, v in ch.items():
            x[i] += side * v if i == 3 else v
    return p, from_section(p, x, side)


@pytest.mark.parametrize("side", [1, -1])
@pytest.mark.parametrize(("changes", "status"), [
    ((BACKWARD,), TrunkStatus.FALL_BACKWARD),
    ((LENGTHENING,), TrunkStatus.FALL_LENGTHENING),
    ((HIP_LOW,), TrunkStatus.FALL_HIP_GROUND),
    ((CROSSED,), TrunkStatus.FALL_CROSSED_LEG),
    ((BACKWARD, LENGTHENING), TrunkStatus.FALL_BACKWARD),
    ((HIP_LOW, BACKWARD), TrunkStatus.FALL_HIP_GROUND),
    ((CROSSED, BACKWARD), TrunkStatus.FALL_CROSSED_LEG),
], ids=["backward", "lengthening", "hip", "crossed", "backward-first", "hip-first",
        "crossed-first"])
def test_touchdown_falls_in_the_documented_order(side, changes, status):
    p, s = _state(side, *changes, splay=0.0)
    y, c, foot = s.y, s.y[0:3], s.foot
    R = s.R
    h = np.array([R[0, 0], 0.0, R[2, 0]])
    # each rule as the docstring states it, computed here
    rules = {
        TrunkStatus.FALL_CROSSED_LEG: side * np.dot(foot - c, np.cross(h, [0.0, 1.0, 0.0])) < 0,
        TrunkStatus.FALL_HIP_GROUND: y[1] + p.r * R[1, 1] <= 0.0,
        TrunkStatus.FALL_BACKWARD: np.dot(y[3:6], h) < 0.0,
    }
    hip = c + p.r * R[:, 1]
    u = (foot - hip) / np.linalg.norm(foot - hip)
    w = R @ y[10:13]
    rules[TrunkStatus.FALL_LENGTHENING] = -np.dot(u, y[3:6] + np.cross(w, p.r * R[:, 1])) > 0.0
    first = next(st for st in rules if rules[st])
    assert first == status
    r = trunk_step(p, s, options=OPT)
    assert r.status == status
    assert r.state is None and r.n_steps == 0 and r.stance_time == 0.0 == r.flight_time
    assert np.all(np.isnan(r.liftoff))


def test_the_gait_itself_has_no_touchdown_fall():
    for side in (1, -1):
        p, s = _state(side)
        assert trunk_step(p, s, options=OPT).ok


def test_thrust_stance_records_on_across_the_switch():
    d = 0.08
    p = dataclasses.replace(table21_params(), leg_thrust=d)
    _, s = _state(1)
    status, ts, ylo, rec, nsteps = trunk_stance(p, s, options=OPT, rows=100000)
    assert status == TrunkStatus.OK
    t, Y = rec[:, 0], rec[:, 1:]
    assert np.all(np.diff(t) > 0.0) and t[-1] < ts
    assert len(rec) <= nsteps + 2  # the starts of the two pieces and accepted steps
    hip = np.array([y[0:3] + p.r * _rot(y)[:, 1] for y in Y])
    ln = np.linalg.norm(s.foot - hip, axis=1)
    k = int(np.argmin(ln))  # the switch: at maximal compression, the second piece's start
    assert 3 < k < len(rec) - 3
    E0 = [trunk_energy(p, y, s.foot, l_rest=p.l0) for y in Y[:k]]
    E1 = [trunk_energy(p, y, s.foot, l_rest=p.l0 * (1 + d)) for y in Y[k:]]
    assert np.ptp(E0) < 1e-8 and np.ptp(E1) < 1e-8
    # the switch stores the spring energy of the longer rest length: a jump, not drift
    jump = 0.5 * p.k * ((p.l0 * (1 + d) - ln[k]) ** 2 - (p.l0 - ln[k]) ** 2)
    assert abs((E1[0] - E0[0]) - jump) < 1e-8 and jump > 0.01
    # at lift-off the leg is longer than l0 (it pushed off to its longer rest length)
    lo_hip = ylo[0:3] + p.r * _rot(ylo)[:, 1]
    assert np.linalg.norm(s.foot - lo_hip) > p.l0


def _rot(y):
    w, a, b, c = y[6:10] / np.linalg.norm(y[6:10])
    return np.array([
        [1 - 2 * (b * b + c * c), 2 * (a * b - w * c), 2 * (a * c + w * b)],
        [2 * (a * b + w * c), 1 - 2 * (a * a + c * c), 2 * (b * c - w * a)],
        [2 * (a * c - w * b), 2 * (b * c + w * a), 1 - 2 * (a * a + b * b)]])


def test_parameters_and_options_follow_the_objects_passed():
    p1, s = _state(1)
    p2 = dataclasses.replace(p1, k=p1.k * 1.1, retraction="apex")
    o1, o2 = OPT, tslip.IntegratorOptions(rtol=1e-6, atol=1e-6)
    first = {(i, j): trunk_step(p, s, options=o) for i, p in enumerate((p1, p2))
             for j, o in enumerate((o1, o2))}
    assert first[0, 0].state is not None and first[1, 0].state is not None
    assert not math.isclose(first[0, 0].stance_time, first[1, 0].stance_time)
    assert first[0, 0].n_steps > first[0, 1].n_steps  # the tighter tolerance takes more
    # in another order, each call gives what it gave before (nothing of another call kept)
    for i, j in [(1, 1), (0, 0), (1, 0), (0, 1), (0, 0)]:
        p, o = (p1, p2)[i], (o1, o2)[j]
        r = trunk_step(p, s, options=o)
        assert r.stance_time == first[i, j].stance_time
        np.testing.assert_array_equal(r.state.y, first[i, j].state.y)
    # a new object with equal fields gives the same stride
    r = trunk_step(dataclasses.replace(p1), s, options=dataclasses.replace(o1))
    np.testing.assert_array_equal(r.state.y, first[0, 0].state.y)
