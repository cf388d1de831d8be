"""``viability(smap, rule="vibly")`` is vibly's cell rule (issue 23 item 2).

vibly (github.com/sheim/vibly, ``viability/viability.py``) bins each successor
with ``np.digitize`` per axis (``compute_Q_map``), stores the bins raveled in
a grid one larger per axis, and ``compute_QV`` removes a pair when any grid
point of the product of ``{b-1, b}`` that lies inside the grid is not a viable
state (``is_outside``, ``get_grid_indices``), sweeping in place until the
viable states stop changing. :func:`vibly_compute_qv` below is written here
from those semantics (not from tslip's code) and run on tslip's own successors.
"""

import dataclasses
import itertools
import re
from pathlib import Path

import numpy as np
import pytest

import tslip
from tslip.gait.viability import StateActionMap, state_action_map, viability

ROOT = Path(__file__).resolve().parents[2]


def vibly_compute_qv(nxt: np.ndarray, failed: np.ndarray, grid: tuple[np.ndarray, ...],
                     conflate_bin0: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """vibly's ``compute_Q_map`` binning and ``compute_QV`` iteration, pair by pair.

    ``conflate_bin0``: as vibly, a pair whose raveled bin is 0 (below the bottom
    on every axis) starts as failed (vibly stores a failure as bin 0).
    """
    shape = tuple(g.size for g in grid)
    bins = tuple(n + 1 for n in shape)
    q_map = np.zeros(failed.shape, dtype=np.int64)
    for idx in np.ndindex(failed.shape):
        if not failed[idx]:
            q_map[idx] = np.ravel_multi_index(
                [int(np.digitize(nxt[idx][j], g)) for j, g in enumerate(grid)], bins)
    q = ~failed & (q_map != 0 if conflate_bin0 else True)
    s = q.reshape(shape + (-1,)).any(axis=-1)
    s_old = np.zeros_like(s)
    while not np.array_equal(s, s_old):
        for idx in np.ndindex(q.shape):  # in place: a removal is seen later in the sweep
            if not q[idx]:
                continue
            b = np.unravel_index(q_map[idx], bins)
            points = [p for p in itertools.product(*[(x - 1, x) for x in b])
                      if all(0 <= c < n for c, n in zip(p, shape))]
            if not points or not all(s[p] for p in points):
                q[idx] = False
        s_old, s = s, q.reshape(shape + (-1,)).any(axis=-1)
    return q, s


@pytest.fixture(scope="module")
def docs_map():
    """The example at the top of docs/analyses/viability.md."""
    return state_action_map(tslip.preset("slip"), {"y": np.linspace(0.8, 2.5, 100)},
                            ("alpha_r", np.linspace(1.0, 1.45, 100)), energy=2.6)


def _agree(smap: StateActionMap) -> None:
    v = viability(smap, "vibly")
    for conflate in (False, True):
        q, s = vibly_compute_qv(smap.next, smap.failed, smap.grid, conflate)
        assert np.array_equal(v.q, q), (conflate, int((v.q != q).sum()))
        assert np.array_equal(v.s, s)


def test_agrees_with_vibly_on_the_docs_example(docs_map):
    """Cell for cell on the 100 x 100 SLIP grid of the docs; it has successors above the
    top and below the bottom of the grid, where the rules differ. The bottom states are
    not viable there, so vibly's bin-0 conflation changes nothing and vibly as it is
    agrees too."""
    ok = ~docs_map.failed
    y = docs_map.next[..., 0]
    assert (ok & (y >= 2.5)).sum() > 100 and (ok & (y < 0.8)).sum() > 100
    _agree(docs_map)
    bracket = viability(docs_map)
    assert viability(docs_map, "vibly").q.sum() > bracket.q.sum()


def test_agrees_with_vibly_on_the_two_variable_tslip_example():
    """The (y, phid) TSLIP grid of docs/analyses/viability.md: the product of {b-1, b}
    over two axes, and an iteration of more than one sweep."""
    p = dataclasses.replace(tslip.preset("table2.1-global-pd"), omega_r=0.0)
    m = state_action_map(p, {"y": np.linspace(0.48, 0.68, 9),
                             "phid": np.linspace(-0.3, 0.3, 7)},
                         ("alpha_r", np.linspace(0.98, 1.10, 9)), energy=13.07)
    assert viability(m, "vibly").sweeps >= 2
    _agree(m)


def test_agrees_with_vibly_on_random_two_variable_maps():
    """Successors on grid points, between them and beyond every edge, on 2-D grids whose
    kernels take several sweeps (vibly without its bin-0 conflation)."""
    partial = 0
    for seed in range(8):
        rng = np.random.default_rng(seed)
        gx, gy = np.linspace(0.0, 1.0, 6), np.linspace(-1.0, 1.0, 5)
        shape = (6, 5, 3)
        nxt = np.stack([rng.uniform(-0.2, 1.2, shape), rng.uniform(-1.3, 1.3, shape)], axis=-1)
        on = rng.uniform(size=shape) < 0.3  # a third onto grid points
        nxt[..., 0] = np.where(on, gx[rng.integers(0, 6, shape)], nxt[..., 0])
        nxt[..., 1] = np.where(on, gy[rng.integers(0, 5, shape)], nxt[..., 1])
        failed = rng.uniform(size=shape) < 0.3
        smap = StateActionMap.from_arrays({"x": gx, "y": gy}, ("a", [0.0, 1.0, 2.0]), nxt,
                                          failed=failed)
        v = viability(smap, "vibly")
        q, s = vibly_compute_qv(smap.next, smap.failed, smap.grid)
        assert np.array_equal(v.q, q) and np.array_equal(v.s, s), seed
        partial += 0 < q.sum() < (~failed).sum()
    assert partial >= 3


# ---------------------------------------------------------------------------
# the rules by hand: grid 0, 1, ..., 9; states 4 and 5 (and `live`) step to 4.0 and stay
# viable under every rule; every other state fails; the probe is a second action at state 4
# ---------------------------------------------------------------------------

GRID = np.arange(10.0)


def _probe(successor: float, live: set[int]) -> dict[str, bool]:
    home = set(live) | {4, 5}
    nxt = np.full((10, 2, 1), np.nan)
    for i in home:
        nxt[i, 0, 0] = 4.0  # needs 4 (bracket, nearest) or 4 and 5 (vibly)
    nxt[4, 1, 0] = successor
    smap = StateActionMap.from_arrays({"x": GRID}, ("a", [0.0, 1.0]), nxt)
    out = {}
    for rule in ("bracket", "nearest", "vibly"):
        v = viability(smap, rule)
        assert np.array_equal(v.s, np.isin(GRID, sorted(home))), rule  # the probe changes no S
        out[rule] = bool(v.q[4, 1])
    return out


@pytest.mark.parametrize(("successor", "live", "bracket", "nearest", "vibly"), [
    # exactly on a grid point: bracket and nearest need it; vibly it and the next one up
    (6.0, {6, 7}, True, True, True),
    (6.0, {6}, True, True, False),
    (6.0, {7}, False, False, False),
    (5.0, set(), True, True, False),
    (3.0 - 1e-12, {3}, True, True, False),  # bracket snaps onto 3; digitize gives 3: {2, 3}
    # between grid points: both neighbours (nearest: the nearer)
    (2.3, {2, 3}, True, True, True),
    (2.3, {2}, False, True, False),
    (2.3, {3}, False, False, False),
    # the top: on it, every rule needs it alone; above it, vibly needs it, tslip's rules fail
    (9.0, {9}, True, True, True),
    (9.0, {8}, False, False, False),
    (9.5, {9}, False, False, True),
    (1e3, {9}, False, False, True),
    (9.5, {8}, False, False, False),
    # the bottom: on it, vibly needs it and the next; below it, vibly needs the bottom point
    (0.0, {0}, True, True, False),
    (0.0, {0, 1}, True, True, True),
    (-0.5, {0}, False, False, True),
    (-0.5, {1}, False, False, False),
])
def test_each_rule_on_each_side(successor, live, bracket, nearest, vibly):
    assert _probe(successor, live) == {"bracket": bracket, "nearest": nearest, "vibly": vibly}


def test_a_failed_step_stays_failed_under_vibly_rule():
    """Only the failure flag fails a pair: a successor below the bottom is not bin 0's
    failure (vibly's conflation, the one difference from vibly)."""
    x = GRID[:3]
    nxt = np.array([[[-1.0], [5.0]], [[0.0], [np.nan]], [[1.5], [2.0]]])
    failed = np.array([[False, False], [False, True], [False, False]])
    smap = StateActionMap.from_arrays({"x": x}, ("a", [0.0, 1.0]), nxt, failed=failed)
    v = viability(smap, "vibly")
    # state 0: below the bottom (needs 0); state 2: 2.0 on the top (needs 2); state 1: 0.0
    # (needs 0 and 1); 5.0 above the top needs 2; the failed pair (1, 1) never
    assert v.q.tolist() == [[True, True], [True, False], [True, True]]
    q, _ = vibly_compute_qv(nxt, failed, (x,), conflate_bin0=True)
    assert q.tolist() == [[False, True], [True, False], [True, True]]


@pytest.mark.parametrize("rule", ["vibl", "Vibly", "", None, 3])
def test_an_unknown_rule_is_one_line_naming_the_allowed(rule):
    smap = StateActionMap.from_arrays({"x": GRID}, ("a", [0.0]), np.zeros((10, 1)))
    with pytest.raises(ValueError, match=r"^rule must be one of \['bracket', 'nearest', "
                       r"'vibly'\], got ") as exc:
        viability(smap, rule)
    assert "\n" not in str(exc.value)


# ---------------------------------------------------------------------------
# the pages name the rules right
# ---------------------------------------------------------------------------

PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md")),
         *(ROOT / "src" / "tslip" / "gait" / f"{m}.py"
           for m in ("viability", "statemap", "mapstore", "basins", "_viable"))]


