"""Every periodic gait at fixed energy (or speed), and the stable region over two parameters.

At given total energy and leg angle the SLIP has two periodic gaits, one of
them self-stable (Seyfarth et al. 2002): a flat one with a short flight and
a steep one. They merge at a fold and vanish (a saddle-node). A gait search
returns one of them depending on its start, and a continuation often follows
the unstable twin past the stable one's end, so neither answers "which gaits
exist here, and which are stable".

:func:`all_gaits` scans the touch-down velocity angle ``delta`` at fixed
energy (the other unknowns at the starting guesses of
:meth:`~tslip.gait.problem.GaitProblem.guesses`: level trunk, ``alpha_r``
from the flight time), brackets each sign change of the ``delta`` residual
(``delta' - delta``, the one-dimensional apex-height map at fixed energy in
the SLIP), solves each bracket with Newton and keeps the distinct gaits,
each with its Floquet multipliers. Where a scan point's stride fails and its
neighbour's does not, the interval is bisected toward the edge of the map's
defined domain, so a gait right next to a failing stride (the flat,
strongly unstable gaits of the SLIP, multipliers down to -11 on
``slip-human``) is bracketed too. What is guaranteed and what can still be
missed: :func:`all_gaits`, Notes.

:func:`stable_region` solves every cell of a two-parameter grid
independently with :func:`all_gaits`, so a cell's answer does not depend on
a path through the grid.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._results import Result
from ..model.parameters import Params
from ..model.units import COLUMN_UNITS, param_unit
from ..simulation.options import IntegratorOptions
from .continuation import get_param, set_param
from .fixed_point import Gait, find_gait
from .problem import _FALL_PENALTY, Fix, GaitProblem, Section
from .stability import Floquet, floquet

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["GaitSet", "StableRegion", "all_gaits", "stable_region", "DEFAULT_DELTAS"]

#: The default scan of touch-down velocity angles [rad]: geometric near 0 (the flat
#: gaits' short flights), then every 0.025 rad to -1.5.
DEFAULT_DELTAS = -np.unique(np.concatenate([np.geomspace(1e-3, 0.1, 12),
                                             np.arange(0.1, 1.5 + 1e-9, 0.025)]))
_SAME = 1e-7  # two solutions with delta and alpha_r this close are one gait
_EDGE_TOL = 1e-7  # [rad] how close to the edge of the defined domain the scan is refined


@dataclass(frozen=True, eq=False)
class GaitSet(Result):
    """The periodic gaits found at one energy and one set of parameters.

    Attributes
    ----------
    params : Params
        The parameters scanned.
    energy : float
        Total energy held [MgL]; NaN where the speed ``params.v0`` was held.
    gaits : tuple of Gait
        Distinct gaits, flattest touch-down first (``delta`` closest to 0).
    floquets : tuple of (Floquet or None)
        Their multipliers on ``section`` (None where a perturbed stride fails).
    section : {"touchdown", "apex"}
    deltas : ndarray
        The scanned touch-down velocity angles [rad].
    seconds : float
        Wall time [s].
    """

    params: Params
    energy: float
    gaits: tuple[Gait, ...]
    floquets: tuple[Floquet | None, ...]
    section: Section = "touchdown"
    deltas: np.ndarray = field(default_factory=lambda: DEFAULT_DELTAS, repr=False)
    seconds: float = field(default=math.nan, repr=False)

    def __len__(self) -> int:
        return len(self.gaits)

    def __iter__(self) -> Iterator[Gait]:
        return iter(self.gaits)

    def __getitem__(self, i: int) -> Gait:
        return self.gaits[i]

    @property
    def stability(self) -> tuple[str, ...]:
        """Each gait's label (``"unknown"`` where its multipliers failed)."""
        return tuple(f.stability if f is not None else "unknown" for f in self.floquets)

    @property
    def max_nontrivial(self) -> np.ndarray:
        """Each gait's largest non-trivial multiplier magnitude (NaN if unknown)."""
        return np.array([f.max_nontrivial if f is not None else math.nan
                         for f in self.floquets])

    @property
    def stable(self) -> tuple[Gait, ...]:
        """The gaits at least neutrally stable."""
        return tuple(g for g, f in zip(self.gaits, self.floquets)
                     if f is not None and f.stable)

    def __repr__(self) -> str:
        what = ", ".join(f"{s} {m:.4g}" for s, m in zip(self.stability, self.max_nontrivial))
        held = (f"energy {self.energy:.6g}" if math.isfinite(self.energy)
                else f"speed {self.params.v0:.6g} ({self.section})")
        return (f"GaitSet({len(self)} gaits at {held}"
                + (f": {what})" if what else ")"))

    def to_dataframe(self) -> pd.DataFrame:
        """One row per gait: ``delta``, ``v``, ``apex_y``, ``alpha_r``, times,
        ``max_nontrivial``, ``stability``, ``residual``; units in ``df.attrs["units"]``."""
        import pandas as pd

        rows = [{"delta": g.state.delta, "v": g.state.v, "apex_y": g.apex.y,
                 "alpha_r": g.params.alpha_r, "stance_time": g.stance_time,
                 "flight_time": g.flight_time, "energy": g.energy,
                 "max_nontrivial": float(m), "stability": s, "residual": g.residual}
                for g, m, s in zip(self.gaits, self.max_nontrivial, self.stability)]
        cols = ["delta", "v", "apex_y", "alpha_r", "stance_time", "flight_time", "energy",
                "max_nontrivial", "stability", "residual"]
        df = pd.DataFrame(rows, columns=cols)
        df.attrs["units"] = {c: COLUMN_UNITS.get(c, "-") for c in cols}
        df.attrs["units"]["apex_y"] = COLUMN_UNITS["y"]
        return df


