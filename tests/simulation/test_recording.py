"""The recorded run of ``tslip.simulate`` (compiled ``record_run``) against references.

* every sample row against an independent run: the Newton-Euler stance of
  ``test_reference`` integrated by scipy ``solve_ivp`` (DOP853, 1e-12) and its
  closed-form flight, chained stride to stride, on a grid built here;
* events and strides against a loop of ``tslip.step`` (the same kernel, no recording);
* physics: energy constant in flight, and over a whole run of the passive gait;
* runs that end early (a fall, an integration error) keep their rows and status.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import tslip
from tslip.gait import find_gait
from tslip.simulation.result import TRAJECTORY_COLUMNS

from .test_reference import flight_state, leg_state, ref_stance, ref_touchdown_time

TIGHT = tslip.IntegratorOptions(rtol=1e-12, atol=1e-12)
COL = {c: i for i, c in enumerate(TRAJECTORY_COLUMNS)}


@pytest.fixture(scope="module")
def gaits():
    out = {}
    for name in ("table6.1", "table2.1"):
        g = find_gait(tslip.preset(name))
        assert g.converged
        out[name] = (g.params, g.state)
    return out


def energy(p, y, xd, yd, phid, l):  # noqa: E741
    """Kinetic + gravity + spring energy [MgL], written out here."""
    return (0.5 * p.m * (xd**2 + yd**2) + 0.5 * p.J * phid**2 + p.m * p.g * y
            + 0.5 * p.k * (p.l0 - l) ** 2)


def reference_rows(p: tslip.Params, td: tslip.TouchdownState, n: int, dt: float,
                   ground: float | None = None) -> np.ndarray:
    """The trajectory table of ``n`` strides from ``td``, independently of tslip's kernels.

    Every touch-down after the first lands on ground at height ``ground``
    (default: that of ``td``).

    Stance rows at ``0, dt, 2 dt, ...`` up to lift-off plus the lift-off
    instant; flight rows at ``dt, 2 dt, ...`` after lift-off, short of the
    touch-down by more than 1e-9; the last touch-down instant closes the run.
    """
    rows = []
    t0 = 0.0
    for i in range(n):
        ts, s_lo, xf, sol = ref_stance(p, td)
        grid = np.arange(0.0, ts, dt)
        grid = np.append(grid[grid <= ts], ts)
        for tl in grid:
            s = sol.sol(tl) if tl < ts else s_lo
            x, y, phi, xd, yd, phid = s
            lg = leg_state(p, s, xf, td.h)
            hip = (x - p.r * math.sin(phi), y + p.r * math.cos(phi))
            rows.append([t0 + tl, i, 1, x, y, xd, yd, phi, phid, lg.l, lg.beta, lg.ld, lg.betad,
                         lg.beta + phi, xf, td.h, *hip, lg.Fx, lg.Fy, lg.tau,
                         energy(p, y, xd, yd, phid, lg.l)])
        h_next = td.h if ground is None else ground
        tf = ref_touchdown_time(p, s_lo, h_next)
        taus = [dt * j for j in range(1, int(tf / dt) + 2) if tf - dt * j >= 1e-9]
        if i == n - 1:
            taus.append(tf)
        x0, _, _, xd0, _, phid0 = s_lo
        for tau in taus:
            xt, yt, ydt, pht, bt = (float(v) for v in flight_state(p, s_lo, tau))
            betad = p.omega_r if p.leg_reset == "global" else p.omega_r - phid0
            hip = (xt - p.r * math.sin(pht), yt + p.r * math.cos(pht))
            foot = (hip[0] + p.l0 * math.cos(bt), hip[1] - p.l0 * math.sin(bt))
            e = energy(p, yt, xd0, ydt, phid0, p.l0)
            rows.append([t0 + ts + tau, i, 0, xt, yt, xd0, ydt, pht, phid0, p.l0, bt, 0.0, betad,
                         bt + pht, *foot, *hip, 0.0, 0.0, 0.0, e])
        _, _, ydt, pht, bt = (float(v) for v in flight_state(p, s_lo, tf))
        td = tslip.TouchdownState(bt, pht, xd0, ydt, phid0, x0 + xd0 * tf, h_next)
        t0 += ts + tf
    return np.array(rows)


@pytest.mark.parametrize("name", ["table6.1", "table2.1"])
def test_rows_match_an_independent_run(gaits, name):
    """Every column of every row, 2 strides at dt = 0.05 and 0.01, within 1e-8 of the reference."""
    p, s = gaits[name]
    for dt in (0.05, 0.01):
        traj = tslip.simulate(p, s, 2, dt=dt, options=TIGHT)
        ref = reference_rows(p, s, 2, dt)
        assert traj.data.shape == ref.shape, f"dt {dt}: rows {len(traj.data)} vs {len(ref)}"
        for c, j in COL.items():
            np.testing.assert_allclose(traj.data[:, j], ref[:, j], rtol=0, atol=1e-8,
                                       err_msg=f"{name} dt {dt} column {c}")


def test_rows_after_a_disturbance_match_the_reference_from_the_disturbed_state(gaits):
    """A push and a step down at stride 1: the rows from there on are those of a run
    started from the pushed state on the lowered ground."""
    p, s = gaits["table6.1"]
    dist = tslip.Disturbance(at_step=1, dh=-0.05, dxd=0.1, dphid=0.2)
    traj = tslip.simulate(p, s, 3, dt=0.02, options=TIGHT, disturbance=dist)
    assert traj.status == tslip.Status.OK
    td1 = traj.steps[0].state
    pushed = dataclasses.replace(td1, xd=td1.xd + 0.1, phid=td1.phid + 0.2)
    assert traj.steps[1].start.as_array() == pytest.approx(pushed.as_array(), abs=1e-15)
    rows = traj.data[traj["step"] >= 1]
    ref = reference_rows(p, pushed, 2, 0.02, ground=-0.05)
    ref[:, COL["t"]] += traj.events[2].t  # the second touch-down
    ref[:, COL["step"]] += 1
    assert rows.shape == ref.shape
    np.testing.assert_allclose(rows, ref, rtol=0, atol=1e-8)
    assert traj.steps[2].start.h == -0.05


def test_events_and_strides_are_those_of_step(gaits):
    """Touch-down and lift-off times from a loop of ``step``; each is a sample row."""
    p, s = gaits["table6.1"]
    n = 25  # more rows than the first buffer (8 strides, estimated) holds: it grows
    traj = tslip.simulate(p, s, n, dt=0.01)
    assert traj.status == tslip.Status.OK and len(traj.steps) == n
    t = traj["t"]
    assert np.all(np.diff(t) > 0)
    td, t0 = s, 0.0
    kinds = [e.kind for e in traj.events]
    assert kinds == ["touchdown", "liftoff"] * n + ["touchdown"]
    for i in range(n):
        r = tslip.step(p, td)
        st = traj.steps[i]
        assert st.start == td and st.state == r.state
        assert (st.stance_time, st.flight_time, st.foot_x) == (r.stance_time, r.flight_time,
                                                                r.foot_x)
        assert st.liftoff == r.liftoff and st.status == r.status
        ev_td, ev_lo = traj.events[2 * i], traj.events[2 * i + 1]
        assert ev_td.step == ev_lo.step == i
        assert ev_td.t == pytest.approx(t0, abs=1e-12)
        assert ev_lo.t == pytest.approx(t0 + r.stance_time, abs=1e-12)
        for ev, stance in ((ev_td, 1.0), (ev_lo, 1.0)):
            k = int(np.argmin(np.abs(t - ev.t)))
            assert t[k] == ev.t and traj["stance"][k] == stance and traj["step"][k] == i
            assert (traj["x"][k], traj["y"][k]) == pytest.approx((ev.x, ev.y), abs=1e-12)
            assert traj["foot_y"][k] == pytest.approx(ev.foot_y, abs=1e-12)
        assert abs(traj["Fy"][np.searchsorted(t, ev_lo.t)]) < 1e-7  # F_y = 0 at lift-off
        # the stride's stance samples are its grf and stance records
        rows = (traj["step"] == i) & (traj["stance"] == 1)
        np.testing.assert_array_equal(st.grf[:, 1:], traj.data[rows][:, [COL["Fx"], COL["Fy"],
                                                                          COL["tau"]]])
        np.testing.assert_allclose(st.stance[:, 0] + t0, t[rows], rtol=0, atol=1e-12)
        t0 += r.stance_time + r.flight_time
        td = r.state
    last = traj.events[-1]
    assert last.t == pytest.approx(t0, abs=1e-12) and t[-1] == last.t
    assert traj["foot_y"][-1] == pytest.approx(td.h, abs=1e-12)
    assert traj.touchdowns[-1] == td
    assert traj.steps[-1] is traj.steps[n - 1] and len(traj.steps[2:5]) == 3
    with pytest.raises(IndexError):
        traj.steps[n]


@pytest.mark.parametrize("name", ["table6.1", "table2.1"])
def test_energy_constant_in_flight(gaits, name):
    """Ballistic flight conserves the energy column to rounding, stride by stride: the
    lift-off row's energy less the spring energy the leg reset drops (l = l0 in flight)."""
    p, s = gaits[name]
    traj = tslip.simulate(p, s, 5, dt=0.01)
    e, step, stance = traj["energy"], traj["step"], traj["stance"]
    for i in range(5):
        lo = np.nonzero((step == i) & (stance == 1))[0][-1]  # the lift-off row
        fl = (step == i) & (stance == 0)
        assert fl.sum() > 3
        spring = 0.5 * p.k * (p.l0 - traj["l"][lo]) ** 2
        np.testing.assert_allclose(e[fl], e[lo] - spring, rtol=1e-13)


