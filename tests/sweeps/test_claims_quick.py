"""The thesis claims of Figures 4.8-4.25, checked on the quick-resolution studies.

Each parametrised case runs (once, cached for the module) the catalogue studies
a claim needs at the resolution of ``tslip reproduce --quick`` and asserts the
claim holds -- plainly or under the reading its result names -- with the
claim's own numbers in the failure message. The claims that do not hold at this
resolution (4.13's pitch rate, 4.18-4.19 with one stable stiffness, 4.25's
"similar" limits of the other controllers, the Table 6.1 pitch-rate limit) are
reported as such by ``tslip reproduce`` and are not asserted here.
"""

from __future__ import annotations

import pytest

from tslip.sweeps import catalogue, run_study
from tslip.sweeps.claims import CLAIMS, Verdict, evaluate

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")

#: (figure, index among that figure's claims)
HOLDING = [("4.8", 0), ("4.9", 0), ("4.9", 1), ("4.9", 2), ("4.11", 0), ("4.11", 1),
           ("4.12", 0), ("4.14", 0), ("4.15", 0), ("4.16", 0), ("4.17", 0), ("4.20", 0),
           ("4.21", 0), ("4.22", 0), ("4.23", 0), ("4.24", 0), ("4.24", 1), ("4.24", 2),
           ("4.25", 0), ("4.25", 2)]
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


@pytest.mark.parametrize(("figure", "index"), HOLDING, ids=[f"{f}-{i}" for f, i in HOLDING])
def test_thesis_claim_holds(figure: str, index: int) -> None:
    claim = [c for c in CLAIMS if c.figure == figure][index]
    (res,) = evaluate(_data(claim.needs), (claim,))
    assert res.holds, f"{figure}: {claim.text} -- our numbers: {res.numbers}"
    if res.verdict is Verdict.HOLDS_UNDER_READING:
        assert res.note.startswith("holds under:") and res.evidence, res
