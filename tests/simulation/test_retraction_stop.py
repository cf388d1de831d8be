"""The retraction stop angle: ``Params(alpha_stop=angle)`` (thesis Section 7.5).

The rule (docs/conventions.md, "Frames and angles"): in the frame of ``alpha_r``
(the hip angle for the local reset, the global leg angle for the global one),
``alpha(t) = min(alpha_r + omega_r max(0, t - t_c), max(alpha_r, alpha_stop))``
for ``omega_r > 0`` and the mirror for ``omega_r < 0``, ``t_c`` the retraction
clock's start. The reference here is written in this file (the leg rule, the
ballistic flight with its touch-down found by a grid and brentq) on the
Newton-Euler stance of ``test_reference`` (scipy's DOP853 at 1e-11).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import brentq

import tslip
from tslip.gait.continuation import set_param
from tslip.gait.robustness import robustness, run_disturbed
from tslip.gait.stability import map_jacobian
from tslip.model import _pack as pk
from tslip.model.dynamics import swing_angle
from tslip.simulation import _packed

from .test_reference import ref_stance

TIGHT = tslip.IntegratorOptions.tight()


# -- the independent reference --------------------------------------------------------

def _alpha(p, s):
    """The rule, ``s`` after the clock's start (held at ``alpha_r`` before it)."""
    a = p.alpha_r + p.omega_r * np.maximum(s, 0.0)
    if p.alpha_stop is None or p.omega_r == 0.0:
        return a
    if p.omega_r > 0.0:
        return np.minimum(a, max(p.alpha_r, p.alpha_stop))
    return np.maximum(a, min(p.alpha_r, p.alpha_stop))


def _clock(p, yd_lo):
    return max(yd_lo, 0.0) / p.g if p.retraction == "apex" else 0.0


def _beta(p, lo, t):
    """Leg angle ``t`` after lift-off from ``lo = (x, y, phi, xd, yd, phid)``."""
    a = _alpha(p, t - _clock(p, lo[4]))
    return a - (lo[2] + lo[5] * t) if p.leg_reset == "local" else a


def _foot(p, lo, t):
    y = lo[1] + lo[4] * t - 0.5 * p.g * t * t
    return y + p.r * np.cos(lo[2] + lo[5] * t) - p.l0 * np.sin(_beta(p, lo, t))


def ref_stride(p, td, h_next=0.0):
    """Next touch-down ``(beta, phi, xd, yd, phid)`` on ground ``h_next``, the flight time."""
    _, s_lo, _, _ = ref_stance(p, td, rtol=1e-11)
    ts = np.linspace(0.0, 3.0, 300001)
    f = _foot(p, s_lo, ts) - h_next
    armed = np.flatnonzero(f > 0.0)[0]  # a reset foot below the ground must rise first
    i = armed + np.flatnonzero((f[armed:-1] > 0.0) & (f[armed + 1:] <= 0.0))[0]
    t = brentq(lambda u: float(_foot(p, s_lo, u)) - h_next, ts[i], ts[i + 1], xtol=1e-15,
               rtol=1e-15)
    x, y, phi, xd, yd, phid = s_lo
    q = np.array([float(_beta(p, s_lo, t)), phi + phid * t, xd, yd - p.g * t, phid])
    return q, t, s_lo


def _stop_time(p, yd_lo):
    """When the leg reaches ``alpha_stop`` (after lift-off), from the rule."""
    return _clock(p, yd_lo) + (p.alpha_stop - p.alpha_r) / p.omega_r


# -- the strides: both resets, both retraction signs, both clocks ------------------------

_T21 = dataclasses.replace(tslip.preset("table2.1"), alpha_r=0.92)
_T21_STATE = tslip.TouchdownState.from_velocity(v=5.0, delta=-0.025, beta=1.05, phi=0.0,
                                                phid=0.0)
_SLIP = dataclasses.replace(tslip.preset("slip"), omega_r=0.5, alpha_r=1.12)
_SLIP_STATE = tslip.TouchdownState.from_velocity(v=1.6, delta=-0.091, beta=1.19, phi=0.0,
                                                 phid=0.0)
