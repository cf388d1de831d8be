"""Periodic gaits: fixed points of the touch-down map (thesis Section 2.8).

Unknowns (docs/conventions.md): the touch-down velocity angle ``delta``, pitch
``phi``, pitch rate ``phid`` and the leg reset angle ``alpha_r``, plus
``alphad_ref`` (local velocity control) or ``tau_c`` (constant torque with
damping); ``v0`` and ``beta0`` are fixed. The residual is the next
touch-down's ``(beta, phi, phid, delta, v)`` minus ``(beta0, phi, phid,
delta, v0)``.

:class:`GaitProblem` (:mod:`tslip.gait.problem`) states the search as pure
functions of the free variables ``z``: the residual, the thesis's cost ``C1``
(eq. 2.20) and the two-stage cost ``C`` (eqs 2.21-2.22) within bounds (eqs
2.23-2.24). It holds the speed (``fix="speed"``, at the touch-down or the
apex section) or the total energy (``fix="energy"``), and at ``r = 0`` the
undetermined pitch. Two searches work on it, both outside the simulation:

* ``method="newton"`` (default): damped Newton on the residual with its
  exact Jacobian (variational equations, :meth:`GaitProblem.residual_jacobian`),
  from automatic starting guesses, stopping at the requested residual; where
  Newton fails from a start, Levenberg-Marquardt least squares with finite
  differences takes over from the same start. The problem is packed once
  per call (:mod:`tslip.simulation._packed`), so a residual costs about one
  compiled stride. It reaches the exact fixed point in a few milliseconds.
* ``method="cma"``: the thesis's own method, CMA-ES (Hansen's ``cma``
  package) on eq. 2.22. It returns a *near*-fixed point, ``C1 < 1e-4``,
  with the smallest non-trivial Floquet multiplier it found there; by
  default a Newton polish then takes it to the exact fixed point nearby.

The thesis's fixed points were approximate to ``C1 < 1e-4`` (a residual
norm up to 1e-2), and CMA-ES pushes them to the edge of that ball where the
multiplier is smallest: on Table 2.1 it reports 0.9855 where the exact fixed
point has 0.9944, and it moves the mass-offset stability limit from
r = 0.849 (exact) to about 0.92. Multipliers near 1 from the thesis can
therefore differ in the second or third decimal from the exact ones.
``C1`` here is eq. 2.20 on the 5-D section residual above.

Over 600 lines: one concept, the two gait searches on one GaitProblem and their Gait result.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import time
import warnings
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.linalg import _umath_linalg

from .._results import Result, frame
from ..model._pack import packed_params
from ..model.controllers import GlobalPD
from ..model.parameters import Params
from ..model.state import TouchdownState
from ..model.units import COLUMN_UNITS
from ..simulation import _packed
from ..simulation.integrate import step
from ..simulation.options import IntegratorOptions
from ._cma import CMAReport, cma_minimize
from .problem import (
    C1_OFFSET,
    C1_THRESHOLD,
    TIGHT,
    Fix,
    GaitProblem,
    Section,
    _finite,
    gait_residual,
    nominal_energy,
)
from .section import ApexState, total_energy, touchdown_to_apex

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "Gait",
    "GaitProblem",
    "CMAReport",
    "find_gait",
    "gait_residual",
    "newton_solve",
    "cma_minimize",
    "C1_THRESHOLD",
    "C1_OFFSET",
    "TIGHT",
    "nominal_energy",
]

Method = Literal["newton", "cma"]

_MAX_STARTS = 13  # automatic guesses tried by Newton: the first 5 plus the 8 best of the scan
_TWO_PI = 2.0 * math.pi
_EPS = float(np.finfo(float).eps)
#: numpy's least-squares gufunc (numpy >= 2.0; :func:`_lstsq`).
_GELSD = getattr(_umath_linalg, "lstsq", None)


@dataclass(frozen=True, slots=True, repr=False)
class Gait(Result):
    """A periodic gait (fixed point of the touch-down map).

    Attributes
    ----------
    state : TouchdownState
        The touch-down state of the gait.
    params : Params
        Parameters with ``alpha_r`` (and the controller's ``alphad_ref`` or
        ``tau_c``) set to the solved values.
    residual : float
        Max-norm of the periodicity residual [-].
    stance_time, flight_time : float
        Durations of the stride's phases [g^-1/2 L^1/2].
    converged : bool
        ``residual <= tol``.
    message : str
        How the search went (both residuals for ``method="cma"``).
    method : {"newton", "cma"}
        The search that produced the gait.
    cma : CMAReport or None
        The CMA-ES result before polishing (``method="cma"`` only).
    fix : {"speed", "energy"}
        What the search held: the speed at the section (``held``) or the total
        energy. ``params.v0`` is the gait's touch-down speed either way.
    section : {"touchdown", "apex"}
        The section the gait was searched on: it sets which speed ``fix="speed"``
        held, and the section of :func:`~tslip.gait.floquet` by default.
    """

    state: TouchdownState
    params: Params
    residual: float
    stance_time: float
    flight_time: float
    converged: bool
    message: str
    method: str = "newton"
    cma: CMAReport | None = None
    fix: Fix = "speed"
    section: Section = "touchdown"

    def _repr_fields(self) -> dict[str, Any]:
        return {"converged": self.converged, "residual": self.residual, "v": self.state.v,
                "beta": self.state.beta, "stance_time": self.stance_time,
                "flight_time": self.flight_time, "method": self.method}

    def to_dataframe(self) -> pd.DataFrame:
        """One row: the touch-down state, ``alpha_r``, stride times and the search's outcome."""
        s = self.state
        return frame([{"beta": s.beta, "phi": s.phi, "xd": s.xd, "yd": s.yd, "phid": s.phid,
                       "x": s.x, "h": s.h, "v": s.v, "delta": s.delta,
                       "alpha_r": self.params.alpha_r, "stance_time": self.stance_time,
                       "flight_time": self.flight_time, "residual": self.residual,
                       "converged": self.converged, "method": self.method,
                       "fix": self.fix, "section": self.section,
                       "message": self.message}], {**COLUMN_UNITS, "fix": "-", "section": "-"})

    def plot(self, ax: Axes | None = None) -> Figure:
        """The CoM path over two strides of the gait."""
        from ..plotting.results import plot_gait

        return plot_gait(self, ax)

    @property
    def energy(self) -> float:
        """Total mechanical energy [MgL] (:func:`tslip.gait.section.total_energy`)."""
        return total_energy(self.params, self.state)

    @property
    def apex(self) -> ApexState:
        """The apex of the flight that ends in this touch-down (the parabola's vertex).

        For a gait whose lift-off moves down this vertex lies before the lift-off,
        outside the flight (the apex map reports ``Status.NO_APEX`` there).
        """
        return touchdown_to_apex(self.params, self.state)

    @property
    def held(self) -> float:
        """The value the search held: touch-down speed, apex forward speed, or energy."""
        if self.fix == "energy":
            return self.energy
        return self.state.v if self.section == "touchdown" else self.state.xd


