"""How close the simulator runs to its physical limit: five ratios measured in one run (issue 25).

Run by hand (not in CI): ``python benchmarks/bench_limit.py``. Everything is on
the Table 6.1 periodic gait (``tslip.find_gait(tslip.preset("table6.1"))``) with
the default options (dopri5, ``rtol = atol = 1e-8``), on one thread. The
workloads are timed interleaved, call by call, for ``--rounds`` rounds
(``_baseline.ab``); each ratio is of the median times (CPU seconds by default,
steadier than wall time on a shared machine; ``--wall`` for wall time). It
prints exactly these lines, after context lines (load, counts)::

    stride kernel / RHS-bound limit: X.XX
    simulate / unrecorded strides: X.XX
    simulate + to_dataframe / unrecorded strides: X.XX
    step_map / stride kernel: X.XX
    study point / its compiled work: X.XX

Definitions:

* **stride kernel**: the time of one compiled stride, from one
  :func:`tslip.run_batch` call of ``--steps`` strides of the gait (one row,
  nothing recorded) divided by ``--steps``.
* **RHS-bound limit** = ``t_rhs x N_RHS``. ``t_rhs`` is the median time of one
  stance right-hand side as the stride kernel runs it: ``_stance.rhs_inline``, the
  code every stage of ``rk_step`` copies in (numba's ``inline="always"``), inlined
  into one compiled loop with the kernels' compile flags (``_rk._JIT``: numpy's error
  model) over the stride's own stance states (the states at the integrator's steps,
  ``tslip.step(...).stance``), each copied into a whole state array as a stage's
  arithmetic writes its ``ytmp``; all six derivatives are summed, so none is dropped
  as unused. Issue 41 found the figure moved with the harness alone: a separately
  compiled ``_stance.rhs`` (issue 25's harness) pays a call the kernel does not (the
  same kernel read 1.35 to 1.73); Python's error model (zero-division checks) made
  the inlined right-hand side 144 ns against 77; and writing into a row of a stage
  matrix (a view, 146-161 ns) or reading a row of ``Y`` in place (150 ns) cost more
  than the kernel's own stage loop spends on a right-hand side and its stage
  arithmetic together (about 72 ns: ``rk_step`` replayed, the breakdown line's
  ``steps``), against 53-63 ns from and into whole arrays (2026-12-06, load 7-9).
  The states are independent, so the processor may overlap consecutive right-hand
  sides, which a step's stages (each from the last) cannot: ``t_rhs`` is a
  throughput, a floor for the kernel's. On a checkout without ``rhs_inline``,
  ``_stance.rhs`` (which LLVM inlined into the stages there). :data:`N_RHS` = 146
  is frozen: the right-hand sides (accepted and rejected steps, 6 per dopri5 step,
  plus the initial-step estimate; no dense-output stages) that the kernel of
  revision 3b38fb1 spends on this stride. Today's count is printed beside it (counted exactly by
  ``_rhs_count.py``: the stride as plain Python in a subprocess, every call of
  ``rhs`` counted), so a kernel taking fewer steps shows as a gain.
* **unrecorded strides**: the same ``--steps`` strides through the compiled
  batch kernel without recording, one :func:`tslip.run_batch` call.
* **simulate**: :func:`tslip.simulate` of those strides at ``dt = --dt``;
  **simulate + to_dataframe**: the same and ``Trajectory.to_dataframe()`` (all
  columns). A context line gives that line's floor: the sine and cosine of both
  angles (``beta``, ``phi``) of every sample, which every derived position,
  velocity and force needs, as ``to_dataframe`` computes them (vectorised,
  ``simulation/_sincos.py``; libm's on a checkout without it, which took them
  from libm as the stride kernel does), plus writing a fresh table of all
  columns once.
* **step_map**: one :func:`tslip.step_map` call from the gait's section (a
  loop of ``--maps`` calls, divided by ``--maps``), against one stride kernel.
* **study point / its compiled work**: the time of one serial continuation point
  of ``run_study`` over the time of the compiled kernel calls it makes (stride
  maps, exact Jacobians, ``alpha_r`` columns), recorded with their arguments in an
  untimed round and replayed from one compiled loop per kernel, so that no Python
  dispatch counts as compiled work; both CPU time (``--wall``: wall), from
  ``benchmarks/_study_limit.py``'s ``measure(rounds, clock) -> (point seconds,
  kernel seconds)``, its own ``--rounds`` rounds after the others; ``n/a`` if that
  module is missing.

Context lines after the stride breakdown (issue 41) give **the method floor**
(``benchmarks/_method_floor.py``, where it is defined in full): the time of one stance by
a minimal hand-written dopri5 loop with the same right-hand side (``rhs_inline``),
tolerances, starting step, error norm and step-size rule as the kernel, so that it takes
the same steps (checked: the same final state, bit for bit), and the lift-off event alone
(``F_y`` from > 0 to <= 0 over a step, located by Illinois on the dense output, then a
fresh step to it); nothing else (no other event, guard, record or run-time choice of the
pair). Its breakdown is the stride breakdown's, the per-step control split into the error
norm, the step size (``pow``) and the rest (lift-off location, starting step, and each
step waiting for its size); ``floor / RHS-bound limit`` is the least the headline ratio
could be with this method, before any touch-down, flight or batch loop, also with the
faster stage arithmetic of the two (the floor's stages, constants and all, ran slower
than the kernel's on 2026-12-06: that part of the floor is not a floor), and with the
stride's per-stride work added (it is not printed
for gaits whose stance the floor does not reproduce: leg thrust, lift-off on the spring).
"""

