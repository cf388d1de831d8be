"""Kernels compiled once per integrator method, with the method a compile-time constant.

Private (see :mod:`._kernels`). :func:`specialise` turns a factory
``make(method, ...)`` into one compiled kernel per Runge-Kutta pair, a tuple
indexed by the method code; :class:`ByMethod` calls such a tuple as one kernel,
for Python callers that hold the method only in the options ``O``. A kernel
calls another's copy through a small ``inline="always"`` function that branches
on the (constant) method, which numba prunes to the one call (a closure over a
compiled kernel would not cache: numba keys its cache on pickled closure cells).

Why one name per copy: numba names a compiled function after its
``__qualname__`` and a counter that restarts in every process, and when two
libraries loaded from the on-disk cache export the same symbol, the first one
loaded serves both. Two copies of one closure compiled in different processes
would then share a name, and a process loading both would run one method's
code for the other (``tests/simulation/test_kernel_variants.py``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from numba import njit

from ..model._pack import M_DOP853, M_DOPRI5, METHODS, O_METHOD
from ._rk import _JIT

__all__ = ["specialise", "ByMethod"]


def specialise(make: Callable, name: str, *consts: object, jit: dict = _JIT) -> tuple:
    """``make(method, *consts)`` compiled for each method: a tuple indexed by method code.

    Copy ``m`` is named ``{name}_{METHODS[m]}`` (see the module docstring);
    ``make`` returns a plain function whose ``method`` and ``consts`` are
    closure constants (ints and bools only: numba keys its cache on them).
    """
    out = []
    for m in (M_DOPRI5, M_DOP853):
        fn = make(m, *consts)
        fn.__name__ = fn.__qualname__ = f"{name}_{METHODS[m]}"
        out.append(njit(**jit)(fn))
    return tuple(out)


class ByMethod:
    """The kernels of :func:`specialise` called as one, by the method in the options ``O``.

    For Python callers that hold a method code only in ``O`` (every kernel takes
    ``O`` as its second argument); ``signatures`` lists what each copy compiled.
    """

    def __init__(self, kernels: tuple) -> None:
        self.kernels = kernels

    def __call__(self, *args: Any) -> Any:
        return self.kernels[int(args[1][O_METHOD])](*args)

    @property
    def signatures(self) -> list:
        return [s for k in self.kernels for s in getattr(k, "signatures", ())]
