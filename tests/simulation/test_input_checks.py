"""The memory estimate behind the size checks, against a measurement."""

from __future__ import annotations

import tracemalloc

import pytest

import tslip
from tslip.gait import find_gait
from tslip.simulation.integrate import trajectory_bytes_per_stride


@pytest.mark.parametrize("name", ["table2.1", "table6.1"])
def test_trajectory_estimate_errs_low_but_not_far(name):
    """Estimated bytes per stride vs tracemalloc's peak: below it, and within a factor 3.

    Below: a refused run could never have fitted. Within 3x: the limit is not
    so loose that a run much larger than memory gets through.
    """
    gait = find_gait(tslip.preset(name))
    assert gait.converged
    n = 100
    tslip.simulate(gait.params, gait.state, 2)  # compile outside the measurement
    tracemalloc.start()
    traj = tslip.simulate(gait.params, gait.state, n, dt=0.01)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert len(traj.steps) == n
    measured = peak / n
    estimate = trajectory_bytes_per_stride(gait.params, 0.01)
    assert measured / 3 < estimate < measured
