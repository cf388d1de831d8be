"""Appendix E, the two-legged model: the data of Figures E.2-E.4 and Section E.4.

Kept apart from :mod:`tslip.sweeps.catalogue` so that its code hash
(:func:`tslip._codehash.code_hash` of this module) covers the biped and
nothing else: :func:`tslip.sweeps.reproduce.appendix_e_cached` reuses the
result until that code changes.

Strides are counted right touch-down to right touch-down, scuffs not
counted (:func:`tslip.biped.simulate.count_strides`). Table E.2 prints its
initial conditions to three or four decimals, so the count is also given
for starts perturbed within that rounding (:func:`table_e2_perturbations`).

The data is cached as JSON text (:func:`to_json`) and read back by a strict
decoder (:func:`from_json`): exactly the fields of :data:`DATA_FIELDS` with
their types, built only from the classes of :data:`DATA_CLASSES`, so a
cache file can hold numbers and nothing that runs.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._results import decode, encode
from ..biped import BipedParams, BipedState, simulate
from ..biped.gait import TrackingErrors, floquet, to_section, tracking_errors
from ..biped.metacentre import metacentric_test
from ..biped.simulate import BipedEvent, Trajectory, default_min_contact
from ..biped.stored import load_gait
from ..gait.impulse import Impulse, PitchResponse
from ..simulation.result import Status

__all__ = ["DATA_CLASSES", "DATA_FIELDS", "PIECE_SECONDS", "TABLE_E2_HALF_UNIT", "assemble",
           "fig_appendix_e", "from_json", "pieces", "table_e2_perturbations", "to_json"]

#: Half a unit of the last printed digit of each Table E.2 entry, in
#: :data:`tslip.biped.STATE_FIELDS` order: positions to 3 decimals; velocities
#: to 3, except the hip rates 1.6282 and -2.9350 (4).
TABLE_E2_HALF_UNIT = 0.5 * np.array([1e-3] * 9 + [1e-3] * 5 + [1e-4] + [1e-3] * 2 + [1e-4])


def table_e2_perturbations(n_random: int = 20, seed: int = 0,
                           one_at_a_time: bool = True) -> np.ndarray:
    """Table E.2 starts moved within the table's rounding, shape (n, 18).

    With ``one_at_a_time`` each entry moved alone by +- half a unit of its
    last printed digit (``x_b`` excepted: a shift along flat ground changes
    nothing), then ``n_random`` corners with every entry at a seeded random
    +- half unit.
    """
    if not isinstance(n_random, int) or n_random < 0:
        raise ValueError(f"n_random must be an integer >= 0, got {n_random!r}")
    y = BipedState.thesis().to_array()
    rows = []
    for i in range(1, len(y) if one_at_a_time else 1):
        for s in (-1.0, 1.0):
            r = y.copy()
            r[i] += s * TABLE_E2_HALF_UNIT[i]
            rows.append(r)
    signs = np.random.default_rng(seed).choice([-1.0, 1.0], size=(n_random, len(y)))
    signs[:, 0] = 0.0
    rows.extend(y + signs * TABLE_E2_HALF_UNIT)
    return np.array(rows).reshape(-1, len(y))


def _e2_run(n_strides: int, mc: float) -> dict[str, Any]:
    """The run from Table E.2 and its tracking errors over the first stride (Figure E.2)."""
    p, s = BipedParams(), BipedState.thesis()
    run = simulate(p, s, n_strides)
    t1 = float(run.strides[0, 0]) if run.n_steps else float(run.time[-1])
    return {"run": run, "strides": run.count_strides(mc), "strides_raw": run.n_steps,
            "reason": run.status.reason, "tracking": tracking_errors(run, 0, 0.0, t1)}


def _e2_floquet() -> tuple[float, float]:
    """Floquet multipliers at Table E.2's (non-periodic) start: largest, residual."""
    p = BipedParams()
    fl = floquet(p, to_section(p, BipedState.thesis().to_array(), 0.0))
    return fl.max_nontrivial, fl.residual


