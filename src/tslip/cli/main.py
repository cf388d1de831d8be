"""``tslip`` command line: the app, assembled from the subcommand modules.

Each subcommand module (:mod:`~tslip.cli.simulate`, :mod:`~tslip.cli.experiment`,
:mod:`~tslip.cli.gait`, :mod:`~tslip.cli.studies`, :mod:`~tslip.cli.design`,
:mod:`~tslip.cli.viability`, :mod:`~tslip.cli.explore`, :mod:`~tslip.cli.biped`,
:mod:`~tslip.cli.spatial`)
defines its commands and imports its shared options and error handling from
:mod:`tslip.cli._common`; this module only puts them together, adds
``--version`` and is the console script's entry point. Invalid input prints
one line ``error: <message>`` to stderr and exits with code 2.
"""

import sys
from typing import Annotated

import typer

from .. import __version__
from . import biped, design, experiment, explore, gait, simulate, spatial, studies, viability
from ._common import run

__all__ = ["app", "main"]

app = typer.Typer(
    name="tslip",
    help="Self-stable planar running with the spring-mass model with a trunk (TSLIP).",
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
)

# the order `tslip --help` lists
for _module in (simulate, experiment, gait, studies, design, viability, explore):
    app.registered_commands.extend(_module.commands.registered_commands)
app.add_typer(biped.biped_app, name="biped")
app.add_typer(spatial.spatial_app, name="spatial")


def _print_version(value: bool) -> None:
    if value:
        typer.echo(f"tslip {__version__}")
        raise typer.Exit()


@app.callback()
def _options(
    version: Annotated[bool, typer.Option(
        "--version", callback=_print_version, is_eager=True,
        help="Print the version (tslip X.Y.Z) and exit.")] = False,
) -> None:
    """Self-stable planar running with the spring-mass model with a trunk (TSLIP)."""


def main() -> None:
    """Entry point of the ``tslip`` console script (and ``python -m tslip``)."""
    sys.exit(run(app, prog_name="tslip"))
