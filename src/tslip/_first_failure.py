"""The first-failure limit search on a grid, then k-section (pure; Section 3.1.3).

:func:`limit_search` sees only a predicate ``survives(magnitudes) -> bool
array``, so the simulation stays outside the algorithm; the algorithm and why
it replaces the thesis's binary search are in the module notes of
:mod:`tslip.gait.robustness`, which re-exports these names. The grid step
``h`` of a report is resolved here for both models (:func:`_grid_steps`).
At the package's top level, below every model: the planar TSLIP's and the
biped's robustness (through :mod:`tslip.gait.robustness`) and the 3-D TSLIP's
lateral limits (:func:`tslip.spatial.trunk_robustness.lateral_limit`) all search
with it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ._renamed import warn_renamed

__all__ = ["LimitSearch", "limit_search"]

#: The most grid points ``max_magnitude / h`` a search may scan: its calls are bounded
#: (about ``MAX_GRID_POINTS / ladder`` for the scan), so a step far too fine for its range
#: is refused rather than scanned for hours (1e7 points of a 0.1 ms stride: 17 minutes).
MAX_GRID_POINTS = 10_000_000


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
    """The first failure: a grid scan of step ``h``, then k-section.

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
        to ``max_magnitude / h`` evaluations when nothing fails, at most
        :data:`MAX_GRID_POINTS`.
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
        For no or a non-positive ``h``, non-positive ``tol``/``max_magnitude``, a grid of
        more than :data:`MAX_GRID_POINTS` points, ``ladder < 1``, ``k < 1``, or a
        predicate answer of the wrong shape.

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
    if max_magnitude / h > MAX_GRID_POINTS:
        raise ValueError(f"h ({h!r}) must be at least max_magnitude / {MAX_GRID_POINTS:.0e} "
                         f"({max_magnitude / MAX_GRID_POINTS:.3g}): a grid of "
                         f"{max_magnitude / h:.3g} points would run for hours")
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
        lo, hi = _bracket(lo, rungs, ask(rungs))
        if lo >= max_magnitude:
            return _done(math.inf, math.inf, mags, oks)
    while hi - lo > tol:  # k-section: k interior points per call
        pts = lo + (hi - lo) * np.arange(1, int(k) + 1) / (k + 1)
        pts = pts[(pts > lo) & (pts < hi)]  # guard against rounding at tiny brackets
        if pts.size == 0:
            break
        lo, hi = _bracket(lo, pts, ask(pts), hi)
    return _done(lo, hi, mags, oks)


def _bracket(lo: float, pts: np.ndarray, ok: np.ndarray, hi: float = math.inf,
             ) -> tuple[float, float]:
    """The bracket ``(lo, hi)`` after asking the increasing ``pts`` above ``lo``.

    The first failure among them is the new ``hi`` and the point before it
    (or the old ``lo``) the new ``lo``; if all survive, ``lo`` is the last and
    ``hi`` stays. The one update of both the grid scan and the k-section.
    """
    fail = np.flatnonzero(~ok)
    if not fail.size:
        return float(pts[-1]), hi
    i = int(fail[0])
    return (float(pts[i - 1]) if i > 0 else lo), float(pts[i])


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
