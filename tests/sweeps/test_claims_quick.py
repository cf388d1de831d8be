"""The thesis claims of Figures 4.8-4.25, checked on the quick-resolution studies.

Each parametrised case runs (once, cached for the module) the catalogue studies
a claim needs at the resolution of ``tslip reproduce --quick`` and asserts the
claim holds -- plainly or under the reading its result names -- with the
claim's own numbers in the failure message. The claims that do not hold at this
resolution (4.9's pitch rate and 4.16's located boundary, which do not hold at full
resolution either; 4.13, 4.18 and 4.19, judged on few points here; 4.25's pitch-rate
claims compared at each r; the Table 6.1 numbers) are
reported as such by ``tslip reproduce`` and are not asserted here.
"""

from __future__ import annotations

import pytest

from tslip.sweeps import catalogue, run_study
from tslip.sweeps.claims import CLAIMS, Verdict, evaluate

#: Claim ids that hold at quick resolution.
HOLDING = ["4.8-minimum-speed", "4.8-stable-above-minimum", "4.8-converge-most-quickly",
           "4.9-push-linear-in-speed",
           "4.9-step-down-peak", "4.11-times-match-equations",
           "4.11-flight-time-trends", "4.11-stance-time-trends", "4.12-leg-damping-stability",
           "4.14-hip-damping-stability", "4.15-hip-damping-robustness",
           "4.17-mass-offset-robustness",
           "4.20-touchdown-angle-range", "4.20-flatter-more-stable",
           "4.21-touchdown-angle-robustness",
           "4.22-retraction-stability", "4.23-retraction-robustness", "4.24-passive-r-positive",
           "4.24-local-velocity-asymptotic", "4.24-global-pd-neutral",
           "4.25-local-velocity-least-push"]
#: Studies a claim reads besides its ``needs``: the second set-up of Figures 4.8-4.9.
EXTRA = {"velocity": ("velocity_bar",)}

_results: dict[str, object] = {}


def _data(needs: tuple[str, ...]) -> dict:
    specs = catalogue.studies(quick=True)
    names = list(needs) + [e for n in needs for e in EXTRA.get(n, ())]
    for name in names:
        if name not in _results:
            _results[name] = run_study(specs[name], workers=1)
    return {n: _results[n] for n in names}


@pytest.mark.parametrize("claim_id", HOLDING)
def test_thesis_claim_holds(claim_id: str) -> None:
    (claim,) = [c for c in CLAIMS if c.id == claim_id]
    (res,) = evaluate(_data(claim.needs), (claim,))
    assert res.verdict in (Verdict.HOLDS, Verdict.HOLDS_UNDER_READING), \
        f"{claim_id}: {claim.text} -- our numbers: {res.numbers}"
    if res.verdict is Verdict.HOLDS_UNDER_READING:
        assert res.note.startswith("holds under:") and res.evidence, res
