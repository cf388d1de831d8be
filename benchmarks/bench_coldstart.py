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

``--first-run`` measures a new user's first run instead (issue 24): a fresh
``git clone`` of this checkout (its committed HEAD), the README's install
command in a fresh venv (with ``--reuse-venv PATH``: that venv, the clone's
``src`` on ``PYTHONPATH``, no install), then the first ``tslip reproduce
--quick`` with ``NUMBA_CACHE_DIR`` unset (numba caches next to the installed
sources) and an empty ``XDG_CACHE_HOME`` (nothing in the user's cache folders).
It prints the install time, the reproduction's wall and CPU seconds (every
process: this one adopts orphaned descendants as a sub-reaper and reaps them),
the time to its first line and the 1-minute load before it, then runs it again
warm and checks that ``claims.json`` and every study's ``results.parquet``
(but its ``seconds`` column) are equal. ``--compile-log`` also records numba's
compile events in every process of the cold run (a ``sitecustomize`` on
``PYTHONPATH``) and prints the compile CPU seconds per process, per kernel
family and per top-level kernel, and any signature compiled in two processes.
``--against REV`` then does the same for a clone checked out at ``REV``, right
after, and prints the ratios this checkout / REV of the cold run's wall, CPU
and (with ``--compile-log``) compile CPU seconds: issue 41's compile target is
``--first-run --compile-log --against 07e68e4`` (the revision before one
compiled loop per model) at a ratio <= 0.75.

``--warm`` measures warm runs instead (issue 25: quick within 4 s, full within
8 s, first line within 5 s): ``tslip reproduce --quick --workers 2`` of this
checkout and of ``--warm-rev`` (default ``ae943bb``, main before the warm-run
work; ``--baseline-src PATH`` takes a source folder instead), kernels compiled
by a first untimed run of each, then ``--rounds`` interleaved rounds (the order
alternating) of a run into a new folder and a rerun into the same folder (every
study, Appendix E and, on this checkout, every figure cached). It prints the
median wall and CPU seconds (every process), the time to the first line and the
1-minute load, each with the ratio new/old, and whether the claims and study
columns of both revisions are equal. ``--full`` adds the full resolution: one
run into a new folder, then ``--rounds`` reruns into it.
"""

from __future__ import annotations

import argparse
import ctypes
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
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


# ---------------------------------------------------------------------------
# --first-run: a new user's install and first reproduction (issue 24)
# ---------------------------------------------------------------------------

ROOT = Path(__file__).resolve().parents[1]

#: Installed as ``sitecustomize`` (``--compile-log``): every process of the run,
#: the fork server and its workers included, appends one JSON line per numba
#: compile with the thread CPU seconds it took, its callees' compiles excluded.
_RECORDER = """
import json, os, threading, time
from numba.core import event

_local = threading.local()


class _Log(event.Listener):
    def on_start(self, e):
        if not hasattr(_local, "stack"):
            _local.stack = []
        _local.stack.append([time.thread_time(), 0.0, time.time()])

    def on_end(self, e):
        c0, inner, t0 = _local.stack.pop()
        incl = time.thread_time() - c0
        if _local.stack:
            _local.stack[-1][1] += incl
        d = e.data["dispatcher"]
        rec = {"pid": os.getpid(), "thread": threading.current_thread().name,
               "fn": d.py_func.__module__ + "." + d.py_func.__qualname__,
               "args": str(e.data["args"]), "cpu": incl - inner, "incl": incl,
               "depth": len(_local.stack), "t0": t0, "t": time.time()}
        with open(os.environ["TSLIP_BENCH_COMPILE_LOG"], "a") as f:
            f.write(json.dumps(rec) + "\\n")


event.register("numba:compile", _Log())
"""


def readme_install() -> str:
    """The README's install command: its Quickstart line before ``&& tslip reproduce``."""
    for line in (ROOT / "README.md").read_text(encoding="utf-8").splitlines():
        if "tslip reproduce --quick" in line and "pip install" in line:
            return line.split("&&")[0].strip()
    raise SystemExit("README.md has no 'pip install ... && tslip reproduce --quick' line")


