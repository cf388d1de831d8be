"""``tslip design SPEC.toml``: the Pareto front of a design search (:func:`tslip.design`)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer

from .._checks import check_output
from ._common import (
    SchedulerOpt,
    WorkersOpt,
    check_scheduler,
    errors,
    interruptible,
    make_console,
    progress_bar,
)

__all__ = ["commands", "design_cmd"]

#: ``design``, added to the app by :mod:`tslip.cli.main`.
commands = typer.Typer()


@commands.command("design")
def design_cmd(
    spec_path: Annotated[Path, typer.Argument(
        help="Design spec (TOML; see docs/analyses/design.md).", metavar="SPEC.toml")],
    out: Annotated[Path | None, typer.Option("--out", help="Output folder (default: "
                                             "designs/<name>).")] = None,
    workers: WorkersOpt = None,
    scheduler: SchedulerOpt = None,
    budget: Annotated[int | None, typer.Option(
        "--budget", min=1, help="Evaluations (default: the spec's budget).")] = None,
) -> None:
    """Search the Pareto front of free parameters between objectives (needs tslip\\[design]).

    Every evaluation is saved as it finishes: after Ctrl-C the same command resumes,
    computing only the missing ones, and ends with the same designs.
    """
    import dataclasses

    from .._io import save_figure
    from ..sweeps._lock import folder_lock
    from ..sweeps._warmup import announce
    from ..sweeps.design_spec import DesignSpec
    from ..sweeps.pareto import budget_note, check_folder, design, require_pymoo

    console = make_console()
    with errors(), interruptible():
        require_pymoo()  # refused before anything is drawn or written
        spec = DesignSpec.from_toml(spec_path)
        if budget is not None:
            spec = dataclasses.replace(spec, budget=budget)
        out_dir = out if out is not None else Path("designs") / spec.name
        check_output(out_dir / "run.json", "--out")
        check_scheduler(scheduler, console.print)  # before the folder is made
        if (note := budget_note(spec)) is not None:
            console.print(note, highlight=False)
        t0 = time.perf_counter()
        with folder_lock(out_dir):  # refused before the bar is drawn if another run writes it
            check_folder(out_dir)  # and a link where it would write
        with progress_bar("designs") as bar, announce(bar.console.print, ("simulation",)):
            task = bar.add_task(f"design {spec.name}", total=spec.generations * spec.population)
            res = design(spec, out_dir, workers=workers, scheduler=scheduler,
                         progress=lambda done, total: bar.update(task, completed=done))
        save_figure(res.plot(), out_dir / "front.png", dpi=120)  # a link there is replaced
    f = res.frame
    console.print(f"{spec.name}: {len(f)} designs ({res.meta['reused']} reused), "
                  f"{int(f['feasible'].sum())} feasible, {len(res.front)} on the Pareto front, "
                  f"{time.perf_counter() - t0:.1f} s")
    console.print(f"wrote {out_dir / 'designs.parquet'}, front.csv, front.png, gaits/ "
                  "and run.json")
