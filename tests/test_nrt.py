"""Kernels compiled without numba's reference counting (tslip._nrt)."""

import numpy as np
import pytest
from numba import njit
from numba.core.errors import NumbaError

from tslip import _nrt


def test_options_keep_the_callers_and_drop_nrt_where_supported():
    opts = _nrt.without_nrt(cache=True, nogil=True)
    assert opts["cache"] is True and opts["nogil"] is True
    assert opts.get("_nrt", True) is (not _nrt.nrt_disabled())


@pytest.mark.skipif(not _nrt.nrt_disabled(), reason="this numba compiles every kernel with NRT")
def test_the_option_really_disables_the_runtime():
    """Without NRT a kernel cannot allocate (so the option is not silently ignored),
    and one that only reads and writes its arguments runs as with it."""

    def alloc(n):
        return np.empty(n)

    def axpy(a, x, y):
        for i in range(x.shape[0]):
            y[i] += a * x[i]

    assert alloc(3).shape == (3,)
    with pytest.raises(NumbaError):
        njit(**_nrt.without_nrt())(alloc)(3)
    x = np.arange(4.0)
    y1, y2 = np.ones(4), np.ones(4)
    njit(**_nrt.without_nrt())(axpy)(0.5, x[::-1], y1)
    njit(axpy)(0.5, x[::-1], y2)
    assert y1.tolist() == y2.tolist() == [2.5, 2.0, 1.5, 1.0]
