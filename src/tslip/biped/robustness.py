"""Robustness of a biped gait: the largest survivable disturbances (Section 3.1.3, Appendix E).

The TSLIP's names and search (:mod:`tslip.gait.robustness`) on the biped:
:func:`robustness` gives one limit, :func:`robustness_report` a
:class:`RobustnessResult` of :class:`~tslip.gait.robustness.RobustnessLimit`.
The three disturbances are applied as :func:`tslip.biped.gait.disturbed_outcome`
describes; a run survives if it completes ``n_steps`` strides. The search is
:func:`tslip.gait.robustness.search_limit`: the first failure on a grid of
step :data:`GRID_STEPS` ``[kind]``, then k-section, each batch run in order
and stopped at its first failure.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..gait.robustness import (
    RobustnessLimit,
    RobustnessLimits,
    _deprecated_start,
    _grid_step,
    _grid_steps,
    search_limit,
)
from .gait import DISTURBANCES, REFINE_OPTIONS, Gait, disturbed_outcome, floquet
from .parameters import BipedParams
from .simulate import BipedOptions

__all__ = ["GRID_STEPS", "RobustnessResult", "check_gait", "robustness", "robustness_report"]

#: Grid step of each disturbance's first-failure search on the biped, in the
#: kind's unit. About 1/30 of the converged gait's limits (-0.16 L, -0.82,
#: -3.3: ``tslip biped robustness``), as :data:`tslip.gait.robustness.GRID_STEPS`
#: is of the TSLIP's; each biped run costs about 1000 times a TSLIP stride, so
#: the grid is not finer than that.
GRID_STEPS: dict[str, float] = {"step_down": 0.005, "push": 0.025, "pitch_rate": 0.1}


@dataclass(frozen=True, slots=True, repr=False)
class RobustnessResult(RobustnessLimits):
    """Robustness limits of a periodic biped gait (the TSLIP's, Section 3.1.3).

    Attributes
    ----------
    limits : tuple of RobustnessLimit
        One per searched kind and sign.
    params : BipedParams
    z : ndarray, shape (18,)
        The gait's section vector the disturbances start from.
    n_steps : int
        Strides a disturbed run must survive.
    tol : float
        Bracket width of the search.
    options : BipedOptions
    """

    params: BipedParams
    z: NDArray[np.float64] = field(repr=False)
    n_steps: int
    tol: float
    options: BipedOptions


def check_gait(gait: Gait, options: BipedOptions | None = None) -> None:
    """Refuse a gait the thesis would not analyse: unconverged or unstable (Section 3.1.3).

    Raises
    ------
    ValueError
        If ``gait.converged`` is False, or a Floquet multiplier
        (:func:`tslip.biped.gait.floquet`) lies outside the unit circle.
    """
    if not gait.converged:
        raise ValueError(f"robustness needs a periodic gait, but this one is not converged "
                         f"({gait.message}); pass check=False to analyse it anyway")
    f = floquet(gait.params, gait.z, options=options or REFINE_OPTIONS)
    if not f.stable:
        raise ValueError(f"robustness is computed only for at least neutrally stable gaits "
                         f"(thesis Section 3.1.3), but this one is {f.stability} (largest "
                         f"multiplier {f.max_nontrivial:.4g}); pass check=False to analyse it "
                         f"anyway")


def robustness(gait: Gait, kind: str, *, n_steps: int = 25, sign: int = -1, tol: float = 1e-3,
               options: BipedOptions | None = None, check: bool = True,
               h: float | None = None, ladder: int = 8, k: int = 1,
               max_magnitude: float = 10.0, start: float | None = None) -> float:
    """Largest disturbance of one kind the biped gait survives for ``n_steps`` strides.

    As :func:`tslip.robustness`: ``kind`` is ``"step_down"`` [L], ``"push"``
    [g^1/2 L^1/2] or ``"pitch_rate"`` [rad g^1/2 L^-1/2]; ``sign=-1`` searches
    down, backward and negative pitch rates; ``tol`` is the accuracy of the
    limit; ``h`` (the grid step, default :data:`GRID_STEPS` ``[kind]``),
    ``ladder``, ``k`` and ``max_magnitude`` set the search
    (:func:`tslip.gait.robustness.limit_search`); ``start`` is ``h``'s old
    name (deprecated). ``options`` are the
    disturbed runs' (default :class:`BipedOptions`, the thesis's 1e-8).

    Returns
    -------
    float
        The signed limit (``sign * inf`` if nothing failed up to ``max_magnitude``).

    Raises
    ------
    ValueError
        For a bad ``kind``, ``sign`` or ``n_steps``, or (with ``check``) an
        unconverged or unstable gait.
    """
    old = _deprecated_start(start)
    step = None if h is None and old is None else {kind: _grid_step(h, old)}
    return robustness_report(gait, n_steps=n_steps, kinds=(kind,), signs=(sign,), tol=tol,
                             options=options, check=check, h=step, ladder=ladder, k=k,
                             max_magnitude=max_magnitude).limits[0].limit


def robustness_report(gait: Gait, *, n_steps: int = 25, kinds: Sequence[str] = DISTURBANCES,
                      both_signs: bool = False, signs: Sequence[int] | None = None,
                      tol: float = 1e-3, options: BipedOptions | None = None,
                      check: bool = True, h: Mapping[str, float] | None = None,
                      ladder: int = 8, k: int = 1, max_magnitude: float = 10.0,
                      start: float | None = None) -> RobustnessResult:
    """Robustness limits of a biped gait for several disturbances, with reasons.

    Parameters are those of :func:`robustness`; ``kinds`` selects the
    disturbances and ``both_signs`` adds the +1 direction to the thesis's -1
    (``signs`` names the directions explicitly instead). ``h`` maps a kind
    to its grid step; kinds it omits use :data:`GRID_STEPS`.

    Returns
    -------
    RobustnessResult
        Per kind and sign: the limit, the failing disturbance that bounds it,
        and the stride in which and the :class:`tslip.Status` with which that
        run ended.
    """
    for kind in kinds:
        if kind not in DISTURBANCES:
            raise ValueError(f"kind must be one of {DISTURBANCES}, got {kind!r}")
    steps = _grid_steps(kinds, h, start, GRID_STEPS)
    signs = tuple(signs) if signs is not None else (-1, 1) if both_signs else (-1,)
    if check:
        check_gait(gait)
    opts = options or BipedOptions()
    limits: list[RobustnessLimit] = []
    for kind in kinds:
        for sign in signs:

            def run_one(d: float, kind: str = kind) -> tuple[int, int]:
                st, done = disturbed_outcome(gait.params, gait.z, kind, d, n_steps, opts)
                if st is None:
                    raise ValueError("a step-down needs a flight phase, and this gait has none")
                return int(st), done

            limits.append(search_limit(kind, sign, run_one, n_steps=n_steps, tol=tol,
                                       h=steps[kind], ladder=ladder, k=k,
                                       max_magnitude=max_magnitude))
    return RobustnessResult(limits=tuple(limits), params=gait.params,
                            z=np.asarray(gait.z, dtype=np.float64), n_steps=int(n_steps),
                            tol=float(tol), options=opts)

