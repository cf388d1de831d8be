"""Run every thesis study, test every claim, write one HTML report.

:func:`run_all` runs the studies of :mod:`tslip.sweeps.catalogue` (each
cached under ``out_dir/studies/<name>/``, so a rerun is instant and an
interrupted one resumes), computes the single-gait figures, evaluates
:data:`tslip.sweeps.claims.CLAIMS`; :func:`tslip.plotting.report.reproduce`
then writes ``out_dir/index.html``. Appendix E (the biped, the slowest
figure) is cached too, in ``out_dir/figures/``, keyed by the hash of the
code that computes it (:func:`appendix_e_cached`).

Where a thesis number does not reproduce, the data carry the evidence the
package computes: Table 6.1's pitch-rate limit under every placement and
setting tried (``data["table6.1"]["pitch_rate_variants"]``), the residual
left with the thesis's ``alphad_ref`` forced (``["alphad_ref_forced"]``),
and Appendix E's stride count for starts within Table E.2's rounding
(``data["E"]["e2"]["strides_perturbed"]``).

Parallelism: most studies are one continuation line, so the studies
themselves are the unit of work: they run in spawned worker processes (one
study per process, serial inside), largest first, while this process
computes the single-gait figures. With ``scheduler`` every study runs on
that Dask cluster instead.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import itertools
import os
import pickle
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from .._codehash import code_hash
from .._io import atomic_write
from ..gait import find_gait, floquet, robustness_report, stride_properties
from ..gait.fixed_point import Gait, GaitProblem, newton_solve
from ..gait.robustness import robustness
from ..model.parameters import preset
from ..simulation.options import IntegratorOptions
from . import catalogue
from ._pool import process_pool
from .claims import ClaimResult, evaluate
from .run import StudyResult, run_study
from .spec import StudySpec

__all__ = ["alphad_ref_forced", "appendix_e_cached", "pitch_rate_variants", "run_all",
           "run_catalogue", "single_figures", "table61"]

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

#: ``progress(stage, name, seconds)`` after each study or figure.
Progress = Callable[[str, str, float], None]


def _run_one(spec: StudySpec, out: str) -> StudyResult:
    return run_study(spec, out, workers=1)


def run_catalogue(out_dir: str | Path, *, quick: bool | str = False, workers: int | None = None,
                  scheduler: str | None = None, progress: Progress | None = None,
                  names: list[str] | None = None,
                  side_job: Callable[[], Any] | None = None) -> tuple[dict[str, StudyResult], Any]:
    """Run (or load from cache) the catalogue's studies; optionally a side job meanwhile.

    ``quick`` is True/False or a :data:`tslip.sweeps.catalogue.RESOLUTIONS`
    name. Returns the results by study name and the side job's return value.
    """
    specs = catalogue.studies(quick)
    if names is not None:
        specs = {n: specs[n] for n in names}
    root = Path(out_dir) / "studies"
    n_workers = workers if workers is not None else (os.cpu_count() or 1)
    if n_workers < 1:
        raise ValueError(f"workers must be >= 1, got {n_workers}")
    results: dict[str, StudyResult] = {}
    side = None

    def done(name: str, res: StudyResult, t0: float) -> None:
        results[name] = res
        if progress:
            progress("study", name, time.perf_counter() - t0)

    order = sorted(specs, key=lambda n: -specs[n].n_points * (3 if "robustness" in
                                                                   specs[n].analyses else 1))
    if scheduler is not None or n_workers == 1:
        if side_job is not None:
            side = side_job()
        for name in order:
            t0 = time.perf_counter()
            done(name, run_study(specs[name], root / name, workers=1, scheduler=scheduler), t0)
        return results, side
    _warm_up()
    t0 = time.perf_counter()
    with process_pool(n_workers) as pool:
        futs = {pool.submit(_run_one, specs[n], str(root / n)): n for n in order}
        if side_job is not None:
            side = side_job()
        try:
            for fut in cf.as_completed(futs):
                done(futs[fut], fut.result(), t0)
        except BaseException:
            for fut in futs:
                fut.cancel()
            raise
    return results, side


def _warm_up() -> None:
    """Compile (or load) every kernel here once, so workers find them in numba's cache."""
    g = find_gait(preset("table2.1"))
    floquet(g)
    stride_properties(g)
    robustness_report(g, n_steps=2, check=False)


