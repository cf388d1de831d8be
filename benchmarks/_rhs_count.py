"""Stance right-hand sides a stride spends, counted exactly (``bench_limit.py``, ``bench_rk.py``).

The kernels run as plain Python (``NUMBA_DISABLE_JIT=1``) in a subprocess, and
a profile hook (``sys.setprofile``) counts every call of the code object of
:func:`tslip.simulation._stance.put_rhs`, however the calling module reached it
(``_stepper`` and ``_stride`` bind it by name at import; replacing
``_kernels.rhs``, as ``bench_rk.py`` once did, counts none of those calls). Every
right-hand side runs it once, whichever function asked for it (``rhs``,
``rhs_inline`` in the stage loop, ``rhs_events_inline`` at a step's last stage);
counting ``rhs`` alone missed the stages and counted 2 a stride.
Every call counts: the stages of accepted and rejected steps, the first
``f(y0)``, the initial-step estimate and, for a pair that has them, dense-output
stages.

Run alone, it checks the count against the stance's own step statistics::

    python benchmarks/_rhs_count.py

For dopri5 (seven stages, the first the last one of the step before) a stance
that ends at an event costs ``2 + 6 (accepted + rejected + 1)`` right-hand
sides: ``f(y0)``, one for the initial step, six a step, and six for the exact
step to the event, which the statistics do not count as accepted.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

_SCRIPT = r"""
import json, sys
import tslip
from tslip.simulation import _stance
# the function every right-hand side runs once, in this checkout (older ones: rhs_inline)
code = next(getattr(_stance, n).__code__ for n in ("put_rhs", "rhs_inline", "rhs")
            if hasattr(_stance, n))
calls = [0]

def hook(frame, event, arg):
    if event == "call" and frame.f_code is code:
        calls[0] += 1

g = tslip.find_gait(tslip.preset("table6.1"))
out = {}
for method, tol in CASES:
    o = tslip.IntegratorOptions(rtol=tol, atol=tol, method=method)
    calls[0] = 0
    sys.setprofile(hook)
    try:
        tslip.run_batch(g.params, [g.state], NS, options=o)
    finally:
        sys.setprofile(None)
    out[f"{method} {tol:g}"] = calls[0] / NS
if CHECK:
    import numpy as np
    from tslip.model import _pack as pk
    from tslip.simulation import _kernels as kn
    from tslip.simulation import _packed
    P, O = pk.pack_params(g.params), tslip.IntegratorOptions().packed()
    y0, yout, stats = np.empty(6), np.empty(6), np.empty(5)
    kn.stance_initial(P, _packed.touchdown(g.state.section()), y0)
    rec = np.empty((0, pk.NREC))
    calls[0] = 0
    sys.setprofile(hook)
    try:
        kn.integrate_stance(P, O, y0, yout, rec, 0.0, stats)
    finally:
        sys.setprofile(None)
    out["check"] = [calls[0], int(stats[1]), int(stats[2])]
print(json.dumps(out))
"""


def rhs_per_stride(cases: list[tuple[str, float]], n_strides: int = 1,
                   check: bool = False) -> dict[str, object]:
    """Right-hand sides per stride of the Table 6.1 gait, by ``"method tol"``.

    ``cases``: ``(method, tol)`` pairs (``rtol = atol = tol``), each run for
    ``n_strides`` strides of :func:`tslip.run_batch`. With ``check``, also
    ``"check": [calls, accepted, rejected]`` of the stance alone at the default
    options (dopri5 1e-8).
    """
    code = f"CASES = {cases!r}\nNS = {n_strides}\nCHECK = {check}\n" + _SCRIPT
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    res = rhs_per_stride([("dopri5", 1e-8)], check=True)
    calls, acc, rej = res["check"]  # type: ignore[misc]
    expected = 2 + 6 * (acc + rej + 1)
    print(f"Table 6.1 stride, dopri5 1e-8: {res['dopri5 1e-08']:.0f} right-hand sides; "
          f"its stance alone {calls}, 2 + 6 x ({acc} accepted + {rej} rejected + 1 to the "
          f"event) = {expected}: "
          f"{'agrees' if calls == expected else 'DISAGREES'}")


if __name__ == "__main__":
    main()
