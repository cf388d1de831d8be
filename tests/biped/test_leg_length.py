"""``BipedParams.leg_length`` (issue 42: it was never called or tested): the rest leg
length, checked against the biped's own kinematics (eq. E.8) and the unit of length."""

import numpy as np
import pytest

import tslip
from tslip.biped import BipedParams
from tslip.biped.dynamics import foot_position, hip_position


def test_thesis_biped_has_the_tslip_leg_length():
    # Table E.1: thigh 0.70 L + shank 0.30 L; L is the rest leg length (Table 3.1), the
    # TSLIP's l0
    assert BipedParams().leg_length == pytest.approx(1.0, abs=1e-15)
    assert BipedParams().leg_length == tslip.preset("table6.1").l0


@pytest.mark.parametrize(("l_t0", "l_s0"), [(0.7, 0.3), (0.6, 0.35), (0.75, 0.2)])
def test_hip_to_foot_distance_at_rest_is_the_leg_length(l_t0, l_s0, rng):
    p = BipedParams().replace(l_t0=l_t0, l_s0=l_s0)
    for _ in range(5):
        q = rng.uniform(-0.5, 0.5, 9)
        q[:2] = rng.uniform(0.0, 2.0, 2)
        q[[3, 6]], q[[4, 7]] = l_t0, l_s0  # both legs at rest
        hip = hip_position(p, q)
        for leg in (0, 1):
            dist = float(np.linalg.norm(foot_position(p, q, leg) - hip))
            assert p.leg_length == pytest.approx(dist, abs=1e-12)
