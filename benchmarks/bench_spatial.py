"""The 3-D TSLIP's stride against the planar TSLIP's stride kernel (issue 43), in one run.

Run by hand (not in CI): ``python benchmarks/bench_spatial.py``. One thread; every
workload repeats one stride ``--reps`` times from the same start, and the workloads
are timed interleaved, call by call, for ``--rounds`` rounds (``_baseline.ab``);
each figure is the median (CPU seconds unless ``--wall``) divided by ``--reps``.
Tolerances ``rtol = atol = --tol`` (default 1e-8, dopri5; ``--method``) for every model.

* **planar stride kernel** (the denominator of every ratio): the compiled planar
  stride (``simulation/_stride.py`` ``stride``) from the touch-down of the Table 2.1
  gait (``tslip.find_gait(tslip.preset("table2.1"))``), called from a compiled loop
  (no Python dispatch); **planar step_map**: ``tslip.step_map`` from its section, from
  Python, for the same stride as a user calls it.
* **3-D stride kernel**: the compiled 3-D stride (``spatial/_trunk_stride.py``
  ``stride``) in a compiled loop, from the right touch-down of the Table 2.1 gait in
  3-D: splay 0.05 (the preset ``table2.1-3d`` with the gait's ``alpha_r``, its
  symmetric gait by ``lateral.table21_gait``) and splay 0 (the planar gait itself,
  ``lateral.TABLE21_SECTION``); **trunk_step**: the public call from Python.
* **before** (``--before REV``, default 9001fbd: the phase kernels joined by Python,
  ``none`` to skip): that revision's ``trunk_step`` from the same starts, imported in
  this process (``_baseline.import_at``; its kernels compile once into its own cache).
* **3-D SLIP step** (Part 1, context): ``tslip.spatial.apex_step`` on the preset
  ``slip3d`` from its docstring's apex (height 1, energy 2.2).

Prints the load before and after, the accepted steps of each stride, each figure in
microseconds and as a ratio to the planar stride kernel.
"""

from __future__ import annotations

import argparse
import functools
import importlib
import os
import time
from collections.abc import Callable

import numba
import numpy as np
from _baseline import ab, import_at
from numba import njit

import tslip
from tslip.model import _pack as pk
from tslip.simulation import _stride
from tslip.spatial import _trunk_stride as ks
from tslip.spatial.lateral import TABLE21_SECTION, table21_gait, table21_params
from tslip.spatial.trunk_section import from_section

#: The revision whose ``trunk_step`` joined the phase kernels in Python (this work's parent).
BEFORE = "9001fbd"


@njit(cache=False, error_model="numpy")
def _planar_loop(P, O, td, reps):  # noqa: N803
    """``reps`` planar strides from ``td`` (flat ground, nothing recorded)."""
    out = np.empty(pk.NOUT)
    rec = np.empty((0, pk.NREC))
    tx, th = np.empty(0), np.zeros(1)
    acc = 0.0
    for _ in range(reps):
        _stride.stride(P, O, td, tx, th, rec, 0.0, out)
        acc += out[pk.OUT_TF]
    return acc


@njit(cache=False, error_model="numpy")
def _trunk_loop(P, O, y0, foot, reps):  # noqa: N803
    """``reps`` 3-D strides from the touch-down ``y0``, ``foot`` (nothing recorded)."""
    out = np.empty(ks.NSOUT)
    rec = np.empty((0, 14))
    acc = 0.0
    for _ in range(reps):
        ks.stride(P, O, y0, foot, True, rec, out)
        acc += out[ks.S_TF]
    return acc


