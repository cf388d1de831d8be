"""The first run: compile each kernel family once, and say so while it happens.

From an empty numba cache, a study or reproduction spends most of its first
minute compiling. Two things make that bearable:

* :func:`warm` compiles (or loads from numba's cache) every kernel family a
  study's tasks use, by running a tiny computation of each through the
  public code path, so each kernel is compiled with the very signatures the
  tasks call it with. The fork server runs it before it forks the workers
  (it imports :mod:`._prewarm`, which calls it): each kernel is then
  compiled in one process only, and every worker starts with all kernels in
  memory.
* :func:`announce`, in the process the user watches, names the families
  that are not cached yet (from the cache folders alone:
  :func:`tslip._kernel_cache.missing_families`) and reports each as its
  cache entries appear, whichever process compiles it. A warm run says
  nothing.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from .. import _kernel_cache

if TYPE_CHECKING:
    from rich.console import Console

__all__ = ["WORKLOADS", "announce", "warm", "warm_in_background", "warm_missing"]

#: Seconds between two looks at the cache folders while compiling.
POLL_SECONDS = 0.5
#: Seconds between two renewals of the updating line of the time spent compiling (a
#: terminal only; the issue asked for at least one every 10 s).
STATUS_SECONDS = 1.0


def _study_point() -> None:
    """A tiny study's tasks, here: gait solves by continuation and every point analysis.

    Not :func:`tslip.sweeps.run.run_study`: its serial path sets numba's
    thread count, which starts numba's thread pool, and a fork server must
    not hold threads when it forks.
    """
    import dataclasses

    from . import catalogue
    from .run import StudyJob

    spec = catalogue.study("leg_damping", "tiny")
    job = StudyJob(dataclasses.replace(spec, analyses=("floquet", "robustness", "stride")),
                   None, writes=False)
    ready = job.start()
    while ready:
        task = ready.pop()
        ready.extend(job.on_done(task, task.fn(*task.args, None)))


def _recorded() -> None:
    """The single-gait figures' and Table 6.1's computations (recorded runs, disturbances)."""
    from . import catalogue

    catalogue.fig_impulse_linearisation()
    catalogue.fig_pitch_disturbance("table2.1")
    catalogue.fig_step_down()
    catalogue.fig_velocity_angle()
    catalogue.fig_friction()
    from .reproduce import _table61_gait, pitch_rate_variants

    pitch_rate_variants(_table61_gait())  # disturbances in flight: batches of runs


def _biped() -> None:
    """A biped stride (one loop serves both Runge-Kutta pairs) and what Appendix E
    calls from Python besides a run."""
    from ..biped import BipedParams, BipedState, simulate
    from ..biped.dynamics import controller_references, momentum

    params, state = BipedParams(), BipedState.thesis()
    simulate(params, state, 1)
    momentum(params, state)
    controller_references(params, 0.5)


def cache_dirs(packages: tuple[str, ...] = ("simulation", "biped")) -> dict[str, Path]:
    """numba's cache folder of the kernels of ``packages`` (imports them; compiles nothing).

    Here, not in :mod:`tslip._kernel_cache`, which every kernel module imports:
    the code hash follows imports, so a kernel module importing both models'
    kernels would key every TSLIP result on the biped's code too.
    """
    dirs = {}
    if "simulation" in packages:
        from ..simulation import _stride

        dirs["simulation"] = Path(_stride.stride._cache.cache_path)  # type: ignore[attr-defined]
    if "biped" in packages:
        from ..biped import _stride as biped_stride

        dirs["biped"] = Path(biped_stride._integrate._cache.cache_path)
    return dirs


def _missing(packages: tuple[str, ...]) -> tuple[dict[str, Path], str, list[str]]:
    """The cache folders of ``packages``, the sources' digest and the families not cached.

    No family is missing when the folders cannot be read (numba then compiles
    where a kernel is first used, as without this module).
    """
    try:
        dirs = cache_dirs(packages)
        digest = _kernel_cache.sources_hash()
        return dirs, digest, _kernel_cache.missing_families(dirs, digest)
    except (OSError, AttributeError, ImportError):
        return {}, "", []


#: How to compile each family of :data:`tslip._kernel_cache.FAMILIES`: a tiny run of it.
WORKLOADS: dict[str, Callable[[], None]] = {
    "TSLIP gait search and analyses": _study_point,
    "TSLIP recorded runs": _recorded,
    "biped": _biped,
}


def warm(families: list[str]) -> None:
    """Compile or load the kernels of ``families`` by running each one's workload.

    Never raises: a family that fails here is compiled where it is first used.
    Starts no threads (no workload runs a parallel kernel): it runs in the
    fork server.
    """
    for name in families:
        try:
            WORKLOADS[name]()
        except Exception:  # noqa: BLE001, S110 - the task that needs it will say why
            pass


def warm_missing(packages: tuple[str, ...] = ("simulation", "biped")) -> list[str]:
    """:func:`warm` the families of ``packages`` not in numba's cache yet; those families."""
    missing = _missing(packages)[2]
    warm(missing)
    return missing


