"""The lateral stability of the 3-D TSLIP's symmetric gaits: the tables of the docs page.

Issue 43, Part 2, "the question" (docs/analyses/spatial_tslip.md): starting from
the Table 2.1 gait in 3-D with a small splay, are the lateral modes stable,
neutral or unstable, how does that change with the mass offset ``r``, and does a
roll coupling of the leg placement (``k_splay``, ``k_trail``:
:class:`~tslip.spatial.trunk_parameters.TrunkParams`) make left-right symmetric
gaits asymptotically stable?

A gait here (:func:`table21_gait`) starts from the planar Table 2.1 gait
(:data:`TABLE21_SECTION`, its touch-down; ``tslip.find_gait(tslip.preset("table2.1"))``
in the 3-D section, checked by tests/spatial/test_lateral.py) and is carried by
continuation, each step a :func:`~tslip.spatial.trunk_section.symmetric_gait`
with the forward velocity ``vx`` at touch-down held at the planar gait's
(:data:`TABLE21_VX`) and its leg reset angle ``alpha_r`` (:data:`TABLE21_ALPHA_R`, solved by
the planar search): first the splay from 0 in steps of at most
:data:`SPLAY_STEP`, then ``r`` from 0.3 in steps of at most :data:`R_STEP`, then
both roll couplings from 0 in steps of at most :data:`GAIN_STEP`. So the gaits
of the ``r`` sweep share the Table 2.1 gait's forward speed at touch-down (the
planar sweep of the thesis holds the touch-down speed ``v0`` and angle ``beta0`` and
solves ``alpha_r`` at each ``r`` instead: a different family away from ``r = 0.3``).

Its multipliers (:func:`lateral_multipliers`) are the eigenvalues of the two-step
map's exact Jacobian (:func:`two_step_jacobian`: variational equations with the
event-time corrections, :mod:`tslip.spatial.trunk_jacobian`;
``IntegratorOptions(rtol=atol=1e-12)``; central differences with step ``1e-5`` on
request). Three of the ten are trivial (the energy of the conservative model, the
heading by yaw invariance, and a Jordan partner of the heading: a turned gait
drifts sideways), exactly 1 for the exact map; the three closest to 1 are set
aside and their distance from 1 is reported (``trivial_error``) as a check.
"Asymptotically stable" means every other multiplier inside the unit circle.

``python -m tslip.spatial.lateral`` prints the tables as markdown
(``--small``: one point of each, a smoke test).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, overload

import numpy as np

from .._io import atomic_write
from .._results import Result, frame
from ..simulation.options import IntegratorOptions
from .parameters import TABLE21_3D_SPLAY
from .trunk_parameters import TrunkParams
from .trunk_section import symmetric_gait, two_step_jacobian

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["LateralPoint", "LateralTable", "ROW_UNITS", "table21_gait", "lateral_multipliers",
           "lateral_point", "TABLE21_3D_SECTION", "splay_table", "r_table", "gain_table",
           "markdown", "main", "OPTIONS",
           "SPLAY_STEP", "R_STEP", "GAIN_STEP", "N_TRIVIAL", "TABLE21_SECTION", "TABLE21_VX",
           "TABLE21_ALPHA_R", "table21_params", "gain_matrix", "SPLAYS", "RS", "K_SPLAYS",
           "K_TRAILS", "tables"]

#: Integrator tolerances of every gait and Jacobian here.
OPTIONS = IntegratorOptions(rtol=1e-12, atol=1e-12)
#: Largest splay step [rad] of the continuation from the planar gait.
SPLAY_STEP = 0.05
#: Largest step in ``r`` [L] of the continuation.
R_STEP = 0.05
#: Largest gain step of the continuation in ``k_splay`` and ``k_trail``.
GAIN_STEP = 0.5
#: Trivial multipliers of the two-step map (energy, heading, the heading's Jordan partner).
N_TRIVIAL = 3
_FD_STEP = 1e-5

#: The planar Table 2.1 gait's touch-down in the 3-D section (splay 0; ``tslip.find_gait``
#: on ``tslip.preset("table2.1")`` at ``IntegratorOptions(rtol=atol=1e-12)``, its ``v0`` 5,
#: ``beta0`` 1.05): the start of every continuation here.
TABLE21_SECTION = np.array([1.0458118983093616, 0.0, -0.004188101690638331, 0.0,
                            4.998408015786053, -0.1261638130595749, 0.0, 0.0, 0.0,
                            -0.033195744405040924])
#: Its forward velocity at touch-down, held by every gait here [g^1/2 L^1/2].
TABLE21_VX = float(TABLE21_SECTION[4])
#: Its leg reset angle [rad]: ``find_gait`` solves ``alpha_r`` (the preset's 1.0 is a
#: start), and every gait here keeps it.
TABLE21_ALPHA_R = 0.7934842721919153
#: The 3-D gait of :func:`table21_params` (splay 0.05, ``r`` 0.3, no coupling):
#: ``table21_gait(table21_params())``, its right touch-down, stored so that a run can start
#: from it without the continuation (tests/spatial/test_trunk_run.py checks that it is a
#: left-right symmetric gait).
TABLE21_3D_SECTION = np.array([1.0457133205643967, 2.7532576437633286e-05,
                               -0.004192260572694797, 0.004354317052413445, 4.998408015786053,
                               -0.12611452418636432, 0.010130424562713219,
                               0.03452648750189442, -1.3329114843007927e-22,
                               -0.033241800254926006])


def table21_params(**changes: Any) -> TrunkParams:
    """``preset("table2.1-3d")`` with the Table 2.1 gait's ``alpha_r``
    (:data:`TABLE21_ALPHA_R`) and ``changes`` (e.g. ``r``, ``splay``, ``k_splay``,
    ``k_trail``): the parameters of this module's gaits."""
    return dataclasses.replace(TrunkParams(splay=TABLE21_3D_SPLAY, alpha_r=TABLE21_ALPHA_R),
                               **changes)