# ---------------------------------------------------------------------------
# searches: they see only pure functions of z
# ---------------------------------------------------------------------------


def newton_solve(
    residual: Callable[[np.ndarray], np.ndarray],
    starts: Iterable[np.ndarray],
    *,
    tol: float = 1e-10,
    max_starts: int | None = None,
    jacobian: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None,
) -> tuple[np.ndarray | None, float, int]:
    """Solve ``residual(z) = 0`` from each start: Newton, then least squares.

    Parameters
    ----------
    residual : callable
        Pure function ``z -> r(z)``, shape (n_eq,).
    starts : iterable of ndarray
        Starting points, tried in order until one reaches ``tol``.
    tol : float
        Max-norm residual that counts as solved.
    max_starts : int, optional
        Try at most this many starts.
    jacobian : callable, optional
        ``z -> (r(z), dr/dz)``. With it and as many equations as unknowns,
        each start first runs a damped Newton iteration (:func:`_newton`)
        that stops as soon as the residual reaches ``tol``; where it fails,
        the start falls back to Levenberg-Marquardt least squares with
        finite differences (``scipy.optimize.least_squares``, tolerances
        1e-15), the only method used without ``jacobian``. A start where
        Newton stalls (no step of at least ``_NEWTON_MIN_STEP`` lowers
        ``|r|``) with ``max|r|`` above :data:`STALL_GIVE_UP` is given up
        without least squares: it sits at a local minimum of ``|r|`` that
        is not a root.

    Returns
    -------
    z : ndarray or None
        Best point found (None if the solver failed on every start).
    err : float
        Its max-norm residual (inf if none).
    n_starts : int
        Starts tried.
    """
    best: tuple[float, np.ndarray] | None = None
    n = 0
    for z0 in starts:
        if max_starts is not None and n >= max_starts:
            break
        n += 1
        z0 = np.asarray(z0, dtype=float)
        if jacobian is not None:
            z, err = _newton(residual, jacobian, z0, tol)
            if z is not None and err <= tol:
                return z, err, n
            if z is not None and err > STALL_GIVE_UP:  # stalled far from a root: next start
                if best is None or err < best[0]:
                    best = (err, z)
                continue
        from scipy.optimize import least_squares  # here: 0.2-0.5 s to import, rarely used

        try:
            sol = least_squares(residual, z0, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                                max_nfev=400 * len(z0), diff_step=1e-7)
        except ValueError:
            continue
        err = float(np.max(np.abs(sol.fun)))
        if best is None or err < best[0]:
            best = (err, sol.x)
        if err <= tol:
            break
    if best is None:
        return None, math.inf, n
    return best[1], best[0], n


