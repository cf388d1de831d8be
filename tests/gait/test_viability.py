"""Viability kernels and basins (issue 13 items 4-5).

The iteration is checked on hand-made maps whose kernels are known in closed
form or by brute force written here; the physical map against a scipy SLIP
apex map written in this file.
"""

import itertools
import math

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
    with pytest.raises(ValueError, match="holds a Viability, not a StateActionMap"):
        StateActionMap.load(tmp_path / "v.parquet")
    import tslip

    for suffix in (".json", ".csv"):  # the whole object as JSON; the table as text
        again = tslip.load(v.save(tmp_path / f"v{suffix}"))
        assert again.map.next.tobytes() == smap.next.tobytes()
        assert np.array_equal(again.q, v.q) and np.array_equal(again.s, v.s)
    assert "viable" in repr(v) and len(repr(v)) < 200
    from dataclasses import replace

    for n, word in ((1, "1 sweep)"), (3, "3 sweeps)")):  # one sweep is not "1 sweeps"
        assert repr(replace(v, sweeps=n)).endswith(word)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"states": {"x": [1.0, 0.0]}}, "strictly increasing"),
    ({"states": {}}, "one to three grids"),
    ({"actions": {"a": [0.0], "b": [1.0], "c": [2.0]}}, "one or two"),
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



# ---------------------------------------------------------------------------
# the physical map (SLIP and TSLIP at the apex) against scipy
# ---------------------------------------------------------------------------

E_SLIP = 2.6  # both SLIP fixed points exist here for alpha_r near 1.15-1.3


def scipy_slip_apex(p, y: float, alpha: float, energy: float) -> float:
    """Next apex height of a SLIP (point mass, massless spring leg): apex -> touch-down at
    l0 sin(alpha) -> stance integrated by solve_ivp (DOP853, 1e-12) -> lift-off at l = l0
    -> apex. NaN for no touch-down, a fall, or a lift-off moving down (no apex)."""
    from scipy.integrate import solve_ivp

    m, g, k, l0 = p.m, p.g, p.k, p.l0
    xd = math.sqrt(2.0 * (energy - m * g * y) / m)
    drop = y - l0 * math.sin(alpha)
    if drop <= 0:
        return math.nan
    yd = -math.sqrt(2.0 * g * drop)
    foot = l0 * math.cos(alpha)  # CoM at x = 0

    def rhs(_t, s):
        dx, dy = s[0] - foot, s[1]
        ell = math.hypot(dx, dy)
        f = k * (l0 - ell) / (m * ell)
        return [s[2], s[3], f * dx, f * dy - g]

    def liftoff(_t, s):
        return math.hypot(s[0] - foot, s[1]) - l0
    liftoff.terminal, liftoff.direction = True, 1.0

    def ground(_t, s):
        return s[1]
    ground.terminal = True

    sol = solve_ivp(rhs, (0.0, 50.0), [0.0, l0 * math.sin(alpha), xd, yd], method="DOP853",
                    rtol=1e-12, atol=1e-12, events=[liftoff, ground])
    if not len(sol.t_events[0]):
        return math.nan
    x, yy, vx, vy = sol.y_events[0][0]
    if vy < 0 or vx < 0:
        return math.nan
    return yy + vy * vy / (2.0 * g)


@pytest.fixture(scope="module")
def slip_map():
    import tslip
    from tslip.gait.viability import state_action_map

    p = tslip.preset("slip")
    return state_action_map(p, {"y": np.linspace(0.9, 2.2, 14)},
                            ("alpha_r", np.linspace(1.05, 1.4, 8)), energy=E_SLIP)


def test_slip_map_matches_scipy(slip_map):
    m = slip_map
    ok = np.argwhere(~m.failed)
    assert len(ok) > 40 and m.failed.any()
    rng = np.random.default_rng(3)
    for i, j in ok[rng.choice(len(ok), 6, replace=False)]:
        want = scipy_slip_apex(m.params, m.grid[0][i], m.actions[j], E_SLIP)
        assert abs(m.next[i, j, 0] - want) < 1e-9, (i, j)
    # where tslip finds no next apex, neither does scipy
    bad = np.argwhere(m.failed)
    for i, j in bad[rng.choice(len(bad), 4, replace=False)]:
        assert math.isnan(scipy_slip_apex(m.params, m.grid[0][i], m.actions[j], E_SLIP))


