"""``bench_limit.py`` on two checkouts, alternated, with the median of each figure.

Run by hand (not in CI)::

    python benchmarks/compare_checkouts.py /work/main . --repeats 3 -- --rounds 11

Each repeat runs ``benchmarks/bench_limit.py`` (this checkout's copy, so both sides
measure the same way) once with ``PYTHONPATH=<A>/src`` and once with ``<B>/src``,
alternating which goes first, each with its own numba cache (``NUMBA_CACHE_DIR``,
warmed by one untimed run). It prints, per figure (the five ratios and the stride
kernel's and RHS's absolute times), the median of each checkout, B / A - 1, and the
1-minute load before each run: the figures of a loaded machine are only comparable
when measured so, side by side.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

_BENCH = Path(__file__).with_name("bench_limit.py")
_FIGURES = {
    "stride kernel (us)": r"stride kernel ([0-9.]+) us",
    "t_rhs (ns)": r"t_rhs ([0-9.]+) ns",
    "stride kernel / RHS-bound limit": r"stride kernel / RHS-bound limit: ([0-9.]+)",
    "simulate / unrecorded strides": r"simulate / unrecorded strides: ([0-9.]+)",
    "simulate + to_dataframe / unrecorded": r"to_dataframe / unrecorded strides: ([0-9.]+)",
    "step_map / stride kernel": r"step_map / stride kernel: ([0-9.]+)",
    "study point / its compiled work": r"study point / its compiled work: ([0-9.]+)",
}


def _run(src: Path, cache: str, args: list[str]) -> dict[str, float]:
    env = dict(os.environ, PYTHONPATH=str(src), NUMBA_CACHE_DIR=cache)
    out = subprocess.run([sys.executable, str(_BENCH), *args], env=env, check=True,
                         capture_output=True, text=True).stdout
    found = {}
    for name, pattern in _FIGURES.items():
        m = re.search(pattern, out)
        if m:
            found[name] = float(m.group(1))
    return found


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a", type=Path, help="checkout A (e.g. main)")
    ap.add_argument("b", type=Path, help="checkout B")
    ap.add_argument("--repeats", type=int, default=3)
    argv = sys.argv[1:]
    cut = argv.index("--") if "--" in argv else len(argv)
    a = ap.parse_args(argv[:cut])
    a.bench_args = argv[cut + 1:]  # after --: arguments of bench_limit.py
    srcs = {"A": a.a.resolve() / "src", "B": a.b.resolve() / "src"}
    with tempfile.TemporaryDirectory() as tmp:
        caches = {k: os.path.join(tmp, k) for k in srcs}
        for k in srcs:  # compile once, untimed
            _run(srcs[k], caches[k], ["--rounds", "1", "--steps", "10", "--maps", "10",
                                      "--reps", "1"])
        res: dict[str, list[dict[str, float]]] = {"A": [], "B": []}
        loads = []
        for i in range(a.repeats):
            for k in ("AB" if i % 2 == 0 else "BA"):
                loads.append(os.getloadavg()[0])
                res[k].append(_run(srcs[k], caches[k], a.bench_args))
                print(f"run {i + 1} {k} (load {loads[-1]:.1f}): {res[k][-1]}", flush=True)
    print(f"A = {srcs['A'].parent}, B = {srcs['B'].parent}; {a.repeats} alternated runs each "
          f"of bench_limit.py {' '.join(a.bench_args)}; 1-min load {min(loads):.1f}-"
          f"{max(loads):.1f}")
    for name in _FIGURES:
        va = [r[name] for r in res["A"] if name in r]
        vb = [r[name] for r in res["B"] if name in r]
        if va and vb:
            ma, mb = statistics.median(va), statistics.median(vb)
            print(f"{name}: A {ma:.4g}, B {mb:.4g}, B/A - 1 = {100 * (mb / ma - 1):+.1f} %")


if __name__ == "__main__":
    main()
