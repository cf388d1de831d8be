"""Leg thrust (issue 26, section 1): the rest length steps to l0 (1 + d) at maximum compression.

Checked against the independent Cartesian model of ``test_leg_exponent`` (scipy, the
switch as an event), the closed-form spring work, and finite differences.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import tslip
from tslip.gait.section import total_energy

from .test_leg_exponent import STATE, TIGHT, _fd_jacobian, reference_stance, spring


def _params(preset, **kw):
    return dataclasses.replace(tslip.preset(preset), **kw)


@pytest.mark.parametrize("n, d, c_l", [(1.0, 0.2, 0.0), (1.5, 0.1, 0.0), (1.0, 0.3, 0.5),
                                       (2.0, 0.05, 0.3)])
def test_thrust_stance_matches_an_independent_integration(n, d, c_l):
    p = _params("table2.1", leg_exponent=n, leg_thrust=d, c_l=c_l,
                k=25.0 * 0.2 ** (1 - n))
    res = tslip.step(p, STATE, options=TIGHT)
    t_lo, u, _ = reference_stance(p, STATE)
    lo = res.liftoff
    assert abs(res.stance_time - t_lo) < 1e-8
    np.testing.assert_allclose([lo.x, lo.y, lo.phi, lo.xd, lo.yd, lo.phid], u,
                               rtol=0, atol=1e-8)
    # the thrust changes the stance: without it the lift-off differs by far more
    t0, u0, _ = reference_stance(dataclasses.replace(p, leg_thrust=0.0), STATE)
    assert np.max(np.abs(u - u0)) > 1e-3


@pytest.mark.parametrize("n, d", [(1.0, 0.2), (1.5, 0.1), (0.8, 0.3)])
def test_energy_added_is_the_closed_form_spring_work(n, d):
    """Passive, no damping: ``E_after - E_before = V(l0 (1+d) - l_min) - V(l0 - l_min)``."""
    p = _params("table2.1", leg_exponent=n, leg_thrust=d, k=25.0 * 0.2 ** (1 - n))
    res = tslip.step(p, STATE, options=TIGHT)
    lo = res.liftoff
    l_min = float(res.stance[:, 1].min())  # a row at each step, one at the switch
    _, _, l_min_ref = reference_stance(p, STATE)
    assert abs(l_min - l_min_ref) < 1e-9
    work = spring(p, l_min, p.l0 * (1 + d))[1] - spring(p, l_min, p.l0)[1]
    assert work > 0.05
    e0 = total_energy(p, tslip.TouchdownState.from_section(STATE))
    # at lift-off the spring is relaxed (c_l = 0, no torque): the energy is the body's
    e1 = (p.m * (lo.xd**2 + lo.yd**2) / 2 + p.J * lo.phid**2 / 2 + p.m * p.g * lo.y
          + spring(p, lo.l, p.l0 * (1 + d))[1])
    assert abs((e1 - e0) - work) < 1e-9
    # the trajectory's energy column jumps by the same amount at the switch
    tr = tslip.simulate(p, tslip.TouchdownState.from_section(STATE), 1, dt=0.002, options=TIGHT)
    e = tr.to_dataframe()["energy"].to_numpy()
    assert abs(e[-1] - e[0] - work) < 1e-8


@pytest.mark.parametrize("preset, kw", [
    ("table6.1", dict(leg_thrust=0.1)),
    ("table6.1", dict(leg_thrust=0.1, leg_exponent=1.5, k=8.0 * 0.2 ** -0.5)),
    ("table2.1", dict(leg_thrust=0.05, c_l=0.5)),
])
def test_exact_jacobian_carries_the_switch(preset, kw):
    p = _params(preset, **kw)
    q = STATE if preset == "table2.1" else np.array([0.93, 0.0, 1.9, -0.35, 0.0])
    p = dataclasses.replace(p, alpha_r=_touching_alpha_r(p, q))
    res, J = tslip.step_jacobian(p, q, options=TIGHT)
    assert res.status == tslip.Status.OK
    assert np.isfinite(tslip.step(p, q, options=TIGHT).stance[:, 1]).all()
    np.testing.assert_allclose(J, _fd_jacobian(p, q), rtol=0, atol=1e-7)


def _touching_alpha_r(p, q):
    """A reset angle whose flight ends in a touch-down: that of the stride's lift-off
    pitch that lands the leg at the start's angle (eq. 2.17 with the flight time)."""
    for a in np.linspace(0.3, 1.6, 27):
        if tslip.step_map(dataclasses.replace(p, alpha_r=float(a)), q).status == tslip.Status.OK:
            return float(a)
    raise AssertionError("no touch-down")


