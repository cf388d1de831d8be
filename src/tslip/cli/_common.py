"""What every ``tslip`` command shares: options, parameters, consoles and errors.

The subcommand modules import this module and nothing else from
:mod:`tslip.cli`; :mod:`tslip.cli.main` imports them and assembles the app,
so the imports inside the package form no cycle (``tests/cli/test_layout.py``).

Errors: bad input (a :class:`ValueError`) prints one line ``error: ...`` to
stderr and exits with code 2; valid input whose work fails (:class:`Failed`,
an unwritable output) exits with code 1; Ctrl-C exits with 130.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

from .._checks import check_output, parse_number

if TYPE_CHECKING:  # the model is imported when parameters are built: `tslip --help` stays fast
    from ..model.parameters import Params

__all__ = [
    "SchedulerOpt", "WorkersOpt",
    "DATA_SUFFIXES", "Failed", "ParamsOpt", "PresetOpt", "SetOpt", "build_params",
    "build_params_and_preset", "check_plot_suffix", "check_scheduler", "check_suffix",
    "echo_error", "errors",
    "fail", "file_size", "interruptible", "make_console", "progress_bar", "run", "stopped",
]


def _flag_shows_no_type(display: Any) -> Any:
    """Typer lists a flag's type as ``<bool>`` in ``--help`` (``--help`` itself too); a flag
    takes no value, so its type column is left empty (every command imports this module)."""
    def display_type_rich(self: Any, ctx: Any) -> str | None:
        return "" if getattr(self, "is_flag", False) else display(self, ctx)
    display_type_rich._tslip = True  # type: ignore[attr-defined]
    return display_type_rich


if not getattr(typer.core.TyperOption.display_type_rich, "_tslip", False):
    typer.core.TyperOption.display_type_rich = _flag_shows_no_type(  # type: ignore[method-assign]
        typer.core.TyperOption.display_type_rich)

#: Table files the commands read and write.
DATA_SUFFIXES = (".csv", ".parquet")

_STRING_KEYS = ("controller", "leg_reset", "retraction")

# -- options shared by several commands --------------------------------------------

PresetOpt = Annotated[
    str | None,
    typer.Option(
        "--preset", "-p",
        help="Base parameter set (see `tslip presets`); default: the --params file's preset, "
        "else table2.1.",
    ),
]
SetOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--set",
        "-s",
        metavar="KEY=VALUE",
        help="Override a parameter, e.g. k=30, omega_r_bar=0.2, controller=local_velocity, "
        "controller.Kd=0.4, leg_reset=global, retraction=apex, alpha_stop=1.3. Repeatable; "
        "applied after --params.",
    ),
]
ParamsOpt = Annotated[
    Path | None,
    typer.Option(
        "--params",
        metavar="FILE.toml",
        help="TOML file of parameters (a \\[params] table or top-level keys).",
    ),
]

# -- consoles and errors ---------------------------------------------------------------


WorkersOpt = Annotated[int | None, typer.Option("--workers", min=1,
                                                help="Worker processes (default: all cores).")]
SchedulerOpt = Annotated[str | None, typer.Option(
    "--scheduler", help="Dask scheduler address, e.g. tcp://127.0.0.1:8786 (needs "
    "tslip\\[dask]); refused if no scheduler answers within 10 s.")]

#: Seconds ``--scheduler`` is given to answer (:func:`check_scheduler`).
SCHEDULER_SECONDS = 10.0


def check_scheduler(address: str | None, echo: Any, seconds: float | None = None) -> None:
    """Refuse a ``--scheduler`` that is empty, malformed or does not answer, before any work
    (and before an output folder is made).

    One ``ValueError`` line naming ``--scheduler`` and what was wrong. The wait for an
    answer is announced (``echo``, one line) and lasts at most ``seconds`` (default
    :data:`SCHEDULER_SECONDS`).
    """
    if address is None:
        return
    from ..sweeps._schedule import check_scheduler as check

    check(address, SCHEDULER_SECONDS if seconds is None else seconds, echo)


def make_console(stderr: bool = False) -> Console:
    """A rich console that prints text as given (no markup, no highlighting)."""
    return Console(stderr=stderr, highlight=False, markup=False, soft_wrap=True)


class Failed(Exception):
    """The input was valid but the work did not succeed (e.g. no periodic gait): exit 1."""


def echo_error(message: str) -> None:
    """Print ``error: <message>`` as one line on stderr."""
    typer.echo("error: " + " ".join(message.split()), err=True)


def fail(message: str, code: int) -> None:
    """Print the error line and exit with ``code``."""
    echo_error(message)
    raise typer.Exit(code=code)


@contextmanager
def errors() -> Iterator[None]:
    """Turn ValueError (bad input) into ``error: ...`` and exit code 2."""
    try:
        yield
    except Failed as exc:
        fail(str(exc), 1)
    except ValueError as exc:
        fail(str(exc), 2)
    except OSError as exc:  # e.g. an output directory that cannot be written
        fail(f"{exc.strerror or exc}: {exc.filename}" if exc.filename else str(exc), 1)


def stopped(message: str) -> None:
    """Ctrl-C: one line on stderr, exit code 130 (128 + SIGINT), no traceback."""
    typer.echo(message, err=True)
    raise typer.Exit(code=130)


@contextmanager
def interruptible() -> Iterator[None]:
    """A Ctrl-C outside the work itself (e.g. while loading) also ends quietly."""
    try:
        yield
    except KeyboardInterrupt:
        stopped("interrupted")


class _Rate(TextColumn):
    """Items per second, e.g. ``12.0 pt/s``; nothing until rich has an estimate."""

    def __init__(self, unit: str) -> None:
        super().__init__("")
        self.unit = unit

    def render(self, task):  # noqa: ANN001, ANN201
        from rich.text import Text

        speed = task.finished_speed or task.speed
        return Text(f"{speed:5.1f} {self.unit}/s" if speed else "")


def progress_bar(unit: str) -> Progress:
    """The progress bar of long runs on stderr: done of total, rate in ``unit``/s, time left."""
    return Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                    _Rate(unit), TimeElapsedColumn(), TextColumn("left"), TimeRemainingColumn(),
                    console=make_console(stderr=True), transient=False)


def run(app: typer.Typer, prog_name: str) -> int:
    """Run ``app`` on ``sys.argv`` and return its exit code.

    Usage errors found by the option parser (``--steps abc``, an unknown
    option) print one line ``error: ...`` like every other bad input.
    """
    # typer's (vendored) click exceptions live beside BadParameter
    exc_mod = sys.modules[typer.BadParameter.__module__]
    try:
        code = app(prog_name=prog_name, standalone_mode=False)
    except exc_mod.NoArgsIsHelpError as exc:
        exc.show()
        return exc.exit_code
    except exc_mod.UsageError as exc:
        command = exc.ctx.command_path if exc.ctx is not None else prog_name
        echo_error(f"{exc.format_message()} (see `{command} --help`)")
        return exc.exit_code
    except exc_mod.ClickException as exc:
        echo_error(exc.format_message())
        return exc.exit_code
    except typer.Abort:
        echo_error("interrupted")
        return 130
    return code if isinstance(code, int) else 0


# -- parameters from --preset, --params and --set ------------------------------------


def _parse_sets(items: list[str] | None, base: Params) -> dict[str, Any]:
    """``["k=30", "controller.Kd=0.4"]`` -> overrides for :meth:`Params.from_dict`."""
    from ..model.parameters import PARAMETER_TABLE

    table = {row.name: row for row in PARAMETER_TABLE}
    out: dict[str, Any] = {}
    gains: dict[str, float] = {}
    seen: set[str] = set()
    for item in items or []:
        key, sep, value = item.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or not key or not value:
            raise ValueError(f"--set expects key=value, got {item!r}")
        if key in seen:
            raise ValueError(f"--set {key} is given twice; give it once")
        seen.add(key)
        if key.startswith("controller."):
            gains[key.split(".", 1)[1]] = parse_number(value, f"--set {key}")
        elif key in _STRING_KEYS:
            out[key] = value
        elif key in table or key in ("omega_r_bar", "alpha_stop"):
            unit = table[key].unit if key in table else {"alpha_stop": "rad"}.get(key, "-")
            out[key] = parse_number(value, f"--set {key} [{unit}]")
        else:
            raise ValueError(
                f"unknown parameter {key!r} in --set; allowed: {sorted(table)} plus "
                "omega_r_bar, alpha_stop, controller, controller.<gain>, leg_reset, retraction"
            )
    if gains:
        if "controller" in out:
            ctrl: dict[str, Any] = {"type": out["controller"]}
        else:
            ctrl = base.controller.to_dict()
        ctrl.update(gains)
        out["controller"] = ctrl
    return out


def build_params(
    preset_name: str | None, sets: list[str] | None, params_file: Path | None
) -> Params:
    """Parameters from the preset, then the ``--params`` file, then ``--set``."""
    return build_params_and_preset(preset_name, sets, params_file)[0]


def build_params_and_preset(
    preset_name: str | None, sets: list[str] | None, params_file: Path | None
) -> tuple[Params, str]:
    """:func:`build_params` and the name of the preset actually used.

    The preset comes from ``--preset`` or the file's ``preset`` key (default
    table2.1); both given with different values is an error naming both.
    """
    from ..model.parameters import Params, preset, presets, read_params_file

    data = {} if params_file is None else read_params_file(params_file)
    file_preset = data.pop("preset", None)
    if file_preset is not None:
        if not isinstance(file_preset, str):
            raise ValueError(f"parameter file {str(params_file)!r}: preset must be one of "
                             f"{presets()}, got {file_preset!r}")
        preset(file_preset)  # validates the name
        if preset_name is not None and preset_name.strip().lower() != file_preset.strip().lower():
            raise ValueError(
                f"--preset {preset_name!r} and preset = {file_preset!r} in "
                f"{str(params_file)!r} differ; give one of them"
            )
    name = preset_name or file_preset or "table2.1"
    params = preset(name)
    if data:
        try:
            params = Params.from_dict(data, base=params)
        except ValueError as exc:
            raise ValueError(f"parameter file {str(params_file)!r}: {exc}") from None
    overrides = _parse_sets(sets, params)
    if overrides:
        params = Params.from_dict(overrides, base=params)
    return params, name.strip().lower()


# -- output files ------------------------------------------------------------------------


def check_suffix(path: Path | None, allowed: tuple[str, ...], option: str) -> None:
    """Check an output file before the work: suffix allowed, directory writable."""
    if path is not None:
        check_output(path, option, allowed)


def check_plot_suffix(path: Path | None) -> None:
    """Check a ``--plot`` file: a format matplotlib writes, in a writable directory."""
    if path is None:
        return
    from matplotlib.figure import Figure

    allowed = tuple(f".{s}" for s in sorted(Figure().canvas.get_supported_filetypes()))
    check_suffix(path, allowed, "--plot")


def file_size(path: Path) -> str:
    """``"1.2 MB"`` or ``"340 kB"``."""
    n = path.stat().st_size
    return f"{n / 1e6:.1f} MB" if n >= 1e6 else f"{n / 1e3:.0f} kB"
