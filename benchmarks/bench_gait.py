"""Gait analysis on one core: gait search, multipliers, robustness vs scipy references.

Run by hand (not in CI): ``python benchmarks/bench_gait.py``. Everything runs
on the Table 6.1 model with numba limited to one thread, and each package
timing is printed beside a scipy reference measured in the same run, so the
ratio is what counts on a shared, noisy machine:

* gait search: :func:`tslip.find_gait` vs ``scipy.optimize.least_squares``
  (same Levenberg-Marquardt settings, the same starting guesses in the same
  order, integrator tolerance 1e-12; best of 3) on a residual built from ``scipy_stride`` of
  ``bench_step.py`` (``solve_ivp`` DOP853 stance, closed-form flight);
* multipliers: :func:`tslip.gait.stability.floquet` with ``method="fd"``
  (ten strides, one batch) and ``"exact"`` (variational equations) vs a
  central-difference Jacobian (eq. B.2, step 1e-5) of ``scipy_stride`` plus
  ``numpy.linalg.eig``;
* robustness triple: :func:`tslip.gait.robustness.robustness_report` (step
  down, push, pitch rate; sign -1; tol 1e-4; 25 strides; thesis tolerance
  1e-8) vs the same search (:func:`limit_search`) whose predicate runs each
  disturbed row serially with a ``solve_ivp`` stance that also stops at the
  fall events of eqs 2.10-2.11. The scipy triple runs at a coarser search
  tolerance (``--scipy-search-tol``, default 1e-2) and is scaled to the full
  search by the ratio of simulated strides (both counted here).

Then (issue 12 item 3) each analysis again against *today's* code, revision
``_baseline.BASELINE_REV``, imported in this process (``_baseline.import_at``)
and timed interleaved with this tree call by call (``_baseline.ab``,
``--rounds`` rounds; one numba thread on both sides): gait search from the
automatic guesses, from the gait itself and from a neighbour (``v0`` + 2 %), a
five-point continuation with multipliers, both Floquet methods and the
robustness triple. Printed as new / old best time and the speed-up old / new
of the best and of the median times (target 4x for gait search, Floquet and
the robustness triple, judged on the best), then the two revisions' answers
side by side. Skip it with ``--no-today``, run only it with ``--only-today``.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import itertools
import math
import sys
import time
import types
from collections.abc import Callable
from pathlib import Path

import numba
import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import least_squares

import tslip
from tslip.gait.fixed_point import GaitProblem, newton_solve
from tslip.gait.robustness import KINDS, limit_search, robustness_report, run_disturbed
from tslip.gait.stability import floquet
from tslip.model import _pack as pk
from tslip.simulation import _kernels as kn
from tslip.simulation import _packed

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _baseline import BASELINE_REV, ab, best_of, import_at  # noqa: E402
from bench_step import scipy_stride  # noqa: E402

TIGHT = 1e-12  # find_gait / floquet default tolerance
THESIS = 1e-8  # robustness runs (thesis tolerance)


# ---------------------------------------------------------------------------
# scipy references
# ---------------------------------------------------------------------------


def scipy_residual(prob: GaitProblem, z: np.ndarray) -> np.ndarray:
    """Periodicity residual of :func:`tslip.gait.fixed_point.gait_residual` via scipy."""
    p, s = prob.decode(z)
    try:
        nxt = scipy_stride(p, s.as_array(), TIGHT)
    except (IndexError, ValueError):  # no lift-off event: a fall
        return np.full(5, 10.0)
    b, ph, xd, yd, phd = nxt[:5]
    return np.array([b - p.beta0, ph - s.phi, phd - s.phid, math.atan2(yd, xd) - s.delta,
                     math.hypot(xd, yd) - p.v0])


def scipy_gait(prob: GaitProblem, starts: list[np.ndarray], tol: float) -> tuple[np.ndarray, float]:
    """``least_squares`` with find_gait's settings from the same starts."""
    best_z, best_err = starts[0], math.inf
    for z0 in starts:
        sol = least_squares(lambda z: scipy_residual(prob, z), z0, method="lm", xtol=1e-15,
                            ftol=1e-15, gtol=1e-15, max_nfev=400 * len(z0), diff_step=1e-7)
        err = float(np.max(np.abs(sol.fun)))
        if err < best_err:
            best_z, best_err = sol.x, err
        if err <= tol:
            break
    return best_z, best_err


