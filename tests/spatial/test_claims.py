"""The feedback claim checked by simulation, not by the multipliers: a lateral push on the
symmetric gait grows step after step without feedback and dies out with it; and the
stable-interval reading of a scan."""

from __future__ import annotations

import numpy as np

import tslip
from tslip.spatial import SpatialApex, SpatialParams, apex_steps
from tslip.spatial.claims import main, stable_intervals
from tslip.spatial.gait import floquet, symmetric_gaits

TIGHT = tslip.IntegratorOptions.tight("dop853")


def _lateral_growth(k_lat: float) -> tuple[float, float]:
    """(largest non-trivial |multiplier|, growth of a 1e-4 lateral push over 20 steps)."""
    p = SpatialParams(k=25.0, beta0=1.19, gamma0=0.05, k_lat=k_lat)
    low = symmetric_gaits(p, energy=2.2, options=TIGHT)[0]  # the low, fast gait
    a = low.apex
    pushed = SpatialApex(a.y, a.vx, a.vz + 1e-4, side=1)
    apexes, status = apex_steps(p, pushed, 20, TIGHT)
    assert status.name == "OK" and len(apexes) == 21
    end = apexes[-1]  # a right step again: compare with the gait itself
    dev = np.hypot(end.y - a.y, end.vz - a.vz)
    return floquet(low, "exact", TIGHT).largest, dev / 1e-4


def test_feedback_on_leg_placement_stabilises_the_gait_a_simulation_shows():
    lam0, grow0 = _lateral_growth(0.0)
    lam1, grow1 = _lateral_growth(1.5)
    assert lam0 > 1.0 and grow0 > 10.0  # unstable: 10 periods of |lambda| ~ 1.47
    assert lam1 < 1.0 and grow1 < 0.1  # stable: the push dies out
    # the growth over 10 two-step periods is about the largest multiplier's 10th power
    assert 0.3 < np.log(grow0) / (10 * np.log(lam0)) < 1.3


def test_stable_intervals_are_the_runs_below_one():
    k = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5]
    assert stable_intervals(k, np.array([2.0, 0.9, 0.8, np.nan, 0.5, 1.2])) == \
        [(0.1, 0.2), (0.4, 0.4)]
    assert stable_intervals(k, np.full(6, 1.0)) == []


def test_the_claims_command_runs_on_one_grid_point(tmp_path):
    out = tmp_path / "claims.md"
    assert main(["--small", "--out", str(out)]) == 0
    text = out.read_text()
    assert "Claim 1 under heading=\"fixed\"" in text and "| fixed | 25 | 1.19 | 0.05 | 2 |" in text