def test_energy_of_the_passive_gait_constant_within_the_tolerance(gaits):
    """Table 2.1 (undamped, passive): the energy column drifts less than 100 x rtol."""
    p, s = gaits["table2.1"]
    for rtol in (1e-8, 1e-11):
        opts = tslip.IntegratorOptions(rtol=rtol, atol=rtol)
        traj = tslip.simulate(p, s, 50, dt=0.01, options=opts)
        e = traj["energy"]
        assert np.ptp(e) / e[0] < 100 * rtol, (rtol, np.ptp(e) / e[0])


def test_a_fall_mid_run_keeps_the_rows_before_it(gaits):
    """A big step down at stride 3: the partial run, its status and its fall event."""
    p, s = gaits["table6.1"]
    dist = tslip.Disturbance(at_step=3, dh=-0.6)
    traj = tslip.simulate(p, s, 20, dt=0.01, disturbance=dist)
    assert traj.fell
    n = len(traj.steps)
    assert 3 < n < 20 and traj.steps[-1].status == traj.status
    assert all(st.ok for st in traj.steps[:-1])
    fall = traj.events[-1]
    assert fall.kind == "fall" and fall.step == n - 1
    last = traj.steps[-1]
    assert traj.events[-2].kind == "touchdown"  # a failed stride has no lift-off event
    t0 = traj.events[-2].t
    assert fall.t == pytest.approx(t0 + last.stance_time + last.flight_time, abs=1e-12)
    assert traj["t"][-1] <= fall.t + 1e-12 and traj["step"][-1] == n - 1
    # the completed strides are the rows of the same run without the fall
    ok = tslip.simulate(p, s, 3, dt=0.01)
    k = len(ok.data) - 1  # its last row is the touch-down that starts stride 3
    np.testing.assert_array_equal(traj.data[:k], ok.data[:k])
    assert traj.data[k, COL["t"]] == ok.data[k, COL["t"]]


