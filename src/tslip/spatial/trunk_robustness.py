"""Lateral disturbances of a 3-D TSLIP gait: the largest it survives for N strides.

Issue 43, Part 2: "a lateral push, a roll-rate and a yaw-rate disturbance beside
the planar ones in robustness" (thesis Section 3.1.3 for the planar ones,
:mod:`tslip.gait.robustness`). Each is applied **just after the right
touch-down that starts stride 0** (the gait's section vector ``x``,
:mod:`tslip.spatial.trunk_section`), with the foot where the gait put it:

``"lateral_push"`` (``dvz`` [g^1/2 L^1/2])
    added to the CoM's lateral velocity ``vz`` (world z, the runner's right),
    keeping the rest of the state;
``"roll_rate"`` (``dw_roll`` [rad g^1/2 L^-1/2])
    added to the body roll rate (about the trunk's forward axis ``x_b``);
``"yaw_rate"`` (``dw_yaw`` [rad g^1/2 L^-1/2])
    added to the body yaw rate (about the trunk's long axis ``y_b``).

The runner survives when ``n_steps`` strides (default 25, the thesis's) end
without a fall or integration error; a failure is named by its
:class:`~tslip.spatial.trunk.TrunkStatus` (a crossed leg, the hip on the ground,
...) and the stride it happened in.

**A finite-horizon measure.** The symmetric gaits of the 3-D Table 2.1 TSLIP
are laterally unstable (a real multiplier of about 1.2-1.9 per two strides:
docs/analyses/spatial_tslip.md), so every disturbance, however small, grows
and the runner eventually falls: "survives ``n_steps`` strides" is then the
statement that the growth takes longer than ``n_steps`` strides, and the limits
shrink roughly by the multiplier for every two strides added to ``n_steps``.
They compare gaits and couplings on the same horizon; they are not a basin of
attraction.

The search (:func:`lateral_limit`) is the planar one's,
:func:`tslip._first_failure.limit_search`, one magnitude a call: a grid scan
``h, 2h, ...`` up to the first failing magnitude, then bisection of the bracket to
``tol``; the limit is the last surviving magnitude ``lo`` and ``first_failing``
(within ``tol`` of it) fails. As there, survival need not be monotone: the limit is
the first failure at resolution ``h``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._first_failure import limit_search
from .._results import Result, frame
from ..simulation.options import IntegratorOptions
from .trunk import TrunkStatus, trunk_step
from .trunk_parameters import TrunkParams
from .trunk_section import from_section

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["KINDS", "UNITS", "LIMIT_UNITS", "GRID_STEPS", "LateralLimit", "disturbed_run",
           "lateral_limit", "lateral_limits"]

#: The disturbances and the section component each is added to (module docstring).
KINDS: dict[str, int] = {"lateral_push": 6, "roll_rate": 7, "yaw_rate": 8}
#: Their units.
UNITS: dict[str, str] = {"lateral_push": "g^1/2 L^1/2", "roll_rate": "rad g^1/2 L^-1/2",
                         "yaw_rate": "rad g^1/2 L^-1/2"}
#: Default grid steps: about 1/20-1/30 of the limits of the 3-D Table 2.1 gait (splay 0.05,
#: 25 strides; docs/analyses/spatial_tslip.md): push +0.00033/-0.00025, roll rate
#: +0.00025/-0.00019, yaw rate +0.000047/-0.000035, all ending in a crossed leg in
#: strides 23-24. Tiny, since the unstable lateral mode grows some 1000-fold in 25
#: strides; a stabler gait has larger limits and needs a larger ``h``.
GRID_STEPS: dict[str, float] = {"lateral_push": 1e-5, "roll_rate": 1e-5, "yaw_rate": 2e-6}


#: Units of a limit's table: the disturbance's own unit is in its ``unit`` column.
LIMIT_UNITS: dict[str, str] = {**dict.fromkeys(("kind", "sign", "unit", "status", "fall_stride",
                                                "n_runs"), "-"),
                               "limit": "column unit", "first_failing": "column unit"}


@dataclass(frozen=True, slots=True, repr=False)
class LateralLimit(Result):
    """The limit of one disturbance in one direction (module docstring).

    A :class:`~tslip._results.Result` (a table of one row, as the planar
    :class:`tslip.gait.robustness.RobustnessLimit`).

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    sign : int
        Direction searched (+1: to the right / positive rate, -1 the opposite).
    limit : float
        The largest surviving disturbance, signed [:data:`UNITS`]; ``sign * inf`` if
        nothing failed up to ``max_magnitude``.
    first_failing : float
        The failing disturbance that bounds it (``|first_failing - limit| <= tol``).
    status : TrunkStatus
        How the ``first_failing`` run ended.
    fall_stride : int
        The stride (0-based) it ended in; -1 if none.
    n_runs : int
        Disturbed runs simulated.
    """

    kind: str
    sign: int
    limit: float
    first_failing: float
    status: TrunkStatus
    fall_stride: int
    n_runs: int

    @property
    def unit(self) -> str:
        return UNITS[self.kind]

    def to_dataframe(self) -> pd.DataFrame:
        """One row; ``limit`` and ``first_failing`` are in the unit of column ``unit``."""
        row: dict[str, Any] = {"kind": self.kind, "sign": self.sign, "limit": self.limit,
                               "first_failing": self.first_failing, "unit": self.unit,
                               "status": self.status.name, "fall_stride": self.fall_stride,
                               "n_runs": self.n_runs}
        return frame([row], LIMIT_UNITS)


def _check(kind: str, n_steps: int) -> None:
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {', '.join(KINDS)}, got {kind!r}")
    if not isinstance(n_steps, (int, np.integer)) or isinstance(n_steps, bool) or n_steps < 1:
        raise ValueError(f"n_steps must be an integer >= 1, got {n_steps!r}")


def disturbed_run(params: TrunkParams, x: np.ndarray, kind: str, value: float, *,
                  n_steps: int = 25, options: IntegratorOptions | None = None,
                  ) -> tuple[TrunkStatus, int]:
    """``n_steps`` strides from the right touch-down ``x`` with the disturbance ``value``
    (signed, [:data:`UNITS`]) added: ``(OK, -1)``, or the failure and its stride."""
    _check(kind, n_steps)
    z = np.array(x, dtype=float)
    z[KINDS[kind]] += value
    state = from_section(params, z, 1)
    for i in range(int(n_steps)):
        r = trunk_step(params, state, options=options)
        if not r.ok or r.state is None:
            return r.status, i
        state = r.state
    return TrunkStatus.OK, -1


def lateral_limit(params: TrunkParams, x: np.ndarray, kind: str, *, sign: int = 1,
                  n_steps: int = 25, h: float | None = None, tol: float | None = None,
                  max_magnitude: float = 1.0, options: IntegratorOptions | None = None,
                  ) -> LateralLimit:
    """The largest disturbance ``kind`` in direction ``sign`` that the gait ``x`` of
    ``params`` survives for ``n_steps`` strides (module docstring: a finite horizon), on
    the grid of step ``h`` (default :data:`GRID_STEPS`), the bracket bisected to ``tol``
    (default ``h / 10``).

    Raises
    ------
    ValueError
        In one line for an unknown ``kind``, ``sign`` not +-1, ``n_steps < 1``, a
        non-positive ``h``/``tol``/``max_magnitude``, or a gait that fails undisturbed.
    """
    _check(kind, n_steps)
    if sign not in (1, -1):
        raise ValueError(f"sign must be 1 or -1, got {sign!r}")
    step = GRID_STEPS[kind] if h is None else h
    tol = step / 10.0 if tol is None else tol
    for name, v in (("h", step), ("tol", tol), ("max_magnitude", max_magnitude)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be in (0, inf), got {v!r}")
    st0, i0 = disturbed_run(params, x, kind, 0.0, n_steps=n_steps, options=options)
    if st0 != TrunkStatus.OK:
        raise ValueError(f"lateral_limit: the undisturbed gait fails ({st0.name} in stride "
                         f"{i0}); pass a periodic gait")
    outcomes: dict[float, tuple[TrunkStatus, int]] = {}

    def survives(m: np.ndarray) -> np.ndarray:
        for v in m.tolist():
            outcomes[v] = disturbed_run(params, x, kind, sign * v, n_steps=n_steps,
                                        options=options)
        return np.array([outcomes[v][0] == TrunkStatus.OK for v in m.tolist()])

    s = limit_search(survives, h=step, tol=tol, ladder=1, k=1, max_magnitude=max_magnitude)
    fail = outcomes.get(s.hi, (TrunkStatus.OK, -1))
    return LateralLimit(kind, sign, sign * s.lo, sign * s.hi, fail[0], fail[1], s.n_evals + 1)


def lateral_limits(params: TrunkParams, x: np.ndarray, *,
                   kinds: Sequence[str] = tuple(KINDS), signs: Sequence[int] = (1, -1),
                   n_steps: int = 25, tol: float | None = None,
                   options: IntegratorOptions | None = None) -> tuple[LateralLimit, ...]:
    """:func:`lateral_limit` for each kind and sign (default grid steps :data:`GRID_STEPS`)."""
    return tuple(lateral_limit(params, x, k, sign=s, n_steps=n_steps, tol=tol, options=options)
                 for k in kinds for s in signs)