def _brackets(prob: GaitProblem, deltas: np.ndarray) -> list[np.ndarray]:
    """Starts at the sign changes of the ``delta`` residual along the scan (interpolated).

    An interval whose two ends differ in outcome (one stride falls) is bisected
    toward the edge of the map's defined domain, down to :data:`_EDGE_TOL`, and
    the residual's sign on the defined side is bracketed there too.
    """
    zs = [prob._guess(float(d)) for d in deltas]
    r = np.array([prob.residual(z) for z in zs])
    ok = ~np.all(r == _FALL_PENALTY, axis=1)
    f = r[:, 3]
    starts = []
    for i in range(len(deltas) - 1):
        if ok[i] and ok[i + 1]:
            if f[i] * f[i + 1] <= 0.0:
                starts.append(_interpolate(zs[i], zs[i + 1], f[i], f[i + 1]))
        elif ok[i] != ok[i + 1]:
            j, m = (i, i + 1) if ok[i] else (i + 1, i)
            z = _toward_edge(prob, float(deltas[j]), zs[j], f[j], float(deltas[m]))
            if z is not None:
                starts.append(z)
    return starts


def _interpolate(za: np.ndarray, zb: np.ndarray, fa: float, fb: float) -> np.ndarray:
    w = fa / (fa - fb) if fa != fb else 0.5
    return za + w * (zb - za)


def _toward_edge(prob: GaitProblem, d_ok: float, z_ok: np.ndarray, f_ok: float,
                 d_fail: float) -> np.ndarray | None:
    """A start where the residual changes sign between ``d_ok`` and the domain's edge.

    Bisection between a defined scan point and a failing one: a failing middle
    moves the failing end, a defined one of the same sign the defined end,
    one of the other sign closes a bracket (None when the edge is within
    :data:`_EDGE_TOL` without a sign change).
    """
    while abs(d_fail - d_ok) > _EDGE_TOL:
        d = 0.5 * (d_ok + d_fail)
        z = prob._guess(d)
        r = prob.residual(z)
        if np.all(r == _FALL_PENALTY):
            d_fail = d
        elif r[3] * f_ok <= 0.0:
            return _interpolate(z_ok, z, f_ok, float(r[3]))
        else:
            d_ok, z_ok, f_ok = d, z, float(r[3])
    return None


