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
* :func:`warm` holds a claim on each family while it runs the family's
  workload (an exclusive lock on a file beside numba's cache,
  :func:`claim`), so that two processes warming at once (``tslip
  reproduce``'s own process and its fork server: :func:`warm_in_background`)
  never compile the same family: the second waits for the first and then
  loads the kernels from the cache.
* :func:`announce`, in the process the user watches, names the families
  that are not cached yet (from the cache folders alone:
  :func:`tslip._kernel_cache.missing_families`) and reports each as its
  cache entries appear, whichever process compiles it. A warm run says
  nothing.
"""

from __future__ import annotations

import copy
import os
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from .. import _kernel_cache

if TYPE_CHECKING:
    from rich.console import Console

    from ..gait import Gait

__all__ = ["MAIN_PROCESS_FAMILIES", "WORKLOADS", "announce", "claim", "ensure", "warm",
           "warm_in_background",
           "warm_missing"]

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


def _strides() -> None:
    """A run of strides as the gait search's analyses and the recorded runs' batches run
    one (:func:`tslip.simulation._packed.run`: the run-of-strides kernel and the stride
    kernel it calls, with the signatures every caller uses: float64 arrays, an int)."""
    import numpy as np

    from ..model import preset
    from ..model._pack import pack_params
    from ..simulation import IntegratorOptions, _packed

    td = _packed.touchdown(np.array([1.05, 0.0, 5.0, -0.3, 0.0]), 0.0)
    _packed.run(pack_params(preset("table2.1")), IntegratorOptions().packed(), td, 2,
                np.empty(0), np.zeros(1))


#: The Table 2.1 and Table 6.1 gaits as :func:`tslip.find_gait` found them (2026-12-06):
#: each preset's changes (the solved ``alpha_r``, and Table 6.1's ``alphad_ref``) and the
#: touch-down state ``(beta, phi, xd, yd, phid)``. The recorded runs' workload
#: (:func:`_recorded`) runs from these instead of searching the gaits, so that it needs
#: none of the gait search's kernels: only the strides, which the other process compiles
#: first (:data:`NEEDS`). Only the kernels' signatures matter here; a test checks that
#: these are still gaits (one stride maps each to itself).
STORED_GAITS: dict[str, tuple[dict[str, float], tuple[float, ...]]] = {
    "table2.1": ({"alpha_r": 0.7934842721906721},
                 (1.05, -0.00418810169145456, 4.99840801578607, -0.12616381305893787,
                  -0.033195744405056904)),
    "table6.1": ({"alpha_r": 1.0329949767502447, "alphad_ref": 2.3201709832486657},
                 (0.93, 0.2895262019971058, 1.8983614664924113, -0.07889069993846931,
                  -0.11983685057850357)),
}


def stored_gait(name: str) -> Gait:
    """The gait of preset ``name`` from :data:`STORED_GAITS`, without a search."""
    import dataclasses

    from ..gait import Gait
    from ..model import TouchdownState, preset

    changes, (beta, phi, xd, yd, phid) = STORED_GAITS[name]
    p = preset(name)
    if "alphad_ref" in changes:
        p = dataclasses.replace(p, controller=dataclasses.replace(  # type: ignore[call-arg]
            p.controller, alphad_ref=changes["alphad_ref"]))
    p = dataclasses.replace(p, alpha_r=changes["alpha_r"])
    state = TouchdownState(beta=beta, phi=phi, xd=xd, yd=yd, phid=phid)
    return Gait(state=state, params=p, residual=0.0, stance_time=float("nan"),
                flight_time=float("nan"), converged=True, message="stored (no search)")


def _recorded() -> None:
    """The single-gait figures' and Table 6.1's recorded runs and disturbances (as
    :mod:`.catalogue`'s figures and :func:`.reproduce.pitch_rate_variants` run them), from
    the stored gaits: no gait search."""
    from ..gait import (
        friction_ratio,
        impulse_linearisation,
        pitch_disturbance_response,
        step_down_response,
        velocity_angle_effect,
    )
    from .reproduce import pitch_rate_variants

    g21, g61 = stored_gait("table2.1"), stored_gait("table6.1")
    impulse_linearisation(g21)  # Figure 4.1
    pitch_disturbance_response(g21, (-0.5, 0.0, 0.5))  # Figures 4.2, 4.3, 6.2
    step_down_response(g21, -0.2, 30)  # Figures 4.5, 4.6
    velocity_angle_effect(g21, (-0.05, 0.0, 0.05))  # Figure 4.7
    for g in (g21, g61):  # Figure C.1
        friction_ratio(g.params, g.state, 1.0)
    pitch_rate_variants(g61)  # Table 6.1: disturbances in flight, batches of runs


def _biped() -> None:
    """A biped stride (one loop serves both Runge-Kutta pairs) and what Appendix E
    calls from Python besides a run."""
    from ..biped import BipedParams, BipedState, simulate
    from ..biped.dynamics import controller_references, momentum

    params, state = BipedParams(), BipedState.thesis()
    simulate(params, state, 1)
    momentum(params, state)
    controller_references(params, 0.5)


def _spatial_study(model: str) -> Callable[[], None]:
    """A tiny 3-D study's tasks (``model`` "slip3d" or "tslip3d"), here: its gait solves and
    multipliers, in this process."""

    def run() -> None:
        from .run import StudyJob
        from .spec import StudySpec

        spec = StudySpec.from_dict(copy.deepcopy(_SPATIAL_SPECS[model]))
        job = StudyJob(spec, None, writes=False)
        ready = job.start()
        while ready:
            task = ready.pop()
            ready.extend(job.on_done(task, task.fn(*task.args, None)))

    return run


#: The tiny 3-D studies of :func:`_spatial_study` (one point each).
_SPATIAL_SPECS: dict[str, dict[str, object]] = {
    "slip3d": {"name": "warm", "model": "slip3d", "analyses": ["floquet"], "params": {},
               "axis": [{"param": "k_lat", "values": [0.0]}]},
    "tslip3d": {"name": "warm", "model": "tslip3d", "analyses": ["floquet"],
                "params": {"splay": 0.05}, "axis": [{"param": "k_splay", "values": [0.0]}]},
}


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
    if "spatial" in packages:
        from ..spatial import _trunk_stride

        dirs["spatial"] = Path(_trunk_stride.stride._cache.cache_path)
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
    "TSLIP strides": _strides,
    "TSLIP gait search and analyses": _study_point,
    "TSLIP recorded runs": _recorded,
    "biped": _biped,
    "3-D spring-mass runner": _spatial_study("slip3d"),
    "3-D TSLIP": _spatial_study("tslip3d"),
}
#: The kernel families a 3-D study of each model runs (:func:`ensure`\ d before its pool).
MODEL_FAMILIES: dict[str, tuple[str, ...]] = {"slip3d": ("3-D spring-mass runner",),
                                              "tslip3d": ("3-D TSLIP",)}


#: The families ``tslip reproduce``'s own process warms (:func:`warm_in_background`), in
#: this order, while its fork server warms the others (the TSLIP's strides, then its gait
#: search): the fork server forks the workers once its own families are warm, and the
#: tasks that need these wait for them (:func:`ensure`). The recorded runs call the stride
#: kernels too (a recorded run is strides; a batch, runs of strides), so their workload
#: waits for those to be cached and loads them, but not for the gait search: it runs
#: from :data:`STORED_GAITS` and compiles none of the gait search's kernels. The biped
#: compiles meanwhile. Measured with numba's compile events (2026-12-06): the strides
#: are 11 of the 16 signatures the gait search's workload compiles alone, and the
#: recorded runs' workload compiles those 11 and none of the other 5.
MAIN_PROCESS_FAMILIES: tuple[str, ...] = ("biped", "TSLIP recorded runs")
#: What a family's workload needs cached before it starts without compiling another
#: family's kernels (see :data:`MAIN_PROCESS_FAMILIES`).
NEEDS: dict[str, tuple[str, ...]] = {"TSLIP recorded runs": ("TSLIP strides",)}
#: Seconds :func:`warm_in_background` waits at most for a family it needs, and at least
#: (the fork server may not have claimed it yet) before it stops waiting for one nobody warms.
NEEDS_TIMEOUT = 600.0
NEEDS_GRACE = 30.0


def _claim_path(name: str) -> Path | None:
    """The lock file of family ``name``: beside its kernels' numba cache (None: unknown)."""
    package = _kernel_cache.FAMILIES[name][0]
    try:
        folder = cache_dirs((package,))[package]
    except (OSError, AttributeError, ImportError):
        return None
    slug = "".join(c if c.isalnum() else "-" for c in name.lower())
    return folder / f"tslip-warming-{slug}.lock"


@contextmanager
def claim(name: str, wait: bool = True) -> Iterator[bool]:
    """Hold family ``name``'s claim while the body runs; yields whether it is held.

    An exclusive ``flock`` on :func:`_claim_path`. With ``wait`` it blocks while
    another process holds the claim; without, it yields False at once if so.
    The file is opened without following a link: a link there (not ours), or a
    folder that cannot be written, runs the body unclaimed (yields True, as
    before claims existed). The lock ends with its process, so a killed holder
    never blocks a later run.
    """
    try:
        import fcntl
    except ImportError:  # not POSIX: unclaimed
        yield True
        return
    path = _claim_path(name)
    fd = -1
    held = True
    if path is not None:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
            fcntl.flock(fd, fcntl.LOCK_EX | (0 if wait else fcntl.LOCK_NB))
        except BlockingIOError:
            held = False
        except OSError:
            pass
    try:
        yield held
    finally:
        if fd >= 0:
            os.close(fd)  # releases the lock, if held


def _is_missing(name: str) -> bool:
    return name in _missing((_kernel_cache.FAMILIES[name][0],))[2]


def warm(families: list[str], wait: bool = True) -> list[str]:
    """Compile or load the kernels of ``families`` by running each one's workload.

    Each workload runs under its family's :func:`claim`. With ``wait``, a
    family another process is warming is waited for and then loaded from the
    cache; without, it is left to that process (and to :func:`ensure` in the
    tasks that need it). Returns the families left so. Never raises: a family
    that fails here is compiled where it is first used. Starts no threads (no
    workload runs a parallel kernel): it runs in the fork server.
    """
    left = []
    for name in families:
        with claim(name, wait) as held:
            if held:
                _run_workload(name)
            else:
                left.append(name)
    return left


def warm_missing(packages: tuple[str, ...] = ("simulation", "biped")) -> list[str]:
    """Warm the families of ``packages`` not in numba's cache yet, but those another
    process is warming (:func:`warm` without waiting); returns the missing families."""
    missing = _missing(packages)[2]
    warm(missing, wait=False)
    return missing


def _run_workload(name: str) -> None:
    try:
        WORKLOADS[name]()
    except Exception:  # noqa: BLE001, S110 - the task that needs it will say why
        pass


def ensure(families: tuple[str, ...]) -> None:
    """Before a task that needs ``families``: wait for any another process is warming;
    warm here, under the claim, any still missing. Costs a look at the cache when warm."""
    for name in families:
        if _is_missing(name):
            with claim(name):  # a second claim in this process would wait for this one
                if _is_missing(name):
                    _run_workload(name)


def _held_elsewhere(name: str) -> bool:
    with claim(name, wait=False) as held:
        return not held


def _wait_for(names: tuple[str, ...]) -> None:
    """Wait while a family of ``names`` is missing and another process warms it (or may
    be about to: :data:`NEEDS_GRACE` seconds), for at most :data:`NEEDS_TIMEOUT`."""
    t0 = time.monotonic()
    for name in names:
        while _is_missing(name):
            waited = time.monotonic() - t0
            if waited > NEEDS_TIMEOUT or (waited > NEEDS_GRACE and not _held_elsewhere(name)):
                return
            time.sleep(POLL_SECONDS)


def warm_in_background(families: tuple[str, ...] = MAIN_PROCESS_FAMILIES) -> threading.Thread:
    """Warm the missing ones of ``families``, in order, in a daemon thread of this process.

    ``tslip reproduce`` calls it right after starting its fork server, which
    warms the strides and the gait search meanwhile (:mod:`._prewarm`,
    :func:`warm_missing`):
    the compiling is split over the two processes. Every claim of
    ``families`` is taken at once, so the fork server finds them held and
    leaves them; each family then waits for what it :data:`NEEDS`, so no
    kernel is compiled in both processes.
    """
    missing = [f for f in families if _is_missing(f)]
    ready = threading.Event()

    def run() -> None:
        with ExitStack() as claims:
            for name in missing:
                claims.enter_context(claim(name))
            ready.set()
            for name in missing:
                _wait_for(NEEDS.get(name, ()))
                _run_workload(name)
        ready.set()

    thread = threading.Thread(target=run, daemon=True, name="tslip-warm")
    thread.start()
    ready.wait()
    return thread

@contextmanager
def announce(echo: Callable[[str], None], packages: tuple[str, ...] = ("simulation", "biped"),
             terminal: Console | None = None, only: tuple[str, ...] | None = None,
             ) -> Iterator[list[str]]:
    """Say which kernel families of ``packages`` are not compiled yet, and each as it gets cached.

    Prints nothing when every family is cached. Yields the missing families.
    With ``terminal`` (the console ``echo`` prints to) a terminal, one updating
    line below the others shows the seconds spent compiling, renewed every
    :data:`STATUS_SECONDS`, until the last family is cached; on anything else
    (a pipe, a file, a log) nothing is added. ``only``: of those families, these
    (the ones a run will compile).
    """
    dirs, digest, missing = _missing(packages)
    if only is not None:
        missing = [f for f in missing if f in only]
    if not missing:
        yield []
        return
    what = "kernel family" if len(missing) == 1 else "kernel families"
    echo(f"first run: compiling {len(missing)} {what} not in numba's cache yet "
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
