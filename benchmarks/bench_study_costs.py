"""Measured against estimated cost of every catalogue study, for the scheduler's estimates.

Run by hand (not in CI): ``python benchmarks/bench_study_costs.py [--quick] [STUDY ...]``.
Each study runs from scratch in this process (``workers=1``, no cache) with a
warm numba cache; printed per study: points, analyses, CPU seconds, the
estimate :class:`tslip.sweeps.run.StudyJob` makes before it starts (from
:data:`tslip.sweeps.run.COST_SECONDS`) and their ratio, and the worker count
:func:`tslip.sweeps._schedule.choose_workers` picks from that estimate. The
estimates choose serial or parallel runs (against
:data:`tslip.sweeps._schedule.STARTUP_SECONDS`), order the tasks and size the
analysis chunks; they need to be right within a factor of about 2, not exact.
"""

from __future__ import annotations

import argparse
import time

from tslip.sweeps._schedule import choose_workers
from tslip.sweeps.catalogue import STUDIES, study
from tslip.sweeps.run import StudyJob, run_study


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("studies", nargs="*", help="catalogue names (default: all)")
    ap.add_argument("--quick", action="store_true", help="the quick resolution")
    a = ap.parse_args()
    names = a.studies or list(STUDIES)
    print(f"{'study':<28}{'points':>7}  {'analyses':<22}{'cpu [s]':>8}{'est [s]':>9}"
          f"{'est/cpu':>9}{'workers':>8}")
    total = total_est = 0.0
    for name in names:
        spec = study(name, quick=a.quick)
        est = StudyJob(spec, None).cost
        t0 = time.process_time()
        run_study(spec, None, workers=1)
        cpu = time.process_time() - t0
        total, total_est = total + cpu, total_est + est
        print(f"{name:<28}{spec.n_points:>7}  {','.join(sorted(set(spec.analyses))):<22}"
              f"{cpu:>8.2f}{est:>9.2f}{est / cpu:>9.2f}{choose_workers(est):>8}")
    print(f"{'all':<28}{'':>7}  {'':<22}{total:>8.2f}{total_est:>9.2f}{total_est / total:>9.2f}")


if __name__ == "__main__":
    main()