#: name -> (params without a stop, touch-down state)
_BASE = {
    "local": (_T21, _T21_STATE),
    "local, pitching": (_T21, tslip.TouchdownState.from_velocity(
        v=5.0, delta=-0.025, beta=1.05, phi=0.1, phid=-1.0)),
    "global": (_SLIP, _SLIP_STATE),
    # protraction (the foot moves forward and up): long flights
    "local, omega_r < 0": (dataclasses.replace(_T21, omega_r=-0.2, alpha_r=1.0), _T21_STATE),
    "global, omega_r < 0": (dataclasses.replace(_SLIP, omega_r=-0.2, alpha_r=1.1),
                            _SLIP_STATE),
    "local, apex clock": (dataclasses.replace(_T21, retraction="apex"), _T21_STATE),
}


def _with_stop(name, where):
    """The base stride with a stop reached at ``where`` of the retraction before touch-down.

    ``where`` < 1 binds (the leg is held for the rest of the flight), > 1 does not.
    """
    p, s = _BASE[name]
    r = tslip.step(p, s)
    assert r.ok, r.reason
    t_c = _clock(p, r.liftoff.yd)
    stop = p.alpha_r + p.omega_r * where * (r.flight_time - t_c)
    return dataclasses.replace(p, alpha_stop=stop), s


@pytest.mark.parametrize("where", [0.6, 1.3])
@pytest.mark.parametrize("name", list(_BASE))
def test_stride_matches_the_independent_reference(name, where):
    p, s = _with_stop(name, where)
    want, t_td, s_lo = ref_stride(p, s)
    got = tslip.step(p, s, options=TIGHT)
    assert got.ok, got.reason
    np.testing.assert_allclose(got.state.section(), want, rtol=0.0, atol=1e-8)
    assert got.flight_time == pytest.approx(t_td, abs=1e-8)
    binds = t_td > _stop_time(p, s_lo[4])
    assert binds == (where < 1.0)
    alpha_td = got.state.beta + (got.state.phi if p.leg_reset == "local" else 0.0)
    if binds:  # held at the stop: a different touch-down from the stride without it
        assert alpha_td == pytest.approx(p.alpha_stop, abs=1e-12)
        free = tslip.step(dataclasses.replace(p, alpha_stop=None), s, options=TIGHT)
        assert abs(free.flight_time - got.flight_time) > 1e-3


def test_a_reset_beyond_the_stop_holds_alpha_r():
    """``max(alpha_r, alpha_stop)``: a leg reset past the stop does not retract at all."""
    p, s = _BASE["local"]
    p = dataclasses.replace(p, alpha_stop=p.alpha_r - 0.1)
    want, _, _ = ref_stride(p, s)
    got = tslip.step(p, s, options=TIGHT)
    np.testing.assert_allclose(got.state.section(), want, rtol=0.0, atol=1e-8)
    assert got.state.beta + got.state.phi == pytest.approx(p.alpha_r, abs=1e-12)


def test_zero_retraction_ignores_the_stop():
    p, s = _BASE["global"]
    p = dataclasses.replace(p, omega_r=0.0)
    free = tslip.step_map(p, s.section())
    stopped = tslip.step_map(dataclasses.replace(p, alpha_stop=0.5), s.section())
    assert stopped.q.tolist() == free.q.tolist()


def test_the_readable_rule_is_the_reference_rule():
    p = dataclasses.replace(_T21, alpha_stop=1.0)
    for omega_r, alpha_r in ((1.0, 0.92), (1.0, 1.1), (-1.0, 1.3), (-1.0, 0.9), (0.0, 0.9)):
        q = dataclasses.replace(p, omega_r=omega_r, alpha_r=alpha_r)
        for s in (-0.1, 0.0, 0.05, 0.2, 0.5):
            assert swing_angle(q, s) == pytest.approx(float(_alpha(q, s)), abs=1e-15)


