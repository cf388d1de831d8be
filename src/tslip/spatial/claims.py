"""The two statements of Seipel & Holmes (2005) judged on a grid (`python -m tslip.spatial.claims`).

1. "All left-right symmetric periodic gaits are unstable": every symmetric gait
   found (:func:`tslip.spatial.gait.symmetric_gaits`, fixed energy) on a grid of
   ``(k, beta0, gamma0, energy)``, under each heading rule, with the largest
   non-trivial Floquet multiplier of its two-step map (exact, variational
   equations). A gait counts as unstable when that modulus exceeds 1.
2. "A feedback on leg placement at touch-down stabilises them": for each gait of
   the uncontrolled grid under ``heading="fixed"`` (the only rule where the
   feedback acts), the gait is continued in ``k_lat`` (Newton from the previous
   ``k_lat``'s gait, same energy) over a grid of gains, and the gains at which its
   largest non-trivial modulus is below 1 are reported as intervals.

The verdicts and tables are printed as Markdown (``--out`` writes them to a file);
docs/analyses/spatial.md holds the run quoted there.
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import root

from .._io import atomic_write
from ..simulation.options import IntegratorOptions
from .gait import SymmetricGait, _residual, _vx, floquet, symmetric_gaits
from .parameters import SpatialParams
from .stride import SpatialApex

__all__ = ["GRID", "K_LATS", "GaitRow", "survey", "feedback_scan", "stable_intervals",
           "report", "main"]

#: The grid judged: spring k [MgL^-1], angle of attack beta0 [rad], azimuth gamma0 [rad],
#: energy [MgL] (m = l0 = g = 1).
GRID: dict[str, tuple[float, ...]] = {
    "k": (20.0, 25.0, 30.0),
    "beta0": (1.15, 1.19, 1.23),
    "gamma0": (0.0, 0.05, 0.15),
    "energy": (1.8, 2.0, 2.2, 2.4),
}
#: The feedback gains scanned [rad g^-1/2 L^-1/2].
K_LATS: tuple[float, ...] = tuple(np.round(np.linspace(-1.0, 6.0, 71), 3))
#: The largest change of the apex state (y, vx, vz) between neighbouring gains of a
#: continuation; a larger one is taken for a jump to another gait, and the gain is skipped.
MAX_JUMP = 0.05
#: A gait is stable when its largest non-trivial modulus is below 1 - STABLE_MARGIN.
STABLE_MARGIN = 1e-6


@dataclass(frozen=True, slots=True)
class GaitRow:
    """One symmetric gait of the survey with its largest non-trivial multiplier."""

    heading: str
    k: float
    beta0: float
    gamma0: float
    energy: float
    gait: SymmetricGait
    largest: float  # largest non-trivial |multiplier| of the two-step map
    nontrivial: tuple[complex, ...]

    @property
    def stable(self) -> bool:
        return self.largest < 1.0 - STABLE_MARGIN


def survey(grid: dict[str, tuple[float, ...]] | None = None,
           headings: Sequence[str] = ("fixed", "velocity"),
           options: IntegratorOptions | None = None) -> list[GaitRow]:
    """Every symmetric gait of the grid under each heading rule, with its multipliers."""
    grid = GRID if grid is None else grid
    rows = []
    for heading in headings:
        for k, beta0, gamma0, E in itertools.product(grid["k"], grid["beta0"], grid["gamma0"],
                                                     grid["energy"]):
            p = SpatialParams(k=k, beta0=beta0, gamma0=gamma0, heading=heading)  # type: ignore[arg-type]
            for g in symmetric_gaits(p, energy=E, options=options):
                f = floquet(g, "exact", options)
                rows.append(GaitRow(heading, k, beta0, gamma0, E, g, f.largest,
                                    tuple(complex(z) for z in f.nontrivial)))
    return rows


def _continue(p: SpatialParams, x: np.ndarray, energy: float,
              options: IntegratorOptions | None) -> np.ndarray | None:
    """The symmetric gait of ``p`` at ``energy`` nearest the apex ``x = (y, vx, vz)``."""
    o = options or IntegratorOptions.tight("dop853")
    sol = root(lambda u: _residual(p, u[0], u[1], energy, None, o), x[[0, 2]], method="hybr",
               tol=1e-14)
    if not np.all(np.abs(sol.fun) < 1e-10):
        return None
    y, vz = (float(u) for u in sol.x)
    return np.array([y, _vx(p, y, vz, energy, None), vz])


def feedback_scan(row: GaitRow, k_lats: Sequence[float] = K_LATS,
                  options: IntegratorOptions | None = None) -> np.ndarray:
    """Largest non-trivial multiplier modulus of the gait of ``row`` continued in ``k_lat``
    (``heading="fixed"``), one per gain; NaN where the continuation lost it."""
    base = row.gait.params
    out = np.full(len(k_lats), np.nan)
    order = np.argsort(np.abs(np.asarray(k_lats)))  # from 0 outwards, each side in turn
    start = row.gait.apex.section()
    last: dict[int, np.ndarray] = {}
    for i in order:
        kl = float(k_lats[i])
        side = int(np.sign(kl))
        guess = last.get(side, start)
        p = dataclasses.replace(base, k_lat=kl)
        x = _continue(p, guess, row.energy, options)
        if x is None or not x[1] > 0.0 or np.max(np.abs(x - guess)) > MAX_JUMP:
            continue  # lost, or jumped to another gait
        last[side] = x
        if side == 0:
            last[1] = last[-1] = x
        g = SymmetricGait(p, SpatialApex(float(x[0]), float(x[1]), float(x[2]), side=1),
                          row.energy, 0.0)
        try:
            out[i] = floquet(g, "exact", options).largest
        except ValueError:
            continue
    return out


def stable_intervals(k_lats: Sequence[float], largest: np.ndarray) -> list[tuple[float, float]]:
    """The runs of consecutive gains with ``largest < 1 - STABLE_MARGIN``, as (first, last)."""
    ok = np.asarray(largest) < 1.0 - STABLE_MARGIN
    out = []
    i = 0
    while i < len(ok):
        if ok[i]:
            j = i
            while j + 1 < len(ok) and ok[j + 1]:
                j += 1
            out.append((float(k_lats[i]), float(k_lats[j])))
            i = j + 1
        else:
            i += 1
    return out


def _fmt(z: complex) -> str:
    if abs(z.imag) < 1e-12:
        return f"{z.real:.4g}"
    return f"{z.real:.3g}{z.imag:+.3g}i"


def report(rows: list[GaitRow], scans: dict[int, np.ndarray], k_lats: Sequence[float],
           grid: dict[str, tuple[float, ...]]) -> str:
    """The verdicts and tables as Markdown."""
    lines = [f"Grid: k {list(grid['k'])}, beta0 {list(grid['beta0'])} rad, gamma0 "
             f"{list(grid['gamma0'])} rad, energy {list(grid['energy'])} MgL (m = l0 = g = 1); "
             f"feedback gains k_lat from {k_lats[0]} to {k_lats[-1]} in {len(k_lats)} steps.",
             ""]
    for heading in ("fixed", "velocity"):
        hr = [r for r in rows if r.heading == heading]
        n_st = sum(r.stable for r in hr)
        verdict = "holds" if hr and n_st == 0 else "fails" if n_st else "untested (no gaits)"
        lines.append(f"- Claim 1 under heading=\"{heading}\": {verdict}: {len(hr)} symmetric "
                     f"gaits, {n_st} stable; smallest largest non-trivial |multiplier| "
                     f"{min((r.largest for r in hr), default=math.nan):.4g}.")
    fixed = [i for i, r in enumerate(rows) if r.heading == "fixed"]
    stabilised = [i for i in fixed if stable_intervals(k_lats, scans[i])]
    lines.append(f"- Claim 2 (heading=\"fixed\"; the feedback has no effect under \"velocity\"): "
                 f"{len(stabilised)} of {len(fixed)} gaits stabilised by some k_lat in the scan.")
    lines += ["", "| heading | k | beta0 | gamma0 | E | y | vx | vz | non-trivial multipliers "
              "| largest | stable k_lat |", "|" + " --- |" * 11]
    for i, r in enumerate(rows):
        a = r.gait.apex
        iv = "; ".join(f"[{lo:g}, {hi:g}]" for lo, hi in stable_intervals(k_lats, scans[i])) \
            if i in scans else "(no effect)"
        lines.append(f"| {r.heading} | {r.k:g} | {r.beta0:g} | {r.gamma0:g} | {r.energy:g} | "
                     f"{a.y:.4f} | {a.vx:.4f} | {a.vz:.4f} | "
                     f"{', '.join(_fmt(z) for z in r.nontrivial)} | {r.largest:.4g} | "
                     f"{iv or 'none'} |")
    return "\n".join(lines) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m tslip.spatial.claims [--out FILE] [--small]``."""
    ap = argparse.ArgumentParser(prog="python -m tslip.spatial.claims", description=__doc__)
    ap.add_argument("--out", help="write the Markdown there (else print it)")
    ap.add_argument("--small", action="store_true", help="one point of each axis (a smoke run)")
    a = ap.parse_args(argv)
    grid = {key: v[1:2] for key, v in GRID.items()} if a.small else GRID
    rows = survey(grid)
    scans = {i: feedback_scan(r) for i, r in enumerate(rows) if r.heading == "fixed"}
    text = report(rows, scans, K_LATS, grid)
    if a.out:  # replaced atomically: a link at that name is replaced, never written through
        atomic_write(a.out, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
    else:
        print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
