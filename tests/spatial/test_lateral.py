"""The lateral-stability tables' gaits and multipliers: the start is the planar Table 2.1
gait (tslip.find_gait), the gaits land on their mirror images, the trivial multipliers
are 1, and the unstable mode of the uncoupled gait is lateral (roll, vz, roll rate)."""

from __future__ import annotations

import numpy as np

import tslip
from tslip.spatial import TRUNK_MIRROR, TrunkStatus, one_step_map, section
from tslip.spatial.lateral import (
    OPTIONS,
    TABLE21_ALPHA_R,
    TABLE21_SECTION,
    gain_matrix,
    lateral_multipliers,
    markdown,
    table21_gait,
    table21_params,
    two_step_jacobian,
)
from tslip.spatial.trunk import from_planar


def test_the_start_is_the_planar_table21_gait():
    g = tslip.find_gait(tslip.preset("table2.1"), options=OPTIONS)
    assert abs(g.params.alpha_r - TABLE21_ALPHA_R) < 1e-9
    tp = table21_params(splay=0.0)
    np.testing.assert_allclose(section(tp, from_planar(tp, g.state)), TABLE21_SECTION,
                               atol=1e-9)


def test_uncoupled_gait_is_laterally_unstable_in_roll():
    p = table21_params()
    x = table21_gait(p)
    f, st = one_step_map(p, x, options=OPTIONS)
    assert st == TrunkStatus.OK
    np.testing.assert_allclose(f, TRUNK_MIRROR * x, atol=1e-10)
    pt = lateral_multipliers(p, x)
    assert pt.trivial_error < 1e-5 and len(pt.nontrivial) == 7
    assert pt.kind == "real" and 1.5 < pt.largest < 2.0 and not pt.stable
    # its eigenvector: mostly roll (3), vz (6) and roll rate (7)
    ev, vec = np.linalg.eig(two_step_jacobian(p, x, step=1e-5, options=OPTIONS))
    v = np.abs(vec[:, np.argmin(np.abs(ev - pt.nontrivial[0]))])
    assert set(np.argsort(-v)[:3]) == {3, 6, 7}
    assert "| 0.3 | 0.05 | 0 | 0 |" in markdown([pt])
    assert gain_matrix([pt]).splitlines()[2].startswith("| 0 | ")


def test_a_coupling_lowers_the_multiplier():
    base = lateral_multipliers(table21_params(), table21_gait(table21_params()))
    p = table21_params(k_splay=1.0)
    x = table21_gait(p)
    pt = lateral_multipliers(p, x)
    f, _ = one_step_map(p, x, options=OPTIONS)
    np.testing.assert_allclose(f, TRUNK_MIRROR * x, atol=1e-10)
    assert pt.largest < base.largest - 0.3