def test_recorded_flight_holds_at_the_stop():
    p, s = _with_stop("global", 0.5)
    tr = tslip.simulate(p, s, n_steps=1, dt=0.002)
    r = tr.steps[0]
    flight = (tr["step"] == 0) & (tr["stance"] == 0.0)
    t = tr["t"][flight] - r.stance_time
    np.testing.assert_allclose(tr["alpha"][flight], _alpha(p, t), atol=1e-12)
    t_stop = _stop_time(p, r.liftoff.yd)
    np.testing.assert_array_equal(tr["betad"][flight], np.where(t >= t_stop, 0.0, p.omega_r))
    assert (t < t_stop).sum() > 5 and (t > t_stop).sum() > 5


# -- the exact Jacobian ------------------------------------------------------------------

@pytest.mark.parametrize("where", [0.6, 1.3])
@pytest.mark.parametrize("name", list(_BASE))
def test_exact_jacobian_matches_finite_differences(name, where):
    p, s = _with_stop(name, where)
    q = s.section()
    r = tslip.step(p, s, options=TIGHT)
    assert abs(r.flight_time - _stop_time(p, r.liftoff.yd)) > 1e-4  # away from the kink
    exact = map_jacobian(p, q, options=TIGHT)
    fd = map_jacobian(p, q, method="fd", options=TIGHT)
    np.testing.assert_allclose(exact, fd, rtol=0.0, atol=1e-7 * max(1.0, np.max(np.abs(exact))))
    if where < 1.0:  # held at the stop: the stop changes the Jacobian
        free = map_jacobian(dataclasses.replace(p, alpha_stop=None), q, options=TIGHT)
        assert np.max(np.abs(free - exact)) > 1e-3


@pytest.mark.parametrize("where", [0.6, 1.3])
@pytest.mark.parametrize("name", ["local", "global, omega_r < 0", "local, apex clock"])
def test_alpha_r_column_matches_finite_differences(name, where):
    """The gait search's ``dq'/d alpha_r``: 0 when held at the stop (the stop stays put)."""
    p, s = _with_stop(name, where)
    P, O = pk.pack_params(p), TIGHT.packed()
    out = np.empty(pk.NOUT)
    assert _packed.stride_map(P, O, s.section(), 0.0, out) == 0
    col = _packed.alpha_r_column(P, out)
    h = 1e-6
    nxt = [tslip.step_map(dataclasses.replace(p, alpha_r=p.alpha_r + sg * h), s.section(),
                          options=TIGHT).q for sg in (1.0, -1.0)]
    np.testing.assert_allclose(col, (nxt[0] - nxt[1]) / (2 * h), rtol=0.0, atol=1e-7)
    assert (np.max(np.abs(col)) == 0.0) == (where < 1.0)


@pytest.mark.parametrize("name", list(_BASE))
def test_alpha_r_column_is_zero_from_the_stop_time_on(name):
    """The rule that decides the held column, on both sides of the stop time.

    A touch-down at the stop time (this file's ``_stop_time``, from the rule)
    is held there (column 0); one a step of the last bit earlier is not
    (column not 0). The stride's ``out`` is the real one but for its flight
    time, as a stride ending at that instant would have it.
    """
    p, s = _with_stop(name, 0.6)
    P, O = pk.pack_params(p), TIGHT.packed()
    out = np.empty(pk.NOUT)
    assert _packed.stride_map(P, O, s.section(), 0.0, out) == 0
    t_stop = _stop_time(p, out[pk.OUT_LO + 3])
    out[pk.OUT_TF] = t_stop
    assert np.max(np.abs(_packed.alpha_r_column(P, out))) == 0.0
    out[pk.OUT_TF] = math.nextafter(t_stop, 0.0)
    assert np.max(np.abs(_packed.alpha_r_column(P, out))) > 0.1


# -- None is today's code path ------------------------------------------------------------