def _subreaper() -> None:
    """Adopt orphaned descendants (the fork server outlives ``tslip``) so their CPU counts."""
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None, use_errno=True).prctl(36, 1, 0, 0, 0)  # PR_SET_CHILD_SUBREAPER


def _reap() -> None:
    while True:
        try:
            os.waitpid(-1, 0)
        except ChildProcessError:
            return


def timed_run(cmd: list[str], env: dict[str, str], cwd: Path, log: Path,
              ) -> dict[str, float]:
    """Wall, CPU (all descendants) and first-line seconds of ``cmd``; its output to ``log``."""
    import resource

    _reap()
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    first = float("nan")
    start = time.time()
    with log.open("w") as out:
        p = subprocess.Popen(cmd, env=env, cwd=cwd, stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, text=True)
        assert p.stdout is not None
        for line in p.stdout:
            t = time.perf_counter() - t0
            if first != first and line.strip():
                first = t
            out.write(f"[{t:7.1f}] {line}")
        p.wait()
    wall = time.perf_counter() - t0
    _reap()
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    if p.returncode:
        raise SystemExit(f"{shlex.join(cmd)} failed ({p.returncode}); see {log}")
    return {"wall": wall, "cpu": cpu, "first": first, "load": load, "start": start,
            "pid": p.pid}


def same_results(a: Path, b: Path) -> list[str]:
    """Where two report folders' results differ: claims.json, each study but its seconds."""
    import pandas as pd

    diffs = []
    if json.loads((a / "claims.json").read_text()) != json.loads((b / "claims.json").read_text()):
        diffs.append("claims.json")
    studies = sorted(p.relative_to(a) for p in a.glob("studies/*/results.parquet"))
    if not studies:
        diffs.append("no study results")
    for rel in studies:
        x, y = (pd.read_parquet(d / rel).drop(columns="seconds", errors="ignore")
                for d in (a, b))
        if not x.equals(y):
            diffs.append(str(rel))
    return diffs


def _family_of(fn: str) -> str:
    """A compiled function's kernel family (by its top-level kernel's package and method)."""
    if ".biped." in fn:
        return "biped"
    if fn.endswith(("_stride.stride", "_stride.run_row")):
        return "TSLIP strides"
    if "_record." in fn or "run_batch" in fn or "flight_state" in fn:
        return "TSLIP recorded runs"
    return "TSLIP gait search and analyses"


def compile_timeline(recs: list[dict], start: float, main_pid: int) -> None:
    """Print when each process compiled which family: its top-level tslip kernels, runs of
    one family merged, as ``[from - to s] family (CPU s)`` from the run's start; the
    gaps between them are where that process compiled nothing of tslip."""
    print("compile timeline (wall seconds from the start of the run; top-level kernels):")
    spans: dict[tuple[int, str], list[list]] = defaultdict(list)
    cpu: dict[tuple[int, str], float] = defaultdict(float)
    for r in recs:
        cpu[(r["pid"], r["thread"])] += r["cpu"]
        if r["depth"] or not r["fn"].startswith("tslip.") or "t0" not in r:
            continue
        fam, t0, t1 = _family_of(r["fn"]), r["t0"] - start, r["t"] - start
        runs = spans[(r["pid"], r["thread"])]
        if runs and runs[-1][0] == fam:
            runs[-1][2] = t1
            runs[-1][3] += r["incl"]
        else:
            runs.append([fam, t0, t1, r["incl"]])
    for (pid, thread), runs in sorted(spans.items(), key=lambda kv: kv[1][0][1]):
        who = "tslip's own process" if pid == main_pid else "another process"
        print(f"  {who} {pid} {thread}:")
        for fam, t0, t1, c in runs:
            print(f"    [{t0:6.1f} - {t1:6.1f} s] {fam} ({c:.1f} s CPU)")


