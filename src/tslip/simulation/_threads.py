"""Which batch kernel runs a batch: serial in the calling thread, or numba's thread pool.

A batch row is one or more strides of about 10 µs each. Waking the pool costs
tens of µs, and on a loaded machine a parallel loop waits for its slowest
thread: batches of a few rows (robustness brackets, finite-difference
multipliers) ran 3-8x slower in parallel than serially with a busy second
core (``benchmarks/bench_batch.py``). So batches below :data:`SERIAL_ROWS`
rows, or with one thread, run serially, and their ``parallel=True`` kernels
are never compiled.

numba's OpenMP layer (the one it picks here) keeps idle threads spinning
after each parallel loop unless ``OMP_WAIT_POLICY=PASSIVE`` is set when the
OpenMP library loads, i.e. before the first parallel kernel runs;
:func:`parallel` sets it then unless the user chose a policy. Measured with a
spinning second process: passive waiting costs about 15 µs of CPU a launch,
active waiting made small batches several times slower than serial.
"""

from __future__ import annotations

import os
from collections.abc import Callable

__all__ = ["SERIAL_ROWS", "choose", "parallel"]

#: Batches with fewer rows run serially (measured: ``benchmarks/bench_batch.py``).
SERIAL_ROWS = 16

_configured = False


def parallel() -> None:
    """Make numba's thread pool wait passively; call before each parallel kernel."""
    global _configured
    if not _configured:
        os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
        _configured = True


def choose(serial: Callable, parallel_kernel: Callable, rows: int) -> Callable:
    """The kernel for a batch of ``rows`` rows: ``serial`` unless it is large."""
    if rows < SERIAL_ROWS:
        return serial
    parallel()  # before numba's pool starts (get_num_threads starts it)
    import numba

    return parallel_kernel if numba.get_num_threads() > 1 else serial
