"""Swing-leg retraction timed from the flight apex: ``Params(retraction="apex")``.

The rule (docs/conventions.md, "Frames and angles"): the leg is reset to
``alpha_r`` at lift-off and held until the apex ``t_apex = ydot_LO / g``, then
retracts, ``alpha(t) = alpha_r + omega_r (t - t_apex)``; a flight that leaves the
ground moving down has no apex and its clock starts at lift-off. The references
here are written in this file: the ballistic flight with the touch-down found by
scipy's brentq, and a point-mass SLIP whose stance is scipy's DOP853 at 1e-12.
"""

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import tslip
from tslip.gait.robustness import run_disturbed
from tslip.gait.stability import floquet, map_jacobian
from tslip.model import _pack as pk
from tslip.simulation import _kernels as kn
from tslip.simulation import _packed

TIGHT = tslip.IntegratorOptions.tight()


def _hex(values):
    return [float.fromhex(v) for v in values]


# -- the rule, with the touch-down time found independently ---------------------------

def _beta(p, lo, t, clock):
    """The leg angle of the rule, ``t`` after lift-off from ``lo = (x, y, xd, yd, phi, phid)``."""
    t_apex = max(lo[3], 0.0) / p.g if clock == "apex" else 0.0
    alpha = p.alpha_r + p.omega_r * np.maximum(t - t_apex, 0.0)
    return alpha - (lo[4] + lo[5] * t) if p.leg_reset == "local" else alpha


def _touchdown_by_brentq(p, lo, clock, t_max=2.0):
    """First downward zero of the foot height of the ballistic flight (eq. 2.9), by brentq."""

    def foot(t):
        y = lo[1] + lo[3] * t - 0.5 * p.g * t * t
        return y + p.r * np.cos(lo[4] + lo[5] * t) - p.l0 * np.sin(_beta(p, lo, t, clock))

    ts = np.linspace(0.0, t_max, 200001)
    f = foot(ts)
    armed = np.flatnonzero(f > 0.0)[0]  # a reset foot below the ground must rise first
    i = armed + np.flatnonzero((f[armed:-1] > 0.0) & (f[armed + 1:] <= 0.0))[0]
    return brentq(lambda t: float(foot(t)), ts[i], ts[i + 1], xtol=1e-15, rtol=1e-15)


def _kernel_touchdown(p, lo):
    """The kernels' touch-down time and leg angle from the lift-off state ``lo``."""
    P, O = pk.pack_params(p), tslip.IntegratorOptions().packed()
    res, fs = np.empty(3), np.empty(10)
    assert kn.find_touchdown(P, O, np.asarray(lo, float), np.empty(0), np.zeros(1), res) == 0
    kn.flight_state(P, np.asarray(lo, float), res[0], fs)
    return res[0], fs[6]


#: name -> (params, touch-down state): strides that touch down after, before and without an apex
_T21 = dataclasses.replace(tslip.preset("table2.1"), alpha_r=0.92)
_SLIP = dataclasses.replace(tslip.preset("slip"), omega_r=0.5, alpha_r=1.12)
_STRIDES = {
    "tslip local reset": (_T21, tslip.TouchdownState.from_velocity(
        v=5.0, delta=-0.025, beta=1.05, phi=0.0, phid=0.0)),
    "slip global reset": (_SLIP, tslip.TouchdownState.from_velocity(
        v=1.6, delta=-0.091, beta=1.19, phi=0.0, phid=0.0)),
    # touches down 0.047 after lift-off, before its apex at 0.083: the leg is still held
    "tslip before the apex": (_T21, tslip.TouchdownState.from_velocity(
        v=5.0, delta=-0.02, beta=1.05, phi=0.3, phid=-2.0)),
    # leaves the ground moving down (ydot = -0.11): no apex
    "slip without apex": (_SLIP, tslip.TouchdownState(beta=1.3, phi=0.0, xd=1.6, yd=0.0,
                                                        phid=0.0)),
}


