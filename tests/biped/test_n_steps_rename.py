"""The biped counts strides with ``n_steps``, as the TSLIP does; ``n_strides`` warns until 0.4."""

import numpy as np
import pytest

from tslip.biped import BipedParams, BipedState, simulate
from tslip.biped.gait import Floquet, disturbance_limit, survives_disturbance, to_section

P = BipedParams()


def test_simulate_takes_n_steps_and_the_old_keyword_warns_with_the_same_run():
    new = simulate(P, BipedState.thesis(), n_steps=2)
    with pytest.warns(DeprecationWarning, match=r"n_strides of tslip\.biped\.simulate.*n_steps"):
        old = simulate(P, BipedState.thesis(), n_strides=2)
    assert new.n_steps == old.n_steps == 2
    np.testing.assert_array_equal(new.data, old.data)


def test_giving_both_keywords_is_a_type_error():
    with pytest.raises(TypeError, match="both n_steps and the deprecated n_strides"):
        simulate(P, BipedState.thesis(), n_steps=1, n_strides=1)


def test_the_old_stride_count_property_warns_and_equals_n_steps():
    tr = simulate(P, BipedState.thesis(), 1)
    with pytest.warns(DeprecationWarning, match=r"Trajectory\.n_strides.*Trajectory\.n_steps"):
        assert tr.n_strides == tr.n_steps == 1


def test_survives_disturbance_takes_the_old_keyword_with_a_warning():
    y = BipedState.thesis().to_array()
    z = to_section(P, y, 0.0)
    new = survives_disturbance(P, z, "push", 0.0, n_steps=1)
    with pytest.warns(DeprecationWarning, match="n_strides"):
        old = survives_disturbance(P, z, "push", 0.0, n_strides=1)
    assert new == old == (True, "OK")


def test_disturbance_limit_takes_the_old_keyword_with_a_warning():
    z = to_section(P, BipedState.thesis().to_array(), 0.0)
    with pytest.warns(DeprecationWarning, match="n_strides"):  # reaches the search itself
        with pytest.raises(ValueError, match="unknown disturbance"):
            disturbance_limit(P, z, "shove", n_strides=1)


def test_the_old_largest_multiplier_name_warns_and_equals_max_nontrivial():
    ev = np.linspace(0.5, 0.1, 17).astype(complex)
    f = Floquet(multipliers=ev, trivial=np.zeros(17, bool), max_nontrivial=0.5,
                stability="asymptotic", jacobian=np.diag(ev.real))
    with pytest.warns(DeprecationWarning, match=r"Floquet\.largest.*max_nontrivial"):
        assert f.largest == 0.5