def compile_breakdown(log: Path, start: float | None = None, main_pid: int = 0) -> float:
    """Print the compile CPU seconds of ``log`` per process, family and top-level kernel
    (with ``start``, the run's epoch seconds, also :func:`compile_timeline`); return their
    sum."""
    recs = [json.loads(line) for line in log.read_text().splitlines()]
    if not recs:
        print("no compiles recorded")
        return 0.0
    per_proc: dict[tuple[int, str], float] = defaultdict(float)
    per_top: dict[tuple[str, str], float] = defaultdict(float)
    where: dict[tuple[str, str], set[int]] = defaultdict(set)
    stack_top: dict[tuple[int, str], list[dict]] = defaultdict(list)
    for r in recs:  # callees end before their caller: attribute them to the next depth-0 end
        per_proc[(r["pid"], r["thread"])] += r["cpu"]
        where[(r["fn"], r["args"])].add(r["pid"])
        stack_top[(r["pid"], r["thread"])].append(r)
        if r["depth"] == 0:
            top = r["fn"].replace("tslip.", "")
            per_top[(_family_of(r["fn"]), top)] += sum(
                x["cpu"] for x in stack_top.pop((r["pid"], r["thread"])))
    print(f"compile CPU: {sum(r['cpu'] for r in recs):.1f} s in {len(recs)} compiles")
    if start is not None:
        compile_timeline(recs, start, main_pid)
    for (pid, thread), c in sorted(per_proc.items(), key=lambda kv: -kv[1]):
        print(f"  process {pid} {thread:12s} {c:6.1f} s")
    fam: dict[str, float] = defaultdict(float)
    for (f, _), c in per_top.items():
        fam[f] += c
    for f, c in sorted(fam.items(), key=lambda kv: -kv[1]):
        print(f"  {f:28s} {c:6.1f} s")
        for (f2, top), c2 in sorted(per_top.items(), key=lambda kv: -kv[1]):
            if f2 == f and c2 >= 0.2:
                print(f"      {top:52s} {c2:6.2f} s (with its callees)")
    twice = {k: v for k, v in where.items() if len(v) > 1}
    ours = [k for k in twice if k[0].startswith("tslip.")]
    theirs = sum(r["cpu"] for r in recs if (r["fn"], r["args"]) in twice
                 and not r["fn"].startswith("tslip."))
    print(f"signatures compiled in two processes: {len(ours)} of tslip"
          + "".join(f"\n  {fn} {args[:80]}" for fn, args in ours)
          + f"; {len(twice) - len(ours)} of numba's own overloads (never cached: every "
            f"process compiling anything compiles them), {theirs:.1f} s in all")
    return sum(r["cpu"] for r in recs)


