"""A study point against its compiled work (issue 25's last ratio; issue 41 made it so).

``measure(rounds)`` runs one catalogue study serially (``workers=1``, in this
process) into a fresh folder per round (so every point is computed and cached, as
a first run does) and returns the median over the rounds of

* the seconds per point of the whole ``run_study`` call (its fixed costs, such
  as the lock, ``run.json`` and ``results.parquet``, spread over the points), and
* the seconds per point of its compiled work: the compiled kernel calls the study
  makes, replayed inside compiled code. One extra round, untimed, records every
  call of the stride map (``tslip.simulation._kernels.section_map``, what
  ``_packed.stride_map`` calls; ``SECTION_MAP`` or ``STRIDE`` on checkouts before it), of the stride
  with its exact Jacobian (``tslip.simulation._variational.stride_jacobian``;
  calls the Jacobian cache of ``_packed`` answers make none) and of the touch-down's
  derivative in ``alpha_r`` (``_kernels.alpha_r_column``), with copies of their
  arguments. Each round then calls the same kernels with the same arguments from
  one compiled loop per kernel (:func:`_replay`), so no Python dispatch (0.6-1.3 us
  a call, a tenth of a Table 6.1 stride) counts as compiled work, as it did when
  each call was wrapped in a timer. A first replay is checked: every argument ends
  as the study's call left it, bit for bit, and the statuses agree.

Both are process CPU seconds (``time.process_time``: the study and the replay run
in this thread), as ``bench_limit.py``'s other lines, or wall seconds with
``clock="wall"``; a round times the study and the replay back to back,
alternating which comes first.

The study is ``grid_v3`` (Figure 4.10, local velocity control at v0 = 3,
k x beta0, Floquet multipliers) at 25 x 25 points: 2-D seeded continuation,
the bulk of ``tslip reproduce``'s points. ``benchmarks/bench_limit.py``
prints the ratio as ``study point / its compiled work``; run alone::

    python benchmarks/_study_limit.py [--rounds 5] [--wall]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit
from numba.core.registry import CPUDispatcher

STUDY, GRID = "grid_v3", 25
CLOCKS = {"wall": time.perf_counter, "cpu": time.process_time}

#: A recorded call: (compiled kernel, copies of its arguments before and after the call,
#: the status it returned, or None for a kernel that returns nothing).
Call = tuple[Any, tuple[Any, ...], tuple[Any, ...], "int | None"]


def _kernel_of(obj: Any, args: tuple[Any, ...]) -> Any:
    """The compiled kernel a call of ``obj`` runs: ``obj`` itself, or for a kernel chosen
    by the method in the options (``_specialise.ByMethod``, ``O`` the second argument)
    the chosen copy. (The one place that knows how the kernels are held.)"""
    if isinstance(obj, CPUDispatcher):
        return obj
    from tslip.model._pack import O_METHOD

    return obj.kernels[int(args[1][O_METHOD])]


def _copies(args: tuple[Any, ...]) -> tuple[Any, ...]:
    return tuple(a.copy() if isinstance(a, np.ndarray) else a for a in args)


def _recording(obj: Any, calls: list[Call]) -> Any:
    """``obj`` (a kernel, a tuple of kernels by method, or a ``ByMethod``) with each call
    appended to ``calls``."""
    if isinstance(obj, tuple):
        return tuple(_recording(k, calls) for k in obj)

    def call(*args: Any) -> Any:
        before = _copies(args)
        status = obj(*args)
        calls.append((_kernel_of(obj, args), before, _copies(args),
                      None if status is None else int(status)))
        return status

    return call


@cache
def _replay(n_args: int, status: bool) -> Callable[..., int]:
    """``replay(kernel, a0, ..., a{n-1})``: ``kernel(a0[i], ..., a{n-1}[i])`` for every ``i``
    in one compiled loop, returning the sum of the statuses (0 if ``status`` is False: a
    kernel that returns nothing). Each ``a_j`` stacks the ``j``-th argument of the recorded
    calls (scalars into a 1-D array, arrays along a new first axis), so any kernel
    signature replays."""
    names = [f"a{j}" for j in range(n_args)]
    call = f"kernel({', '.join(n + '[i]' for n in names)})"
    src = (f"def replay(kernel, {', '.join(names)}):\n"
           f"    st = 0\n"
           f"    for i in range(a0.shape[0]):\n"
           f"        {'st += ' if status else ''}{call}\n"
           f"    return st\n")
    ns: dict[str, Any] = {}
    exec(src, ns)  # noqa: S102 - generated from the arity alone
    return njit(cache=False)(ns["replay"])


def _stack(values: list[Any]) -> np.ndarray:
    return np.ascontiguousarray(np.stack([np.asarray(v) for v in values]))


class _Replay:
    """One kernel's recorded calls, replayed from one compiled loop (:func:`_replay`)."""

    def __init__(self, group: list[Call]) -> None:
        self.kernel = group[0][0]
        n = len(group[0][1])
        self.before = tuple(_stack([c[1][j] for c in group]) for j in range(n))
        self.after = tuple(_stack([c[2][j] for c in group]) for j in range(n))
        self.status = sum(c[3] or 0 for c in group)
        self.fn = _replay(n, group[0][3] is not None)

    def fresh(self) -> tuple[np.ndarray, ...]:
        """The recorded arguments, copied (the calls write their outputs into them)."""
        return tuple(a.copy() for a in self.before)

    def run(self, args: tuple[np.ndarray, ...]) -> int:
        return self.fn(self.kernel, *args)

    def check(self) -> None:
        """Replay once (compiling the loop) and refuse unless every argument ends as the
        study's call left it, bit for bit, and the statuses sum as there: the replay does
        the study's work."""
        args = self.fresh()
        st = self.run(args)
        same = all(a.tobytes() == b.tobytes() for a, b in zip(args, self.after, strict=True))
        if st != self.status or not same:
            raise RuntimeError(f"{self.kernel.py_func.__name__}: the replay differs from the "
                               f"study's calls (statuses {st} vs {self.status})")


