"""Beyond the thesis: search gains, sweep, duty factor and masses for the most stable gait.

Nested solve. The outer loop (CMA-ES, the ``cma`` package, on the design
variables scaled to ``[0, 1]``) minimises the largest Floquet multiplier
magnitude ``max |lambda|`` of the reduced stride map
(:func:`~tslip.biped.gait.section_multipliers`). The inner solve, for each
design, is :func:`~tslip.biped.gait.refine_periodic_gait` with free stride
time ``T`` and forward hip reference ``theta_f``, warm-started from the best
gait found so far; a design without a periodic gait (residual above
``tol``) scores ``10 + residual``.

Design variables and bounds (:data:`DESIGN_BOUNDS`, all in the units of
thesis Table 3.1): thigh gains ``Kp_t`` 100-2000, ``Kd_t`` 5-60; hip gains
``Kp_h`` 0.1-5, ``Kd_h`` 0.05-3; sweep ``theta_s`` 0.8-2.0 rad; duty factor
``d`` 0.4-0.75; thigh, shank and foot masses ``m_t`` 0.02-0.15, ``m_s``
0.005-0.05, ``m_f`` 0.005-0.03. The total mass stays 1: the trunk takes the
rest, ``m_b = 1 - 2 (m_t + m_s + m_f)``, and must be at least 0.5 (within
these bounds it is at least 0.54, so the check only guards other bounds;
designs outside the bounds score ``20``). Inertias scale with mass at the Table E.1
radii of gyration: ``J_b = 0.125 m_b``, ``J_t = 0.125 m_t``, ``J_s = 0.5 m_s``
(Table E.1: 0.1/0.8, 0.01/0.08, 0.005/0.01). Segment lengths, ``r_1``,
``r_2``, the contact model and the shank spring stay at their thesis values.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .._checks import check_number
from .._results import Result, frame
from ..gait._cma import ask_tell
from .gait import refine_periodic_gait, section_multipliers
from .parameters import BipedParams

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["DESIGN_BOUNDS", "SEARCH_SETTINGS", "DesignSearch", "apply_design",
           "check_search_settings",
           "design_objective", "stable_gait_search"]

#: Design variable -> (lower, upper); see the module docstring.
DESIGN_BOUNDS: dict[str, tuple[float, float]] = {
    "Kp_t": (100.0, 2000.0),
    "Kd_t": (5.0, 60.0),
    "Kp_h": (0.1, 5.0),
    "Kd_h": (0.05, 3.0),
    "theta_s": (0.8, 2.0),
    "d": (0.4, 0.75),
    "m_t": (0.02, 0.15),
    "m_s": (0.005, 0.05),
    "m_f": (0.005, 0.03),
}
_MASSES = ("m_t", "m_s", "m_f")
#: Radii of gyration squared of Table E.1 (J / m).
_GYRATION = {"J_b": ("m_b", 0.1 / 0.8), "J_t": ("m_t", 0.01 / 0.08), "J_s": ("m_s", 0.005 / 0.01)}


def apply_design(base: BipedParams, values: dict[str, float]) -> BipedParams:
    """``base`` with design ``values``, the trunk mass balancing and inertias scaled.

    Raises
    ------
    ValueError
        For an unknown name, a value outside :data:`DESIGN_BOUNDS`, or a trunk
        mass below 0.5.
    """
    bad = sorted(set(values) - set(DESIGN_BOUNDS))
    if bad:
        raise ValueError(f"unknown design variable(s) {bad}; known: {list(DESIGN_BOUNDS)}")
    for n, v in values.items():
        lo, hi = DESIGN_BOUNDS[n]
        if not lo <= v <= hi:
            raise ValueError(f"{n} must be in [{lo:g}, {hi:g}], got {v!r}")
    ch: dict[str, float] = {n: float(v) for n, v in values.items()}
    m = {n: ch.get(n, getattr(base, n)) for n in _MASSES}
    ch["m_b"] = 1.0 - 2.0 * (m["m_t"] + m["m_s"] + m["m_f"])
    if ch["m_b"] < 0.5:
        raise ValueError(f"trunk mass m_b = {ch['m_b']:.3f} below 0.5")
    masses = {**m, "m_b": ch["m_b"]}
    for j, (mn, r2) in _GYRATION.items():
        ch[j] = r2 * masses[mn]
    return base.replace(**ch)


def design_objective(base: BipedParams, z_warm: NDArray[np.float64],
                     values: dict[str, float], *, tol: float = 1e-8,
                     max_iter: int = 8) -> dict[str, Any]:
    """Score one design: periodic gait with free ``T``, ``theta_f``, then ``max |lambda|``.

    Returns a dict with ``score`` (largest multiplier magnitude, or a penalty
    ``10 + residual`` / ``20`` for no gait / infeasible), ``residual``,
    ``params`` (dict), ``z`` (list) and ``largest``.
    """
    try:
        p = apply_design(base, values)
    except ValueError as exc:
        return {"score": 20.0, "residual": math.inf, "message": str(exc)}
    try:
        res = refine_periodic_gait(p, z_warm, free_params=("T", "theta_f"), tol=tol,
                                   max_iter=max_iter, multipliers=False)
    except ValueError as exc:
        return {"score": 20.0, "residual": math.inf, "message": str(exc)}
    out: dict[str, Any] = {"residual": res.residual, "params": res.params.to_dict(),
                           "z": res.z.tolist(), "message": res.message}
    if not res.converged:
        out["score"] = 10.0 + min(res.residual, 10.0)
        return out
    ev = section_multipliers(res.params, res.z, fd_step=1e-5, central=False)
    lam = float(np.abs(ev[0]))
    out["score"] = lam if math.isfinite(lam) else 10.0
    out["largest"] = lam
    return out


def _eval(args: tuple[BipedParams, NDArray[np.float64], dict[str, float]]) -> dict[str, Any]:
    return design_objective(*args)


#: Allowed ranges of :func:`stable_gait_search`'s settings (``check_number`` bounds).
SEARCH_SETTINGS: dict[str, dict[str, Any]] = {
    "budget_s": {"unit": "s", "lower": 0.0, "lower_open": True},
    "max_evals": {"lower": 1, "integer": True},
    "popsize": {"lower": 2, "integer": True},
    "sigma0": {"lower": 0.0, "upper": 1.0, "lower_open": True},
    "seed": {"lower": 0, "integer": True},
    "processes": {"lower": 1, "upper": 256, "integer": True},
}


def check_search_settings(names: dict[str, str] | None = None, **values: Any) -> None:
    """Check :func:`stable_gait_search`'s settings; errors use ``names`` (e.g. CLI options)."""
    for key, value in values.items():
        check_number(value, (names or {}).get(key, key), **SEARCH_SETTINGS[key])