@pytest.mark.parametrize("name", list(_BASE))
def test_a_stop_out_of_reach_is_no_stop_bit_for_bit(name):
    """A stop the leg never reaches computes what no stop computes, to the last bit.

    The default (``None``) path is also compared with main's kernels by
    ``benchmarks/compare_kernels.py``.
    """
    p, s = _with_stop(name, 1.3)
    free = dataclasses.replace(p, alpha_stop=None)
    q = s.section()
    a, b = tslip.step_jacobian(p, q), tslip.step_jacobian(free, q)
    assert a[0].q.tolist() == b[0].q.tolist() and a[1].tolist() == b[1].tolist()
    assert (a[0].stance_time, a[0].flight_time) == (b[0].stance_time, b[0].flight_time)
    ta, tb = tslip.simulate(p, s, n_steps=1), tslip.simulate(free, s, n_steps=1)
    assert np.array_equal(ta.data, tb.data, equal_nan=True)


# -- gait search ----------------------------------------------------------------------

@pytest.fixture(scope="module")
def gait61():
    g = tslip.find_gait(tslip.preset("table6.1"))
    assert g.converged, g.message
    return g


@pytest.mark.parametrize("name", ["table2.1", "table6.1"])
def test_find_gait_refuses_a_stop_that_binds(gait61, name):
    """Held at the stop, ``alpha_r`` has no effect: Table 2.1's search converges to such a
    gait (its pitch at touch-down puts ``alpha_stop - phi`` at ``beta0``) and is refused;
    Table 6.1's finds none (with ``alpha_r`` inert, 4 unknowns are left for its 5
    equations). A stop beyond ``alpha_TD`` leaves the gait as it is."""
    free = gait61 if name == "table6.1" else tslip.find_gait(tslip.preset(name))
    alpha_td = free.state.beta + free.state.phi  # local reset: the hip angle
    p = dataclasses.replace(tslip.preset(name), alpha_stop=alpha_td - 0.05)
    if name == "table2.1":
        with pytest.raises(ValueError, match=r"^alpha_stop binds at the periodic gait, so "
                           r"alpha_r has no effect; choose alpha_stop beyond alpha_TD$"):
            tslip.find_gait(p)
    else:
        assert not tslip.find_gait(p).converged
    beyond = tslip.find_gait(dataclasses.replace(p, alpha_stop=alpha_td + 0.05))
    assert beyond.converged
    np.testing.assert_allclose(beyond.state.section(), free.state.section(), atol=1e-9)
    assert beyond.params.alpha_r == pytest.approx(free.params.alpha_r, abs=1e-9)


def test_a_stop_raises_the_step_down_limit(gait61):
    """Section 7.5's question on the Table 6.1 gait (local reset, ``omega_r`` 1.5).

    A step-down lengthens the flight, so the leg retracts further than at the gait
    (``alpha_TD`` 1.2195); a stop 0.12 rad beyond ``alpha_TD`` holds it at 1.3395
    instead. Measured (tslip 0.4 development, limits to 1e-4 of the first failure): the
    step-down limit goes from -0.1189 (the thesis's -0.12) to -0.1405; stops closer to
    ``alpha_TD`` lower it (-0.042 at +0.005, -0.082 at +0.02), stops from +0.2 on are
    never reached before the runner fails and leave it at -0.1189. The first touch-down
    on the lowered ground is checked against the reference flight; survival over 25
    strides at ``dh = -0.13`` is the kernels' own (a regression pin of the measurement).
    """
    alpha_td = gait61.state.beta + gait61.state.phi
    p = dataclasses.replace(gait61.params, alpha_stop=alpha_td + 0.12)
    dh = -0.13
    stopped = run_disturbed(p, gait61.state, "step_down", [dh], options=TIGHT)
    free = run_disturbed(gait61.params, gait61.state, "step_down", [dh], options=TIGHT)
    want, _, s_lo = ref_stride(p, gait61.state, h_next=dh)
    assert want[0] + want[1] == pytest.approx(p.alpha_stop, abs=1e-12)  # held at the stop
    np.testing.assert_allclose(stopped.touchdowns[0, 1, :5], want, rtol=0.0, atol=1e-8)
    assert stopped.n_done[0] == 25 and free.n_done[0] < 25
    limits = {name: robustness(dataclasses.replace(gait61, params=q), "step_down")
              for name, q in (("free", gait61.params), ("stop", p))}
    assert limits["free"] == pytest.approx(-0.12, abs=0.005)  # thesis Table 6.2
    assert limits["stop"] == pytest.approx(-0.1405, abs=2e-4)


