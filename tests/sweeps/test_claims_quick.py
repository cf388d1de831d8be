"""The thesis claims of Figures 4.11-4.25, checked on the quick-resolution studies.

Each parametrised case runs (once, cached for the module) the catalogue studies
a claim needs at the resolution of ``tslip reproduce --quick`` and asserts the
claim holds, with the claim's own numbers in the failure message. The claims
that do not hold in our model (4.9 pitch rate, 4.11 stiffness, 4.13, 4.18-4.19
at this resolution, 4.22, the Table 6.1 pitch-rate limit) are reported as such
by ``tslip reproduce`` and are not asserted here.
"""

from __future__ import annotations

import pytest

from tslip.sweeps import catalogue, run_study
from tslip.sweeps.claims import CLAIMS, evaluate

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")

#: (figure, index among that figure's claims)
HOLDING = [("4.11", 0), ("4.14", 0), ("4.15", 0), ("4.17", 0), ("4.20", 0), ("4.21", 0),
           ("4.23", 0), ("4.24", 0), ("4.25", 0), ("4.25", 1)]

_results: dict[str, object] = {}


def _data(needs: tuple[str, ...]) -> dict:
    specs = catalogue.studies(quick=True)
    for name in needs:
        if name not in _results:
            _results[name] = run_study(specs[name], workers=1)
    return {n: _results[n] for n in needs}


@pytest.mark.parametrize(("figure", "index"), HOLDING, ids=[f"{f}-{i}" for f, i in HOLDING])
def test_thesis_claim_holds(figure: str, index: int) -> None:
    claim = [c for c in CLAIMS if c.figure == figure][index]
    (res,) = evaluate(_data(claim.needs), (claim,))
    assert res.holds, f"{figure}: {claim.text} -- our numbers: {res.numbers}"
