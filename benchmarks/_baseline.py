"""Time the same workload on an earlier revision of tslip, in the same run.

A benchmark prints its speed as a ratio against a baseline measured in the
same invocation, because the machines here are shared and noisy. When the
baseline is "the code as it was before a change", this module extracts that
revision's ``src/`` (``git archive``, no change to the repository's state) into
``~/.cache/tslip-bench/<rev>/`` and runs a snippet against it in a subprocess,
so the old and new code are timed minutes apart on the same machine.

Usage::

    from _baseline import run_at
    t = run_at(BASELINE_REV, setup="import tslip; p = tslip.presets.table_6_1()",
               stmt="tslip.simulate(p, ...)", repeat=5)   # best of 5, in seconds

The snippet runs with numba's cache warm (a first untimed call is made), on
the same number of threads as the caller unless ``threads`` is given.
``rev=None`` means this checkout's ``src``. :func:`run_fresh` runs a script in
a fresh interpreter instead (cold starts: pass ``NUMBA_CACHE_DIR`` in ``env``).
"""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import tarfile
import time
from collections.abc import Callable
from pathlib import Path

#: The revision every benchmark of issue 12 compares with: main before that work.
BASELINE_REV = "1b54594"

_REPO = Path(__file__).resolve().parents[1]
_CACHE = Path(os.environ.get("TSLIP_BENCH_CACHE", Path.home() / ".cache" / "tslip-bench"))

_RUNNER = r"""
import json, sys, time
setup, stmt, repeat, number, clock = json.loads(sys.argv[1])
clock = getattr(time, clock)
ns = {}
exec(setup, ns)
stmt = compile(stmt, "<stmt>", "exec")
exec(stmt, ns)  # warm: compile or load the numba cache
best = float("inf")
for _ in range(repeat):
    t0 = clock()
    for _ in range(number):
        exec(stmt, ns)
    best = min(best, (clock() - t0) / number)
print(json.dumps(best))
"""


def best_of(fn: Callable[[], object], repeat: int = 5,
            clock: Callable[[], float] = time.perf_counter) -> float:
    """Best of ``repeat`` timed calls of ``fn`` [s], after one untimed (warm-up) call.

    ``clock=time.process_time`` counts CPU seconds, steadier than wall time on a
    shared machine (time slices lost to other processes do not count).
    """
    fn()
    best = float("inf")
    for _ in range(repeat):
        t0 = clock()
        fn()
        best = min(best, clock() - t0)
    return best


def source_at(rev: str | None = BASELINE_REV) -> Path:
    """The ``src`` folder of ``rev``, extracted once into the benchmark cache (None: this one)."""
    if rev is None:
        return _REPO / "src"
    full = subprocess.run(["git", "-C", str(_REPO), "rev-parse", rev], check=True,
                          capture_output=True, text=True).stdout.strip()
    dest = _CACHE / full[:12]
    src = dest / "src"
    if not (src / "tslip" / "__init__.py").exists():
        data = subprocess.run(["git", "-C", str(_REPO), "archive", full, "src"], check=True,
                              capture_output=True).stdout
        tmp = dest.with_name(dest.name + f".tmp{os.getpid()}")
        with tarfile.open(fileobj=io.BytesIO(data)) as tar:
            tar.extractall(tmp, filter="data")
        tmp.replace(dest) if not dest.exists() else None
    return src


def run_at(rev: str | None, setup: str, stmt: str, repeat: int = 5, number: int = 1,
           threads: int | None = None, clock: str = "perf_counter") -> float:
    """Best-of-``repeat`` seconds per execution of ``stmt`` on revision ``rev``.

    ``clock`` names the :mod:`time` function: ``"process_time"`` counts the CPU
    seconds of all the process's threads (spinning ones included).
    """
    env = dict(os.environ, PYTHONPATH=str(source_at(rev)))
    if threads is not None:
        env["NUMBA_NUM_THREADS"] = str(threads)
    args = json.dumps([setup, stmt, repeat, number, clock])
    out = subprocess.run([sys.executable, "-c", _RUNNER, args], capture_output=True, text=True,
                         env=env)
    if out.returncode != 0:
        raise RuntimeError(f"baseline {rev} failed:\n{out.stderr[-2000:]}")
    return float(out.stdout.strip().splitlines()[-1])


def run_fresh(rev: str | None, script: str, env: dict[str, str] | None = None) -> str:
    """The last line ``script`` prints, run by a fresh interpreter on revision ``rev``.

    ``env`` adds to the environment (e.g. ``NUMBA_CACHE_DIR`` for a cold start).
    """
    full_env = dict(os.environ, PYTHONPATH=str(source_at(rev)), **(env or {}))
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         env=full_env)
    if out.returncode != 0:
        raise RuntimeError(f"script on {rev or 'this checkout'} failed:\n{out.stderr[-2000:]}")
    return out.stdout.strip().splitlines()[-1]