# -- the field: values, files and sweeps ---------------------------------------------------

@pytest.mark.parametrize("bad", [0.0, math.pi, -0.5, 4.0, math.nan, math.inf, True, "1.0"])
def test_bad_alpha_stop_is_a_one_line_error(bad):
    with pytest.raises(ValueError, match=r"^alpha_stop \[rad\] must be (a number|finite and) "
                       r"in \(0, 3\.14159\d*\), got .*$") as exc:
        tslip.Params(alpha_stop=bad)
    assert "\n" not in str(exc.value)
    with pytest.raises(ValueError, match="alpha_stop"):
        tslip.Params.from_dict({"alpha_stop": bad})


def test_alpha_stop_in_dicts_and_files(tmp_path):
    assert "alpha_stop" not in tslip.Params().to_dict()  # None is omitted
    p = tslip.Params(alpha_stop=1.4)
    assert p.to_dict()["alpha_stop"] == 1.4
    assert tslip.Params.from_dict(p.to_dict()) == p
    f = tmp_path / "p.toml"
    f.write_text("[params]\npreset = \"table6.1\"\nalpha_stop = 1.3\n")
    assert tslip.Params.from_toml(f) == dataclasses.replace(tslip.preset("table6.1"),
                                                            alpha_stop=1.3)
    path = tmp_path / "g.json"
    g = tslip.find_gait(tslip.preset("table2.1"))
    g2 = dataclasses.replace(g, params=dataclasses.replace(g.params, alpha_stop=1.5))
    g2.save(path)
    assert tslip.load(path).params.alpha_stop == 1.5
    g.save(path)
    assert "alpha_stop" not in path.read_text()
    assert tslip.load(path).params.alpha_stop is None


def test_alpha_stop_in_si():
    from tslip.model.units import ROBOT_SCALING, from_si, param_unit, to_si

    p = tslip.Params(alpha_stop=1.4)
    si = to_si(p, ROBOT_SCALING)
    assert si["alpha_stop"] == 1.4 and "alpha_stop" not in to_si(tslip.Params(), ROBOT_SCALING)
    assert from_si(si, ROBOT_SCALING).alpha_stop == pytest.approx(1.4, abs=0.0)
    assert param_unit("alpha_stop") == "rad"


def test_alpha_stop_cannot_be_swept():
    with pytest.raises(ValueError, match=r"^alpha_stop cannot be swept"):
        set_param(tslip.Params(alpha_stop=1.4), "alpha_stop", 1.2)


def test_alpha_stop_on_the_command_line():
    from tslip.cli._common import build_params

    assert build_params("table6.1", ["alpha_stop=1.3"], None).alpha_stop == 1.3
    with pytest.raises(ValueError, match=r"^--set alpha_stop \[rad\] must be a number"):
        build_params(None, ["alpha_stop=x"], None)
    with pytest.raises(ValueError, match=r"^alpha_stop \[rad\] must be a number in \(0, "):
        build_params(None, ["alpha_stop=4"], None)


@pytest.mark.parametrize("placement", ["apex", "liftoff"])
def test_zero_flight_disturbance_keeps_the_stop(placement):
    """A disturbance placed in flight restarts the flight from there: the leg must still be
    held at the stop it reached before (here by the apex) and touch down as undisturbed."""
    p, s = _with_stop("local, apex clock", 0.6)
    p = dataclasses.replace(p, retraction="liftoff", alpha_stop=p.alpha_r + 0.05)
    r = tslip.step(p, s)
    assert _stop_time(p, r.liftoff.yd) < r.liftoff.yd / p.g < r.flight_time  # stopped by apex
    run = run_disturbed(p, s, "push", [0.0], n_steps=1, placement=placement)
    np.testing.assert_allclose(run.touchdowns[0, 0, :5], r.state.section(), atol=1e-12)
