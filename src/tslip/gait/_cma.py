"""CMA-ES: the package's one ask/tell loop, the gait search's minimiser and its report.

:func:`ask_tell` is the loop every CMA-ES search runs: the gait search of
Section 2.8 (eq. 2.22) through :func:`cma_minimize` (which
:mod:`tslip.gait.fixed_point` runs on the two-stage cost, ``method="cma"``, and
re-exports with :class:`CMAReport`), and the biped's gait and design searches
(:mod:`tslip.biped.gait`, :mod:`tslip.biped.design`) with their own bounds,
seeds and stopping rules.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["CMAReport", "ask_tell", "cma_minimize"]


@dataclass(frozen=True, slots=True)
class CMAReport:
    """What the CMA-ES search of eq. 2.22 found, before any polish.

    Attributes
    ----------
    seed : int
        Seed of the run; the same seed reproduces it exactly.
    evaluations, iterations : int
        Cost evaluations and CMA-ES generations used.
    z : tuple of float
        Best free variables ``(delta, phi, phid, alpha_r[, alphad_ref | tau_c])``.
    c1 : float
        Eq. 2.20 at ``z``: squared periodicity residual [-].
    c2 : float
        Eq. 2.21 at ``z``: largest squared non-trivial multiplier magnitude,
        NaN when ``c1 >= C1_THRESHOLD``.
    cost : float
        Eq. 2.22 at ``z``.
    stop : str
        Why CMA-ES stopped (its termination criteria).
    seconds : float
        Wall time of the CMA-ES run [s] (not compared by ``==``).
    """

    seed: int
    evaluations: int
    iterations: int
    z: tuple[float, ...]
    c1: float
    c2: float
    cost: float
    stop: str
    seconds: float = field(default=math.nan, compare=False)

    @property
    def max_nontrivial(self) -> float:
        """``sqrt(c2)``: the largest non-trivial multiplier magnitude at ``z``."""
        return math.sqrt(self.c2) if math.isfinite(self.c2) else math.nan


def _cma_seed(seed: int) -> int:
    """A non-zero 32-bit seed for ``cma`` (which reads 0 as "use the clock")."""
    s = int(np.random.SeedSequence(seed).generate_state(1)[0])
    return s or 1


#: Termination tolerances of the gait search (``cma`` option names).
_GAIT_TOLERANCES = {"tolfun": 1e-13, "tolfunhist": 1e-14, "tolx": 1e-14, "tolflatfitness": 20}

_Bound = float | Sequence[float] | np.ndarray | None


def _bound(b: _Bound) -> float | list[float] | None:
    """One side of ``cma``'s ``bounds`` option: None, one value for all coordinates, or a list."""
    if b is None:
        return None
    a = np.asarray(b, dtype=float)
    return float(a) if a.ndim == 0 else [float(v) for v in a]


