"""Newton refinement of the stride map, disturbances, and the kernels without numba."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from tslip.biped import BipedParams, BipedState
from tslip.biped.gait import (
    REFINE_OPTIONS,
    _wrap,
    floquet,
    refine_periodic_gait,
    section_multipliers,
    step_map,
    survives_disturbance,
    to_section,
)
from tslip.biped.simulate import simulate
from tslip.biped.stored import gait_path


def test_refine_reduces_the_residual_and_reports_non_convergence():
    p = BipedParams()
    z = to_section(p, BipedState.thesis().to_array(), 0.0)
    res = refine_periodic_gait(p, z, max_iter=2, multipliers=False)
    assert not res.converged and "best residual" in res.message
    assert res.history[-1] < 0.6 * res.history[0]
    assert np.all(np.isfinite(res.z))
    with pytest.raises(ValueError, match="unknown free parameter"):
        refine_periodic_gait(p, z, free_params=("nope",))


def test_stored_converged_gait_is_periodic_and_stable():
    """The gait found by refine_periodic_gait from Table E.2 (see the report)."""
    with open(str(gait_path("converged-e2"))) as fh:
        data = json.load(fh)
    p = BipedParams.from_dict(data["params"])
    z = np.array(data["z"])
    z1, st = step_map(p, z, REFINE_OPTIONS)
    assert st.name == "OK"
    assert np.linalg.norm(_wrap(z1 - z)) < 1e-8
    fr = floquet(p, z)  # central differences on the section, step 1e-5
    assert fr.residual < 1e-8 and fr.multipliers.shape == (17,)
    assert 0.5 < fr.max_nontrivial < 1.0
    # a second step size (10x) and a forward-difference check agree to 1e-4
    for ev in (section_multipliers(p, z, fd_step=1e-4),
               section_multipliers(p, z, fd_step=1e-5, central=False)):
        assert abs(np.abs(ev[0]) - fr.max_nontrivial) < 1e-4
        lead = ev[np.abs(ev) > np.abs(ev[0]) - 1e-3]  # the leading (complex pair) multipliers
        for m in fr.multipliers[:lead.size]:
            assert np.min(np.abs(lead - m)) < 1e-4


def test_floquet_stays_on_the_section():
    """Perturbing z_b off the section gave 0.649 at the stored gait; on it, 0.788."""
    with open(str(gait_path("converged-e2"))) as fh:
        data = json.load(fh)
    p = BipedParams.from_dict(data["params"])
    z = np.array(data["z"])
    z_off = z.copy()
    z_off[0] += 1e-3  # off the section: floquet puts it back first
    fr = floquet(p, z_off, eps=1e-4)
    assert fr.z[0] == pytest.approx(z[0], abs=1e-9)
    # regression pin (this package's value at the stored gait; no independent source:
    # the thesis prints no multiplier for it). The section check above is the point.
    assert fr.max_nontrivial == pytest.approx(0.788, abs=2e-3)


def test_disturbance_kinds():
    p = BipedParams()
    z = to_section(p, BipedState.thesis().to_array(), 0.0)
    ok, status = survives_disturbance(p, z, "push", 0.0, n_steps=1)
    assert ok and status == "OK"
    with pytest.raises(ValueError, match="unknown disturbance"):
        survives_disturbance(p, z, "kick", 0.1)


_SCRIPT = """
import json, sys
import numpy as np
from tslip.biped import BipedParams, BipedState
from tslip.biped.simulate import simulate
tr = simulate(BipedParams(), BipedState.thesis(), 1, t_end=0.03)
print(json.dumps({"y": tr.final_state.tolist(), "status": tr.status.name,
                  "acc": tr.stats["accepted"]}))
"""


def test_kernels_run_without_jit_and_match_compiled():
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-c", _SCRIPT], env=env, capture_output=True,
                         text=True, timeout=120, check=True)
    got = json.loads(out.stdout.strip().splitlines()[-1])
    tr = simulate(BipedParams(), BipedState.thesis(), 1, t_end=0.03)
    assert got["status"] == tr.status.name == "T_END"
    assert got["acc"] == tr.stats["accepted"]
    np.testing.assert_allclose(got["y"], tr.final_state, rtol=0, atol=1e-12)
