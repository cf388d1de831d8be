"""The TSLIP fixed point as the biped's start (Table E.2, Section E.2.6)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from typer.testing import CliRunner

import tslip
from tslip.biped import BipedParams, BipedState
from tslip.biped.anchor import TSLIP_BASED, tslip_start
from tslip.biped.dynamics import foot_position, hip_position
from tslip.cli import biped as biped_cli  # noqa: F401  (registers `tslip biped`)
from tslip.cli.main import app


@pytest.fixture(scope="module")
def table61():
    g = tslip.find_gait(tslip.preset("table6.1"))
    assert g.converged
    return g


def test_table_e2_plus_entries_follow_from_the_table61_gait(table61):
    """Table E.2 marks x_b, z_b, theta_b, l_tR, l_sR, theta_hR, xd_b, zd_b as based
    on the TSLIP fixed point; ours gives them to the printed 3 decimals."""
    y = tslip_start(table61.state, BipedParams()).to_array()
    thesis = BipedState.thesis().to_array()
    idx = list(TSLIP_BASED)
    np.testing.assert_allclose(y[idx], thesis[idx], atol=5e-4 + 1e-12)
    others = [i for i in range(18) if i not in TSLIP_BASED]
    np.testing.assert_array_equal(y[others], thesis[others])


def test_tslip_geometry_is_kept(table61):
    """Same hip, foot and CoM offset as the TSLIP touch-down (docs/conventions.md)."""
    p = BipedParams()
    s = table61.state
    q = tslip_start(s, p).q
    hip = hip_position(p, q)
    foot = foot_position(p, q, 0)
    assert foot[1] == pytest.approx(0.0, abs=1e-15)  # on the ground
    np.testing.assert_allclose(foot - hip, (math.cos(s.beta), -math.sin(s.beta)), atol=1e-15)
    np.testing.assert_allclose(q[:2] - hip, p.r_1 * np.array([math.sin(s.phi), -math.cos(s.phi)]),
                               atol=1e-15)


def test_bad_state_type():
    with pytest.raises(ValueError, match="TouchdownState"):
        tslip_start(BipedState.thesis(), BipedParams())  # type: ignore[arg-type]


def test_cli_from_tslip(tmp_path):
    r = CliRunner().invoke(app, ["biped", "simulate", "--from-tslip", "table6.1", "-n", "2"])
    assert r.exit_code == 0, r.output
    assert "2 strides" in r.output
    r = CliRunner().invoke(app, ["biped", "simulate", "--from-tslip", "nope"])
    assert r.exit_code == 2 and "preset must be one of" in r.output
    r = CliRunner().invoke(app, ["biped", "simulate", "--from-tslip", "table6.1",
                                 "--gait", str(tmp_path / "g.json")])
    assert r.exit_code == 2 and "at most one" in r.output