def _sentences(text: str) -> list[str]:
    """Paragraphs (and list items, docstrings) split at sentence ends, newlines joined."""
    out = []
    for para in re.split(r'\n\s*\n|\n\s*[-*] |"""', text):
        out += re.split(r"(?<=[.;!?])\s+", " ".join(para.split()))
    return out


def default_called_viblys(text: str) -> list[str]:
    """Lines or sentences that call the default rule (or the default call) vibly's: a
    ``viability(...)`` call without ``"vibly"`` on a line that mentions vibly; "vibly's
    iteration" (with the default rule it is not); a sentence that mentions vibly with the
    default or ``bracket`` rule without naming ``"vibly"``, the rule that is vibly's."""
    bad = [ln for ln in text.splitlines()
           if "viability(" in ln and "vibly" in ln.lower() and '"vibly"' not in ln]
    for s in _sentences(text):
        low = s.lower()
        if "vibly's iteration" in low or ("vibly" in low and ("default" in low
                                                             or "bracket" in low)
                                          and '"vibly"' not in s):
            bad.append(s)
    return bad


def test_no_page_calls_the_default_rule_viblys():
    assert len(PAGES) > 10
    bad = {p.relative_to(ROOT).as_posix(): default_called_viblys(p.read_text())
           for p in PAGES}
    assert not any(bad.values()), {k: v for k, v in bad.items() if v}


@pytest.mark.parametrize("text", [
    'viable = tslip.gait.viability(smap)      # the viable state-action set (vibly\'s iteration)',
    "viability follows vibly's iteration.",
    '`rule="bracket"` (default, conservative, as vibly\'s bracketing of off-grid successors)',
    "The default rule is vibly's.",
])
def test_the_page_check_catches_what_the_pages_said(text):
    assert default_called_viblys(text)


def test_the_pages_name_vibly_rule_and_the_difference():
    page = (ROOT / "docs" / "analyses" / "viability.md").read_text()
    readme = (ROOT / "README.md").read_text()
    for text in (page, readme):
        assert 'rule="vibly"' in text
    assert "np.digitize" in page and "bin 0" in page
