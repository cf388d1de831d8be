"""Worker processes that die with their parent and stay quiet on Ctrl-C.

:func:`process_pool` is the one way this package starts worker processes
(``tslip study`` and ``tslip reproduce``). Each worker

* is forked, on Linux, from a fork server that imported the tasks' modules
  once (:func:`process_pool`'s ``preload``), so that starting a worker costs
  a fork, not an interpreter start and the imports (about a second of CPU
  each); elsewhere it is spawned,
* runs numba single-threaded (one process per core, no nested threads),
* ignores SIGINT from its first instruction (it is spawned with SIGINT
  ignored, so not even a Ctrl-C during its seconds of start-up prints a
  traceback): Ctrl-C reaches the whole process group, and only the parent
  decides what to do (it stops the workers itself),
* dies with its parent, whatever killed it (SIGKILL included): on Linux the
  kernel kills it at once (``PR_SET_PDEATHSIG``), elsewhere a daemon thread
  polling ``os.getppid()`` ends it within :data:`WATCH_SECONDS` or so; no
  worker is left behind as an orphan. A forked worker's parent is the fork
  server, which ends when this process does (it reads end-of-file on a pipe
  only this process holds), and its workers with it. (Workers start in
  ``submit``, so on Linux spawned workers also end with the thread that
  submitted first: use a pool from one thread.)
* can report progress to the parent through a queue (:func:`notify`).

Leaving the ``with`` block normally waits for the submitted work and the
workers' exit; leaving it by an exception, or a Ctrl-C during that wait,
cancels what has not started and terminates the workers instead of waiting
for them.
"""

from __future__ import annotations

import ast
import concurrent.futures as cf
import ctypes
import multiprocessing as mp
import os
import signal
import sys
import threading
import time
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

__all__ = ["WATCH_SECONDS", "check_main_guard", "lasting_pool", "notify", "prestart",
           "process_pool", "progress_queue", "stop_workers"]

#: How often a worker checks that its parent is alive [s].
WATCH_SECONDS = 0.5

_queue: Any = None  # the progress queue, in a worker


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, owned by someone else
        return True
    return True


def _release_fork_server() -> None:  # pragma: no cover - runs in worker processes
    """Close a forked worker's copy of the fork server's keep-alive pipe.

    The server runs until every holder of that pipe's write end has closed
    it; each forked child gets a copy (to start processes of its own, which
    workers do not). Closed here, the owner's death ends the server, and the
    kernel then ends its workers (``PR_SET_PDEATHSIG``).
    """
    from multiprocessing import forkserver

    fd = getattr(forkserver._forkserver, "_forkserver_alive_fd", None)
    if fd is None:  # spawned
        return
    try:
        os.close(fd)
    except OSError:
        pass
    setattr(forkserver._forkserver, "_forkserver_alive_fd", None)  # noqa: B010 - private


def _die_with_parent(owner: int) -> None:  # pragma: no cover - runs in worker processes
    """End this process when its parent ends (``owner``, or the fork server serving it).

    Linux: the kernel sends SIGKILL on the parent's death (``PR_SET_PDEATHSIG``),
    immediate even while a compiled kernel holds the GIL. Everywhere: a daemon
    thread polls ``os.getppid()`` (a worker is re-parented when its parent dies).
    """
    parent = os.getppid()  # owner (spawned) or the fork server, which ends with owner
    _release_fork_server()
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGKILL, 0, 0, 0)  # 1 = PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            pass
    if os.getppid() != parent or not _alive(owner):  # it died before we were watching
        os._exit(1)

    def watch() -> None:
        while True:
            time.sleep(WATCH_SECONDS)
            if os.getppid() != parent or not _alive(owner):
                os._exit(1)

    threading.Thread(target=watch, daemon=True, name="tslip-parent-watch").start()


def _init_worker(parent: int, queue: Any) -> None:  # pragma: no cover - in workers
    global _queue
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # already inherited when submit started us
    _die_with_parent(parent)
    _queue = queue
    # A worker starts no processes. Under a "fork" start method numba guards its threading
    # layer's start with a named semaphore (multiprocessing.RLock), which a terminated
    # worker (Ctrl-C: stop_workers) never unlinks: "leaked semaphore objects" at exit.
    mp.set_start_method("spawn", force=True)
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


def _is_main_test(node: ast.expr) -> bool:
    """``__name__ == "__main__"`` (either way round)."""
    if not (isinstance(node, ast.Compare) and len(node.ops) == 1
            and isinstance(node.ops[0], ast.Eq)):
        return False
    sides = [node.left, node.comparators[0]]
    return (any(isinstance(x, ast.Name) and x.id == "__name__" for x in sides)
            and any(isinstance(x, ast.Constant) and x.value == "__main__" for x in sides))


