"""Viability over three apex variables (issue 28): the TSLIP's map over (y, phi, phid)
against a scipy stride written here, its slices against the 1-D and 2-D maps, the
chunked iteration against the in-memory one, and the 3-D result's sections."""

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import tslip
from tslip.gait import _viable
from tslip.gait.viability import StateActionMap, Viability, state_action_map, viability

E = 14.0  # the Table 2.1 gait's speed v0 = 5 at apex height about 1.5
P = dataclasses.replace(tslip.preset("table2.1"), omega_r=0.0)  # the apex is a section
GRID = {"y": np.linspace(0.9, 1.3, 4), "phi": np.linspace(-0.2, 0.2, 3),
        "phid": np.linspace(-0.6, 0.6, 3)}
ACTIONS = {"alpha_r": np.linspace(0.9, 1.3, 4)}


def scipy_tslip_apex(p, y, phi, phid, alpha, energy):
    """Next apex ``(y, phi, phid)`` of the passive TSLIP with its trunk (local leg reset,
    no retraction, no leg damping), NaNs for no touch-down, a fall or no apex.

    Flight from the apex: the CoM falls freely, the trunk turns at ``phid``, the leg
    holds ``beta = alpha - phi`` (docs/conventions.md); touch-down at the first downward
    zero of the foot height ``y + r cos phi - l0 sin beta`` (eq. 2.9), found by a scan
    and brentq. Stance: CoM and trunk under the spring force at the hip,
    ``m a = F - m g``, ``J phidd = (hip - CoM) x F``, by solve_ivp (DOP853, 1e-13) to the
    downward zero of F_y (eq. 2.6); a fall if the hip reaches the ground or the CoM
    moves backward. Then the ballistic rise to the apex."""
    m, J, r, k, l0, g = p.m, p.J, p.r, p.k, p.l0, p.g
    nan = np.full(3, np.nan)
    xd = math.sqrt(2.0 * (energy - m * g * y - 0.5 * J * phid**2) / m)

    def foot(t):
        ph = phi + phid * t
        return y - 0.5 * g * t * t + r * math.cos(ph) - l0 * math.sin(alpha - ph)

    def hip(t):
        return y - 0.5 * g * t * t + r * math.cos(phi + phid * t)

    t, dt, above = 0.0, 1e-3, foot(0.0) > 0
    while True:
        if hip(t + dt) <= 0:
            return nan
        if above and foot(t + dt) <= 0:
            T = brentq(foot, t, t + dt, xtol=1e-15, rtol=1e-15)
            break
        above = above or foot(t + dt) > 0
        t += dt
    ph = phi + phid * T
    xf = -r * math.sin(ph) + l0 * math.cos(alpha - ph)  # the foot; CoM at x = 0

    def leg(s):
        hx, hy = s[0] - r * math.sin(s[2]), s[1] + r * math.cos(s[2])
        ell = math.hypot(hx - xf, hy)
        f = k * (l0 - ell) / ell
        return f * (hx - xf), f * hy, hy

    def rhs(_t, s):
        fx, fy, _ = leg(s)
        tau = -r * math.sin(s[2]) * fy - r * math.cos(s[2]) * fx
        return [s[3], s[4], s[5], fx / m, fy / m - g, tau / J]

    def liftoff(_t, s):
        return leg(s)[1]

    def hip_down(_t, s):
        return leg(s)[2]

    def backward(_t, s):
        return s[3]

    liftoff.terminal, liftoff.direction = True, -1.0
    hip_down.terminal = backward.terminal = True
    sol = solve_ivp(rhs, (0.0, 50.0), [0.0, y - 0.5 * g * T * T, ph, xd, -g * T, phid],
                    method="DOP853", rtol=1e-13, atol=1e-13,
                    events=[liftoff, hip_down, backward])
    if not len(sol.t_events[0]):
        return nan
    _, yl, pl, vxl, vyl, pdl = sol.y_events[0][0]
    if vyl < 0 or vxl < 0:
        return nan
    return np.array([yl + vyl * vyl / (2 * g), pl + pdl * vyl / g, pdl])


@pytest.fixture(scope="module")
def map3():
    return state_action_map(P, GRID, ACTIONS, energy=E)


