"""The exact Jacobian of the power-law leg against an independent stride (issue 39, section 2).

For ``1 < n < 2`` without leg damping or hip torque a stance ends where the spring force
vanishes, and ``dF_s/dl ~ |x|^(n-1)`` is not smooth there. The reference is written here
from the thesis's Appendix A alone: the stance equations ``M qdd = Q - C`` assembled by the
TMT method (eqs A.3-A.14) in scalar arithmetic with a Cramer solve (the package solves
them in closed form through the Schur complement), integrated by scipy's ``solve_ivp``
(DOP853, rtol = atol = 1e-12); lift-off at ``l = l_rest`` for the undamped passive leg,
``F_y = 0`` (eq. 2.6) otherwise, its state from a step that ends at the event (not the
dense output) and its time refined by one Newton step; the leg thrust's switch at the first
``ldot`` crossing upward; the closed-form flight (eq. 2.17 with the conventions' sign) and
the touch-down as the first downward zero of the foot height (eq. 2.9). The Jacobian is
its central differences, step ``1e-5 max(1, |q_j|)``.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import tslip
from tslip.gait.stability import floquet

TOL = 1e-12  # the reference's rtol and atol
EXPONENTS = (0.8, 1.2, 1.5, 1.8, 2.0, 2.5)
X_STAR = 0.15  # k_n = k x*^(1-n): each leg's force at the compression x* is Table 2.1's


def hip_torque(p, ph, phd):
    c = p.controller
    if isinstance(c, tslip.Passive):
        return 0.0
    assert isinstance(c, tslip.GlobalPD)
    return c.Kp * (c.phi_ref - ph) + c.Kd * (c.phid_ref - phd)  # eq. 2.13


def leg_force(p, l, ld, l_rest):
    x = (l_rest - l) / p.l0
    return p.k * p.l0 * math.copysign(abs(x) ** p.leg_exponent, x) - p.c_l * ld


def solve3(M, b):
    """``M^-1 b`` for a 3 x 3 ``M`` by Cramer's rule."""
    def det(A):
        return (A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1])
                - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0])
                + A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]))
    d = det(M)
    return [det([[b[i] if j == c else M[i][j] for j in range(3)] for i in range(3)]) / d
            for c in range(3)]


def stance_rhs(p, l_rest):
    m, J, r, g = p.m, p.J, p.r, p.g

    def f(t, s):
        l, b, ph, ld, bd, phd = s
        sb, cb, sp, cp = math.sin(b), math.cos(b), math.sin(ph), math.cos(ph)
        jx, jy = (-cb, l * sb, r * cp), (sb, l * cb, r * sp)  # rows x_m, y_m of J_T (A.4)
        # M = J_T^T diag(m, m, 0, 0, J) J_T (A.6-A.7)
        M = [[m * (jx[i] * jx[j] + jy[i] * jy[j]) + (J if i == j == 2 else 0.0)
              for j in range(3)] for i in range(3)]
        tau = hip_torque(p, ph, phd)
        fl = leg_force(p, l, ld, l_rest)
        # the x_m, y_m rows of c = (dJ_T/dq qd) qd (A.12)
        cx = 2 * ld * bd * sb + l * cb * bd * bd - r * sp * phd * phd
        cy = 2 * ld * bd * cb - l * sb * bd * bd + r * cp * phd * phd
        # Q = J_T^T (f_g + f_t + f_l) (A.8-A.11), C = J_T^T M_f c (A.13)
        force = (0.0, -m * g, (fl, tau, tau))
        R = [jx[i] * force[0] + jy[i] * force[1] + force[2][i] - m * (jx[i] * cx + jy[i] * cy)
             for i in range(3)]
        return [ld, bd, phd, *solve3(M, R)]  # A.14
    return f