def check_main_guard() -> None:
    """Refuse, in one line, to start workers that would re-run an unguarded script.

    Workers are spawned or forked from a fork server, and either imports
    the main script again (Python's ``multiprocessing``): a script that runs
    a study at its top level, with no ``if __name__ == "__main__":`` block, would start the study
    again in every worker, which Python stops with a ``BrokenProcessPool``
    deep in a traceback. Interactive sessions, ``python -c`` and
    ``python -m package`` (a ``__main__`` module is not re-imported) pass.
    """
    main = sys.modules.get("__main__")
    spec_name = getattr(getattr(main, "__spec__", None), "name", None)
    path = getattr(main, "__file__", None)
    if not path or (spec_name or "").endswith("__main__"):
        return
    try:
        tree = ast.parse(Path(path).read_text(encoding="utf-8"))
    except (OSError, SyntaxError, ValueError):
        return  # not a readable Python source: leave it to multiprocessing
    if not any(isinstance(n, ast.If) and _is_main_test(n.test) for n in tree.body):
        raise RuntimeError(
            f"worker processes import the script {path!r} again, and it has no "
            "`if __name__ == \"__main__\":` block: put the code that runs the study "
            "under one, or pass workers=1")


def _context(preload: Iterable[str] | None = None) -> Any:
    """Fork server on Linux (started once per process, with ``preload`` imported), else spawn.

    Not plain fork: this process may run numba's and BLAS's threads, and a
    forked copy of a threaded process can deadlock. The fork server is a
    fresh single-threaded interpreter; only the ``preload`` given before it
    starts counts (it then stays, serving every later pool of this process).
    """
    if not sys.platform.startswith("linux") or "forkserver" not in mp.get_all_start_methods():
        return mp.get_context("spawn")
    ctx = mp.get_context("forkserver")
    from multiprocessing import forkserver

    started = getattr(forkserver._forkserver, "_forkserver_pid", None) is not None
    if preload is not None and not started:
        ctx.set_forkserver_preload(["__main__", *preload])  # "__main__": as spawn does
    return ctx


def prestart(preload: Iterable[str]) -> None:
    """Start the fork server now, importing ``preload`` (Linux; elsewhere nothing).

    Its imports (a few seconds of CPU) then overlap this process's own
    set-up instead of delaying the first worker. Nothing for a script
    without a main guard (:func:`check_main_guard`).
    """
    try:
        check_main_guard()
    except RuntimeError:
        return  # refused by process_pool if the work turns out parallel
    ctx = _context(list(preload))
    if ctx.get_start_method() == "forkserver":
        from multiprocessing import forkserver

        with _sigint_ignored():  # no traceback from a Ctrl-C during its imports
            forkserver.ensure_running()


@contextmanager
def process_pool(workers: int, queue: Any = None,
                 preload: Iterable[str] = ()) -> Iterator[cf.ProcessPoolExecutor]:
    """A process pool of ``workers`` watched, SIGINT-deaf workers.

    ``queue`` (from :func:`progress_queue`) receives the workers' :func:`notify`
    calls. ``preload``: modules the fork server imports once for every
    worker (the tasks' modules; see :func:`_context`). Raises
    ``RuntimeError`` up front for a script without a main guard
    (:func:`check_main_guard`).
    """
    check_main_guard()
    pool = _Executor(max_workers=workers, mp_context=_context(list(preload)),
                     initializer=_init_worker, initargs=(os.getpid(), queue))
    try:
        yield pool
        pool.shutdown(wait=True)  # a Ctrl-C here too stops the workers (a slow starter)
    except BaseException:
        stop_workers(pool)
        raise


def _init_lasting(parent: int) -> None:  # pragma: no cover - in workers
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _die_with_parent(parent)


def lasting_pool(workers: int) -> cf.ProcessPoolExecutor:
    """A pool of watched, SIGINT-deaf, spawned workers that lasts until it is shut down.

    For a server (``tslip explore``) rather than one run's ``with`` block
    (:func:`process_pool`). Its workers start in its first ``submit`` calls and
    on Linux die with the thread that made those calls (``PR_SET_PDEATHSIG``
    tracks a thread): submit first from a thread that lives as long as the
    pool should. End it with :func:`stop_workers`.
    """
    return _Executor(max_workers=workers, mp_context=mp.get_context("spawn"),
                     initializer=_init_lasting, initargs=(os.getpid(),))


def progress_queue() -> Any:
    """A queue that :func:`process_pool` workers can :func:`notify` through."""
    return _context().Queue()