def scipy_multipliers(params: tslip.Params, q: np.ndarray, step: float = 1e-5) -> np.ndarray:
    """Eq. B.2 central differences of the scipy stride, then the eigenvalues."""
    A = np.empty((5, 5))
    for j in range(5):
        e = np.zeros(7)
        e[j] = step
        td = np.append(q, [0.0, 0.0])
        A[:, j] = (scipy_stride(params, td + e, TIGHT)[:5]
                   - scipy_stride(params, td - e, TIGHT)[:5]) / (2 * step)
    return np.linalg.eigvals(A)


def scipy_run(params: tslip.Params, td: np.ndarray, n_steps: int, tol: float,
              tx: np.ndarray, th: np.ndarray) -> tuple[int, int]:
    """``n_steps`` strides with a solve_ivp stance; returns (status, strides simulated).

    Stance events as the kernels (``event_values``): lift-off ``F_y`` (eq. 2.8),
    hip on the ground (eq. 2.11), ``xdot_m < 0`` (eq. 2.10), the leg collapsing (the
    hip on its foot, also eq. 2.11); the flight is the
    package's closed form on the terrain ``(tx, th)``.
    """
    P = pk.pack_params(params)
    O = tslip.IntegratorOptions(rtol=tol, atol=tol).packed()
    accel, ev = kn.stance_accel.py_func, kn.event_values.py_func
    gv = np.empty(kn.NEVENTS)

    def f(t, y):
        ldd, bdd, phdd, _, _ = accel(P, y)
        return [y[3], y[4], y[5], ldd, bdd, phdd]

    def event(i):
        def g(t, y):
            ev(P, y, gv)
            return gv[i]
        g.terminal, g.direction = True, -1
        return g

    events = [event(0), event(1), event(2), event(3)]
    falls = (None, pk.ST_FALL_HIP_GROUND, pk.ST_FALL_BACKWARD, pk.ST_FALL_HIP_GROUND)
    td = np.array(td, dtype=float)
    y0, res, fs = np.empty(6), np.empty(3), np.empty(10)
    for n in range(n_steps):
        kn.stance_initial(P, td, y0)
        sol = solve_ivp(f, (0.0, 50.0), y0, method="DOP853", rtol=tol, atol=tol, events=events)
        if sol.status != 1:
            return pk.ST_ERR_STANCE_TIMEOUT, n + 1
        first = min((te[0], i) for i, te in enumerate(sol.t_events) if te.size)[1]
        if falls[first] is not None:
            return falls[first], n + 1
        y1 = sol.y_events[0][0]
        xd, yd = kn.com_velocity(P, y1)
        if xd < 0.0:
            return pk.ST_FALL_BACKWARD, n + 1
        xf = td[5] + params.l0 * math.cos(td[0]) - params.r * math.sin(td[1])
        lo = np.array([xf - y1[0] * math.cos(y1[1]) + params.r * math.sin(y1[2]),
                       td[6] + y1[0] * math.sin(y1[1]) - params.r * math.cos(y1[2]),
                       xd, yd, y1[2], y1[5]])
        st = kn.find_touchdown(P, O, lo, tx, th, res)
        if st != pk.ST_OK:
            return st, n + 1
        kn.flight_state(P, lo, res[0], fs)
        td = np.array([fs[6], fs[4], fs[2], fs[3], fs[5], fs[0], res[1]])
    return pk.ST_OK, n_steps


def scipy_survives(gait: tslip.Gait, kind: str, tol: float, count: list[int]):
    """Predicate for :func:`limit_search` running rows serially through ``scipy_run``."""
    p, s = gait.params, gait.state
    xf = s.x + p.l0 * math.cos(s.beta) - p.r * math.sin(s.phi)
    col = {"push": 2, "pitch_rate": 4}

    def survives(m: np.ndarray) -> np.ndarray:
        ok = np.empty(len(m), dtype=bool)
        for i, d in enumerate(-m):
            td = s.as_array()
            tx, th = np.empty(0), np.array([s.h])
            if kind == "step_down":
                tx, th = tslip.Terrain.flat(s.h).shifted_after(xf, float(d)).arrays()
            else:
                td[col[kind]] += d
            st, n = scipy_run(p, td, 25, tol, tx, th)
            count[0] += n
            ok[i] = st == pk.ST_OK
        return ok

    return survives


