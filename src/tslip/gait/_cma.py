"""CMA-ES for the thesis's gait search (Section 2.8, eq. 2.22): the minimiser and its report.

Split from :mod:`tslip.gait.fixed_point`, which runs it on the two-stage cost
(``method="cma"``) and re-exports both names.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["CMAReport", "cma_minimize"]


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
    import cma

    x0 = np.asarray(x0, dtype=float)
    opts: dict[str, Any] = {
        "seed": _cma_seed(seed), "verbose": -9, "verb_disp": 0, "verb_log": 0,
        "maxfevals": int(max_evals), "tolfun": 1e-13, "tolfunhist": 1e-14, "tolx": 1e-14,
        "tolflatfitness": 20,
    }
    if stds is not None:
        opts["CMA_stds"] = list(map(float, stds))
    if lower is not None or upper is not None:
        lo = None if lower is None else list(map(float, lower))
        hi = None if upper is None else list(map(float, upper))
        opts["bounds"] = [lo, hi]
    if popsize is not None:
        opts["popsize"] = int(popsize)
    # cma seeds and draws from NumPy's legacy global generator: put it back after
    state = np.random.get_state()  # noqa: NPY002
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", module=r"cma(\.|$)")
            es = cma.CMAEvolutionStrategy(x0, sigma0, opts)
            best_x, best_f = x0.copy(), math.inf
            while not es.stop():
                X = es.ask()
                F = [float(cost(np.asarray(x))) for x in X]
                es.tell(X, F)
                i = int(np.argmin(F))
                if F[i] < best_f:
                    best_x, best_f = np.array(X[i], dtype=float), F[i]
            stop = ", ".join(f"{k}={v}" for k, v in es.stop().items())
            return best_x, best_f, int(es.countevals), int(es.countiter), stop
    finally:
        np.random.set_state(state)  # noqa: NPY002