_NEWTON_MAX_ITER = 25
_NEWTON_MIN_STEP = 1.0 / 64
#: Max-norm residual above which a start where Newton stalls is given up without least
#: squares (:func:`newton_solve`). Over every point of the thesis studies (``tslip
#: reproduce``, quick and full: 1557 stalled starts) Newton stalled only at residuals of
#: 1.4e-4 or more, and least squares from those starts never reached a gait (it ended at
#: about half the stalled residual), at a third of the studies' solve time.
STALL_GIVE_UP = 1e-5


def _newton(residual: Callable[[np.ndarray], np.ndarray],
            fj: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], z0: np.ndarray,
            tol: float) -> tuple[np.ndarray | None, float]:
    """Damped Newton on a square system; ``(z, max-norm residual)`` or ``(None, inf)``.

    Each iteration solves ``J dz = -r`` (least squares where ``J`` is
    singular, as at ``r = 0`` where the pitch is undetermined) and halves
    the step until ``|r|`` decreases (Armijo). It stops at ``max|r| <= tol``;
    unless the residual is already below ``tol / 100`` (the usual case, as
    convergence is quadratic) it takes one more step with the Jacobian at
    hand, kept only if it lowers the residual (one stride). It gives up
    after ``_NEWTON_MAX_ITER`` iterations or at a non-finite Jacobian (a
    fall), returning ``(None, inf)``, and at a step shorter than
    ``_NEWTON_MIN_STEP`` (a stall), returning the point reached and its
    residual (above ``tol``).
    """
    try:
        r, J = fj(z0)
    except ValueError:
        return None, math.inf
    z = z0
    nrm = _norm(r)
    for it in range(_NEWTON_MAX_ITER + 1):
        if not (math.isfinite(nrm) and _finite(J)):
            return None, math.inf
        err = max(map(abs, r.tolist()))  # r is finite here (its norm is)
        if err <= 1e-2 * tol:  # done (the map's Jacobian at z is kept for floquet)
            return z, err
        if err > tol and it == _NEWTON_MAX_ITER:
            return None, math.inf
        dz = _lstsq(J, -r)
        if err <= tol:
            try:  # one polishing step with the Jacobian at hand
                rp = residual(z + dz)
            except ValueError:
                return z, err
            errp = float(np.abs(rp).max())
            return (z + dz, errp) if errp < err else (z, err)
        # The full step, usually taken, is tried with its Jacobian; a shortened
        # one with the residual alone (a stride, not a variational stride), its
        # Jacobian computed once it is accepted. The iterates are the same either way.
        t = 1.0
        Jn = None
        while True:
            zn = z + dz if t == 1.0 else z + t * dz  # (the same bits: 1.0 * dz is dz)
            try:
                if t == 1.0:
                    rn, Jn = fj(zn)
                else:
                    rn, Jn = residual(zn), None
                nn = _norm(rn)
            except ValueError:
                nn = math.inf
            if nn <= (1.0 - 1e-4 * t) * nrm:
                break
            t *= 0.5
            if t < _NEWTON_MIN_STEP:
                return z, err
        if Jn is None:
            try:
                rn, Jn = fj(zn)
            except ValueError:
                return None, math.inf
        z, r, J, nrm = zn, rn, Jn, nn
    return None, math.inf  # not reached


