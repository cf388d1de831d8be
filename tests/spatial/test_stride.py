"""The 3-D spring-mass runner's step (issue 43, Part 1) against physics, the planar SLIP and an
independent scipy integration written here."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import tslip
from tslip.gait.section import ApexState, apex_map
from tslip.spatial import (
    SpatialApex,
    SpatialParams,
    SpatialStatus,
    apex_step,
    apex_steps,
    energy,
    mirror,
)

TIGHT = tslip.IntegratorOptions(rtol=1e-12, atol=1e-12)
TIGHT853 = tslip.IntegratorOptions(rtol=1e-12, atol=1e-12, method="dop853")
#: away from 1, where a missing factor of m, l0 or g would show
ODD = dict(m=0.9, l0=1.3, g=1.2)


# ---------------------------------------------------------------------------
# an independent implementation: world coordinates, the placement formula
# with the vectors h and n, scipy's solve_ivp with its own event location
# ---------------------------------------------------------------------------

def _reference_step(p: SpatialParams, a: SpatialApex, max_step: float = np.inf
                    ) -> tuple[str, np.ndarray | None]:
    y_td = p.l0 * math.sin(p.beta0)
    if a.y <= y_td:
        return "apex low", None
    T = math.sqrt(2 * (a.y - y_td) / p.g)
    c = np.array([a.x + a.vx * T, y_td, a.z + a.vz * T])
    v = np.array([a.vx, -p.g * T, a.vz])
    ey = np.array([0.0, 1.0, 0.0])
    hv = np.array([1.0, 0.0, 0.0]) if p.heading == "fixed" else \
        np.array([v[0], 0.0, v[2]]) / math.hypot(v[0], v[2])
    n = np.cross(hv, ey)
    s = a.side
    gamma = p.gamma0 + p.k_lat * s * float(v @ n)
    foot = c + p.l0 * (math.cos(p.beta0) * (math.cos(gamma) * hv + s * math.sin(gamma) * n)
                       - math.sin(p.beta0) * ey)
    if float((c - foot) @ v) >= 0:
        return "no stance", None

    def f(t, u):
        d = u[:3] - foot
        r = np.linalg.norm(d)
        acc = p.k * (p.l0 - r) * d / r / p.m - p.g * ey
        return np.concatenate([u[3:], acc])

    def liftoff(t, u):
        return np.linalg.norm(u[:3] - foot) - p.l0
    liftoff.terminal, liftoff.direction = True, 1.0

    def ground(t, u):
        return u[1]
    ground.terminal, ground.direction = True, -1.0

    sol = solve_ivp(f, (0, 50), np.concatenate([c, v]), method="DOP853", rtol=1e-12,
                    atol=1e-12, events=(liftoff, ground), max_step=max_step)
    if sol.t_events[1].size:
        return "fall", sol.y_events[1][0]
    u = sol.y_events[0][0]
    if u[4] < 0:
        return "no apex", u
    Tu = u[4] / p.g
    return "ok", np.array([u[1] + u[4] * Tu / 2, u[3], u[5], u[0] + u[3] * Tu,
                           u[2] + u[5] * Tu])


@pytest.mark.parametrize("heading,k_lat", [("fixed", 0.0), ("fixed", 0.4), ("velocity", 0.0)])
@pytest.mark.parametrize("side", [1, -1])
def test_step_matches_an_independent_scipy_integration(heading, k_lat, side):
    p = SpatialParams(k=31.0, beta0=1.12, gamma0=0.09, k_lat=k_lat, heading=heading, **ODD)
    a = SpatialApex(1.34, 1.7, 0.13 * side, x=0.2, z=-0.3, side=side)
    kind, ref = _reference_step(p, a)
    assert kind == "ok"
    for opts in (TIGHT, TIGHT853):  # the pair is a run-time argument of one loop
        s = apex_step(p, a, opts)
        assert s.status == SpatialStatus.OK
        got = np.array([s.apex.y, s.apex.vx, s.apex.vz, s.apex.x, s.apex.z])
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-9)
        assert s.apex.side == -side
    assert abs(ref[2] - a.vz) > 1e-2  # the stance really moved the mass sideways


@pytest.mark.parametrize("y,E_extra", [(1.25, 0.0), (1.4, 0.5)])
def test_planar_limit_equals_the_planar_slip_apex_map(y, E_extra):
    """gamma0 = 0, no lateral motion: the planar SLIP's apex map (tslip.gait.section) with
    its leg angle alpha_r (measured from +x down to the leg, docs/conventions.md) = beta0."""
    k, beta0 = 27.0, 1.15
    planar = dataclasses.replace(tslip.preset("slip"), k=k, beta0=beta0, alpha_r=beta0, **ODD)
    p = SpatialParams(k=k, beta0=beta0, gamma0=0.0, **ODD)
    E = ODD["m"] * ODD["g"] * y + 0.5 * ODD["m"] * 1.6**2 + E_extra
    a2 = ApexState.from_energy(planar, y, E)
    ref = apex_map(planar, a2, TIGHT)
    assert ref.status.name == "OK"
    for side in (1, -1):
        s = apex_step(p, SpatialApex(y, a2.xd, 0.0, side=side), TIGHT)
        np.testing.assert_allclose([s.apex.y, s.apex.vx, s.apex.x], [ref.apex.y, ref.apex.xd,
                                   ref.apex.x], rtol=0, atol=1e-9)
        assert s.apex.vz == 0.0 and s.apex.z == 0.0
        assert abs(s.time - ref.time) < 1e-9


def test_energy_is_conserved_over_steps_with_lateral_motion():
    p = SpatialParams(k=28.0, beta0=1.2, gamma0=0.1, k_lat=0.2, **ODD)
    a = SpatialApex(1.4, 1.5, 0.05)
    apexes, status = apex_steps(p, a, 4, TIGHT)
    assert status == SpatialStatus.OK and len(apexes) == 5
    E = [energy(p, b) for b in apexes]
    assert max(abs(e - E[0]) for e in E) < 1e-9
    assert [b.side for b in apexes] == [1, -1, 1, -1, 1]
    assert len({round(b.vz, 6) for b in apexes}) > 2  # lateral motion changes


def test_mirror_image_steps_to_the_mirror_image():
    """Left-right symmetry of the placement rule under both headings."""
    for heading, k_lat in (("fixed", 0.3), ("velocity", 0.0)):
        p = SpatialParams(k=26.0, beta0=1.18, gamma0=0.07, k_lat=k_lat, heading=heading)
        a = SpatialApex(1.2, 1.4, 0.08, x=0.1, z=0.2, side=1)
        s1 = apex_step(p, a, TIGHT).apex
        s2 = apex_step(p, mirror(a), TIGHT).apex
        np.testing.assert_allclose(mirror(s1).as_array(), s2.as_array(), rtol=0, atol=1e-10)


# ---------------------------------------------------------------------------
# the outcomes, each on both sides (the left case is the mirror image of the right)
# ---------------------------------------------------------------------------
CASES = {
    "fall": (dict(k=2.0, beta0=1.0, gamma0=0.1), SpatialApex(1.3, 0.6, 0.1),
             SpatialStatus.FALL, "fall"),
    "apex low": (dict(k=25.0, beta0=1.19, gamma0=0.1), SpatialApex(1.3 * math.sin(1.19) - 1e-9,
                                                                    1.5, 0.1),
                 SpatialStatus.APEX_LOW, "apex low"),
    "no stance": (dict(k=25.0, beta0=1.19, gamma0=0.1), SpatialApex(1.25, -3.0, 0.1),
                  SpatialStatus.NO_STANCE, "no stance"),
    "no apex": (dict(k=25.0, beta0=1.09, gamma0=0.02), SpatialApex(1.31 * 1.3, 7.0, 0.05),
                SpatialStatus.NO_APEX, "no apex"),
}


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("side", [1, -1])
def test_each_outcome_on_both_sides(case, side):
    kw, a, status, kind = CASES[case]
    p = SpatialParams(**kw, **ODD)
    if side == -1:
        a = mirror(a)
    assert a.side == side
    s = apex_step(p, a, TIGHT)
    assert s.status == status
    ref_kind, ref = _reference_step(p, a)
    assert ref_kind == kind
    if status == SpatialStatus.FALL:
        assert abs(s.liftoff[1]) < 1e-9  # the mass is on the ground
        np.testing.assert_allclose(s.liftoff, ref, atol=1e-8)
    if status == SpatialStatus.NO_APEX:
        assert s.liftoff[4] < 0.0
        np.testing.assert_allclose(s.liftoff, ref, atol=1e-8)


def test_bad_parameters_are_refused_in_one_line():
    for kw, field in ((dict(k=-1.0), "SpatialParams.k"), (dict(m=0.0), "SpatialParams.m"),
                      (dict(beta0=2.0), "SpatialParams.beta0"),
                      (dict(gamma0=math.nan), "SpatialParams.gamma0"),
                      (dict(heading="north"), "SpatialParams.heading"),
                      (dict(heading="velocity", k_lat=0.1), "SpatialParams.k_lat")):
        with pytest.raises(ValueError, match=field) as e:
            SpatialParams(**kw)
        assert "\n" not in str(e.value)
    with pytest.raises(ValueError, match="SpatialApex.side"):
        SpatialApex(1.0, 1.0, side=0)


def test_pure_python_kernel_agrees_with_the_compiled_one():
    """The stance loop runs with NUMBA_DISABLE_JIT=1 (CONTRIBUTING's rule) to the same numbers."""
    import json
    import os
    import subprocess
    import sys

    code = ("import json, tslip\nfrom tslip.spatial import SpatialApex, SpatialParams, apex_step\n"
            "p = SpatialParams(k=31.0, beta0=1.12, gamma0=0.09, k_lat=0.4, m=0.9, l0=1.3, g=1.2)\n"
            "o = tslip.IntegratorOptions(rtol=1e-10, atol=1e-10, method='dop853')\n"
            "s = apex_step(p, SpatialApex(1.34, 1.7, 0.13), o)\n"
            "print(json.dumps(s.apex.as_array().tolist()))\n")
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         check=True).stdout
    p = SpatialParams(k=31.0, beta0=1.12, gamma0=0.09, k_lat=0.4, **ODD)
    s = apex_step(p, SpatialApex(1.34, 1.7, 0.13),
                  tslip.IntegratorOptions(rtol=1e-10, atol=1e-10, method="dop853"))
    np.testing.assert_allclose(json.loads(out), s.apex.as_array(), rtol=0, atol=1e-13)


