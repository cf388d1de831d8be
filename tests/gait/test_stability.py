"""Floquet multipliers: exact vs finite differences, thesis stability claims."""

import dataclasses

import numpy as np
import pytest

import tslip
from tslip.gait.stability import conserved_gradients, floquet, map_jacobian

CASES = {
    "table2.1": tslip.preset("table2.1"),
    "table6.1": tslip.preset("table6.1"),
    "local-velocity": tslip.preset("table2.1-local-velocity"),
    "constant-torque-hip-damping": dataclasses.replace(
        tslip.preset("table2.1"), controller=tslip.ConstantTorque(tau_c=0.0, c_h=0.5)),
}


@pytest.fixture(scope="module")
def gaits():
    return {k: tslip.find_gait(p) for k, p in CASES.items()}


@pytest.mark.parametrize("name", list(CASES))
def test_exact_and_finite_difference_multipliers_agree(gaits, name):
    g = gaits[name]
    assert g.converged
    ex = floquet(g, method="exact")
    fd = floquet(g, method="fd")
    np.testing.assert_allclose(ex.jacobian, fd.jacobian, atol=1e-6)
    np.testing.assert_allclose(np.sort_complex(ex.multipliers), np.sort_complex(fd.multipliers),
                               atol=1e-6)


def test_finite_differences_insensitive_to_step(gaits):
    g = gaits["table6.1"]
    mags = [np.sort(floquet(g, method="fd", step=h).magnitudes) for h in (1e-4, 1e-5, 1e-6)]
    assert np.max(np.abs(mags[0] - mags[1])) < 1e-6
    assert np.max(np.abs(mags[1] - mags[2])) < 1e-6


def test_table_6_1_largest_multiplier(gaits):
    """Thesis Section 6.1: largest eigenvalue magnitude 0.92, asymptotically stable."""
    f = floquet(gaits["table6.1"])
    assert f.max_nontrivial == pytest.approx(0.92, abs=0.01)
    assert f.stability == "asymptotic" and not f.trivial.any()


def test_table_2_1_passive_is_neutral_with_one_energy_multiplier(gaits):
    g = gaits["table2.1"]
    f = floquet(g)
    assert f.stability == "neutral" and f.trivial.sum() == 1
    lam = f.multipliers[f.trivial][0]
    assert abs(lam - 1.0) < 1e-6
    assert np.all(np.abs(f.multipliers[~f.trivial]) < 1.0)
    # its left eigenvector is the energy gradient (docs/conventions.md)
    w, V = np.linalg.eig(f.jacobian.T)
    v = np.real(V[:, np.argmin(np.abs(w - 1.0))])
    (grad,) = conserved_gradients(g.params, g.state.section())
    cos = abs(v @ grad) / (np.linalg.norm(v) * np.linalg.norm(grad))
    assert cos > 1 - 1e-6


@pytest.mark.parametrize("r", [-0.3, 0.9])
def test_mass_above_hip_or_too_low_is_unstable(r):
    """Section 4.5.1: stable for r below the hip up to about 0.86; unstable beyond."""
    g = tslip.find_gait(dataclasses.replace(tslip.preset("table2.1"), r=r))
    assert g.converged
    f = floquet(g)
    assert f.stability == "unstable" and f.max_nontrivial > 1.0 + 1e-6


def test_r_zero_has_two_structural_multipliers():
    g = tslip.find_gait(dataclasses.replace(tslip.preset("table2.1"), r=0.0))
    f = floquet(g)
    assert f.trivial.sum() == 2
    assert np.all(np.abs(f.multipliers[f.trivial] - 1.0) < 1e-4)


def test_local_velocity_equals_constant_torque_with_hip_damping(gaits):
    """Eq. 2.16 text: local velocity control is tau_c = Kd alphad_ref with c_h = Kd."""
    lv, ct = gaits["local-velocity"], gaits["constant-torque-hip-damping"]
    assert ct.params.controller.tau_c == pytest.approx(
        lv.params.controller.Kd * lv.params.controller.alphad_ref, abs=1e-8)
    np.testing.assert_allclose(ct.state.section(), lv.state.section(), atol=1e-8)
    np.testing.assert_allclose(np.sort_complex(floquet(ct).multipliers),
                               np.sort_complex(floquet(lv).multipliers), atol=1e-8)


def test_map_jacobian_rejects_bad_input(gaits):
    g = gaits["table2.1"]
    with pytest.raises(ValueError, match="method must be"):
        map_jacobian(g.params, g.state.section(), method="magic")
    with pytest.raises(ValueError, match="step must be"):
        map_jacobian(g.params, g.state.section(), method="fd", step=-1.0)