def _perturbed(y: np.ndarray, n_strides: int, mc: float) -> int:
    """Full strides from one perturbed Table E.2 start."""
    return simulate(BipedParams(), y, n_strides).count_strides(mc)


def _converged_floquet() -> tuple[float, float]:
    pc, yc, tc, _ = load_gait("converged-e2")
    flc = floquet(pc, to_section(pc, yc, tc))
    return flc.max_nontrivial, flc.residual


def _converged_run(n_converged: int, mc: float) -> int:
    pc, yc, tc, _ = load_gait("converged-e2")
    return simulate(pc, yc, n_converged, t0=tc).count_strides(mc)


def _converged_metacentric() -> Any:
    pc, yc, tc, _ = load_gait("converged-e2")
    return metacentric_test(pc, BipedState.from_array(yc), tc)


#: Seconds each piece takes, about (warm compile cache, one core), by name prefix.
PIECE_SECONDS = {"e2_run": 3.2, "e2_floquet": 4.5, "perturbed": 3.2, "converged_floquet": 4.5,
                 "converged_run": 1.6, "converged_metacentric": 0.3}


def pieces(n_strides: int = 20, n_converged: int = 50, n_random: int = 0,
           one_at_a_time: bool = False, min_contact: float | None = None
           ) -> dict[str, tuple[Any, tuple[Any, ...]]]:
    """:func:`fig_appendix_e`'s independent computations: name -> (function, arguments).

    Each Floquet analysis, each perturbed start and each run is its own
    piece, so they can run in parallel; :func:`assemble` puts the results
    together.
    """
    mc = _min_contact(min_contact)
    out: dict[str, tuple[Any, tuple[Any, ...]]] = {
        "e2_run": (_e2_run, (n_strides, mc)), "e2_floquet": (_e2_floquet, ())}
    for k, y in enumerate(table_e2_perturbations(n_random, one_at_a_time=one_at_a_time)):
        out[f"perturbed/{k}"] = (_perturbed, (y, n_strides, mc))
    out["converged_floquet"] = (_converged_floquet, ())
    out["converged_run"] = (_converged_run, (n_converged, mc))
    out["converged_metacentric"] = (_converged_metacentric, ())
    return out


def _min_contact(min_contact: float | None) -> float:
    return default_min_contact(BipedParams()) if min_contact is None else float(min_contact)


def assemble(results: dict[str, Any], n_strides: int = 20, n_converged: int = 50,
             min_contact: float | None = None, **_: Any) -> dict[str, Any]:
    """:func:`fig_appendix_e`'s data from its :func:`pieces`' results (by name)."""
    e2 = results["e2_run"]
    largest, residual = results["e2_floquet"]
    clargest, cresidual = results["converged_floquet"]
    n_pert = sum(k.startswith("perturbed/") for k in results)
    return {
        "e2": {"run": e2["run"], "strides": e2["strides"], "strides_raw": e2["strides_raw"],
               "min_contact": _min_contact(min_contact),
               "strides_perturbed": [results[f"perturbed/{k}"] for k in range(n_pert)],
               "of": n_strides, "reason": e2["reason"], "largest": largest,
               "residual": residual, "tracking": e2["tracking"]},
        "converged": {"largest": clargest, "residual": cresidual,
                      "strides": results["converged_run"], "of": n_converged,
                      "metacentric": results["converged_metacentric"]},
    }


def fig_appendix_e(n_strides: int = 20, n_converged: int = 50, n_random: int = 0,
                   one_at_a_time: bool = False,
                   min_contact: float | None = None) -> dict[str, Any]:
    """Appendix E, the two-legged model: Figures E.2-E.4 and Section E.4's numbers.

    ``"e2"``: the run from Table E.2 (full strides until fall, of
    ``n_strides`` right contacts; ``strides_raw`` counts scuffs too), the
    counts from starts perturbed within Table E.2's rounding
    (``strides_perturbed``, :func:`table_e2_perturbations`; none by default:
    each costs about 2 s, the falling runs being stiff), the minimum
    contact used (``min_contact`` [g^-1/2 L^1/2], default
    :func:`tslip.biped.simulate.default_min_contact`),
    its Floquet multipliers at that (non-periodic) start, and the tracking
    errors over its first stride (Figure E.2). ``"converged"``: the stored
    periodic gait reached from there (:mod:`tslip.biped.stored`), its
    residual, multipliers and full strides until fall (of ``n_converged``),
    and the metacentric test of Figure E.4 on it.

    Runs its :func:`pieces` one after the other; ``tslip reproduce`` runs
    them in parallel and calls :func:`assemble`.
    """
    work = pieces(n_strides, n_converged, n_random, one_at_a_time, min_contact)
    return assemble({k: fn(*args) for k, (fn, args) in work.items()}, n_strides, n_converged,
                    min_contact)