@dataclass(frozen=True, repr=False)
class DesignSearch(Result):
    """What :func:`stable_gait_search` found.

    Attributes
    ----------
    best : dict
        The best :func:`design_objective` result (``score``, ``residual``,
        ``params``, ``z``, ``largest``, ``message``) plus its ``design``.
    evaluations : int
        Designs scored.
    history : tuple of float
        Best score after the start and after each generation.
    seconds : float
        Wall time [s].
    interrupted : bool
        Ended by Ctrl-C (the best so far is kept).
    """

    best: dict[str, Any]
    evaluations: int
    history: tuple[float, ...]
    seconds: float
    interrupted: bool

    def __getitem__(self, key: str) -> Any:
        """The field ``key``, as from the dict this result replaced."""
        if key not in ("best", "evaluations", "history", "seconds", "interrupted"):
            raise KeyError(key)
        return getattr(self, key)

    def _repr_fields(self) -> dict[str, Any]:
        return {"score": self.best.get("score"), "evaluations": self.evaluations,
                "generations": len(self.history) - 1, "seconds": self.seconds,
                "interrupted": self.interrupted}

    def to_dataframe(self) -> pd.DataFrame:
        """One row per generation (0: the start): the best score so far."""
        return frame({"generation": range(len(self.history)), "best_score": self.history},
                     {"generation": "-", "best_score": "-"})

    def plot(self, ax: Axes | None = None) -> Figure:
        """The best score (largest multiplier magnitude, or a penalty) per generation."""
        from ..plotting.results import plot_series

        return plot_series(self.history, ax, xlabel="generation [-]",
                           ylabel="best score (max |lambda|) [-]",
                           title=f"design search: {self.evaluations} designs")