def test_slip_map_conserves_energy(slip_map):
    """The next apex of every cell has the energy of the grid (potential m g y' plus the
    forward speed the section returns); tslip's own xd, checked against m g y' + m xd'^2/2."""
    from tslip.gait import section

    m = slip_map
    i, j = np.nonzero(~m.failed)
    xd = np.sqrt(2 * (E_SLIP - m.params.g * m.grid[0][i]))
    b = section.apex_map_states(m.params, np.column_stack([m.grid[0][i], xd, 0 * xd, 0 * xd]),
                                m.actions[j], options=__import__("tslip").IntegratorOptions.tight(
                                    "dop853"))
    assert np.array_equal(b.y, m.next[i, j, 0])
    e = m.params.m * m.params.g * b.y + 0.5 * m.params.m * b.xd**2
    assert np.max(np.abs(e - E_SLIP)) < 1e-9


def test_slip_viability_and_a_parameter_action(slip_map, tmp_path):
    import tslip
    from tslip.gait.viability import state_action_map

    v = viability(slip_map)
    assert v.s.any() and not v.q[slip_map.failed].any()
    back = StateActionMap.load(slip_map.save(tmp_path / "m.parquet"))
    assert back.next.tobytes() == slip_map.next.tobytes()
    assert back.params == slip_map.params and back.energy == E_SLIP
    # the stiffness as the action: the same cells as alpha_r = 1.19 at k = 25
    p = tslip.preset("slip")
    by_k = state_action_map(p, {"y": slip_map.grid[0]}, ("k", [20.0, 25.0]), energy=E_SLIP)
    by_a = state_action_map(p, {"y": slip_map.grid[0]}, ("alpha_r", [p.alpha_r]),
                            energy=E_SLIP)
    assert np.array_equal(by_k.next[:, 1], by_a.next[:, 0], equal_nan=True)


def test_tslip_two_state_variables_conserve_energy():
    """The passive TSLIP (no leg damping, no retraction) over (y, phid): the next apex keeps
    the energy m g y + m xd^2/2 + J phid^2/2."""
    import dataclasses

    import tslip
    from tslip.gait import section
    from tslip.gait.viability import state_action_map

    p = dataclasses.replace(tslip.preset("table2.1"), omega_r=0.0)
    E = 14.0
    m = state_action_map(p, {"y": np.linspace(0.7, 1.3, 4), "phid": np.linspace(-0.5, 0.5, 3)},
                         ("alpha_r", np.linspace(0.6, 0.9, 3)), energy=E)
    assert m.next.shape == (4, 3, 3, 2) and (~m.failed).sum() > 5
    i, j, k = np.nonzero(~m.failed)
    y, phid = m.grid[0][i], m.grid[1][j]
    xd = np.sqrt(2 * (E - p.g * y - 0.5 * p.J * phid**2) / p.m)
    b = section.apex_map_states(p, np.column_stack([y, xd, 0 * y, phid]), m.actions[k],
                                options=tslip.IntegratorOptions.tight("dop853"))
    assert np.array_equal(np.stack([b.y, b.phid], -1), m.next[i, j, k])
    e = p.m * p.g * b.y + 0.5 * p.m * b.xd**2 + 0.5 * p.J * b.phid**2
    assert np.max(np.abs(e - E)) < 1e-9
    assert viability(m).s.shape == (4, 3)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"states": {"xd": [1.0, 2.0]}}, "unknown apex variable 'xd'"),
    ({"states": {"y": [1.0, 3.0]}}, "must stay below 2.6"),
    ({"energy": -1.0}, r"energy \[MgL\] must be"),
    ({"actions": ("k", [-1.0, 2.0])}, "actions\\['k'\\]"),
    ({"params": "table2.1"}, "params: the apex is a Poincare section only"),
])
def test_physical_map_bad_input_is_one_line(kwargs, match):
    import tslip
    from tslip.gait.viability import state_action_map

    args = {"states": {"y": [1.0, 1.2]}, "actions": ("alpha_r", [1.1, 1.2]), "energy": E_SLIP,
            "params": "slip"}
    args.update(kwargs)
    with pytest.raises(ValueError, match=match) as exc:
        state_action_map(tslip.preset(args["params"]), args["states"], args["actions"],
                         energy=args["energy"])
    assert "\n" not in str(exc.value)