def _replays(calls: list[Call]) -> list[_Replay]:
    """One replay per kernel (and arity), over that kernel's recorded calls."""
    groups: dict[tuple[int, int], list[Call]] = {}
    for c in calls:
        groups.setdefault((id(c[0]), len(c[1])), []).append(c)
    return [_Replay(group) for group in groups.values()]


def _run_study(spec: Any) -> None:
    from tslip.sweeps.run import run_study

    with tempfile.TemporaryDirectory() as tmp:
        run_study(spec, Path(tmp) / "study", workers=1)


def _record(spec: Any) -> list[Call]:
    """One round of the study with its kernel calls recorded (this also loads the kernels)."""
    from tslip.simulation import _kernels as kn
    from tslip.simulation import _variational as va

    # the map's kernel: one for both methods (section_map); before it a tuple by method
    # (SECTION_MAP, calling STRIDE inside; STRIDE before that)
    maps = next(n for n in ("section_map", "SECTION_MAP", "STRIDE") if hasattr(kn, n))
    hooked = [(kn, maps), (va, "stride_jacobian"), (kn, "alpha_r_column")]
    saved = [getattr(mod, name) for mod, name in hooked]
    calls: list[list[Call]] = [[] for _ in hooked]
    for (mod, name), obj, kept in zip(hooked, saved, calls, strict=True):
        setattr(mod, name, _recording(obj, kept))
    try:
        _run_study(spec)
    finally:
        for (mod, name), obj in zip(hooked, saved, strict=True):
            setattr(mod, name, obj)
    for (mod, name), kept in zip(hooked[:2], calls, strict=False):
        if not kept:  # the analyses reach the kernel by another name now
            raise RuntimeError(f"the study made no call of {mod.__name__}.{name}: "
                               "update _study_limit._record")
    return [c for kept in calls for c in kept]


def measure(rounds: int, clock: str = "cpu") -> tuple[float, float]:
    """Median seconds of one study point and of its compiled work (``clock``: cpu, wall)."""
    from tslip.sweeps.catalogue import study

    now = CLOCKS[clock]
    spec = study(STUDY, quick=True).with_resolution([GRID, GRID])
    replays = _replays(_record(spec))
    for r in replays:
        r.check()  # and compiles the replay loops
    points: list[float] = []
    kernels: list[float] = []
    for i in range(rounds):
        for what in ("study", "replay") if i % 2 == 0 else ("replay", "study"):
            if what == "study":
                t0 = now()
                _run_study(spec)
                points.append((now() - t0) / spec.n_points)
            else:
                args = [r.fresh() for r in replays]
                t0 = now()
                for r, a in zip(replays, args, strict=True):
                    r.run(a)
                kernels.append((now() - t0) / spec.n_points)
    return statistics.median(points), statistics.median(kernels)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--wall", action="store_true", help="wall time instead of CPU time")
    a = ap.parse_args()
    clock = "wall" if a.wall else "cpu"
    point, kernel = measure(a.rounds, clock)
    print(f"[{clock}] study point {point * 1e3:.3f} ms, its compiled work "
          f"{kernel * 1e3:.3f} ms")
    print(f"study point / its compiled work: {point / kernel:.2f}")


if __name__ == "__main__":
    main()
