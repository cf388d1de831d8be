"""``tslip study SPEC.toml`` (one study) and ``tslip reproduce`` (every thesis study)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer
from rich import box
from rich.table import Table

from .._checks import check_output
from ._common import (
    SchedulerOpt,
    WorkersOpt,
    check_scheduler,
    errors,
    interruptible,
    make_console,
    progress_bar,
    stopped,
)

__all__ = ["commands", "study_cmd", "reproduce_cmd"]

#: ``study`` and ``reproduce``, added to the app by :mod:`tslip.cli.main`.
commands = typer.Typer()



def _saved_message(out: Path, quick: bool) -> str:
    """``N of M points saved`` over every catalogue study under ``out/studies``."""
    from ..sweeps import catalogue
    from ..sweeps.run import StudyInterrupted, saved_points

    specs = catalogue.studies(quick)
    saved = sum(saved_points(spec, out / "studies" / name) for name, spec in specs.items())
    return str(StudyInterrupted(saved, sum(s.n_points for s in specs.values())))


@commands.command("study")
def study_cmd(
    spec_path: Annotated[Path, typer.Argument(help="Study spec (TOML).", metavar="SPEC.toml")],
    out: Annotated[Path | None, typer.Option("--out", help="Output folder (default: "
                                             "studies/<name>).")] = None,
    workers: WorkersOpt = None,
    scheduler: SchedulerOpt = None,
    csv: Annotated[bool, typer.Option("--csv", help="Also write results.csv.")] = False,
    wait: Annotated[bool, typer.Option("--wait", help="If another run is writing the "
                                       "output folder, wait for it (default: stop).")] = False,
) -> None:
    """Run (or resume) one parameter study from a TOML spec.

    Every point is saved as it finishes: after Ctrl-C (or a crash) the same
    command resumes with the missing points.
    """
    from ..sweeps import StudySpec, run_study
    from ..sweeps._warmup import MODEL_FAMILIES, announce
    from ..sweeps.run import StudyInterrupted

    console = make_console()
    with errors(), interruptible():
        spec = StudySpec.from_toml(spec_path)
        out_dir = out if out is not None else Path("studies") / spec.name
        check_output(out_dir / "run.json", "--out")  # before any work, naming the user's path
        check_scheduler(scheduler, console.print)  # before the folder is made
        from ..sweeps._lock import folder_lock
        from ..sweeps.run import check_study_folder

        with folder_lock(out_dir, wait=wait):  # refused (or waited for) before the bar is drawn
            check_study_folder(spec, out_dir)  # and a link where its points are saved
        t0 = time.perf_counter()
        if spec.model == "tslip":  # the fork server compiles both TSLIP families
            packages, only = ("simulation",), None
        else:  # a 3-D study: its model's family, compiled before the pool starts
            packages, only = ("spatial",), MODEL_FAMILIES[spec.model]
        with progress_bar("pt") as bar, announce(bar.console.print, packages, only=only):
            task = bar.add_task(f"study {spec.name}", total=spec.n_points)
            try:
                res = run_study(spec, out_dir, workers=workers, scheduler=scheduler, csv=csv,
                                wait=wait,
                                progress=lambda done, total: bar.update(task, completed=done))
            except StudyInterrupted as exc:
                bar.stop()
                stopped(str(exc))
    f = res.frame
    n_stable = int(f["stability"].isin(["asymptotic", "neutral"]).sum())
    console.print(f"{spec.name}: {len(f)} points ({res.meta['cached']} cached), "
                  f"{int(f['converged'].sum())} with a periodic gait, {n_stable} stable or "
                  f"neutral, {time.perf_counter() - t0:.1f} s")
    console.print(f"wrote {out_dir / 'results.parquet'}" + (" and results.csv" if csv else "")
                  + " and run.json")


#: Colour of each verdict in the claims table, by its text; "not assessed" stays plain.
_STYLE = {"holds": "green", "holds under a stated reading": "yellow",
          "does not hold": "bold red", "not assessed": "dim"}


@commands.command("reproduce")
def reproduce_cmd(
    quick: Annotated[bool, typer.Option("--quick", help="Coarse resolution (12-14 s once "
                                        "the kernels are compiled).")] = False,
    out: Annotated[Path, typer.Option("--out", help="Report folder.")] = Path("report"),
    workers: WorkersOpt = None,
    scheduler: SchedulerOpt = None,
) -> None:
    """Run every thesis study and write a report (out/index.html).

    A first run (empty numba cache) compiles the kernels first and says so
    (on a terminal with the time elapsed): --quick then takes 43 s on a
    quiet 2-core machine (48 s of CPU compiling, on both cores), several
    minutes on a loaded one. Once the kernels are cached, --quick takes
    12-14 s into a new folder, 5 s into the same one (2026-12-02).
    """
    from contextlib import ExitStack

    from rich.text import Text

    t0 = time.perf_counter()
    console = make_console()
    with errors():
        check_output(out / "index.html", "--out")  # before any work, naming the user's path
        check_scheduler(scheduler, console.print)  # before the folder is made
    # at once, before the slower imports (tslip.sweeps imports the analyses and numba);
    # a first run then says that it compiles
    console.print(f"reproducing the thesis at {'quick' if quick else 'full'} resolution into "
                  f"{out}")
    from ..sweeps._warmup import announce

    compiling = ExitStack()
    compiling.enter_context(announce(console.print, terminal=console))
    from ..plotting.report import figure_inputs, read_claims, reproduce
    from ..sweeps import catalogue
    from ..sweeps.claims import Verdict, count_verdicts

    n_studies = len(catalogue.STUDIES)
    state = {"studies": 0}

    def progress(stage: str, name: str, seconds: float) -> None:
        el = time.perf_counter() - t0
        if stage == "workers":
            console.print(f"[{el:6.1f} s] {n_studies} studies, {len(figure_inputs())} figures "
                          f"on {name} worker{'s' if name != '1' else ''}")
        elif stage == "study":
            state["studies"] += 1
            console.print(f"[{el:6.1f} s] study {state['studies']:2d}/{n_studies} {name} "
                          f"done ({seconds:.1f} s)")
        elif stage == "figure":
            console.print(f"[{el:6.1f} s] figure {name} ({seconds:.1f} s)")

    with errors(), interruptible(), compiling:
        try:
            path = reproduce(out, quick=quick, workers=workers, scheduler=scheduler,
                             progress=progress)
        except KeyboardInterrupt:
            stopped(_saved_message(out, quick))
    with errors():
        claims = read_claims(path.with_name("claims.json"))
    t = Table(title="thesis claims", box=box.SIMPLE_HEAD, title_justify="left")
    t.add_column("figure")
    t.add_column("claim")
    t.add_column("verdict")
    for c in claims:
        v = Verdict(c["verdict"])
        t.add_row(Text(c["figure"]), Text(c["claim"]), Text(v.value, style=_STYLE.get(v, "")))
    console.print(t)
    counts = ", ".join(f"{v.value}: {n}" for v, n in count_verdicts(claims).items())
    console.print(f"{len(claims)} claims; {counts}; {time.perf_counter() - t0:.1f} s")
    console.print(f"report: {path}")