def test_switch_time_is_reported_only_with_thrust():
    """``OUT_TSW``: NaN without thrust (no switch looked for); with it, the instant of
    maximum compression (``ldot = 0``) of the recorded stance."""
    from tslip.model import _pack as pk

    q = np.array([0.93, 0.0, 1.9, -0.35, 0.0])
    p = tslip.preset("table6.1")
    assert np.isnan(tslip.step_batch(p, q[None, :]).raw[0, pk.OUT_TSW])
    pt = dataclasses.replace(p, leg_thrust=0.2)
    t_sw = tslip.step_batch(pt, q[None, :], options=TIGHT).raw[0, pk.OUT_TSW]
    st = tslip.step(pt, q, options=TIGHT).stance
    row = st[st[:, 0] == t_sw]
    assert len(row) == 1 and abs(row[0, 4]) < 1e-10  # ldot = 0 there
    assert st[0, 4] < 0 and t_sw == st[np.argmin(st[:, 1]), 0]


@pytest.mark.parametrize("c_l", [0.05, 0.2])
def test_find_gait_solves_the_thrust_that_replaces_the_dampers_loss(c_l):
    """Passive hip with leg damping: ``find_gait`` solves ``leg_thrust`` (issue 26). On the
    gait found, an independent integration of the stance (scipy, the thrust's switch as an
    event) ends with the body's energy at touch-down: the thrust gives back exactly what
    the damper took (the flight conserves it), and a thrust 1 % off does not."""
    p = _params("table2.1", c_l=c_l)
    g = tslip.find_gait(p)
    assert g.converged, g.message
    d = g.params.leg_thrust
    assert 0.0 < d < 0.5

    def body_energy_change(thrust):
        q = dataclasses.replace(g.params, leg_thrust=thrust)
        _, u, _ = reference_stance(q, g.state.section())
        e_lo = q.m * (u[3] ** 2 + u[4] ** 2) / 2 + q.J * u[5] ** 2 / 2 + q.m * q.g * u[1]
        return e_lo - total_energy(q, g.state)

    assert abs(body_energy_change(d)) < 1e-8
    assert abs(body_energy_change(1.01 * d)) > 1e-5
    # without the damper there is nothing to give back: no thrust is solved for
    assert "leg_thrust" not in tslip.gait.GaitProblem.from_params(
        tslip.preset("table2.1")).names


def test_a_solved_thrust_is_no_sweep_parameter_and_a_fixed_one_is():
    from tslip.sweeps import StudySpec

    def spec(c_l):
        return StudySpec.from_dict({"name": "d", "preset": "table2.1", "params": {"c_l": c_l},
                                    "analyses": ["floquet"],
                                    "axis": [{"param": "leg_thrust", "values": [0.1, 0.2]}]})

    with pytest.raises(ValueError, match=r"^'leg_thrust' is solved for by the gait search"):
        spec(0.1)
    assert spec(0.0).axes[0].param == "leg_thrust"


def test_stride_work_closes_with_the_thrust():
    """``stride_work`` counts the thrust's spring work: on the passive Table 2.1 gait with
    leg damping (thrust solved) the thrust is all the energy put in, so it equals the
    damper's loss plus the lift-off loss, and equals the closed form at the independent
    integration's ``l_min``."""
    g = tslip.find_gait(_params("table2.1", c_l=0.1))
    w = tslip.gait.stride_work(g)
    assert w.hip == 0.0 and w.thrust > 0.04
    assert abs(w.residual) < 1e-6
    assert abs(w.thrust - (w.damper + w.liftoff)) < 1e-6
    p = g.params
    _, _, l_min = reference_stance(p, g.state.section())
    closed = spring(p, l_min, p.l0 * (1 + p.leg_thrust))[1] - spring(p, l_min, p.l0)[1]
    assert abs(w.thrust - closed) < 1e-9


