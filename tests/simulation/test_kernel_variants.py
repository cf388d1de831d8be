"""Kernels compiled once per integrator method: distinct names, the right code from the cache.

numba names a compiled function after its ``__qualname__`` plus a counter that
restarts in every process, and of two cached libraries exporting one symbol the
first loaded serves both. So every per-method copy needs its own name, or a
process that loads both methods' kernels from a warm cache runs one method's
code for the other (tslip.simulation._specialise).
"""

import json
import os
import subprocess
import sys

from tslip.simulation import _kernels as kn
from tslip.simulation import _record, _stride, _variational

#: every per-method kernel tuple, by where it lives
_TUPLES = {
    "stride": _stride.STRIDE, "run_row": _stride.RUN_ROW,
    "run_batch": _stride.RUN_BATCH, "run_batch_serial": _stride.RUN_BATCH_SERIAL,
    "stride_batch": _stride.STRIDE_BATCH, "stride_batch_serial": _stride.STRIDE_BATCH_SERIAL,
    "stance_rec": _stride.STANCE_REC, "section_map": _stride.SECTION_MAP,
    "record_run": _record.RECORD_RUN, "jacobian": _variational.STRIDE_JACOBIAN,
}


def test_every_kernel_copy_has_its_own_name():
    names = [k.py_func.__qualname__ for t in _TUPLES.values() for k in t]
    assert len(names) == 2 * len(_TUPLES)
    assert len(set(names)) == len(names), sorted(names)
    for t in _TUPLES.values():
        assert t[0].py_func.__qualname__.endswith("_dopri5")
        assert t[1].py_func.__qualname__.endswith("_dop853")


def test_compiled_symbols_of_the_two_methods_differ():
    """The names numba links by (``fndesc.mangled_name``) differ between the copies."""
    import numpy as np

    import tslip

    p = tslip.preset("table2.1")
    q = np.array([1.05, 0.0, 5.0, -0.3, 0.0])
    for method in ("dopri5", "dop853"):
        options = tslip.IntegratorOptions(method=method)
        tslip.step_map(p, q, options=options)  # the map's kernel, kn.SECTION_MAP
        tslip.step(p, q, options=options)  # the stride kernel, kn.STRIDE
    for kernels, name in ((kn.STRIDE, "stride"), (kn.SECTION_MAP, "section_map")):
        symbols = [next(iter(k.overloads.values())).fndesc.mangled_name for k in kernels]
        assert f"{name}_dopri5" in symbols[0] and f"{name}_dop853" in symbols[1]


_RUN = """
import json, sys, numpy as np, tslip
p = tslip.preset("table2.1")
q = np.array([1.05, 0.0, 5.0, -0.3, 0.0])
out = {}
for m in sys.argv[1].split(","):
    o = tslip.IntegratorOptions(method=m)
    r = tslip.step_map(p, q, options=o)
    s = tslip.step(p, q, options=o)
    out[m] = [*r.q.tolist(), r.stance_time, float(s.n_integrator_steps)]
print(json.dumps(out))
"""


def _run(methods: str, cache: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    proc = subprocess.run([sys.executable, "-c", _RUN, methods], env=env, capture_output=True,
                          text=True, timeout=900, check=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_a_process_loading_both_methods_from_the_cache_runs_each_ones_code(tmp_path):
    """Each method compiled (and cached) in its own process, then both loaded in a third."""
    cache = str(tmp_path / "numba")
    alone = {**_run("dopri5", cache), **_run("dop853", cache)}
    both = _run("dopri5,dop853", cache)
    assert alone["dopri5"] != alone["dop853"]  # the two pairs' strides are told apart
    assert alone["dop853"][-1] * 2 < alone["dopri5"][-1]  # fewer steps for the 8th-order pair
    assert both == alone