#: Units of :meth:`LateralPoint.row` (the columns of the tables).
ROW_UNITS: dict[str, str] = {"r": "L", "splay": "rad", "k_splay": "-", "k_trail": "-",
                             "largest": "-", "kind": "-", "stable": "-", "trivial_error": "-",
                             "lateral_speed": "g^1/2 L^1/2"}


@dataclass(frozen=True, repr=False)
class LateralPoint(Result):
    """One gait and its multipliers (module docstring).

    A :class:`~tslip._results.Result`: a table of one row (:meth:`row`, units
    :data:`ROW_UNITS`); ``plot()`` draws the multipliers in the unit circle.

    Attributes
    ----------
    params : TrunkParams
    x : ndarray, shape (10,)
        The gait's right touch-down (:data:`~tslip.spatial.trunk_section.SECTION_NAMES`).
    multipliers : ndarray, shape (10,)
        All eigenvalues of the two-step map's Jacobian.
    nontrivial : ndarray, shape (7,)
        Those left after setting aside the :data:`N_TRIVIAL` closest to 1, by modulus
        (largest first).
    trivial_error : float
        The largest distance of a set-aside multiplier from 1 (the error of the trivial
        ones: 2e-8 and less here with the exact Jacobian, about 1e-7 by differences).
    """

    params: TrunkParams
    x: np.ndarray
    multipliers: np.ndarray
    nontrivial: np.ndarray
    trivial_error: float

    @property
    def largest(self) -> float:
        """The largest non-trivial ``|multiplier|``."""
        return float(np.abs(self.nontrivial[0]))

    @property
    def kind(self) -> str:
        """``"real"`` or ``"complex"``: the largest non-trivial multiplier's."""
        return "complex" if abs(self.nontrivial[0].imag) > 1e-9 else "real"

    @property
    def stable(self) -> bool:
        """Asymptotically stable: every non-trivial multiplier inside the unit circle."""
        return self.largest < 1.0

    def row(self) -> dict[str, float | str]:
        """The table row: parameters varied here, the largest ``|multiplier|`` and its kind."""
        p = self.params
        return {"r": p.r, "splay": p.splay, "k_splay": p.k_splay, "k_trail": p.k_trail,
                "largest": self.largest, "kind": self.kind,
                "trivial_error": self.trivial_error, "lateral_speed": float(self.x[6])}

    @property
    def trivial(self) -> np.ndarray:
        """The :data:`N_TRIVIAL` multipliers set aside (those closest to 1)."""
        ev = np.asarray(self.multipliers)
        return ev[np.argsort(np.abs(ev - 1.0), kind="stable")[:N_TRIVIAL]]

    def _repr_fields(self) -> dict[str, object]:
        return {**{k: v for k, v in self.row().items() if k != "lateral_speed"},
                "stable": self.stable}

    def to_dataframe(self) -> pd.DataFrame:
        """One row: :meth:`row` and ``stable``, units :data:`ROW_UNITS`."""
        return frame([{**self.row(), "stable": self.stable}], ROW_UNITS)

    def plot(self, ax: Axes | None = None) -> Figure:
        """The multipliers in the unit circle, the trivial ones hollow
        (:func:`tslip.plotting.spatial.plot_multipliers`)."""
        from ..plotting.spatial import plot_multipliers

        p = self.params
        return plot_multipliers(self.nontrivial, self.trivial, ax, title=(
            f"r {p.r:g}, splay {p.splay:g}, k_splay {p.k_splay:g}, k_trail {p.k_trail:g}: "
            f"max |lambda| = {self.largest:.4g}"))