@pytest.mark.parametrize("clock", ["apex", "liftoff"])
@pytest.mark.parametrize("case", list(_STRIDES))
def test_touchdown_angle_follows_the_rule(case, clock):
    p, s = _STRIDES[case]
    p = dataclasses.replace(p, retraction=clock)
    r = tslip.step(p, s)
    assert r.ok, r.reason
    lo = [r.liftoff.x, r.liftoff.y, r.liftoff.xd, r.liftoff.yd, r.liftoff.phi, r.liftoff.phid]
    t_td = _touchdown_by_brentq(p, lo, clock)
    assert r.flight_time == pytest.approx(t_td, abs=1e-10)
    t_apex = max(lo[3], 0.0) / p.g if clock == "apex" else 0.0
    alpha_td = r.state.beta + (r.state.phi if p.leg_reset == "local" else 0.0)
    # alpha_TD = alpha_r + omega_r (t_TD - t_apex), held at alpha_r before the apex
    assert alpha_td == pytest.approx(p.alpha_r + p.omega_r * max(t_td - t_apex, 0.0), abs=1e-10)
    if case == "tslip before the apex":
        assert t_td < 0.6 * lo[3] / p.g
        if clock == "apex":
            assert alpha_td == pytest.approx(p.alpha_r, abs=1e-12)
    if case == "slip without apex":
        assert lo[3] < -0.1


def test_flight_without_apex_is_the_liftoff_clock_bit_for_bit():
    lo = [0.0, 0.95, 1.6, -0.2, 0.1, 0.4]  # moving down at lift-off
    for base in (_T21, _SLIP):
        got = {c: _kernel_touchdown(dataclasses.replace(base, retraction=c), lo)
               for c in ("apex", "liftoff")}
        assert got["apex"] == got["liftoff"]
        assert got["apex"][0] == pytest.approx(_touchdown_by_brentq(base, lo, "liftoff"),
                                               abs=1e-10)


def test_the_apex_kink_is_not_stepped_over():
    """A foot that reaches the ground just after the apex, where its rate jumps.

    Held level (global reset), the foot of a rising body rises; fast retraction
    from the apex brings it down at once. Every touch-down time must be the
    brentq one, and none may be missed.
    """
    p = dataclasses.replace(_SLIP, omega_r=40.0, alpha_r=1.0, retraction="apex")
    for yd in (0.05, 0.2, 0.4):
        lo = [0.0, math.sin(1.0) + 0.003, 1.6, yd, 0.0, 0.0]
        t_td, beta = _kernel_touchdown(p, lo)
        assert t_td > yd / p.g
        assert t_td == pytest.approx(_touchdown_by_brentq(p, lo, "apex", t_max=1.5), abs=1e-10)
        assert beta == pytest.approx(1.0 + 40.0 * (t_td - yd / p.g), abs=1e-9)


@pytest.mark.parametrize("leg_reset", ["local", "global"])
def test_random_flights_touch_down_as_brentq_finds(rng, leg_reset):
    """Random lift-offs (pitch rates up to 6, retraction from -3 to 6, feet just above the
    ground): the kernels' first touch-down is the brentq one, never a later crossing."""
    compared = 0
    for _ in range(60):
        p = tslip.Params(r=rng.uniform(-0.3, 0.5), omega_r=rng.uniform(-3.0, 6.0),
                         alpha_r=rng.uniform(0.6, 1.4), leg_reset=leg_reset, retraction="apex")
        phi, phid = rng.uniform(-0.4, 0.4), rng.uniform(-6.0, 6.0)
        beta = p.alpha_r - (phi if leg_reset == "local" else 0.0)
        y = p.l0 * math.sin(beta) - p.r * math.cos(phi) + rng.uniform(5e-4, 0.05)
        lo = np.array([0.0, y, rng.uniform(0.5, 5.0), rng.uniform(-1.0, 1.5), phi, phid])
        P, res = pk.pack_params(p), np.empty(3)
        if kn.find_touchdown(P, tslip.IntegratorOptions().packed(), lo, np.empty(0),
                             np.zeros(1), res) != 0:
            continue  # a fall (the hip lands first)
        compared += 1
        assert res[0] == pytest.approx(_touchdown_by_brentq(p, lo, "apex", 1.5 * res[0] + 0.01),
                                       abs=1e-9)
    assert compared > 40