def all_gaits(
    params: Params,
    *,
    energy: float | None = None,
    deltas: Sequence[float] | np.ndarray | None = None,
    tol: float = 1e-10,
    options: IntegratorOptions | None = None,
    section: Section = "touchdown",
    multipliers: bool = True,
) -> GaitSet:
    """Every periodic gait at energy ``energy`` (or speed ``v0``) and ``beta0``.

    Parameters
    ----------
    params : Params
        Model, with the touch-down angle ``beta0`` (and the speed ``v0`` held
        without ``energy``).
    energy : float, optional
        Total energy [MgL] (:func:`tslip.gait.section.total_energy`). Without
        it the speed ``params.v0`` at ``section`` is held instead
        (``fix="speed"`` of :func:`tslip.find_gait`): the touch-down speed, or
        the apex's forward speed.
    deltas : sequence of float, optional
        Touch-down velocity angles to scan [rad], in (-pi/2, 0); default
        :data:`DEFAULT_DELTAS`. Finer near a fold.
    tol : float
        Residual tolerance of each gait.
    options : IntegratorOptions, optional
        Default tolerance 1e-12 with DOP853.
    section : {"touchdown", "apex"}
        Section of the multipliers (and of the speed held without ``energy``).
    multipliers : bool
        Compute each gait's Floquet multipliers.

    Returns
    -------
    GaitSet
        ``energy`` is NaN when the speed was held (each gait has its own).

    Notes
    -----
    What is guaranteed, for the SLIP (where the scan line holds the leg reset
    at ``beta0``, so the ``delta`` residual's zeros on it are exactly the
    gaits): every gait whose touch-down angle lies in the scanned range is
    returned, unless

    * two gaits lie in one refined interval: between two neighbouring defined
      scan points (the residual has the same sign at both; right at a fold:
      on ``slip-human`` at ``k = 35`` the default scan finds both gaits 0.005
      deg of ``beta0`` above the fold and neither 0.001 deg above it, where a
      finer ``deltas`` finds them), or between a defined scan point and a
      failing one, where only the first sign change of the bisection toward
      the edge is solved;
    * it lies within 1e-7 rad of the edge of the domain where strides are
      defined (the SLIP's multiplier grows without bound toward that edge: on
      ``slip-human`` about ``-0.2 / sqrt(distance)``, -11 at 3e-4 rad, so a
      gait missed this way has a multiplier beyond about -600), or in a
      defined stretch that lies wholly between two failing scan points;
    * Newton does not converge from the bracket's start (none seen).

    ``tests/gait/test_allgaits_complete.py`` checks this against an
    independent SLIP on ten ``slip-human`` cells, including seven with a gait
    next to a failing stride and three within 0.05 deg of the fold. For the
    TSLIP the scan runs along the level-trunk line and the ``delta``
    residual's sign changes on it only seed the searches, so a gait far from
    that line can be missed too.

    With the speed held, the SLIP's touch-down speed and angle fix its energy
    (``m v0^2 / 2 + m g l0 sin beta0``), so the gaits are those at that
    energy; the apex's forward speed held does not fix it.

    Examples
    --------
    >>> import tslip
    >>> s = tslip.all_gaits(tslip.preset("slip"), energy=2.2)
    >>> s.stability
    ('asymptotic', 'unstable')
    """
    t0 = time.perf_counter()
    fix: Fix = "speed" if energy is None else "energy"
    prob = GaitProblem.from_params(params, options, fix=fix, energy=energy, section=section)
    d = DEFAULT_DELTAS if deltas is None else np.asarray(deltas, dtype=float).ravel()
    if d.size < 2 or not np.all((d > -math.pi / 2) & (d < 0.0)):
        raise ValueError("deltas must hold at least 2 angles in (-pi/2, 0) rad")
    d = np.sort(d)[::-1]  # from 0 down
    found: list[Gait] = []
    for z in _brackets(prob, d):
        g = find_gait(params, guess=z, tol=tol, options=options, fix=fix, energy=energy,
                      section=section)
        if not g.converged:
            continue
        zg = prob.encode(g)
        if all(np.max(np.abs(zg - prob.encode(h))) > _SAME for h in found):
            found.append(g)
    found.sort(key=lambda g: -g.state.delta)
    fl: list[Floquet | None] = []
    for g in found:
        if not multipliers:
            fl.append(None)
            continue
        try:
            fl.append(floquet(g, options=options, section=section))
        except ValueError:
            fl.append(None)
    return GaitSet(params=params, energy=prob.energy, gaits=tuple(found), floquets=tuple(fl),
                   section=section, deltas=d, seconds=time.perf_counter() - t0)


