"""Every rule that decides an apex-map outcome, on both sides, against a flight written here.

The reference: the descent from the apex and the flight after lift-off are
ballistic (eq. 2.7), so their events are the first zeros of closed-form
heights (eq. 2.9's foot height; the hip's), located here by a dense scan
and ``brentq``; the leg angle law is docs/conventions.md's. The stance
between them is scipy's (``ref_stance_end`` of tests/simulation/test_reference.py,
DOP853 at 1e-12, with the touch-down refused when the leg lengthens,
docs/conventions.md "Events") in the registry and for every fifth random
state; for the others, to keep the test short, :func:`tslip.step_batch`'s
(which that reference checks). What is tested is the outcome logic: a fall
of the descent, a fall in stance, a lift-off moving down, a touch-down while
still rising, a fall before the apex.

Two tests: property tests on 4,200 random apex states (fixed seed) of
Table 2.1 (apex-timed retraction; and the global reset with a turning
trunk) and of ``slip``; and a registry of named situations run through
every entry point that classifies them.
"""

import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import brentq

import tslip
from simulation.test_reference import ref_stance_end  # tests/ is on pytest's path
from tslip.gait.section import ApexState, apex_map, apex_map_batch, apex_map_states
from tslip.gait.viability import state_action_map
from tslip.simulation.integrate import step_batch
from tslip.simulation.result import Status

TIGHT = tslip.IntegratorOptions.tight("dop853")
EPS = 1e-9  # a state this close to a status boundary is excluded (and counted)
STANCE_ONLY = {Status.OK, Status.FALL_NO_TOUCHDOWN, Status.FALL_TRIP, Status.FLIGHT_TIMEOUT}


def _leg(p, t, phi0, phid, ta):
    """Leg angle beta(t) in flight, the clock held until ``ta`` (docs/conventions.md)."""
    a = p.alpha_r + p.omega_r * np.maximum(0.0, t - ta)
    return a if p.leg_reset == "global" else a - (phi0 + phid * t)


def flight_event(p, y0, yd0, phi0, phid, ta):
    """First event of a ballistic flight from CoM height ``y0`` (ground at 0), rate ``yd0``.

    ``("td", t)``: the first downward zero of the foot height (eq. 2.9) after
    the foot is above the ground; ``("fall", t)``: the hip reaches the ground
    first. The third value is True within EPS of another outcome.
    """
    g, r, l0 = p.g, p.r, p.l0

    def hip(t):
        return y0 + yd0 * t - 0.5 * g * t * t + r * np.cos(phi0 + phid * t)

    def foot(t):
        return hip(t) - l0 * np.sin(_leg(p, t, phi0, phid, ta))

    t_end = (yd0 + math.sqrt(yd0 * yd0 + 2 * g * (y0 + r + 1.0))) / g  # hip surely down
    ts = np.linspace(0.0, t_end, int(t_end / 1e-3) + 2)
    if ta > 0:
        ts = np.sort(np.append(ts, ta))
    H, F = hip(ts), foot(ts)
    boundary = bool(abs(F[0]) < EPS)
    k = np.flatnonzero(H <= 0.0)[0]
    t_hip = brentq(hip, ts[k - 1], ts[k], xtol=1e-14) if k > 0 else 0.0
    t_td = math.inf
    above = np.flatnonzero(F > 0.0)
    if above.size:
        k0 = above[0]
        down = np.flatnonzero((F[k0:-1] > 0.0) & (F[k0 + 1:] <= 0.0))
        if down.size:
            k = k0 + down[0]
            t_td = brentq(foot, ts[k], ts[k + 1], xtol=1e-14)
            rate = (foot(t_td + 1e-7) - foot(t_td - 1e-7)) / 2e-7
            boundary |= abs(rate) < 1e-6  # grazing
    boundary |= abs(t_td - t_hip) < EPS
    return ("fall", t_hip, boundary) if t_hip <= t_td else ("td", t_td, boundary)


