"""Discontinuities of the biped's right-hand side are events (issue 12, item 7).

The controller switches branch at phases d and 1 (eqs E.29-E.30: the thigh
velocity reference jumps there) and the ground law at touch-down and lift-off
(eqs E.23-E.24). The kernel locates each switch and restarts the integration
there, so the stride map converges as the tolerance tightens and agrees with
an independent integration (scipy's DOP853 with its own event finder) run
piecewise between the same kinds of events.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from tslip.biped import BipedOptions, BipedParams, BipedState, simulate, step
from tslip.biped import _kernels as kn
from tslip.biped import _pack as pk
from tslip.biped.dynamics import mass_matrix
from tslip.biped.simulate import to_status
from tslip.sweeps.appendix_e import table_e2_perturbations

from ._foot import foot


def _opts(tol, method="dopri5"):
    return BipedOptions(rtol=tol, atol=tol, method=method)


def _scipy_stride(p, y0, tol):
    """One stride, right touch-down to right touch-down, with solve_ivp(DOP853).

    The kernel's right-hand side, but the discrete state (contact flags and
    anchors, controller branch and cycle) is switched here, at events located
    by solve_ivp itself: the foot height / ground force of each leg and the
    controller's switch times ``(n + d or 1 - rho0 - leg/2) T`` (eqs E.25-E.27).
    """
    P = pk.pack_params(p)
    cs = np.zeros(pk.NCS)
    kn.init_contact(P, y0, cs)
    branch = [0, 0]
    cycle = [0.0, 0.0]
    for leg in range(2):  # phase at t = 0, the right limit at a switch
        s = p.rho0 + 0.5 * leg
        cycle[leg] = np.floor(s + 1e-12)
        branch[leg] = int(s - cycle[leg] >= p.d - 1e-12)
    ws = kn._make_ws()
    aux = np.empty(10)

    def ctl():
        return np.array([branch[0], cycle[0], branch[1], cycle[1]], dtype=float)

    def f(t, y):
        out = np.empty(18)
        kn.rhs(P, t, y, cs, ctl(), False, out, ws, aux)
        return out

    def foot_z(y, leg):
        return foot(p, y, leg)

    def contact(leg):
        def g(t, y):
            z, zd = foot_z(y, leg)
            if cs[pk.CS_ON_R + leg] == 0.0:
                return z
            return min(p.k_z * (0.0 - z) - p.c_z * zd, p.k_z * (0.0 - z))
        g.terminal, g.direction = True, -1
        return g

    def switch(leg):
        def g(t, y):
            end = 1.0 if branch[leg] else p.d
            return (cycle[leg] + end - p.rho0 - 0.5 * leg) * p.T - t
        g.terminal, g.direction = True, -1
        return g

    events = [contact(0), contact(1), switch(0), switch(1)]
    t, y = 0.0, y0.copy()
    log = []
    while True:
        sol = solve_ivp(f, (t, t + 3.0), y, method="DOP853", rtol=tol, atol=tol, events=events)
        t, k = min((te[0], k) for k, te in enumerate(sol.t_events) if len(te))
        y = sol.y_events[k][0].copy()
        if k >= 2:
            leg = k - 2
            cycle[leg] += branch[leg]
            branch[leg] = 1 - branch[leg]
            continue
        if cs[pk.CS_ON_R + k] == 0.0:
            gam = y[2] + y[5 + 3 * k]
            x = y[0] + p.r_1 * np.sin(y[2]) - (y[3 + 3 * k] + y[4 + 3 * k]) * np.sin(gam)
            cs[pk.CS_ON_R + k], cs[pk.CS_XR + 2 * k], cs[pk.CS_ZR + 2 * k] = 1.0, x, 0.0
            log.append((t, f"touchdown_{'RL'[k]}"))
            if k == 0:
                return t, y, log
        else:
            cs[pk.CS_ON_R + k] = 0.0
            log.append((t, f"liftoff_{'RL'[k]}"))


def test_the_stride_map_converges_as_the_tolerance_tightens():
    p = BipedParams()
    y0 = BipedState.thesis().to_array()
    res = [step(p, y0, 0.0, options=_opts(tol)) for tol in (1e-8, 1e-10, 1e-12)]
    assert all(r.status.name == "OK" for r in res)
    end = [np.r_[r.t, r.state] for r in res]
    d1 = np.abs(end[1] - end[0]).max()
    d2 = np.abs(end[2] - end[1]).max()
    assert d2 < 0.1 * d1, (d1, d2)
    assert d1 < 1e-6


def test_the_stride_at_1e12_agrees_with_scipy_dop853_between_the_same_events():
    p = BipedParams()
    y0 = BipedState.thesis().to_array()
    t_ref, y_ref, log = _scipy_stride(p, y0, 1e-12)
    for method in ("dopri5", "dop853"):
        tr = simulate(p, y0, 1, options=_opts(1e-12, method))
        assert [e.kind for e in tr.events] == [k for _, k in log]
        np.testing.assert_allclose([e.t for e in tr.events], [t for t, _ in log], rtol=0,
                                   atol=1e-11)
        assert tr.strides[0, 0] == pytest.approx(t_ref, abs=1e-11)
        np.testing.assert_allclose(tr.strides[0, 1:19], y_ref, rtol=0, atol=5e-11)


def test_the_integration_restarts_at_every_controller_switch():
    """Each leg's switch times (phase d and 1, eqs E.25-E.27) are recorded rows."""
    p = BipedParams()
    tr = simulate(p, BipedState.thesis(), 2)
    t = tr.time
    for leg in range(2):
        n = np.arange(-1, 4)
        for end in (p.d, 1.0):
            tb = (n + end - p.rho0 - 0.5 * leg) * p.T
            tb = tb[(tb > t[0] + 1e-9) & (tb < t[-1])]
            assert tb.size >= 1
            gap = np.abs(t[None, :] - tb[:, None]).min(axis=1)
            assert gap.max() < 1e-12, (leg, end, gap)


