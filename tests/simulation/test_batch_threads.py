"""Small batches run serially in the calling thread; large ones on numba's threads.

Both kernels of a batch must give the same numbers row for row, and a small
batch must not even compile the ``parallel=True`` kernel (no thread pool
started, nothing to spin). No timing here: speed is ``benchmarks/bench_batch.py``.
"""

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import tslip
from tslip.simulation import _kernels as kn
from tslip.simulation import _threads


@pytest.fixture(scope="module")
def gait():
    return tslip.find_gait(tslip.preset("table2.1"))


def _rows(gait, n):
    """``n`` step-down runs from the gait, each on its own terrain."""
    xf = gait.state.x + math.cos(gait.state.beta) - 0.3 * math.sin(gait.state.phi)
    dhs = np.linspace(0.0, -0.4, n)
    return [gait.state] * n, [tslip.Terrain.step(xf, float(dh)) for dh in dhs]


def test_serial_and_parallel_batch_kernels_agree(gait):
    n = _threads.SERIAL_ROWS + 4
    states, terrains = _rows(gait, n)
    Ps, S, TX, TH = tslip.simulation.integrate._batch_inputs(gait.params, states, terrains)
    O = tslip.IntegratorOptions().packed()
    runs = []
    for kernel in (kn.run_batch_serial, kn.run_batch):
        hist = np.full((n, 9, 7), np.nan)
        out = (np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n))
        kernel(Ps, O, S, 8, TX, TH, hist, *out)
        runs.append((hist, *out))
    for a, b in zip(*runs):
        np.testing.assert_array_equal(a, b)
    assert len(set(runs[0][1].tolist())) > 1  # some rows fell, some did not
    steps = []
    for kernel in (kn.stride_batch_serial, kn.stride_batch):
        OUT, st = np.empty((n, tslip.model._pack.NOUT)), np.empty(n, np.int64)
        kernel(Ps, O, S, TX, TH, OUT, st)
        steps.append((OUT, st))
    np.testing.assert_array_equal(steps[0][0], steps[1][0])
    np.testing.assert_array_equal(steps[0][1], steps[1][1])


def test_public_batches_equal_row_by_row_runs_on_both_sides_of_the_threshold(gait):
    for n in (3, _threads.SERIAL_ROWS + 1):
        states, terrains = _rows(gait, n)
        out = tslip.run_batch(gait.params, states, 4, terrain=terrains)
        for i in (0, n - 1):
            one = tslip.run_batch(gait.params, states[i:i + 1], 4, terrain=terrains[i:i + 1])
            np.testing.assert_array_equal(out.touchdowns[i], one.touchdowns[0])
            assert out.status[i] == one.status[0]


def test_choice_of_kernel():
    assert _threads.choose("s", "p", _threads.SERIAL_ROWS - 1) == "s"
    import numba

    n = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        assert _threads.choose("s", "p", 10 * _threads.SERIAL_ROWS) == "s"
    finally:
        numba.set_num_threads(n)
    if n > 1:
        assert _threads.choose("s", "p", _threads.SERIAL_ROWS) == "p"
    assert os.environ.get("OMP_WAIT_POLICY")  # set before the pool could start


_SMALL_BATCH = """
import json, numpy as np, tslip
from tslip.simulation import _kernels as kn
p = tslip.preset("table2.1")
q = np.array([[1.05, 0.0, 5.0, -0.3, 0.0]] * 3)
tslip.step_batch(p, q)
tslip.run_batch(p, q, 2)
print(json.dumps([len(kn.stride_batch.signatures), len(kn.run_batch.signatures),
                  len(kn.stride_batch_serial.signatures)]))
"""


def test_a_small_batch_never_compiles_the_parallel_kernels():
    out = subprocess.run([sys.executable, "-c", _SMALL_BATCH], capture_output=True, text=True,
                         check=True)
    assert json.loads(out.stdout.strip().splitlines()[-1]) == [0, 0, 1]
