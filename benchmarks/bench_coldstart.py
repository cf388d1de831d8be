"""Cold start: ``import tslip`` and the first stride in a fresh environment.

Run by hand (not in CI): ``python benchmarks/bench_coldstart.py``. Every
number comes from a fresh interpreter:

* import: ``import tslip`` (best of ``--repeat``);
* first stride, cold: ``import tslip``, ``tslip.preset("table2.1")`` and one
  ``tslip.step_map`` (or a one-stride ``tslip.simulate``) with
  ``NUMBA_CACHE_DIR`` pointing to a new empty folder, so every kernel the
  stride needs is compiled (``tslip._kernel_cache`` keeps its source-hash
  marker in that folder too, so it finds nothing to delete);
* first stride, warm: the same again with that folder now filled (loading
  the compiled kernels from disk).

Each is measured on this checkout and on revision ``1b54594`` (today's code,
``_baseline.py``) in the same run, and printed as wall and CPU seconds with the
ratio new/old. On a loaded machine the CPU seconds are the steadier figure.
Targets (issue 12, item 6): import <= 0.3 s, first stride cold <= 3 s.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from _baseline import BASELINE_REV, run_fresh  # noqa: E402

_IMPORT = """
import json, time
t, c = time.perf_counter(), time.process_time()
import tslip
print(json.dumps([time.perf_counter() - t, time.process_time() - c]))
"""

_FIRST = """
import json, time
t0, c0 = time.perf_counter(), time.process_time()
import tslip
p = tslip.preset("table2.1")
s = tslip.TouchdownState(beta=1.05, phi=0.0, xd=5.0, yd=-0.3, phid=0.0)
{stmt}
print(json.dumps([time.perf_counter() - t0, time.process_time() - c0]))
"""

STMTS = {
    "step_map": "tslip.step_map(p, s.section())",
    "simulate": "tslip.simulate(p, s, 1)",
}


def first_stride(rev: str | None, stmt: str, cache: Path) -> tuple[float, float]:
    """(wall, cpu) seconds of import + one stride, with numba's cache in ``cache``."""
    return tuple(json.loads(run_fresh(rev, _FIRST.format(stmt=stmt),
                                      env={"NUMBA_CACHE_DIR": str(cache)})))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="fresh imports (best of)")
    ap.add_argument("--what", default="step_map,simulate", help="first strides to time")
    ap.add_argument("--rev", default=BASELINE_REV, help="baseline revision")
    args = ap.parse_args()
    revs = {"new": None, "old": args.rev}

    print(f"{'':28s}{'new wall':>10s}{'old wall':>10s}{'ratio':>7s}"
          f"{'new cpu':>10s}{'old cpu':>10s}{'ratio':>7s}")

    def row(label: str, new: tuple[float, float], old: tuple[float, float]) -> None:
        print(f"{label:28s}{new[0]:10.3f}{old[0]:10.3f}{new[0] / old[0]:7.2f}"
              f"{new[1]:10.3f}{old[1]:10.3f}{new[1] / old[1]:7.2f}", flush=True)

    imports = {k: min(tuple(json.loads(run_fresh(r, _IMPORT))) for _ in range(args.repeat))
               for k, r in revs.items()}
    row("import tslip", imports["new"], imports["old"])
    for what in args.what.split(","):
        cold, warm = {}, {}
        for k, r in revs.items():
            with tempfile.TemporaryDirectory(prefix="tslip-cold-") as d:
                cold[k] = first_stride(r, STMTS[what], Path(d))
                warm[k] = first_stride(r, STMTS[what], Path(d))
        row(f"first {what}, cold cache", cold["new"], cold["old"])
        row(f"first {what}, warm cache", warm["new"], warm["old"])
    print("targets: import <= 0.3 s, first stride cold <= 3 s (wall, unloaded machine)")


if __name__ == "__main__":
    main()
