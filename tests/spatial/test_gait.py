"""Left-right symmetric gaits of the 3-D spring-mass runner and their Floquet multipliers:
mirror symmetry checked by stepping, exact against finite differences, the planar limit
against the planar SLIP's apex map."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import tslip
from tslip.gait.section import apex_map_batch
from tslip.spatial import SpatialParams, apex_step, energy, mirror
from tslip.spatial.gait import floquet, symmetric_gaits

TIGHT = tslip.IntegratorOptions.tight("dop853")
ODD = dict(m=0.9, l0=1.3, g=1.2)


@pytest.fixture(scope="module")
def gaits():
    out = {}
    for heading in ("fixed", "velocity"):
        p = SpatialParams(k=20.0, beta0=1.17, gamma0=0.08, heading=heading, **ODD)
        out[heading] = (p, symmetric_gaits(p, energy=2.2 * 0.9 * 1.2 * 1.3, options=TIGHT))
    return out


@pytest.mark.parametrize("heading", ["fixed", "velocity"])
def test_symmetric_gaits_step_to_their_mirror_image(gaits, heading):
    p, found = gaits[heading]
    assert len(found) == 2  # the low (fast) and the high (slow) gait of the scan
    for g in found:
        a = g.apex
        assert a.side == 1 and abs(energy(p, a) - g.energy) < 1e-12
        s1 = apex_step(p, a, TIGHT).apex
        s2 = apex_step(p, s1, TIGHT).apex
        if heading == "fixed":
            m = mirror(s1)
            np.testing.assert_allclose([m.y, m.vx, m.vz], [a.y, a.vx, a.vz], atol=1e-9)
            assert abs(a.vz) > 1e-3  # a zigzag: the mass moves towards the landing leg
            np.testing.assert_allclose([s2.y, s2.vx, s2.vz], [a.y, a.vx, a.vz], atol=1e-8)
            assert abs(s2.z - a.z) < 1e-8  # back on the same line: translation along x only
        else:
            turn = math.atan2(s1.vz, s1.vx)
            assert abs(turn) > 1e-3  # the right step turns the runner left ...
            assert abs(s1.y - a.y) < 1e-9 and abs(math.hypot(s1.vx, s1.vz) - a.vx) < 1e-9
            np.testing.assert_allclose([s2.y, s2.vx, s2.vz], [a.y, a.vx, a.vz], atol=1e-8)


@pytest.mark.parametrize("heading", ["fixed", "velocity"])
def test_exact_multipliers_agree_with_finite_differences(gaits, heading):
    p, found = gaits[heading]
    for g in found:
        ex, fd = floquet(g, "exact", TIGHT), floquet(g, "fd", TIGHT)
        scale = max(1.0, float(np.max(np.abs(ex.jacobian))))
        assert np.max(np.abs(ex.jacobian - fd.jacobian)) < 1e-6 * scale
        np.testing.assert_allclose(np.sort_complex(ex.nontrivial), np.sort_complex(fd.nontrivial),
                                   rtol=1e-6)
        # the trivial ones: energy, and the heading under "velocity"
        assert len(ex.trivial) == (2 if heading == "velocity" else 1)
        np.testing.assert_allclose(ex.trivial, 1.0, atol=1e-7)
        # energy is conserved: its gradient is a left eigenvector of multiplier 1
        y, vx, vz = g.apex.section()
        grad = p.m * np.array([p.g, vx, vz])
        np.testing.assert_allclose(grad @ ex.jacobian, grad, atol=1e-8)


def test_planar_limit_multiplier_is_the_planar_apex_maps_squared():
    """gamma0 = 0: the non-trivial multiplier under "velocity" is (dy'/dy)^2 of the planar
    SLIP's apex map at fixed energy (two steps), by central differences of tslip.gait.section."""
    k, beta0, E = 26.0, 1.2, 2.3 * 0.9 * 1.2 * 1.3
    p = SpatialParams(k=k, beta0=beta0, gamma0=0.0, heading="velocity", **ODD)
    found = symmetric_gaits(p, energy=E, options=TIGHT)
    assert found
    planar = dataclasses.replace(tslip.preset("slip"), k=k, beta0=beta0, alpha_r=beta0, **ODD)
    for g in found:
        y, d = g.apex.y, 1e-6
        b = apex_map_batch(planar, np.array([y - d, y, y + d]), energy=E, options=TIGHT)
        assert abs(b.y[1] - y) < 1e-9  # a fixed point of the planar map too
        slope = (b.y[2] - b.y[0]) / (2 * d)
        (lam,) = floquet(g, "exact", TIGHT).nontrivial
        assert abs(lam.real - slope**2) < 1e-6 * max(1.0, slope**2) and lam.imag == 0.0


def test_fixed_speed_finds_the_gait_of_that_forward_speed(gaits):
    """A gait found at fixed energy is found again at fixed forward apex speed (its vx)."""
    p, found = gaits["fixed"]
    g = found[0]
    again = symmetric_gaits(p, speed=g.apex.vx, options=TIGHT)
    best = min(again, key=lambda h: abs(h.apex.y - g.apex.y))
    np.testing.assert_allclose(best.apex.section(), g.apex.section(), atol=1e-9)
    assert abs(best.energy - g.energy) < 1e-9
