"""One stride kernel for both integrator methods, and its copies' names.

The Runge-Kutta pair is a run-time argument (``O[O_METHOD]``): a kernel compiles once
for both. The stride's loop is still built twice by one factory (the stride, and the
stance alone for the tests), and numba names a compiled function after its
``__qualname__`` plus a counter that restarts in every process, and of two cached
libraries exporting one symbol the first loaded serves both: so each copy needs its
own name, or a process that loads both from a warm cache runs one copy's code for the
other (tslip.simulation._stride._make_stride).
"""

import json
import subprocess
import sys

from tslip.simulation import _kernels as kn
from tslip.simulation import _stride


def test_each_copy_of_the_stride_loop_has_its_own_name():
    names = [k.py_func.__qualname__ for k in (_stride.stride, _stride.stance_rec)]
    assert names == ["stride", "stance_rec"]


def test_both_methods_run_one_compiled_kernel():
    """The map's and the stride's kernels compile once whichever pair they are given."""
    import numpy as np

    import tslip

    p = tslip.preset("table2.1")
    q = np.array([1.05, 0.0, 5.0, -0.3, 0.0])
    for method in ("dopri5", "dop853"):
        options = tslip.IntegratorOptions(method=method)
        tslip.step_map(p, q, options=options)  # the map's kernel, kn.section_map
        tslip.step(p, q, options=options)  # the stride kernel, kn.stride
    for kernel in (kn.stride, kn.section_map):
        assert len(kernel.overloads) == 1, kernel.signatures


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


def _run(methods: str) -> dict:
    proc = subprocess.run([sys.executable, "-c", _RUN, methods], capture_output=True,
                          text=True, timeout=900, check=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_a_process_loading_both_methods_from_the_cache_runs_each_ones_code():
    """Each method run in its own process, then both in a third, every kernel loaded from
    numba's cache (the suite's: the one kernel serves both methods, so a cold cache of its
    own, 20 s of compiling, would test nothing more; the first process compiles it if the
    suite has not)."""
    alone = {**_run("dopri5"), **_run("dop853")}
    both = _run("dopri5,dop853")
    assert alone["dopri5"] != alone["dop853"]  # the two pairs' strides are told apart
    assert alone["dop853"][-1] * 2 < alone["dopri5"][-1]  # fewer steps for the 8th-order pair
    assert both == alone