def test_a_fall_stops_at_the_located_fall_and_does_not_grind():
    """A perturbed Table E.2 start falls; the run ends where a fall margin is zero.

    Before events located the lift-offs, such a run took 180,000 rejected
    steps to 75,000 accepted ones (a clamped ground force jumps at lift-off).
    """
    p = BipedParams()
    tr = simulate(p, table_e2_perturbations(0)[0], 20)
    assert tr.fell
    g, kind = kn.fall_value(pk.pack_params(p), tr.final_state)
    assert to_status(kind) == tr.status  # the kernel's code, translated to the shared enum
    assert abs(g) < 1e-9
    assert tr.stats["rejected"] < 0.02 * tr.stats["accepted"]


def test_block_solve_equals_a_dense_solve():
    p = BipedParams(r_2=0.35, J_s=0.004)
    P = pk.pack_params(p)
    rng = np.random.default_rng(3)
    for _ in range(10):
        q = np.array([0.3, 0.6, 0.4, 0.7, 0.3, -0.5, 0.5, 0.25, 0.8]) + rng.uniform(-0.2, 0.2, 9)
        qd = rng.uniform(-3.0, 3.0, 9)
        blk, h, x = np.empty(kn.NBLK), np.empty(9), np.empty(9)
        kn.tmt_blocks(P, q, qd, blk, h, np.empty(6))
        b = rng.normal(size=9)
        assert kn.block_solve(blk, b, x, np.empty((3, 3)), np.empty((2, 3, 3)))
        np.testing.assert_allclose(x, np.linalg.solve(mass_matrix(p, q), b), rtol=1e-10,
                                   atol=1e-12)


def test_method_field():
    p = BipedParams()
    y0 = BipedState.thesis().to_array()
    a = step(p, y0, 0.0, options=_opts(1e-12, "dop853"))
    b = step(p, y0, 0.0, options=_opts(1e-12, "dopri5"))
    assert a.accepted < 0.5 * b.accepted  # the 8th-order pair takes fewer steps
    np.testing.assert_allclose(np.r_[a.t, a.state], np.r_[b.t, b.state], rtol=0, atol=1e-9)
    with pytest.raises(ValueError, match="BipedOptions.method must be one of dopri5, dop853"):
        BipedOptions(method="rk4")
    with pytest.raises(ValueError, match="BipedOptions.max_steps"):
        BipedOptions(max_steps=2.5)