from __future__ import annotations

import argparse
import inspect
import math
import os
import time
from collections.abc import Callable

import numba
import numpy as np
from _baseline import ab
from _rhs_count import rhs_per_stride
from numba import njit

import tslip
from tslip.model import _pack as pk
from tslip.simulation import _kernels as kn
from tslip.simulation import _rk, _stance
from tslip.simulation._stepper import rk_step

try:  # the method floor (issue 41); a checkout without stance_terms / put_rhs has none
    import _method_floor
except (ImportError, AttributeError):
    _method_floor = None

#: Right-hand sides of the Table 6.1 stride at dopri5 1e-8 with the kernel of
#: revision 3b38fb1 (frozen: the limit does not move when the kernel takes fewer steps).
N_RHS = 146

#: The stance right-hand side as the stages of ``rk_step`` run it: inlined into them
#: (``_stance.rhs`` on checkouts before ``rhs_inline``, which LLVM inlined by itself).
_RHS = getattr(_stance, "rhs_inline", _stance.rhs)
#: The loops that time the kernels' own code compile with the kernels' flags (numpy's
#: error model: no zero-division checks), uncached.
_KJIT = dict(getattr(_rk, "_JIT", {"error_model": "numpy"}), cache=False)


@njit(**_KJIT)
def _rhs_loop(P, Y, reps):  # noqa: N803
    """``reps`` passes over the rows of ``Y`` of the right-hand side as a stage of ``rk_step``
    calls it: inlined, from a whole state array (its ``ytmp``; here the row copied in) into
    a whole output array. The sum of every derivative keeps all of each call alive."""
    dy = np.empty(6)
    y = np.empty(6)
    acc = 0.0
    for _ in range(reps):
        for i in range(Y.shape[0]):
            for j in range(6):
                y[j] = Y[i, j]
            _RHS(P, y, dy)
            acc += dy[0] + dy[1] + dy[2] + dy[3] + dy[4] + dy[5]
    return acc


@njit(cache=False)
def _libm_trig(beta, phi):
    """libm's sines and cosines of both angles of each sample; the sum keeps the calls alive."""
    acc = 0.0
    for i in range(beta.shape[0]):
        acc += math.sin(beta[i]) + math.cos(beta[i]) + math.sin(phi[i]) + math.cos(phi[i])
    return acc


def _trig_loop(beta: np.ndarray, phi: np.ndarray) -> Callable[[], object]:
    """The sines and cosines ``to_dataframe`` cannot do without, of both angles of each
    sample, as this checkout's ``_record.fill_table`` computes them: vectorised
    (``_sincos.sincos_array``), or libm's on a checkout without that module."""
    try:
        from tslip.simulation._sincos import sincos_array
    except ImportError:
        return lambda: _libm_trig(beta, phi)
    out = np.empty((4, len(beta)))
    return lambda: (sincos_array(beta, out[0], out[1]), sincos_array(phi, out[2], out[3]))


#: The method of the loops below, a compile-time constant there (as in the kernels).
_DOPRI5 = pk.M_DOPRI5


