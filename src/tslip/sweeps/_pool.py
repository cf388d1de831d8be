"""Worker processes that die with their parent and stay quiet on Ctrl-C.

:func:`process_pool` is the one way this package starts worker processes
(``tslip study`` and ``tslip reproduce``). Each worker

* runs numba single-threaded (one process per core, no nested threads),
* ignores SIGINT from its first instruction (it is spawned with SIGINT
  ignored, so not even a Ctrl-C during its seconds of start-up prints a
  traceback): Ctrl-C reaches the whole process group, and only the parent
  decides what to do (it stops the workers itself),
* dies with its parent, whatever killed it (SIGKILL included): on Linux the
  kernel kills it at once (``PR_SET_PDEATHSIG``), elsewhere a daemon thread
  polling ``os.getppid()`` ends it within :data:`WATCH_SECONDS` or so; no
  worker is left behind as an orphan. (Workers start in ``submit``, so on
  Linux they also end with the thread that submitted first: use a pool from
  one thread.)
* can report progress to the parent through a queue (:func:`notify`).

Leaving the ``with`` block normally waits for the submitted work; leaving it
by an exception (Ctrl-C included) cancels what has not started and
terminates the workers instead of waiting for them.
"""

from __future__ import annotations

import concurrent.futures as cf
import ctypes
import multiprocessing as mp
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

__all__ = ["WATCH_SECONDS", "notify", "process_pool", "progress_queue", "stop_workers"]

#: How often a worker checks that its parent is alive [s].
WATCH_SECONDS = 0.5

_queue: Any = None  # the progress queue, in a worker


def _die_with_parent(parent: int) -> None:  # pragma: no cover - runs in worker processes
    """End this process when ``parent`` ends.

    Linux: the kernel sends SIGKILL on the parent's death (``PR_SET_PDEATHSIG``),
    immediate even while a compiled kernel holds the GIL. Everywhere: a daemon
    thread polls ``os.getppid()`` (a worker is re-parented when its parent dies).
    """
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGKILL, 0, 0, 0)  # 1 = PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            pass
    if os.getppid() != parent:  # it died before we were watching
        os._exit(1)

    def watch() -> None:
        while True:
            time.sleep(WATCH_SECONDS)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=watch, daemon=True, name="tslip-parent-watch").start()


def _init_worker(parent: int, queue: Any) -> None:  # pragma: no cover - in workers
    global _queue
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # already inherited when submit started us
    _die_with_parent(parent)
    _queue = queue
    import numba

    numba.set_num_threads(1)  # one process per core; no nested threads


def notify(n: int = 1) -> None:
    """In a worker: tell the parent that ``n`` more points are done (else nothing)."""
    if _queue is not None:
        _queue.put(n)


def stop_workers(pool: cf.ProcessPoolExecutor) -> None:
    """Cancel pending work and terminate the pool's workers now (no waiting)."""
    procs = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        if p.is_alive():
            p.terminate()
    for p in procs:
        p.join(timeout=5)


@contextmanager
def _sigint_ignored() -> Iterator[None]:
    """Ignore SIGINT in this block; processes started in it inherit that."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


class _Executor(cf.ProcessPoolExecutor):
    """Starts its workers (which happens in ``submit``) with SIGINT ignored."""

    def submit(self, fn, /, *args, **kwargs):  # noqa: ANN001, ANN002, ANN003, ANN201
        with _sigint_ignored():
            return super().submit(fn, *args, **kwargs)


@contextmanager
def process_pool(workers: int, queue: Any = None) -> Iterator[cf.ProcessPoolExecutor]:
    """A spawn-context process pool of ``workers`` watched, SIGINT-deaf workers.

    ``queue`` (from :func:`progress_queue`) receives the workers' :func:`notify`
    calls.
    """
    ctx = mp.get_context("spawn")  # numba threads and fork do not mix
    pool = _Executor(max_workers=workers, mp_context=ctx, initializer=_init_worker,
                     initargs=(os.getpid(), queue))
    try:
        yield pool
    except BaseException:
        stop_workers(pool)
        raise
    pool.shutdown(wait=True)


def progress_queue() -> Any:
    """A queue that :func:`process_pool` workers can :func:`notify` through."""
    return mp.get_context("spawn").Queue()