def test_a_touch_down_anchors_the_foot_on_the_ground_and_a_lift_off_releases_it():
    """The contact switch of the stride loop (eqs E.23-E.24: displacements from the
    touch-down position, ``z_f,TD = 0`` on the ground); the foot's ``x_f`` is eq. E.8
    written out here."""
    p = BipedParams()
    P = pk.pack_params(p)
    y = BipedState.thesis().to_array()
    trig = np.empty(6)
    kn.state_trig(y, trig)
    for leg in range(2):
        gam = y[2] + y[5 + 3 * leg]
        x = y[0] + p.r_1 * np.sin(y[2]) - (y[3 + 3 * leg] + y[4 + 3 * leg]) * np.sin(gam)
        z, _ = foot(p, y, leg)
        cs = np.array([0.0, 0.0, 7.0, 7.0, 7.0, 7.0])
        kind, xf, zf = kn.contact_switch(P, y, cs, leg, trig)
        assert kind == pk.EV_TD_R + leg
        assert (xf, zf) == pytest.approx((x, z), abs=1e-14)
        assert cs[pk.CS_ON_R + leg] == 1.0 and cs[pk.CS_ON_R + 1 - leg] == 0.0
        assert cs[pk.CS_XR + 2 * leg] == pytest.approx(x, abs=1e-14)
        assert cs[pk.CS_ZR + 2 * leg] == 0.0
        assert cs[pk.CS_XR + 2 - 2 * leg] == 7.0  # the other leg's anchor untouched
        kind, _, _ = kn.contact_switch(P, y, cs, leg, trig)
        assert kind == pk.EV_LO_R + leg
        assert cs[pk.CS_ON_R + leg] == 0.0



def _flight_rhs(P, cs, ctl):
    ws, aux = kn._make_ws(), np.empty(10)

    def f(t, y):
        out = np.empty(18)
        kn.rhs(P, t, y, cs, ctl, False, out, ws, aux)
        return out
    return f


def test_the_first_event_of_a_step_with_two_crossings_is_the_earlier_one():
    """Event detection in one DOP853 step in which both feet, in flight, cross the
    ground: the left one first (its leg swinging back, 0.6 -> 0.3 rad), the right
    one 0.04 of the step later.

    The dense output's extra stages (dop853) call the right-hand side, which keeps
    its state's sines and cosines in ``ws[5]``, where the switching functions at the
    step's end read them. Those must be the feet's heights at the step's end
    (eq. E.8, written out in ``_foot``), and the event the left touch-down at the
    left foot's crossing, as scipy's DOP853 at 1e-12 with its own event finder
    locates it on the same right-hand side.
    """
    from tslip.biped import _stride
    from tslip.model._pack import M_DOP853

    p = BipedParams(actuated=False)
    P = pk.pack_params(p)
    cs = np.zeros(pk.NCS)  # both feet in flight
    ctl = np.empty(4)
    kn.init_ctl(P, 0.0, ctl)
    y = BipedState.thesis().to_array()
    y[1], y[2], y[5], y[8] = 0.4048, 0.0, -0.8572, 0.6
    y[9:] = 0.0
    y[10], y[17] = -1.0, -6.0  # the hip sinks, the left leg swings back
    h = 0.05
    ws, aux = kn._make_ws(), np.empty(10)
    K, ynew = np.zeros((16, 18)), np.empty(18)
    kn.rhs(P, 0.0, y, cs, ctl, False, K[0], ws, aux)
    _stride.rk_step(P, M_DOP853, 0.0, y, h, K, np.empty(18), ynew, cs, ctl, ws, aux)

    def touch_down(leg):
        def g(t, y):
            return foot(p, y, leg)[0]
        g.direction = -1
        return g

    ref = solve_ivp(_flight_rhs(P, cs, ctl), (0.0, h), y, method="DOP853", rtol=1e-12,
                    atol=1e-12, events=[touch_down(0), touch_down(1)])
    t_r, t_l = ref.t_events[0][0], ref.t_events[1][0]
    assert t_l < t_r - 0.02 * h

    g_old = np.array([foot(p, y, 0)[0], foot(p, y, 1)[0], 1.0, 1.0, 1.0])
    g_new = np.full(5, np.nan)
    active = np.array([True, True, False, False, False])
    _stride._end_values(P, 0.0, ynew, h, cs, np.full(2, np.inf), active, g_new, ws)
    k, theta, nfev = _stride._first_event(
        M_DOP853, P, 0.0, y, ynew, h, K, np.empty((8, 18)), cs, ctl, np.full(2, np.inf),
        active, g_old, g_new, np.empty(18), np.empty(6), np.empty(5), ws, aux)
    assert (k, nfev) == (1, 3)
    assert theta * h == pytest.approx(t_l, abs=1e-6)  # one step of 0.05: 9e-8 off scipy's
    for leg in range(2):
        assert g_new[leg] == pytest.approx(foot(p, ynew, leg)[0], abs=1e-14)