def _make_steps_loop(with_events: bool):  # noqa: ANN202 - a compiled function
    """``_steps_loop(P, y0, hs, reps)``: ``reps`` replays of the stance's steps (sizes ``hs``)
    from ``y0``, the stages and their right-hand sides alone (plus ``f(y0)``), without error
    control, events or step-size choice. ``with_events``: ``rk_step`` takes the event
    values' array (its last stage computes them; checkouts before that take no such array)."""

    @njit(**_KJIT)
    def _steps_loop(P, y0, hs, reps):  # noqa: N803
        ns = _rk.n_stages(_DOPRI5)
        K = np.empty((_rk.NK, 6))
        y, ytmp, ynew, gv = np.empty(6), np.empty(6), np.empty(6), np.empty(8)
        acc = 0.0
        for _ in range(reps):
            for i in range(6):
                y[i] = y0[i]
            _stance.rhs(P, y, K[0])
            for h in hs:
                if with_events:
                    rk_step(P, _DOPRI5, y, h, K, ytmp, ynew, gv)
                else:
                    rk_step(P, _DOPRI5, y, h, K, ytmp, ynew)
                for i in range(6):
                    y[i] = ynew[i]
                    K[0, i] = K[ns, i]
            acc += y[0]
        return acc

    return _steps_loop


_steps_loop = _make_steps_loop(len(inspect.signature(rk_step.py_func).parameters) == 8)


def _stance_kernel():  # noqa: ANN202 - a compiled function
    """The compiled dopri5 stance kernel ``(P, O, y0, tx, th, rec, rec_dt, out) -> status``
    that :func:`_stance_loop` calls (the one place that knows how the kernels are held:
    one per method in a tuple, or one for all)."""
    kernels = kn.stance_rec if hasattr(kn, "stance_rec") else kn.STANCE_REC
    return kernels[pk.M_DOPRI5] if isinstance(kernels, tuple) else kernels