def test_recorded_flight_follows_the_rule():
    p = dataclasses.replace(_SLIP, retraction="apex")
    g = tslip.find_gait(p)
    tr = tslip.simulate(g.params, g.state, n_steps=2, dt=0.01)
    flight = (tr["step"] == 0) & (tr["stance"] == 0.0)
    t = tr["t"][flight] - tr.steps[0].stance_time
    t_apex = tr.steps[0].liftoff.yd / p.g
    want = g.params.alpha_r + p.omega_r * np.maximum(t - t_apex, 0.0)
    np.testing.assert_allclose(tr["beta"][flight], want, atol=1e-12)
    np.testing.assert_array_equal(tr["betad"][flight], np.where(t >= t_apex, p.omega_r, 0.0))
    assert (t < t_apex).sum() > 5 and (t > t_apex).sum() > 5


# -- gait search and the exact Jacobian -----------------------------------------------

_APEX_GAITS = {
    "slip": dataclasses.replace(tslip.preset("slip"), omega_r=0.5, retraction="apex"),
    "table2.1": dataclasses.replace(tslip.preset("table2.1"), retraction="apex"),
    "table6.1": dataclasses.replace(tslip.preset("table6.1"), retraction="apex"),
}


@pytest.fixture(scope="module")
def apex_gaits():
    return {name: tslip.find_gait(p) for name, p in _APEX_GAITS.items()}


@pytest.mark.parametrize("name", list(_APEX_GAITS))
def test_find_gait_converges_with_the_apex_clock(apex_gaits, name):
    g = apex_gaits[name]
    assert g.converged, g.message
    nxt = tslip.step(g.params, g.state, options=TIGHT)
    np.testing.assert_allclose(nxt.state.section(), g.state.section(), atol=1e-9)
    # it is the apex clock's gait: the leg retracts from the apex only
    lo = nxt.liftoff
    t_apex = lo.yd / g.params.g
    assert 0.0 < t_apex < nxt.flight_time
    alpha_td = g.state.beta + (g.state.phi if g.params.leg_reset == "local" else 0.0)
    assert alpha_td == pytest.approx(
        g.params.alpha_r + g.params.omega_r * (nxt.flight_time - t_apex), abs=1e-9)


@pytest.mark.parametrize("name", list(_APEX_GAITS))
def test_exact_multipliers_match_finite_differences(apex_gaits, name):
    g = apex_gaits[name]
    exact, fd = floquet(g), floquet(g, method="fd")
    np.testing.assert_allclose(exact.jacobian, fd.jacobian, atol=2e-7)
    np.testing.assert_allclose(np.sort(np.abs(exact.multipliers)),
                               np.sort(np.abs(fd.multipliers)), atol=1e-6)
    assert exact.stability == fd.stability
    # a touch-down after the apex follows from the 4-D apex state: rank 4, a multiplier 0
    assert np.min(np.abs(np.linalg.eigvals(exact.jacobian))) < 1e-9
    liftoff = floquet(tslip.find_gait(dataclasses.replace(g.params, retraction="liftoff")))
    assert np.min(np.abs(np.linalg.eigvals(liftoff.jacobian))) > 0.1


@pytest.mark.parametrize("case", list(_STRIDES))
def test_exact_jacobian_off_the_gait(case):
    """Strides after, before and without an apex: exact and central differences agree."""
    p, s = _STRIDES[case]
    p = dataclasses.replace(p, retraction="apex")
    q = s.section()
    exact = map_jacobian(p, q, options=TIGHT)
    fd = map_jacobian(p, q, method="fd", options=TIGHT)
    np.testing.assert_allclose(exact, fd, atol=1e-6 * max(1.0, np.max(np.abs(exact))))


