"""SI <-> dimensionless conversion (Table 3.1) and the robot of Table 5.1."""

import math

import pytest

import tslip
from tslip.model.units import QUANTITY_DIMS, ROBOT_SCALING, Scaling, from_si, robot_params, to_si


def test_table_5_1_dimensionless_values():
    # Table 5.1 lists v0 = 4.4 m/s as 2.0 and r = 0.15 m as 0.3 in g^1/2 L^1/2 and L.
    p = robot_params()
    assert p.v0 == pytest.approx(4.4 / math.sqrt(9.81 * 0.5))
    assert round(p.v0, 1) == 2.0
    assert p.r == pytest.approx(0.3)
    assert (p.m, p.g, p.l0) == (1.0, 1.0, 1.0)


def test_fast_running_index_of_robot_matches_section_5_2():
    # Section 5.2: 4.4 m/s corresponds to a fast-running index of 1.73 (eq. 3.12),
    # with the Table 6.1 stiffness and touch-down angle.
    p = tslip.preset("table6.1")
    v0 = robot_params().v0
    ifr = math.pi * v0 * math.sqrt(p.m / p.k) / (p.l0 * (math.pi - 2 * p.beta0))
    assert ifr == pytest.approx(1.73, abs=0.01)


@pytest.mark.parametrize("name", tslip.presets())
def test_roundtrip_si(name):
    p = tslip.preset(name)
    s = Scaling(M=80.0, g=9.81, L=1.1)
    back = from_si(to_si(p, s), s)
    for f in ("m", "J", "r", "k", "l0", "g", "v0", "beta0", "c_l", "omega_r", "alpha_r"):
        assert getattr(back, f) == pytest.approx(getattr(p, f), rel=1e-12)
    for k, v in p.controller.to_dict().items():
        if k != "type":
            assert back.controller.to_dict()[k] == pytest.approx(v, rel=1e-12)


def test_scaling_factors_by_hand():
    s = ROBOT_SCALING  # M = 3.3 kg, g = 9.81, L = 0.5
    assert s.factor("time") == pytest.approx(math.sqrt(0.5 / 9.81))
    assert s.factor("force") == pytest.approx(3.3 * 9.81)
    assert s.factor("stiffness") == pytest.approx(3.3 * 9.81 / 0.5)
    assert s.factor("impulse") == pytest.approx(3.3 * math.sqrt(9.81 * 0.5))
    assert set(QUANTITY_DIMS) >= {"length", "time", "speed", "energy", "damping"}


def test_bad_scaling():
    with pytest.raises(ValueError, match=r"Scaling.L must be in \(0, inf\)"):
        Scaling(M=1.0, g=9.81, L=0.0)
    with pytest.raises(ValueError, match="quantity must be one of"):
        ROBOT_SCALING.factor("colour")
