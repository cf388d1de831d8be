"""The 3-D TSLIP's planar limit: with splay = 0 and no roll, yaw or lateral motion, every
stride is the planar ``tslip.step`` in every planar variable (issue 43, Part 2), for each
of the four hip controllers, under the local and the global leg reset, to 1e-9."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import tslip
from tslip.model.controllers import ConstantTorque, GlobalPD, LocalVelocity, Passive
from tslip.spatial.trunk import TrunkStatus, from_planar, to_planar, trunk_step
from tslip.spatial.trunk_parameters import TrunkParams

OPT = tslip.IntegratorOptions(rtol=1e-12, atol=1e-12)

CONTROLLERS = {
    "passive": Passive(),
    "global_pd": GlobalPD(Kp=3.0, Kd=0.4, phi_ref=0.05, phid_ref=0.0),
    "local_velocity": LocalVelocity(Kd=0.3, alphad_ref=2.0),
    "constant_torque": ConstantTorque(tau_c=0.2, c_h=0.05),
}


def _planar(controller, reset):
    # m, l0, g away from 1, so that a missing factor shows; a damped leg with the torques
    return dataclasses.replace(
        tslip.preset("table2.1"), m=1.3, l0=0.9, g=1.2, J=0.12, r=0.25, k=30.0,
        alpha_r=0.9, omega_r=0.8, controller=controller,
        leg_reset=reset, c_l=0.0 if controller.name == "passive" else 0.05)


@pytest.mark.parametrize("reset", ["local", "global"])
@pytest.mark.parametrize("name", list(CONTROLLERS))
def test_every_stride_is_the_planar_step(name, reset):
    p = _planar(CONTROLLERS[name], reset)
    tp = TrunkParams.from_planar(p)
    # a start from which the planar model runs three strides (found by a scan)
    beta = 1.1 if (name, reset) == ("local_velocity", "local") else 1.0
    td = tslip.TouchdownState(beta=beta, phi=0.04, xd=2.0, yd=-0.3, phid=-0.2, x=0.3)
    state = from_planar(tp, td, side=1)
    done = 0
    for _ in range(3):
        r2 = tslip.step(p, td, options=OPT)
        r3 = trunk_step(tp, state, options=OPT)
        assert r3.status.name == r2.status.name
        if not r2.ok:
            break
        assert abs(r3.stance_time - r2.stance_time) < 1e-9
        assert abs(r3.flight_time - r2.flight_time) < 1e-9
        got = to_planar(tp, r3.state).as_array()
        np.testing.assert_allclose(got, r2.state.as_array(), rtol=0, atol=1e-9)
        # nothing left the sagittal plane, and the legs alternate
        y = r3.state.y
        assert np.all(y[[2, 5, 7, 8, 10, 11]] == 0.0) and r3.state.foot[2] == 0.0
        assert r3.state.side == -state.side
        td, state = r2.state, r3.state
        done += 1
    assert done == 3


def test_a_planar_fall_is_the_same_fall():
    # too steep a landing: the planar model falls; so does the 3-D one, with the same name
    p = _planar(Passive(), "local")
    tp = TrunkParams.from_planar(p)
    td = tslip.TouchdownState(beta=0.35, phi=0.0, xd=0.5, yd=-0.2, phid=0.0)
    r2 = tslip.step(p, td, options=OPT)
    r3 = trunk_step(tp, from_planar(tp, td), options=OPT)
    assert not r2.ok
    assert r3.status == TrunkStatus[r2.status.name]


@pytest.mark.parametrize("change", [
    {"retraction": "apex"},
    {"leg_exponent": 1.5},  # passive, undamped: lift-off located on the spring
    {"leg_exponent": 0.8, "controller": ConstantTorque(tau_c=0.2, c_h=0.05)},
    {"leg_thrust": 0.1, "c_l": 0.3},
    {"alpha_stop": 0.95, "leg_reset": "global"},
])
def test_the_planar_leg_law_and_retraction_options_carry_over(change):
    p = dataclasses.replace(_planar(Passive(), "local"), **change)
    tp = TrunkParams.from_planar(p)
    td = tslip.TouchdownState(beta=1.0, phi=0.04, xd=2.0, yd=-0.3, phid=-0.2, x=0.3)
    state = from_planar(tp, td, side=-1)
    for _ in range(2):
        r2 = tslip.step(p, td, options=OPT)
        r3 = trunk_step(tp, state, options=OPT)
        # the same outcome at the same instant: a fall too (the hip reaching the ground)
        assert r3.status.name == r2.status.name
        assert abs(r3.stance_time - r2.stance_time) < 1e-9
        assert abs(r3.flight_time - r2.flight_time) < 1e-9
        if not r2.ok:
            break
        np.testing.assert_allclose(to_planar(tp, r3.state).as_array(), r2.state.as_array(),
                                   rtol=0, atol=1e-9)
        td, state = r2.state, r3.state
