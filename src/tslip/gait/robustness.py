"""Robustness to large disturbances: the largest survivable disturbance (Section 3.1.3).

Robustness is "the largest disturbance from the periodic limit cycle which
does not result in a fall within 25 steps", found by a search over three
disturbances (thesis Section 3.1.3; where and with which sign each is applied
follows docs/conventions.md, "Disturbances for robustness"):

``"step_down"`` (``dh`` [L])
    The first stance starts on the original ground; every later touch-down is
    on ground shifted by ``dh`` (a terrain step at the first stance's foot,
    ``x_f = x + l0 cos(beta) - r sin(phi)``, eq. A.3).
``"push"`` (``dxd`` [g^1/2 L^1/2])
    Added to the CoM horizontal velocity of the touch-down state that starts
    stride 0, keeping ``yd`` and the pitch rate; the leg rates follow from the
    kinematics (eq. A.5).
``"pitch_rate"`` (``dphid`` [rad g^1/2 L^-1/2])
    Added to the pitch rate of the same state, keeping the CoM velocity.

Where the push or pitch-rate change is applied (``placement``): the thesis
says only "from the periodic limit cycle"; the default ``"touchdown"`` is
docs/conventions.md's. The others exist to show how much the limit depends on
that choice (Table 6.1's pitch-rate limit does not reproduce):

``"touchdown"``
    Just after the touch-down that starts stride 0, keeping the CoM velocity.
``"touchdown_hip"`` (pitch rate only)
    Just after that touch-down, keeping the *hip* velocity instead: the CoM
    velocity changes by ``r (cos phi, sin phi) dphid`` (eq. A.5 with the leg
    rates held).
``"liftoff"``
    Just after stride 0's lift-off (its stance undisturbed); the flight is
    ballistic with constant pitch rate, so the state reaches the next
    touch-down by the kernels' own flight solution.
``"apex"``
    At the apex of stride 0's flight (``yd = 0``; at lift-off if the CoM
    already falls there); the leg keeps its retraction schedule.

For the two flight placements the runner must then survive ``n_steps``
strides from the next touch-down; a fall in that flight is a failure.

Signs follow the thesis: with ``sign=-1`` (default) the limits are negative
(down, backward, negative pitch rate); ``sign=+1`` searches the opposite
direction (step up, forward push, positive pitch rate).

The search (:func:`limit_search`) is pure: it sees only a predicate
``survives(magnitudes) -> bool array``, so the simulation stays outside the
algorithm. Survival is not monotone in the magnitude: beyond the first
failure there can be islands of survival (the Table 2.1 gait at
``omega_r_bar >= 1.5`` survives step-downs of 0.15-0.30 L in patches after
falling at 0.14 L). The limit is the *first* failure, on a grid:

1. grid scan: the magnitudes ``h, 2h, 3h, ...`` (step ``h``, per kind
   :data:`GRID_STEPS`) are evaluated in ascending batches of ``ladder``; the
   first failing one ``hi`` and the grid point below it ``lo`` (0 for the
   first: the periodic gait itself) bracket the limit;
2. k-section: ``k`` equally spaced interior points of ``(lo, hi)`` are
   evaluated in one batch; the smallest failing one becomes ``hi`` and the
   point below it ``lo``, so each round shrinks the bracket ``k + 1`` times,
   until ``hi - lo <= tol``.

The reported limit is ``lo``: every grid magnitude up to it and every
k-section point below it survives, and ``hi`` (within ``tol``) fails. This
replaces the thesis's "binary search" (Section 3.1.3), which on such a curve
can return a limit past a failure; with a monotone curve both give the same
boundary to ``tol``. A failing sliver narrower than ``h`` can lie between
two grid points below the limit and is not seen (the boundary of a 25-stride
survival set can be ragged: Table 2.1 at ``omega_r_bar = 1.9`` fails at a
pitch-rate change of 1.335 but survives 1.334 and 1.336), so the limit is
the first failure *at resolution h*. If the first grid point ``h`` fails,
the limit lies in ``[0, h)`` (0 when no k-section point survives); if
nothing fails up to ``max_magnitude`` the limit is ``sign * inf``.

Since only the first failure of a batch matters, :func:`robustness` runs a
batch's magnitudes in ascending order, one after another on arrays packed
once (:func:`tslip.simulation._packed.run`), and stops at the first that
fails: the limit is the same as with every point run, with fewer runs (the
flight placements still run each batch as one :func:`tslip.run_batch`).

Runs that end in an integration error (:attr:`Status.is_error`) are not falls;
they count as failures of the disturbance, and the result records the reason.

The biped (:mod:`tslip.biped.robustness`) searches its limits with the same
:func:`search_limit` and reports them in the same :class:`RobustnessLimit`
and :class:`RobustnessLimits`.

The parts live beside this module, which re-exports their names: the
disturbances and the runs that start from them in
:mod:`tslip.gait._disturbances`, the search in :mod:`tslip._first_failure`;
here are the grid steps, the results and the searches of a gait.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._first_failure import (
    LimitSearch,
    _deprecated_start,
    _grid_step,
    _grid_steps,
    limit_search,
)
from .._results import Result, frame
from ..model.parameters import Params
from ..model.state import TouchdownState
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status
from ._disturbances import (
    KINDS,
    PLACEMENTS,
    UNITS,
    Kind,
    Placement,
    _check_kind,
    _check_placement,
    _touchdown_runner,
    run_disturbed,
)
from .fixed_point import Gait

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "GRID_STEPS",
    "KINDS",
    "PLACEMENTS",
    "LimitSearch",
    "RobustnessLimit",
    "RobustnessLimits",
    "RobustnessResult",
    "check_gait",
    "limit_search",
    "search_limit",
    "robustness",
    "robustness_report",
    "run_disturbed",
]

#: ``limit_search``'s example runs with this module's (``tests/test_api.py``).
__test__ = {"limit_search": limit_search}

#: Grid step ``h`` of the first-failure scan per disturbance kind, in its
#: unit (:data:`UNITS`; module notes). About 1/30 of the kind's typical limit,
#: so that a search costs some 20-40 surviving runs (``n_steps`` strides
#: each) before the first failure, and islands and failing gaps wider than
#: ``h`` are resolved: step-down 0.005 L (limits 0.12-0.21 L: Table 6.1,
#: Table 2.1 and its controllers); push 0.02 g^1/2 L^1/2 (Table 6.1: -0.73;
#: the Table 2.1 gaits reach -1.1 to -2.2, up to ~110 grid runs); pitch rate
#: 0.02 rad g^1/2 L^-1/2 (limits 0.68-1.6 here, Table 6.1 prints -1.50). In
#: the retraction study (Figure 4.23, ``omega_r_bar`` 0.7-2) the first
#: failing gap is 0.0005-0.044 L wide for the step-down, 0.001-0.047 for the
#: push and 0.005-0.095 for the pitch rate: narrower ones can fall between
#: grid points (module notes).
GRID_STEPS: dict[str, float] = {"step_down": 0.005, "push": 0.02, "pitch_rate": 0.02}


def check_gait(gait: Gait) -> None:
    """Refuse a gait the thesis would not analyse (Section 3.1.3).

    Raises
    ------
    ValueError
        If the gait is not converged, or is unstable (a Floquet multiplier
        outside the unit circle): robustness is computed only for at least
        neutrally stable limit cycles.
    """
    from .stability import floquet

    if not gait.converged:
        raise ValueError(
            f"robustness needs a periodic gait, but this one is not converged (residual "
            f"{gait.residual:.2e}: {gait.message}); pass check=False to analyse it anyway"
        )
    f = floquet(gait)
    if not f.stable:
        raise ValueError(
            f"robustness is computed only for at least neutrally stable gaits (thesis Section "
            f"3.1.3), but this one is {f.stability} (largest multiplier {f.max_nontrivial:.4g}); "
            f"pass check=False to analyse it anyway"
        )



@dataclass(frozen=True, slots=True, repr=False)
class RobustnessLimit(Result):
    """The robustness limit for one disturbance and direction.

    Attributes
    ----------
    kind : {"step_down", "push", "pitch_rate"}
    sign : {-1, +1}
        Direction searched (-1: down, backward, negative pitch rate).
    limit : float
        Largest surviving disturbance, signed [unit of ``kind``]: ``dh`` [L],
        ``dxd`` [g^1/2 L^1/2] or ``dphid`` [rad g^1/2 L^-1/2]. ``sign * inf``
        if nothing failed up to ``max_magnitude``.
    first_failing : float
        The failing disturbance that bounds ``limit`` (signed,
        ``|first_failing - limit| <= tol``); ``sign * inf`` if none.
    fall_stride : int
        Stride (0-based) in which the ``first_failing`` run ended; -1 if none.
    status : Status
        How it ended: a fall (``status.fell``) or an integration error
        (``status.is_error``), which is not a fall but counts as a failure.
    n_batches : int
        Batches of the search (:func:`limit_search` calls of its predicate).
    n_runs : int
        Disturbed runs simulated (a batch stops at its first failure).
    n_errors : int
        Runs of the search that ended in an integration error.
    """

    kind: str
    sign: int
    limit: float
    first_failing: float
    fall_stride: int
    status: Status
    n_batches: int
    n_runs: int
    n_errors: int

    @property
    def reason(self) -> str:
        """Why the first failing disturbance failed (one line)."""
        return self.status.reason

    def _row(self) -> dict[str, Any]:
        return {"kind": self.kind, "sign": self.sign, "limit": self.limit,
                "first_failing": self.first_failing, "unit": self.unit,
                "fall_stride": self.fall_stride, "status": self.status.name,
                "n_batches": self.n_batches, "n_runs": self.n_runs, "n_errors": self.n_errors}

    def to_dataframe(self) -> pd.DataFrame:
        """One row; ``limit`` and ``first_failing`` are in the unit of column ``unit``."""
        return frame([self._row()], _LIMIT_UNITS)

    @property
    def unit(self) -> str:
        """Unit of the disturbance."""
        return UNITS[self.kind]


#: Units of a robustness table: the disturbance's own unit is in its ``unit`` column.
_LIMIT_UNITS = {**dict.fromkeys(("kind", "sign", "unit", "fall_stride", "status", "n_batches",
                                 "n_runs", "n_errors"), "-"),
                "limit": "column unit", "first_failing": "column unit"}


@dataclass(frozen=True, slots=True, repr=False)
class RobustnessLimits(Result):
    """The limits of a robustness search, for either model (thesis Section 3.1.3).

    The base of the TSLIP's :class:`RobustnessResult` and the biped's
    :class:`tslip.biped.robustness.RobustnessResult`, which add what the
    search started from (their parameters, start and options differ in type).

    Attributes
    ----------
    limits : tuple of RobustnessLimit
        One per searched kind and sign.
    """

    limits: tuple[RobustnessLimit, ...]

    def _repr_fields(self) -> dict[str, Any]:
        out: dict[str, Any] = {"n_steps": getattr(self, "n_steps", None)}
        for lim in self.limits:
            out[lim.kind if lim.sign < 0 else f"{lim.kind}_up"] = lim.limit
        return out

    def to_dataframe(self) -> pd.DataFrame:
        """One row per searched kind and sign (see :meth:`RobustnessLimit.to_dataframe`)."""
        return frame([lim._row() for lim in self.limits] or {k: [] for k in _LIMIT_UNITS},
                     _LIMIT_UNITS)

    def plot(self, ax: Axes | None = None) -> Figure:
        """One bar per limit."""
        from ..plotting.results import plot_robustness

        return plot_robustness(self, ax)

    def get(self, kind: str, sign: int = -1) -> RobustnessLimit:
        """Return the :class:`RobustnessLimit` for ``kind`` and ``sign``."""
        for lim in self.limits:
            if lim.kind == kind and lim.sign == sign:
                return lim
        raise KeyError(f"no limit for kind={kind!r}, sign={sign!r} in this result")

    @property
    def step_down(self) -> float:
        """Maximum step-down ``dh`` [L] (negative)."""
        return self.get("step_down").limit

    @property
    def push(self) -> float:
        """Maximum backward push ``dxd`` [g^1/2 L^1/2] (negative)."""
        return self.get("push").limit

    @property
    def pitch_rate(self) -> float:
        """Maximum negative pitch-rate disturbance ``dphid`` [rad g^1/2 L^-1/2]."""
        return self.get("pitch_rate").limit

    @property
    def n_batches(self) -> int:
        """Batched evaluations over all searches."""
        return sum(lim.n_batches for lim in self.limits)


@dataclass(frozen=True, slots=True, repr=False)
class RobustnessResult(RobustnessLimits):
    """Robustness limits of a periodic TSLIP gait (thesis Section 3.1.3).

    Attributes
    ----------
    limits : tuple of RobustnessLimit
        One per searched kind and sign.
    params : Params
    state : TouchdownState
        The gait's touch-down state the disturbances start from.
    n_steps : int
        Strides a disturbed run must survive.
    tol : float
        Bracket width of the search.
    options : IntegratorOptions
    """

    params: Params
    state: TouchdownState
    n_steps: int
    tol: float
    options: IntegratorOptions


def robustness(
    gait: Gait,
    kind: Kind,
    *,
    n_steps: int = 25,
    sign: int = -1,
    tol: float = 1e-4,
    options: IntegratorOptions | None = None,
    check: bool = True,
    h: float | None = None,
    ladder: int = 8,
    k: int = 3,
    max_magnitude: float = 100.0,
    placement: Placement = "touchdown",
    start: float | None = None,
) -> float:
    """Largest disturbance of one kind the gait survives for ``n_steps`` strides.

    Parameters
    ----------
    gait : Gait
        A converged, at least neutrally stable periodic gait
        (:func:`tslip.find_gait`).
    kind : {"step_down", "push", "pitch_rate"}
        Ground step ``dh`` [L], horizontal push ``dxd`` [g^1/2 L^1/2] or
        pitch-rate change ``dphid`` [rad g^1/2 L^-1/2] (see the module notes).
    n_steps : int
        Strides to survive without a fall (thesis: 25).
    sign : {-1, +1}
        -1: step down, backward push, negative pitch rate (the thesis's
        limits); +1: step up, forward push, positive pitch rate.
    tol : float
        Accuracy of the limit, in the unit of ``kind`` (thesis: 1e-4).
    options : IntegratorOptions, optional
        Integrator of the disturbed runs (default: the thesis's 1e-8).
    check : bool
        Refuse unconverged or unstable gaits (see :func:`check_gait`).
    h : float, optional
        Grid step of the first-failure scan, in the unit of ``kind``
        (default :data:`GRID_STEPS` ``[kind]``).
    ladder, k, max_magnitude
        Search settings (:func:`limit_search`).
    placement : {"touchdown", "touchdown_hip", "liftoff", "apex"}
        Where a push or pitch-rate change is applied (module notes).
    start : float, optional
        Deprecated old name of ``h`` (it warns; removed in 0.4).

    Returns
    -------
    float
        The signed limit: the first failure on the grid of step ``h``,
        refined to ``tol`` (module notes); ``sign * inf`` if no failure up to
        ``max_magnitude``.

    Raises
    ------
    ValueError
        For a bad ``kind``, ``sign`` or ``h``, or (with ``check``) an
        unconverged or unstable gait.

    References
    ----------
    Thesis Section 3.1.3; Table 6.1 model: -0.12 L, -0.73 g^1/2 L^1/2,
    -1.50 rad g^1/2 L^-1/2 (Section 6.1).

    Examples
    --------
    >>> import tslip
    >>> gait = tslip.find_gait(tslip.preset("table6.1"))
    >>> round(robustness(gait, "step_down", tol=1e-3), 2)
    -0.12
    """
    _check_kind(kind)
    _check_placement(kind, placement)
    old = _deprecated_start(start)
    h = GRID_STEPS[kind] if h is None and old is None else _grid_step(h, old)
    if check:
        check_gait(gait)
    return _limit(gait, kind, sign, n_steps=n_steps, tol=tol, options=options, h=h,
                  ladder=ladder, k=k, max_magnitude=max_magnitude, placement=placement).limit


def robustness_report(
    gait: Gait,
    *,
    n_steps: int = 25,
    kinds: Sequence[Kind] = KINDS,
    both_signs: bool = False,
    tol: float = 1e-4,
    options: IntegratorOptions | None = None,
    check: bool = True,
    h: Mapping[str, float] | None = None,
    ladder: int = 8,
    k: int = 3,
    max_magnitude: float = 100.0,
    placement: Placement = "touchdown",
    start: float | None = None,
) -> RobustnessResult:
    """Robustness limits of a gait for several disturbances, with reasons.

    Parameters are those of :func:`robustness`; ``kinds`` selects the
    disturbances and ``both_signs`` adds the +1 direction (step up, forward
    push, positive pitch rate) to the thesis's -1. ``placement`` applies to
    the push and pitch-rate searches (a step-down is always at touch-down).
    ``h`` maps a kind to its grid step; kinds it omits use
    :data:`GRID_STEPS`.

    Returns
    -------
    RobustnessResult
        Per kind and sign: the limit, the failing disturbance that bounds it,
        the stride in which and the :class:`Status` with which that run
        ended, and the number of batched evaluations.

    Raises
    ------
    ValueError
        As :func:`robustness`.
    """
    for kind in kinds:
        _check_kind(kind)
        if kind != "step_down":
            _check_placement(kind, placement)
    steps = _grid_steps(kinds, h, start, GRID_STEPS)
    if check:
        check_gait(gait)
    signs = (-1, 1) if both_signs else (-1,)
    limits = tuple(
        _limit(gait, kind, s, n_steps=n_steps, tol=tol, options=options, h=steps[kind],
               ladder=ladder, k=k, max_magnitude=max_magnitude,
               placement="touchdown" if kind == "step_down" else placement)
        for kind in kinds for s in signs
    )
    return RobustnessResult(limits=limits, params=gait.params, state=gait.state,
                            n_steps=int(n_steps), tol=float(tol),
                            options=options or IntegratorOptions())


def _limit(gait: Gait, kind: Kind, sign: int, *, n_steps: int, tol: float,
           options: IntegratorOptions | None, h: float | None, ladder: int, k: int,
           max_magnitude: float, placement: Placement = "touchdown") -> RobustnessLimit:
    _check_sign_and_steps(sign, n_steps)
    if placement in ("touchdown", "touchdown_hip"):
        run_one = _touchdown_runner(gait, kind, placement, int(n_steps), options)
        return search_limit(kind, sign, run_one, n_steps=int(n_steps), tol=tol, h=h,
                            ladder=ladder, k=k, max_magnitude=max_magnitude)

    def run_many(d: np.ndarray) -> tuple[list[int], list[int]]:  # flight placements: one batch
        run = run_disturbed(gait.params, gait.state, kind, d, n_steps=int(n_steps),
                            options=options, placement=placement)
        return run.status.tolist(), run.n_done.tolist()

    return search_limit(kind, sign, run_many=run_many, n_steps=int(n_steps), tol=tol,
                        h=h, ladder=ladder, k=k, max_magnitude=max_magnitude)


def _check_sign_and_steps(sign: int, n_steps: int) -> None:
    if sign not in (-1, 1):
        raise ValueError(f"sign must be -1 or +1, got {sign!r}")
    if not isinstance(n_steps, (int, np.integer)) or n_steps < 1:
        raise ValueError(f"n_steps must be an integer >= 1, got {n_steps!r}")


def search_limit(kind: str, sign: int,
                 run_one: Callable[[float], tuple[int, int]] | None = None, *,
                 run_many: Callable[[np.ndarray], tuple[list[int], list[int]]] | None = None,
                 n_steps: int, tol: float, h: float | None = None, ladder: int = 8, k: int = 3,
                 max_magnitude: float = 100.0, start: float | None = None) -> RobustnessLimit:
    """The robustness limit of one disturbance and direction, for either model.

    ``run_one(d) -> (status, strides done)`` runs one disturbed run of signed
    size ``d``; a run survives if it ends :attr:`Status.OK` after ``n_steps``
    strides. :func:`limit_search` asks ascending magnitudes and uses only a
    batch's first failure, so the batch runs in order and stops there (the
    rest count as failures, unrun). ``run_many(d_array) -> (statuses,
    strides done)`` instead runs a whole batch at once. The grid step ``h``
    defaults to :data:`GRID_STEPS` ``[kind]``; ``start`` is its old name
    (:func:`limit_search`), taken without a warning while
    :mod:`tslip.biped.robustness` still passes it.

    Returns
    -------
    RobustnessLimit
        With the status and stride of the failing run that bounds the limit.
    """
    if h is None and start is None:
        h = GRID_STEPS[kind]
    _check_sign_and_steps(sign, n_steps)
    if (run_one is None) == (run_many is None):
        raise ValueError("give exactly one of run_one and run_many")
    outcome: dict[float, tuple[int, int]] = {}  # magnitude -> (status, n_done)
    n_errors = 0
    n_runs = 0

    def survives(m: np.ndarray) -> np.ndarray:
        nonlocal n_errors, n_runs
        if run_many is not None:
            sts, nds = run_many(sign * m)
        else:
            assert run_one is not None
            sts, nds = [], []
            for mi in m.tolist():
                st, nd = run_one(sign * mi)
                sts.append(st)
                nds.append(nd)
                if st != Status.OK or nd != n_steps:
                    break
        ok = np.zeros(len(m), dtype=bool)
        for i, (st, nd) in enumerate(zip(sts, nds)):
            outcome[float(m[i])] = (st, nd)
            ok[i] = st == Status.OK and nd == n_steps
        n_errors += sum(Status(st).is_error for st in sts)
        n_runs += len(sts)
        return ok

    s = limit_search(survives, h=h, start=start, tol=tol, ladder=ladder, k=k,
                     max_magnitude=max_magnitude)
    if s.bounded:
        st, nd = outcome[s.hi]
        status, stride = Status(st), nd
    else:
        status, stride = Status.OK, -1
    return RobustnessLimit(kind=kind, sign=sign, limit=sign * s.lo, first_failing=sign * s.hi,
                           fall_stride=stride, status=status, n_batches=s.n_calls,
                           n_runs=n_runs, n_errors=n_errors)