@pytest.mark.parametrize("case", list(_STRIDES))
def test_alpha_r_column_matches_finite_differences(case):
    """The gait search's analytic ``dq'/d alpha_r``, also for a leg still held at touch-down."""
    p, s = _STRIDES[case]
    p = dataclasses.replace(p, retraction="apex")
    P, O = pk.pack_params(p), TIGHT.packed()
    out = np.empty(pk.NOUT)
    assert _packed.stride_map(P, O, s.section(), 0.0, out) == 0
    col = _packed.alpha_r_column(P, out)
    h = 1e-6
    nxt = []
    for sign in (1.0, -1.0):
        step = tslip.step_map(dataclasses.replace(p, alpha_r=p.alpha_r + sign * h), s.section(),
                              options=TIGHT)
        nxt.append(step.q)
    np.testing.assert_allclose(col, (nxt[0] - nxt[1]) / (2 * h), atol=1e-6)


# -- stability: the apex clock against the lift-off clock, with an independent SLIP ---

def _slip_stride(p, beta, xd, yd, clock):
    """Point-mass SLIP (m = g = l0 = 1, global reset): next touch-down (beta, xd, yd)."""

    def f(t, s):
        x, y, u, v = s
        a = p.k * (1.0 - math.hypot(x, y)) / math.hypot(x, y)
        return [u, v, a * x, a * y - 1.0]

    def lift_off(t, s):
        return math.hypot(s[0], s[1]) - 1.0

    lift_off.terminal, lift_off.direction = True, 1.0
    sol = solve_ivp(f, (0.0, 5.0), [-math.cos(beta), math.sin(beta), xd, yd], method="DOP853",
                    rtol=1e-12, atol=1e-12, events=lift_off, first_step=1e-6)
    x, y, u, v = sol.y_events[0][0]
    lo = [x, y, u, v, 0.0, 0.0]
    t = _touchdown_by_brentq(p, lo, clock, t_max=4.0)
    return np.array([float(_beta(p, lo, t, clock)), u, v - t])


def _slip_multipliers(p, q3, clock, h=1e-5):
    J = np.empty((3, 3))
    for j in range(3):
        e = np.zeros(3)
        e[j] = h
        J[:, j] = (_slip_stride(p, *(q3 + e), clock) - _slip_stride(p, *(q3 - e), clock)) / (2 * h)
    return np.sort(np.abs(np.linalg.eigvals(J)))


@pytest.mark.parametrize(
    ("beta0", "omega_r", "stable"),
    [(1.19, 0.5, "apex"),  # preset slip: unstable with the lift-off clock, stable from the apex
     (1.25, 0.25, "liftoff")],  # ... but not always: here the other way round
)
def test_apex_clock_changes_slip_stability(beta0, omega_r, stable):
    base = dataclasses.replace(tslip.preset("slip"), beta0=beta0, alpha_r=beta0, omega_r=omega_r)
    largest = {}
    for clock in ("liftoff", "apex"):
        g = tslip.find_gait(dataclasses.replace(base, retraction=clock))
        assert g.converged, g.message
        f = floquet(g)
        s = g.state
        ref = _slip_multipliers(g.params, np.array([s.beta, s.xd, s.yd]), clock)
        ours = np.sort(np.abs(f.multipliers[np.array(f.trivial_kinds) != "pitch"]))
        np.testing.assert_allclose(ours, ref, atol=1e-5)
        largest[clock] = f.max_nontrivial
        assert f.stability == ("asymptotic" if clock == stable else "unstable")
    other = "liftoff" if stable == "apex" else "apex"
    assert largest[stable] < 0.95 and largest[other] > 1.2


