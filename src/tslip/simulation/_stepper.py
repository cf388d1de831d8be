"""The stance integrator's steps: the :mod:`._rk` stage loop with the stance ``rhs``, events.

Private (see :mod:`._kernels`). Small ``inline="always"`` functions taking the
Runge-Kutta pair ``method`` as an argument: the stride kernels
(:func:`._stride._make_stride`, which hold the step-size and event loop) pass it
as a compile-time constant, so each compiled stride holds one method's stage loop.
The two called once a stride or so, :func:`initial_step` and :func:`event_root`,
compile on their own instead (``method`` a run-time argument; the same
arithmetic): numba's type inference of the stride's body, most of a cold
start, shrinks by their copies.
"""

from __future__ import annotations

from numba import njit

from .._kernel_cache import check as _check_cache
from . import _rk
from ._rk import _INLINE, _JIT
from ._stance import NSTATE, event_values, grf, rhs


@njit(**_INLINE)
def rk_step(P, method, y, h, K, ytmp, ynew):
    """One step of size ``h`` from ``y`` with ``K[0] = f(y)`` (see :mod:`._rk`).

    Fills the stages ``K[1..ns]`` and ``ynew``; ``K[ns] = f(ynew)`` (FSAL). With
    a constant ``method`` the loops over the tableau compile like a hand-unrolled
    stepper, which the cheap stance right-hand side makes worth it
    (``benchmarks/bench_rk.py``).
    """
    ns = _rk.n_stages(method)
    for s in range(1, ns):
        _rk.stage_state(method, NSTATE, y, h, K, s, ytmp)
        rhs(P, ytmp, K[s])
    _rk.stage_state(method, NSTATE, y, h, K, ns, ynew)
    rhs(P, ynew, K[ns])


@njit(**_INLINE)
def dense_output(P, method, y, ynew, h, K, R, ytmp):
    """Continuous extension of the step just taken (extra stages for dop853)."""
    ns = _rk.n_stages(method)
    for s in range(ns + 1, ns + 1 + _rk.n_extra(method)):
        _rk.stage_state(method, NSTATE, y, h, K, s, ytmp)
        rhs(P, ytmp, K[s])
    _rk.dense_coeffs_inline(method, y, ynew, h, K, R)


@njit(**_JIT)
def initial_step(P, method, y, f0, rtol, atol, ytmp, f1):
    """Starting step size (Hairer, Norsett & Wanner, II.4)."""
    h0, d1 = _rk.initial_probe(y, f0, rtol, atol, ytmp)
    rhs(P, ytmp, f1)
    return _rk.initial_step(method, y, f0, f1, h0, d1, rtol, atol)


@njit(**_JIT)
def event_root(P, method, R, ev, g_lo, g_hi, ytmp, gv, st):
    """Root in theta of event ``ev`` on the dense output (Illinois method)."""
    _rk.root_start_inline(st, g_lo, g_hi)
    for _ in range(100):
        c = _rk.root_guess_inline(st)
        _rk.dense_eval_inline(method, R, c, ytmp)
        event_values(P, ytmp, gv)
        if _rk.root_update_inline(st, c, gv[ev], 1e-15):
            break
    return st[1]  # the earliest theta known to be at or past the crossing


@njit(**_JIT)
def record_row(P, rec, row, t, y):
    """Stance record row ``row``: ``t, y, F_x, F_y, tau``.

    Compiled on its own, not inlined: a recording stride writes rows from four places.
    """
    rec[row, 0] = t
    for i in range(NSTATE):
        rec[row, 1 + i] = y[i]
    fx, fy, tau = grf(P, y)
    rec[row, 7] = fx
    rec[row, 8] = fy
    rec[row, 9] = tau


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(record_row, __file__)
