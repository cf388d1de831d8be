"""``all_gaits`` finds every fixed point an independent dense scan finds (issue 23, item 1).

The reference is a SLIP written here (m = g = l0 = 1, the units of the
``slip-human`` preset): a point mass on a massless spring leg with the foot
at the origin, stance by scipy's DOP853, flight in closed form, on the apex
section at fixed energy E (Seyfarth et al. 2002). It scans 3,000 touch-down
velocity angles over the default scan's range [-1.5, -0.001] rad (a
thousand stances at once in one ``solve_ivp`` system at rtol 1e-11, each
lift-off located on the quintic Hermite interpolant of its steps), brackets every sign change of
``P(y) - y`` between two defined apex heights, and polishes each bracket with
``brentq`` on the single-stride map (``solve_ivp`` with a lift-off event at
rtol 1e-12).

Cells (``slip-human``'s k and energy unless stated):

* seven (k, beta0) cells where the scan before this fix (brackets only
  between two defined strides) missed the flat, flip-unstable gait that lies
  right next to a failing stride (multipliers -2.6 to -11.2; k 20 to 50 across
  the band where the flat gait exists, mapped with 3,000-point scans);
* three cells 0.01, 0.02 and 0.04 deg above the fold where the flat and the
  steep gait merge (found by bisection on beta0 of the residual's extremum;
  the test checks with the reference that the fold lies within 0.05 deg
  below each cell).
"""

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

import tslip
from tslip.gait.allgaits import all_gaits
from tslip.gait.problem import nominal_energy

HUMAN = tslip.preset("slip-human")
E = nominal_energy(HUMAN)  # 2.2014 MgL: 5 m/s touching down at 68 deg
D_LO, D_HI = -1.5, -1e-3  # the range of the default scan [rad]
N_SCAN = 3000

#: (k, beta0) cells where the flat gait sits next to a failing stride.
EDGE_CELLS = [(20.0, 1.17), (22.5, 1.20), (25.48, 1.23), (30.0, 1.25), (35.0, 1.28),
              (40.0, 1.30), (50.0, 1.33)]
#: (k, fold beta0, cell offset above the fold [deg]).
FOLD_CELLS = [(25.48, 1.165197624, 0.01), (35.0, 1.223353726, 0.02),
              (45.0, 1.262970366, 0.04)]


def _rhs(t, s, k):
    x, y, u, v = s.reshape(4, -1)
    l = np.hypot(x, y)
    a = k * (1.0 - l) / l
    return np.concatenate([u, v, a * x, a * y - 1.0])


def _hermite(p0, v0, a0, p1, v1, a1, h, s):
    """Quintic Hermite on one step (value and time derivative at ``s`` in [0, 1])."""
    s2, s3, s4, s5 = s * s, s**3, s**4, s**5
    b = [1 - 10 * s3 + 15 * s4 - 6 * s5, s - 6 * s3 + 8 * s4 - 3 * s5,
         0.5 * (s2 - 3 * s3 + 3 * s4 - s5), 10 * s3 - 15 * s4 + 6 * s5,
         -4 * s3 + 7 * s4 - 3 * s5, 0.5 * (s3 - 2 * s4 + s5)]
    db = [-30 * s2 + 60 * s3 - 30 * s4, 1 - 18 * s2 + 32 * s3 - 15 * s4,
          0.5 * (2 * s - 9 * s2 + 12 * s3 - 5 * s4), 30 * s2 - 60 * s3 + 30 * s4,
          -12 * s2 + 28 * s3 - 15 * s4, 0.5 * (3 * s2 - 8 * s3 + 5 * s4)]
    c = [p0, h * v0, h * h * a0, p1, h * v1, h * h * a1]
    return sum(ci * bi for ci, bi in zip(c, b)), sum(ci * bi for ci, bi in zip(c, db)) / h


def scan_excess(k, beta, deltas):
    """Apex heights ``y`` of the touch-downs at ``deltas`` and ``P(y) - y`` (NaN: no apex)."""
    n = deltas.size
    y_td = math.sin(beta)
    v = math.sqrt(2.0 * (E - y_td))
    s0 = np.concatenate([np.full(n, -math.cos(beta)), np.full(n, y_td),
                         v * np.cos(deltas), v * np.sin(deltas)])
    sol = solve_ivp(_rhs, (0.0, 3.0), s0, method="DOP853", rtol=1e-11, atol=1e-11, args=(k,))
    t, S = sol.t, sol.y.reshape(4, n, -1)
    A = _rhs(0.0, S.ravel(), k).reshape(4, n, -1)[2:]  # accelerations at the steps
    leg = np.hypot(S[0], S[1])
    leg[:, 0] = 0.0  # touch-down: the leg compresses from l0
    up = (leg[:, 1:] >= 1.0) & (leg[:, :-1] < 1.0)
    has = up.any(axis=1)
    i = np.argmax(up, axis=1)  # lift-off in the step (t_i, t_i+1)
    rows = np.arange(n)
    h = t[i + 1] - t[i]

    def state(s):
        (x, u), (y, w) = (_hermite(S[c, rows, i], S[c + 2, rows, i], A[c, rows, i],
                                   S[c, rows, i + 1], S[c + 2, rows, i + 1], A[c, rows, i + 1],
                                   h, s) for c in (0, 1))
        return x, y, u, w

    lo, hi = np.zeros(n), np.ones(n)
    for _ in range(60):  # bisection on the leg length along each step's interpolant
        m = 0.5 * (lo + hi)
        x, y, _, _ = state(m)
        longer = np.hypot(x, y) >= 1.0
        hi, lo = np.where(longer, m, hi), np.where(longer, lo, m)
    x, y_lo, u_lo, w_lo = state(hi)
    before = np.arange(t.size)[None, :] <= i[:, None]
    fell = np.any((S[1] <= 0.0) & before, axis=1)  # the hip at the ground in stance
    ok = has & ~fell & (u_lo >= 0.0) & (w_lo >= 0.0)
    y0 = y_td + 0.5 * (v * np.sin(deltas)) ** 2
    return y0, np.where(ok, y_lo + 0.5 * w_lo**2 - y0, np.nan)