def _lstsq(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.linalg.lstsq(a, b, rcond=None)[0]`` of a float matrix and vector (the same bits).

    The same LAPACK call (``dgelsd`` through numpy's ``_umath_linalg.lstsq``)
    without the argument handling around it, most of its cost on a 5 x 5.
    Where LAPACK's SVD does not converge (never seen on a finite Jacobian) the
    step is NaN, with numpy's ``RuntimeWarning``, and the line search rejects it.
    numpy before 2.0 names the call otherwise: there ``np.linalg.lstsq`` itself.
    """
    if _GELSD is None:
        return np.linalg.lstsq(a, b, rcond=None)[0]
    return _GELSD(a, b[:, None], _EPS * max(a.shape), signature="ddd->ddid")[0][:, 0]


def _norm(r: np.ndarray) -> float:
    """``np.linalg.norm(r)`` of a float vector, without its generality (the same bits)."""
    return math.sqrt(r.dot(r))  # (a NumPy float is a float: no conversion)


# ---------------------------------------------------------------------------
# the entry point
# ---------------------------------------------------------------------------


def _wrap(prob: GaitProblem, z: np.ndarray) -> np.ndarray:
    """Shift ``phi`` and ``alpha_r`` together by whole turns so ``phi`` is in (-pi, pi].

    The touch-down leg angle depends on ``alpha_r - phi`` only (local reset),
    so the gait is unchanged; this matters at ``r = 0``, where the pitch is
    undetermined and the solver may wander.
    """
    if "phi" not in prob.names:  # held at 0
        return z
    i, j = prob.names.index("phi"), prob.names.index("alpha_r")
    turns = math.floor((z[i] + math.pi) / _TWO_PI)
    if turns == 0 or prob.params.leg_reset != "local":
        return z
    z = z.copy()
    z[i] -= turns * _TWO_PI
    z[j] -= turns * _TWO_PI
    return z


def _make_gait(prob: GaitProblem, z: np.ndarray, tol: float, message: str,
               method: str = "newton", cma: CMAReport | None = None) -> Gait:
    p, s = prob.decode(z)
    r, ts, tf = prob.evaluate(z)
    err = float(np.abs(r).max())
    return Gait(state=s, params=p, residual=err, stance_time=ts, flight_time=tf,
                converged=bool(err <= tol), message=message, method=method, cma=cma,
                fix=prob.fix, section=prob.section)


def _failure_reason(prob: GaitProblem, err: float, n_starts: int) -> str:
    if isinstance(prob.params.controller, GlobalPD):
        return (f"no exact fixed point: global PD has more equations than unknowns; "
                f"best residual {err:.2e}")
    return (f"no periodic gait found from {n_starts} starting guesses; best residual "
            f"{err:.2e} (the gait may not exist here, e.g. below the minimum speed or "
            f"past a fold of the branch)")


def _newton_gait(prob: GaitProblem, starts: Iterable[np.ndarray], tol: float,
                 max_starts: int | None) -> Gait:
    starts = iter(starts)
    first = next(starts)
    # global PD has more equations than unknowns and no exact fixed point: least squares
    # only; so too a leg spring exponent below 1, which has no exact Jacobian
    exact = not isinstance(prob.params.controller, GlobalPD) and prob.params.leg_exponent >= 1

    z, err, n = newton_solve(prob.residual, itertools.chain([first], starts), tol=tol,
                             max_starts=max_starts,
                             jacobian=prob.residual_jacobian if exact else None)
    if z is not None and not prob.exists(z):  # least squares left the energy's states
        z = None
    if z is None:  # every start failed inside the solver
        g = _make_gait(prob, first, tol, "")
        return dataclasses.replace(
            g, converged=False,
            message="no periodic gait found: the least-squares solver failed to start")
    z = _wrap(prob, z)
    msg = (f"periodic gait found, residual {err:.2e}" if err <= tol
           else _failure_reason(prob, err, n))
    return _make_gait(prob, z, tol, msg)


def _search(prob: GaitProblem, guess: np.ndarray | None = None, tol: float = 1e-10) -> Gait:
    """:func:`find_gait`'s Newton search on a problem built by the caller.

    From ``guess`` (``prob.names``, the right length) or, without one, from
    the automatic guesses; continuation builds the problem once per point.
    """
    if guess is None:
        return _newton_gait(prob, prob.guesses(), tol, _MAX_STARTS)
    return _newton_gait(prob, [guess], tol, None)


def _cma_gait(prob: GaitProblem, starts: Iterable[np.ndarray], tol: float, seed: int | None,
              max_evals: int, polish: bool, jacobian: Literal["fd", "exact"]) -> Gait:
    if seed is None:
        seed = int(np.random.default_rng().integers(2**32))
    starts = list(starts)
    if len(starts) == 1:
        x0 = starts[0]
    else:  # the lowest C1 among the automatic guesses
        c1s = [prob.c1(z) for z in starts]
        x0 = starts[int(np.argmin(c1s))]
    lo, hi = prob.bounds()
    x0 = np.clip(x0, lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))
    t0 = time.perf_counter()
    x, f, nev, nit, stop = cma_minimize(
        lambda z: prob.cost(z, jacobian=jacobian), x0, stds=prob.scales(), lower=lo,
        upper=hi, seed=seed, max_evals=max_evals)
    seconds = time.perf_counter() - t0
    c1 = prob.c1(x)
    c2 = prob.c2(x, jacobian) if c1 <= C1_THRESHOLD else math.nan
    report = CMAReport(seed=seed, evaluations=nev, iterations=nit, z=tuple(map(float, x)),
                       c1=c1, c2=c2, cost=f, stop=stop, seconds=seconds)
    head = f"CMA-ES (seed {seed}, {nev} evaluations, {seconds:.2f} s): C1 {c1:.2e}"
    if c1 <= C1_THRESHOLD:
        head += f" < {C1_THRESHOLD:g}, max |lambda| {math.sqrt(c2):.6f}"
    else:
        head += f" > {C1_THRESHOLD:g}: no near-periodic point"
        if c1 < 10 * C1_THRESHOLD:
            head += (f" (if its multipliers exceed sqrt({C1_OFFSET:g}), eq. 2.22 ranks "
                     "non-periodic points first)")
    r_cma = float(np.max(np.abs(prob.residual(x))))
    head += f", residual {r_cma:.2e}"
    if not polish:
        return _make_gait(prob, x, tol, head, "cma", report)
    z, err, _ = newton_solve(prob.residual, [x], tol=tol, jacobian=(
        prob.residual_jacobian if prob.params.leg_exponent >= 1 else None))
    if z is None or err > r_cma:  # polishing did not help: keep the CMA-ES point
        return _make_gait(prob, x, tol, head + "; Newton polish failed", "cma", report)
    z = _wrap(prob, z)
    return _make_gait(prob, z, tol, head + f"; Newton polish: residual {err:.2e}", "cma",
                      report)


def _held_pitch_guess(prob: GaitProblem, z0: np.ndarray) -> np.ndarray:
    """A guess of the form before the pitch was held at ``r = 0``, without the held entries.

    Until 0.3 a guess was always ``(delta, phi, phid, alpha_r[, reference])``;
    at ``r = 0`` the search now holds ``phi`` (and ``phid`` without hip torque;
    docs/conventions.md, "Held pitch"). The old form is accepted, with a
    ``DeprecationWarning``, until 0.5.
    """
    if z0.ndim != 1 or z0.size == prob.size:
        return z0
    full = ("delta", "phi", "phid", *prob.names[prob.names.index("alpha_r"):])
    if z0.size != len(full):
        return z0
    held = [n for n in full if n not in prob.names]
    warnings.warn(
        f"at r = 0 the guess is ({', '.join(prob.names)}); {' and '.join(held)} "
        f"{'is' if len(held) == 1 else 'are'} held (docs/conventions.md, 'Held pitch'). "
        f"A guess of {len(full)} entries ({', '.join(full)}) is deprecated and refused "
        "from 0.5", DeprecationWarning, stacklevel=3)
    return np.array([v for n, v in zip(full, z0) if n in prob.names])


def find_gait(
    params: Params,
    *,
    v0: float | None = None,
    beta0: float | None = None,
    guess: np.ndarray | None = None,
    tol: float = 1e-10,
    options: IntegratorOptions | None = None,
    method: Method = "newton",
    seed: int | None = None,
    max_evals: int = 3000,
    polish: bool = True,
    jacobian: Literal["fd", "exact"] = "fd",
    fix: Fix = "speed",
    energy: float | None = None,
    section: Section = "touchdown",
) -> Gait:
    """Find a periodic gait at the nominal speed ``v0`` (or energy) and angle ``beta0``.

    Parameters
    ----------
    params : Params
        Model; ``params.v0`` and ``params.beta0`` are used unless overridden.
    v0, beta0 : float, optional
        Override the nominal speed [g^1/2 L^1/2] and touch-down angle [rad].
    fix : {"speed", "energy"}
        Hold the speed ``v0`` at the section (default), or the total energy
        ``energy`` (:func:`tslip.gait.section.total_energy`), which the SLIP
        literature fixes; the returned ``gait.params.v0`` is the touch-down
        speed found.
    energy : float, optional
        Total energy [MgL] with ``fix="energy"``; default :func:`nominal_energy`
        (touch-down at ``v0`` and ``beta0`` with a level trunk).
    section : {"touchdown", "apex"}
        With ``fix="speed"``, ``v0`` is the touch-down speed or the apex's
        forward speed. Also the default section of the gait's Floquet multipliers.
    guess : ndarray, optional
        Starting unknowns ``(delta, phi, phid, alpha_r[, alphad_ref | tau_c])``
        (``GaitProblem.names``: at ``r = 0`` without ``phi``, and without
        ``phid`` when no hip torque acts, docs/conventions.md "Held pitch";
        the full form still works there, with a ``DeprecationWarning``, until
        0.5); by default the automatic guesses of :meth:`GaitProblem.guesses`.
    tol : float
        Max-norm residual for ``converged``.
    options : IntegratorOptions, optional
        Defaults to tolerance 1e-12 with DOP853 so the residual can reach ``tol``.
    method : {"newton", "cma"}
        ``"newton"``: Newton on the residual (exact fixed point), with
        Levenberg-Marquardt as the fallback from each start.
        ``"cma"``: CMA-ES on the two-stage cost of eqs 2.20-2.22, as in the
        thesis: it minimises the largest non-trivial multiplier among points
        with ``C1 < 1e-4``, so its result is a near-fixed point (reported in
        ``gait.cma``), then polished by Newton unless ``polish=False``. As in
        the thesis, the offset 25 of eq. 2.22 assumes ``|lambda| < 5``: for
        more unstable gaits CMA-ES stays just above ``C1 = 1e-4`` (the
        polish still finds the fixed point).
    seed : int, optional
        CMA-ES seed; the same seed gives the identical result. ``None`` draws
        one (reported in ``gait.cma.seed``).
    max_evals : int
        CMA-ES budget of cost evaluations (about 0.1 ms each for ``C1``,
        1 ms for ``C2``).
    polish : bool
        Newton-polish the CMA-ES result to the exact fixed point nearby.
    jacobian : {"fd", "exact"}
        Multipliers in ``C2``: central differences (eq. B.2, as the thesis)
        or the variational equations.

    Returns
    -------
    Gait
        ``converged=False`` with the best residual and the reason when no
        start reaches ``tol`` (the global PD controller has one equation more
        than unknowns; some parameters have no gait at all).

    Raises
    ------
    ValueError
        For a ``guess`` of the wrong length or an unknown ``method``.

    References
    ----------
    Thesis Section 2.8, eqs 2.19-2.24; docs/conventions.md "Poincare section and
    periodic gaits".

    Examples
    --------
    >>> import tslip
    >>> g = find_gait(tslip.preset("table2.1"))
    >>> g.converged, round(g.params.alpha_r, 4)
    (True, 0.7935)
    """
    if method not in ("newton", "cma"):
        raise ValueError(f"method must be 'newton' or 'cma', got {method!r}")
    if v0 is not None or beta0 is not None:
        params = dataclasses.replace(
            params, v0=params.v0 if v0 is None else v0,
            beta0=params.beta0 if beta0 is None else beta0,
        )
    prob = GaitProblem.from_params(params, options, fix=fix, section=section, energy=energy)
    z0 = None
    if guess is not None:
        z0 = _held_pitch_guess(prob, np.asarray(guess, dtype=float))
        if z0.shape != (prob.size,):
            raise ValueError(f"guess must have {prob.size} entries {list(prob.names)}, "
                             f"got {z0.size}")
    if method == "cma":
        if max_evals < 1:
            raise ValueError(f"max_evals must be >= 1, got {max_evals!r}")
        starts = prob.guesses() if z0 is None else [z0]
        gait = _cma_gait(prob, starts, tol, seed, max_evals, polish, jacobian)
    else:
        gait = _search(prob, z0, tol)
    return _refuse_binding_stop(gait, options)


def _refuse_binding_stop(gait: Gait, options: IntegratorOptions | None) -> Gait:
    """``gait``, unless it touches down held by the retraction stop (``alpha_stop``).

    Held there, ``alpha_r`` drops out of the residual (Section 7.5's stop is a
    disturbance-only mechanism; docs/conventions.md).
    """
    p = gait.params
    if not gait.converged or p.alpha_stop is None:
        return gait
    s = step(p, gait.state, options=options)
    if s.ok and _packed.stop_binds(packed_params(p), s.liftoff.yd, s.flight_time):
        raise ValueError("alpha_stop binds at the periodic gait, so alpha_r has no effect; "
                         "choose alpha_stop beyond alpha_TD")
    return gait
