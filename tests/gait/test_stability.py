"""Floquet multipliers: exact vs finite differences, thesis stability claims."""

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tslip
from tslip.gait.stability import (
    conserved_gradients,
    eigvals,
    floquet,
    map_jacobian,
    pitch_decoupled,
)

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


def test_table_2_1_passive_is_stable_on_its_energy_level_with_one_energy_multiplier(gaits):
    """Conservative: the energy multiplier 1 is trivial, the label comes from the others."""
    g = gaits["table2.1"]
    f = floquet(g)
    assert f.stability == "asymptotic" and f.trivial.sum() == 1
    assert f.trivial_kinds[int(np.argmax(f.trivial))] == "energy"
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


def test_r_zero_sets_the_decoupled_pitch_and_the_energy_aside():
    """r = 0, passive, local reset: the pitch block [[1, T], [0, 1]] and the energy."""
    g = tslip.find_gait(dataclasses.replace(tslip.preset("table2.1"), r=0.0))
    f = floquet(g)
    assert sorted(f.trivial_kinds) == ["", "", "energy", "pitch", "pitch"]
    assert np.all(np.abs(f.multipliers[f.trivial] - 1.0) < 1e-6)
    # the pitch rows of the Jacobian are those of a free rotation over the stride time
    T = g.stance_time + g.flight_time
    np.testing.assert_allclose(f.jacobian[[1, 4]], [[0, 1, 0, 0, T], [0, 0, 0, 0, 1]],
                               atol=1e-9)
    # the others are the eigenvalues of the Jacobian on (beta, xd, yd)
    red = np.linalg.eigvals(f.jacobian[np.ix_([0, 2, 3], [0, 2, 3])])
    rest = f.multipliers[[k != "pitch" for k in f.trivial_kinds]]
    np.testing.assert_allclose(np.sort(np.abs(red)), np.sort(np.abs(rest)), atol=1e-12)


@pytest.mark.parametrize("controller, reset, decoupled", [
    (tslip.Passive(), "local", True),
    (tslip.ConstantTorque(tau_c=0.1, c_h=0.0), "global", True),
    (tslip.ConstantTorque(tau_c=0.1, c_h=0.0), "local", False),  # beta_TD depends on phi
    (tslip.ConstantTorque(tau_c=0.0, c_h=0.5), "global", False),  # torque on phid
    (tslip.GlobalPD(), "global", False),
    (tslip.LocalVelocity(), "global", False),
])
def test_which_controllers_decouple_the_pitch(controller, reset, decoupled):
    p = dataclasses.replace(tslip.preset("table2.1"), r=0.0, controller=controller,
                            leg_reset=reset)
    assert pitch_decoupled(p) is decoupled
    assert not pitch_decoupled(dataclasses.replace(p, r=1e-9))


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


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 7), seed=st.integers(0, 2**32 - 1), scale=st.sampled_from([1e-3, 1.0, 1e3]))
def test_eigvals_are_numpys(n, seed, scale):
    """The dgeev shortcut gives numpy's eigenvalues, complex pairs included (rotation blocks)."""
    rng = np.random.default_rng(seed)
    A = scale * rng.normal(size=(n, n))
    if n >= 2:  # force a complex pair: a rotation block similar-transformed into A
        B = np.eye(n)
        B[:2, :2] = [[0.3, -0.9], [0.9, 0.3]]
        T = rng.normal(size=(n, n)) + n * np.eye(n)
        A = A * 1e-3 + scale * (T @ B @ np.linalg.inv(T))
    ours = eigvals(A)
    ref = np.linalg.eigvals(A).astype(complex)
    assert ours.dtype == np.complex128 and ours.shape == (n,)
    # the same set either way round (order-free): each one's nearest in the other
    dist = np.abs(ours[:, None] - ref[None, :])
    tol = 1e-10 * np.abs(ref).max() + 1e-12 * scale
    assert dist.min(axis=1).max() <= tol and dist.min(axis=0).max() <= tol


def test_eigvals_refuses_non_finite_like_numpy():
    A = np.eye(3)
    A[1, 2] = np.nan
    with pytest.raises(np.linalg.LinAlgError, match="infs or NaNs"):
        eigvals(A)
    with pytest.raises(np.linalg.LinAlgError, match="infs or NaNs"):
        np.linalg.eigvals(A)