def _repeat(fn: Callable[[], object], reps: int) -> Callable[[], None]:
    def run() -> None:
        for _ in range(reps):
            fn()
    return run


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=21, help="interleaved rounds")
    ap.add_argument("--reps", type=int, default=200, help="strides a workload a round")
    ap.add_argument("--tol", type=float, default=1e-8, help="rtol = atol of every model")
    ap.add_argument("--method", default="dopri5", choices=("dopri5", "dop853"))
    ap.add_argument("--before", default=BEFORE, help="revision for 'before', or none")
    ap.add_argument("--wall", action="store_true", help="wall time instead of CPU time")
    a = ap.parse_args()
    clock = time.perf_counter if a.wall else time.process_time
    numba.set_num_threads(1)
    load0 = os.getloadavg()[0]
    opt = tslip.IntegratorOptions(rtol=a.tol, atol=a.tol, method=a.method)
    O = opt.packed()  # noqa: N806

    g = tslip.find_gait(tslip.preset("table2.1"))
    P = pk.pack_params(g.params)  # noqa: N806
    td = np.asarray(g.state.as_array(), dtype=float)
    td = np.r_[td, np.zeros(7 - len(td))]
    q = g.state.section()
    out = np.empty(pk.NOUT)
    _stride.stride(P, O, td, np.empty(0), np.zeros(1), np.empty((0, pk.NREC)), 0.0, out)
    counts = {"planar": int(out[pk.OUT_NSTEP])}

    starts = {0.05: (table21_params(), table21_gait(table21_params())),
              0.0: (table21_params(splay=0.0), TABLE21_SECTION)}
    fns: dict[str, Callable[[], object]] = {
        "planar kernel": lambda: _planar_loop(P, O, td, a.reps),
        "planar step_map": _repeat(lambda: tslip.step_map(g.params, q, options=opt), a.reps),
    }
    old = None if a.before.lower() == "none" else import_at(a.before)
    for splay, (p, x) in starts.items():
        s = from_section(p, x, 1)
        r = tslip.spatial.trunk_step(p, s, options=opt)
        if not r.ok:
            raise SystemExit(f"the 3-D stride at splay {splay} fell: {r.status.name}")
        counts[f"3-D {splay:g}"] = r.n_steps
        Pt = p.packed(1)  # noqa: N806
        fns[f"3-D kernel {splay:g}"] = functools.partial(_trunk_loop, Pt, O, s.y, s.foot, a.reps)
        fns[f"trunk_step {splay:g}"] = _repeat(
            functools.partial(tslip.spatial.trunk_step, p, s, options=opt), a.reps)
        if old is not None:
            po = importlib.import_module(f"{old.__name__}.spatial.lateral").table21_params(
                splay=splay)
            so = importlib.import_module(f"{old.__name__}.spatial.trunk_section").from_section(
                po, x, 1)
            oopt = old.IntegratorOptions(rtol=a.tol, atol=a.tol, method=a.method)
            fns[f"before {splay:g}"] = _repeat(
                functools.partial(old.spatial.trunk_step, po, so, options=oopt), a.reps)
    sp = tslip.spatial.preset("slip3d")
    apex = tslip.spatial.SpatialApex.from_energy(sp, 1.0, 2.2)
    fns["3-D SLIP step"] = _repeat(lambda: tslip.spatial.apex_step(sp, apex, opt), a.reps)

    t = ab(fns, a.rounds, clock=clock).median
    load1 = os.getloadavg()[0]
    us = {k: v / a.reps * 1e6 for k, v in t.items()}
    base = us["planar kernel"]
    what = "wall" if a.wall else "CPU"
    print(f"{a.method} rtol = atol = {a.tol:g}, one thread; medians of {a.rounds} interleaved "
          f"rounds of {a.reps} strides ({what} time); 1-minute load {load0:.2f} before, "
          f"{load1:.2f} after")
    print("accepted steps a stride: " + ", ".join(f"{k} {v}" for k, v in counts.items()))
    for k, v in us.items():
        print(f"{k:>22}: {v:8.2f} us  ({v / base:5.2f} x planar stride kernel)")
    for splay in starts:
        ratio = us[f"trunk_step {splay:g}"] / base
        kern = us[f"3-D kernel {splay:g}"] / base
        line = f"3-D TSLIP stride (splay {splay:g}) / planar stride kernel: {ratio:.2f} " \
               f"(kernel alone {kern:.2f})"
        if old is not None:
            line += f"; before ({a.before}): {us[f'before {splay:g}'] / base:.2f}"
        print(line)


if __name__ == "__main__":
    main()
