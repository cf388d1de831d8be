"""The shared Runge-Kutta core (tslip.simulation._rk): orders, events, and both pairs on the models.

Orders are measured on the harmonic oscillator ``y = (cos t, -sin t)``; the
tableaus are also checked against scipy's independent copy of the same pairs.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate._ivp import dop853_coefficients as scipy853
from scipy.integrate._ivp.rk import RK45

import tslip
from tslip.biped import BipedOptions, BipedParams, BipedState
from tslip.biped import _kernels as bkn
from tslip.biped import _pack as bpk
from tslip.model import _pack as pk
from tslip.simulation import _rk
from tslip.simulation import _variational as va

from .test_reference import ref_stride

METHODS = {"dopri5": pk.M_DOPRI5, "dop853": pk.M_DOP853}


def f_osc(y, out):
    out[0] = y[1]
    out[1] = -y[0]


def exact(t):
    return np.array([math.cos(t), -math.sin(t)])


def rk_step(m, y, h, K):
    """The stage loop every model writes (see the _rk docstring), for the oscillator."""
    ytmp = np.empty(2)
    ynew = np.empty(2)
    ns = _rk.n_stages(m)
    f_osc(y, K[0])
    for s in range(1, ns):
        _rk.stage_state(m, 2, y, h, K, s, ytmp)
        f_osc(ytmp, K[s])
    _rk.stage_state(m, 2, y, h, K, ns, ynew)
    f_osc(ynew, K[ns])
    return ynew


def dense(m, y, ynew, h, K):
    ns = _rk.n_stages(m)
    ytmp = np.empty(2)
    for s in range(ns + 1, ns + 1 + _rk.n_extra(m)):
        _rk.stage_state(m, 2, y, h, K, s, ytmp)
        f_osc(ytmp, K[s])
    R = np.empty((_rk.NR, 2))
    _rk.dense_coeffs(m, y, ynew, h, K, R)
    return R


def slope(hs, errs):
    return np.polyfit(np.log(hs), np.log(errs), 1)[0]


def test_tableaus_match_scipy():
    """Our copies of the coefficients equal scipy's (RK45 and DOP853)."""
    m = pk.M_DOPRI5
    np.testing.assert_array_equal(_rk.C_TAB[m, :7], RK45.C.tolist() + [1.0])
    np.testing.assert_allclose(_rk.A_TAB[m, :6, :5], RK45.A, rtol=1e-15, atol=0)
    np.testing.assert_allclose(_rk.A_TAB[m, 6, :6], RK45.B, rtol=1e-15, atol=0)
    np.testing.assert_allclose(_rk.E_TAB[m, :7], -RK45.E, rtol=1e-15, atol=0)
    m = pk.M_DOP853
    np.testing.assert_array_equal(_rk.C_TAB[m], scipy853.C)
    np.testing.assert_array_equal(_rk.A_TAB[m], scipy853.A)
    np.testing.assert_array_equal(_rk.E_TAB[m, :13], scipy853.E5)
    np.testing.assert_array_equal(_rk.E3_TAB[m, :13], scipy853.E3)
    np.testing.assert_array_equal(_rk.D_TAB[m], scipy853.D)


@pytest.mark.parametrize(("name", "order", "ns"), [("dopri5", 5, (16, 32, 64)),
                                                   ("dop853", 8, (4, 6, 8))])
def test_global_convergence_order(name, order, ns):
    """Fixed steps to t = 2: the global error falls like h^p."""
    m = METHODS[name]
    K = np.empty((_rk.NK, 2))
    hs, errs = [], []
    for n in ns:
        h = 2.0 / n
        y = exact(0.0)
        for _ in range(n):
            y = rk_step(m, y, h, K)
        hs.append(h)
        errs.append(np.abs(y - exact(2.0)).max())
    assert slope(hs, errs) == pytest.approx(order, abs=0.3)


@pytest.mark.parametrize(("name", "order", "hs"), [("dopri5", 5, (0.4, 0.2, 0.1)),
                                                   ("dop853", 8, (0.8, 0.4, 0.2))])
def test_error_estimate_and_dense_output_orders(name, order, hs):
    """One step of size h: the error estimate falls like h^p (dopri5: the local
    error h^5 of the 4th-order solution; dop853: h err5^2 / sqrt(err5^2 +
    err3^2 / 100) with err5 ~ h^5, err3 ~ h^3, so h^8), and so does the error
    of the dense output at mid-step (local error of orders 4 and 7)."""
    m = METHODS[name]
    K = np.empty((_rk.NK, 2))
    est, mid = [], []
    y0 = exact(0.3)
    for h in hs:
        y1 = rk_step(m, y0, h, K)
        est.append(_rk.error_norm(m, 2, y0, y1, h, K, 0.0, 1.0))
        R = dense(m, y0, y1, h, K)
        out = np.empty(2)
        _rk.dense_eval(m, R, 0.5, out)
        mid.append(np.abs(out - exact(0.3 + 0.5 * h)).max())
        _rk.dense_eval(m, R, 1.0, out)
        np.testing.assert_allclose(out, y1, rtol=0, atol=1e-15)
    assert slope(hs, est) == pytest.approx(order, abs=0.3)
    assert slope(hs, mid) == pytest.approx(order, abs=0.3)