def test_basin_of_the_slip_gait_against_scipy(tmp_path):
    """Starts at the gait's own apex are there at once; the strides a converged start needs
    bring scipy's apex map near the gait too, and a start that falls has no scipy apex
    within its strides either."""
    import tslip
    from tslip.gait import section
    from tslip.gait.viability import Basin, basin

    p = tslip.preset("slip")
    g = tslip.find_gait(p)
    E = section.total_energy(g.params, g.state)
    y_star = section.touchdown_to_apex(g.params, g.state).y
    grid = np.sort(np.append(np.linspace(0.85, 1.6, 16), y_star))
    b = basin(p, g, {"y": grid}, 40, tol=1e-7)
    assert b.steps[np.searchsorted(grid, y_star)] == 0
    assert b.converged.sum() >= 5 and b.fell.sum() >= 3
    alpha = g.params.alpha_r
    for i in np.flatnonzero(b.converged)[::3]:
        y = grid[i]
        for _ in range(int(b.steps[i])):
            y = scipy_slip_apex(p, y, alpha, E)
        assert abs(y - y_star) < 1e-5, (grid[i], b.steps[i])
    for i in np.flatnonzero(b.fell)[:2]:
        y = grid[i]
        for _ in range(int(b.n_done[i]) + 1):
            y = scipy_slip_apex(p, y, alpha, E) if np.isfinite(y) else y
        assert math.isnan(y)
    back = Basin.load(b.save(tmp_path / "b.parquet"))
    assert np.array_equal(back.steps, b.steps) and np.array_equal(back.status, b.status)
    assert back.grid[0].tobytes() == grid.tobytes() and back.params == b.params
    assert list(b.to_dataframe().columns[:2]) == ["y", "steps"]


def test_plots_draw_on_a_given_axes():
    from matplotlib.figure import Figure

    import tslip
    from tslip.gait.viability import Basin

    x, a, nxt = _doubling()
    one = viability(StateActionMap.from_arrays({"x": x}, ("a", a), nxt))
    X, Y, A = np.meshgrid(x, x[::4], a, indexing="ij")
    two = viability(StateActionMap.from_arrays({"x": x, "y": x[::4]}, ("a", a),
                                               np.stack([2 * X + A, Y / 2], axis=-1)))
    steps = np.where(np.abs(x) < 0.5, 3, -1)
    b1 = Basin(("y",), (x,), steps, np.full(x.shape, 10), np.where(steps < 0, 1, 0), 10, 1e-6,
               2.0, tslip.preset("slip"), np.zeros(5))
    b2 = Basin(("y", "phid"), (x, x[::4]), np.add.outer(steps, 0 * x[::4]),
               np.full((33, 9), 10), np.zeros((33, 9), dtype=np.int64), 10, 1e-6, 2.0,
               tslip.preset("slip"), np.zeros(5))
    for res in (one, two, b1, b2):
        fig = Figure()
        ax = fig.add_subplot()
        assert res.plot(ax) is fig
        assert ax.collections or ax.lines
    assert "reach the gait" in repr(b1)


def test_basin_over_two_section_variables_keeps_the_slip_pitch_rate():
    """At r = 0 with no hip torque the trunk spins at its apex rate for ever (no moment
    about the CoM), and at the gait's total energy its spin J phid^2 / 2 is missing from
    the point-mass motion: over (y, phid) only the phid = 0 row can reach the gait, and it
    is the one-variable basin (the 2-D grid's rows and coordinates are laid out right)."""
    import tslip
    from tslip.gait.viability import basin

    p = tslip.preset("slip")
    g = tslip.find_gait(p)
    y = np.linspace(0.85, 1.3, 6)
    two = basin(p, g, {"y": y, "phid": [-0.2, 0.0, 0.2]}, 30, tol=1e-7)
    one = basin(p, g, {"y": y}, 30, tol=1e-7)
    assert two.steps.shape == (6, 3)
    assert np.array_equal(two.steps[:, 1], one.steps) and one.converged.any()
    assert not two.converged[:, [0, 2]].any()


