"""Periodic gaits against the thesis's reported numbers and the map itself."""

import math

import numpy as np
import pytest

import tslip


@pytest.fixture(scope="module")
def fit():
    return tslip.find_gait(tslip.preset("table6.1"))


@pytest.mark.parametrize(
    "name", ["table2.1", "table2.1-local-velocity", "table2.1-constant-torque", "table6.1"]
)
def test_gait_is_a_fixed_point_of_the_map(name):
    g = tslip.find_gait(tslip.preset(name))
    assert g.converged and g.residual < 1e-10
    m = tslip.step_map(g.params, g.state.section(), options=tslip.IntegratorOptions.tight())
    np.testing.assert_allclose(m.q, g.state.section(), atol=1e-9)
    assert g.state.beta == g.params.beta0
    assert g.state.v == pytest.approx(g.params.v0, abs=1e-12)


def test_table_6_2_stride_times(fit):
    """Thesis Table 6.2 (TSLIP column), which the fit matched to within 0.01."""
    ts, tf = fit.stance_time, fit.flight_time
    assert ts == pytest.approx(0.58, abs=0.01)
    assert tf == pytest.approx(0.13, abs=0.01)
    assert ts / (ts + tf) == pytest.approx(0.82, abs=0.01)  # duty factor
    assert 1 / (ts + tf) == pytest.approx(1.41, abs=0.01)  # step frequency


def test_table_e2_initial_conditions_from_the_tslip_fixed_point(fit):
    """Table E.2's entries marked 'based on a fixed point from the TSLIP model'.

    The biped's body pitch theta_b is measured the other way round (-0.290).
    """
    s = fit.state
    y = s.h + fit.params.l0 * math.sin(s.beta) - fit.params.r * math.cos(s.phi)
    assert s.xd == pytest.approx(1.898, abs=1e-3)
    assert s.yd == pytest.approx(-0.079, abs=1e-3)
    assert s.phi == pytest.approx(0.290, abs=1e-3)
    assert y == pytest.approx(0.514, abs=1e-3)


def test_global_pd_reports_best_residual_instead_of_converging():
    g = tslip.find_gait(tslip.preset("table2.1-global-pd"))
    assert not g.converged
    assert "global PD" in g.message and g.residual > 1e-10
    assert g.residual < 1e-2  # close to periodic, as the thesis's C1 < 1e-4 criterion


def test_overrides_and_bad_guess():
    g = tslip.find_gait(tslip.preset("table2.1"), v0=4.0, beta0=1.1)
    assert g.converged and g.params.v0 == 4.0 and g.state.beta == 1.1
    with pytest.raises(ValueError, match="guess must have 4 entries"):
        tslip.find_gait(tslip.preset("table2.1"), guess=np.zeros(3))


@pytest.mark.parametrize("preset", ["slip", "slip-human"])
def test_the_old_full_guess_at_r0_warns_and_finds_the_same_gait(preset):
    """At r = 0 the pitch is held (docs/conventions.md, 'Held pitch'): the guess is
    (delta, alpha_r). The form before 0.4, (delta, phi, phid, alpha_r), still works for
    one release, naming the new form in a DeprecationWarning."""
    p = tslip.preset(preset)
    g = tslip.find_gait(p)
    assert g.converged
    new = np.array([g.state.delta, g.params.alpha_r]) + [0.01, -0.01]
    old = np.array([new[0], 0.0, 0.0, new[1]])
    with pytest.warns(DeprecationWarning, match=r"at r = 0 the guess is \(delta, alpha_r\); "
                      r"phi and phid are held \(docs/conventions.md, 'Held pitch'\)"):
        from_old = tslip.find_gait(p, guess=old)
    from_new = tslip.find_gait(p, guess=new)
    assert from_old.converged and from_new.converged
    assert from_old.state == from_new.state and from_old.params == from_new.params
    assert from_new.state.delta == pytest.approx(g.state.delta, abs=1e-9)
    # neither form is the wrong length: a 3-entry guess is still refused, in one line
    with pytest.raises(ValueError, match=r"guess must have 2 entries \['delta', 'alpha_r'\]"):
        tslip.find_gait(p, guess=old[:3])