def scipy_stance(p, td):
    """(status, lift-off ``(y, xd, yd, phi, phid)``) of the stance from ``td`` by scipy.

    ``(None, None)`` when two stance events tie (the reference refuses to choose)
    or the stance ends at once.
    """
    beta, phi, xd, yd, phid = td[:5]
    # the hip's speed along the leg, foot to hip (eq. A.5): a lengthening leg cannot push
    ld = ((xd - p.r * phid * math.cos(phi)) * -math.cos(beta)
          + (yd - p.r * phid * math.sin(phi)) * math.sin(beta))
    if ld > 0.0:
        return Status.FALL_LENGTHENING, None
    try:
        kind, t_end, s_end, _, _ = ref_stance_end(p, tslip.TouchdownState(*td))
    except AssertionError as exc:  # two events within 1e-6 of each other: a boundary
        assert "tie of events" in str(exc)
        return None, None
    if t_end < EPS:  # F_y starts at 0 (l = l0): scipy saw it fall at once, a boundary
        return None, None
    if kind != "liftoff":
        return {"hip_ground": Status.FALL_HIP_GROUND, "backward": Status.FALL_BACKWARD}[kind], None
    x, y, ph, u, v, w = s_end
    return Status.OK, (y, u, v, ph, w)


def kernel_stance(p, td):
    """As :func:`scipy_stance`, by :func:`tslip.step_batch` (its flight's outcome ignored)."""
    s = step_batch(p, np.array([td]), options=TIGHT)
    stance = Status(int(s.status[0]))
    if stance not in STANCE_ONLY:
        return stance, None
    _, y, xd, yd, phi, phid = s.raw[0, 9:15]
    return Status.OK, (y, xd, yd, phi, phid)


def ref_apex_map(p, apex, stance=scipy_stance):
    """Reference outcome of one apex ``(y, xd, phi, phid)``: (status, next apex, boundary, how).

    ``how`` names the rule that decided: "descent fall", "stance", "lift-off down",
    "touch-down while rising", "fall before the apex", "apex".
    """
    y, xd, phi, phid = apex
    kind, t, b = flight_event(p, y, 0.0, phi, phid, 0.0)  # the clock starts at the apex
    if kind == "fall":
        return Status.FALL_NO_TOUCHDOWN, None, b, "descent fall"
    td = (_leg(p, t, phi, phid, 0.0), phi + phid * t, xd, -p.g * t, phid, xd * t, 0.0)
    status, lo = stance(p, td)
    if status is None:
        return None, None, True, "stance tie"
    if status != Status.OK:
        return status, None, b, "stance"
    y_lo, xd_lo, yd_lo, phi_lo, phid_lo = lo
    if abs(yd_lo) < EPS:
        return None, None, True, "lift-off level"
    if yd_lo < 0.0:
        return Status.NO_APEX, None, b, "lift-off down"
    t_up = yd_lo / p.g
    ta = t_up if p.retraction == "apex" else 0.0
    kind, t, b2 = flight_event(p, y_lo, yd_lo, phi_lo, phid_lo, ta)
    b = b or b2 or abs(t - t_up) < EPS
    if t < t_up:
        if kind == "fall":
            return Status.FALL_NO_TOUCHDOWN, None, b, "fall before the apex"
        return Status.NO_APEX, None, b, "touch-down while rising"
    nxt = (y_lo + 0.5 * yd_lo * t_up, xd_lo, phi_lo + phid_lo * t_up, phid_lo)
    return Status.OK, np.array(nxt), b, "apex"


def _sets():
    t21 = tslip.preset("table2.1")
    return {"table2.1": dataclasses.replace(t21, retraction="apex"),  # retracting from the apex
            "table2.1-global": dataclasses.replace(t21, leg_reset="global", omega_r=0.0),
            "slip": tslip.preset("slip")}