def test_3d_map_matches_scipy_and_its_failures_agree(map3):
    m = map3
    assert m.next.shape == (4, 3, 3, 4, 3) and m.names == ("y", "phi", "phid")
    ok, bad = np.argwhere(~m.failed), np.argwhere(m.failed)
    assert len(ok) >= 20 and len(bad) >= 20
    assert len(set(m.status[m.failed].tolist())) >= 3  # several kinds of failure
    rng = np.random.default_rng(5)
    sample = np.vstack([ok[rng.choice(len(ok), 15, replace=False)],
                        bad[rng.choice(len(bad), 15, replace=False)]])
    for idx in map(tuple, sample):
        i, j, k, a = idx
        want = scipy_tslip_apex(P, GRID["y"][i], GRID["phi"][j], GRID["phid"][k],
                                m.actions[a], E)
        if m.failed[idx]:
            assert np.isnan(want).all(), (idx, int(m.status[idx]), want)
        else:
            assert np.max(np.abs(m.next[idx] - want)) < 1e-8, (idx, m.next[idx], want)


def test_1d_and_2d_maps_are_slices_of_the_3d_map_bit_for_bit(map3):
    m = map3
    y, phi, phid = GRID["y"], GRID["phi"], GRID["phid"]
    j0, k0 = int(np.flatnonzero(phi == 0)[0]), int(np.flatnonzero(phid == 0)[0])
    yphi = state_action_map(P, {"y": y, "phi": phi}, ACTIONS, energy=E)
    yphid = state_action_map(P, {"y": y, "phid": phid}, ("alpha_r", ACTIONS["alpha_r"]),
                             energy=E)
    one = state_action_map(P, {"y": y}, ACTIONS, energy=E)
    pairs = [(yphi, m.next[:, :, k0][..., [0, 1]], m.status[:, :, k0]),
             (yphid, m.next[:, j0][..., [0, 2]], m.status[:, j0]),
             (one, m.next[:, j0, k0][..., [0]], m.status[:, j0, k0])]
    for part, nxt, status in pairs:
        assert part.next.tobytes() == np.ascontiguousarray(nxt).tobytes()
        assert np.array_equal(part.status, status)
    assert (~one.failed).any()


def _random_map(rng, shape, n_a):
    axes = [np.sort(rng.uniform(-1, 1, n)) for n in shape]
    lo = np.array([g[0] for g in axes]) - 0.1
    hi = np.array([g[-1] for g in axes]) + 0.1
    nxt = rng.uniform(lo, hi, size=shape + (n_a, len(shape)))
    pick = rng.uniform(size=nxt.shape[:-1]) < 0.3  # successors on grid points
    for j, g in enumerate(axes):
        on = rng.integers(0, len(g), size=nxt.shape[:-1])
        nxt[..., j] = np.where(pick, g[on], nxt[..., j])
    nxt[rng.uniform(size=nxt.shape[:-1]) < (0.1, 0.1, 0.05)[len(shape) - 1]] = np.nan
    return axes, nxt


@pytest.mark.parametrize("rule", _viable.RULES)
@pytest.mark.parametrize("shape", [(30,), (7, 6), (5, 4, 6)])
def test_chunked_iteration_equals_the_in_memory_one(rule, shape):
    """The chunked sweep (any chunk size) gives the in-memory iteration's q, s and sweeps."""
    n_a, n_s, seen = 2, int(np.prod(shape)), []
    for seed in range(10):
        axes, nxt = _random_map(np.random.default_rng(seed), shape, n_a)
        flat = nxt.reshape(-1, len(shape))
        ok = np.all(np.isfinite(flat), axis=1)
        q0, s0, k0 = _viable.viable_sets(_viable.successor_cells(axes, flat, ok, rule), ok,
                                         n_s)
        seen.append((0 < q0.sum() < q0.size, k0))
        for rows in (1, 7, 64, 10_000):
            chunks = _viable.encode_chunks(axes, flat, ok, rule, rows=rows)
            assert all(c.dtype == np.int32 for c in chunks)
            q, s, k = _viable.viable_sets_chunked(chunks, n_s, n_a)
            assert np.array_equal(q, q0) and np.array_equal(s, s0) and k == k0
    assert any(part and k >= 2 for part, k in seen)  # the maps exercise the iteration


def test_chunked_iteration_refuses_chunks_that_do_not_fit():
    c = np.zeros((4, 2), dtype=np.int32)
    with pytest.raises(ValueError, match="hold 4 rows, not 6"):
        _viable.viable_sets_chunked([c], 3, 2)
    with pytest.raises(ValueError, match="2-D integer cell array"):
        _viable.viable_sets_chunked([c.astype(float)], 2, 2)


