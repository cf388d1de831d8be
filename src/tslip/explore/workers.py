"""The explorer's threads and its worker process, none of which outlives the server.

A page's work (its gait, its limits and runner, its stability map) and the
export routes' gait searches run in :class:`Lane` threads: daemon threads,
so that a server told to stop does not wait for a search in flight (a
first-run compile takes a minute; ``concurrent.futures``' thread pools are
joined at exit, which kept a server asked to stop by SIGINT running).

The robustness limits run in one worker process for all pages (numba's
kernels hold Python's GIL, and in a thread a search would stall the
server's event loop): :func:`limit`. The worker is a watched, SIGINT-deaf
worker of :func:`tslip.sweeps._pool.lasting_pool`, as the study pool's
workers are, so it dies with the server whatever ends it (SIGTERM, SIGINT,
SIGKILL): on Linux the kernel kills it when the thread that started it ends
(``PR_SET_PDEATHSIG``), elsewhere it polls its parent. That thread is
:data:`_OWNER`'s, which lives as long as the server, not a page's thread,
which ends when its tab closes. :func:`stop_worker` ends it at once (the
server does on its way out).
"""

from __future__ import annotations

import logging
import os
import queue
import threading
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from ..sweeps import _pool
from . import compute

__all__ = ["Lane", "limit", "prestart", "stop_worker"]

log = logging.getLogger("tslip.explore")


class Lane:
    """One daemon thread that runs the calls submitted to it in order.

    :meth:`submit` returns a :class:`concurrent.futures.Future`;
    :meth:`shutdown` cancels what has not started and ends the thread after
    the call in flight (without waiting for it).
    """

    def __init__(self, name: str) -> None:
        self._queue: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._closed = False
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def submit(self, fn: Callable[..., Any], *args: Any) -> Future[Any]:
        """Run ``fn(*args)`` in this lane's thread after what was submitted before."""
        future: Future[Any] = Future()
        if self._closed:
            future.cancel()
        else:
            self._queue.put((future, fn, args))
        return future

    def shutdown(self) -> None:
        """Cancel the calls not started and end the thread once the current call returns."""
        self._closed = True
        while True:
            try:
                item = self._queue.get_nowait()
            except queue.Empty:
                break
            if item is not None:
                item[0].cancel()
        self._queue.put(None)

    def _run(self) -> None:
        while (item := self._queue.get()) is not None:
            future, fn, args = item
            if not future.set_running_or_notify_cancel():
                continue
            try:
                future.set_result(fn(*args))
            except BaseException as exc:  # noqa: BLE001 - handed to the future's owner
                future.set_exception(exc)


#: Starts the worker process (see the module's docstring): a thread as long-lived as the
#: server. Idle, it is ended at once by the interpreter's exit.
_OWNER = Lane("tslip-limit-owner")
_WORKER: list[ProcessPoolExecutor] = []
_LOCK = threading.Lock()


def _start() -> ProcessPoolExecutor:
    """A new worker process, started now, in this (the owner's) thread.

    Returns once the worker runs its initializer (it then dies with the
    server); until then it is importing (seconds), and a server killed in
    that time leaves it to notice alone, when its imports end.
    """
    pool = _pool.lasting_pool(1)
    pid = pool.submit(os.getpid).result()  # a pool's process starts in its first submit
    log.info("tslip explore: worker process %d started (robustness limits)", pid)
    return pool


def _worker() -> ProcessPoolExecutor:
    with _LOCK:
        if not _WORKER:
            _WORKER.append(_OWNER.submit(_start).result())
        return _WORKER[0]


def prestart() -> None:
    """Start the worker process now, in the background (its imports overlap the page's)."""
    threading.Thread(target=_worker, name="tslip-limit-prestart", daemon=True).start()


def limit(gait: Any, kind: str) -> float:
    """:func:`compute.limit` in the worker process (a new one if the old one died)."""
    pool = _worker()
    try:
        return float(pool.submit(compute.limit, gait, kind).result())
    except BrokenProcessPool:
        with _LOCK:
            if _WORKER and _WORKER[0] is pool:
                _WORKER.clear()
        raise


def stop_worker() -> None:
    """End the worker process now (the searches in it are dropped)."""
    with _LOCK:
        pools = list(_WORKER)
        _WORKER.clear()
    for pool in pools:
        _pool.stop_workers(pool)
