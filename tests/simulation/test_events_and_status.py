"""Falls with their reasons, integration failures as statuses, bad input."""

import dataclasses
import math

import numpy as np
import pytest

import tslip
from tslip import Status


@pytest.fixture(scope="module")
def gait():
    return tslip.find_gait(tslip.preset("table2.1"))


def test_periodic_gait_returns_to_itself(gait):
    r = tslip.step(gait.params, gait.state, options=tslip.IntegratorOptions.tight())
    assert r.ok and not r.fell and r.reason == "ok"
    np.testing.assert_allclose(r.state.section(), gait.state.section(), atol=1e-9)
    assert r.state.x > gait.state.x  # it ran forward


def test_fall_backward_eq_2_10(gait):
    """Very slow and steep: the runner is thrown back over its foot."""
    s = tslip.TouchdownState.from_velocity(v=0.3, delta=-0.1, beta=1.0)
    r = tslip.step(gait.params, s)
    assert r.fell and r.status == Status.FALL_BACKWARD
    assert "eq. 2.10" in r.reason


def test_fall_hip_ground_in_stance(gait):
    """A soft leg at high downward speed collapses until the hip is at the ground."""
    p = dataclasses.replace(gait.params, k=2.0)
    s = tslip.TouchdownState.from_velocity(v=5.0, delta=-1.2, beta=1.0)
    r = tslip.step(p, s)
    assert r.status == Status.FALL_HIP_GROUND
    assert r.liftoff.l * math.sin(r.liftoff.beta) == pytest.approx(0.0, abs=1e-8)


def test_fall_no_touchdown_leg_pointing_up(gait):
    """A leg reset pointing upward never reaches the ground: the hip lands first."""
    p = dataclasses.replace(gait.params, alpha_r=-1.0, omega_r=0.0)
    r = tslip.step(p, gait.state)
    assert r.status == Status.FALL_NO_TOUCHDOWN and r.fell
    assert r.flight_time > 0


def test_trip_on_step_up(gait):
    """A riser higher than the swinging foot, in its path, trips the runner."""
    tr = tslip.simulate(gait.params, gait.state, 1, dt=1e-3)
    flight = tr["stance"] == 0
    fx, fy = tr["foot_x"][flight], tr["foot_y"][flight]
    i = int(np.argmax(fy))  # riser where the foot is highest, twice as high as the foot
    terrain = tslip.Terrain.step(x=fx[i], dh=2 * fy[i])
    r = tslip.step(gait.params, gait.state, terrain=terrain)
    assert r.status == Status.FALL_TRIP
    # a riser lower than the foot there is stepped onto instead
    low = tslip.step(gait.params, gait.state, terrain=tslip.Terrain.step(x=fx[i], dh=0.5 * fy[i]))
    assert low.ok and low.state.h == pytest.approx(0.5 * fy[i])


@pytest.mark.parametrize("frac", [0.3, 0.6, 0.9])
def test_riser_just_below_the_descending_foot_is_stepped_onto(gait, frac):
    """A riser whose top the foot clears at its edge, by 2 % of its height there, is landed
    on, never tripped over: the touch-down search may not step across the edge (a safe step
    sized against the lower ground would carry the foot below the riser's top beyond it).
    The foot's path is the closed-form flight (eq. 2.7) sampled by ``simulate``."""
    tr = tslip.simulate(gait.params, gait.state, 1, dt=1e-4)
    flight = tr["stance"] == 0
    fx, fy = tr["foot_x"][flight], tr["foot_y"][flight]
    top = int(np.argmax(fy))
    i = top + int(frac * (len(fy) - 1 - top))  # on the way down
    assert np.all(np.diff(fx) > 0)  # the foot moves forward: it passes the edge once
    dh = 0.98 * fy[i]
    r = tslip.step(gait.params, gait.state, terrain=tslip.Terrain.step(x=fx[i], dh=dh))
    assert r.ok and r.state.h == pytest.approx(dh)