def warm_in_background(packages: tuple[str, ...]) -> threading.Thread:
    """:func:`warm_missing` of ``packages`` in a daemon thread of this process.

    ``tslip reproduce`` compiles the biped's families here while the fork
    server compiles the TSLIP's (first in :data:`tslip._kernel_cache.FAMILIES`):
    the two share no cached kernel, so the fork server then loads the biped's
    from disk instead of compiling them after the TSLIP's, on the second core.
    """
    thread = threading.Thread(target=warm_missing, args=(packages,), daemon=True,
                              name="tslip-warm")
    thread.start()
    return thread


@contextmanager
def announce(echo: Callable[[str], None], packages: tuple[str, ...] = ("simulation", "biped"),
             terminal: Console | None = None) -> Iterator[list[str]]:
    """Say which kernel families of ``packages`` are not compiled yet, and each as it gets cached.

    Prints nothing when every family is cached. Yields the missing families.
    With ``terminal`` (the console ``echo`` prints to) a terminal, one updating
    line below the others shows the seconds spent compiling, renewed every
    :data:`STATUS_SECONDS`, until the last family is cached; on anything else
    (a pipe, a file, a log) nothing is added.
    """
    dirs, digest, missing = _missing(packages)
    if not missing:
        yield []
        return
    echo(f"first run: compiling {len(missing)} kernel families not in numba's cache yet "
         f"({', '.join(missing)}); later runs load them")
    t0 = time.perf_counter()
    stop = threading.Event()
    families = {k: _kernel_cache.FAMILIES[k] for k in missing}
    status = (terminal.status(_compiling(len(missing), len(missing), 0.0))
              if terminal is not None and terminal.is_terminal else None)

    def watch() -> None:
        left = list(missing)
        shown = 0.0
        while left and not stop.wait(POLL_SECONDS):
            now = _kernel_cache.missing_families(dirs, digest, families)
            for name in [f for f in left if f not in now]:
                left.remove(name)
                echo(f"  compiled {name} ({len(missing) - len(left)}/{len(missing)}, "
                     f"{time.perf_counter() - t0:.0f} s)")
            elapsed = time.perf_counter() - t0
            if status is not None and left and elapsed - shown >= STATUS_SECONDS:
                status.update(_compiling(len(left), len(missing), elapsed))
                shown = elapsed
        if status is not None:
            status.stop()

    if status is not None:
        status.start()
    thread = threading.Thread(target=watch, daemon=True, name="tslip-compile-watch")
    thread.start()
    try:
        yield missing
    finally:
        stop.set()
        thread.join(timeout=2 * POLL_SECONDS)
        if status is not None:
            status.stop()


def _compiling(left: int, total: int, seconds: float) -> str:
    """The updating line: ``compiling kernels: 2 of 4 families left, 37 s``."""
    return f"compiling kernels: {left} of {total} famil{'y' if total == 1 else 'ies'} left, " \
           f"{seconds:.0f} s"