#: The fields of :func:`fig_appendix_e`'s data, section by section, and their types
#: (``list`` is a list of ``int``): what :func:`from_json` accepts, nothing more or less.
DATA_FIELDS: dict[str, dict[str, type]] = {
    "e2": {"run": Trajectory, "strides": int, "strides_raw": int, "min_contact": float,
           "strides_perturbed": list, "of": int, "reason": str, "largest": float,
           "residual": float, "tracking": TrackingErrors},
    "converged": {"largest": float, "residual": float, "strides": int, "of": int,
                  "metacentric": PitchResponse},
}
#: The classes a cached copy may name (the run, its events, parameters and status; the
#: tracking errors; the metacentric test, its impulses and states) and its one array dtype.
DATA_CLASSES = frozenset(f"{c.__module__}:{c.__qualname__}" for c in (
    Trajectory, BipedEvent, BipedParams, BipedState, Status, TrackingErrors, PitchResponse,
    Impulse))
_DTYPES = frozenset({"<f8"})
#: The tags of :func:`tslip._results.encode` the data uses (no object arrays, frames, paths).
_TAGS = frozenset({"__type__", "__enum__", "__ndarray__", "__tuple__", "__float__"})


def _is(v: Any, kind: type) -> bool:
    """``v`` is a ``kind``: exactly for numbers and text (no bool for an int), a list of int."""
    if kind is list:
        return isinstance(v, list) and all(type(n) is int for n in v)
    return type(v) is kind if kind in (int, float, str) else isinstance(v, kind)


def to_json(data: dict[str, Any]) -> Any:
    """:func:`fig_appendix_e`'s data as JSON values (floats and arrays bit for bit)."""
    return encode(data, "appendix_e")


def from_json(tree: Any) -> dict[str, Any]:
    """The data :func:`to_json` made ``tree`` from, if it is exactly that; else ``ValueError``.

    Before anything is built, every tagged value must be one of :data:`DATA_CLASSES`, a
    float64 array, a tuple or a non-finite float; after, the sections and fields must be
    those of :data:`DATA_FIELDS`, of their types.
    """
    stack = [tree]
    while stack:
        x = stack.pop()
        if isinstance(x, list):
            stack.extend(x)
        elif isinstance(x, dict):
            tags = {k for k in x if k.startswith("__")}
            if not tags <= _TAGS or len(tags) > 1:
                raise ValueError(f"unexpected tags {sorted(tags)}")
            for tag, allowed in (("__type__", DATA_CLASSES), ("__enum__", DATA_CLASSES),
                                 ("__ndarray__", _DTYPES)):
                if tag in x and not (isinstance(x[tag], str) and x[tag] in allowed):
                    raise ValueError(f"unexpected {tag} {x[tag]!r}")
            stack.extend(x.values())
    data = decode(tree)
    if not isinstance(data, dict) or set(data) != set(DATA_FIELDS):
        raise ValueError(f"expected the sections {sorted(DATA_FIELDS)}")
    for section, fields in DATA_FIELDS.items():
        got = data[section]
        if not isinstance(got, dict) or set(got) != set(fields):
            raise ValueError(f"{section}: expected the fields {sorted(fields)}")
        for name, kind in fields.items():
            if not _is(got[name], kind):
                raise ValueError(f"{section}.{name}: expected {kind.__name__}, "
                                 f"got {type(got[name]).__name__}")
    return data
