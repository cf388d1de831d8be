"""Stride timing (Section 3.4.3, Table 6.2, Figure 4.11) and no-slip (Appendix C)."""

import dataclasses
import doctest
import math

import numpy as np
import pytest
from matplotlib.figure import Figure

import tslip
import tslip.gait.stride as stride_module
from tslip.gait.impulse import stance_impulse
from tslip.gait.stride import (
    bounce_time,
    fast_running_index,
    friction_ratio,
    predicted_flight_time,
    predicted_stance_time,
    stride_properties,
)
from tslip.plotting.gait import plot_friction


@pytest.fixture(scope="module")
def passive():
    return tslip.find_gait(tslip.preset("table2.1"))


@pytest.fixture(scope="module")
def fit():
    return tslip.find_gait(tslip.preset("table6.1"))


def test_table_6_2_stride_times(fit):
    """Thesis Table 6.2 (TSLIP column) to within the fit's 0.01.

    Measured: t_s 0.5869, t_f 0.1244, duty 0.8252, f 1.4060.
    """
    s = stride_properties(fit)
    assert s.stance_time == pytest.approx(0.58, abs=0.01)
    assert s.flight_time == pytest.approx(0.13, abs=0.01)
    assert s.duty_factor == pytest.approx(0.82, abs=0.01)
    assert s.step_frequency == pytest.approx(1.41, abs=0.01)
    assert s.stride_time == pytest.approx(1.0 / s.step_frequency, rel=1e-12)


def test_fast_running_index_of_the_robot():
    """Section 5.2: 4.4 m/s with l0 = 0.5 m is I_fr = 1.73 (measured 1.7218)."""
    p = tslip.preset("table6.1")
    v0 = 4.4 / math.sqrt(9.81 * 0.5)
    assert fast_running_index(p, v0=v0) == pytest.approx(1.73, abs=0.01)
    # eq. 3.12 is eq. 3.9 over eq. 3.10
    assert fast_running_index(p, v0) == pytest.approx(
        bounce_time(p) / predicted_stance_time(p, v0), rel=1e-14
    )
    assert bounce_time(p) == pytest.approx(math.pi / math.sqrt(8.0), rel=1e-14)


def test_flight_time_eq_3_11(passive, fit):
    """A symmetric ballistic flight lasts 2|ydot|/g: exact for the passive gait."""
    s = stride_properties(passive)
    assert s.flight_time == pytest.approx(s.flight_time_predicted, abs=1e-4)
    assert s.flight_time_small_angle == pytest.approx(s.flight_time_predicted, rel=1e-3)
    # the damped fit lifts off lower than it lands: eq. 3.11 overestimates (0.158 vs 0.124)
    f = stride_properties(fit)
    assert f.flight_time < f.flight_time_predicted - 0.02
    exact, approx = predicted_flight_time(-0.5, 1.0)
    assert exact == 1.0 and math.isnan(approx)
    assert predicted_flight_time(-0.5, 1.0, v0=5.0, delta=-0.1)[1] == pytest.approx(1.0)


def test_stance_time_eq_3_10_holds_for_fast_running_only(passive, fit):
    """I_fr = 3.0 (passive): eq. 3.10 within 5 %; I_fr = 1.65 (fit): off by > 10 %."""
    s, f = stride_properties(passive), stride_properties(fit)
    assert s.fast_running_index > 2 > f.fast_running_index
    assert s.stance_time == pytest.approx(s.stance_time_predicted, rel=0.05)
    assert abs(f.stance_time / f.stance_time_predicted - 1) > 0.10


def test_figure_4_11_trends():
    """Stance time ignores stiffness, falls with speed and steeper legs; flight time
    grows with stiffness and falls with speed and steeper legs (Section 4.3.3)."""
    p = tslip.preset("table2.1")

    def props(**kw):
        return stride_properties(tslip.find_gait(dataclasses.replace(p, **kw)))

    k20, k30 = props(k=20.0), props(k=30.0)
    v4, v6 = props(v0=4.0), props(v0=6.0)
    b10, b11 = props(beta0=1.0), props(beta0=1.1)
    assert k30.stance_time == pytest.approx(k20.stance_time, rel=0.01)  # 0.2001, 0.2011
    assert v6.stance_time < v4.stance_time and b11.stance_time < b10.stance_time
    assert k30.flight_time > k20.flight_time
    assert v6.flight_time < v4.flight_time and b11.flight_time < b10.flight_time
    for s in (k20, k30, v4, v6, b10, b11):  # "match closely" eqs 3.10 and 3.11
        assert s.stance_time == pytest.approx(s.stance_time_predicted, rel=0.05)
        assert s.flight_time == pytest.approx(s.flight_time_predicted, rel=1e-3)


def test_passive_gait_never_slips(passive):
    """Figure C.1 left. Without hip torque F is along the leg: |F_x|/F_y = |cot beta|."""
    c = friction_ratio(passive.params, passive.state)
    assert not c.slips and c.slip_fraction == 0.0 and math.isnan(c.first_slip)
    assert c.max_ratio < 1.0
    imp = stance_impulse(passive.params, passive.state)
    cot = np.abs((imp.hip_x - imp.x) / (imp.hip_y - imp.y))
    ok = c.F_y > 1e-3 * np.max(c.F_y)
    np.testing.assert_allclose(c.ratio[ok], cot[ok], atol=1e-6)
    assert c.max_ratio == pytest.approx(np.max(cot[ok]), abs=1e-6)  # ~cot(1.05) = 0.573


def test_fit_slips_in_the_last_tenth_of_stance(fit):
    """Figure C.1 right: friction exceeded in about the last 10 % (measured 10.1 %)."""
    c = friction_ratio(fit.params, fit.state, mu=1.0)
    assert c.slips
    assert 0.05 < c.slip_fraction < 0.15
    assert c.first_slip > 0.85
    assert c.slip_fraction == pytest.approx(1.0 - c.first_slip, abs=0.01)  # one interval
    # a higher friction coefficient shortens it
    assert friction_ratio(fit.params, fit.state, mu=2.0).slip_fraction < c.slip_fraction
    with pytest.raises(ValueError, match="mu"):
        friction_ratio(fit.params, fit.state, mu=-1.0)


def test_plot_friction(passive, fit):
    checks = [friction_ratio(g.params, g.state) for g in (passive, fit)]
    fig = plot_friction(checks, titles=["Table 2.1", "Table 6.1"])
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    line = fig.axes[0].get_lines()[0]
    np.testing.assert_allclose(line.get_ydata(), np.abs(checks[0].F_x))
    assert len(plot_friction(checks[1]).axes) == 1


def test_docstring_examples():
    result = doctest.testmod(stride_module, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
