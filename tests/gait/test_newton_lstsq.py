"""Newton's linear step (:func:`tslip.gait.fixed_point._lstsq`) against ``np.linalg.lstsq``.

``_lstsq`` calls numpy's least-squares gufunc without ``lstsq``'s argument
handling; the gait search's iterates, and so every study's numbers, stay the
same only if its solutions are ``np.linalg.lstsq(a, b, rcond=None)[0]`` bit for
bit: on square Jacobians, on the tall ones of a held pitch (5 x 3, 5 x 4), and
on rank-deficient ones, where ``rcond`` (machine epsilon times the larger
dimension) decides which singular values count.
"""

import numpy as np
import pytest

from tslip.gait.fixed_point import _lstsq


def _with_singular_values(rng: np.random.Generator, m: int, n: int, s: list[float]) -> np.ndarray:
    u = np.linalg.qr(rng.normal(size=(m, m)))[0][:, :n]
    v = np.linalg.qr(rng.normal(size=(n, n)))[0]
    return (u * s) @ v.T


@pytest.mark.parametrize("shape", [(5, 5), (5, 4), (5, 3)])
def test_lstsq_is_numpys_bit_for_bit(shape: tuple[int, int]) -> None:
    rng = np.random.default_rng(7)
    m, n = shape
    for i in range(300):
        a, b = rng.normal(size=shape), rng.normal(size=m)
        if i % 3 == 1:
            a[:, 0] = a[:, 1]  # exactly rank deficient
        if i % 3 == 2:  # the smallest singular value between 3 and 5 eps: rcond decides
            a = _with_singular_values(rng, m, n, [1.0] * (n - 1) + [4.0 * np.finfo(float).eps])
        x = _lstsq(a, b)
        assert x.shape == (n,)
        assert np.array_equal(x, np.linalg.lstsq(a, b, rcond=None)[0])
