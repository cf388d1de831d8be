"""Jit options for kernels compiled without numba's reference counting.

numba keeps every array alive with an atomically reference-counted
``MemInfo`` (its runtime, NRT): a compiled function increments and
decrements the counts of the arrays it receives, slices and unpacks from
tuples. For the biped's right-hand side, called some 18,000 times a stride
with a dozen array arguments, those atomic operations cost about as much as
the arithmetic (``benchmarks/bench_biped.py``; ``perf`` showed a fifth of a
stride in ``NRT_incref``/``NRT_decref`` alone, before the loads and stores
around them). The kernels here never outlive their arguments: the caller
owns every array for the whole call, so the counts are not needed.

numba compiles such functions with its *private* ``_nrt=False`` option (it
uses it itself for its string kernels); without the runtime a function
cannot create arrays, so a kernel compiled with :func:`without_nrt` must not
allocate (``np.empty``, ``.copy()``, ...): its caller, compiled with the
runtime, allocates the work arrays and passes them in. Calls between the two
kinds are ordinary calls. If a numba version drops or rejects the option,
:func:`without_nrt` returns the options unchanged: the kernels then compile
with reference counting, the same numbers, only slower.
"""

from __future__ import annotations

import functools
from typing import Any

__all__ = ["without_nrt", "nrt_disabled"]


@functools.cache
def nrt_disabled() -> bool:
    """True if this numba accepts the ``_nrt`` jit option (so kernels run without NRT)."""
    try:
        from numba.core import cpu
    except ImportError:  # pragma: no cover - a numba that moved its modules
        return False
    return hasattr(cpu.CPUTargetOptions, "_nrt")


def without_nrt(**jit_kwargs: Any) -> dict[str, Any]:
    """``jit_kwargs`` plus ``_nrt=False`` where numba supports it (see the module docstring)."""
    if nrt_disabled():
        return dict(jit_kwargs, _nrt=False)
    return dict(jit_kwargs)
