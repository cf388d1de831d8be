"""The thesis's claims, one sentence each, tested on our results.

Each :class:`Claim` carries its figure, a one-line summary, the thesis's own
sentence (``quote``) and where it stands (``source``), the ``reading`` its
test implements, and a function of the results that returns a :class:`Check`:
the measured numbers and a :class:`Verdict`. The thresholds come from the
wording and are shared: "minimally", "little", "similar" mean a relative
size below :data:`REL`; "decreases", "improves" a Spearman correlation of at
least :data:`TREND` over the stated range ("tend to": :data:`TEND`); a
printed number is matched to its rounding (:data:`PRINTED`); |lambda| = 1 to
the multipliers' accuracy (:data:`MULT_TOL`) is neutral. Where the sentence
allows two readings both are checked and both readings' numbers are in the
evidence; a stability or convergence sentence read off an eigenvalue figure is
judged on the largest and the mean non-trivial |lambda| (``_eigen``); Figures
4.8-4.9 are judged in the set-up Section 3.4.1 states (omega_r held), the
other set-up's numbers shown. The tests
are written from the claims, never from our numbers: a claim that fails is
reported as failing, with the numbers and evidence, and, at quick resolution, a
note that the full resolution decides. A check whose statistic has too few
points (fewer than :data:`MIN_POINTS` for a rank correlation) returns
``Verdict.NOT_ASSESSED``, never a failure. Each claim has a stable ``id``
(:data:`ID_PATTERN`); :func:`count_verdicts` counts results per verdict
(``ClaimResult.holds`` is deprecated: read ``verdict``).

``data`` maps a study name (:data:`tslip.sweeps.catalogue.STUDIES`) to its
:class:`~tslip.sweeps.StudyResult`, and a figure key ("4.1", "4.2", "4.3",
"6.2", "4.4", "4.5", "4.7", "C.1", "4.16", "table6.1", "E") to the analysis object that
:mod:`tslip.sweeps.reproduce` computed for it; ``data["quick"]`` is True at
quick resolution. Optional evidence is read with ``.get`` (shown as "not
computed" when absent): ``table6.1`` ``pitch_rate_variants`` (label -> limit)
and ``alphad_ref_forced`` (``alphad_ref``, ``residual``, ``free``);
``E["e2"]`` ``strides_perturbed`` and ``min_contact``; the ``velocity_bar``
study (Figures 4.8-4.9 with ``omega_r_bar`` held).
"""

from ._list import CLAIMS, evaluate
from ._rules import (
    ID_PATTERN,
    MIN_POINTS,
    MULT_TOL,
    PRINTED,
    REL,
    TEND,
    TREND,
    Check,
    Claim,
    ClaimResult,
    Verdict,
    count_verdicts,
    stable_mask,
    stable_range,
)
from ._studies import grid_stable_fractions

__all__ = ["Check", "Claim", "ClaimResult", "CLAIMS", "ID_PATTERN", "MIN_POINTS", "MULT_TOL",
           "PRINTED", "REL", "TEND", "TREND", "Verdict", "count_verdicts", "evaluate",
           "grid_stable_fractions", "stable_mask", "stable_range"]
