"""The Table 6.1 stride kernel of two checkouts, timed in alternating bursts.

Run by hand (not in CI)::

    python benchmarks/compare_stride.py /path/to/A /path/to/B --rounds 41

Two long-lived child processes, one with ``PYTHONPATH=<A>/src`` and one with ``<B>/src``
(each with its own numba cache, warmed first), run the compiled stride kernel from the
Table 6.1 gait's touch-down state in bursts of ``--strides`` strides, A and B alternately
(which goes first alternates too). Bursts a few tens of milliseconds apart see the same
machine phase, so the median of the paired ratios B / A is steadier than two whole
benchmark runs a minute apart (``compare_checkouts.py``), whose absolute times move with the
host. Prints each side's median time a stride, the median and quartiles of B / A, and the
1-minute load before and after.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

_CHILD = """
import sys, time
import numpy as np
import tslip
from tslip.model import _pack as pk
from tslip.simulation import _stride
g = tslip.find_gait(tslip.preset("table6.1"))
P = pk.pack_params(g.params)
O = tslip.IntegratorOptions().packed()
td = np.array(list(g.state.as_array()[:5]) + [0.0, 0.0])
tx, th = tslip.Terrain.flat(0.0).arrays()
rec = np.empty((0, pk.NREC))
out = np.empty(pk.NOUT)
# one kernel for both pairs (the pair read from O); a tuple by method code before
kernel = _stride.STRIDE[int(O[pk.O_METHOD])] if hasattr(_stride, "STRIDE") else _stride.stride
assert kernel(P, O, td, tx, th, rec, 0.0, out) == 0
print("ready", flush=True)
for line in sys.stdin:
    n = int(line)
    t0 = time.process_time()
    for _ in range(n):
        kernel(P, O, td, tx, th, rec, 0.0, out)
    print((time.process_time() - t0) / n * 1e6, flush=True)
"""


def _start(src: Path, cache: str) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=str(src / "src"), NUMBA_CACHE_DIR=cache)
    p = subprocess.Popen([sys.executable, "-c", _CHILD], env=env, stdin=subprocess.PIPE,
                         stdout=subprocess.PIPE, text=True)
    assert p.stdout is not None and p.stdout.readline().strip() == "ready"
    return p


def _burst(p: subprocess.Popen, n: int) -> float:
    assert p.stdin is not None and p.stdout is not None
    p.stdin.write(f"{n}\n")
    p.stdin.flush()
    return float(p.stdout.readline())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a", type=Path, help="checkout A (the baseline)")
    ap.add_argument("b", type=Path, help="checkout B")
    ap.add_argument("--rounds", type=int, default=41)
    ap.add_argument("--strides", type=int, default=2000, help="strides a burst")
    ap.add_argument("--caches", nargs=2, metavar=("DIR_A", "DIR_B"),
                    help="numba cache folders to use (default: new, empty ones)")
    args = ap.parse_args()
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as ta_, tempfile.TemporaryDirectory() as tb_:
        ca, cb = args.caches or (ta_, tb_)
        pa, pb = _start(args.a, ca), _start(args.b, cb)
        for p in (pa, pb):
            _burst(p, args.strides)  # warm
        ta, tb, ratio = [], [], []
        for i in range(args.rounds):
            if i % 2:
                b, a = _burst(pb, args.strides), _burst(pa, args.strides)
            else:
                a, b = _burst(pa, args.strides), _burst(pb, args.strides)
            ta.append(a)
            tb.append(b)
            ratio.append(b / a)
            time.sleep(0.01)
        for p in (pa, pb):
            assert p.stdin is not None
            p.stdin.close()
            p.wait()
    q = statistics.quantiles(ratio, n=4)
    print(f"A {args.a}: {statistics.median(ta):.3f} us a stride (median of {args.rounds})")
    print(f"B {args.b}: {statistics.median(tb):.3f} us a stride")
    print(f"B / A: median {statistics.median(ratio):.4f}, quartiles {q[0]:.4f}-{q[2]:.4f}")
    print(f"1-minute load {load0:.2f} before, {os.getloadavg()[0]:.2f} after")


if __name__ == "__main__":
    main()