@pytest.mark.parametrize(
    ("opts", "status"),
    [(tslip.IntegratorOptions(max_steps=3), Status.MAX_STEPS),
     (tslip.IntegratorOptions(h_min=0.5), Status.STEP_UNDERFLOW),
     (tslip.IntegratorOptions(t_max_stance=0.01), Status.STANCE_TIMEOUT),
     (tslip.IntegratorOptions(t_max_flight=0.01), Status.FLIGHT_TIMEOUT)],
)
def test_integration_failures_end_with_a_status(gait, opts, status):
    r = tslip.step(gait.params, gait.state, options=opts)
    assert r.status == status and r.status.is_error and not r.fell
    with pytest.raises(tslip.simulation.IntegrationError):
        tslip.step(gait.params, gait.state, options=opts, raise_on_failure=True)


def test_simulate_stops_at_fall_and_records_event(gait):
    tr = tslip.simulate(gait.params, gait.state, 25, disturbance=tslip.Disturbance(dxd=-4.5))
    assert tr.fell
    assert tr.events[-1].kind == "fall"
    assert len(tr.steps) < 25


@pytest.mark.parametrize("kw", [{"rtol": 0.0}, {"atol": -1.0}, {"max_steps": 0},
                                {"rtol": math.nan}])
def test_bad_options(kw):
    with pytest.raises(ValueError, match="IntegratorOptions"):
        tslip.IntegratorOptions(**kw)


def test_bad_simulate_input(gait):
    with pytest.raises(ValueError, match="n_steps"):
        tslip.simulate(gait.params, gait.state, 0)
    with pytest.raises(ValueError, match="dt"):
        tslip.simulate(gait.params, gait.state, 2, dt=-1.0)
    with pytest.raises(ValueError, match="state must"):
        tslip.step(gait.params, [1.0, 2.0])
    with pytest.raises(ValueError, match="params must be a tslip.Params"):
        tslip.step({"k": 1}, gait.state)
    with pytest.raises(ValueError, match="Disturbance.at_step"):
        tslip.Disturbance(at_step=-1)


def test_fy_negative_at_touchdown_is_flagged():
    """With a large hip torque F_y starts negative; the stance continues until F_y
    crosses zero from above (docs/conventions.md)."""
    p = dataclasses.replace(tslip.preset("table2.1"),
                            controller=tslip.ConstantTorque(tau_c=-3.0, c_h=0.0))
    s = tslip.TouchdownState.from_velocity(v=5.0, delta=-0.2, beta=1.05)
    r = tslip.step(p, s)
    assert r.fy_negative_at_touchdown
    assert r.stance_time > 0.01
    assert np.any(r.grf[:, 2] > 0)


def test_hip_reaching_ground_in_flight_is_a_fall_not_a_timeout():
    """The safe steps approach the hip's contact from above; it must still end the
    flight as a fall (it once ran into the iteration limit as FLIGHT_TIMEOUT)."""
    g = tslip.find_gait(tslip.preset("table6.1"))
    s = g.state
    xf = s.x + g.params.l0 * math.cos(s.beta) - g.params.r * math.sin(s.phi)
    tr = tslip.simulate(g.params, s, 25, terrain=tslip.Terrain.step(xf, -0.13))
    assert tr.status == Status.FALL_NO_TOUCHDOWN
    assert tr.steps[-1].flight_time < 10.0


