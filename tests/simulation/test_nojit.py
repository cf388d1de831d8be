"""The kernels also run as plain Python (NUMBA_DISABLE_JIT=1), with the same result."""

import json
import os
import subprocess
import sys

import numpy as np

import tslip

SCRIPT = """
import json, tslip
g = tslip.find_gait(tslip.preset("table6.1"))
r = tslip.step_map(g.params, g.state.section())
b = tslip.run_batch(g.params, [g.state], 2)
print(json.dumps({"q": list(r.q), "ts": r.stance_time, "tf": r.flight_time,
                  "batch": list(b.touchdowns[0, -1]), "alpha_r": g.params.alpha_r}))
"""


def test_pure_python_kernels_agree_with_compiled():
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    proc = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                          text=True, timeout=600, check=True)
    pure = json.loads(proc.stdout.strip().splitlines()[-1])
    g = tslip.find_gait(tslip.preset("table6.1"))
    r = tslip.step_map(g.params, g.state.section())
    b = tslip.run_batch(g.params, [g.state], 2)
    assert pure["alpha_r"] == g.params.alpha_r or abs(pure["alpha_r"] - g.params.alpha_r) < 1e-12
    np.testing.assert_allclose(pure["q"], r.q, rtol=0, atol=1e-12)
    np.testing.assert_allclose([pure["ts"], pure["tf"]], [r.stance_time, r.flight_time],
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(pure["batch"], b.touchdowns[0, -1], rtol=0, atol=1e-12)