def test_an_integration_error_mid_run_returns_the_partial_run(gaits):
    """A flight longer than ``t_max_flight`` after a deep step down: status, rows, no fall."""
    p, s = gaits["table6.1"]
    opts = tslip.IntegratorOptions(t_max_flight=3.0)
    traj = tslip.simulate(p, s, 10, dt=0.01, options=opts,
                          disturbance=tslip.Disturbance(at_step=2, dh=-100.0))
    assert traj.status == tslip.Status.FLIGHT_TIMEOUT and not traj.fell
    assert len(traj.steps) == 3 and traj.steps[-1].status == traj.status
    assert [e.kind for e in traj.events] == ["touchdown", "liftoff"] * 2 + ["touchdown"]
    t_lo = traj.events[-1].t + traj.steps[-1].stance_time
    fl = traj.data[(traj["step"] == 2) & (traj["stance"] == 0)]
    assert len(fl) > 250  # the flight was sampled up to the time-out
    assert fl[-1, COL["t"]] == pytest.approx(t_lo + traj.steps[-1].flight_time, abs=1e-9)


NOJIT = """
import json, tslip
g = tslip.find_gait(tslip.preset("table6.1"))
tr = tslip.simulate(g.params, g.state, 2, dt=0.05)
print(json.dumps(tr.data.tolist()))
"""


def test_recording_runs_as_plain_python(gaits):
    """``NUMBA_DISABLE_JIT=1`` gives the same table (CONTRIBUTING: kernels run uncompiled)."""
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    proc = subprocess.run([sys.executable, "-c", NOJIT], env=env, capture_output=True, text=True,
                          timeout=600, check=True)
    pure = np.array(json.loads(proc.stdout.strip().splitlines()[-1]))
    p, s = gaits["table6.1"]
    np.testing.assert_allclose(pure, tslip.simulate(p, s, 2, dt=0.05).data, rtol=0, atol=1e-12)


def test_a_run_holds_few_rows_beyond_its_samples(gaits):
    """The rows a run allocated ahead are given back when it stops early (here a fall at
    stride 23 of 400: rows were allocated for all 400); a run that goes its length keeps
    at most an eighth of its rows spare (``integrate.TRIM_SPARE``)."""
    p, s = gaits["table6.1"]
    for dist in (tslip.Disturbance(at_step=20, dxd=-1.0), None):
        traj = tslip.simulate(p, s, 400, disturbance=dist)
        assert (len(traj.steps) < 30) == (dist is not None)
        rec = traj.steps._rec  # the rows of the trajectory's samples
        assert len(rec) == len(traj["t"])
        held = rec if rec.base is None else rec.base
        assert len(held) <= len(rec) * 8 / 7
