"""Biped stride map, search reporting, metacentric test, CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from tslip.biped import BipedParams, BipedState
from tslip.biped.gait import (
    find_periodic_gait,
    from_section,
    metacentric_test,
    stride_map,
    to_section,
)
from tslip.cli import biped as biped_cli  # noqa: F401  (registers `tslip biped`)
from tslip.cli.main import app


def test_section_round_trip_and_stride_map_phase():
    p = BipedParams()
    y = BipedState.thesis().to_array()
    z = to_section(p, y, 0.0)
    y2, t0 = from_section(p, z)
    assert t0 == pytest.approx(0.0)
    np.testing.assert_array_equal(y2[1:], y[1:])
    z1, st = stride_map(p, z)
    assert st.name == "OK"
    assert 0.0 <= z1[-1] < 1.0
    assert z1[-1] != pytest.approx(z[-1], abs=1e-3)  # the Table E.2 stride is not T long


def test_search_that_does_not_converge_reports_best_residual():
    p = BipedParams()
    z = to_section(p, BipedState.thesis().to_array(), 0.0)
    res = find_periodic_gait(p, z, cma_evals=0, lsq_evals=3)
    assert not res.converged
    assert np.isfinite(res.residual) and res.residual > 1e-8
    assert "best residual" in res.message
    assert res.history[-1] <= res.history[0]


def test_metacentric_pitch_changes_keep_the_legs_in_place():
    p = BipedParams()
    out = metacentric_test(p, BipedState.thesis(), pitches=(0.0, 0.5))
    assert [r["dtheta"] for r in out] == [0.0, 0.5]
    for r in out:
        assert r["impulse"][1] > 0.0  # the stance pushes up


def test_cli_simulate_search_report(tmp_path):
    runner = CliRunner()
    r = runner.invoke(app, ["biped", "simulate", "-n", "2", "--out", str(tmp_path / "a.csv")])
    assert r.exit_code == 0, r.output
    assert "2 strides" in r.output and (tmp_path / "a.csv").exists()
    r = runner.invoke(app, ["biped", "search", "--out", str(tmp_path / "g.json"),
                            "--cma-evals", "0", "--lsq-evals", "2", "--no-multipliers"])
    assert r.exit_code == 0, r.output
    data = json.loads((tmp_path / "g.json").read_text())
    assert data["converged"] is False and len(data["z"]) == 18
    r = runner.invoke(app, ["biped", "simulate", "-n", "1", "--gait", str(tmp_path / "g.json")])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["biped", "simulate", "--set", "m_b=-1"])
    assert r.exit_code == 2 and "m_b" in r.output