@dataclass(frozen=True, eq=False)
class StableRegion(Result):
    """The gaits of each cell of a two-parameter grid at fixed energy.

    Arrays have shape ``(len(values[0]), len(values[1]))``: rows the first
    parameter, columns the second.

    Attributes
    ----------
    params : Params
        Base parameters.
    energy : float
        Total energy held [MgL].
    names : tuple of str
        The two parameters (names of :func:`tslip.gait.set_param`).
    values : tuple of ndarray
        Their grid values.
    n_gaits, n_stable : ndarray of int
        Gaits found per cell, and how many of them are at least neutrally stable.
    max_nontrivial : ndarray
        The smallest largest-non-trivial multiplier among a cell's gaits (its
        most stable gait), NaN without a gait.
    seconds : float
        Wall time [s].
    """

    params: Params
    energy: float
    names: tuple[str, str]
    values: tuple[np.ndarray, np.ndarray]
    n_gaits: np.ndarray
    n_stable: np.ndarray
    max_nontrivial: np.ndarray
    seconds: float = field(default=math.nan, repr=False)

    @property
    def stable(self) -> np.ndarray:
        """Cells with at least one stable gait."""
        return self.n_stable > 0

    def __repr__(self) -> str:
        n = self.n_gaits.size
        return (f"StableRegion({self.names[0]} x {self.names[1]}, {n} cells at energy "
                f"{self.energy:.6g}: {int(self.stable.sum())} stable, "
                f"{int((self.n_gaits == 0).sum())} without a gait)")

    def to_dataframe(self) -> pd.DataFrame:
        """One row per cell: the two parameters, ``n_gaits``, ``n_stable``, ``max_nontrivial``."""
        import pandas as pd

        a, b = np.meshgrid(self.values[0], self.values[1], indexing="ij")
        df = pd.DataFrame({self.names[0]: a.ravel(), self.names[1]: b.ravel(),
                           "n_gaits": self.n_gaits.ravel(), "n_stable": self.n_stable.ravel(),
                           "max_nontrivial": self.max_nontrivial.ravel()})
        df.attrs["units"] = {n: param_unit(n) or "-" for n in self.names}
        df.attrs["units"].update({"n_gaits": "-", "n_stable": "-", "max_nontrivial": "-"})
        return df

    def plot(self, ax: Axes | None = None) -> Figure:
        """The region: no gait, unstable gaits only, a stable gait (:func:`plot_stable_region`)."""
        from ..plotting.studies import plot_stable_region

        return plot_stable_region(self, ax=ax)


def stable_region(
    params: Params,
    grid: Mapping[str, Sequence[float] | np.ndarray],
    *,
    energy: float,
    deltas: Sequence[float] | np.ndarray | None = None,
    tol: float = 1e-10,
    options: IntegratorOptions | None = None,
    progress: Any = None,
) -> StableRegion:
    """Self-stable region over two parameters at fixed energy, every cell solved alone.

    Parameters
    ----------
    params : Params
        Base parameters (e.g. ``preset("slip")``).
    grid : mapping of two parameter names to values
        E.g. ``{"k": np.linspace(15, 35, 5), "beta0": np.linspace(1.15, 1.35, 9)}``;
        names as :func:`tslip.gait.set_param` takes them.
    energy : float
        Total energy [MgL].
    deltas, tol, options
        As :func:`all_gaits`.
    progress : callable, optional
        ``progress(done, total)`` after each cell.

    Returns
    -------
    StableRegion
    """
    if not isinstance(grid, Mapping) or len(grid) != 2:
        raise ValueError("grid must map exactly two parameter names to values, e.g. "
                         "{'k': [...], 'beta0': [...]}")
    names = tuple(grid)
    vals = tuple(np.asarray(grid[n], dtype=float).ravel() for n in names)
    for n, v in zip(names, vals):
        get_param(params, n)  # checks the name
        if v.size == 0 or not np.all(np.isfinite(v)):
            raise ValueError(f"grid[{n!r}] must be a non-empty sequence of finite numbers")
    t0 = time.perf_counter()
    shape = (vals[0].size, vals[1].size)
    n_g = np.zeros(shape, dtype=int)
    n_s = np.zeros(shape, dtype=int)
    lam = np.full(shape, math.nan)
    done = 0
    for i, a in enumerate(vals[0]):
        for j, b in enumerate(vals[1]):
            p = set_param(set_param(params, names[0], float(a)), names[1], float(b))
            s = all_gaits(p, energy=energy, deltas=deltas, tol=tol, options=options)
            n_g[i, j] = len(s)
            n_s[i, j] = len(s.stable)
            m = s.max_nontrivial
            if np.isfinite(m).any():
                lam[i, j] = float(np.nanmin(m))
            done += 1
            if progress is not None:
                progress(done, n_g.size)
    return StableRegion(params=params, energy=float(energy), names=(names[0], names[1]),
                        values=(vals[0], vals[1]), n_gaits=n_g, n_stable=n_s,
                        max_nontrivial=lam, seconds=time.perf_counter() - t0)
