"""Natural-parameter continuation of periodic gaits (thesis Sections 3.4-3.7).

The thesis's parameter studies (Figures 4.8-4.24) follow one gait of Table
2.1 while a single parameter varies: speed ``v0``, leg damping ``c_l``, hip
damping ``c_h``, mass offset ``r``, stiffness ``k``, touch-down angle
``beta0`` and the normalised retraction rate of eq. 2.18. Here each point is
solved by :func:`~tslip.gait.fixed_point.find_gait`, warm-started from its
neighbours (a secant predictor through the last two points), with the
automatic guesses as a fallback; the multipliers are
:func:`~tslip.gait.stability.floquet` (exact Jacobian), computed right after
each point is solved, usually from the Jacobian the Newton search left at the
gait (:mod:`tslip.simulation._packed` keeps it). Natural continuation
cannot turn around a fold: the branch ends where the gait ceases to exist,
which is what the thesis reports as "no periodic limit cycles are found".

Parameter names: the :class:`~tslip.model.parameters.Params` fields (``v0``,
``k``, ``beta0``, ``r``, ``omega_r``, ``c_l``, ``m``, ``J``, ``l0``, ``g``),
``"omega_r_bar"`` (eq. 2.18, at the point's ``v0``) and controller gains by
dotted name (``"controller.c_h"``, ``"controller.Kd"``, ``"controller.Kp"``).

What the branch holds besides the parameter (``fix``, ``energy``, ``section``
of :func:`~tslip.gait.fixed_point.find_gait`): the speed ``v0`` at the
touch-down (the thesis's studies) or at the apex, or the total energy (the
SLIP literature's): a continuation along ``beta0`` at fixed speed changes the
energy, and its stability boundaries move. :func:`stability_boundaries`
re-solves with what the branch held.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from .._results import Result, with_units
from ..model.parameters import PARAMETER_TABLE, Params
from ..model.units import COLUMN_UNITS, param_unit
from ..simulation.options import IntegratorOptions
from .fixed_point import Gait, GaitProblem, _search, find_gait
from .problem import Fix, Section, checked_replace, nominal_energy, thrust_solved
from .section import apex_section_ok
from .stability import floquet

__all__ = [
    "Branch",
    "continue_gait",
    "get_param",
    "set_param",
    "stability_boundaries",
]

_FIELDS = {row.name for row in PARAMETER_TABLE}
_SOLVED = {"alpha_r", "controller.alphad_ref", "controller.tau_c"}

Progress = Callable[[int, int, float, "Gait | None"], None]



# ---------------------------------------------------------------------------
# parameter access by name
# ---------------------------------------------------------------------------


def _check_name(params: Params, name: str) -> None:
    if name == "alpha_stop":
        raise ValueError("alpha_stop cannot be swept (it may be None, no stop); set it in the "
                         "parameters of each run")
    if name in _SOLVED or (name == "leg_thrust" and thrust_solved(params)):
        raise ValueError(f"{name!r} is solved for by the gait search (Section 2.8); it cannot "
                         "be a continuation parameter")
    if name in _FIELDS or name == "omega_r_bar":
        return
    if name.startswith("controller."):
        gain = name.split(".", 1)[1]
        allowed = [f.name for f in dataclasses.fields(params.controller)]
        if gain in allowed:
            return
        raise ValueError(f"controller {type(params.controller).__name__} has no field "
                         f"{gain!r}; allowed: {allowed}")
    raise ValueError(f"unknown parameter {name!r}; allowed: {sorted(_FIELDS - {'alpha_r'})}, "
                     "'omega_r_bar' or 'controller.<gain>'")


def get_param(params: Params, name: str) -> float:
    """Value of a continuation parameter (see :func:`set_param`)."""
    _check_name(params, name)
    if name == "omega_r_bar":
        return params.omega_r_bar
    if name.startswith("controller."):
        return float(getattr(params.controller, name.split(".", 1)[1]))
    return float(getattr(params, name))


def set_param(params: Params, name: str, value: float) -> Params:
    """Copy of ``params`` with one scalar parameter changed.

    Parameters
    ----------
    params : Params
        Base parameters (unchanged).
    name : str
        A :class:`Params` field, ``"omega_r_bar"`` (eq. 2.18: sets ``omega_r
        = value * v0 / l0``) or ``"controller.<gain>"``.
    value : float
        New value, in the parameter's unit (Table 3.1).

    Returns
    -------
    Params
        Only the changed value is checked (``params`` was checked when built;
        :func:`~tslip.gait.problem.checked_replace`).

    Raises
    ------
    ValueError
        For an unknown name, a solved-for variable (``alpha_r``,
        ``controller.alphad_ref``, ``controller.tau_c``) or an invalid value.
    """
    _check_name(params, name)
    value = float(value)
    if name == "omega_r_bar":
        return params.with_omega_r_bar(value)
    if name.startswith("controller."):
        gain: dict[str, Any] = {name.split(".", 1)[1]: value}
        return checked_replace(params, controller=checked_replace(params.controller, **gain))
    change: dict[str, Any] = {name: value}
    return checked_replace(params, **change)


# ---------------------------------------------------------------------------
# the result
# ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False, repr=False)
class Branch(Result):
    """A gait followed along one parameter.

    Attributes
    ----------
    param : str
        Name of the continuation parameter.
    values : ndarray, shape (n,)
        Parameter values, ascending.
    gaits : tuple of (Gait or None)
        The gait at each value; None where none was found or the point was
        not attempted (past the end of the branch).
    converged : ndarray of bool, shape (n,)
    residual : ndarray, shape (n,)
        Best max-norm residual (NaN where not attempted).
    stance_time, flight_time : ndarray, shape (n,)
        [g^-1/2 L^1/2], NaN where there is no gait.
    multipliers : ndarray of complex, shape (n, 5) or (n, 4)
        Floquet multipliers (exact Jacobian) on the branch's section, largest
        first; NaN where none.
    trivial : ndarray of bool, shape (n, 5) or (n, 4)
        Structural multipliers (energy; pitch rate at ``r = 0``).
    max_nontrivial : ndarray, shape (n,)
        Largest non-trivial magnitude, NaN where none.
    stability : tuple of str
        ``"asymptotic"``, ``"neutral"``, ``"unstable"``, ``"none"`` (no gait)
        or ``"unknown"`` (a perturbed stride fails).
    messages : tuple of str
        Per point: how it was found or why not.
    base : float
        The parameter's value in the starting gait or parameters.
    params : Params
        The starting parameters.
    tol : float
        Residual tolerance used.
    options : IntegratorOptions or None
        Integrator settings used (None: the default, tolerance 1e-12).
    seconds : ndarray, shape (n,)
        Wall time per point [s] (solve plus multipliers).
    fix : {"speed", "energy"}
        What each point held besides the parameter: the speed ``params.v0`` at
        the section, or the total energy ``energy``.
    energy : float
        The energy held [MgL] (NaN with ``fix="speed"``).
    section : {"touchdown", "apex"}
        The section of the speed held and of the multipliers.
    """

    param: str
    values: np.ndarray
    gaits: tuple[Gait | None, ...]
    converged: np.ndarray
    residual: np.ndarray
    stance_time: np.ndarray
    flight_time: np.ndarray
    multipliers: np.ndarray
    trivial: np.ndarray
    max_nontrivial: np.ndarray
    stability: tuple[str, ...]
    messages: tuple[str, ...]
    base: float
    params: Params
    tol: float
    options: IntegratorOptions | None
    seconds: np.ndarray = field(repr=False)
    fix: Fix = "speed"
    energy: float = math.nan
    section: Section = "touchdown"

    def __len__(self) -> int:
        return len(self.values)

    def __repr__(self) -> str:
        """One line: parameter, range, points with a gait, what was held."""
        held = (f"energy {self.energy:.6g}" if self.fix == "energy"
                else f"{self.section} speed {self.params.v0:.6g}")
        return (f"Branch({self.param} {self.values[0]:.6g} to {self.values[-1]:.6g}, "
                f"{int(self.converged.sum())} of {len(self)} with a gait, {held})")

    @property
    def hold(self) -> dict[str, Any]:
        """``find_gait`` keywords of what the branch held (``fix``, ``energy``, ``section``)."""
        return {"fix": self.fix, "section": self.section,
                "energy": self.energy if self.fix == "energy" else None}

    def plot(self, ax: Any = None) -> Any:
        """Non-trivial multiplier magnitudes against the parameter (thesis Figure 4.8)."""
        from ..plotting.sweeps import plot_branch

        return plot_branch(self, ax)

    @property
    def stable(self) -> np.ndarray:
        """At least neutrally stable (the thesis's green areas)."""
        return np.array([s in ("asymptotic", "neutral") for s in self.stability])

    def exists(self) -> tuple[float, float]:
        """Smallest and largest value with a gait (NaN if none)."""
        v = self.values[self.converged]
        return (float(v.min()), float(v.max())) if v.size else (math.nan, math.nan)

    def to_dataframe(self) -> pd.DataFrame:
        """Tidy table, one row per point.

        Columns: ``param``, ``value``, ``converged``, ``residual``, ``delta``,
        ``phi``, ``phid``, ``alpha_r``, the controller reference
        (``alphad_ref`` or ``tau_c`` when the controller has one),
        ``stance_time``, ``flight_time``, ``energy`` (total, MgL),
        ``abs_lambda_1`` ... ``abs_lambda_5`` (descending; 4 on the apex
        section), ``max_nontrivial``, ``stability``, ``message``.
        """
        ctrl = self.params.controller
        ref = next((n for n in ("alphad_ref", "tau_c") if hasattr(ctrl, n)), None)
        thrust = thrust_solved(self.params)
        rows = []
        for i, g in enumerate(self.gaits):
            row: dict[str, object] = {
                "param": self.param, "value": float(self.values[i]),
                "converged": bool(self.converged[i]), "residual": float(self.residual[i]),
                "delta": g.state.delta if g else math.nan,
                "phi": g.state.phi if g else math.nan,
                "phid": g.state.phid if g else math.nan,
                "alpha_r": g.params.alpha_r if g else math.nan,
            }
            if ref is not None:
                row[ref] = float(getattr(g.params.controller, ref)) if g else math.nan
            if thrust:
                row["leg_thrust"] = float(g.params.leg_thrust) if g else math.nan
            row["stance_time"] = float(self.stance_time[i])
            row["flight_time"] = float(self.flight_time[i])
            row["energy"] = g.energy if g else math.nan
            mags = np.sort(np.abs(self.multipliers[i]))[::-1]
            for j, m in enumerate(mags, 1):
                row[f"abs_lambda_{j}"] = float(m)
            row["max_nontrivial"] = float(self.max_nontrivial[i])
            row["stability"] = self.stability[i]
            row["message"] = self.messages[i]
            rows.append(row)
        units = {**COLUMN_UNITS, "param": "-", "value": param_unit(self.param) or "-",
                 "max_nontrivial": "-", **{f"abs_lambda_{j}": "-" for j in range(1, 6)}}
        return with_units(pd.DataFrame(rows), units)


# ---------------------------------------------------------------------------
# continuation
# ---------------------------------------------------------------------------


def _solve_point(
    base: Params, param: str, value: float, history: list[tuple[float, Gait]], tol: float,
    options: IntegratorOptions | None, predictor: str, hold: dict[str, Any] | None = None,
) -> tuple[Gait, str]:
    """One point: secant predictor, then the neighbour, then the automatic guesses.

    ``base`` carries the speed held (a gait's ``params.v0`` is its touch-down
    speed, not the apex speed a branch may hold); ``hold``: ``find_gait``'s
    ``fix``, ``energy``, ``section``.
    """
    hold = hold or {}
    p = set_param(base, param, value)
    prob = GaitProblem.from_params(p, options, **hold)
    starts: list[tuple[str, np.ndarray]] = []
    if history:
        z1 = prob.encode(history[-1][1])
        if predictor == "secant" and len(history) >= 2:
            (v0, g0), (v1, _) = history[-2], history[-1]
            z0 = prob.encode(g0)
            if v1 != v0:
                starts.append(("secant predictor", z1 + (z1 - z0) * (value - v1) / (v1 - v0)))
        starts.append(("neighbour", z1))
    best: Gait | None = None
    for how, z in starts:
        g = _search(prob, z, tol)
        if g.converged:
            return g, f"{g.message} (warm start: {how})"
        if best is None or g.residual < best.residual:
            best = g
    g = _search(prob, None, tol)
    if g.converged or best is None or g.residual < best.residual:
        best = g
    how = "automatic guess" + (" after the warm start failed" if starts else "")
    return best, f"{best.message} ({how})"


def continue_gait(
    gait_or_params: Gait | Params,
    param: str,
    values: Sequence[float] | np.ndarray,
    *,
    tol: float = 1e-10,
    options: IntegratorOptions | None = None,
    progress: Progress | None = None,
    predictor: str = "secant",
    max_failures: int | None = 2,
    multipliers: bool = True,
    fix: Fix = "speed",
    energy: float | None = None,
    section: Section = "touchdown",
) -> Branch:
    """Follow a periodic gait along one scalar parameter.

    Starts at the value nearest the base value (the parameter's value in
    ``gait_or_params``) and walks up and down from it, warm-starting each
    point from its neighbours. A point that fails is retried from the
    automatic guesses; after ``max_failures`` consecutive failures in one
    direction the branch ends there and the remaining points are marked
    "not attempted".

    Parameters
    ----------
    gait_or_params : Gait or Params
        A solved gait (warm start at the base value) or parameters (solved
        first with :func:`find_gait`).
    param : str
        Parameter name (module docstring), e.g. ``"v0"``, ``"omega_r_bar"``,
        ``"controller.c_h"``.
    values : sequence of float
        Parameter values, in the parameter's unit; sorted ascending.
    tol : float
        Max-norm residual for a point to count as a gait. For the global PD
        controller, which has no exact fixed point, pass ``tol=1e-2`` (the
        thesis's ``C1 < 1e-4``).
    options : IntegratorOptions, optional
        Integrator settings (default tolerance 1e-12).
    progress : callable, optional
        ``progress(done, total, value, gait_or_None)`` after each point.
    predictor : {"secant", "constant"}
        Warm start from the secant through the last two points (then the
        last point), or from the last point only.
    max_failures : int or None
        Consecutive failures that end the branch in one direction; None
        attempts every value.
    multipliers : bool
        Compute the Floquet multipliers (exact Jacobian) of each gait, on ``section``.
    fix, energy, section
        What every point holds besides the parameter, as in ``find_gait``: the
        speed ``v0`` at the section, or the total energy (default: the
        starting parameters' :func:`~tslip.gait.problem.nominal_energy`, held
        along the whole branch).

    Returns
    -------
    Branch

    Raises
    ------
    ValueError
        For an unknown or solved-for parameter, or values that are empty,
        not finite or repeated.

    Examples
    --------
    >>> import tslip
    >>> b = continue_gait(tslip.preset("table2.1"), "v0", [4.0, 5.0, 6.0])
    >>> b.converged.tolist(), b.stability
    ([True, True, True], ('asymptotic', 'asymptotic', 'asymptotic'))
    """
    if isinstance(gait_or_params, Gait):
        params = gait_or_params.params
        if gait_or_params.section == "apex" and gait_or_params.fix == "speed":
            params = dataclasses.replace(params, v0=gait_or_params.state.xd)  # the speed held
    else:
        params = gait_or_params
    if fix == "energy":
        if param == "v0":
            raise ValueError("param 'v0' is not held with fix='energy': the energy sets the "
                             "speed")
        energy = nominal_energy(params) if energy is None else energy
    hold: dict[str, Any] = {"fix": fix, "energy": energy, "section": section}
    GaitProblem.from_params(params, options, **hold)  # checks fix, section and energy
    if section == "apex" and multipliers and not apex_section_ok(params):
        raise ValueError("the apex multipliers need omega_r = 0 or retraction from the apex, "
                         f"got omega_r={params.omega_r!r}")
    base_value = get_param(params, param)
    vals = np.sort(np.asarray(values, dtype=float).ravel())
    if vals.size == 0 or not np.all(np.isfinite(vals)):
        raise ValueError("values must be a non-empty sequence of finite numbers")
    if np.any(np.diff(vals) == 0):
        raise ValueError("values must not repeat")
    if predictor not in ("secant", "constant"):
        raise ValueError(f"predictor must be 'secant' or 'constant', got {predictor!r}")
    n = vals.size
    gaits: list[Gait | None] = [None] * n
    best: list[Gait | None] = [None] * n
    msgs = ["not attempted: past the end of the branch"] * n
    seconds = np.full(n, math.nan)

    nm = 4 if section == "apex" else 5
    lam = np.full((n, nm), np.nan, dtype=complex)
    triv = np.zeros((n, nm), dtype=bool)
    mnt = np.full(n, math.nan)
    stab = ["none"] * n

    def multipliers_at(i: int, g: Gait) -> None:
        # right after the solve: the exact Jacobian Newton computed at the gait is
        # still kept (tslip.simulation._packed), so this costs no stride
        try:
            f = floquet(g, method="exact", options=options, section=section)
        except ValueError:
            stab[i] = "unknown"
        else:
            lam[i], triv[i], mnt[i], stab[i] = f.multipliers, f.trivial, f.max_nontrivial, \
                f.stability

    anchor = gait_or_params if isinstance(gait_or_params, Gait) else None
    if anchor is not None and anchor.converged and not _holds(anchor, hold):
        # a gait of another constraint: the warm start of one that holds the branch's
        z = GaitProblem.from_params(params, options, **hold).encode(anchor)
        anchor = find_gait(params, guess=z, tol=tol, options=options, **hold)
    if anchor is None or not anchor.converged:
        anchor = find_gait(params, tol=tol, options=options, **hold)
    start: list[tuple[float, Gait]] = [(base_value, anchor)] if anchor.converged else []
    i0 = int(np.argmin(np.abs(vals - base_value)))
    done = 0

    def walk(indices: range, history: list[tuple[float, Gait]]) -> None:
        nonlocal done
        failures = 0
        for i in indices:
            if max_failures is not None and failures >= max_failures:
                break
            t0 = time.perf_counter()
            g, msg = _solve_point(params, param, float(vals[i]), history, tol, options,
                                  predictor, hold)
            best[i], msgs[i] = g, msg
            if g.converged:
                gaits[i] = g
                if multipliers:
                    multipliers_at(i, g)
                history = (history + [(float(vals[i]), g)])[-2:]
                failures = 0
            else:
                failures += 1
            seconds[i] = time.perf_counter() - t0
            done += 1
            if progress is not None:
                progress(done, n, float(vals[i]), gaits[i])

    walk(range(i0, n), list(start))
    g0 = gaits[i0]
    first = [(float(vals[i0]), g0)] if g0 is not None else []
    walk(range(i0 - 1, -1, -1), (start + first)[-2:] if first else list(start))

    def arr(attr: str) -> np.ndarray:
        return np.array([getattr(g, attr) if g is not None else math.nan for g in gaits])

    return Branch(
        param=param, values=vals, gaits=tuple(gaits),
        converged=np.array([g is not None for g in gaits]),
        residual=np.array([b.residual if b is not None else math.nan for b in best]),
        stance_time=arr("stance_time"), flight_time=arr("flight_time"),
        multipliers=lam, trivial=triv, max_nontrivial=mnt, stability=tuple(stab),
        messages=tuple(msgs), base=base_value, params=params, tol=tol, options=options,
        seconds=seconds, fix=fix, energy=math.nan if energy is None else float(energy),
        section=section,
    )


def _holds(gait: Gait, hold: dict[str, Any]) -> bool:
    """Whether ``gait`` satisfies the constraint ``hold`` (to 1e-9 in the energy)."""
    if gait.fix != hold["fix"] or gait.section != hold["section"]:
        return False
    return hold["fix"] != "energy" or abs(gait.energy - float(hold["energy"])) <= 1e-9


# ---------------------------------------------------------------------------
# where stability changes
# ---------------------------------------------------------------------------


def stability_boundaries(
    branch: Branch,
    *,
    level: float = 1.0,
    refine: bool = True,
    xtol: float = 1e-6,
) -> np.ndarray:
    """Parameter values where the largest non-trivial multiplier crosses ``level``.

    Parameters
    ----------
    branch : Branch
        From :func:`continue_gait` with multipliers.
    level : float
        Magnitude to cross (1: the unit circle, Section 3.1.2).
    refine : bool
        Solve ``max_nontrivial(value) = level`` between the two bracketing
        points by Brent's method, each evaluation a gait warm-started from
        the nearer end; otherwise interpolate linearly.
    xtol : float
        Tolerance on the parameter value (``refine=True``).

    Returns
    -------
    ndarray
        Crossing values, ascending (empty if none).
    """
    out = []
    v, m = branch.values, branch.max_nontrivial - level
    for i in range(len(v) - 1):
        if not (np.isfinite(m[i]) and np.isfinite(m[i + 1])) or m[i] * m[i + 1] > 0:
            continue
        if m[i] == 0 or m[i + 1] == 0:
            out.append(float(v[i] if m[i] == 0 else v[i + 1]))
            continue
        x_lin = float(v[i] - m[i] * (v[i + 1] - v[i]) / (m[i + 1] - m[i]))
        if not refine:
            out.append(x_lin)
            continue
        ga, gb = branch.gaits[i], branch.gaits[i + 1]
        if ga is None or gb is None:  # multipliers without gaits: not from continue_gait
            out.append(x_lin)
            continue

        def f(x: float, ga: Gait = ga, gb: Gait = gb, va: float = v[i],
              vb: float = v[i + 1]) -> float:
            near = ga if abs(x - va) <= abs(x - vb) else gb
            p = set_param(branch.params, branch.param, x)  # holds what the branch held
            z = GaitProblem.from_params(p, branch.options, **branch.hold).encode(near)
            g = find_gait(p, guess=z, tol=branch.tol, options=branch.options, **branch.hold)
            if not g.converged:
                raise RuntimeError(f"no gait at {branch.param} = {x}: {g.message}")
            f = floquet(g, options=branch.options, section=branch.section)
            return f.max_nontrivial - level

        from scipy.optimize import brentq  # here: scipy.optimize costs 0.2-0.5 s to import

        try:
            out.append(float(brentq(f, float(v[i]), float(v[i + 1]), xtol=xtol)))
        except (RuntimeError, ValueError):
            out.append(x_lin)
    return np.array(out)
