"""The SLIP recipe at the top of docs/analyses/slip.md, and the README's snippets, run
exactly as printed.

The recipe's answers are checked against the independent point-mass SLIP of
tests/gait/test_section.py (scipy DOP853 stance, closed-form flight), not
against tslip's own numbers. The README's printed outputs are checked against
the comments beside them (what a reader is told the line prints), and its
pages are checked to state no verdict counts, which only ``tslip reproduce``
and the documentation table generated from its ``claims.json`` give.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import matplotlib
import numpy as np
import pytest

from gait.test_section import ref_apex_map  # tests/ is on the path (rootdir conftest)

matplotlib.use("Agg")

PAGE = Path(__file__).resolve().parents[2] / "docs" / "analyses" / "slip.md"


@pytest.fixture(scope="module")
def recipe() -> dict:
    text = PAGE.read_text()
    block = re.search(r"```python\n(.*?)```", text, re.S)
    assert block is not None, "slip.md lost its recipe"
    code = block.group(1)
    assert len([ln for ln in code.splitlines() if ln.strip() and not ln.startswith(
        ("import", "p = "))]) <= 5, "the recipe is five lines of the API"
    ns: dict = {}
    exec(compile(code, str(PAGE), "exec"), ns)  # noqa: S102 - our own documentation
    return ns


def _ref_slope(y: float, E: float, beta: float, k: float, h: float = 1e-5) -> float:
    up, down = ref_apex_map(y + h, E, beta, k), ref_apex_map(y - h, E, beta, k)
    return (up[0] - down[0]) / (2 * h)


def test_both_fixed_points_with_their_labels(recipe):
    p, gaits = recipe["p"], recipe["gaits"]
    assert len(gaits) == 2
    for g, label in zip(gaits, gaits.stability):
        y = g.apex.y
        nxt = ref_apex_map(y, 2.2, p.beta0, p.k)
        assert nxt is not None and nxt[0] == pytest.approx(y, abs=1e-8)  # a fixed point
        slope = _ref_slope(y, 2.2, p.beta0, p.k)
        assert label == ("asymptotic" if abs(slope) < 1 else "unstable")
    assert sorted(gaits.stability) == ["asymptotic", "unstable"]


def _ref_stable_gait(E: float, beta: float, k: float) -> bool:
    """Whether the reference SLIP has a stable apex fixed point (|slope| < 1) at (k, beta)."""
    from scipy.optimize import brentq

    def gap(y: float) -> float:
        nxt = ref_apex_map(y, E, beta, k)
        return math.nan if nxt is None else nxt[0] - y

    ys = np.linspace(math.sin(beta) + 1e-3, E - 1e-3, 60)
    gs = [gap(y) for y in ys]
    for a, b, ga, gb in zip(ys[:-1], ys[1:], gs[:-1], gs[1:]):
        if np.isfinite(ga) and np.isfinite(gb) and ga * gb < 0:
            y = brentq(gap, a, b, xtol=1e-12)
            if abs(_ref_slope(y, E, beta, k)) < 1:
                return True
    return False


def test_stable_region_matches_the_reference(recipe):
    region = recipe["region"]
    assert region.stable.shape == (5, 4)
    ks, betas = (list(v) for v in region.values)
    # either side of the fixed-energy stability boundary at k = 25 (beta0 about 1.202)
    for beta in (1.2, 1.25):
        i, j = ks.index(25), betas.index(beta)
        assert bool(region.stable[i, j]) == _ref_stable_gait(2.2, beta, 25.0), beta
    assert region.stable.any() and not region.stable.all()
    assert region.plot() is not None


def test_viable_set_contains_the_stable_gait_and_excludes_falls(recipe):
    p, gaits, viable = recipe["p"], recipe["gaits"], recipe["viable"]
    smap = recipe["smap"]
    ys, alphas = smap.grid[0], smap.actions
    # the stable fixed point (y*, beta0 = 1.19) lies inside the viability kernel
    stable = gaits.stable[0]
    i = int(np.argmin(np.abs(ys - stable.apex.y)))
    j = int(np.argmin(np.abs(alphas - p.beta0)))
    assert viable.s[i] and viable.q[i, j], "the stable gait is viable"
    # an apex below the touch-down height l0 sin(alpha) falls at once, for every action
    below = ys < math.sin(alphas.min())
    assert below.any() and not viable.s[below].any()
    # every viable pair's next apex (from the reference) is still a state of the grid
    vi, vj = np.nonzero(viable.q)
    for a, b in list(zip(vi, vj))[:: max(1, len(vi) // 15)]:
        nxt = ref_apex_map(float(ys[a]), 2.2, float(alphas[b]), p.k)
        assert nxt is not None and ys.min() <= nxt[0] <= ys.max()


# -- the README's snippets, run as printed -------------------------------------------

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
_NUM = re.compile(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def _printing_blocks() -> list[str]:
    """The README's Python blocks that print, each as written."""
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.S)
    return [b for b in blocks if "print(" in b]


def _same(printed: str, expected: str) -> bool:
    """A printed token against the README's: a number to the README's decimals, else equal."""
    expected = expected.rstrip(":;,") if _NUM.fullmatch(expected.rstrip(":;,")) else expected
    if _NUM.fullmatch(expected) and _NUM.fullmatch(printed):
        decimals = len(expected.split(".")[1]) if "." in expected else 0
        return round(float(printed), decimals) == pytest.approx(float(expected), abs=1e-12)
    return printed == expected


@pytest.mark.parametrize("block", _printing_blocks(), ids=lambda b: b.split("\n")[0][:40])
def test_readme_prints_what_its_comments_say(block, tmp_path, monkeypatch, capsys) -> None:
    """Each ``print(...)  # output`` line of the README prints that output (its numbers to
    the decimals shown; the text after them in the comment is explanation)."""
    monkeypatch.chdir(tmp_path)  # the snippets write their example files here
    comments = [ln.split("#", 1)[1].strip() for ln in block.splitlines()
                if ln.startswith("print(") and "#" in ln]
    assert comments, "a printing README block states its output in a comment"
    exec(compile(block, str(README), "exec"), {})  # noqa: S102 - our own documentation
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == len(comments)
    for line, comment in zip(lines, comments, strict=True):
        got, want = line.split(), comment.split()
        assert len(want) >= len(got) and all(
            _same(g, w) for g, w in zip(got, want[: len(got)])), (line, comment)


def test_no_page_states_a_verdict_count_and_a_claim_count_is_the_list_s() -> None:
    """Verdict counts live only in what ``tslip reproduce`` writes (and the docs table
    generated from it); a number of claims, where a page states one, is ``len(CLAIMS)``."""
    from tslip.sweeps.claims import CLAIMS

    pages = [README, *(p for p in (ROOT / "docs").rglob("*.md")
                       if not {"_generated", "_build"} & set(p.parts))]
    for page in pages:
        text = page.read_text(encoding="utf-8")
        counts = re.findall(r"\b\d+ (?:hold|do not hold|holds? under|not assessed)\b", text)
        assert not counts, (page.name, counts)
        for n in re.findall(r"\b(\d+) (?:thesis )?claims\b", text):
            assert int(n) == len(CLAIMS), (page.name, n)
