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
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from .._renamed import warn_renamed
from .._results import Result, frame
from ..model import _pack as pk
from ..model.parameters import Params
from ..model.state import TouchdownState
from ..model.terrain import Terrain
from ..simulation import _kernels as kn
from ..simulation import _packed
from ..simulation.integrate import BatchRun, run_batch, step
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status
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

Kind = Literal["step_down", "push", "pitch_rate"]

#: The three disturbances of thesis Section 3.1.3, in the thesis's order.
KINDS: tuple[Kind, ...] = ("step_down", "push", "pitch_rate")

Placement = Literal["touchdown", "touchdown_hip", "liftoff", "apex"]

#: Where a push or pitch-rate disturbance can be applied (see the module notes).
PLACEMENTS: tuple[Placement, ...] = ("touchdown", "touchdown_hip", "liftoff", "apex")

#: Unit of each disturbance (Table 3.1, dimensionless units).
UNITS: dict[str, str] = {
    "step_down": "L",
    "push": "g^1/2 L^1/2",
    "pitch_rate": "rad g^1/2 L^-1/2",
}

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

_SECTION_COLUMN = {"push": 2, "pitch_rate": 4}  # xd, phid in TouchdownState.as_array()
_FLIGHT_COLUMN = {"push": 2, "pitch_rate": 5}  # xd, phid in the lift-off (x, y, xd, yd, phi, phid)
_DEFAULT_OPTIONS = IntegratorOptions()  # the thesis's 1e-8, built (and checked) once


# ---------------------------------------------------------------------------
# The search: a grid scan for the first failure, then k-section (pure)
# ---------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class LimitSearch:
    """Outcome of :func:`limit_search` (magnitudes, all >= 0).

    Attributes
    ----------
    lo : float
        The limit: every grid magnitude up to it survives, as does every
        k-section point below it; in ``[0, h)`` if the first grid point
        failed, ``inf`` if nothing failed up to ``max_magnitude``.
    hi : float
        The first failure found, ``hi - lo <= tol`` (``inf`` if none).
    n_calls : int
        Calls of the predicate (batches).
    n_evals : int
        Magnitudes evaluated in all calls.
    magnitudes, survived : ndarray, shape (n_evals,)
        Every evaluated magnitude and its outcome, in evaluation order.
    """

    lo: float
    hi: float
    n_calls: int
    n_evals: int
    magnitudes: np.ndarray = field(repr=False)
    survived: np.ndarray = field(repr=False)

    @property
    def bounded(self) -> bool:
        """True if a failing magnitude was found."""
        return math.isfinite(self.hi)


