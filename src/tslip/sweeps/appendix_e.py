"""Appendix E, the two-legged model: the data of Figures E.2-E.4 and Section E.4.

Kept apart from :mod:`tslip.sweeps.catalogue` so that its code hash
(:func:`tslip._codehash.code_hash` of this module) covers the biped and
nothing else: :func:`tslip.sweeps.reproduce.appendix_e_cached` reuses the
result until that code changes.

Strides are counted right touch-down to right touch-down, scuffs not
counted (:func:`tslip.biped.simulate.count_strides`). Table E.2 prints its
initial conditions to three or four decimals, so the count is also given
for starts perturbed within that rounding (:func:`table_e2_perturbations`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..biped import BipedParams, BipedState, simulate
from ..biped.gait import floquet, to_section, tracking_errors
from ..biped.metacentre import metacentric_test
from ..biped.simulate import default_min_contact
from ..biped.stored import load_gait

__all__ = ["TABLE_E2_HALF_UNIT", "fig_appendix_e", "table_e2_perturbations"]

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
    """
    p, s = BipedParams(), BipedState.thesis()
    mc = default_min_contact(p) if min_contact is None else float(min_contact)
    run = simulate(p, s, n_strides)
    t1 = float(run.strides[0, 0]) if run.n_strides else float(run.time[-1])
    fl = floquet(p, to_section(p, s.to_array(), 0.0))
    perturbed = [simulate(p, y, n_strides).count_strides(mc)
                 for y in table_e2_perturbations(n_random, one_at_a_time=one_at_a_time)]
    pc, yc, tc, _ = load_gait("converged-e2")
    flc = floquet(pc, to_section(pc, yc, tc))
    runc = simulate(pc, yc, n_converged, t0=tc)
    return {
        "e2": {"run": run, "strides": run.count_strides(mc), "strides_raw": run.n_strides,
               "min_contact": mc, "strides_perturbed": perturbed, "of": n_strides,
               "reason": run.status.reason, "largest": fl.largest, "residual": fl.residual,
               "tracking": tracking_errors(run, 0, 0.0, t1)},
        "converged": {"largest": flc.largest, "residual": flc.residual,
                      "strides": runc.count_strides(mc), "of": n_converged,
                      "metacentric": metacentric_test(pc, BipedState.from_array(yc), tc)},
    }
