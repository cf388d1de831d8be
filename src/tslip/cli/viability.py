"""``tslip viability SPEC.toml``: a state-action map and its viability kernel."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from pathlib import Path
from typing import Annotated

import typer

from .. import _gridsize
from .._checks import check_output
from .._io import read_toml
from ._common import (
    SchedulerOpt,
    check_scheduler,
    errors,
    interruptible,
    make_console,
    progress_bar,
    stopped,
)

__all__ = ["commands", "viability_cmd"]

#: ``viability``, added to the app by :mod:`tslip.cli.main`.
commands = typer.Typer()


@commands.command("viability")
def viability_cmd(
    spec_path: Annotated[Path, typer.Argument(help="Viability spec (TOML).",
                                              metavar="SPEC.toml")],
    out: Annotated[Path | None, typer.Option("--out", help="Output folder (default: "
                                             "viability/<name>).")] = None,
    workers: Annotated[int | None, typer.Option("--workers", min=1, help="Worker processes "
                                                "(default: by the work, up to all cores).")]
    = None,
    rule: Annotated[str | None, typer.Option("--rule", help='Cell rule: "bracket" (tslip\'s '
                                             'default), "nearest" or "vibly" (vibly\'s); '
                                             "default: the spec's rule.")] = None,
    plot: Annotated[bool, typer.Option("--plot", help="Also draw viability.png.")] = False,
    wait: Annotated[bool, typer.Option("--wait", help="If another run is writing the "
                                       "output folder, wait for it (default: stop).")] = False,
    scheduler: SchedulerOpt = None,
) -> None:
    """Compute (or resume) the viable state-action set of a grid at fixed energy.

    The spec (TOML): name; preset; energy \\[MgL] of every cell; rule
    ("bracket", "nearest" or "vibly", as --rule); optional \\[params]
    overrides and \\[options] (IntegratorOptions); one to three \\[\\[state]]
    apex variables, each a different one (the height "y", and "phi" and/or
    "phid"; each a name with from/to/points or values) and one \\[action] (a
    parameter, e.g. name = "alpha_r", with its values), or one or two
    \\[actions.<name>] tables with their values (e.g. \\[actions.alpha_r] and
    \\[actions.omega_r]).
    Example and meaning: the documentation page "Viability and basins of
    attraction" (docs/analyses/viability.md).

    Each chunk of cells is saved as it finishes: after Ctrl-C (or a crash)
    the same command resumes with the missing ones. With --scheduler the
    chunks run on that Dask cluster and are cached here. A grid whose run
    would not fit in memory is refused before any work, with its estimate.
    """
    console = make_console()
    with errors(), interruptible():
        said = _grid_line(spec_path, rule, console.print)  # before the kernels' import
        import numpy as np

        from ..gait.viability import StoredMap
        from ..simulation.result import Status
        from ..sweeps.run import StudyInterrupted
        from ..sweeps.viability import ViabilitySpec, run_viability

        spec = ViabilitySpec.from_toml(spec_path)
        if rule is not None:  # the cached map serves every rule: only the iteration reruns
            spec = dataclasses.replace(spec, rule=rule)
        out_dir = out if out is not None else Path("viability") / spec.name
        check_output(out_dir / "run.json", "--out")  # before any work, naming the user's path
        spec.check_fits()  # before anything is allocated or the folder made
        if not said:
            console.print(_grid_text(spec.name, spec.n_cells, len(spec.chunks())))
        check_scheduler(scheduler, console.print)
        from ..sweeps._lock import folder_lock

        with folder_lock(out_dir, wait=wait):  # refused (or waited for) before the bar is drawn
            pass
        with progress_bar("cells") as bar:
            task = bar.add_task(f"viability {spec.name}", total=spec.n_cells)
            try:
                res = run_viability(spec, out_dir, workers=workers, wait=wait,
                                    scheduler=scheduler,
                                    progress=lambda done, total: bar.update(task,
                                                                            completed=done))
            except StudyInterrupted as exc:
                bar.stop()
                stopped(str(exc))
        smap = res.map  # stored (an output folder): its failures counted chunk by chunk
        fell = (sum(int(np.count_nonzero(st != Status.OK)) for _, st in smap.chunks())
                if isinstance(smap, StoredMap) else int(smap.failed.sum()))
        console.print(f"{spec.name}: {res.q.size} cells, {fell} fail at "
                      f"once, {int(res.q.sum())} viable ({100 * res.viable_fraction:.1f} %), "
                      f"{int(res.s.sum())} of {res.s.size} states viable, {res.sweeps} "
                      f"sweep{'s' if res.sweeps != 1 else ''}")
        console.print(f"wrote {out_dir / 'results.parquet'} (with results.json) and run.json")
        if plot:
            from .._io import save_figure

            save_figure(res.plot().figure, out_dir / "viability.png", dpi=120)
            console.print(f"wrote {out_dir / 'viability.png'}")


def _grid_line(spec_path: Path, rule: str | None, echo: Callable[[str], None]) -> bool:
    """The grid's first line (cells, chunks), or its refusal if its run does not fit in
    memory (:func:`tslip._gridsize.check_run_fits`), from the spec's tables alone: before
    the kernels are imported (seconds) or a grid is made. False if the tables cannot be
    read so (the spec's parse then says why)."""
    try:
        data = read_toml(spec_path, "viability spec")
    except ValueError:
        return False
    points = _gridsize.grid_points(data)
    name = data.get("name", spec_path.stem)
    rule = rule if rule is not None else data.get("rule", "bracket")
    if points is None or not isinstance(name, str) or not isinstance(rule, str):
        return False
    _gridsize.check_run_fits(name, *points, rule, True)
    cells = math.prod(points[0]) * math.prod(points[1])
    echo(_grid_text(name, cells, _gridsize.n_chunks(*points)))
    return True


def _grid_text(name: str, cells: int, chunks: int) -> str:
    return f"{name}: {cells} cell{'s' if cells != 1 else ''} in {chunks} chunk" + (
        "s" if chunks != 1 else "")