def _bracket_needs(grid: np.ndarray, x: float) -> set[int] | None:
    """The grid points a successor ``x`` needs viable under the bracket rule, written out:
    on a grid point (within 1e-9 of a spacing) that point, between two points both, NaN or
    outside the grid never (None)."""
    if math.isnan(x) or x < grid[0] - 1e-9 * (grid[1] - grid[0]) or x > grid[-1]:
        return None
    near = [i for i, g in enumerate(grid) if abs(x - g) <= 1e-9 * (grid[1] - grid[0])]
    if near:
        return {near[0]}
    i = int(np.searchsorted(grid, x))
    return {i - 1, i}


def test_two_actions_against_scipy_and_a_brute_force_kernel():
    """Two actions, the leg angle and the stiffness (issue 28): every cell of a small SLIP
    map over y x alpha_r x k equals the scipy stride above (to 1e-9, with the stiffness of
    its column; failures agree), and the viable pairs equal a greatest fixed point found by
    brute force in plain Python over the scipy successors (the bracket rule written out)."""
    import dataclasses

    import tslip
    from tslip.gait.viability import state_action_map

    p = tslip.preset("slip")
    ys, alphas, ks = np.linspace(0.9, 2.2, 10), np.linspace(1.05, 1.4, 5), [20.0, 30.0]
    m = state_action_map(p, {"y": ys}, {"alpha_r": alphas, "k": ks}, energy=E_SLIP)
    assert m.shape == (10, 5, 2) and m.action == ("alpha_r", "k") and m.n_actions == 10
    want = np.array([[[scipy_slip_apex(dataclasses.replace(p, k=k), y, a, E_SLIP) for k in ks]
                      for a in alphas] for y in ys])
    assert np.array_equal(np.isnan(want), m.failed)
    assert np.nanmax(np.abs(m.next[..., 0] - want)) < 1e-9
    live = {c for c in itertools.product(range(10), range(5), range(2))
            if _bracket_needs(ys, want[c]) is not None}
    while True:
        states = {c[0] for c in live}
        kept = {c for c in live if _bracket_needs(ys, want[c]) <= states}  # type: ignore[operator]
        if kept == live:
            break
        live = kept
    q = np.zeros(m.shape, dtype=bool)
    for c in live:
        q[c] = True
    v = viability(m, "bracket")
    assert 0 < q.sum() < (~m.failed).sum()  # some pairs viable, some surviving pairs not
    assert np.array_equal(v.q, q) and np.array_equal(v.s, q.any(axis=(1, 2)))


def test_omega_r_with_the_apex_clock_as_a_second_action():
    """``{"alpha_r": ..., "omega_r": ...}`` with ``retraction="apex"``: each omega_r column
    of the map is the one-action map at that retraction rate, bit for bit (the action axes
    in the order given); the lift-off clock is refused, since it is not an apex section."""
    import dataclasses

    import tslip
    from tslip.gait.viability import state_action_map

    p = dataclasses.replace(tslip.preset("table2.1"), retraction="apex")
    grid = {"y": [1.0, 1.2], "phid": [0.0, 0.3]}
    alphas, rates = [1.0, 1.1, 1.2], [0.0, 2.0]
    m = state_action_map(p, grid, {"alpha_r": alphas, "omega_r": rates}, energy=14.0)
    assert m.shape == (2, 2, 3, 2)
    for j, w in enumerate(rates):
        one = state_action_map(dataclasses.replace(p, omega_r=w), grid, ("alpha_r", alphas),
                               energy=14.0)
        assert m.next[..., j, :].tobytes() == one.next.tobytes()
        assert np.array_equal(m.status[..., j], one.status)
    assert not np.array_equal(m.next[..., 0, :], m.next[..., 1, :], equal_nan=True)
    swapped = state_action_map(p, grid, {"omega_r": rates, "alpha_r": alphas}, energy=14.0)
    assert swapped.next.tobytes() == np.swapaxes(m.next, 2, 3).tobytes()
    with pytest.raises(ValueError, match="Poincare section") as exc:
        state_action_map(dataclasses.replace(p, retraction="liftoff"), grid,
                         {"alpha_r": alphas, "omega_r": rates}, energy=14.0)
    assert "\n" not in str(exc.value)
