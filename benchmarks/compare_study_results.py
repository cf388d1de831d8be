"""Whether two checkouts compute the same study results, value for value, bit for bit.

Run by hand (not in CI)::

    python benchmarks/compare_study_results.py /work/main . [--study grid_v3] [--grid 25]

Runs the catalogue study (quick, ``--grid`` points per axis; 0 keeps its quick
resolution) serially with each checkout's sources (``PYTHONPATH=<checkout>/src``, in a
fresh folder each) and compares the two ``results.parquet`` tables: the same columns
and, in every column but ``seconds`` (timing), the same values, floats by their bits
(NaN payloads included). Prints one line per study; exits 1 if any differs. For a
change meant to be a pure speed-up (issue 41).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

_RUN = """
import sys
from pathlib import Path
from tslip.sweeps.catalogue import study
from tslip.sweeps.run import run_study
spec = study(sys.argv[1], quick=True)
n = int(sys.argv[2])
if n:
    spec = spec.with_resolution([n] * len(spec.axes))
run_study(spec, Path(sys.argv[3]), workers=1)
"""


def _results(checkout: Path, name: str, grid: int, tmp: Path) -> pd.DataFrame:
    out = tmp / f"{checkout.resolve().name}-{name}"
    env = {**os.environ, "PYTHONPATH": str(checkout.resolve() / "src")}
    subprocess.run([sys.executable, "-c", _RUN, name, str(grid), str(out)], env=env, check=True)
    return pd.read_parquet(out / "results.parquet")


def differences(a: pd.DataFrame, b: pd.DataFrame) -> list[str]:
    """What differs between two results tables (empty: identical but for ``seconds``)."""
    if list(a.columns) != list(b.columns) or a.shape != b.shape:
        return [f"columns or shape: {list(a.columns)} {a.shape} vs {list(b.columns)} {b.shape}"]
    bad = []
    for col in a.columns.drop("seconds", errors="ignore"):
        x, y = a[col].to_numpy(), b[col].to_numpy()
        if x.dtype.kind == "f" and y.dtype.kind == "f":
            same = x.view(np.uint64) == y.view(np.uint64)
        else:
            same = np.array([u == v for u, v in zip(x, y, strict=True)], dtype=bool)
        if not same.all():
            bad.append(f"{col}: {int((~same).sum())} of {len(same)} rows")
    return bad


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a", type=Path)
    ap.add_argument("b", type=Path)
    ap.add_argument("--study", action="append", help="catalogue study (repeatable; grid_v3)")
    ap.add_argument("--grid", type=int, default=25, help="points per axis (0: quick's own)")
    args = ap.parse_args()
    failed = False
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.study or ["grid_v3"]:
            a, b = (_results(c, name, args.grid, Path(tmp)) for c in (args.a, args.b))
            bad = differences(a, b)
            failed |= bool(bad)
            print(f"{name} ({len(a)} points): " + ("identical" if not bad else "; ".join(bad)))
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