@njit(**_KJIT)
def _stance_loop(stance, P, O, y0, reps):  # noqa: N803
    """``reps`` stances from ``y0`` through the stance kernel ``stance``, nothing recorded."""
    rec = np.empty((0, pk.NREC))
    tx = np.empty(0)
    out = np.empty(11)
    acc = 0.0
    for _ in range(reps):
        stance(P, O, y0, tx, tx, rec, 0.0, out)
        acc += out[0]
    return acc


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=21, help="interleaved rounds")
    ap.add_argument("--steps", type=int, default=1000, help="strides of the runs")
    ap.add_argument("--maps", type=int, default=1000, help="step_map calls a round")
    ap.add_argument("--reps", type=int, default=200, help="passes over the stance states")
    ap.add_argument("--dt", type=float, default=0.01)
    ap.add_argument("--wall", action="store_true", help="wall time instead of CPU time")
    a = ap.parse_args()
    clock = time.perf_counter if a.wall else time.process_time
    numba.set_num_threads(1)
    load0 = os.getloadavg()[0]

    g = tslip.find_gait(tslip.preset("table6.1"))
    p, s = g.params, g.state
    q = s.section()
    P = pk.pack_params(p)
    Y = np.ascontiguousarray(tslip.step(p, s).stance[:, 1:7])
    n_now = round(rhs_per_stride([("dopri5", 1e-8)])["dopri5 1e-08"])
    # the stance alone: its start, and its steps' sizes (recorded at each accepted step)
    O = tslip.IntegratorOptions().packed()  # noqa: N806
    y0, yout, stats = np.empty(6), np.empty(6), np.empty(5)
    kn.stance_initial(P, np.r_[q, 0.0, 0.0], y0)
    rec = np.empty((4096, pk.NREC))
    kn.integrate_stance(P, O, y0, yout, rec, 0.0, stats)
    hs = np.diff(rec[: int(stats[3]), pk.REC_T])
    stance = _stance_kernel()

    data = tslip.simulate(p, s, a.steps, dt=a.dt).data
    beta = np.ascontiguousarray(data[:, pk.TR_BETA])
    phi = np.ascontiguousarray(data[:, pk.TR_PHI])

    def maps() -> None:
        for _ in range(a.maps):
            tslip.step_map(p, q)

    fns = {
        "rhs": lambda: _rhs_loop(P, Y, a.reps),
        "strides": lambda: tslip.run_batch(p, [s], a.steps),
        "simulate": lambda: tslip.simulate(p, s, a.steps, dt=a.dt),
        "simulate + df": lambda: tslip.simulate(p, s, a.steps, dt=a.dt).to_dataframe(),
        "step_map": maps,
        "trig": _trig_loop(beta, phi),
        "fresh table": lambda: np.empty((pk.NTRAJ, len(beta))).fill(1.0),
        "steps": lambda: _steps_loop(P, y0, hs, a.reps),
        "stance": lambda: _stance_loop(stance, P, O, y0, a.reps),
    }
    mf = _method_floor
    floor = mf is not None and mf.applies(P)
    if floor:
        fns.update(mf.floor_fns(P, O, y0, hs, a.reps))
        same = mf.same_as_kernel(P, O, y0, yout, stats)
    t = ab(fns, a.rounds, clock=clock).median
    rows = len(beta)
    t_rhs = t["rhs"] / (a.reps * len(Y))
    stride = t["strides"] / a.steps
    study = None
    try:
        from _study_limit import measure  # another helper's module (issue 25)
    except ImportError:
        pass
    else:
        study = measure(a.rounds, "wall" if a.wall else "cpu")
    load1 = os.getloadavg()[0]

    what = "wall" if a.wall else "CPU"
    print(f"Table 6.1 gait, dopri5 rtol = atol = 1e-8, one thread; medians of {a.rounds} "
          f"interleaved rounds ({what} time); 1-minute load {load0:.2f} before, "
          f"{load1:.2f} after")
    print(f"RHS: t_rhs {t_rhs * 1e9:.1f} ns over {len(Y)} stance states x {a.reps}; "
          f"N_rhs {N_RHS} (revision 3b38fb1, frozen), today {n_now}; limit "
          f"{t_rhs * N_RHS * 1e6:.2f} us (today's count: {t_rhs * n_now * 1e6:.2f} us)")
    print(f"stride kernel {stride * 1e6:.2f} us ({a.steps} strides, run_batch); step_map "
          f"{t['step_map'] / a.maps * 1e6:.2f} us a call; simulate {t['simulate'] * 1e3:.2f} ms, "
          f"+ to_dataframe {t['simulate + df'] * 1e3:.2f} ms ({a.steps} strides, {rows} rows, "
          f"dt {a.dt:g})")
    t_steps, t_stance = t["steps"] / a.reps, t["stance"] / a.reps
    n_steps_rhs = 1 + 6 * len(hs)
    print(f"stride breakdown: right-hand sides {t_rhs * n_now * 1e6:.2f} us ({n_now}), stage "
          f"arithmetic {(t_steps - t_rhs * n_steps_rhs) * 1e6:.2f} us ({len(hs)} steps replayed), "
          f"per-step control (error norm, step size, events, initial step) "
          f"{(t_stance - t_steps - t_rhs * (n_now - n_steps_rhs)) * 1e6:.2f} us, "
          f"per-stride work (touch-down, flight, batch loop) {(stride - t_stance) * 1e6:.2f} us")
    if floor:
        for line in mf.floor_lines(t, a.reps, t_rhs, n_now, N_RHS, len(hs), int(stats[1]), stride,
                                same):
            print(line)
    df_floor = t["simulate"] + t["trig"] + t["fresh table"]
    print(f"to_dataframe adds {(t['simulate + df'] - t['simulate']) * 1e3:.2f} ms; its floor: "
          f"sin and cos of both angles of each sample {t['trig'] * 1e3:.2f} ms, a fresh "
          f"table written once {t['fresh table'] * 1e3:.2f} ms; simulate + these / unrecorded "
          f"strides: {df_floor / t['strides']:.2f}")
    if study is not None:
        print(f"study point {study[0] * 1e3:.3f} ms, its compiled kernel calls "
              f"{study[1] * 1e3:.3f} ms (replayed in compiled loops; {what} time)")
    print(f"stride kernel / RHS-bound limit: {stride / (t_rhs * N_RHS):.2f}")
    print(f"simulate / unrecorded strides: {t['simulate'] / t['strides']:.2f}")
    print(f"simulate + to_dataframe / unrecorded strides: "
          f"{t['simulate + df'] / t['strides']:.2f}")
    print(f"step_map / stride kernel: {t['step_map'] / a.maps / stride:.2f}")
    if study is None:
        print("study point / its compiled work: n/a (benchmarks/_study_limit.py missing)")
    else:
        print(f"study point / its compiled work: {study[0] / study[1]:.2f}")


if __name__ == "__main__":
    main()
