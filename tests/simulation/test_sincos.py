"""The vectorised sine and cosine of the trajectory table (simulation._sincos) against libm."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tslip.simulation import _sincos as sc

#: The bounds the module's docstring states: at most 1 ulp from glibc's ``math.sin``,
#: ``math.cos`` (which are within 0.52 ulp of the true values), and within 0.85 ulp of the
#: true values (measured 0.78: fdlibm's kernels on an exact reduction).
MAX_ULP = 1
MAX_TRUE_ULP = 0.85


def ulp_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Doubles between ``a`` and ``b`` (0 for equal values, -0.0 and 0.0 included)."""
    ia, ib = a.view(np.int64), b.view(np.int64)
    # map the sign-magnitude bit patterns onto a monotone integer line
    ia = np.where(ia < 0, np.int64(-(2**63)) - ia, ia)
    ib = np.where(ib < 0, np.int64(-(2**63)) - ib, ib)
    return np.abs(ia - ib)


def libm(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``math.sin``, ``math.cos`` of each element; NaN where they refuse (inf)."""
    s = np.array([math.sin(v) if math.isfinite(v) else math.nan for v in x])
    c = np.array([math.cos(v) if math.isfinite(v) else math.nan for v in x])
    return s, c


def ours(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    s, c = np.full_like(x, 7.0), np.full_like(x, 7.0)
    sc.sincos_array(np.ascontiguousarray(x), s, c)
    return s, c


def _edge_cases() -> np.ndarray:
    k = np.arange(-40, 41)
    tiny = [5e-324, -5e-324, 2.2250738585072014e-308, 1e-300, 1e-20, 1e-9, 3e-8]
    return np.concatenate([
        [0.0, -0.0, 1.0, -1.0, math.pi, -math.pi, 2 * math.pi],
        k * (math.pi / 2), k * (math.pi / 4), np.nextafter(k * (math.pi / 2), np.inf),
        tiny, np.negative(tiny),
        [sc.REDUCE_MAX, -sc.REDUCE_MAX, np.nextafter(sc.REDUCE_MAX, np.inf), 1e5 + 0.5, 1e6,
         -1e6, 1e22, 1e300, -1e300, 1.7976931348623157e308],
    ])


@pytest.mark.parametrize("name", ["uniform [-50, 50]", "log-uniform 1e-300 .. 1e5",
                                  "uniform [-1e5, 1e5]", "edge cases"])
def test_within_one_ulp_of_libm(name, rng):
    """10^5 points of each range (and the edge cases): at most MAX_ULP apart from libm."""
    if name == "uniform [-50, 50]":
        x = rng.uniform(-50.0, 50.0, 100_000)
    elif name == "log-uniform 1e-300 .. 1e5":
        x = np.exp(rng.uniform(math.log(1e-300), math.log(1e5), 100_000))
        x *= rng.choice([-1.0, 1.0], x.size)
    elif name == "uniform [-1e5, 1e5]":
        x = rng.uniform(-1e5, 1e5, 100_000)
    else:
        x = _edge_cases()
    s, c = ours(x)
    rs, rc = libm(x)
    assert ulp_distance(s, rs).max() <= MAX_ULP, x[np.argmax(ulp_distance(s, rs))]
    assert ulp_distance(c, rc).max() <= MAX_ULP, x[np.argmax(ulp_distance(c, rc))]


@pytest.mark.skipif(np.finfo(np.longdouble).nmant <= 52, reason="long double is double here")
def test_within_085_ulp_of_the_true_values(rng):
    """Against ``np.sin``/``np.cos`` in long double (11 more bits on x86): the error of each
    value in ulps of the exact result, which a wrong digit in a constant or a reduction that
    loses a rounding error push towards or past 1 ulp."""
    x = np.concatenate([rng.uniform(-4.0, 4.0, 100_000), rng.uniform(-1e5, 1e5, 20_000)])
    s, c = ours(x)
    xl = x.astype(np.longdouble)
    for got, exact in ((s, np.sin(xl)), (c, np.cos(xl))):
        ulp = np.spacing(np.abs(exact.astype(np.float64))).astype(np.longdouble)
        err = np.abs((got.astype(np.longdouble) - exact) / ulp).astype(np.float64)
        assert err.max() <= MAX_TRUE_ULP, (x[np.argmax(err)], err.max())


def test_exact_where_it_must_be():
    """sin(+-0) keeps the sign, cos(0) is 1, and beyond REDUCE_MAX libm's own values."""
    s, c = ours(np.array([0.0, -0.0]))
    assert s.tolist() == [0.0, 0.0] and np.signbit(s).tolist() == [False, True]
    assert c.tolist() == [1.0, 1.0]
    far = np.array([np.nextafter(sc.REDUCE_MAX, np.inf), 1e6, -3e7, 1e300])
    s, c = ours(far)
    rs, rc = libm(far)
    assert s.tolist() == rs.tolist() and c.tolist() == rc.tolist()


def test_nan_where_libm_gives_nan():
    x = np.array([math.nan, math.inf, -math.inf, 0.5, math.nan])
    s, c = ours(x)
    assert np.isnan(s).tolist() == np.isnan(c).tolist() == [True, True, True, False, True]
    assert (s[3], c[3]) == pytest.approx((math.sin(0.5), math.cos(0.5)), rel=1e-15)


def test_every_element_is_written_whatever_the_length():
    """Lengths around the vector width (the loop's remainder) and the empty array."""
    for n in (0, 1, 7, 8, 9, 15, 16, 17, 33):
        x = np.linspace(-3.0, 3.0, n)
        s, c = ours(x)
        rs, rc = libm(x)
        assert ulp_distance(s, rs).max(initial=0) <= MAX_ULP
        assert ulp_distance(c, rc).max(initial=0) <= MAX_ULP
