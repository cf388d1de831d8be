"""Jit options and sizes shared by the biped kernel modules.

Private. :data:`JIT` compiles with numba's reference counting, for the few
kernels that allocate (the entry points that create the work arrays);
every other kernel is compiled :data:`FAST`, without it (see
:mod:`tslip._nrt`), and must not allocate. :data:`INLINE` kernels are small
helpers inlined into their callers (numba IR inlining), which compile them
with their own options.
"""

from __future__ import annotations

from typing import Any

from .._nrt import without_nrt

JIT: dict[str, Any] = {"cache": True, "nogil": True, "fastmath": False, "error_model": "numpy"}
FAST = without_nrt(**JIT)
INLINE = dict(FAST, inline="always")

N = 18  # state size
NB = 7  # bodies: trunk, thigh R, shank R, foot R, thigh L, shank L, foot L
FOOT = (3, 6)
