"""The 3-D TSLIP's touch-down section: round trip, mirror symmetry of the model, yaw
invariance, and the planar multipliers recovered from the 3-D two-step map."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import tslip
from tslip.gait.stability import floquet
from tslip.model.controllers import ConstantTorque
from tslip.spatial.trunk import TrunkStatus, from_planar
from tslip.spatial.trunk_parameters import TrunkParams
from tslip.spatial.trunk_section import (
    MIRROR,
    from_section,
    one_step_map,
    section,
    symmetric_gait,
    two_step_jacobian,
    yaw_rotated,
)

OPT = tslip.IntegratorOptions(rtol=1e-12, atol=1e-12)
TP = TrunkParams(m=1.4, J=0.11, J_roll=0.07, J_yaw=0.045, r=0.25, k=28.0, l0=0.9, g=1.3,
                 c_l=0.05, splay=0.08, alpha_r=0.95, omega_r=0.8,
                 controller=ConstantTorque(tau_c=0.25, c_h=0.05))
X = np.array([1.0, 0.1, 0.05, -0.03, 2.2, -0.4, 0.15, 0.3, -0.25, -0.2])


def test_section_round_trip_and_foot_on_the_ground():
    for side in (1, -1):
        s = from_section(TP, X, side)
        assert s.foot[1] == 0.0 and s.side == side
        np.testing.assert_allclose(section(TP, s), X, atol=1e-13)
        # the leg has its rest length and the planned direction in the trunk frame
        u = s.R.T @ (s.foot - s.y[0:3] - TP.r * s.R[:, 1])
        assert abs(np.linalg.norm(u) - TP.l0) < 1e-13
        assert np.sign(u[2]) == side  # splay > 0 puts the foot outward, on its own side


def test_the_model_is_mirror_symmetric():
    # stepping the mirror image with the other leg gives the mirror image of the step
    right, st_r = one_step_map(TP, X, side=1, options=OPT)
    left, st_l = one_step_map(TP, MIRROR * X, side=-1, options=OPT)
    assert st_r == st_l == TrunkStatus.OK
    assert np.max(np.abs(right - MIRROR * right)) > 0.01  # not trivially symmetric
    np.testing.assert_allclose(left, MIRROR * right, rtol=0, atol=1e-9)


def test_the_model_is_invariant_under_yaw():
    a, _ = one_step_map(TP, X, options=OPT)
    b, _ = one_step_map(TP, yaw_rotated(X, 0.7), options=OPT)
    np.testing.assert_allclose(b, yaw_rotated(a, 0.7), rtol=0, atol=1e-9)


def test_planar_multipliers_are_the_planar_floquet_multipliers_squared():
    p = dataclasses.replace(tslip.preset("table2.1"))
    g = tslip.find_gait(p, options=OPT)
    planar = floquet(g, options=OPT).multipliers
    tp = TrunkParams.from_planar(g.params)
    x = section(tp, from_planar(tp, g.state))
    cols = (0, 2, 4, 5, 9)
    J = two_step_jacobian(tp, x, columns=cols, step=1e-5, options=OPT)
    assert np.max(np.abs(np.delete(J, cols, axis=0))) == 0.0  # it stays in the plane
    ev = np.linalg.eigvals(J[list(cols), :])
    got = np.sort_complex(np.round(ev, 6))
    want = np.sort_complex(np.round(planar**2, 6))
    np.testing.assert_allclose(got, want, atol=2e-6)


def test_symmetric_gait_lands_on_its_mirror_and_has_the_trivial_multipliers():
    tp = TrunkParams(splay=0.05)
    g = tslip.find_gait(tslip.preset("table2.1"), options=OPT)
    tp = TrunkParams.from_planar(g.params, splay=0.05)
    x = symmetric_gait(tp, section(tp, from_planar(tp, g.state)), options=OPT)
    f, st = one_step_map(tp, x, options=OPT)
    assert st == TrunkStatus.OK
    np.testing.assert_allclose(f, MIRROR * x, atol=1e-10)
    assert abs(x[6]) > 1e-3  # a real lateral motion, not the planar gait
    J = two_step_jacobian(tp, x, step=1e-5, options=OPT)
    # heading: turning the gait turns its image (yaw invariance), a multiplier 1
    e = yaw_rotated(np.zeros(10), 0.0)
    e[1], e[4], e[6] = 1.0, x[6], -x[4]
    np.testing.assert_allclose(J @ e, e, atol=1e-5)
    # energy: conserved by the passive model, a left eigenvector with multiplier 1
    ev = np.linalg.eigvals(J)
    assert np.sum(np.abs(ev - 1.0) < 1e-4) >= 2


def test_bad_section_vector_is_refused():
    with pytest.raises(ValueError, match="section vector"):
        from_section(TP, X[:9])


@pytest.mark.parametrize("change", [{"k_splay": 0.5}, {"k_trail": 0.8},
                                    {"k_splay": -0.7, "k_trail": -1.2}])
def test_roll_couplings_keep_the_mirror_and_the_round_trip(change):
    tp = dataclasses.replace(TP, **change)
    for side in (1, -1):
        s = from_section(tp, X, side)
        np.testing.assert_allclose(section(tp, s), X, atol=1e-13)
    right, st_r = one_step_map(tp, X, side=1, options=OPT)
    left, st_l = one_step_map(tp, MIRROR * X, side=-1, options=OPT)
    assert st_r == st_l == TrunkStatus.OK
    np.testing.assert_allclose(left, MIRROR * right, rtol=0, atol=1e-9)
    base, _ = one_step_map(TP, X, side=1, options=OPT)
    assert np.max(np.abs(right - base)) > 1e-3  # the coupling acts


def test_roll_couplings_place_the_leg_as_documented():
    # leaning right (roll > 0): the right leg splays further out, the trail turns it right
    from tslip.spatial.trunk_section import _attitude, _placement
    R = _attitude(0.0, 0.0, 0.1)
    base = _placement(TP, 1, 1.0, R)
    out = _placement(dataclasses.replace(TP, k_splay=1.0), 1, 1.0, R)
    np.testing.assert_allclose(out, [np.cos(1.0), -np.sin(1.0) * np.cos(0.18),
                                     np.sin(1.0) * np.sin(0.18)], atol=1e-15)
    left = _placement(dataclasses.replace(TP, k_splay=1.0), -1, 1.0, R)
    assert abs(left[2]) < abs(base[2])  # the left leg, leaning away from it: less splay
    turned = _placement(dataclasses.replace(TP, k_trail=1.0), 1, 1.0, R)
    assert turned[2] > base[2] and abs(np.linalg.norm(turned) - 1.0) < 1e-15