def first_run(reuse_venv: str | None, compile_log: bool, keep: bool,
              rev: str | None = None) -> dict[str, float]:
    """Clone (at ``rev``: default HEAD), install (or reuse a venv), then a cold and a warm
    ``tslip reproduce --quick``; returns the cold run's wall, CPU and compile CPU seconds."""
    _subreaper()
    tmp = Path(tempfile.mkdtemp(prefix="tslip-first-run-"))
    clone = tmp / "clone"
    subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
    if rev is not None:
        subprocess.run(["git", "-C", str(clone), "checkout", "-q", rev], check=True)
    env = {k: v for k, v in os.environ.items()
           if k not in ("NUMBA_CACHE_DIR", "PYTHONPATH", "VIRTUAL_ENV")}
    env["XDG_CACHE_HOME"] = str(tmp / "user-cache")  # numba's fallback cache folder: empty
    if reuse_venv:
        venv = Path(reuse_venv)
        env["PYTHONPATH"] = str(clone / "src")
        install = float("nan")
    else:
        venv = tmp / "venv"
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
        cmd = readme_install()
        env["PATH"] = f"{venv / 'bin'}{os.pathsep}{env['PATH']}"
        t = time.perf_counter()
        subprocess.run(cmd, shell=True, cwd=clone, env=env, check=True)  # noqa: S602
        install = time.perf_counter() - t
    env["PATH"] = f"{venv / 'bin'}{os.pathsep}{env['PATH']}"
    python = str(venv / "bin" / "python")
    located = subprocess.run([python, "-c", "import tslip; print(tslip.__file__)"], env=env,
                             capture_output=True, text=True, check=True).stdout.strip()
    pkg = Path(located).parent
    if any(pkg.rglob("*.nbi")):
        raise SystemExit(f"{pkg} already holds numba cache files: not a first run")
    run_env = dict(env)
    if compile_log:
        site = tmp / "site"
        site.mkdir()
        (site / "sitecustomize.py").write_text(_RECORDER)
        run_env["PYTHONPATH"] = os.pathsep.join(
            [str(site), *([env["PYTHONPATH"]] if "PYTHONPATH" in env else [])])
        run_env["TSLIP_BENCH_COMPILE_LOG"] = str(tmp / "compiles.jsonl")
    cmd = [python, "-m", "tslip", "reproduce", "--quick", "--out"]
    print(f"clone {clone} at {rev or 'HEAD'}; package {pkg}; install: "
          f"{'reused ' + str(venv) if reuse_venv else readme_install()}", flush=True)
    cold = timed_run([*cmd, "report-cold"], run_env, clone, tmp / "cold.log")
    warm = timed_run([*cmd, "report-warm"], env, clone, tmp / "warm.log")
    said = (tmp / "cold.log").read_text().splitlines()[0]
    print(f"install {install:.1f} s")
    for name, r in (("first reproduce --quick", cold), ("second (warm)", warm)):
        print(f"{name:24s} wall {r['wall']:6.1f} s  CPU {r['cpu']:6.1f} s  "
              f"first line {r['first']:5.1f} s  (1-min load before: {r['load']:.2f})")
    print(f"first line: {said}")
    print(f"warm run silent about compiling: "
          f"{not re.search('compil', (tmp / 'warm.log').read_text())}")
    diffs = same_results(clone / "report-cold", clone / "report-warm")
    print("results identical to the warm run's" if not diffs else f"results DIFFER: {diffs}")
    for line in (tmp / "cold.log").read_text().splitlines():
        if "compiled " in line or "first run:" in line:
            print(f"said {line}")
    compiled = (compile_breakdown(tmp / "compiles.jsonl", cold["start"], int(cold["pid"]))
                if compile_log else float("nan"))
    if keep:
        print(f"kept {tmp}")
    else:
        import shutil

        shutil.rmtree(tmp, ignore_errors=True)
    return {"wall": cold["wall"], "cpu": cold["cpu"], "compile": compiled}


