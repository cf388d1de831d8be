"""Viability kernels and basins (issue 13 items 4-5).

The iteration is checked on hand-made maps whose kernels are known in closed
form or by brute force written here; the physical map against a scipy SLIP
apex map written in this file.
"""

import itertools

import numpy as np
import pytest

from tslip.gait.viability import StateActionMap, Viability, viability

STEP = 1.0 / 16.0


def _doubling(u: float = 0.5):
    """x' = 2x + a on |x| <= 1, |a| <= u: its viability kernel is exactly |x| <= u."""
    x = np.arange(-16, 17) * STEP
    a = np.arange(-round(u / STEP), round(u / STEP) + 1) * STEP
    nxt = 2 * x[:, None] + a[None, :]
    return x, a, nxt


@pytest.mark.parametrize("rule", ["bracket", "nearest"])
@pytest.mark.parametrize("u", [0.25, 0.5])
def test_doubling_map_kernel_is_the_closed_form(rule, u):
    x, a, nxt = _doubling(u)
    v = viability(StateActionMap.from_arrays({"x": x}, ("a", a), nxt, failed=np.abs(nxt) > 1),
                  rule)
    assert np.array_equal(v.s, np.abs(x) <= u + 1e-12)
    assert np.array_equal(v.q, np.abs(nxt) <= u + 1e-12)


def test_outside_the_grid_is_not_viable_even_without_a_failure_flag():
    x, a, nxt = _doubling()
    v = viability(StateActionMap.from_arrays({"x": x}, ("a", a), nxt))  # |x'| > 1 off the grid
    assert np.array_equal(v.s, np.abs(x) <= 0.5 + 1e-12)


def test_bracket_and_nearest_differ_as_stated():
    # state: successor (one action); nan = the stride fails
    succ = {0: 0.0, 1: 1.0, 2: np.nan, 3: 0.4, 4: 1.6, 5: 1.3, 6: 3.4, 7: 7 + 1e-12, 8: 8.5}
    x = np.arange(9.0)
    nxt = np.array([[succ[i]] for i in range(9)])
    smap = StateActionMap.from_arrays({"x": x}, ("a", [0.0]), nxt)
    bracket = viability(smap, "bracket").s
    nearest = viability(smap, "nearest").s
    assert bracket.tolist() == [True, True, False, True, False, False, False, True, False]
    assert nearest.tolist() == [True, True, False, True, False, True, True, True, False]


def test_a_chain_to_a_failure_is_removed_one_sweep_at_a_time():
    n = 12
    x = np.arange(float(n))
    nxt = (x + 1)[:, None]  # the last state steps off the grid
    v = viability(StateActionMap.from_arrays({"x": x}, ("a", [0.0]), nxt))
    assert not v.s.any() and v.sweeps == n - 1
    # a second action that stays put at even states (odd ones step on to the next even one)
    # keeps every state but the last (odd: it steps off the grid either way)
    stay = np.where(x % 2 == 0, x, x + 1)
    v2 = viability(StateActionMap.from_arrays({"x": x}, ("a", [0.0, 1.0]),
                                              np.stack([x + 1, stay], axis=1)))
    assert np.array_equal(v2.s, x < n - 1)
    assert np.array_equal(v2.q[:, 0], x < n - 2) and np.array_equal(v2.q[:, 1], x < n - 1)


@pytest.mark.parametrize("rule", ["bracket", "nearest"])
def test_two_state_variables(rule):
    """(x, y)' = (2x + a, 2y): viable exactly on |x| <= u, y = 0; and (2x + a, y / 2) keeps
    every y (y / 2 falls between grid points, where the bracket needs both neighbours)."""
    x, a, _ = _doubling()
    y = np.arange(-8, 9) * (2 * STEP)
    X, Y, A = np.meshgrid(x, y, a, indexing="ij")
    grow = np.stack([2 * X + A, 2 * Y], axis=-1)
    v = viability(StateActionMap.from_arrays({"x": x, "y": y}, ("a", a), grow), rule)
    want = (np.abs(x)[:, None] <= 0.5 + 1e-12) & (y[None, :] == 0)
    assert np.array_equal(v.s, want)
    shrink = np.stack([2 * X + A, Y / 2], axis=-1)
    v = viability(StateActionMap.from_arrays({"x": x, "y": y}, ("a", a), shrink), rule)
    assert np.array_equal(v.s, np.broadcast_to(np.abs(x)[:, None] <= 0.5 + 1e-12, v.s.shape))


