"""The touch-down map on packed arrays, for the analyses' inner loops.

:func:`tslip.step_map` and :func:`tslip.step_jacobian` check their inputs and
pack ``Params`` and ``IntegratorOptions`` on every call; gait search,
continuation, Floquet multipliers and robustness call the map thousands of
times with the same parameters. They validate and pack once per public call
(``pack_params``, ``IntegratorOptions.packed``) and then call these entry
points, which take

* ``P``: packed parameters (``model._pack.pack_params``), possibly with the
  gait search's unknowns written into it (``P_ALPHA``, ``P_C0``);
* ``O``: packed integrator options;
* ``q``: the 5-D section ``(beta, phi, xd, yd, phid)``, finite;
* ``h``: the ground height of the touch-down and of the whole stride.

Nothing here checks its arguments: the callers have. The kernels are the
same as the public functions', so the results are identical bit for bit.
"""

from __future__ import annotations

import math
import threading
from typing import Any

import numpy as np

from ..model import _pack as pk
from . import _kernels as kn

__all__ = ["touchdown", "stride_map", "stride_map_at", "stride_jacobian", "check_exact",
           "alpha_r_column", "run"]

_TX = np.empty(0)  # flat ground: no terrain breakpoints


#: The touch-down vector's layout that :func:`touchdown` builds directly.
if (pk.TD_X, pk.TD_H, pk.NTD) != (5, 6, 7):  # pragma: no cover - a layout change
    raise ImportError("_packed.touchdown assumes the touch-down layout (q, x, h)")
_TH0 = np.zeros(1)  # flat ground at h = +0.0: the kernels only read it


def touchdown(q: np.ndarray | tuple[float, ...], h: float = 0.0) -> np.ndarray:
    """The kernels' touch-down vector ``(beta, phi, xd, yd, phid, x=0, h)``.

    ``q``: the section as an array or as a tuple of floats. Built from one list
    (a third of zeros-then-fill on this 7-vector; the same values).
    """
    return np.array([*(q.tolist() if isinstance(q, np.ndarray) else q), 0.0, float(h)])


def stride_map(P: np.ndarray, O: np.ndarray, q: np.ndarray, h: float,  # noqa: E741
               out: np.ndarray) -> int:
    """One stride on flat ground at height ``h``; fills ``out`` (``OUT_*``), returns the status.

    The next section is ``out[OUT_TD:OUT_TD + 5]``; as :func:`tslip.step_map`.
    """
    return stride_map_at(P, O, q.tolist(), h, out)


def stride_map_at(P: np.ndarray, O: np.ndarray,  # noqa: E741
                  q: tuple[float, ...] | list[float], h: float, out: np.ndarray) -> int:
    """:func:`stride_map` from the section as a tuple of five floats (the gait search
    holds it so, without building an array per stride)."""
    return int(kn.section_map(P, O, *q, float(h), out))


#: The last exact Jacobians, keyed by their exact inputs (P, O, q, h): gait search
#: computes the Jacobian at the gait it returns, and the Floquet multipliers of that
#: gait (also in continuation and the robustness check) need the same one.
_JACOBIANS: dict[bytes, tuple[int, np.ndarray, np.ndarray]] = {}
_JACOBIANS_KEPT = 64
_JACOBIANS_LOCK = threading.Lock()
_VA: Any = None  # _variational, once imported


def _variational() -> Any:
    """:mod:`._variational`, imported on first use (importing it loads its kernels)."""
    global _VA
    if _VA is None:
        from . import _variational as va

        _VA = va
    return _VA


def check_exact(P: np.ndarray) -> None:
    """Refuse an exact Jacobian for a leg spring exponent below 1 (one-line ``ValueError``).

    ``dF_s/dl = -k n |x|^(n-1)`` is infinite at touch-down (``x = 0``) when ``n < 1``,
    so the variational equations have no finite start; finite differences work.
    """
    n = P[pk.P_NEXP]
    if n < 1.0:
        raise ValueError(f"leg_exponent {n:g} < 1 has no exact Jacobian: the leg stiffness "
                         "k n |x|^(n-1) is infinite at touch-down; use finite differences "
                         "(method='fd')")