def package_strides(gait: tslip.Gait, search_tol: float) -> tuple[int, list[float]]:
    """Strides simulated by the package's robustness triple (same search, counted)."""
    total = [0]
    limits = []
    for kind in KINDS:
        def survives(m, kind=kind):
            run = run_disturbed(gait.params, gait.state, kind, -m)
            total[0] += int(np.sum(run.n_done + (run.status != 0)))
            return (run.status == 0) & (run.n_done == 25)
        limits.append(-limit_search(survives, tol=search_tol).lo)
    return total[0], limits


# ---------------------------------------------------------------------------
# against today's code (revision BASELINE_REV)
# ---------------------------------------------------------------------------

#: Item 3's 4x targets.
TARGETS = ("gait search (find_gait)", "multipliers, exact, cold (floquet)",
           "multipliers, fd (floquet)", "robustness triple")


def today_tasks(ts: types.ModuleType) -> tuple[dict[str, Callable[[], object]], dict]:
    """The tasks on package ``ts`` (``tslip`` or the old revision), and their results.

    Floquet "exact" on this tree reuses the Jacobian that find_gait computed at
    the gait (``simulation._packed`` keeps it); the "cold" row clears that store
    first. The old revision keeps none: both of its "exact" rows are cold.
    """
    def sub(name: str) -> types.ModuleType:
        return importlib.import_module(f"{ts.__name__}.{name}")

    continue_gait = sub("gait.continuation").continue_gait
    floquet_ = sub("gait.stability").floquet
    report = sub("gait.robustness").robustness_report
    try:
        jacobians = sub("simulation._packed")._JACOBIANS
    except ModuleNotFoundError:
        jacobians = {}
    p = ts.preset("table6.1")
    g = ts.find_gait(p)
    z = sub("gait.fixed_point").GaitProblem.from_params(p).encode(g)
    pn = dataclasses.replace(p, v0=p.v0 * 1.02)

    def cold_exact() -> object:
        jacobians.clear()
        return floquet_(g)

    tasks = {
        "gait search (find_gait)": lambda: ts.find_gait(p),
        "gait search from the gait": lambda: ts.find_gait(p, guess=z),
        "gait search from a neighbour": lambda: ts.find_gait(pn, guess=z),
        "continuation, 5 points": lambda: continue_gait(g, "v0", np.linspace(1.8, 2.0, 5)),
        "multipliers, exact, cold (floquet)": cold_exact,
        "multipliers, exact, after find_gait": lambda: floquet_(g),
        "multipliers, fd (floquet)": lambda: floquet_(g, method="fd"),
        "robustness triple": lambda: report(g),
    }
    return tasks, {"z": z, "exact": floquet_(g).multipliers,
                   "fd": floquet_(g, method="fd").multipliers, "report": report(g)}