@dataclass(frozen=True, repr=False)
class LateralTable(Result):
    """Gaits and their multipliers, as :func:`splay_table`, :func:`r_table` and
    :func:`gain_table` return them (a list): ``LateralTable(r_table())``.

    A sequence of :class:`LateralPoint` (``len``, iteration, indexing; :func:`markdown`
    and :func:`gain_matrix` take it) and a :class:`~tslip._results.Result`: one table row
    per gait (units :data:`ROW_UNITS`); ``plot()`` draws the largest non-trivial
    ``|multiplier|`` over the parameter that varies (``r``, ``splay``, ``k_splay`` or
    ``k_trail``), or over the ``k_splay`` x ``k_trail`` grid when both gains vary
    (:func:`tslip.plotting.spatial.plot_lateral_table`).
    """

    points: tuple[LateralPoint, ...]

    def __post_init__(self) -> None:
        pts = tuple(self.points)
        for i, pt in enumerate(pts):
            if not isinstance(pt, LateralPoint):
                raise TypeError(f"LateralTable.points[{i}] must be a LateralPoint, got "
                                f"{type(pt).__name__}")
        object.__setattr__(self, "points", pts)

    def __len__(self) -> int:
        return len(self.points)

    def __iter__(self) -> Iterator[LateralPoint]:
        return iter(self.points)

    @overload
    def __getitem__(self, i: int) -> LateralPoint: ...

    @overload
    def __getitem__(self, i: slice) -> tuple[LateralPoint, ...]: ...

    def __getitem__(self, i: int | slice) -> LateralPoint | tuple[LateralPoint, ...]:
        return self.points[i]

    def _repr_fields(self) -> dict[str, object]:
        return {"n_points": len(self.points),
                "n_stable": sum(pt.stable for pt in self.points)}

    def to_dataframe(self) -> pd.DataFrame:
        """One row per gait: :meth:`LateralPoint.row` and ``stable``."""
        rows = [{**pt.row(), "stable": pt.stable} for pt in self.points]
        return frame(rows or {k: [] for k in ROW_UNITS}, ROW_UNITS)

    def plot(self, ax: Axes | None = None) -> Figure:
        """The largest non-trivial ``|multiplier|`` over the varied parameter, or the gain
        grid (class docstring)."""
        from ..plotting.spatial import plot_lateral_table

        return plot_lateral_table(self.to_dataframe(), ax)


def _steps(a: float, b: float, h: float) -> list[float]:
    n = max(1, math.ceil(abs(b - a) / h - 1e-12))
    return [a + (b - a) * i / n for i in range(1, n + 1)]


