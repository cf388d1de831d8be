"""Biped simulation: TSLIP limit, events, status, bad input."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import tslip
from tslip.biped import BipedOptions, BipedParams, BipedState, Status, simulate, step


def _tslip_limit_case():
    """Biped with 1e-4 leg masses, a stiff thigh PD in series with the shank
    spring, no hip torque and a stiff ground, started at a TSLIP touch-down."""
    eps, ks, kpt = 1e-4, 25.0, 1e4
    tp = dataclasses.replace(tslip.preset("table2.1"), k=ks * kpt / (ks + kpt))
    td = tslip.TouchdownState(beta=1.05, phi=0.1, xd=5.0, yd=-0.3, phid=0.2)
    bp = BipedParams(
        m_b=tp.m, J_b=tp.J, r_1=tp.r, m_t=eps, m_s=eps, m_f=eps, J_t=eps * 1e-2,
        J_s=eps * 1e-2, k=ks, c_l=0.0, Kp_t=kpt, Kd_t=1.0, Kp_h=0.0, Kd_h=0.0,
        k_z=1e5, k_x=1e5, c_z=5.0, c_x=5.0, d=0.99, T=100.0, rho0=0.0,
    )
    b, ph, tb = td.beta, td.phi, -td.phi  # theta_b = -phi, gamma = beta - pi/2
    gam = b - math.pi / 2
    hip = np.array([-math.cos(b), math.sin(b)])
    com = hip + tp.r * np.array([math.sin(ph), -math.cos(ph)])
    vh = np.array([td.xd, td.yd]) - tp.r * td.phid * np.array([math.cos(tb), -math.sin(tb)])
    u = np.array([math.sin(gam), math.cos(gam)])
    up = np.array([math.cos(gam), -math.sin(gam)])
    gl = math.pi - 0.3  # left leg held up and back, clear of the ground
    q = np.array([com[0], com[1], tb, 0.7, 0.3, gam - tb, 0.7, 0.3, gl - tb])
    qd = np.array([td.xd, td.yd, -td.phid, 0.0, vh @ u, vh @ up + td.phid, 0, 0, td.phid])
    return tp, td, bp, BipedState(q, qd)


def test_massless_single_leg_limit_matches_tslip_stance():
    tp, td, bp, s = _tslip_limit_case()
    ref = tslip.simulate(tp, td, 1, dt=1e-3)
    st = ref["stance"] > 0
    t, fx, fy = ref["t"][st], ref["Fx"][st], ref["Fy"][st]
    tr = simulate(bp, s, 1, t_end=t[-1] + 0.05, contact=np.array([1, 0, 0.0, 0, 0, 0]),
                  options=BipedOptions(check_falls=False))
    assert tr["contact_L"].max() == 0.0
    scale = np.abs(fy).max()
    err_z = np.abs(np.interp(t, tr.time, tr["Fz_R"]) - fy).max() / scale
    err_x = np.abs(np.interp(t, tr.time, tr["Fx_R"]) - fx).max() / scale
    assert err_z < 2e-3, err_z
    assert err_x < 2e-3, err_x
    lo = [e.t for e in tr.events if e.kind == "liftoff_R"]
    assert len(lo) == 1 and lo[0] == pytest.approx(t[-1], abs=2e-3)


def test_table_e2_run_records_alternating_contacts_and_right_strides():
    tr = simulate(BipedParams(), BipedState.thesis(), 2)
    assert tr.status == Status.OK
    kinds = [e.kind for e in tr.events]
    assert kinds[:4] == ["liftoff_R", "touchdown_L", "liftoff_L", "touchdown_R"]
    assert tr.n_steps == 2
    # touch-down anchors: the foot lands at the ground, the stance foot barely slides
    for e in tr.events:
        if e.kind.startswith("touchdown"):
            assert abs(e.foot_z) < 1e-9
    one = step(BipedParams(), BipedState.thesis().to_array(), 0.0)
    assert one.t == pytest.approx(tr.strides[0, 0], abs=1e-9)
    np.testing.assert_allclose(one.state, tr.strides[0, 1:19], atol=1e-9)


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"m_b": 0.0}, "m_b"),
        ({"r_2": 1.5}, "r_2"),
        ({"d": 1.0}, "d"),
        ({"T": -1.0}, "T"),
        ({"Kp_t": -1.0}, "Kp_t"),
        ({"k_z": math.nan}, "k_z"),
        ({"l_ts": 0.8}, "l_ts"),
        ({"c_l": "a"}, "c_l"),
        ({"contact": 1}, "contact"),
    ],
)
def test_invalid_parameters_name_the_field(changes, field):
    with pytest.raises(ValueError, match=field):
        BipedParams(**changes)


def test_invalid_simulation_input():
    p = BipedParams()
    with pytest.raises(ValueError, match="n_steps"):
        simulate(p, BipedState.thesis(), 0)
    with pytest.raises(ValueError, match="shape"):
        simulate(p, np.zeros(5), 1)
    with pytest.raises(ValueError, match="finite"):
        BipedState(np.full(9, np.nan), np.zeros(9))
    with pytest.raises(ValueError, match="rtol"):
        BipedOptions(rtol=0.0)
    with pytest.raises(ValueError, match="params"):
        simulate({"m_b": 1.0}, BipedState.thesis(), 1)


def test_a_gait_that_falls_reports_stride_and_reason():
    p = BipedParams(Kp_h=0.0, Kd_h=0.0)  # no hip control: the legs do not reciprocate
    tr = simulate(p, BipedState.thesis(), 20)
    assert tr.fell
    assert tr.status.reason.startswith("fall:")
    assert tr.n_steps < 20
    assert tr.events[-1].kind == "fall"