def test_a_contact_shorter_than_the_step_after_its_touch_down_is_not_lost():
    """A foot whose swing dips 1e-4 L below the ground: its contact lasts 1.4e-5, far
    shorter than the step after the touch-down. The foot's lift-off function
    ``min(F_z, k_z (z_TD - z_f))`` starts the contact a few ulps from 0 (the touch-down is
    located to 1e-13 in time), so a step that jumps the whole contact ended it at the
    touch-down itself (2e-17 later). The kernel retries such a first step shorter
    (``_stride._jumped_hump``); scipy's DOP853, with a first step of 1e-10 and steps below a
    tenth of the contact, switching the contact at its own events, gives the same lift-off.
    (A shallower dip is a graze of the flight's touch-down function inside one step, which
    no step-end test sees, at 1e-8 or with dop853: a different matter.)"""
    from scipy.optimize import minimize_scalar

    p = BipedParams(actuated=False)
    P = pk.pack_params(p)
    y = BipedState.thesis().to_array()
    y[1], y[2], y[5], y[8] = 0.4048, 0.0, -0.8572, 0.3
    y[9:] = 0.0
    y[17] = -15.0  # the left leg swings back through its lowest point
    cs = np.zeros(pk.NCS)
    ctl = np.empty(4)
    kn.init_ctl(P, 0.0, ctl)
    f = _flight_rhs(P, cs, ctl)
    sol = solve_ivp(f, (0.0, 0.1), y, method="DOP853", rtol=1e-13, atol=1e-13,
                    dense_output=True, max_step=1e-3)
    low = minimize_scalar(lambda t: foot(p, sol.sol(t), 1)[0], bounds=(0.05, 0.09),
                          method="bounded", options=dict(xatol=1e-12))
    y[1] += -low.fun - 1e-4  # the lowest point 1e-4 below the ground (flight is uniform in z)
    assert foot(p, y, 0)[0] > 0.05  # the right foot stays in the air

    def touch_down(t, yy):
        return foot(p, yy, 1)[0]

    def lift_off(t, yy):
        z, zd = foot(p, yy, 1)
        return min(p.k_z * (0.0 - z) - p.c_z * zd, p.k_z * (0.0 - z))

    touch_down.terminal, touch_down.direction = True, -1
    lift_off.terminal, lift_off.direction = True, -1
    a = solve_ivp(f, (0.0, 0.1), y, method="DOP853", rtol=1e-12, atol=1e-12,
                  events=touch_down)
    t_td, y_td = float(a.t_events[0][0]), a.y_events[0][0]
    gam = y_td[2] + y_td[8]
    cs[pk.CS_ON_R + 1] = 1.0
    cs[pk.CS_XR + 2] = y_td[0] + p.r_1 * np.sin(y_td[2]) - (y_td[6] + y_td[7]) * np.sin(gam)
    cs[pk.CS_ZR + 2] = 0.0
    b = solve_ivp(f, (t_td, t_td + 1e-3), y_td, method="DOP853", rtol=1e-12, atol=1e-12,
                  events=lift_off, first_step=1e-10, max_step=1e-6)
    t_lo = float(b.t_events[0][0])
    assert 1e-5 < t_lo - t_td < 2e-5
    for method, tol in (("dopri5", 1e-12), ("dop853", 1e-12), ("dopri5", 1e-8)):
        opts = BipedOptions(rtol=tol, atol=tol, method=method, check_falls=False)
        ev = [(e.kind, e.t) for e in simulate(p, y, 1, options=opts).events]
        assert [k for k, _ in ev[:2]] == ["touchdown_L", "liftoff_L"], (method, tol)
        assert ev[0][1] == pytest.approx(t_td, abs=100 * tol)
        assert ev[1][1] == pytest.approx(t_lo, abs=100 * tol)
