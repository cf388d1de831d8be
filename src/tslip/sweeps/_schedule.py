"""One scheduler: tasks on one worker pool, largest first, results handled as they arrive.

Every unit of work of ``tslip study`` and ``tslip reproduce`` (a line's gait
solve, a chunk of points' analyses, a single-gait figure, a piece of
Appendix E) is a :class:`Task`: a picklable function, its arguments, and an
estimate of its cost in seconds. :func:`run_tasks` runs them

* largest first: the ready task with the highest ``priority`` (its cost
  plus the work that waits for it) goes next, and at most one task more than
  the pool has workers is handed to it (one queued, so that no worker waits
  while this process handles a result), so a large task that becomes ready
  later (the next line of a 2-D continuation) is not queued behind small ones;
* on one pool (:func:`tslip.sweeps._pool.process_pool`) of
  :func:`choose_workers` processes, or serially in this process when the
  work is too small to pay for starting them (numba on one thread then, as
  in the workers: the tasks' small batches are slower on more);
* with ``on_done(task, result)`` called here as each result arrives; it
  returns the tasks that result made ready (e.g. the next line, seeded
  with this one's gaits).

Tasks are pure functions of their arguments, so the results do not depend
on the order or on the worker count: a serial run and a parallel one end
bit-identical. A task function takes ``tick`` last: ``tick(n)`` reports
``n`` more points done (in a worker it goes through the pool's progress
queue, :func:`tslip.sweeps._pool.notify`).

Ctrl-C: the pool's workers are stopped (not waited for) and the
``KeyboardInterrupt`` propagates; what the tasks cached stays cached.
"""

from __future__ import annotations

import asyncio
import concurrent.futures as cf
import heapq
import itertools
import os
import queue as queue_mod
import threading
import time
from collections.abc import Callable, Hashable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

from . import _pool

__all__ = ["STARTUP_SECONDS", "Task", "choose_workers", "own_seconds", "run_tasks"]

#: Seconds to start the workers (the fork server importing the task modules,
#: each worker loading the compiled kernels it uses) on the project's 2-core
#: machine with a warm compile cache: a pool of 2 took 2.3 s to run its first
#: tasks, and a worker's first gait search loads kernels for 0.4 s. Below a few
#: of these the work runs serially (:func:`choose_workers`).
STARTUP_SECONDS = 2.5


@dataclass(frozen=True)
class Task:
    """A unit of work: ``fn(*args, tick)``, about ``cost`` seconds.

    ``priority`` orders the ready tasks (highest first; default ``cost``):
    give a task the cost of the work that waits for it too, so that the
    longest chain starts first.
    """

    key: tuple[Any, ...]
    fn: Callable[..., Any]
    args: tuple[Any, ...] = ()
    cost: float = 1.0
    priority: float | None = None
    meta: dict[str, Any] = field(default_factory=dict, compare=False)

    @property
    def rank(self) -> float:
        return self.cost if self.priority is None else self.priority


#: ``on_done(task, result)``: the tasks the result made ready.
OnDone = Callable[[Task, Any], Iterable[Task]]


