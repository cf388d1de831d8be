"""Terrain, disturbances, and the batch entry points against the serial map."""

import dataclasses
import math

import numpy as np
import pytest

import tslip
from tslip import Status


@pytest.fixture(scope="module")
def gait():
    return tslip.find_gait(tslip.preset("table2.1"))


def test_terrain_lookup_and_shift():
    t = tslip.Terrain.sequence([1.0, 2.0], [0.0, -0.1, 0.2])
    assert [t.height(x) for x in (0.5, 1.0, 1.5, 2.5)] == [0.0, -0.1, -0.1, 0.2]
    s = t.shifted_after(1.5, -0.05)
    assert [s.height(x) for x in (0.5, 1.2, 1.6, 2.5)] == pytest.approx([0, -0.1, -0.15, 0.15])
    with pytest.raises(ValueError, match="strictly increasing"):
        tslip.Terrain.sequence([2.0, 1.0], [0, 0, 0])
    with pytest.raises(ValueError, match="len\\(breakpoints\\) \\+ 1"):
        tslip.Terrain((1.0,), (0.0,))


def test_step_down_disturbance_lowers_every_later_touchdown(gait):
    tr = tslip.simulate(gait.params, gait.state, 6, disturbance=tslip.Disturbance(dh=-0.1))
    hs = [s.start.h for s in tr.steps]
    assert hs[0] == 0.0 and all(h == pytest.approx(-0.1) for h in hs[1:])
    # the passive model converts the drop into speed (eq. 3.8 direction)
    assert tr.steps[-1].start.v > gait.state.v


def test_step_down_through_terrain_equals_disturbance(gait):
    xf0 = tr_foot = gait.state.x + math.cos(gait.state.beta) - 0.3 * math.sin(gait.state.phi)
    a = tslip.simulate(gait.params, gait.state, 3, terrain=tslip.Terrain.step(xf0, -0.1))
    b = tslip.simulate(gait.params, gait.state, 3, disturbance=tslip.Disturbance(dh=-0.1))
    assert tr_foot == pytest.approx(a.steps[0].foot_x)
    np.testing.assert_array_equal(a.steps[-1].state.as_array(), b.steps[-1].state.as_array())


def test_push_and_pitch_rate_disturbances_change_the_state(gait):
    d = tslip.Disturbance(at_step=1, dxd=0.3, dphid=-0.5)
    tr = tslip.simulate(gait.params, gait.state, 3, disturbance=d)
    ref = tslip.simulate(gait.params, gait.state, 3)
    s, s0 = tr.steps[1].start, ref.steps[1].start
    assert s.xd == pytest.approx(s0.xd + 0.3) and s.yd == s0.yd
    assert s.phid == pytest.approx(s0.phid - 0.5)


def test_step_batch_equals_serial_map(gait, rng):
    states = gait.state.section() + rng.normal(scale=[0.01, 0.02, 0.05, 0.02, 0.05],
                                               size=(64, 5))
    b = tslip.step_batch(gait.params, states)
    for i in range(len(states)):
        m = tslip.step_map(gait.params, states[i])
        assert b.status[i] == m.status
        if m.status == Status.OK:
            np.testing.assert_array_equal(b.states[i, :5], m.q)
            assert b.stance_time[i] == m.stance_time and b.flight_time[i] == m.flight_time


def test_run_batch_equals_sequential_steps_with_per_row_terrain(gait):
    dhs = [0.0, -0.05, -0.1, -0.2, -0.4]
    xf = gait.state.x + math.cos(gait.state.beta) - 0.3 * math.sin(gait.state.phi)
    terrains = [tslip.Terrain.step(xf, dh) for dh in dhs]
    out = tslip.run_batch(gait.params, [gait.state] * len(dhs), 8, terrain=terrains)
    for i in range(len(dhs)):
        tr = tslip.simulate(gait.params, gait.state, 8, terrain=terrains[i])
        assert out.n_done[i] == sum(s.ok for s in tr.steps)
        assert Status(out.status[i]) == tr.status
        if tr.status == Status.OK:
            np.testing.assert_array_equal(out.touchdowns[i, -1], tr.steps[-1].state.as_array())


def test_batch_with_params_per_row(gait):
    ps = [dataclasses.replace(gait.params, k=k) for k in (20.0, 25.0, 30.0)]
    b = tslip.step_batch(ps, np.tile(gait.state.section(), (3, 1)))
    ts = [tslip.step_map(p, gait.state.section()).stance_time for p in ps]
    np.testing.assert_array_equal(b.stance_time, ts)
    assert b.stance_time[0] > b.stance_time[2]  # softer leg, longer stance
    with pytest.raises(ValueError, match="parameter sets"):
        tslip.step_batch(ps[:2], np.tile(gait.state.section(), (3, 1)))