def stable_gait_search(base: BipedParams, z0: NDArray[np.float64], *,
                       names: tuple[str, ...] = tuple(DESIGN_BOUNDS),
                       budget_s: float = 600.0, max_evals: int = 400, popsize: int = 8,
                       sigma0: float = 0.08, seed: int = 3, processes: int = 1,
                       log: Callable[[str], None] | None = None,
                       on_improve: Callable[[dict[str, Any]], None] | None = None,
                       ) -> DesignSearch:
    """CMA-ES over the design variables ``names`` for the smallest ``max |lambda|``.

    ``base`` and ``z0`` are a converged gait (the warm start). Stops after
    ``budget_s`` seconds (checked per generation), ``max_evals`` designs, or
    an interrupt (Ctrl-C), returning the best design so far in each case.
    ``processes > 1`` scores a generation in a process pool. ``on_improve``
    is called with each new best (e.g. to checkpoint it; a run resumes by
    warm-starting from that gait).

    Returns
    -------
    DesignSearch
        ``best`` (the best :func:`design_objective` result plus ``design``),
        ``evaluations``, ``history`` (best score per generation), ``seconds``,
        ``interrupted``.
    """
    check_search_settings(budget_s=budget_s, max_evals=max_evals, popsize=popsize,
                          sigma0=sigma0, seed=seed, processes=processes)
    unknown = sorted(set(names) - set(DESIGN_BOUNDS))
    if unknown or not names:
        raise ValueError(f"names must be design variables from {sorted(DESIGN_BOUNDS)}, got "
                         f"{list(names)!r}")
    lo = np.array([DESIGN_BOUNDS[n][0] for n in names])
    hi = np.array([DESIGN_BOUNDS[n][1] for n in names])

    def values(u: NDArray[np.float64]) -> dict[str, float]:
        return {n: float(v) for n, v in zip(names, lo + np.clip(u, 0, 1) * (hi - lo),
                                             strict=True)}

    u0 = np.clip((np.array([getattr(base, n) for n in names]) - lo) / (hi - lo), 0, 1)
    t_start = time.perf_counter()
    first = design_objective(base, z0, values(u0))
    first["design"] = values(u0)
    best = first
    z_warm = np.asarray(first.get("z", z0), dtype=np.float64)
    history = [best["score"]]
    n_ev = 1
    if log:
        log(f"start: score {best['score']:.4f} residual {best['residual']:.1e}")
    pool = None
    if processes > 1:
        import multiprocessing as mp

        pool = mp.get_context("fork").Pool(processes)

    def generation(us: list[NDArray[np.float64]]) -> list[float]:
        """Score the designs ``us`` and keep the best so far (the caller's record)."""
        nonlocal best, z_warm, n_ev
        jobs = [(base, z_warm, values(u)) for u in us]
        outs = pool.map(_eval, jobs) if pool else [_eval(j) for j in jobs]
        n_ev += len(outs)
        k = int(np.argmin([o["score"] for o in outs]))
        if outs[k]["score"] < best["score"]:
            best = {**outs[k], "design": jobs[k][2]}
            z_warm = np.asarray(best["z"], dtype=np.float64)
            if on_improve:
                on_improve({**best, "evaluations": n_ev})
        history.append(best["score"])
        if log:
            ok = sum(o["score"] < 10 for o in outs)
            log(f"{n_ev} designs, {time.perf_counter() - t_start:.0f} s: generation best "
                f"{outs[k]['score']:.4f} ({ok}/{len(outs)} periodic), best {best['score']:.4f}")
        return [o["score"] for o in outs]

    def proceed() -> bool:
        return time.perf_counter() - t_start < budget_s and n_ev + popsize <= max_evals

    interrupted = False
    try:
        ask_tell(generation, u0, sigma0, seed=seed, lower=0.0, upper=1.0, popsize=popsize,
                 proceed=proceed)
    except KeyboardInterrupt:
        interrupted = True
        if log:
            log(f"interrupted after {n_ev} designs; keeping the best so far")
    finally:
        if pool is not None:
            pool.terminate() if interrupted else pool.close()
            pool.join()
    return DesignSearch(best=best, evaluations=n_ev, history=tuple(history),
                        seconds=time.perf_counter() - t_start, interrupted=interrupted)