def ask_tell(
    costs: Callable[[list[np.ndarray]], Sequence[float]],
    x0: Sequence[float] | np.ndarray,
    sigma0: float,
    *,
    seed: int,
    lower: _Bound = None,
    upper: _Bound = None,
    stds: Sequence[float] | np.ndarray | None = None,
    popsize: int | None = None,
    max_evals: int | None = None,
    tolerances: Mapping[str, float] | None = None,
    proceed: Callable[[], bool] | None = None,
) -> tuple[np.ndarray, float, int, int, str]:
    """The package's one CMA-ES loop: ask a generation, cost it, tell, until a stop.

    Every CMA-ES search (the gait search's :func:`cma_minimize`, the biped's
    :func:`~tslip.biped.gait.find_periodic_gait` and
    :func:`~tslip.biped.design.stable_gait_search`) runs this loop, quietly,
    with ``cma``'s own warnings silenced and NumPy's global random state (which
    ``cma`` seeds and draws from) restored afterwards, even after an interrupt.

    Parameters
    ----------
    costs : callable
        ``costs(X)``: the costs of one generation ``X`` (a list of points), in
        order. It may record what its caller needs (best design, history, log).
    x0 : array_like, shape (n,)
        Initial mean.
    sigma0 : float
        Initial step size, multiplied per coordinate by ``stds``.
    seed : int
        ``cma``'s seed, passed as is (``cma`` reads 0 as "seed from the clock").
    lower, upper : float or array_like, optional
        Box bounds, one value for every coordinate or one per coordinate.
    stds : array_like, optional
        Per-coordinate scaling of ``sigma0``.
    popsize : int, optional
        Population size (``cma``'s default ``4 + 3 ln n``).
    max_evals : int, optional
        ``cma``'s budget of cost evaluations (``maxfevals``).
    tolerances : mapping, optional
        Further ``cma`` termination options, e.g. ``{"tolfun": 1e-14}``.
    proceed : callable, optional
        The caller's own stopping rule, asked before every generation
        (e.g. a wall-time budget); the loop stops when it returns False.

    Returns
    -------
    x : ndarray
        Best point evaluated (``x0`` when none had a finite cost; ties go to
        the earliest, as ``cma``'s own ``result.xbest``).
    f : float
        Its cost (inf when none was finite).
    evaluations, iterations : int
        Cost evaluations and generations told to ``cma``.
    stop : str
        ``cma``'s termination criteria that fired (empty when ``proceed`` stopped it).
    """
    import cma

    opts: dict[str, Any] = {"seed": int(seed), "verbose": -9, **(tolerances or {})}
    if max_evals is not None:
        opts["maxfevals"] = int(max_evals)
    if stds is not None:
        opts["CMA_stds"] = [float(s) for s in stds]
    if lower is not None or upper is not None:
        opts["bounds"] = [_bound(lower), _bound(upper)]
    if popsize is not None:
        opts["popsize"] = int(popsize)
    x0 = np.asarray(x0, dtype=float)
    best_x, best_f = x0.copy(), math.inf
    state = np.random.get_state()  # noqa: NPY002
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", module=r"cma(\.|$)")
            es = cma.CMAEvolutionStrategy(x0, sigma0, opts)
            while (proceed is None or proceed()) and not es.stop():
                X = es.ask()
                F = [float(f) for f in costs(X)]
                es.tell(X, list(F))  # a copy: cma sets NaN costs to the median in place
                i = int(np.argmin([math.inf if math.isnan(f) else f for f in F]))
                if F[i] < best_f:
                    best_x, best_f = np.array(X[i], dtype=float), F[i]
            stop = ", ".join(f"{k}={v}" for k, v in es.stop().items())
            return best_x, best_f, int(es.countevals), int(es.countiter), stop
    finally:
        np.random.set_state(state)  # noqa: NPY002


def cma_minimize(
    cost: Callable[[np.ndarray], float],
    x0: np.ndarray,
    *,
    sigma0: float = 1.0,
    stds: np.ndarray | None = None,
    lower: np.ndarray | None = None,
    upper: np.ndarray | None = None,
    seed: int = 1,
    max_evals: int = 3000,
    popsize: int | None = None,
) -> tuple[np.ndarray, float, int, int, str]:
    """Minimise ``cost`` with CMA-ES (``cma`` package, ask/tell), quietly.

    The gait search's settings of :func:`ask_tell`: tight tolerances, so that
    the budget ``max_evals`` usually ends the run.

    Parameters
    ----------
    cost : callable
        Pure function ``z -> float``.
    x0 : ndarray, shape (n,)
        Initial mean.
    sigma0 : float
        Initial step size, multiplied per coordinate by ``stds``.
    stds : ndarray, shape (n,), optional
        Per-coordinate scaling of ``sigma0``.
    lower, upper : ndarray, shape (n,), optional
        Box bounds (eqs 2.23-2.24), handled by ``cma``'s bound transform.
    seed : int
        Any non-negative integer; equal seeds give identical runs. The
        global NumPy random state is restored afterwards.
    max_evals : int
        Budget of cost evaluations.
    popsize : int, optional
        Population size (default ``4 + 3 ln n``).

    Returns
    -------
    x : ndarray
        Best point evaluated.
    f : float
        Its cost.
    evaluations, iterations : int
    stop : str
        Termination criteria that fired.

    References
    ----------
    N. Hansen, "The CMA Evolution Strategy: A Tutorial", arXiv:1604.00772.
    """
    return ask_tell(lambda X: [cost(np.asarray(x)) for x in X], x0, sigma0,
                    seed=_cma_seed(seed), lower=lower, upper=upper, stds=stds,
                    popsize=popsize, max_evals=max_evals, tolerances=_GAIT_TOLERANCES)
