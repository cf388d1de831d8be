"""Compile CPU seconds of the biped's stride kernels, this checkout against an older revision.

Run by hand (not in CI): ``python benchmarks/bench_biped_compile.py [--rev 9b67228]
[--rounds 3]``. Each measurement is a fresh interpreter with an empty
``NUMBA_CACHE_DIR``: the CPU seconds of its first stride from the Table E.2
start (``tslip.biped.step``) minus those of a second one, once with each
Runge-Kutta pair (dopri5 first, so dop853's figure excludes the kernels both
share, such as the right-hand side; since one loop serves both pairs, dop853's
is about 0 s where the loop takes the pair at run time), and numba's compile CPU seconds per
function (its callees' compiles excluded). The two revisions alternate, round
by round; printed: each round with the 1-minute load before it, then medians.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from _baseline import run_fresh  # noqa: E402

_SCRIPT = """
import json, resource, time
from collections import defaultdict
from numba.core import event

def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime

stack, per_fn = [], defaultdict(float)

class _Log(event.Listener):
    def on_start(self, e):
        stack.append([time.thread_time(), 0.0])

    def on_end(self, e):
        c0, inner = stack.pop()
        incl = time.thread_time() - c0
        if stack:
            stack[-1][1] += incl
        f = e.data["dispatcher"].py_func
        per_fn[f.__module__.replace("tslip.", "") + "." + f.__qualname__] += incl - inner

event.register("numba:compile", _Log())
from tslip.biped import BipedOptions, BipedParams, BipedState, step
p, y0 = BipedParams(), BipedState.thesis().to_array()
out = {}
for m in ("dopri5", "dop853"):
    o = BipedOptions(method=m)
    c = cpu(); step(p, y0, 0.0, options=o); first = cpu() - c
    c = cpu(); step(p, y0, 0.0, options=o); out[m] = first - (cpu() - c)
out["functions"] = {k: v for k, v in per_fn.items() if v > 0.05}
print(json.dumps(out))
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rev", default="9b67228", help="the older revision")
    ap.add_argument("--rounds", type=int, default=3)
    a = ap.parse_args()
    revs: dict[str, str | None] = {"this checkout": None, a.rev: a.rev}
    rows: dict[str, list[dict]] = {k: [] for k in revs}
    for r in range(a.rounds):
        order = list(revs) if r % 2 == 0 else list(revs)[::-1]
        for name in order:
            with tempfile.TemporaryDirectory() as cache:
                load = os.getloadavg()[0]
                d = json.loads(run_fresh(revs[name], _SCRIPT, {"NUMBA_CACHE_DIR": cache}))
            rows[name].append(d)
            print(f"round {r}  {name:14s} dopri5 {d['dopri5']:6.2f}  dop853 {d['dop853']:6.2f} "
                  f"CPU s  (load {load:.2f})", flush=True)
    for name, rs in rows.items():
        med = {m: statistics.median(d[m] for d in rs) for m in ("dopri5", "dop853")}
        print(f"\n{name}: median dopri5 {med['dopri5']:.2f}, dop853 {med['dop853']:.2f}, "
              f"sum {sum(med.values()):.2f} CPU s; per function (median, callees excluded):")
        fns: dict[str, list[float]] = defaultdict(list)
        for d in rs:
            for k, v in d["functions"].items():
                fns[k].append(v)
        top = sorted(fns.items(), key=lambda kv: -statistics.median(kv[1]))[:8]
        for k, v in top:
            v = v + [0.0] * (len(rs) - len(v))
            print(f"  {k:45s} {statistics.median(v):6.2f}")


if __name__ == "__main__":
    main()