@pytest.mark.parametrize("name", ["dopri5", "dop853"])
def test_event_located_on_dense_output(name):
    """Adaptive steps at tolerance 1e-12 and the Illinois root of y0 = cos t on
    the dense output: the first zero is pi/2 to 1e-12."""
    m = METHODS[name]
    K = np.empty((_rk.NK, 2))
    st = np.empty(5)
    out = np.empty(2)
    tol = 1e-12
    t, y, h = 0.0, exact(0.0), 0.05
    for _ in range(10_000):
        y1 = rk_step(m, y, h, K)
        err = _rk.error_norm(m, 2, y, y1, h, K, tol, tol)
        if err > 1.0:
            h *= _rk.step_factor(m, err, 10.0)
            continue
        if y[0] > 0.0 >= y1[0]:
            R = dense(m, y, y1, h, K)
            _rk.root_start(st, y[0], y1[0])
            for _ in range(100):
                c = _rk.root_guess(st)
                _rk.dense_eval(m, R, c, out)
                if _rk.root_update(st, c, out[0], 1e-15):
                    break
            t_ev = t + st[1] * h
            break
        t, y = t + h, y1
        h *= _rk.step_factor(m, err, 10.0)
    assert abs(t_ev - math.pi / 2) < 1e-12


def test_initial_step_scales_with_the_order():
    """HNW's starting step (0.01 / |f'|)^(1/p): larger for the 8th-order pair."""
    y = np.array([1.0, 0.0])
    f0 = np.empty(2)
    f_osc(y, f0)
    ytmp = np.empty(2)
    h0, d1 = _rk.initial_probe(y, f0, 1e-6, 1e-6, ytmp)
    f1 = np.empty(2)
    f_osc(ytmp, f1)
    h5 = _rk.initial_step(pk.M_DOPRI5, y, f0, f1, h0, d1, 1e-6, 1e-6)
    h8 = _rk.initial_step(pk.M_DOP853, y, f0, f1, h0, d1, 1e-6, 1e-6)
    dm = max(d1, np.sqrt(np.mean(((f1 - f0) / (1e-6 + 1e-6 * np.abs(y))) ** 2)) / h0)
    assert h5 == pytest.approx(min(100 * h0, (0.01 / dm) ** 0.2), rel=1e-12)
    assert h8 == pytest.approx(min(100 * h0, (0.01 / dm) ** 0.125), rel=1e-12)


def test_method_is_validated():
    with pytest.raises(ValueError, match="IntegratorOptions.method must be one of"):
        tslip.IntegratorOptions(method="rk4")
    o = tslip.IntegratorOptions(method="dop853").packed()
    assert o[pk.O_METHOD] == pk.M_DOP853


@pytest.fixture(scope="module")
def gait():
    return tslip.find_gait(tslip.preset("table6.1"))


def test_stride_agrees_between_methods_and_with_reference(gait):
    """At tolerance 1e-12 both pairs give the stride of an independent
    Newton-Euler model integrated by scipy's DOP853 (test_reference.py)."""
    ref = ref_stride(gait.params, gait.state)
    res = {}
    for name in METHODS:
        o = tslip.IntegratorOptions(rtol=1e-12, atol=1e-12, method=name)
        r = tslip.step(gait.params, gait.state, options=o)
        res[name] = r
        np.testing.assert_allclose(r.state.section(), ref.q, rtol=0, atol=1e-9)
        assert r.stance_time == pytest.approx(ref.stance_time, abs=1e-10)
    np.testing.assert_allclose(res["dop853"].state.section(), res["dopri5"].state.section(),
                               rtol=0, atol=1e-10)
    # the 8th-order pair takes several times fewer steps at this tolerance
    assert res["dop853"].n_integrator_steps * 3 < res["dopri5"].n_integrator_steps


def test_stride_jacobian_agrees_between_methods(gait):
    """The variational equations replayed with either pair give the same Jacobian."""
    P = pk.pack_params(gait.params)
    td = gait.state.as_array()
    J = {}
    for name in METHODS:
        O = tslip.IntegratorOptions(rtol=1e-12, atol=1e-12, method=name).packed()
        Jq = np.empty((5, 5))
        st = va.stride_jacobian(P, O, td, np.empty(0), np.zeros(1), Jq, np.empty(pk.NOUT))
        assert st == pk.ST_OK
        J[name] = Jq
    np.testing.assert_allclose(J["dop853"], J["dopri5"], rtol=0, atol=1e-8)


def test_biped_stride_agrees_between_methods():
    """The biped's first stride from the Table E.2 start, with each pair at 1e-10."""
    p = BipedParams()
    y0 = BipedState.thesis().to_array()
    P = bpk.pack_params(p)
    ends = {}
    for name, m in METHODS.items():
        O = BipedOptions(rtol=1e-10, atol=1e-10).pack()
        O[bpk.O_METHOD] = m
        cs = np.zeros(bpk.NCS)
        bkn.init_contact(P, y0, cs)
        strides = np.empty((1, bpk.NSTRIDE))
        stats = np.zeros(bpk.NSTATS)
        st = bkn.run(P, O, 0.0, y0, cs, 1, np.empty((0, bpk.NREC)), np.empty((16, bpk.NEV)),
                     strides, np.empty(18), np.empty(bpk.NCS), stats)
        assert st == bpk.ST_OK
        ends[name] = strides[0, :19].copy()
    np.testing.assert_allclose(ends["dop853"], ends["dopri5"], rtol=0, atol=1e-7)