@pytest.mark.parametrize("name", list(_sets()))
def test_apex_map_status_of_random_states_equals_the_reference(name):
    p = _sets()[name]
    rng = np.random.default_rng(23)
    n = 1400  # x 3 sets: 4,200 states
    if name == "slip":
        A = np.column_stack([rng.uniform(0.8, 1.6, n), rng.uniform(0.2, 3.0, n),
                             np.zeros(n), np.zeros(n)])
        alpha = rng.uniform(0.9, 1.5, n)
    else:
        A = np.column_stack([rng.uniform(0.4, 1.5, n), rng.uniform(1.0, 7.0, n),
                             rng.uniform(-0.6, 0.6, n), rng.uniform(-4.0, 4.0, n)])
        alpha = rng.uniform(0.8, 1.4, n)
    b = apex_map_states(p, A, alpha, options=TIGHT)
    got = np.column_stack([b.y, b.xd, b.phi, b.phid])
    excluded, how = 0, {}
    for i in range(n):
        stance = scipy_stance if i % 5 == 0 else kernel_stance
        status, nxt, boundary, rule = ref_apex_map(dataclasses.replace(p, alpha_r=alpha[i]), A[i],
                                                   stance)
        if boundary:
            excluded += 1
            continue
        how[rule] = how.get(rule, 0) + 1
        assert b.status[i] == status, (i, A[i], alpha[i], rule, Status(int(b.status[i])))
        if status == Status.OK:
            np.testing.assert_allclose(got[i], nxt, rtol=0, atol=1e-8, err_msg=str(i))
    print(f"{name}: {n} states, {excluded} excluded (within {EPS:g} of a boundary); {how}")
    assert excluded <= n // 100, excluded
    # every rule is exercised (the SLIP's stance is point-mass: no turning trunk to trip on)
    rules = {"descent fall", "stance", "lift-off down", "apex"}
    if name != "slip":
        rules.add("touch-down while rising")
    if name == "table2.1":
        rules.add("fall before the apex")
    assert rules <= set(how), how


# --- the registry: situation -> how to build it -> expected status ----------------------------

def _state(name, y, xd, phi, phid, alpha_r):
    return dataclasses.replace(_sets()[name], alpha_r=alpha_r), (y, xd, phi, phid)


SITUATIONS = {
    "an apex": (lambda: _state("slip", 1.46, 3.2, 0.0, 0.0, 0.91), Status.OK),
    "an apex below the touch-down height": (lambda: _state("slip", 0.9, 2.0, 0.0, 0.0, 1.2),
                                            Status.FALL_NO_TOUCHDOWN),
    "a stance falling backward": (lambda: _state("slip", 1.37, 1.2, 0.0, 0.0, 0.83),
                                  Status.FALL_BACKWARD),
    "a lift-off moving down": (lambda: _state("slip", 1.31, 7.0, 0.0, 0.0, 1.09),
                               Status.NO_APEX),
    "a touch-down while rising": (lambda: _state("table2.1-global", 1.4, 3.2, 0.0, 0.8, 0.92),
                                  Status.NO_APEX),
    "a flight fall before the apex": (lambda: _state("table2.1", 1.11, 4.9, 0.0, -3.0, 1.37),
                                      Status.FALL_NO_TOUCHDOWN),
    "a turning trunk under the global reset": (
        lambda: _state("table2.1-global", 1.41, 2.8, 0.0, -1.8, 0.83), Status.OK),
}


def _entry_points(p, a):
    """The status of the apex ``a`` from each entry point that classifies it."""
    y, xd, phi, phid = a
    E = 0.5 * p.m * xd**2 + 0.5 * p.J * phid**2 + p.m * p.g * y
    single = apex_map(p, ApexState(y, xd, phi, phid), options=TIGHT)
    rows = apex_map_states(p, np.array([a]), np.array([p.alpha_r]), options=TIGHT)
    energy = apex_map_batch(p, y, p.alpha_r, energy=E, phi=phi, phid=phid, options=TIGHT)
    assert phi == 0.0  # a state-action grid spans two apex variables: here y and phid
    sam = state_action_map(p, {"y": [y], "phid": [phid]},
                           ("alpha_r", [p.alpha_r]), energy=E, options=TIGHT)
    return {"apex_map": single.status, "apex_map_states": Status(int(rows.status[0])),
            "apex_map_batch": Status(int(energy.status)),
            "state_action_map": Status(int(sam.status.ravel()[0]))}, single


@pytest.mark.parametrize("situation", list(SITUATIONS))
def test_each_situation_through_every_entry_point(situation):
    build, expected = SITUATIONS[situation]
    p, a = build()
    status, nxt, boundary, _ = ref_apex_map(p, a)
    assert not boundary and status == expected  # the registry agrees with the reference
    statuses, single = _entry_points(p, a)
    assert statuses == dict.fromkeys(statuses, expected)
    if expected == Status.OK:
        np.testing.assert_allclose(single.apex.section(), nxt, rtol=0, atol=1e-9)
        # the descent: the touch-down is at the reference's first zero of eq. 2.9
        kind, t_down, _ = flight_event(p, a[0], 0.0, a[2], a[3], 0.0)
        assert kind == "td"
        assert single.touchdown.yd == pytest.approx(-p.g * t_down, abs=1e-10)