def test_apex_clock_stability_boundaries_are_twice_the_liftoff_ones():
    """Preset slip: stable for omega_r in (-0.099, 0.316) with the lift-off clock, and in
    exactly twice that interval from the apex (measured; at the lower end a multiplier
    crosses +1, at the upper end -1).

    With ``v0`` and ``beta0`` fixed both clocks have the same periodic orbit, with a
    symmetric flight (rise time = fall time): a change that keeps the flight symmetric
    changes the touch-down angle by ``omega_r dt_TD`` with the lift-off clock and by
    ``omega_r dt_TD / 2`` with the apex clock. Measured: the boundaries scale by 2 to
    1e-5 (also at beta0 = 1.25: 0.155 and 0.464 against 0.309 and 0.927), the multipliers
    inside the interval do not (0.82 at ``omega_r`` = 0.25 with the lift-off clock, 0.93
    at 0.5 from the apex).
    """
    base = tslip.preset("slip")

    def largest(w, clock):
        g = tslip.find_gait(dataclasses.replace(base, omega_r=w, retraction=clock))
        assert g.converged, g.message
        return floquet(g).max_nontrivial

    for a, b in ((-0.3, -0.01), (0.1, 0.6)):
        w = brentq(lambda v: largest(v, "liftoff") - 1.0, a, b, xtol=1e-9)
        assert largest(2.0 * w, "apex") == pytest.approx(1.0, abs=1e-5)
        assert largest(2.0 * w * 0.98, "apex") < 1.0 < largest(2.0 * w * 1.02, "apex")


# -- the default clock is today's, bit for bit ---------------------------------------

def test_default_liftoff_clock_is_bit_identical_to_main():
    """A Table 6.1 stride and its exact Jacobian, as computed by main at 0285a37.

    Regression pins: that revision's output (float.hex), so any change to the
    default arithmetic shows; a deliberate numerical change must re-pin them.
    The independent check of the same map is beside it:
    tests/simulation/test_reference.py (scipy DOP853 at 1e-12, to 1e-8).
    """
    p = tslip.preset("table6.1")
    assert p.retraction == "liftoff"
    q = _hex(['0x1.dc28f5c28f5c3p-1', '0x0.0p+0', '0x1.e3f8539f949c4p+0',
              '-0x1.8478c74919a9dp-3', '0x0.0p+0'])
    m = tslip.step_map(p, q)
    assert list(m.q) + [m.stance_time, m.flight_time] == _hex(
        ['0x1.bca84dbf83ff7p-1', '0x1.05782b637797ep-2', '0x1.e0aab572bc5e4p+0',
         '-0x1.29c0803627076p-4', '0x1.797985b151a35p-3', '0x1.51aad2afd28e9p-1',
         '0x1.089e79d1d67ddp-3'])
    _, J = tslip.step_jacobian(p, q)
    assert J.ravel().tolist() == _hex(
        ['-0x1.08218b8036362p-2', '-0x1.c74c1a82ac028p-6', '-0x1.9be3c128891c0p-6',
         '0x1.9b77a1bf0be6bp-2', '-0x1.33106d0aac2e8p-5', '-0x1.0827cf18ccd58p+0',
         '0x1.bc9bc295ac2e6p-3', '-0x1.69e9a7a471ccap-1', '0x1.8f834492282d2p-3',
         '0x1.68554febe33a3p-2', '0x1.736fabc8351e5p-1', '0x1.017f6a1314f5ap-3',
         '0x1.a0aa5bc8c3c97p-1', '-0x1.47b6411c06c59p-4', '-0x1.1a2fb3f88dab6p-4',
         '-0x1.2535540c45e02p+0', '-0x1.9562edb8c81bap-4', '0x1.fbd9d91ca8513p-3',
         '-0x1.d2aa98a6a54dep-2', '-0x1.1d2daf67662f3p-3', '-0x1.b9618a1e66800p-5',
         '-0x1.3a1c64aade404p+0', '-0x1.53d047813eea3p-1', '0x1.c56b86aca9198p-1',
         '-0x1.5ddc17fdfb430p-7'])


# -- a disturbance in flight keeps the clock running ----------------------------------

@pytest.mark.parametrize("clock", ["apex", "liftoff"])
@pytest.mark.parametrize("placement", ["apex", "liftoff"])
def test_zero_flight_disturbance_is_the_undisturbed_stride(clock, placement):
    p, s = _STRIDES["tslip local reset"]
    p = dataclasses.replace(p, retraction=clock)
    run = run_disturbed(p, s, "push", [0.0], n_steps=1, placement=placement)
    want = tslip.step(p, s).state
    np.testing.assert_allclose(run.touchdowns[0, 0, :5], want.section(), atol=1e-12)