def floors(gait: tslip.Gait) -> dict[str, Callable[[], object]]:
    """The compiled work alone of three tasks, on arrays packed once: what no wrapper
    change can remove (the least each task can cost at its integrator and tolerance).

    * Floquet exact, cold: one call of the variational kernel (``stride_jacobian``,
      DOP853 at 1e-12, the options ``floquet`` uses);
    * Floquet fd: the ten stride kernels of eq. B.2's central differences;
    * robustness triple: the very runs ``robustness_report`` makes (recorded from
      one call: the same packed inputs, the same order), each a compiled ``run_row``.
    """
    from tslip.gait.fixed_point import TIGHT
    from tslip.simulation import _variational as va
    from tslip.simulation._stride import run_row

    P, O = pk.pack_params(gait.params), TIGHT.packed()  # noqa: E741 - the kernels' names
    q = gait.state.section()
    td, tx, th = _packed.touchdown(q), np.empty(0), np.array([0.0])
    J, out = np.empty((5, 5)), np.empty(pk.NOUT)
    rows = [_packed.touchdown(q + d) for d in np.vstack([np.eye(5), -np.eye(5)]) * 1e-5]
    jac, stride = va.stride_jacobian, kn.stride
    no_rec = np.empty((0, pk.NREC))

    calls: list[tuple] = []
    real_run = _packed.run

    def record(*args: object) -> tuple[int, int]:
        calls.append(tuple(a.copy() if isinstance(a, np.ndarray) else a for a in args))
        return real_run(*args)

    _packed.run = record
    try:
        robustness_report(gait)
    finally:
        _packed.run = real_run

    def runs() -> None:
        for P_, O_, td_, n, tx_, th_ in calls:
            run_row(P_, O_, td_, n, tx_, th_, np.empty((n + 1, pk.NTD)))

    return {
        "multipliers, exact, cold (floquet)": lambda: jac(P, O, td, tx, th, J, out),
        "multipliers, fd (floquet)": lambda: [stride(P, O, r, tx, th, no_rec, 0.0, out)
                                              for r in rows],
        "robustness triple": runs,
    }


def today_ratios(rounds: int) -> None:
    """Each task on this tree and on BASELINE_REV, in this process, interleaved call by call.

    Where :func:`floors` has a row, the floor is timed in the same rounds, and
    ``max`` is old / floor: the largest speed-up possible without a faster
    integrator or fewer strides.
    """
    numba.set_num_threads(1)
    new, res_new = today_tasks(tslip)
    old, res_old = today_tasks(import_at(BASELINE_REV))
    low = floors(tslip.find_gait(tslip.preset("table6.1")))
    print(f"against today's code (revision {BASELINE_REV}, imported in this process), one "
          f"thread, {rounds} interleaved rounds: best (and median)")
    print(f"{'task':<38}{'new':>11}{'old':>11}{'speed-up':>10}{'(median)':>10}{'target':>8}"
          f"{'floor':>11}{'max':>7}")
    for name in new:
        fns = {"new": new[name], "old": old[name]}
        if name in low:
            fns["floor"] = low[name]
        t = ab(fns, rounds)
        best, med = t.ratio("old", "new")
        tgt = ("met" if best >= 4.0 else "MISSED") if name in TARGETS else ""
        bound = (f"{t['floor'] * 1e3:>9.2f}ms{t.ratio('old', 'floor')[0]:>6.1f}x"
                 if name in low else "")
        print(f"{name:<38}{t['new'] * 1e3:>9.2f}ms{t['old'] * 1e3:>9.2f}ms{best:>9.1f}x"
              f"{med:>9.1f}x{tgt:>8}{bound}")
    print(f"same answers? |z new - old| {np.max(np.abs(res_new['z'] - res_old['z'])):.1e}; "
          f"|lambda| max: exact {np.max(np.abs(res_new['exact'])):.8f} / "
          f"{np.max(np.abs(res_old['exact'])):.8f}, fd {np.max(np.abs(res_new['fd'])):.8f} / "
          f"{np.max(np.abs(res_old['fd'])):.8f}")
    print("robustness limits new / old: " + ", ".join(
        f"{a.kind} {a.limit:+.5f} / {b.limit:+.5f}"
        for a, b in zip(res_new["report"].limits, res_old["report"].limits, strict=True)))