@pytest.mark.parametrize("method", ["dopri5", "dop853"])
def test_recorded_forces_are_the_ground_force_of_the_recorded_state(method):
    """The forces of ``step`` (rows at each step) and ``simulate`` (grid rows: its strides'
    ``grf`` and its ``Fx, Fy, tau`` columns) are derived from the recorded state: they are
    ``dynamics.ground_reaction_force`` and ``hip_torque`` there, with the switched rest
    length on the rows the kernel wrote after the thrust's switch: a step's from
    ``t >= t_sw`` (the switch's own row), the grid's from ``t > t_sw``."""
    from tslip.model import _pack as pk
    from tslip.model import dynamics as dyn

    p = _params("table6.1", leg_thrust=0.2)
    q = np.array([0.93, 0.0, 1.9, -0.35, 0.0])
    o = tslip.IntegratorOptions(method=method)
    t_sw = tslip.step_batch(p, q[None, :], options=o).raw[0, pk.OUT_TSW]

    def forces(st, after):  # st: rows (t, l, beta, phi, ld, betad, phid)
        rows = []
        for y, sw in zip(st[:, 1:], after):
            fx, fy = dyn.ground_reaction_force(p, y, p.l0 * (1.0 + p.leg_thrust) if sw else None)
            rows.append([fx, fy, dyn.hip_torque(p, y[:3], y[3:])])
        return np.array(rows)

    r = tslip.step(p, q, options=o)
    assert r.ok and np.count_nonzero(r.stance[:, 0] == t_sw) == 1
    np.testing.assert_array_equal(r.grf[:, 0], r.stance[:, 0])
    np.testing.assert_allclose(r.grf[:, 1:], forces(r.stance, r.stance[:, 0] >= t_sw),
                               rtol=0, atol=1e-12)
    tr = tslip.simulate(p, tslip.TouchdownState.from_section(q), 1, dt=0.01, options=o)
    st = tr.steps[0]
    assert st.ok and np.any(st.stance[:, 0] > t_sw) and np.any(st.stance[:, 0] < t_sw)
    want = forces(st.stance, st.stance[:, 0] > t_sw)
    np.testing.assert_allclose(st.grf[:, 1:], want, rtol=0, atol=1e-12)
    d = tr.to_dataframe()
    np.testing.assert_allclose(d.loc[d["stance"], ["Fx", "Fy", "tau"]].to_numpy(), want,
                               rtol=0, atol=1e-12)


def test_a_grid_row_at_the_switch_has_the_force_before_it():
    """The grid's side of the rule (``after_switch``): a grid row at exactly ``t_sw`` was
    sampled from the step that ends at the switch, so its forces are those of the rest
    length ``l0`` (a row at each step there is written after the switch: ``l0 (1 + d)``).
    The grid's first sample is at ``dt``: with ``dt = t_sw`` it falls on the switch."""
    from tslip.model import _pack as pk
    from tslip.model import dynamics as dyn

    p = _params("table6.1", leg_thrust=0.2)
    q = np.array([0.93, 0.0, 1.9, -0.35, 0.0])
    t_sw = float(tslip.step_batch(p, q[None, :]).raw[0, pk.OUT_TSW])
    tr = tslip.simulate(p, tslip.TouchdownState.from_section(q), 1, dt=t_sw)
    st = tr.steps[0]
    at = np.flatnonzero(st.stance[:, 0] == t_sw)
    assert st.ok and len(at) == 1
    y = st.stance[at[0], 1:]
    before = dyn.ground_reaction_force(p, y, None)
    after = dyn.ground_reaction_force(p, y, p.l0 * (1.0 + p.leg_thrust))
    assert abs(after[1] - before[1]) > 0.1  # the two sides differ
    np.testing.assert_allclose(st.grf[at[0], 1:3], before, rtol=0, atol=1e-12)
    d = tr.to_dataframe()
    row = d[d["stance"] & (d["t"] == t_sw)]
    np.testing.assert_allclose(row[["Fx", "Fy"]].to_numpy()[0], before, rtol=0, atol=1e-12)