def choose_workers(cost: float, workers: int | None = None, width: int | None = None) -> int:
    """Worker processes for ``cost`` seconds of work.

    ``workers`` given: that many (the caller's choice). Otherwise up to all
    cores, but parallel only when each worker gets at least
    ``4 * STARTUP_SECONDS`` of work (the start-up then costs a quarter of
    what it saves at most): 1, serial, when start-up would dominate.
    ``width`` is how many tasks can run at once at most.
    """
    if workers is not None:
        if workers < 1:
            raise ValueError(f"workers must be >= 1, got {workers}")
        n = workers
    else:
        per_worker = 4 * STARTUP_SECONDS
        cores = os.cpu_count() or 1
        n = min(cores, int(cost // per_worker) or 1) if per_worker > 0 else cores
    if width is not None:
        n = min(n, max(1, width))
    return n


@contextmanager
def _one_thread() -> Iterator[None]:
    """Numba on one thread for the block, as in the pool's workers (one process per core)."""
    import numba

    old = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(old)


def _timed(fn: Callable[..., Any], args: tuple[Any, ...],
           tick: Callable[[int], None] | None) -> tuple[Any, float, float]:
    """Run ``fn(*args, tick)``; its result and its CPU and wall seconds (in workers too)."""
    c0, w0 = time.process_time(), time.perf_counter()
    out = fn(*args, tick)
    return out, time.process_time() - c0, time.perf_counter() - w0


#: ``key -> (cpu_seconds, wall_seconds, parent)`` of each task run (:func:`run_tasks`).
Timing = Mapping[Hashable, tuple[float, float, Hashable]]


def own_seconds(timing: Timing, prefix: tuple[Any, ...]) -> float:
    """Wall seconds of the tasks whose key starts with ``prefix``.

    The time spent on one study or figure, however its tasks interleaved with
    others' on the pool (not the time since the pool started).
    """
    n = len(prefix)
    return sum(wall for key, (_, wall, _) in timing.items()
               if isinstance(key, tuple) and key[:n] == prefix)


def run_tasks(tasks: Iterable[Task], on_done: OnDone, workers: int = 1,
              tick: Callable[[int], None] | None = None,
              timing: dict[Hashable, tuple[float, float, Hashable]] | None = None,
              scheduler: str | None = None, preload: Iterable[str] = ()) -> None:
    """Run ``tasks`` and every task their results make ready; see the module docstring.

    ``workers``: 1 runs each task here; more starts that many processes.
    ``tick(n)``: progress, here, as the tasks report points done.
    ``timing``: filled with ``key -> (cpu_seconds, wall_seconds, parent)`` of each
    task, ``parent`` the key of the task whose result made it ready (or None).
    ``scheduler``: address of a Dask cluster to run the tasks on instead
    (``workers`` is then ignored; the tasks cannot report progress).
    ``preload``: modules of tasks made ready later, for the workers to import
    once (:func:`tslip.sweeps._pool.process_pool`); the first tasks' modules
    are imported anyway.
    """
    order = itertools.count()
    ready: list[tuple[float, int, Task]] = []
    parent: dict[Hashable, Hashable] = {}

    def push(new: Iterable[Task], by: Hashable = None) -> None:
        for t in new:
            parent[t.key] = by
            heapq.heappush(ready, (-t.rank, next(order), t))

    def finish(task: Task, packed: tuple[Any, float, float]) -> None:
        out, cpu, wall = packed
        if timing is not None:
            timing[task.key] = (cpu, wall, parent.get(task.key))
        push(on_done(task, out), task.key)

    push(tasks)
    if scheduler is not None:
        _run_dask(scheduler, ready, finish)
        return
    if workers <= 1:
        with _one_thread():
            while ready:
                task = heapq.heappop(ready)[2]
                finish(task, _timed(task.fn, task.args, tick))
        return
    if not ready:
        return
    modules = dict.fromkeys([*(t.fn.__module__ for _, _, t in ready), *preload])
    queue = _pool.progress_queue()
    try:
        with _pool.process_pool(workers, queue, preload=modules) as pool:
            running: dict[cf.Future, Task] = {}
            while ready or running:
                while ready and len(running) <= workers:
                    task = heapq.heappop(ready)[2]
                    running[pool.submit(_timed, task.fn, task.args, None)] = task
                done = cf.wait(running, timeout=0.2, return_when=cf.FIRST_COMPLETED).done
                _drain(queue, tick)
                for fut in done:
                    finish(running.pop(fut), fut.result())
            _drain(queue, tick)
    finally:
        queue.close()


#: Tasks submitted to a Dask cluster at a time, per worker thread (a newly joined worker
#: gets work when the next one is submitted).
DASK_IN_FLIGHT = 4


def _run_dask(address: str, ready: list[tuple[float, int, Task]],
              finish: Callable[[Task, tuple[Any, float, float]], None]) -> None:
    """:func:`run_tasks` on a Dask cluster: ready tasks submitted largest first, at most
    :data:`DASK_IN_FLIGHT` per worker thread at a time (the scheduler and the client hold
    every submitted task's arguments and result until it is collected: submitting a
    4500-chunk viability map at once took 4 GB here)."""
    check_scheduler(address)  # a Client that fails to connect can hang when collected
    from dask.distributed import Client, wait

    with Client(address) as client:
        running: dict[Any, Task] = {}
        limit = DASK_IN_FLIGHT * max(1, sum(client.nthreads().values()))
        try:
            while ready or running:
                while ready and len(running) < limit:
                    task = heapq.heappop(ready)[2]
                    running[client.submit(_timed, task.fn, task.args, None, pure=False)] = task
                for fut in wait(list(running), return_when="FIRST_COMPLETED").done:
                    finish(running.pop(fut), fut.result())
        except BaseException:
            client.cancel(list(running))
            raise


def check_scheduler(address: str, seconds: float = 10.0,
                    echo: Callable[[str], object] | None = None) -> None:
    """Refuse a Dask scheduler ``address`` that is empty, malformed or does not answer
    within ``seconds``, with one ``ValueError`` line naming ``--scheduler``.

    ``echo`` (optional) announces the wait in one line. The check asks the server its
    ``identity`` over one bare connection, closed before returning, and refuses a server
    that is not a scheduler (e.g. a worker's address). It does not build a
    ``distributed.Client``: a ``Client`` whose constructor fails (an address such as
    ``foo``) closes itself when collected, and that close can wait forever on its event
    loop's lock (it hung a CI run for 900 s).
    """
    if not address.strip():
        raise ValueError("--scheduler is empty; give a Dask scheduler's address, e.g. "
                         "tcp://127.0.0.1:8786")
    try:
        from distributed.comm import connect
    except ImportError:
        raise ValueError("--scheduler needs Dask: pip install 'tslip[dask]'") from None
    if echo is not None:
        echo(f"connecting to the Dask scheduler at {address} (giving up after {seconds:g} s)")

    async def identity() -> object:
        comm = await connect(address, timeout=seconds)
        try:
            await comm.write({"op": "identity", "reply": True})
            answer = await asyncio.wait_for(comm.read(), seconds)
        finally:
            await comm.close()
        return answer.get("type") if isinstance(answer, dict) else type(answer).__name__

    try:
        kind = _in_own_loop(identity, 2 * seconds + 5)
    except (OSError, TimeoutError) as exc:
        why = " ".join(str(exc).split()) or type(exc).__name__
        raise ValueError(f"--scheduler {address!r}: no Dask scheduler answered within "
                         f"{seconds:g} s ({why})") from None
    except Exception as exc:  # noqa: BLE001 - Dask's refusal of the address, whatever its type
        why = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise ValueError(f"--scheduler {address!r} is not a Dask scheduler's address "
                         f"({type(exc).__name__}: {why})") from None
    if kind != "Scheduler":
        raise ValueError(f"--scheduler {address!r} is not a Dask scheduler's address "
                         f"(it answered as {str(kind)[:40]!r})")


def _in_own_loop(coroutine: Callable[[], Any], seconds: float) -> Any:
    """``coroutine()`` run to its end on a fresh event loop in a thread of its own (this
    thread may already run a loop, where ``asyncio.run`` refuses); its result or its
    exception, or ``TimeoutError`` after ``seconds``."""
    box: dict[str, Any] = {}

    def run() -> None:
        try:
            box["result"] = asyncio.run(coroutine())
        except BaseException as exc:  # noqa: BLE001 - handed to the caller
            box["error"] = exc

    thread = threading.Thread(target=run, name="tslip-scheduler-check", daemon=True)
    thread.start()
    thread.join(seconds)
    if thread.is_alive():
        raise TimeoutError(f"no answer within {seconds:g} s")
    if "error" in box:
        raise box["error"]
    return box["result"]


def _drain(queue: Any, tick: Callable[[int], None] | None) -> None:
    n = 0
    try:
        while True:
            n += queue.get_nowait()
    except (queue_mod.Empty, OSError, ValueError):
        pass
    if n and tick is not None:
        tick(n)