def _invariant(q: np.ndarray, nxt_idx: np.ndarray) -> bool:
    """Every pair in q leads to a state with some pair in q (nearest rule, as a graph)."""
    s = q.any(axis=1)
    return bool(np.all(~q | np.where(nxt_idx >= 0, s[np.maximum(nxt_idx, 0)], False)))


@pytest.mark.parametrize("seed", range(6))
def test_kernel_is_the_union_of_all_invariant_sets(seed):
    """Brute force: the viability kernel is the largest set of pairs that never leaves itself
    (the union of every invariant subset of the pairs that do not fail at once)."""
    rng = np.random.default_rng(seed)
    n_s, n_a = 4, 2
    x = np.arange(float(n_s))
    nxt_idx = rng.integers(-1, n_s, size=(n_s, n_a))  # -1: falls
    nxt = np.where(nxt_idx >= 0, nxt_idx.astype(float), np.nan)
    v = viability(StateActionMap.from_arrays({"x": x}, ("a", [0.0, 1.0]), nxt), "nearest")
    union = np.zeros((n_s, n_a), dtype=bool)
    for bits in itertools.product((False, True), repeat=n_s * n_a):
        q = np.array(bits).reshape(n_s, n_a)
        if _invariant(q, nxt_idx):
            union |= q
    assert np.array_equal(v.q, union)


def test_random_map_fixed_point_properties():
    """On a random off-grid map: every viable pair's cell corners are viable states, and
    every pair left out that does not fail at once has a corner that is not."""
    rng = np.random.default_rng(1)
    x = np.linspace(0.0, 1.0, 21)
    a = np.linspace(0.0, 1.0, 7)
    nxt = rng.uniform(-0.05, 1.0, size=(21, 7))
    nxt[rng.uniform(size=nxt.shape) < 0.2] = np.nan
    v = viability(StateActionMap.from_arrays({"x": x}, ("a", a), nxt))
    assert 0 < v.q.sum() < v.q.size
    lo = np.clip(np.searchsorted(x, nxt, side="right") - 1, 0, len(x) - 2)
    ok = np.isfinite(nxt) & (nxt >= 0)
    corners_viable = ok & v.s[lo] & v.s[lo + 1]
    assert np.array_equal(v.q, corners_viable)


def test_results_round_trip_bit_for_bit(tmp_path):
    x, a, nxt = _doubling()
    smap = StateActionMap.from_arrays({"x": x}, ("a", a), nxt + 1e-3 * np.pi,
                                      failed=np.abs(nxt) > 1)
    v = viability(smap)
    df = v.to_dataframe()
    assert list(df.columns[:2]) == ["x", "a"] and len(df) == smap.status.size
    assert df.attrs["units"]["x"] == "-" and set(df.attrs["units"]) == set(df.columns)
    back = Viability.load(v.save(tmp_path / "v.parquet"))
    for got, want in ((back.q, v.q), (back.s, v.s), (back.map.status, smap.status)):
        assert np.array_equal(got, want)
    assert back.map.next.tobytes() == smap.next.tobytes()
    assert all(g.tobytes() == w.tobytes() for g, w in zip(back.map.grid, smap.grid))
    assert back.rule == v.rule and back.sweeps == v.sweeps
    m2 = StateActionMap.load(smap.save(tmp_path / "m.parquet"))
    assert m2.next.tobytes() == smap.next.tobytes() and m2.names == ("x",)
    with pytest.raises(ValueError, match="not a 'StateActionMap'"):
        StateActionMap.load(tmp_path / "v.parquet")
    assert "viable" in repr(v) and len(repr(v)) < 200


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"states": {"x": [1.0, 0.0]}}, "strictly increasing"),
    ({"states": {}}, "one or two grids"),
    ({"actions": "a"}, r"\(name, grid\)"),
    ({"rule": "closest"}, "rule must be one of"),
])
def test_bad_input_is_one_line(kwargs, match):
    args = {"states": {"x": [0.0, 1.0]}, "actions": ("a", [0.0]), "rule": "bracket"}
    args.update(kwargs)
    with pytest.raises(ValueError, match=match) as exc:
        smap = StateActionMap.from_arrays(args["states"], args["actions"],
                                          np.zeros((2, 1)))
        viability(smap, args["rule"])
    assert "\n" not in str(exc.value)

