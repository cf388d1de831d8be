"""The 3-D Table 2.1 TSLIP preset: Table 2.1 in every planar field, the two new inertias
equal to J, a small outward splay, no roll coupling; and the exports of tslip.spatial."""

from __future__ import annotations

import dataclasses
import math

import pytest

import tslip
import tslip.spatial as sp
from tslip.spatial import TrunkParams, preset, preset_description, presets


def test_table21_3d_is_table21_in_its_planar_fields():
    p3 = preset("table2.1-3d")
    assert isinstance(p3, TrunkParams)
    planar = tslip.preset("table2.1")
    shared = [f.name for f in dataclasses.fields(planar) if hasattr(p3, f.name)]
    # every planar field but the nominal touch-down (v0, beta0: a gait, not a parameter)
    assert set(f.name for f in dataclasses.fields(planar)) - set(shared) == {"v0", "beta0"}
    for name in shared:
        assert getattr(p3, name) == getattr(planar, name), name
    # thesis Table 2.1 itself, independent of the planar preset's code
    assert (p3.m, p3.J, p3.r, p3.k, p3.omega_r, p3.alpha_r) == (1.0, 0.1, 0.3, 25.0, 1.0, 1.0)
    assert p3.J_roll == p3.J_yaw == p3.J
    assert 0.0 < p3.splay <= 0.1 and p3.k_splay == p3.k_trail == 0.0
    assert p3.leg_reset == "local"


def test_presets_list_and_describe_both_parts():
    assert {"slip3d", "slip3d-feedback", "table2.1-3d"} <= set(presets())
    assert "J_roll = J_yaw = J" in preset_description("table2.1-3d")
    assert isinstance(preset(" Table2.1-3D "), TrunkParams)
    assert not isinstance(preset("slip3d"), TrunkParams)
    with pytest.raises(ValueError, match="preset must be one of"):
        preset("table2.1")


def test_part2_is_exported_and_all_names_resolve():
    for name in ("TrunkParams", "trunk_step", "TrunkStatus", "TrunkTouchdown", "TrunkStep",
                 "symmetric_gait", "two_step_jacobian", "TRUNK_SECTION_NAMES"):
        assert name in sp.__all__
    assert all(hasattr(sp, n) for n in sp.__all__)
    assert len(set(sp.__all__)) == len(sp.__all__)
    assert len(sp.TRUNK_SECTION_NAMES) == 10 and len(sp.SECTION_NAMES) != 10
    assert math.isclose(float(sp.TRUNK_MIRROR @ sp.TRUNK_MIRROR), 10.0)