def pitch_rate_variants(gait: Gait) -> dict[str, float]:
    """Table 6.1's pitch-rate limit under each placement, sign and setting tried.

    The thesis prints -1.50 rad g^1/2 L^-1/2 and says only "the largest
    disturbance from the periodic limit cycle which does not result in a
    fall within 25 steps" (Section 3.1.3). The default (docs/conventions.md) is
    the first label; the others change one choice each: where the change
    is applied (:data:`tslip.gait.robustness.PLACEMENTS`), its sign, the
    strides to survive (50) and the integrator tolerance (1e-12). Labels
    read ``"<placement>, <sign>[, <setting>]"``.
    """
    out: dict[str, float] = {}
    for placement in ("touchdown", "touchdown_hip", "liftoff", "apex"):
        for sign, mark in ((-1, "-"), (1, "+")):
            out[f"{placement}, {mark}"] = robustness(gait, "pitch_rate", sign=sign,
                                                     placement=placement, check=False)
    out["touchdown, -, 50 strides"] = robustness(gait, "pitch_rate", n_steps=50, check=False)
    out["touchdown, -, tol 1e-12"] = robustness(gait, "pitch_rate", check=False,
                                                options=IntegratorOptions.tight())
    return out


def alphad_ref_forced(gait: Gait, alphad_ref: float = THESIS_ALPHAD_REF) -> dict[str, float]:
    """Force the local velocity controller's ``alphad_ref`` and solve the rest of the gait.

    With ``alphad_ref`` fixed the search of Section 2.8 has four unknowns
    (``delta, phi, phid, alpha_r``) for five periodicity equations, so it is
    solved in the least-squares sense (:func:`tslip.gait.fixed_point.newton_solve`,
    from the free gait and the automatic guesses). ``residual`` is the
    max-norm of the periodicity residual left (as :attr:`Gait.residual`),
    ``c1`` its eq. 2.20 cost (the thesis accepted ``C1 < 1e-4``); ``free``
    is our solved ``alphad_ref``.
    """
    p = gait.params
    forced = dataclasses.replace(p, controller=dataclasses.replace(p.controller,
                                                                   alphad_ref=alphad_ref))
    names = ("delta", "phi", "phid", "alpha_r")
    prob = GaitProblem(params=forced, options=IntegratorOptions.tight(), names=names)
    z0 = GaitProblem.from_params(p).encode(gait)[:4]
    z, err, _ = newton_solve(prob.residual, itertools.chain([z0], prob.guesses()), tol=1e-10,
                             max_starts=5)
    c1 = float(np.sum(prob.residual(z) ** 2)) if z is not None else float("inf")
    return {"alphad_ref": float(alphad_ref), "residual": float(err), "c1": c1,
            "free": float(p.controller.alphad_ref)}


def table61() -> dict[str, Any]:
    """Table 6.1 gait: multipliers, robustness (Section 6.1), stride (Table 6.2).

    Also the evidence for the two numbers that do not reproduce: the
    pitch-rate limit under every variant tried (:func:`pitch_rate_variants`)
    and the residual left with the thesis's ``alphad_ref`` (:func:`alphad_ref_forced`).
    """
    g = find_gait(preset("table6.1"))
    fl = floquet(g)
    rr = robustness_report(g, check=False)
    sp = stride_properties(g)
    return {"max_nontrivial": fl.max_nontrivial, "stability": fl.stability,
            "step_down": rr.step_down, "push": rr.push, "pitch_rate": rr.pitch_rate,
            "stance_time": sp.stance_time, "flight_time": sp.flight_time,
            "duty_factor": sp.duty_factor, "step_frequency": sp.step_frequency,
            "alphad_ref": g.params.controller.alphad_ref, "alpha_r": g.params.alpha_r,
            "pitch_rate_variants": pitch_rate_variants(g),
            "alphad_ref_forced": alphad_ref_forced(g)}


