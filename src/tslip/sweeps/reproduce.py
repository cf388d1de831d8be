"""Run every thesis study, test every claim, write one HTML report.

:func:`run_all` runs the studies of :mod:`tslip.sweeps.catalogue` (each
cached under ``out_dir/studies/<name>/``, so a rerun is instant and an
interrupted one resumes), computes the single-gait figures, evaluates
:data:`tslip.sweeps.claims.CLAIMS`; :func:`tslip.plotting.report.reproduce`
then writes ``out_dir/index.html``. Every single-gait figure's data, Table
6.1's and Appendix E's are kept too, in ``out_dir/figures/``, keyed by the
hash of the code that computes them (:mod:`._figstore`,
:func:`appendix_e_cached`), so a rerun into the same folder computes nothing
that is kept and starts no worker.

Where a thesis number does not reproduce, the data carry the evidence the
package computes: Table 6.1's pitch-rate limit under every placement and
setting tried (``data["table6.1"]["pitch_rate_variants"]``), the residual
left with the thesis's ``alphad_ref`` forced (``["alphad_ref_forced"]``),
and Appendix E's stride count for starts within Table E.2's rounding
(``data["E"]["e2"]["strides_perturbed"]``).

Parallelism: one scheduler (:mod:`tslip.sweeps._schedule`) runs every unit
of work on one worker pool, largest first: each line's gait solve and each
chunk of its points' analyses (:class:`tslip.sweeps.run.StudyJob`), each
single-gait figure, each piece of Table 6.1 (:data:`TABLE61_PIECES`) and of
Appendix E (each Floquet analysis and each perturbed start,
:func:`tslip.sweeps.appendix_e.pieces`). Results are assembled here as they
arrive. The worker count follows the work left
(:func:`tslip.sweeps._schedule.choose_workers`): a rerun with everything
cached starts no worker. With ``scheduler`` the same tasks run on that Dask
cluster.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import math
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, Protocol, cast

from .._codehash import code_hash
from .._safefile import folder
from ..gait import find_gait, floquet, robustness_report, stride_properties
from ..gait.fixed_point import Gait, GaitProblem, newton_solve
from ..gait.robustness import robustness
from ..model.controllers import LocalVelocity
from ..model.parameters import preset
from ..simulation.options import IntegratorOptions
from . import _figstore, _pool, catalogue
from ._figstore import HeightChange, Table61, figure_load, figure_store, kept
from ._lock import folder_locks
from ._schedule import Task, Timing, choose_workers, own_seconds, run_tasks
from ._warmup import ensure, warm_in_background
from .claims import ClaimResult, evaluate
from .run import StudyJob

__all__ = ["PITCH_RATE_VARIANTS", "TABLE61_PIECES", "alphad_ref_forced", "appendix_e_cached",
           "pitch_rate_variant", "pitch_rate_variants", "run_all", "run_catalogue",
           "single_figures", "table61"]

#: Table 6.1's printed values that do not reproduce (Section 6.1, docs/conventions.md).
THESIS_ALPHAD_REF = 2.42
THESIS_PITCH_RATE = -1.50

#: The modules that compute Appendix E's data: their code hash keys its cache.
APPENDIX_E_MODULES: tuple[str, ...] = ("tslip.sweeps.appendix_e",)
#: Appendix E settings per resolution (:func:`tslip.sweeps.appendix_e.fig_appendix_e`):
#: the Table E.2 perturbations cost about 2 s each (the falling runs are stiff), so the
#: quick run samples 4 random corners of the rounding box and the full run makes the 34
#: one-at-a-time moves (each printed entry up and down by half a unit of its last digit).
APPENDIX_E_SETTINGS: dict[str, dict[str, Any]] = {
    "tiny": {"n_strides": 4, "n_converged": 3, "n_random": 1, "one_at_a_time": False},
    "quick": {"n_random": 4, "one_at_a_time": False},
    "full": {"n_random": 0, "one_at_a_time": True},
}

#: ``progress(stage, name, seconds)`` after each study or figure, ``seconds`` its own time
#: (the wall seconds of its tasks: :func:`tslip.sweeps._schedule.own_seconds`); and once,
#: before any work, ``("workers", "<count>", 0.0)`` with the worker processes chosen.
Progress = Callable[[str, str, float], None]


class Extra(Protocol):
    """More tasks on the results as they arrive (the report's figures,
    :class:`tslip.plotting.report.ReportPlots`), run on the same pool.

    ``ready(data so far)`` returns the tasks the data now allow (keys not
    starting with a study's name or ``"figure"``), ``done(task, result)``
    takes each result here, ``cost`` estimates the seconds not yet sent and
    ``modules`` names the modules its tasks use (for the workers to import once).
    """

    @property
    def cost(self) -> float: ...

    @property
    def modules(self) -> tuple[str, ...]: ...

    def ready(self, data: Mapping[str, Any]) -> list[Task]: ...

    def done(self, task: Task, result: Any) -> None: ...


#: Table 6.1's pitch-rate limit variants (:func:`pitch_rate_variants`): label ->
#: keyword arguments of :func:`tslip.gait.robustness.robustness`.
PITCH_RATE_VARIANTS: dict[str, dict[str, Any]] = {
    **{f"{placement}, {mark}": {"sign": sign, "placement": placement}
       for placement in ("touchdown", "touchdown_hip", "liftoff", "apex")
       for sign, mark in ((-1, "-"), (1, "+"))},
    "touchdown, -, 50 strides": {"n_steps": 50},
    "touchdown, -, tol 1e-12": {"options": IntegratorOptions.tight()},
}


def pitch_rate_variant(gait: Gait, label: str) -> float:
    """One of :func:`pitch_rate_variants`, by label."""
    return robustness(gait, "pitch_rate", check=False, **PITCH_RATE_VARIANTS[label])


def pitch_rate_variants(gait: Gait) -> dict[str, float]:
    """Table 6.1's pitch-rate limit under each placement, sign and setting tried.

    The thesis prints -1.50 rad g^1/2 L^-1/2 and says only "the largest
    disturbance from the periodic limit cycle which does not result in a
    fall within 25 steps" (Section 3.1.3). The default (docs/conventions.md) is
    the first label; the others change one choice each: where the change
    is applied (:data:`tslip.gait.robustness.PLACEMENTS`), its sign, the
    strides to survive (50) and the integrator tolerance (1e-12). Labels
    read ``"<placement>, <sign>[, <setting>]"`` (:data:`PITCH_RATE_VARIANTS`).
    """
    return {label: pitch_rate_variant(gait, label) for label in PITCH_RATE_VARIANTS}


def alphad_ref_forced(gait: Gait, alphad_ref: float = THESIS_ALPHAD_REF) -> dict[str, Any]:
    """Force the local velocity controller's ``alphad_ref`` and solve the rest of the gait.

    With ``alphad_ref`` fixed the search of Section 2.8 has four unknowns
    (``delta, phi, phid, alpha_r``) for five periodicity equations, so it is
    solved in the least-squares sense (:func:`tslip.gait.fixed_point.newton_solve`,
    from the free gait and the automatic guesses). ``residual`` is the
    max-norm of the periodicity residual left (as :attr:`Gait.residual`),
    ``c1`` its eq. 2.20 cost (the thesis accepted ``C1 < 1e-4``, eq. 2.22); ``free``
    is our solved ``alphad_ref``; ``stride`` the first stride from that
    least-squares start (``stance_time``, ``flight_time``, ``duty_factor``,
    ``step_frequency``, as :func:`tslip.gait.stride_properties`; Table 6.2's
    columns), empty if no start was found.
    """
    p = gait.params
    if not isinstance(p.controller, LocalVelocity):
        raise ValueError("alphad_ref_forced needs a gait with LocalVelocity control (Table 6.1)")
    free = p.controller.alphad_ref
    forced = dataclasses.replace(p, controller=dataclasses.replace(p.controller,
                                                                   alphad_ref=alphad_ref))
    names = ("delta", "phi", "phid", "alpha_r")
    prob = GaitProblem(params=forced, options=IntegratorOptions.tight(), names=names)
    z0 = GaitProblem.from_params(p).encode(gait)[:4]
    z, err, _ = newton_solve(prob.residual, itertools.chain([z0], prob.guesses()), tol=1e-10,
                             max_starts=5)
    c1 = prob.c1(z) if z is not None else float("inf")
    stride: dict[str, float] = {}
    if z is not None:
        _, ts, tf = prob.evaluate(z)
        stride = {"stance_time": float(ts), "flight_time": float(tf),
                  "duty_factor": float(ts / (ts + tf)), "step_frequency": float(1 / (ts + tf))}
    return {"alphad_ref": float(alphad_ref), "residual": float(err), "c1": c1,
            "free": float(free), "stride": stride}


def _pitch_rate_piece(label: str, g: Gait) -> float:
    return pitch_rate_variant(g, label)


def _table61_core(g: Gait) -> dict[str, Any]:
    fl = floquet(g)
    rr = robustness_report(g, check=False)
    sp = stride_properties(g)
    return {"max_nontrivial": fl.max_nontrivial, "stability": fl.stability,
            "step_down": rr.step_down, "push": rr.push, "pitch_rate": rr.pitch_rate,
            "stance_time": sp.stance_time, "flight_time": sp.flight_time,
            "duty_factor": sp.duty_factor, "step_frequency": sp.step_frequency,
            "alphad_ref": getattr(g.params.controller, "alphad_ref", math.nan),
            "alpha_r": g.params.alpha_r}


#: Table 6.1's independent pieces (:func:`table61`), each a task of ``tslip reproduce``:
#: name -> (function of the gait, estimated seconds).
TABLE61_PIECES: dict[str, tuple[Callable[[Gait], Any], float]] = {
    "core": (_table61_core, 0.2),
    **{f"pitch_rate/{label}": (functools.partial(_pitch_rate_piece, label), 0.02)
       for label in PITCH_RATE_VARIANTS},
    "alphad_ref_forced": (alphad_ref_forced, 0.15),
}


@functools.cache
def _table61_gait() -> Gait:
    return find_gait(preset("table6.1"))


def _table61_assemble(parts: dict[str, Any]) -> Table61:
    return {**parts["core"],  # type: ignore[typeddict-item]  # core: Table61's first keys
            "pitch_rate_variants": {label: parts[f"pitch_rate/{label}"]
                                    for label in PITCH_RATE_VARIANTS},
            "alphad_ref_forced": parts["alphad_ref_forced"]}


def table61() -> Table61:
    """Table 6.1 gait: multipliers, robustness (Section 6.1), stride (Table 6.2).

    Also the evidence for the two numbers that do not reproduce: the
    pitch-rate limit under every variant tried (:func:`pitch_rate_variants`)
    and the residual left with the thesis's ``alphad_ref`` (:func:`alphad_ref_forced`).
    """
    g = _table61_gait()
    return _table61_assemble({k: fn(g) for k, (fn, _) in TABLE61_PIECES.items()})


def _appendix_e_entry(out_dir: str | Path, resolution: str) -> tuple[Path, str]:
    """Appendix E's cache file and the key its content must carry."""
    settings = APPENDIX_E_SETTINGS[catalogue.resolution_name(resolution)]
    key = f"{code_hash(*APPENDIX_E_MODULES)}:{sorted(settings.items())!r}"
    return Path(out_dir) / "figures" / f"appendix_e-{resolution}.json", key


#: The format of Appendix E's cache file, stored in it.
APPENDIX_E_FORMAT = {"name": "tslip-appendix-e", "version": 1}


def _appendix_e_load(path: Path, key: str) -> dict[str, Any] | None:
    """The cached data if ``path`` holds it under ``key``; else None (a bad file warns once).

    JSON text, decoded strictly (:func:`tslip.sweeps.appendix_e.from_json`): nothing
    in the file can run. A file of another key (the code changed) is silently stale.
    """
    from .appendix_e import from_json

    data: dict[str, Any] | None = _figstore.load(path, key, APPENDIX_E_FORMAT, from_json,
                                                 "Appendix E")
    return data


def _appendix_e_store(path: Path, key: str, data: dict[str, Any]) -> None:
    from .appendix_e import to_json

    _figstore.store(path, key, APPENDIX_E_FORMAT, to_json(data))


def appendix_e_cached(out_dir: str | Path, resolution: str = "full") -> dict[str, Any]:
    """Appendix E's data, from ``out_dir/figures/appendix_e-<resolution>.json`` if still valid.

    The cache is keyed by :func:`tslip._codehash.code_hash` of
    :data:`APPENDIX_E_MODULES` (their sources, everything they import from
    tslip, and the numerical libraries' versions) and the settings: a rerun
    reuses it, a change to the biped code recomputes it. Written atomically;
    read as data only (:func:`_appendix_e_load`), a damaged or foreign file
    recomputed.
    """
    from .appendix_e import fig_appendix_e

    path, key = _appendix_e_entry(out_dir, resolution)
    data = _appendix_e_load(path, key)
    if data is None:
        data = fig_appendix_e(**APPENDIX_E_SETTINGS[catalogue.resolution_name(resolution)])
        _appendix_e_store(path, key, data)
    return data


#: Figure 4.4's two gaits (:func:`tslip.sweeps.catalogue.fig_height_change`), by key.
HEIGHT_CHANGE_PRESETS = {"passive": "table2.1", "local_velocity": "table2.1-local-velocity"}


def height_change(coarse: bool = False) -> HeightChange:
    """Figure 4.4's speed changes and each gait's own step-down limit.

    ``step_down_limit`` maps ``"passive"`` and ``"local_velocity"`` to the
    largest step down [L] the gait survives (:func:`tslip.gait.robustness.robustness`):
    the claim judges convergence at the steps within it and shows the falls beyond.
    """
    out = cast(HeightChange, catalogue.fig_height_change(coarse))
    out["step_down_limit"] = {key: robustness(catalogue._gait(name), "step_down", check=False)
                              for key, name in HEIGHT_CHANGE_PRESETS.items()}
    return out


def _figure_jobs(res: str) -> dict[str, Callable[[], Any]]:
    """The single-gait figures other than Table 6.1 and Appendix E, by key."""
    coarse = res != "full"
    return {
        "4.1": catalogue.fig_impulse_linearisation,
        "4.2": lambda: catalogue.fig_pitch_disturbance("table2.1"),
        "4.3": lambda: catalogue.fig_pitch_disturbance("table2.1-global-pd"),
        "6.2": lambda: catalogue.fig_pitch_disturbance("table6.1"),
        "4.4": lambda: height_change(coarse),
        "4.5": catalogue.fig_step_down,
        "4.7": catalogue.fig_velocity_angle,
        "C.1": catalogue.fig_friction,
        "4.16": catalogue.fig_mass_offset_boundary,
    }


#: Estimated seconds of each figure of :func:`_figure_jobs` (warm compile cache, one core).
FIGURE_SECONDS = {"4.1": 0.02, "4.2": 0.04, "4.3": 0.02, "6.2": 0.02, "4.4": 1.5, "4.5": 0.02,
                  "4.7": 0.02, "C.1": 0.03, "4.16": 1.5}


def single_figures(quick: bool | str = False, progress: Progress | None = None,
                   out_dir: str | Path | None = None) -> dict[str, Any]:
    """The single-gait analyses (Figures 4.1-4.7, 6.2, C.1, E.2-E.4) and Table 6.1's numbers.

    ``quick`` is True/False or a :data:`tslip.sweeps.catalogue.RESOLUTIONS`
    name; with ``out_dir`` every figure's data is kept there (:func:`._figstore.figure_load`,
    :func:`appendix_e_cached`) and read back when still valid. Runs here, one after the other
    (:func:`run_all` runs the same work as parallel tasks).
    """
    res = catalogue.resolution_name(quick)
    jobs: dict[str, Callable[[], Any]] = {
        **_figure_jobs(res), "table6.1": table61,
        "E": (lambda: appendix_e_cached(out_dir, res)) if out_dir is not None
        else lambda: catalogue.fig_appendix_e(**APPENDIX_E_SETTINGS[res])}
    out = {}
    for key, job in jobs.items():
        t0 = time.perf_counter()
        out[key] = job() if key == "E" else kept(out_dir, res, key, job)
        if progress:
            progress("figure", key, time.perf_counter() - t0)
    return out


#: The kernel families the single-gait figures and Table 6.1 use (the workers may start
#: before ``tslip reproduce``'s own process has them cached: :func:`._warmup.ensure`).
_TSLIP_FAMILIES = ("TSLIP strides", "TSLIP gait search and analyses", "TSLIP recorded runs")


def _figure_task(res: str, key: str, tick: Any = None) -> Any:
    """One single-gait figure (a task)."""
    ensure(_TSLIP_FAMILIES)
    return _figure_jobs(res)[key]()


def _table61_task(name: str, tick: Any = None) -> Any:
    """One piece of Table 6.1 (a task)."""
    ensure(_TSLIP_FAMILIES)
    return TABLE61_PIECES[name][0](_table61_gait())


def _piece_task(fn: Callable[..., Any], args: tuple[Any, ...], tick: Any = None) -> Any:
    """One piece of Appendix E (a task)."""
    ensure(("biped",))
    return fn(*args)


class _Figures:
    """The single-gait figures, Table 6.1 and Appendix E as scheduler tasks.

    A figure made of pieces is assembled when its last piece arrives; each is
    taken from the report folder when kept there and still valid
    (:func:`._figstore.figure_load`, :func:`appendix_e_cached`), and kept there when computed.
    """

    def __init__(self, res: str, out: Path, progress: Progress | None,
                 arrived: Callable[[], None], timing: Timing) -> None:
        from . import appendix_e

        self.res, self.out, self.progress, self.timing = res, out, progress, timing
        self.arrived: Callable[[], None] = lambda: None
        self.data: dict[str, Any] = {}
        self.tasks = []
        for k in [*_figure_jobs(res), "table6.1"]:
            stored = figure_load(out, res, k)
            if stored is not None:
                self._done(k, stored)
            elif k == "table6.1":
                self.tasks += [Task(("figure", k, piece), _table61_task, (piece,), sec)
                               for piece, (_, sec) in TABLE61_PIECES.items()]
            else:
                self.tasks.append(Task(("figure", k), _figure_task, (res, k), FIGURE_SECONDS[k]))
        self.t61: dict[str, Any] = {}
        self.e_path, self.e_key = _appendix_e_entry(out, res)
        cached = _appendix_e_load(self.e_path, self.e_key)
        self.e_parts: dict[str, Any] = {}
        self.e_settings = APPENDIX_E_SETTINGS[res]
        if cached is not None:
            self._done("E", cached)
            self.e_pieces: dict[str, Any] = {}
        else:
            self.e_pieces = appendix_e.pieces(**self.e_settings)
            self.tasks += [Task(("figure", "E", k), _piece_task, (fn, args),
                                appendix_e.PIECE_SECONDS[k.split("/")[0]])
                           for k, (fn, args) in self.e_pieces.items()]
        self.arrived = arrived

    @property
    def cost(self) -> float:
        return sum(t.cost for t in self.tasks)

    def _done(self, key: str, value: Any) -> None:
        self.data[key] = value
        if self.progress:
            self.progress("figure", key, own_seconds(self.timing, ("figure", key)))
        self.arrived()

    def on_done(self, task: Task, result: Any) -> list[Task]:
        from . import appendix_e

        key = task.key[1]
        if key == "table6.1":
            self.t61[task.key[2]] = result
            if len(self.t61) == len(TABLE61_PIECES):
                table = _table61_assemble(self.t61)
                figure_store(self.out, self.res, key, table)
                self._done(key, table)
        elif key == "E":
            self.e_parts[task.key[2]] = result
            if len(self.e_parts) == len(self.e_pieces):
                data = appendix_e.assemble(self.e_parts, **self.e_settings)
                _appendix_e_store(self.e_path, self.e_key, data)
                self._done(key, data)
        else:
            figure_store(self.out, self.res, key, result)
            self._done(key, result)
        return []


def run_all(out_dir: str | Path, *, quick: bool = False, workers: int | None = None,
            scheduler: str | None = None, progress: Progress | None = None,
            resolution: str | None = None,
            timing: dict[Any, tuple[float, float, Any]] | None = None,
            on_result: Callable[[dict[str, Any]], None] | None = None,
            extra: Extra | None = None, info: dict[str, Any] | None = None,
            ) -> tuple[dict[str, Any], list[ClaimResult], float]:
    """Run every thesis study and figure; return the data, the claims and the seconds.

    The report itself is written by :func:`tslip.plotting.report.reproduce`
    (sweeps does not import plotting).

    Parameters
    ----------
    out_dir : path
        Report folder; studies are cached in ``out_dir/studies/<name>/``,
        Appendix E in ``out_dir/figures/``.
    quick : bool
        Coarse resolution (12 points a line, 6 x 6 grids) instead of the full
        one (50 points, 40 x 40).
    workers : int, optional
        Worker processes (1 runs everything here). Default: by the work
        left, up to all cores, serial when start-up would dominate
        (:func:`tslip.sweeps._schedule.choose_workers`).
    scheduler : str, optional
        Dask scheduler address to run the tasks on.
    progress : callable, optional
        ``progress(stage, name, seconds)`` after each study and figure, and once
        ``("workers", "<count>", 0.0)`` before the work (:data:`Progress`).
    resolution : {"tiny", "quick", "full"}, optional
        Overrides ``quick``; ``"tiny"`` (3 points a line, 3 x 3 grids, a
        short Appendix E) tests the pipeline, its numbers are not meant to be read.
    timing : dict, optional
        Filled with each task's CPU and wall seconds (see :func:`run_catalogue`).
    on_result : callable, optional
        ``on_result(data)`` here after each study and figure, with the data so
        far.
    extra : Extra, optional
        More tasks on the data as they arrive, on the same pool (the report's
        figures: :class:`tslip.plotting.report.ReportPlots`).
    info : dict, optional
        Filled with ``"workers"``: the worker processes used.

    Returns
    -------
    data : dict
        Study results and figure data by key, plus ``"quick"`` (not full
        resolution) and ``"resolution"`` (its name).
    claims : list of ClaimResult
    seconds : float
    """
    t0 = time.perf_counter()
    res = catalogue.resolution_name(quick if resolution is None else resolution)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    results = run_catalogue(out, res, workers=workers, scheduler=scheduler, progress=progress,
                            timing=timing, on_result=on_result, extra=extra, info=info)
    order = [*catalogue.STUDIES, *_figure_jobs(res), "table6.1", "E"]
    data: dict[str, Any] = {**{k: results[k] for k in order},
                            "quick": res != "full", "resolution": res}
    return data, evaluate(data), time.perf_counter() - t0


def run_catalogue(out_dir: str | Path, resolution: bool | str = False, *,
                  workers: int | None = None, scheduler: str | None = None,
                  progress: Progress | None = None,
                  timing: dict[Any, tuple[float, float, Any]] | None = None,
                  on_result: Callable[[dict[str, Any]], None] | None = None,
                  extra: Extra | None = None,
                  info: dict[str, Any] | None = None) -> dict[str, Any]:
    """Every study and single-gait figure as tasks of one scheduler; results by key.

    Each study folder is locked (:func:`tslip.sweeps._lock.folder_locks`)
    for the run. ``timing`` receives each task's CPU and wall seconds and
    the task that made it ready (:func:`tslip.sweeps._schedule.run_tasks`);
    ``on_result(data so far)`` is called after each study and figure, and
    ``extra``'s tasks (:class:`Extra`) run as the data they need arrive;
    ``info["workers"]`` is set to the worker count used.
    """
    res = catalogue.resolution_name(resolution)
    out = Path(out_dir)
    specs = catalogue.studies(res)
    results: dict[str, Any] = {}
    timing = {} if timing is None else timing
    preload = ["tslip.sweeps.run", __name__, *(extra.modules if extra is not None else ()),
               "tslip.sweeps._prewarm"]  # last: compiles what the modules above use, once
    with folder_locks((out / "studies" / name for name in specs), root=out):
        folder(out, out / "figures")  # the report's figures: a link there is refused
        jobs = {name: StudyJob(spec, out / "studies" / name, writes=scheduler is None)
                for name, spec in specs.items()}

        follow: list[Task] = []  # extra's tasks made ready by the last arrival

        def arrived() -> None:
            if on_result is not None or extra is not None:
                data = {**results, **figures.data}
                if on_result is not None:
                    on_result(data)
                if extra is not None:
                    follow.extend(extra.ready(data))

        def followers() -> list[Task]:
            out = follow[:]
            follow.clear()
            return out

        figures = _Figures(res, out, progress, arrived, timing)
        cost = sum(j.cost for j in jobs.values()) + figures.cost
        cost += extra.cost if extra is not None else 0.0
        n = 1 if scheduler is not None else choose_workers(cost, workers)
        if scheduler is None and n > 1 and cost > 0:  # parallel: the workers' imports start
            warm_in_background()  # now; biped, recorded runs: here (claimed before the fork
            _pool.prestart(preload)  # server starts), while it warms the gait search
        if info is not None:
            info["workers"] = n
        if progress:
            progress("workers", str(n), 0.0)

        def study_done(name: str) -> None:
            results[name] = jobs.pop(name).result(n, scheduler, timing=timing)
            if progress:
                progress("study", name, results[name].meta["seconds"])
            arrived()

        def on_done(task: Task, result: Any) -> list[Task]:
            owner = task.key[0]
            if owner == "figure":
                return figures.on_done(task, result) + followers()
            if owner not in jobs and extra is not None:
                extra.done(task, result)
                return []
            new = jobs[owner].on_done(task, result)
            if jobs[owner].finished:
                study_done(owner)
            return new + followers()

        for name in [n for n, j in jobs.items() if j.finished]:
            study_done(name)
        arrived()  # what was cached
        tasks = [t for j in jobs.values() for t in j.start()] + figures.tasks + followers()
        run_tasks(tasks, on_done, n, timing=timing, scheduler=scheduler, preload=preload)
    return {**results, **figures.data}