# ---------------------------------------------------------------------------


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--scipy-search-tol", type=float, default=1e-2,
                    help="search tolerance of the scipy robustness triple (scaled to 1e-4)")
    ap.add_argument("--no-today", action="store_true",
                    help=f"skip the comparison with today's code ({BASELINE_REV})")
    ap.add_argument("--only-today", action="store_true",
                    help="only the comparison with today's code")
    ap.add_argument("--rounds", type=int, default=10,
                    help="interleaved new/old rounds of the comparison with today's code")
    args = ap.parse_args()
    if not args.no_today:
        today_ratios(args.rounds)
        print()
    if args.only_today:
        return

    params = tslip.preset("table6.1")
    gait = tslip.find_gait(params)  # compile / load caches
    floquet(gait, method="fd")
    floquet(gait, method="exact")
    robustness_report(gait, tol=1e-2)
    numba.set_num_threads(1)

    # gait search
    t_gait = best_of(lambda: tslip.find_gait(params), args.repeat)
    prob = GaitProblem.from_params(params)
    _, err, n_starts = newton_solve(prob.residual, prob.guesses())
    starts = list(itertools.islice(prob.guesses(), n_starts))
    z_sp, err_sp = scipy_gait(prob, starts, 1e-10)
    t_gait_sp = best_of(lambda: scipy_gait(prob, starts, 1e-10), 3)
    z_pk = prob.encode(gait)

    # multipliers
    t_fd = best_of(lambda: floquet(gait, method="fd"), args.repeat)
    def cold_exact():  # without the Jacobian find_gait kept for this gait
        _packed._JACOBIANS.clear()
        floquet(gait, method="exact")

    t_ex = best_of(cold_exact, args.repeat)
    q = gait.state.section()
    lam_sp = scipy_multipliers(gait.params, q)
    t_fd_sp = best_of(lambda: scipy_multipliers(gait.params, q), 3)
    lam_pk = floquet(gait, method="fd").multipliers

    # robustness triple
    report = robustness_report(gait)
    t_rob = best_of(lambda: robustness_report(gait), max(1, args.repeat // 2))
    t_rob_nocheck = best_of(lambda: robustness_report(gait, check=False), max(1, args.repeat // 2))
    n_full, _ = package_strides(gait, 1e-4)
    n_coarse_pk, lim_coarse_pk = package_strides(gait, args.scipy_search_tol)
    count = [0]
    t0 = time.perf_counter()
    lim_sp = [-limit_search(scipy_survives(gait, k, THESIS, count), tol=args.scipy_search_tol).lo
              for k in KINDS]
    t_rob_sp_coarse = time.perf_counter() - t0
    t_rob_sp = t_rob_sp_coarse * n_full / count[0]

    print(f"Table 6.1 model, one core (numba threads 1), best of {args.repeat}")
    print(f"gait: residual {gait.residual:.1e} (scipy {err_sp:.1e}, |z diff| "
          f"{np.max(np.abs(z_sp - z_pk)):.1e}); {n_starts} start(s) tried")
    print(f"multipliers |lambda|max: fd {np.max(np.abs(lam_pk)):.6f}, scipy fd "
          f"{np.max(np.abs(lam_sp)):.6f}")
    print("robustness (sign -1, tol 1e-4): " + ", ".join(
        f"{lim.kind} {lim.limit:+.4f} ({lim.status.name}, stride {lim.fall_stride})"
        for lim in report.limits))
    print(f"  at search tol {args.scipy_search_tol:g}: package "
          + ", ".join(f"{v:+.4f}" for v in lim_coarse_pk) + "; scipy "
          + ", ".join(f"{v:+.4f}" for v in lim_sp))
    print(f"  strides simulated: full triple {n_full}, at tol {args.scipy_search_tol:g}: "
          f"package {n_coarse_pk}, scipy {count[0]}; batches {report.n_batches}; runs ending "
          f"in an integration error {sum(lim.n_errors for lim in report.limits)}")
    print()
    print(f"{'task':<34}{'package':>12}{'scipy':>12}{'speed-up':>10}{'target':>10}")
    rows = [
        ("gait search (find_gait)", t_gait, t_gait_sp, 20e-3),
        ("multipliers, fd (floquet)", t_fd, t_fd_sp, 5e-3),
        ("multipliers, exact (floquet)", t_ex, t_fd_sp, None),
        ("robustness triple", t_rob, t_rob_sp, 0.5),
        ("robustness triple, check=False", t_rob_nocheck, t_rob_sp, 0.5),
    ]
    for name, t, ref, target in rows:
        tgt = "" if target is None else ("met" if t < target else "MISSED")
        print(f"{name:<34}{t * 1e3:>10.2f}ms{ref * 1e3:>10.1f}ms{ref / t:>9.0f}x{tgt:>10}")
    print(f"(scipy robustness triple: {t_rob_sp_coarse:.2f} s measured at search tol "
          f"{args.scipy_search_tol:g}, scaled by strides {n_full}/{count[0]})")


if __name__ == "__main__":
    main()