def appendix_e_cached(out_dir: str | Path, resolution: str = "full") -> dict[str, Any]:
    """Appendix E's data, from ``out_dir/figures/appendix_e-<resolution>.pkl`` if still valid.

    The cache is keyed by :func:`tslip._codehash.code_hash` of
    :data:`APPENDIX_E_MODULES` (their sources, everything they import from
    tslip, and the numerical libraries' versions) and the settings: a rerun
    reuses it, a change to the biped code recomputes it. Written atomically.
    """
    from .appendix_e import fig_appendix_e

    settings = APPENDIX_E_SETTINGS[catalogue.resolution_name(resolution)]
    key = f"{code_hash(*APPENDIX_E_MODULES)}:{sorted(settings.items())!r}"
    path = Path(out_dir) / "figures" / f"appendix_e-{resolution}.pkl"
    try:
        cached = pickle.loads(path.read_bytes())
        if isinstance(cached, dict) and cached.get("key") == key:
            return cached["data"]
    except (OSError, EOFError, pickle.UnpicklingError, AttributeError, ImportError):
        pass  # missing or unreadable: recompute
    data = fig_appendix_e(**settings)
    blob = pickle.dumps({"key": key, "data": data}, protocol=pickle.HIGHEST_PROTOCOL)
    atomic_write(path, lambda tmp: Path(tmp).write_bytes(blob))
    return data


def single_figures(quick: bool | str = False, progress: Progress | None = None,
                   out_dir: str | Path | None = None) -> dict[str, Any]:
    """The single-gait analyses (Figures 4.1-4.7, 6.2, C.1, E.2-E.4) and Table 6.1's numbers.

    ``quick`` is True/False or a :data:`tslip.sweeps.catalogue.RESOLUTIONS`
    name; with ``out_dir`` Appendix E's data is cached there
    (:func:`appendix_e_cached`).
    """
    res = catalogue.resolution_name(quick)
    coarse = res != "full"
    jobs: dict[str, Callable[[], Any]] = {
        "4.1": catalogue.fig_impulse_linearisation,
        "4.2": lambda: catalogue.fig_pitch_disturbance("table2.1"),
        "4.3": lambda: catalogue.fig_pitch_disturbance("table2.1-global-pd"),
        "6.2": lambda: catalogue.fig_pitch_disturbance("table6.1"),
        "4.4": lambda: catalogue.fig_height_change(coarse),
        "4.5": catalogue.fig_step_down,
        "4.7": catalogue.fig_velocity_angle,
        "C.1": catalogue.fig_friction,
        "table6.1": table61,
        "E": (lambda: appendix_e_cached(out_dir, res)) if out_dir is not None
        else lambda: catalogue.fig_appendix_e(**APPENDIX_E_SETTINGS[res]),
    }
    out = {}
    for key, job in jobs.items():
        t0 = time.perf_counter()
        out[key] = job()
        if progress:
            progress("figure", key, time.perf_counter() - t0)
    return out


def run_all(out_dir: str | Path, *, quick: bool = False, workers: int | None = None,
            scheduler: str | None = None, progress: Progress | None = None,
            resolution: str | None = None) -> tuple[dict[str, Any], list[ClaimResult], float]:
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
        Worker processes (default all cores; 1 runs everything here).
    scheduler : str, optional
        Dask scheduler address for the studies.
    progress : callable, optional
        ``progress(stage, name, seconds)`` after each study and figure.
    resolution : {"tiny", "quick", "full"}, optional
        Overrides ``quick``; ``"tiny"`` (3 points a line, 3 x 3 grids, a
        short Appendix E) tests the pipeline, its numbers are not meant to be read.

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
    results, figures = run_catalogue(out, quick=res, workers=workers, scheduler=scheduler,
                                     progress=progress,
                                     side_job=lambda: single_figures(res, progress, out))
    data: dict[str, Any] = {**results, **figures, "quick": res != "full", "resolution": res}
    return data, evaluate(data), time.perf_counter() - t0
