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

A subprocess minutes apart is a poor baseline on a shared machine whose CPU
speed changes by up to 2x from one minute to the next. :func:`import_at` makes
the old revision's package importable in *this* process under another name
(``tslip_1b54594``, beside the current ``tslip``), and :func:`ab` times old
and new call by call, alternating, so both see the same machine::

    from _baseline import BASELINE_REV, ab, import_at
    old = import_at(BASELINE_REV)
    g_old = old.find_gait(old.preset("table6.1"))
    t = ab({"new": lambda: tslip.floquet(g), "old": lambda: old.floquet(g_old)}, rounds=20)
    print(t.ratio("old", "new"))    # (best-of ratio, median ratio)
"""

from __future__ import annotations

import importlib
import io
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tarfile
import time
import types
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


# ---------------------------------------------------------------------------
# the old revision in this process, and interleaved timing
# ---------------------------------------------------------------------------

#: Absolute references to the package in its sources: ``import tslip``, ``from tslip(.x)
#: import``, and quoted module names (``"tslip"``, ``"tslip.gait.stride"``) that code
#: hashes and loggers read. Docstrings and comments (``:func:`tslip.simulate```) stay.
_ABSOLUTE = re.compile(r"""(\bimport |\bfrom )tslip(?=[.\s])|(?<=["'])tslip(?=[."'])""")


def import_at(rev: str = BASELINE_REV) -> types.ModuleType:
    """The package ``tslip`` of revision ``rev``, imported in this process as ``tslip_<rev>``.

    The sources of :func:`source_at` are copied once into
    ``<cache>/<rev>/pkg/tslip_<rev>/`` (a temporary folder, then a rename) with
    their absolute imports renamed; relative imports need nothing. The copy
    keeps its own numba cache (``__pycache__`` beside its files, or its own
    path under ``NUMBA_CACHE_DIR``), and its kernels' symbols carry its module
    names, so they cannot be served by the current package's (or vice versa).
    """
    src = source_at(rev) / "tslip"
    name = f"tslip_{rev}"
    pkg_root = src.parents[1] / "pkg"
    dest = pkg_root / name
    if not (dest / "__init__.py").exists():
        tmp = pkg_root / f".{name}.tmp{os.getpid()}"
        shutil.rmtree(tmp, ignore_errors=True)
        shutil.copytree(src, tmp, ignore=shutil.ignore_patterns("__pycache__"))
        for f in tmp.rglob("*.py"):
            text = f.read_text(encoding="utf-8")
            f.write_text(_ABSOLUTE.sub(lambda m: (m[1] or "") + name, text), encoding="utf-8")
        try:
            tmp.rename(dest)
        except OSError:  # another process got there first
            shutil.rmtree(tmp, ignore_errors=True)
    if str(pkg_root) not in sys.path:
        sys.path.append(str(pkg_root))  # holds only the copy: shadows nothing
    mod = importlib.import_module(name)
    home = dest.resolve()
    for m in list(sys.modules.values()):  # each package's modules from its own files
        top, file = m.__name__.partition(".")[0], getattr(m, "__file__", None)
        in_copy = file is not None and home in Path(file).resolve().parents
        if top in (name, "tslip") and file and (top == name) != in_copy:
            raise RuntimeError(f"{m.__name__} was imported from {file}")
    return mod


class ABTimes(dict[str, float]):
    """Best seconds per name, from :func:`ab`; ``median`` and ``times`` per name too."""

    def __init__(self, times: dict[str, list[float]]) -> None:
        super().__init__({k: min(v) for k, v in times.items()})
        self.times = {k: tuple(v) for k, v in times.items()}
        self.median = {k: statistics.median(v) for k, v in times.items()}

    def ratio(self, num: str, den: str) -> tuple[float, float]:
        """``num / den`` of the best times and of the medians (old / new: a speed-up)."""
        return self[num] / self[den], self.median[num] / self.median[den]


def ab(fns: dict[str, Callable[[], object]], rounds: int,
       clock: Callable[[], float] = time.perf_counter) -> ABTimes:
    """Time ``fns`` interleaved, call by call: one warm-up call each, then ``rounds`` rounds.

    Round ``i`` calls every function once, in the given order for even ``i``
    and reversed for odd ``i`` (A B, B A, ...), so a slow spell of the machine
    falls on all of them alike and none always runs right after another.
    Returns the best time per function (a ``dict``), with the median as
    ``.median`` (:class:`ABTimes`). ``clock=time.process_time``: CPU seconds.
    """
    if rounds < 1:
        raise ValueError(f"rounds must be >= 1, got {rounds}")
    for fn in fns.values():
        fn()
    order = list(fns)
    times: dict[str, list[float]] = {k: [] for k in order}
    for i in range(rounds):
        for k in order if i % 2 == 0 else reversed(order):
            fn = fns[k]
            t0 = clock()
            fn()
            times[k].append(clock() - t0)
    return ABTimes(times)
