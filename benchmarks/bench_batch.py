"""Small batches under load: robustness with a busy second core, default threads vs one.

Run by hand (not in CI): ``python benchmarks/bench_batch.py``. While a
spinning subprocess keeps a second core busy, it times (best of ``--repeat``,
numba cache warm, each configuration in its own interpreter via
``_baseline.run_at``):

* ``robustness_report``: :func:`tslip.robustness_report` on the Table 6.1
  gait (step down, push, pitch rate; sign -1; 25 strides; tolerance 1e-4);
* 1-D sweep: :func:`tslip.robustness` (step down) of the gaits at
  ``--points`` leg stiffnesses around Table 6.1's (gaits found beforehand).

Their batches have 3-8 rows. Each runs with numba's default thread count and
with ``NUMBA_NUM_THREADS=1``, on this checkout and on revision ``1b54594``
(today's code). Target (issue 12, item 4): default threads no slower than one
thread, i.e. ``new default / new 1-thread <= 1``; ``old default / old
1-thread`` shows the spinning it replaces. Wall and CPU seconds (all threads)
are printed; on a loaded machine the CPU seconds are the steadier figure.
"""

from __future__ import annotations

import argparse
import itertools
import os
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from _baseline import BASELINE_REV, run_at  # noqa: E402

SETUP = """
import dataclasses
import numpy as np
import tslip
p = tslip.preset("table6.1")
g = tslip.find_gait(p)
gs = [tslip.find_gait(dataclasses.replace(p, k=k)) for k in p.k * np.linspace(0.9, 1.1, {points})]
"""

WORK = {
    "robustness_report": "tslip.robustness_report(g)",
    "1-D robustness sweep": "[tslip.robustness(gi, 'step_down') for gi in gs]",
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--points", type=int, default=4, help="gaits in the 1-D sweep")
    ap.add_argument("--rev", default=BASELINE_REV, help="baseline revision")
    args = ap.parse_args()
    os.environ.pop("NUMBA_NUM_THREADS", None)  # "default" means numba's own choice
    setup = SETUP.format(points=args.points)
    spinner = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        for (name, stmt), clock in itertools.product(WORK.items(), ("perf_counter",
                                                                     "process_time")):
            t = {(rev, th): run_at(rev, setup, stmt, repeat=args.repeat, threads=th, clock=clock)
                 for rev in (None, args.rev) for th in (None, 1)}
            new_d, new_1, old_d, old_1 = (t[None, None], t[None, 1], t[args.rev, None],
                                          t[args.rev, 1])
            unit = "wall" if clock == "perf_counter" else "CPU"
            print(f"{name} (second core busy), {unit} s: new default {new_d:.3f}, "
                  f"new 1-thread {new_1:.3f}, old default {old_d:.3f}, old 1-thread {old_1:.3f}")
            print(f"  new default / new 1-thread {new_d / new_1:.2f} (target <= 1)   "
                  f"old default / old 1-thread {old_d / old_1:.2f}   "
                  f"new / old: default {new_d / old_d:.2f}, 1-thread {new_1 / old_1:.2f}",
                  flush=True)
    finally:
        spinner.kill()
        spinner.wait()


if __name__ == "__main__":
    main()
