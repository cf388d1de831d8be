"""The points of a 3-D study (:mod:`tslip.sweeps.spatial_spec`): a symmetric gait and its
multipliers, and for the 3-D TSLIP its lateral robustness.

Each point is computed from its own parameters alone (unlike a planar line, no
point is seeded by its neighbour), so a resumed study equals an uninterrupted one
trivially, and the lines of a 2-D study are independent. The two steps of the
runner are kept: :func:`solve_gaits` finds a line's gaits (a point without one is
final at once: ``converged = False``, ``stability = "none"``), :func:`analyse_point`
computes the rest.

``"slip3d"``: every left-right symmetric gait at the point's energy
(:func:`tslip.spatial.gait.symmetric_gaits`, a scan of 60 apex heights) and the
exact Floquet multipliers of each (:func:`tslip.spatial.gait.floquet`); the record
counts them (``n_gaits``, ``n_stable``) and describes the fastest (lowest apex) one.

``"tslip3d"``: the symmetric gait reached from the planar Table 2.1 gait
(:func:`tslip.spatial.lateral.table21_gait`: the splay, ``r`` and the roll couplings
by continuation) and then, if the point differs in other fields or in ``vx``, by a
continuation of those in :data:`CONTINUATION_STEPS`-sized steps
(:func:`tslip.spatial.trunk_section.symmetric_gait` from the previous step's gait);
its ten multipliers by central differences
(:func:`tslip.spatial.lateral.lateral_multipliers`: three trivial ones set aside).
``lateral_robustness``: the largest lateral push, roll-rate and yaw-rate
disturbance of each sign that the gait survives for ``n_steps`` strides
(:func:`tslip.spatial.trunk_robustness.lateral_limit`: a finite horizon; its grid
step grows :data:`GROWTH`-fold until a failure lies within :data:`GRID_POINTS`
steps).

:func:`code_version` hashes the code a point runs, by model and analyses: the
cache key (:func:`tslip.sweeps.run.study_keys`) holds it, so an edit of
:mod:`tslip.spatial` recomputes the 3-D points it can change and no planar one.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._codehash import code_hash, module_digest
from ..spatial.gait import SymmetricGait, floquet, symmetric_gaits
from ..spatial.lateral import (
    N_TRIVIAL,
    OPTIONS,
    TABLE21_VX,
    lateral_multipliers,
    table21_gait,
    table21_params,
)
from ..spatial.trunk import TrunkStatus
from ..spatial.trunk_parameters import TrunkParams
from ..spatial.trunk_robustness import GRID_STEPS, KINDS, lateral_limit
from ..spatial.trunk_section import MIRROR, SECTION_NAMES, one_step_map, symmetric_gait
from .spec import StudySpec

__all__ = ["CODE", "COST_SECONDS", "UNITS", "Pending", "Solved", "analyse_point",
           "code_version", "solve_gaits", "CONTINUATION_STEPS", "GROWTH", "GRID_POINTS"]

#: The modules whose code computes a point, by model and analysis (``None``: every point).
CODE: dict[str, dict[str | None, tuple[str, ...]]] = {
    "slip3d": {None: ("tslip.spatial.gait",), "floquet": ()},
    "tslip3d": {None: ("tslip.spatial.lateral", "tslip.spatial.trunk_section"),
                "floquet": (), "lateral_robustness": ("tslip.spatial.trunk_robustness",)},
}
#: Estimated seconds of a point (warm compile cache, one core): its gait, each analysis.
COST_SECONDS: dict[str, dict[str, float]] = {
    "slip3d": {"solve": 0.3, "floquet": 0.01},
    "tslip3d": {"solve": 0.5, "floquet": 0.05, "lateral_robustness": 3.0},
}
#: The ``tslip3d`` continuation beyond :func:`table21_gait`: the number of steps is the
#: largest change of a field (or of ``vx``) over this fraction of its size (at least 0.1).
CONTINUATION_STEPS = 0.05
#: ``lateral_robustness``: the grid step starts at :data:`GRID_STEPS` and grows this
#: factor while nothing fails within :data:`GRID_POINTS` steps.
GROWTH = 30.0
GRID_POINTS = 100
#: Units of the 3-D record's columns besides the axes (``seconds`` is wall time).
UNITS: dict[str, str] = {
    **dict.fromkeys(("n_gaits", "n_stable", "n_trivial", "max_nontrivial", "min_nontrivial",
                     "trivial_error", "residual", "kind", "stability", "message", "floquet_message",
                     "converged"), "-"),
    **{f"abs_lambda_{j}": "-" for j in range(1, 11)},
    "apex_y": "L", "apex_vx": "g^1/2 L^1/2", "apex_vz": "g^1/2 L^1/2",
    **dict.fromkeys(("a", "yaw", "pitch", "roll"), "rad"),
    **dict.fromkeys(("vx", "vy", "vz"), "g^1/2 L^1/2"),
    **dict.fromkeys(("w_roll", "w_yaw", "w_pitch"), "rad g^1/2 L^-1/2"),
    **{f"{kind}_{side}": unit for kind, unit in (("lateral_push", "g^1/2 L^1/2"),
                                                 ("roll_rate", "rad g^1/2 L^-1/2"),
                                                 ("yaw_rate", "rad g^1/2 L^-1/2"))
       for side in ("plus", "minus")},
    **{f"{kind}_{side}_{what}": "-" for kind in KINDS for side in ("plus", "minus")
       for what in ("status", "stride")},
    "seconds": "s",
}

#: ``emit(index, record)``: a point of the line is final.
Emit = Callable[[int, dict[str, Any]], None]


def code_version(model: str, analyses: Sequence[str]) -> str:
    """Hash of the code computing a ``model`` point with ``analyses`` (this module included)."""
    code = CODE[model]
    mods = code[None] + tuple(m for a in sorted(set(analyses)) for m in code[a])
    return f"{code_hash(*mods)}-{module_digest(__name__)[:24]}"


@dataclass(frozen=True)
class Pending:
    """A point with a gait, not yet analysed: its index on the line, its axis values, the
    gait (a ``tslip3d`` section vector, or the ``slip3d`` gaits) and its solve time."""

    index: int
    point: dict[str, float]
    gait: Any
    message: str
    seconds: float


@dataclass(frozen=True)
class Solved:
    """A line after :func:`solve_gaits` (as :class:`tslip.sweeps.point.Solved`; ``seeds``
    is empty: no point seeds another)."""

    records: list[dict[str, Any] | None]
    pending: list[Pending]
    seeds: dict[float, dict[str, float]]


def _tslip3d_gait(params: TrunkParams, vx: float) -> np.ndarray:
    """The ``tslip3d`` gait of a point (module docstring); ``ValueError`` if none is reached."""
    start = table21_params(r=params.r, splay=params.splay, k_splay=params.k_splay,
                           k_trail=params.k_trail)
    x = table21_gait(start, options=OPTIONS)
    names = [f.name for f in dataclasses.fields(TrunkParams)
             if isinstance(getattr(start, f.name), float) and getattr(start, f.name)
             != getattr(params, f.name)]
    ends = [(getattr(start, n), getattr(params, n)) for n in names] + [(TABLE21_VX, vx)]
    n = max(math.ceil(abs(b - a) / (CONTINUATION_STEPS * max(abs(a), abs(b), 0.1)) - 1e-12)
            for a, b in ends)
    for i in range(1, n + 1):
        changes: dict[str, Any] = {nm: _at(a, b, i, n) for nm, (a, b) in zip(names, ends)}
        p = dataclasses.replace(start, **changes)
        guess = x.copy()
        guess[4] = _at(TABLE21_VX, vx, i, n)
        x = symmetric_gait(p, guess, options=OPTIONS)
    return x


def _at(a: float, b: float, i: int, n: int) -> float:
    """Step ``i`` of ``n`` from ``a`` to ``b`` (``b`` itself at the last)."""
    return b if i == n else a + (b - a) * i / n


def _solve(spec: StudySpec, point: dict[str, float]) -> tuple[Any, str]:
    """The gait of one point, or None and why not."""
    base = spec.params_at(point)
    if base.model == "slip3d":
        gaits = symmetric_gaits(base.params, energy=base.gait)
        if not gaits:
            return None, "no symmetric gait found at this energy"
        return tuple(gaits), "found by the apex-height scan"
    try:
        return _tslip3d_gait(base.params, base.gait), "continued from the planar Table 2.1 gait"
    except ValueError as exc:
        return None, str(exc)


def solve_gaits(spec: StudySpec, assignment: dict[str, float], values: Sequence[float], *,
                seeds: dict[float, dict[str, float]] | None = None,
                cached: dict[float, dict[str, Any]] | None = None,
                emit: Emit | None = None) -> Solved:
    """Find the gaits of one line (the signature of :func:`tslip.sweeps.point.solve_gaits`;
    ``seeds`` is not used); a point without a gait is emitted as final."""
    cached = cached or {}
    vals = sorted(float(v) for v in values)
    inner = spec.axes[-1].param
    records: list[dict[str, Any] | None] = [cached.get(v) for v in vals]
    pending = []
    for i, v in enumerate(vals):
        if records[i] is not None:
            continue
        point = {**assignment, inner: v}
        t0 = time.perf_counter()
        gait, message = _solve(spec, point)
        seconds = time.perf_counter() - t0
        if gait is None:
            rec = {**point, "converged": False, "stability": "none", "n_trivial": 0,
                   "message": message, "seconds": seconds}
            records[i] = rec
            if emit is not None:
                emit(i, rec)
        else:
            pending.append(Pending(i, point, gait, message, seconds))
    return Solved(records, pending, {})


def analyse_point(spec: StudySpec, item: Pending) -> dict[str, Any]:
    """The record of one point with a gait (plain numbers and text, as the cache holds)."""
    t0 = time.perf_counter()
    base = spec.params_at(item.point)
    rec: dict[str, Any] = {**item.point, "converged": True}
    if base.model == "slip3d":
        rec.update(_slip3d(item.gait))
    else:
        rec.update(_tslip3d(spec, base.params, item.gait))
    rec["message"] = item.message
    rec["seconds"] = item.seconds + time.perf_counter() - t0
    return rec


def _slip3d(gaits: tuple[SymmetricGait, ...]) -> dict[str, Any]:
    """The ``slip3d`` columns: the gaits' count and the fastest one's multipliers."""
    largest = []
    for g in gaits:
        try:
            largest.append(floquet(g, "exact").largest)
        except ValueError:
            largest.append(math.nan)
    g = gaits[0]  # lowest apex: the fastest
    rec: dict[str, Any] = {"n_gaits": len(gaits), "n_stable": sum(v < 1.0 for v in largest),
                           "apex_y": g.apex.y, "apex_vx": g.apex.vx, "apex_vz": g.apex.vz,
                           "residual": g.residual}
    try:
        f = floquet(g, "exact")
    except ValueError:
        return {**rec, "stability": "unknown", "n_trivial": 0}
    mags = sorted(np.abs(f.all).tolist(), reverse=True)
    rec.update({f"abs_lambda_{j + 1}": m for j, m in enumerate(mags)})
    nt = np.abs(f.nontrivial)
    rec.update(max_nontrivial=float(nt.max()), min_nontrivial=float(nt.min()),
               n_trivial=len(f.trivial),
               stability="asymptotic" if nt.max() < 1.0 else "unstable")
    return rec


def _tslip3d(spec: StudySpec, params: TrunkParams, x: np.ndarray) -> dict[str, Any]:
    """The ``tslip3d`` columns: the gait's touch-down, multipliers and lateral limits."""
    f, _ = one_step_map(params, x, options=OPTIONS)
    rec: dict[str, Any] = {name: float(v) for name, v in zip(SECTION_NAMES, x)}
    rec["residual"] = float(np.max(np.abs(f - MIRROR * x)))
    try:
        pt = lateral_multipliers(params, x, options=OPTIONS)
    except ValueError as exc:
        return {**rec, "stability": "unknown", "n_trivial": 0, "floquet_message": str(exc)}
    mags = sorted(np.abs(pt.multipliers).tolist(), reverse=True)
    rec.update({f"abs_lambda_{j + 1}": m for j, m in enumerate(mags)})
    rec.update(max_nontrivial=pt.largest, min_nontrivial=float(np.abs(pt.nontrivial).min()),
               n_trivial=N_TRIVIAL, kind=pt.kind, trivial_error=pt.trivial_error,
               stability="asymptotic" if pt.stable else "unstable")
    if "lateral_robustness" in spec.analyses:
        for kind in KINDS:
            for sign, side in ((1, "plus"), (-1, "minus")):
                rec.update(_limit(params, x, kind, sign, side, spec.n_steps))
    return rec


def _limit(params: TrunkParams, x: np.ndarray, kind: str, sign: int, side: str,
           n_steps: int) -> dict[str, Any]:
    """One lateral limit's columns (module docstring: the grid step grows until a failure)."""
    col = f"{kind}_{side}"
    h = GRID_STEPS[kind]
    while True:
        try:
            lim = lateral_limit(params, x, kind, sign=sign, n_steps=n_steps, h=h,
                                max_magnitude=GRID_POINTS * h, options=OPTIONS)
        except ValueError:  # the undisturbed gait falls within n_steps
            return {col: 0.0, f"{col}_status": "UNDISTURBED_FALLS", f"{col}_stride": -1}
        if math.isfinite(lim.limit) or GRID_POINTS * h >= 1.0:
            break
        h *= GROWTH
    status = lim.status.name if lim.status != TrunkStatus.OK else "NONE_UP_TO_MAX"
    return {col: float(lim.limit), f"{col}_status": status,
            f"{col}_stride": int(lim.fall_stride)}