def table21_gait(params: TrunkParams, *, guess: np.ndarray | None = None,
                 options: IntegratorOptions | None = None) -> np.ndarray:
    """The left-right symmetric gait of ``params`` reached from the planar Table 2.1 gait
    by continuation (module docstring): its right touch-down section vector.

    ``params`` differs from :func:`table21_params` in ``r``, ``splay``, ``k_splay``,
    ``k_trail`` (continued); any other change is applied in one last Newton solve.
    ``guess`` (a nearby gait of ``params``) skips the continuation. Raises ``ValueError``
    in one line if a solve fails (no gait near the path), or for ``splay <= 0`` (the foot
    on the mid-plane: any roll crosses a leg, so the 10-D map is not differentiable).
    """
    opt = OPTIONS if options is None else options
    if not params.splay > 0.0:
        raise ValueError(f"table21_gait: splay must be in (0, pi/2) rad, got {params.splay!r} "
                         f"(at 0 the foot lands on the mid-plane, a roll crosses a leg)")
    if guess is not None:
        return symmetric_gait(params, np.asarray(guess, dtype=float), options=opt)
    base = TrunkParams(alpha_r=TABLE21_ALPHA_R)
    x = TABLE21_SECTION.copy()
    path: list[TrunkParams] = []
    for sp in _steps(0.0, params.splay, SPLAY_STEP):
        path.append(dataclasses.replace(base, splay=sp))
    for r in _steps(base.r, params.r, R_STEP) if params.r != base.r else []:
        path.append(dataclasses.replace(path[-1], r=r))
    gains = max(abs(params.k_splay), abs(params.k_trail))
    n = max(1, math.ceil(gains / GAIN_STEP - 1e-12)) if gains > 0 else 0
    for i in range(1, n + 1):
        path.append(dataclasses.replace(path[-1], k_splay=params.k_splay * i / n,
                                        k_trail=params.k_trail * i / n))
    if path[-1] != params:
        path.append(params)
    for p in path:
        x = symmetric_gait(p, x, options=opt)
    return x


def lateral_multipliers(params: TrunkParams, x: np.ndarray, *,
                        options: IntegratorOptions | None = None,
                        method: str = "exact") -> LateralPoint:
    """The multipliers of the gait ``x`` of ``params`` (module docstring); ``method``
    ``"fd"`` takes the Jacobian by central differences (step ``1e-5``) instead."""
    opt = OPTIONS if options is None else options
    J = two_step_jacobian(params, x, step=_FD_STEP, options=opt, method=method)
    ev = np.linalg.eigvals(J)
    near = np.argsort(np.abs(ev - 1.0))
    trivial, rest = near[:N_TRIVIAL], near[N_TRIVIAL:]
    nontrivial = ev[rest][np.argsort(-np.abs(ev[rest]), kind="stable")]
    return LateralPoint(params, np.asarray(x, dtype=float), ev, nontrivial,
                        float(np.max(np.abs(ev[trivial] - 1.0))))


def lateral_point(params: TrunkParams, *, guess: np.ndarray | None = None,
                  options: IntegratorOptions | None = None) -> LateralPoint:
    """:func:`table21_gait` and its :func:`lateral_multipliers`."""
    x = table21_gait(params, guess=guess, options=options)
    return lateral_multipliers(params, x, options=options)


#: The grids of the docs page (docs/analyses/spatial_tslip.md).
SPLAYS = (0.01, 0.05, 0.15, 0.3)
RS = (0.1, 0.2, 0.3, 0.4, 0.5)
K_SPLAYS = (-1.0, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0)
K_TRAILS = (-2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0, 3.0, 4.0)


def _points(changes: Iterable[dict[str, float]],
            options: IntegratorOptions | None) -> list[LateralPoint]:
    out = []
    for ch in changes:
        try:
            out.append(lateral_point(table21_params(**ch), options=options))
        except ValueError:  # no gait reached on the path: left out of the table, said there
            continue
    return out


def splay_table(splays: Sequence[float] = SPLAYS, *, r: float = 0.3,
                options: IntegratorOptions | None = None) -> list[LateralPoint]:
    """The gaits over the splay at ``r``, no coupling."""
    return _points(({"splay": s, "r": r} for s in splays), options)


def r_table(rs: Sequence[float] = RS, *, splay: float = TABLE21_3D_SPLAY,
            options: IntegratorOptions | None = None) -> list[LateralPoint]:
    """The gaits over the mass offset ``r`` at ``splay``, no coupling."""
    return _points(({"splay": splay, "r": r} for r in rs), options)