def reference_stride(p, q):
    """The next touch-down section ``(beta, phi, xd, yd, phid)`` from ``q``, flat ground."""
    assert p.leg_reset == "local" and p.retraction == "liftoff" and p.alpha_stop is None
    b, ph, xd, yd, phd = q
    r, l0, g = p.r, p.l0, p.g
    # eq. A.5 at l = l0, solved for (ldot, betadot)
    A = np.array([[-math.cos(b), l0 * math.sin(b)], [math.sin(b), l0 * math.cos(b)]])
    ld, bd = np.linalg.solve(A, [xd - r * math.cos(ph) * phd, yd - r * math.sin(ph) * phd])
    on_spring = p.c_l == 0.0 and isinstance(p.controller, tslip.Passive)
    kw = dict(rtol=TOL, atol=TOL, method="DOP853")

    def liftoff(l_rest):
        def ev(t, s):
            if on_spring:
                return l_rest - s[0]
            l, b_, ph_, ld_, _, phd_ = s
            return (leg_force(p, l, ld_, l_rest) * math.sin(b_)
                    + hip_torque(p, ph_, phd_) / l * math.cos(b_))  # F_y, eq. 2.6
        ev.terminal, ev.direction = True, -1
        return ev

    def switch(t, s):
        return s[3]
    switch.terminal, switch.direction = True, 1
    l_rest = l0
    sol = solve_ivp(stance_rhs(p, l_rest), (0.0, 5.0), [l0, b, ph, ld, bd, phd],
                    events=[liftoff(l_rest)] + ([switch] if p.leg_thrust > 0 else []), **kw)
    if p.leg_thrust > 0:
        assert len(sol.t_events[1]) == 1 and len(sol.t_events[0]) == 0
        l_rest = l0 * (1 + p.leg_thrust)
        sol = solve_ivp(stance_rhs(p, l_rest), (sol.t_events[1][0], 5.0), sol.y_events[1][0],
                        events=[liftoff(l_rest)], **kw)
    assert len(sol.t_events[0]) == 1, "no lift-off"
    t_e, f, g_lo = sol.t_events[0][0], stance_rhs(p, l_rest), liftoff(l_rest)
    s = solve_ivp(f, (sol.t[-2], t_e), sol.y[:, -2], **kw).y[:, -1]
    fs = np.array(f(t_e, s))
    eps = 1e-7
    gdot = (g_lo(t_e, s + eps * fs) - g_lo(t_e, s - eps * fs)) / (2 * eps)
    l, b, ph, ld, bd, phd = s - fs * g_lo(t_e, s) / gdot
    # CoM height and velocity at lift-off over the foot (A.3, A.5)
    y = l * math.sin(b) - r * math.cos(ph)
    xd = -ld * math.cos(b) + l * math.sin(b) * bd + r * math.cos(ph) * phd
    yd = ld * math.sin(b) + l * math.cos(b) * bd + r * math.sin(ph) * phd

    def beta(t):  # the leg reset to alpha_r and retracted at omega_r, relative to the trunk
        return p.alpha_r + p.omega_r * t - (ph + phd * t)

    def foot(t):
        return y + yd * t - g * t * t / 2 + r * np.cos(ph + phd * t) - l0 * np.sin(beta(t))
    ts = np.arange(1, 5001) * 1e-3
    above = foot(ts) > 0
    i = int(np.argmax(above))
    assert above[i], "the foot never clears the ground"
    k = i + int(np.argmax(~above[i:]))
    assert not above[k], "no touch-down"
    t_td = brentq(foot, ts[k - 1], ts[k], xtol=1e-16, rtol=1e-15)
    return np.array([beta(t_td), ph + phd * t_td, xd, yd - g * t_td, phd])


def reference_jacobian(p, q):
    cols = []
    for j in range(5):
        e = np.zeros(5)
        e[j] = 1e-5 * max(1.0, abs(q[j]))
        cols.append((reference_stride(p, q + e) - reference_stride(p, q - e)) / (2 * e[j]))
    return np.array(cols).T


@functools.cache
def gait(controller, damped, n):
    """A gait of the package's own search. Passive and damped: the search solves the leg
    thrust that powers it. Global PD has one unknown fewer than equations (conventions,
    "Poincare section and periodic gaits"): its least-squares near fixed point (residual
    4e-4 to 3e-3), with leg damping powered by the thrust the passive hip's search solves."""
    base = tslip.preset("table2.1" if controller == "passive" else "table2.1-global-pd")
    kw = dict(leg_exponent=n, k=base.k * X_STAR ** (1 - n))
    if damped:
        kw["c_l"] = 0.3
        if controller == "global-pd":
            kw["leg_thrust"] = gait("passive", True, n).params.leg_thrust
    g = tslip.find_gait(dataclasses.replace(base, **kw))
    assert g.converged or (controller == "global-pd" and g.residual < 5e-3), g.residual
    return g


@pytest.mark.parametrize("n", EXPONENTS)
@pytest.mark.parametrize("controller, damped", [
    ("passive", False),  # lift-off at l = l_rest, where the spring force vanishes
    ("passive", True),
    ("global-pd", False),
    ("global-pd", True),
])
def test_jacobian_matches_an_independent_stride(controller, damped, n):
    g = gait(controller, damped, n)
    p, q = g.params, g.state.section()
    J_ref = reference_jacobian(p, q)
    bound = 1e-6 * np.maximum(1.0, np.abs(J_ref))
    fl = floquet(g)
    assert fl.method == ("fd" if n < 1 else "exact")
    assert np.all(np.abs(fl.jacobian - J_ref) <= bound), np.max(np.abs(fl.jacobian - J_ref))
    if n < 1:
        with pytest.raises(ValueError, match=r"< 1 has no exact Jacobian"):
            tslip.step_jacobian(p, q, options=tslip.IntegratorOptions.tight())
        return
    res, J = tslip.step_jacobian(p, q, options=tslip.IntegratorOptions.tight())
    assert res.status == tslip.Status.OK
    assert np.all(np.abs(J - J_ref) <= bound), np.max(np.abs(J - J_ref))