def test_touchdown_with_the_leg_lengthening_is_a_failed_touchdown():
    """A spring leg cannot pull: ld > 0 at touch-down ends the contact at once.

    Human-scale SLIP (80 kg, 20 kN/m) landing while the body rises along the leg:
    the mass moves away from the foot along the leg, so the spring would stretch
    past l0 and pull (before the rule: F_y down to about -890 N in a 0.34 s stance).
    """
    p = tslip.preset("slip-human")
    s = tslip.TouchdownState(beta=p.beta0, phi=0.0, xd=1.0, yd=0.6, phid=0.0, x=0.0, h=0.0)
    # the CoM velocity along the leg, away from the foot (r = 0: the CoM is the hip)
    ld = -s.xd * math.cos(s.beta) + s.yd * math.sin(s.beta)
    assert ld > 0.1
    r = tslip.step(p, s)
    assert r.fell and r.status == Status.FALL_LENGTHENING and "lengthening" in r.reason
    assert r.stance_time == 0.0 and r.state is None
    assert r.liftoff.ld == pytest.approx(ld, rel=1e-12) and r.liftoff.l == p.l0
    # a leg touching down while shortening, however slowly, starts an ordinary stance
    s_in = dataclasses.replace(s, yd=(s.xd * math.cos(s.beta) - 1e-3) / math.sin(s.beta))
    assert tslip.step(p, s_in).stance_time > 0.0


def test_negative_fy_from_the_hip_torque_with_the_leg_shortening_keeps_the_stance():
    """Thesis case (Table 6.1 model, eq. 2.6): F_y < 0 at touch-down from the hip torque
    alone, the spring compressing (ld < 0): the stance goes on until F_y crosses zero
    from above (docs/conventions.md, "Events")."""
    g = tslip.find_gait(tslip.preset("table6.1"))
    s = dataclasses.replace(g.state, phid=g.state.phid + 3.0)  # hip torque -Kd alphad
    r = tslip.step(g.params, s)
    assert r.fy_negative_at_touchdown and r.grf[0, 2] < 0.0
    assert r.stance[0, 4] < 0.0  # ld at touch-down: the spring compresses
    assert r.ok and r.stance_time > 0.3
    assert r.grf[:, 2].max() > 1.0 and r.grf[-1, 2] == pytest.approx(0.0, abs=1e-6)


def test_collapsing_leg_is_a_hip_ground_fall():
    """A soft leg landing fast collapses to zero length with the hip still above the foot
    by ``l sin(beta) > 0`` all the way: the polar stance equations are singular at ``l = 0``
    and event 1 never crosses. The stance must end as the hip reaching the ground
    (eq. 2.11) when ``l`` reaches ``L_COLLAPSE l0``, at the time an independent Cartesian
    model (tests/simulation/test_reference.py, no singularity there) puts it; before the
    collapse event it ground on to ``max_steps`` (MAX_STEPS after 100,000 steps).
    """
    from tslip.simulation._kernels import L_COLLAPSE

    from .test_reference import _com_from_touchdown, leg_state, stance_rhs

    p = dataclasses.replace(tslip.preset("table2.1-local-velocity"), k=5.0)
    td = tslip.TouchdownState.from_velocity(v=5.0, delta=-1.0, beta=1.08)
    tight = tslip.IntegratorOptions.tight()
    r = tslip.step(p, td, options=tight)
    assert r.status == Status.FALL_HIP_GROUND
    assert r.liftoff.l == pytest.approx(L_COLLAPSE * p.l0, rel=1e-9)
    assert r.n_integrator_steps < 5000

    from scipy.integrate import solve_ivp

    y0, xf = _com_from_touchdown(p, td)
    s0 = np.array([td.x, y0, td.phi, td.xd, td.yd, td.phid])

    def collapse(t, s):
        return leg_state(p, s, xf, td.h).l - L_COLLAPSE * p.l0

    collapse.terminal, collapse.direction = True, -1.0
    sol = solve_ivp(lambda t, s: stance_rhs(p, s, xf, td.h), (0.0, 1.0), s0, method="DOP853",
                    rtol=1e-12, atol=1e-12, events=collapse)
    assert sol.t_events[0].size == 1, "the reference leg does not collapse"
    assert r.stance_time == pytest.approx(sol.t_events[0][0], abs=1e-8)
    lift = leg_state(p, sol.y_events[0][0], xf, td.h)
    assert lift.l * math.sin(lift.beta) < L_COLLAPSE * p.l0  # the hip is at the ground
    # it never lifts off on the way: F_y stays positive up to the collapse
    assert all(leg_state(p, s, xf, td.h).Fy > 0 for s in sol.y.T)