def apex_excess(y, k, beta):
    """``P(y) - y`` of one stride (scipy DOP853 with a lift-off event at 1e-12); NaN: no apex."""
    y_td = math.sin(beta)

    def lift_off(t, s):
        return math.hypot(s[0], s[1]) - 1.0

    def hits_ground(t, s):
        return s[1]

    lift_off.terminal, lift_off.direction = True, 1.0
    hits_ground.terminal, hits_ground.direction = True, -1.0
    s0 = [-math.cos(beta), y_td, math.sqrt(2.0 * (E - y)), -math.sqrt(2.0 * (y - y_td))]
    sol = solve_ivp(lambda t, s: _rhs(t, s, k), (0.0, 20.0), s0, method="DOP853", rtol=1e-12,
                    atol=1e-12, events=(lift_off, hits_ground), first_step=1e-6)
    if sol.status != 1 or sol.t_events[0].size == 0:
        return math.nan
    _, y_lo, u, w = sol.y_events[0][0]
    return y_lo + 0.5 * w * w - y if u >= 0.0 and w >= 0.0 else math.nan


def reference_gaits(k, beta):
    """Apex heights of every fixed point the scan brackets, and the map's slope there."""
    deltas = np.linspace(D_LO, D_HI, N_SCAN)
    # in chunks: scipy's step on one 12,000-state system is slower than three of 4,000
    y, f = map(np.concatenate, zip(*(scan_excess(k, beta, c) for c in np.split(deltas, 3))))
    roots = []
    for j in np.flatnonzero(np.isfinite(f[:-1]) & np.isfinite(f[1:]) & (f[:-1] * f[1:] <= 0)):
        a, b = sorted((y[j], y[j + 1]))
        r = brentq(apex_excess, a, b, args=(k, beta), xtol=1e-14, rtol=1e-15)
        c = [(apex_excess(r + e, k, beta) - apex_excess(r - e, k, beta)) / (2 * e)
             for e in (1e-6, 2e-6)]
        roots.append((r, 1.0 + (4 * c[0] - c[1]) / 3))  # Richardson-extrapolated P'(y)
    return roots


def _check_cell(k, beta):
    ref = reference_gaits(k, beta)
    p = dataclasses.replace(HUMAN, k=k, beta0=beta, alpha_r=beta)
    s = all_gaits(p, energy=E)
    heights = [g.apex.y for g in s if D_LO <= g.state.delta <= D_HI]
    for y, _ in ref:
        assert min(abs(h - y) for h in heights) < 1e-8, (k, beta, y, heights)
    assert len(heights) == len(ref)  # and nothing the reference does not have
    return ref, s


@pytest.mark.parametrize(("k", "beta"), EDGE_CELLS)
def test_gaits_next_to_failing_strides_are_found(k, beta):
    ref, s = _check_cell(k, beta)
    assert len(ref) == 2  # the flat flip-unstable gait and the steep unstable one
    (_, flat), (_, steep) = sorted(ref)
    assert flat < -1.9 and steep > 1.0
    assert s.max_nontrivial[0] == pytest.approx(abs(flat), rel=1e-4)


@pytest.mark.parametrize(("k", "fold", "above"), FOLD_CELLS)
def test_both_gaits_are_found_next_to_the_fold(k, fold, above):
    beta = fold + math.radians(above)
    ref, _ = _check_cell(k, beta)
    assert len(ref) == 2
    (y1, m1), (y2, m2) = sorted(ref)
    assert m1 < 1.0 < m2 and abs(m1 - 1.0) < 0.1 and abs(m2 - 1.0) < 0.1  # closing in
    # P(y) - y < 0 between the two; 0.05 deg below the cell the dip is gone (the fold
    # lies between): the map stays above the diagonal there
    assert apex_excess(0.5 * (y1 + y2), k, beta) < 0.0
    below = fold + math.radians(above - 0.05)
    low = minimize_scalar(apex_excess, bounds=(y1 - 0.02, y2 + 0.02), args=(k, below),
                          method="bounded", options={"xatol": 1e-8})
    assert low.fun > 0.0


def test_at_fixed_speed_the_slip_gaits_are_those_at_its_energy():
    """The SLIP's touch-down speed and angle fix its energy: the same gaits, the reference's."""
    k, beta = EDGE_CELLS[3]
    p = dataclasses.replace(HUMAN, k=k, beta0=beta, alpha_r=beta,
                            v0=math.sqrt(2.0 * (E - math.sin(beta))))
    s = all_gaits(p)
    assert math.isnan(s.energy) and "speed" in repr(s)
    ref = sorted(y for y, _ in reference_gaits(k, beta))
    assert len(s) == len(ref) == 2
    for g, y in zip(sorted(s, key=lambda g: g.apex.y), ref):
        assert g.apex.y == pytest.approx(y, abs=1e-8)
        assert g.state.v == pytest.approx(p.v0, abs=1e-12) and g.fix == "speed"