def test_presets_and_a_bad_name():
    from tslip.spatial import preset, presets

    assert presets() == ["slip3d", "slip3d-feedback", "table2.1-3d"]
    p = preset("slip3d")
    assert (p.k, p.beta0, p.gamma0, p.k_lat, p.heading) == (25.0, 1.19, 0.05, 0.0, "fixed")
    assert preset("slip3d-feedback").k_lat == 1.5
    with pytest.raises(ValueError, match="preset must be one of"):
        preset("slip4d")


@pytest.mark.parametrize("side", [1, -1])
def test_a_stance_shorter_than_the_first_step_is_not_jumped(side):
    """A touch-down barely compressing the leg at high speed (the foot almost sideways): a
    stance of ~2e-4 under a forced first step of 0.3. Without the core's hump check the
    first step ends with the leg beyond rest length again, no lift-off is seen, and the
    stance goes on with the spring in tension."""
    p = SpatialParams(k=25.0, beta0=1.19, gamma0=1.4, **ODD)
    drop = 0.05
    T = math.sqrt(2 * drop / p.g)
    cb, phi, vx = math.cos(p.beta0), p.gamma0, 2.0
    vz0 = -(cb * math.cos(phi) * vx + math.sin(p.beta0) * p.g * T) / (cb * math.sin(phi))
    a = SpatialApex(p.touchdown_height + drop, vx, vz0 + 1e-3, side=1)  # (c - p).v < 0
    if side == -1:
        a = mirror(a)
    kind, ref = _reference_step(p, a, max_step=1e-5)  # scipy, too, jumps it otherwise
    assert kind == "no apex"
    # the stance's length from the leg's length l(t): 2 |l'(0)| / l''(0) for a short hump
    v2 = vx**2 + (p.g * T) ** 2 + a.vz**2
    ld = -cb * math.sin(phi) * 1e-3  # (q.v)/l0 with the placement above, q.v = -l0 cb sin(phi) dvz
    ldd = (v2 - ld**2) / p.l0 - p.g * math.sin(p.beta0)
    for h0 in (0.0, 0.3):
        s = apex_step(p, a, tslip.IntegratorOptions(rtol=1e-12, atol=1e-12, h0=h0))
        assert s.status == SpatialStatus.NO_APEX
        assert abs(s.stance_time / (2 * abs(ld) / ldd) - 1) < 0.01
        np.testing.assert_allclose(s.liftoff, ref, rtol=0, atol=1e-9)