def warm_runs(rounds: int, full: bool, rev: str, baseline_src: str | None,
              workers: int) -> None:
    """Interleaved warm ``tslip reproduce`` of this checkout and a baseline (``--warm``)."""
    import statistics

    from _baseline import source_at

    _subreaper()
    tmp = Path(tempfile.mkdtemp(prefix="tslip-warm-"))
    srcs = {"new": source_at(None),
            "old": Path(baseline_src) if baseline_src else source_at(rev)}
    envs = {k: dict(os.environ, PYTHONPATH=str(src)) for k, src in srcs.items()}
    print(f"new: {srcs['new']}; old: {srcs['old']}; folders in {tmp}", flush=True)

    def run(k: str, res: str, out: Path) -> dict[str, float]:
        cmd = [sys.executable, "-m", "tslip", "reproduce", "--workers", str(workers), "--out",
               str(out)] + (["--quick"] if res == "quick" else [])
        return timed_run(cmd, envs[k], tmp, tmp / f"{out.name}.log")

    resolutions = ["quick", "full"] if full else ["quick"]
    for res in resolutions:
        rows: dict[tuple[str, str], list[dict[str, float]]] = defaultdict(list)
        for k in srcs:  # compiles the kernels if needed; the first new folder of full
            r = run(k, res, tmp / f"{res}-same-{k}")
            if res == "full":
                rows[(k, "new folder")].append(r)
        if res == "quick" and not (diffs := same_results(tmp / "quick-same-new",
                                                         tmp / "quick-same-old")):
            print("quick: claims.json and every study's columns equal on both revisions")
        elif res == "quick":
            print(f"quick: results DIFFER between the revisions: {diffs}")
        for i in range(rounds):
            for k in (("new", "old") if i % 2 == 0 else ("old", "new")):
                if res == "quick":
                    rows[(k, "new folder")].append(run(k, res, tmp / f"{res}-{k}-{i}"))
                rows[(k, "same folder")].append(run(k, res, tmp / f"{res}-same-{k}"))
        for mode in ("new folder", "same folder"):
            med = {k: {f: statistics.median(r[f] for r in rows[(k, mode)])
                       for f in ("wall", "cpu", "first", "load")} for k in srcs}
            n, o = med["new"], med["old"]
            print(f"{res:5s} {mode:11s} wall {n['wall']:6.1f} s (old {o['wall']:6.1f}, ratio "
                  f"{n['wall'] / o['wall']:.2f})  CPU {n['cpu']:6.1f} s (old {o['cpu']:6.1f}, "
                  f"ratio {n['cpu'] / o['cpu']:.2f})  first line {n['first']:4.1f} s (old "
                  f"{o['first']:4.1f})  load {n['load']:.1f}/{o['load']:.1f}  "
                  f"[{len(rows[('new', mode)])} runs each]", flush=True)
    print("targets (quiet machine, 1-min load < 0.5): quick <= 4 s, full <= 8 s, "
          "first line <= 5 s")
    import shutil

    shutil.rmtree(tmp, ignore_errors=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="fresh imports (best of)")
    ap.add_argument("--what", default="step_map,simulate", help="first strides to time")
    ap.add_argument("--rev", default=BASELINE_REV, help="baseline revision")
    ap.add_argument("--first-run", action="store_true",
                    help="a fresh clone's install and first `tslip reproduce --quick` instead")
    ap.add_argument("--reuse-venv", metavar="PATH",
                    help="with --first-run: this venv and the clone's src, no install")
    ap.add_argument("--compile-log", action="store_true",
                    help="with --first-run: numba's compile events of every process")
    ap.add_argument("--keep", action="store_true", help="with --first-run: keep the folder")
    ap.add_argument("--against", metavar="REV",
                    help="with --first-run: then the same at REV, and the ratios (issue 41: "
                         "07e68e4, the revision before one loop per model)")
    ap.add_argument("--warm", action="store_true",
                    help="warm `tslip reproduce` runs against a baseline instead")
    ap.add_argument("--rounds", type=int, default=3, help="with --warm: interleaved rounds")
    ap.add_argument("--full", action="store_true", help="with --warm: the full resolution too")
    ap.add_argument("--warm-rev", default="ae943bb", help="with --warm: baseline revision")
    ap.add_argument("--baseline-src", metavar="PATH",
                    help="with --warm: the baseline's src folder instead of --warm-rev")
    ap.add_argument("--workers", type=int, default=2, help="with --warm: worker processes")
    args = ap.parse_args()
    if args.first_run:
        new = first_run(args.reuse_venv, args.compile_log, args.keep)
        if args.against:
            old = first_run(args.reuse_venv, args.compile_log, args.keep, args.against)
            for k in ("wall", "cpu", "compile"):
                print(f"first run {k:8s}: {new[k]:6.1f} s, at {args.against} {old[k]:6.1f} s, "
                      f"ratio {new[k] / old[k]:.2f}")
        return
    if args.warm:
        warm_runs(args.rounds, args.full, args.warm_rev, args.baseline_src, args.workers)
        return
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
