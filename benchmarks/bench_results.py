"""Saving and loading a long run: 1000 strides of Table 6.1 in .parquet, .csv and .json.

Times ``Trajectory.save`` and ``tslip.load`` (best of ``--repeat``, after a
warm-up), prints the size on disk (table plus its ``.json`` record) and checks
that the loaded run is the saved one, bit for bit.

    python benchmarks/bench_results.py [--steps 1000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
from _baseline import best_of


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--repeat", type=int, default=3, help="best of this many runs")
    args = ap.parse_args()
    import tslip

    g = tslip.find_gait(tslip.preset("table6.1"))
    tr = tslip.simulate(g.params, g.state, n_steps=args.steps)
    print(repr(tr))
    with tempfile.TemporaryDirectory() as d:
        for suffix in (".parquet", ".csv", ".json"):
            path = Path(d) / f"run{suffix}"
            t_save = best_of(lambda p=path: tr.save(p), args.repeat)
            t_load = best_of(lambda p=path: tslip.load(p), args.repeat)
            back = tslip.load(path)
            same = (np.array_equal(back.data, tr.data)
                    and [s.state for s in back.steps] == [s.state for s in tr.steps])
            size = sum(f.stat().st_size for f in {path, path.with_suffix(".json")})
            print(f"{suffix:9s} save {t_save:6.3f} s   load {t_load:6.3f} s   "
                  f"{size / 1e6:5.1f} MB   {'identical' if same else 'DIFFERENT'}")


if __name__ == "__main__":
    main()
