"""``tslip viability SPEC.toml``: a state-action map and its viability kernel."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Annotated

import typer

from .._checks import check_output
from ._common import errors, interruptible, make_console, progress_bar, stopped

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
    scheduler: Annotated[str | None, typer.Option(
        "--scheduler", help="Dask scheduler address (needs tslip\\[dask]); the chunks run "
        "on its cluster and are cached here.")] = None,
) -> None:
    """Compute (or resume) the viable state-action set of a grid at fixed energy.

    The spec (TOML): name; preset; energy \\[MgL] of every cell; rule ("bracket" or
    "nearest"); optional \\[params] overrides and \\[options] (IntegratorOptions);
    one to three \\[\\[state]] apex variables (the height "y", and "phi" and/or
    "phid"; each a name with from/to/points or values) and one \\[action] (a
    parameter, e.g. name = "alpha_r", with its values), or one or two
    \\[actions.<name>] tables with their values (e.g. \\[actions.alpha_r] and
    \\[actions.omega_r]).
    Example and meaning: the documentation page "Viability and basins of
    attraction" (docs/analyses/viability.md).

    Each chunk of cells is saved as it finishes: after Ctrl-C (or a crash)
    the same command resumes with the missing ones.
    """
    from ..sweeps.run import StudyInterrupted
    from ..sweeps.viability import ViabilitySpec, run_viability

    console = make_console()
    with errors(), interruptible():
        spec = ViabilitySpec.from_toml(spec_path)
        if rule is not None:  # the cached map serves every rule: only the iteration reruns
            spec = dataclasses.replace(spec, rule=rule)
        out_dir = out if out is not None else Path("viability") / spec.name
        check_output(out_dir / "run.json", "--out")  # before any work, naming the user's path
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
        console.print(f"{spec.name}: {res.q.size} cells, {int(res.map.failed.sum())} fail at "
                      f"once, {int(res.q.sum())} viable ({100 * res.viable_fraction:.1f} %), "
                      f"{int(res.s.sum())} of {res.s.size} states viable, {res.sweeps} sweeps")
        console.print(f"wrote {out_dir / 'results.parquet'} (with results.json) and run.json")
        if plot:
            fig = res.plot().figure
            fig.savefig(out_dir / "viability.png", dpi=120)
            console.print(f"wrote {out_dir / 'viability.png'}")