def limit_search(
    survives: Callable[[np.ndarray], np.ndarray],
    *,
    h: float | None = None,
    tol: float = 1e-4,
    ladder: int = 8,
    k: int = 3,
    max_magnitude: float = 100.0,
    start: float | None = None,
) -> LimitSearch:
    """The first failure: a grid scan of step ``h``, then k-section (module notes).

    Parameters
    ----------
    survives : callable
        ``survives(m)`` with ``m`` an ndarray of ascending magnitudes (> 0)
        returns a bool array of the same shape: True where the disturbance of
        that magnitude is survived. Called once per batch.
    h : float
        Grid step (> 0), in the magnitude's unit; the grid is ``h, 2h, ...``
        (:data:`GRID_STEPS` for the three disturbances).
    tol : float
        Final bracket width ``hi - lo`` (> 0), in the magnitude's unit.
    ladder : int
        Grid points evaluated per scan call (>= 1); if all survive, the next
        call continues the grid.
    k : int
        Interior points per k-section call (>= 1; 1 is bisection). Each call
        shrinks the bracket ``k + 1`` times.
    max_magnitude : float
        End of the grid (the last point is clipped to it); the scan costs up
        to ``max_magnitude / h`` evaluations when nothing fails.
    start : float, optional
        The old name of ``h`` (the doubling ladder's first rung, as ``h`` is
        the grid's); give one of the two.

    Returns
    -------
    LimitSearch
        ``lo`` survives and ``hi`` fails, with ``hi - lo <= tol``; no grid
        point at or below ``lo`` and no k-section point below ``lo`` fails.

    Raises
    ------
    ValueError
        For no or a non-positive ``h``, non-positive ``tol``/``max_magnitude``,
        ``ladder < 1``, ``k < 1``, or a predicate answer of the wrong shape.

    Examples
    --------
    Survival on [0, 0.3) and on an island [0.5, 0.6): the limit is 0.3.

    >>> s = limit_search(lambda m: (m < 0.3) | ((m >= 0.5) & (m < 0.6)), h=0.01, tol=1e-3)
    >>> s.lo < 0.3 <= s.hi, s.hi - s.lo <= 1e-3, s.n_calls
    (True, True, 6)
    """
    h = _grid_step(h, start)
    for name, v in (("tol", tol), ("max_magnitude", max_magnitude)):
        if not (math.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be in (0, inf), got {v!r}")
    if h > max_magnitude:
        raise ValueError(f"h ({h!r}) must not exceed max_magnitude ({max_magnitude!r})")
    for name, n in (("ladder", ladder), ("k", k)):
        if not isinstance(n, (int, np.integer)) or n < 1:
            raise ValueError(f"{name} must be an integer >= 1, got {n!r}")
    mags: list[np.ndarray] = []
    oks: list[np.ndarray] = []

    def ask(m: np.ndarray) -> np.ndarray:
        ok = np.asarray(survives(m), dtype=bool)
        if ok.shape != m.shape:
            raise ValueError(f"survives must return shape {m.shape}, got {ok.shape}")
        mags.append(m)
        oks.append(ok)
        return ok

    lo, hi = 0.0, math.inf
    j = 0  # grid points asked so far
    while not math.isfinite(hi):  # grid scan: ``ladder`` points j*h per call
        rungs = h * np.arange(j + 1, j + int(ladder) + 1)
        j += int(ladder)
        rungs = rungs[rungs < max_magnitude]
        if len(rungs) < ladder:
            rungs = np.append(rungs, max_magnitude)
        ok = ask(rungs)
        fail = np.flatnonzero(~ok)
        if fail.size:
            i = int(fail[0])
            hi = float(rungs[i])
            lo = float(rungs[i - 1]) if i > 0 else lo
        else:
            lo = float(rungs[-1])
            if lo >= max_magnitude:
                return _done(math.inf, math.inf, mags, oks)
    while hi - lo > tol:  # k-section: k interior points per call
        pts = lo + (hi - lo) * np.arange(1, int(k) + 1) / (k + 1)
        pts = pts[(pts > lo) & (pts < hi)]  # guard against rounding at tiny brackets
        if pts.size == 0:
            break
        ok = ask(pts)
        fail = np.flatnonzero(~ok)
        if fail.size:
            i = int(fail[0])
            hi = float(pts[i])
            lo = float(pts[i - 1]) if i > 0 else lo
        else:
            lo = float(pts[-1])
    return _done(lo, hi, mags, oks)


def _deprecated_start(start: float | None, stacklevel: int = 4) -> float | None:
    """The public functions' old ``start`` (the ladder's first rung), now ``h``: warns."""
    if start is not None:
        warn_renamed("start= (the first rung of the old doubling ladder)",
                     "h= (the grid step, tslip.gait.robustness.GRID_STEPS)",
                     stacklevel=stacklevel)
    return start


def _grid_steps(kinds: Sequence[str], h: Mapping[str, float] | None, start: float | None,
                defaults: Mapping[str, float]) -> dict[str, float]:
    """Each kind's grid step: ``h[kind]``, else the old ``start`` (warns), else ``defaults``.

    The one resolution of a report's ``h`` for both models (``defaults`` is
    :data:`GRID_STEPS` or the biped's); ``h`` may name only kinds of ``defaults``.
    """
    given = dict(h or {})
    if not set(given) <= set(defaults):
        raise ValueError(f"h must map kinds among {tuple(defaults)} to grid steps, "
                         f"got keys {sorted(given)}")
    old = _deprecated_start(start, stacklevel=6)
    return {kind: _grid_step(given.get(kind), old) if kind in given or old is not None
            else defaults[kind] for kind in kinds}


def _grid_step(h: float | None, start: float | None) -> float:
    """``h``, or its old name ``start``; refuse neither, both different, or a bad value."""
    if h is None:
        h = start
    elif start is not None and start != h:
        raise ValueError(f"give h or its old name start, not both (h={h!r}, start={start!r})")
    if h is None:
        raise ValueError("h (the grid step) must be given")
    if not (math.isfinite(h) and h > 0):
        raise ValueError(f"h must be in (0, inf), got {h!r}")
    return float(h)


def _done(lo: float, hi: float, mags: list[np.ndarray], oks: list[np.ndarray]) -> LimitSearch:
    m = np.concatenate(mags) if mags else np.empty(0)
    s = np.concatenate(oks) if oks else np.empty(0, dtype=bool)
    return LimitSearch(lo=lo, hi=hi, n_calls=len(mags), n_evals=len(m), magnitudes=m, survived=s)


# ---------------------------------------------------------------------------
# Disturbed runs (the simulation side)
# ---------------------------------------------------------------------------


def run_disturbed(
    params: Params,
    state: TouchdownState,
    kind: Kind,
    values: Sequence[float] | np.ndarray,
    *,
    n_steps: int = 25,
    options: IntegratorOptions | None = None,
    placement: Placement = "touchdown",
) -> BatchRun:
    """Run ``n_steps`` strides after each disturbance, in one batch.

    Parameters
    ----------
    params : Params
    state : TouchdownState
        Touch-down state that starts stride 0 (the gait's).
    kind : {"step_down", "push", "pitch_rate"}
    values : array_like, shape (n,)
        Signed disturbances: ``dh`` [L] (negative: step down), ``dxd``
        [g^1/2 L^1/2] (negative: backward push) or ``dphid``
        [rad g^1/2 L^-1/2].
    n_steps : int
    options : IntegratorOptions, optional
    placement : {"touchdown", "touchdown_hip", "liftoff", "apex"}
        Where a push or pitch-rate change is applied (module notes); a
        step-down is always ``"touchdown"``.

    Returns
    -------
    BatchRun
        Row ``i`` for ``values[i]``; with ``"touchdown"`` the same runs as
        :func:`tslip.simulate` with ``Disturbance(at_step=0, dh=|dxd=|dphid=values[i])``.
        For the flight placements the rows start at the touch-down after the
        disturbance; a fall in that flight has ``n_done = 0`` and its status.
    """
    _check_kind(kind)
    _check_placement(kind, placement)
    d = np.asarray(values, dtype=float).reshape(-1)
    if not np.all(np.isfinite(d)):
        raise ValueError("disturbance values must be finite")
    if placement in ("liftoff", "apex"):
        return _run_flight_disturbed(params, state, kind, d, placement, n_steps, options)
    S = np.tile(state.as_array(), (len(d), 1))
    if placement == "touchdown_hip":  # hip velocity xd - r cos(phi) phid, yd - r sin(phi) phid held
        S[:, 2] += params.r * math.cos(state.phi) * d
        S[:, 3] += params.r * math.sin(state.phi) * d
    terrain: list[Terrain] | None = None
    if kind == "step_down":
        xf = state.x + params.l0 * math.cos(state.beta) - params.r * math.sin(state.phi)
        ground = Terrain.flat(state.h)
        terrain = [ground.shifted_after(xf, float(v)) for v in d]
    else:
        S[:, _SECTION_COLUMN[kind]] += d
    return run_batch(params, S, n_steps, terrain=terrain, options=options)


def _run_flight_disturbed(params: Params, state: TouchdownState, kind: Kind, d: np.ndarray,
                          placement: str, n_steps: int,
                          options: IntegratorOptions | None) -> BatchRun:
    """Stride 0 undisturbed; the change at lift-off or apex; flight; ``n_steps`` strides."""
    s0 = step(params, state, options=options)
    if not s0.ok:
        raise ValueError(f"the undisturbed stride 0 ended: {s0.reason}")
    lo = np.array([getattr(s0.liftoff, f) for f in ("x", "y", "xd", "yd", "phi", "phid")])
    P = pk.pack_params(params)
    O = (options or IntegratorOptions()).packed()  # noqa: E741 - kernels' name
    fs = np.empty(10)
    if placement == "apex":
        t_a = min(max(lo[3], 0.0) / params.g, s0.flight_time)
        # the leg's retraction clock keeps running (the apex clock starts at t_a)
        P[pk.P_ALPHA] += P[pk.P_OMEGA] * max(t_a - kn.retraction_start(P, lo[3]), 0.0)
        kn.flight_state(P, lo, t_a, fs)  # (the CoM part does not depend on alpha_r)
        lo = fs[:6].copy()
    tx, th = Terrain.flat(state.h).arrays()
    S = np.full((len(d), 7), np.nan)
    st0 = np.zeros(len(d), dtype=np.int64)
    res = np.empty(3)
    for i, di in enumerate(d):
        lo_i = lo.copy()
        lo_i[_FLIGHT_COLUMN[kind]] += di
        st0[i] = kn.find_touchdown(P, O, lo_i, tx, th, res)
        if st0[i] == Status.OK:
            kn.flight_state(P, lo_i, res[0], fs)
            S[i] = (fs[6], fs[4], fs[2], fs[3], fs[5], fs[0], res[1])
    n = len(d)
    n_done = np.zeros(n, dtype=np.int64)
    t_fall = np.full(n, np.nan)
    hist = np.full((n, int(n_steps) + 1, 7), np.nan)
    status = st0.copy()
    ok = st0 == Status.OK
    if ok.any():
        run = run_batch(params, S[ok], n_steps, options=options)
        n_done[ok], status[ok], t_fall[ok], hist[ok] = (run.n_done, run.status, run.t_fall,
                                                        run.touchdowns)
    return BatchRun(n_done, status, t_fall, hist)


def _check_kind(kind: str) -> None:
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")


def _check_placement(kind: str, placement: str) -> None:
    if placement not in PLACEMENTS:
        raise ValueError(f"placement must be one of {PLACEMENTS}, got {placement!r}")
    if placement != "touchdown" and kind == "step_down":
        raise ValueError(f"placement must be 'touchdown' for a step-down, got {placement!r}")
    if placement == "touchdown_hip" and kind != "pitch_rate":
        raise ValueError(f"placement 'touchdown_hip' is for kind 'pitch_rate', got {kind!r}")


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


# ---------------------------------------------------------------------------
# Public API
# ---------------------------------------------------------------------------


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


def _touchdown_runner(gait: Gait, kind: Kind, placement: Placement, n_steps: int,
                      options: IntegratorOptions | None) -> Callable[[float], tuple[int, int]]:
    """``d -> (status, strides done)``: one run of :func:`run_disturbed` (touch-down placements).

    The same disturbed start and terrain as :func:`run_disturbed` builds for
    each row, run in the calling thread on arrays packed once
    (:func:`tslip.simulation._packed.run`), stopping at the first fall.
    """
    params, state = gait.params, gait.state
    P = pk.pack_params(params)
    O = (options or _DEFAULT_OPTIONS).packed()  # noqa: E741 - the kernels' name
    td0 = state.as_array()
    flat = Terrain.flat(0.0).arrays()
    xf = state.x + params.l0 * math.cos(state.beta) - params.r * math.sin(state.phi)
    hip = (params.r * math.cos(state.phi), params.r * math.sin(state.phi))

    def run_one(d: float) -> tuple[int, int]:
        td = td0.copy()
        tx, th = flat
        if placement == "touchdown_hip":
            td[2] += hip[0] * d
            td[3] += hip[1] * d
        if kind == "step_down":
            tx, th = Terrain.flat(state.h).shifted_after(xf, d).arrays()
        else:
            td[_SECTION_COLUMN[kind]] += d
        return _packed.run(P, O, td, n_steps, tx, th)

    return run_one