def gain_table(k_splays: Sequence[float] = K_SPLAYS, k_trails: Sequence[float] = K_TRAILS, *,
               splay: float = TABLE21_3D_SPLAY, r: float = 0.3,
               options: IntegratorOptions | None = None) -> list[LateralPoint]:
    """The gaits over the roll couplings ``k_splay`` x ``k_trail`` at ``splay`` and ``r``
    (a grid point whose continuation fails is left out)."""
    return _points(({"splay": splay, "r": r, "k_splay": a, "k_trail": b}
                    for a in k_splays for b in k_trails), options)


def markdown(points: Sequence[LateralPoint]) -> str:
    """A markdown table of :meth:`LateralPoint.row`."""
    head = ("| r | splay | k_splay | k_trail | largest non-trivial \\|multiplier\\| | kind | "
            "stable | lateral speed vz at touch-down | trivial ones: max \\|mu - 1\\| |")
    lines = [head, "|" + "---|" * 9]
    for pt in points:
        w = pt.row()
        lines.append(f"| {w['r']:g} | {w['splay']:g} | {w['k_splay']:g} | {w['k_trail']:g} | "
                     f"{pt.largest:.4f} | {pt.kind} | {'yes' if pt.stable else 'no'} | "
                     f"{w['lateral_speed']:.5f} | {pt.trivial_error:.1e} |")
    return "\n".join(lines)


def gain_matrix(points: Sequence[LateralPoint]) -> str:
    """The largest non-trivial ``|multiplier|`` of :func:`gain_table` as a k_splay x k_trail
    markdown matrix (``-`` where no gait was reached)."""
    ks = sorted({p.params.k_splay for p in points})
    kt = sorted({p.params.k_trail for p in points})
    val = {(p.params.k_splay, p.params.k_trail): p for p in points}
    lines = ["| k_splay \\ k_trail | " + " | ".join(f"{b:g}" for b in kt) + " |",
             "|" + "---|" * (len(kt) + 1)]
    for a in ks:
        cells = []
        for b in kt:
            pt = val.get((a, b))
            mark = "" if pt is None or pt.kind == "real" else "c"
            cells.append("-" if pt is None else f"{pt.largest:.3f}{mark}")
        lines.append(f"| {a:g} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def tables(small: bool = False, options: IntegratorOptions | None = None) -> str:
    """The docs page's tables as markdown (``small``: one point of each, a smoke run)."""
    parts = []
    splays, rs = (SPLAYS[1:2], RS[2:3]) if small else (SPLAYS, RS)
    parts.append("### Splay (r 0.3, no coupling)\n\n"
                 + markdown(splay_table(splays, options=options)))
    parts.append("### Mass offset r (splay 0.05, no coupling)\n\n"
                 + markdown(r_table(rs, options=options)))
    ks, kt = ((1.0,), (1.0,)) if small else (K_SPLAYS, K_TRAILS)
    for splay in ((TABLE21_3D_SPLAY,) if small else (TABLE21_3D_SPLAY, 0.15)):
        pts = gain_table(ks, kt, splay=splay, options=options)
        parts.append(f"### Roll couplings (r 0.3, splay {splay:g}): largest non-trivial "
                     f"|multiplier| (c: a complex pair)\n\n" + gain_matrix(pts))
        if pts:
            best = min(pts, key=lambda p: p.largest)
            parts.append(f"Best: k_splay {best.params.k_splay:g}, k_trail "
                         f"{best.params.k_trail:g}: {best.largest:.4f} ({best.kind}); stable "
                         f"points: {sum(p.stable for p in pts)} of {len(pts)}")
    return "\n\n".join(parts) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m tslip.spatial.lateral [--small] [--out FILE]``: the tables as markdown."""
    ap = argparse.ArgumentParser(prog="python -m tslip.spatial.lateral",
                                 description="Lateral multipliers of the 3-D Table 2.1 TSLIP.")
    ap.add_argument("--small", action="store_true", help="one point of each table")
    ap.add_argument("--out", help="write the Markdown there (else print it)")
    a = ap.parse_args(argv)
    text = tables(a.small)
    if a.out:  # replaced atomically: a link at that name is replaced, never written through
        atomic_write(a.out, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