@pytest.mark.parametrize("rule", _viable.RULES)
def test_a_slip_slice_is_the_1d_result(rule):
    """The SLIP (r = 0, global leg reset) ignores the pitch, and its pitch stays put with no
    pitch rate: each pitch row of a (y, phi, phid = 0) map is viable exactly where the 1-D
    map is, as the former whole-array iteration computes it."""
    p = tslip.preset("slip")
    y, alpha = np.linspace(0.9, 2.2, 14), np.linspace(1.05, 1.4, 8)
    three = viability(state_action_map(p, {"y": y, "phi": [-0.2, 0.0, 0.2], "phid": [0.0]},
                                       ("alpha_r", alpha), energy=2.6), rule)
    one = state_action_map(p, {"y": y}, ("alpha_r", alpha), energy=2.6)
    ok = ~one.failed.ravel()
    q, s, _ = _viable.viable_sets(_viable.successor_cells(one.grid, one.next.reshape(-1, 1),
                                                          ok, rule), ok, len(y))
    assert s.any() and 0 < q.sum() < q.size
    for j in range(3):
        assert np.array_equal(three.s[:, j, 0], s)
        assert np.array_equal(three.q[:, j, 0], q.reshape(len(y), len(alpha)))


def _synthetic_3d():
    """(y, phi, phid)' = (y, phi / 2, 0) with one action, failing where y > 0.5 or
    |phi| > 0.7 or phid < -0.4: viable where y <= 0.5, |phi| <= 0.7 and phid >= -0.4."""
    y, phi, phid = np.linspace(0, 1, 5), np.linspace(-1, 1, 11), np.linspace(-1, 0.5, 7)
    Y, PH, PD = np.meshgrid(y, phi, phid, indexing="ij")
    nxt = np.stack([Y, PH / 2, 0 * PD], axis=-1)[..., None, :]
    failed = ((Y > 0.5) | (np.abs(PH) > 0.7) | (PD < -0.4))[..., None]
    return (y, phi, phid), StateActionMap.from_arrays({"y": y, "phi": phi, "phid": phid},
                                                      {"a": [0.0]}, nxt, failed)


def test_3d_sections_volume_and_labels(tmp_path):
    (y, phi, phid), smap = _synthetic_3d()
    v = viability(smap)
    want = (y[:, None, None] <= 0.5) & (np.abs(phi)[None, :, None] <= 0.7) \
        & (phid[None, None, :] >= -0.4)
    assert np.array_equal(v.s, want)
    assert v.volume_fraction == pytest.approx(3 * 7 * 4 / (5 * 11 * 7))
    sl = v.slice("phi")
    assert sl.names == ("y", "phid") and sl.at == 0.0 and sl.kind == "slice"
    assert np.array_equal(sl.s, want[:, 5]) and sl.label == "slice at phi = 0"
    pr = v.projection("phi")
    assert np.array_equal(pr.s, want.any(axis=1)) and "projection over phi" in pr.label
    at = v.slice("phid")  # phid's grid has no 0: the value nearest it
    assert at.at == phid[np.argmin(np.abs(phid))] and np.array_equal(at.s, want[:, :, 4])
    back = tslip.load(sl.save(tmp_path / "s.parquet"))
    assert np.array_equal(back.s, sl.s) and back.label == sl.label
    back = tslip.load(pr.save(tmp_path / "p.json"))
    assert np.array_equal(back.s, pr.s) and math.isnan(back.at)
    again = Viability.load(v.save(tmp_path / "v.parquet"))
    assert np.array_equal(again.s, v.s) and again.map.names == ("y", "phi", "phid")
    assert df_units_complete(sl)
    from matplotlib.figure import Figure

    for res in (v, sl, pr):
        fig = Figure()
        ax = fig.add_subplot()
        assert res.plot(ax) is fig and ax.collections
        assert ("projection" in ax.get_title()) == (res is not sl)


def df_units_complete(res) -> bool:
    df = res.to_dataframe()
    return set(df.attrs["units"]) == set(df.columns) and len(df) == res.s.size


@pytest.mark.parametrize(("grid", "name", "match"), [
    ({"phi": [0.1, 0.2]}, "phi", r"states\['phi'\] must contain 0"),
    ({}, "y", "name must be one of"),
    ({}, "x", "name must be one of"),
])
def test_bad_section_is_one_line(grid, name, match):
    (y, phi, phid), _ = _synthetic_3d()
    axes = {"y": y[:2], "phi": phi[:2], "phid": phid[:2], **grid}
    m = StateActionMap.from_arrays(axes, ("a", [0.0]), np.zeros((2, 2, 2, 1, 3)))
    with pytest.raises(ValueError, match=match) as exc:
        viability(m).slice(name)
    assert "\n" not in str(exc.value)