def stride_jacobian(P: np.ndarray, O: np.ndarray,  # noqa: E741
                    q: np.ndarray | tuple[float, ...], h: float, J: np.ndarray,
                    out: np.ndarray) -> int:
    """As :func:`stride_map`, and the exact Jacobian ``dq'/dq`` (5 x 5) into ``J``.

    Variational equations through the stance steps plus the saltation terms
    (:mod:`._variational`); as :func:`tslip.step_jacobian`. The kernel is
    deterministic, so a call with the same inputs as one of the last
    ``_JACOBIANS_KEPT`` returns its stored result (identical bits).
    """
    check_exact(P)
    td = touchdown(q, h)
    key = P.tobytes() + O.tobytes() + td.tobytes()
    hit = _JACOBIANS.get(key)  # one atomic look-up: the lock guards only the eviction
    if hit is not None:
        J[:] = hit[1]
        out[:] = hit[2]
        return hit[0]
    th = _TH0 if h == 0.0 and math.copysign(1.0, h) > 0.0 else np.array([h])
    st = int(_variational().stride_jacobian(P, O, td, _TX, th, J, out))
    with _JACOBIANS_LOCK:
        if len(_JACOBIANS) >= _JACOBIANS_KEPT:
            del _JACOBIANS[next(iter(_JACOBIANS))]  # the oldest
        _JACOBIANS[key] = (st, J.copy(), out.copy())
    return st


def stop_binds(P: np.ndarray, yd0: float, tf: float) -> bool:
    """Whether a flight of ``tf`` after a lift-off at ``ydot = yd0`` touches down stopped.

    The retraction stop (Section 7.5; docs/conventions.md) holds the hip angle
    at ``max(alpha_r, alpha_stop)`` (``min`` for ``omega_r < 0``) from
    :func:`._kernels.stop_time` on; False without a stop or with ``omega_r = 0``
    (the kernels' rule, :func:`._flight.stop_binds`).
    """
    return bool(kn.stop_binds(P, yd0, tf))


def alpha_r_column(P: np.ndarray, out: np.ndarray) -> np.ndarray:
    """``dq'/d alpha_r`` of a completed stride (5,), from its ``out`` vector.

    ``alpha_r`` only moves the swing leg in flight (eq. 2.17): the leg angle
    ``beta(t) = alpha_r + omega_r (t - t_apex)^+ [- phi(t)]`` (``t_apex = 0``
    for the lift-off clock, :func:`._kernels.retraction_start`; ``alpha_r``
    shifts the whole flight's angle alike) and so the touch-down time
    ``t_TD``, a root of the foot height ``f(t) = y_hip(t) - l0 sin beta(t) - H``.
    With ``df/d alpha_r = -l0 cos beta`` the implicit derivative is
    ``dt_TD/d alpha_r = l0 cos beta / f'(t_TD)``, and ``q' = (beta(t),
    phi(t), xd, yd - g t, phid)`` moves by its time derivative times that,
    plus 1 in ``beta``. A touch-down held at ``alpha_stop`` by the retraction
    stop (:func:`stop_binds`) does not depend on ``alpha_r``: the column is 0
    (a reset beyond the stop is held at ``alpha_r``, as without retraction).
    """
    col = np.empty(5)
    kn.alpha_r_column(P, out, col)  # compiled (:func:`._flight.alpha_r_column`)
    return col


def run(P: np.ndarray, O: np.ndarray, td: np.ndarray, n_steps: int,  # noqa: E741
        tx: np.ndarray, th: np.ndarray) -> tuple[int, int]:
    """Up to ``n_steps`` strides from the touch-down vector ``td`` on terrain ``(tx, th)``.

    Stops at the first stride that does not end in a touch-down. Returns
    ``(status, strides completed)``, as one row of :func:`tslip.run_batch`.
    """
    hist = np.empty((n_steps + 1, pk.NTD))
    st, done, _ = kn.run_row(P, O, td, n_steps, tx, th, hist)  # the strides in compiled code
    return int(st), int(done)
