"""``tslip presets``, ``simulate``, ``animate`` and ``demo``: the TSLIP's parameters and runs.

A thin skin over the public API: options are parsed into :class:`tslip.Params`
(preset, then ``--params`` TOML, then ``--set key=value``), the periodic gait
is solved with :func:`tslip.gait.find_gait`, :func:`tslip.simulate` runs it,
and results go to explicit output files (with the version and the code hash
in the ``.json`` beside them).
"""

from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich import box
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

from .. import __version__
from .._checks import check_number, check_output
from ._common import (
    DATA_SUFFIXES,
    Failed,
    ParamsOpt,
    PresetOpt,
    SetOpt,
    build_params,
    build_params_and_preset,
    check_plot_suffix,
    check_suffix,
    errors,
    file_size,
    make_console,
)

if TYPE_CHECKING:  # the commands import the model's code when they run (a fast --help)
    from ..gait import Gait
    from ..model.parameters import Params
    from ..model.state import TouchdownState
    from ..simulation import Trajectory

__all__ = ["commands", "presets_cmd", "simulate_cmd", "animate_cmd", "demo_cmd"]

#: ``presets``, ``simulate``, ``animate``, ``demo``, added to the app by :mod:`tslip.cli.main`.
commands = typer.Typer()

_ANIM_SUFFIXES = (".gif", ".mp4")
#: The modules that compute a run (gait search, simulation): their code hash goes into the
#: ``.json`` beside the data, next to ``tslip_version``, like a study's ``run.json``.
CODE = ("tslip.gait.fixed_point", "tslip.simulation.integrate")

# -- options of these commands -------------------------------------------------------------

StepsOpt = Annotated[int, typer.Option("--steps", "-n", help="Number of strides.")]
DtOpt = Annotated[
    float, typer.Option("--dt", help="Sample interval \\[g^-1/2 L^1/2].")
]
RtolOpt = Annotated[float, typer.Option("--rtol", help="Stance integrator relative tolerance.")]
AtolOpt = Annotated[float, typer.Option("--atol", help="Stance integrator absolute tolerance.")]
NoGaitOpt = Annotated[
    bool,
    typer.Option(
        "--no-gait", help="Start from v0, delta=-0.1, beta0 instead of the solved periodic gait."
    ),
]


# -- helpers ---------------------------------------------------------------------------


def _start(
    params: Params, no_gait: bool, console: Console
) -> tuple[Params, TouchdownState, Gait | None]:
    """Return the starting parameters and state: the periodic gait by default."""
    from ..gait import find_gait
    from ..model.state import TouchdownState

    if no_gait:
        state = TouchdownState.from_velocity(v=params.v0, delta=-0.1, beta=params.beta0)
        console.print(
            f"start: v0 = {params.v0:g}, delta = -0.1, beta0 = {params.beta0:g} (no gait search)"
        )
        return params, state, None
    gait = find_gait(params)
    console.print(f"gait: {gait.message}", style="green" if gait.converged else "yellow")
    if not gait.converged:
        raise Failed(f"no periodic gait found ({gait.message}); --no-gait starts from "
                     "v0, beta0 instead")
    console.print(
        f"      delta = {gait.state.delta:+.6f}, phi = {gait.state.phi:+.6f}, "
        f"phid = {gait.state.phid:+.6f}, alpha_r = {gait.params.alpha_r:.6f}"
    )
    return gait.params, gait.state, gait


def _check_run_options(steps: int, dt: float, rtol: float, atol: float,
                       params: Params | None = None) -> None:
    """Validate run options before the (slower) gait search; with ``params``, the size too."""
    check_number(steps, "--steps", lower=1, integer=True)
    check_number(dt, "--dt", unit="g^-1/2 L^1/2", lower=0.0, lower_open=True)
    check_number(rtol, "--rtol", lower=0.0, upper=1.0, lower_open=True, upper_open=True)
    check_number(atol, "--atol", lower=0.0, upper=1.0, lower_open=True, upper_open=True)
    if params is not None:
        from ..simulation.integrate import check_simulation_size

        check_simulation_size(params, steps, dt, "--steps")


def _run(
    params: Params,
    state: TouchdownState,
    steps: int,
    dt: float,
    rtol: float,
    atol: float,
    meta: dict[str, Any],
) -> Trajectory:
    from .._codehash import code_hash
    from ..simulation import IntegratorOptions, simulate

    options = IntegratorOptions(rtol=rtol, atol=atol)
    traj = simulate(params, state, steps, dt=dt, options=options)
    meta = {
        **traj.meta,
        "options": {"rtol": rtol, "atol": atol},
        "start": dataclasses.asdict(state),
        "code": code_hash(*CODE),
        **meta,
    }
    return dataclasses.replace(traj, meta=meta)


def _gait_meta(gait: Gait | None) -> dict[str, Any] | None:
    if gait is None:
        return None
    return {
        "converged": gait.converged,
        "residual": gait.residual,
        "message": gait.message,
        "stance_time": gait.stance_time,
        "flight_time": gait.flight_time,
    }


def _steps_table(traj: Trajectory) -> Table:
    table = Table(
        box=box.SIMPLE_HEAD,
        pad_edge=False,
        show_edge=False,
        title="touch-down state and stride times per stride",
    )
    for name in ("step", "v", "delta", "beta", "phi", "phid", "t_s", "t_f"):
        table.add_column(name, justify="right", no_wrap=True)
    table.add_column("status", justify="left", overflow="fold")
    for i, s in enumerate(traj.steps):
        td = s.start
        table.add_row(
            str(i),
            f"{td.v:.4f}",
            f"{td.delta:+.4f}",
            f"{td.beta:.4f}",
            f"{td.phi:+.4f}",
            f"{td.phid:+.4f}",
            f"{s.stance_time:.4f}",
            f"{s.flight_time:.4f}",
            "fall" if s.status.fell else "error" if s.status.is_error else "ok",
        )
    return table


def _status_line(traj: Trajectory) -> str:
    from ..simulation import Status

    st = traj.status
    t_end = float(traj["t"][-1]) if len(traj.data) else 0.0
    x_end = float(traj["x"][-1]) if len(traj.data) else 0.0
    if st == Status.OK:
        return (
            f"status: OK, {len(traj.steps)} strides completed "
            f"(t = {t_end:.3f} g^-1/2 L^1/2, x = {x_end:.3f} L)"
        )
    return f"status: {st.name} in stride {len(traj.steps) - 1}: {st.reason} (t = {t_end:.3f})"


def _energy_drift(traj: Trajectory) -> float:
    import numpy as np

    e = traj["energy"]
    if len(e) == 0 or e[0] == 0:
        return math.nan
    return float(np.max(np.abs(e - e[0])) / abs(e[0]))


def _write_animation(traj: Trajectory, out: Path, fps: float, speed: float, dpi: float) -> Path:
    from ..plotting.animation import animate

    err = make_console(stderr=True)
    with Progress(
        TextColumn("rendering {task.description}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total} frames"),
        TimeRemainingColumn(),
        console=err,
        transient=True,
    ) as bar:
        task = bar.add_task(out.name, total=None)

        def progress(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        return animate(traj, out, fps=fps, speed=speed, dpi=dpi, progress=progress)


def _save_plot(traj: Trajectory, path: Path) -> Path:
    from .._io import save_figure
    from ..plotting.trajectories import plot_trajectory

    return save_figure(plot_trajectory(traj), path, dpi=110)


# -- commands ------------------------------------------------------------------------


@commands.command("presets")
def presets_cmd(
    name: Annotated[
        str | None, typer.Argument(help="Show one preset in detail (all parameters).")
    ] = None,
) -> None:
    """List the parameter presets from the thesis tables."""
    from ..model.parameters import preset, preset_description, presets

    with errors():
        console = make_console()
        if name is not None:
            console.print(_preset_detail(name))
            return
        names = presets()
        overview = Table(title="presets", box=box.SIMPLE_HEAD)
        overview.add_column("#", justify="right")
        overview.add_column("name", no_wrap=True)
        overview.add_column("controller", no_wrap=True)
        overview.add_column("description")
        for k, n in enumerate(names, 1):
            overview.add_row(str(k), n, preset(n).controller.name, preset_description(n))
        console.print(overview)
        console.print(_preset_matrix(names))
        console.print(
            "Columns are the presets by #. `tslip presets NAME` shows one preset "
            "with descriptions and sources."
        )


def _preset_matrix(names: list[str]) -> Table:
    from ..model.parameters import PARAMETER_TABLE, preset

    ps = [preset(n) for n in names]
    table = Table(title="parameters (dimensionless units of thesis Table 3.1)", box=box.SIMPLE_HEAD)
    table.add_column("symbol", no_wrap=True)
    table.add_column("unit", no_wrap=True)
    for k in range(1, len(names) + 1):
        table.add_column(f"#{k}", justify="right", no_wrap=True)
    for row in PARAMETER_TABLE:
        table.add_row(row.symbol, row.unit, *(f"{getattr(p, row.name):g}" for p in ps))
    seen: dict[str, tuple[str, str]] = {}
    for p in ps:
        for f in dataclasses.fields(p.controller):
            seen.setdefault(f.name, (f.metadata.get("symbol", f.name), f.metadata.get("unit", "")))
    for fname, (symbol, unit) in seen.items():
        table.add_row(
            symbol,
            unit,
            *(
                f"{getattr(p.controller, fname):g}" if hasattr(p.controller, fname) else "-"
                for p in ps
            ),
        )
    table.add_row("leg_reset", "", *(p.leg_reset for p in ps))
    table.add_row("retraction", "", *(p.retraction for p in ps))
    return table


def _preset_detail(name: str) -> Table:
    from ..model.parameters import PARAMETER_TABLE, preset, preset_description

    p = preset(name)
    table = Table(title=f"{name}: {preset_description(name)}", box=box.SIMPLE_HEAD)
    table.add_column("name (--set)", no_wrap=True)
    table.add_column("value", justify="right", no_wrap=True)
    table.add_column("unit", no_wrap=True)
    table.add_column("description [source]")
    for row in PARAMETER_TABLE:
        table.add_row(
            row.name, f"{getattr(p, row.name):g}", row.unit, f"{row.description} [{row.source}]"
        )
    doc = (type(p.controller).__doc__ or "").strip().splitlines()
    table.add_row("controller", p.controller.name, "", doc[0] if doc else "")
    for f in dataclasses.fields(p.controller):
        table.add_row(
            f"controller.{f.name}",
            f"{getattr(p.controller, f.name):g}",
            f.metadata.get("unit", ""),
            f.metadata.get("description", ""),
        )
    table.add_row("leg_reset", p.leg_reset, "", "frame of the leg reset at lift-off")
    table.add_row("retraction", p.retraction, "", "start of the retraction clock: lift-off "
                  "or apex")
    return table


@commands.command("simulate")
def simulate_cmd(
    preset_name: PresetOpt = None,
    steps: StepsOpt = 20,
    sets: SetOpt = None,
    params_file: ParamsOpt = None,
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help="Write the time series (.csv or .parquet, + .json)."),
    ] = None,
    plot: Annotated[
        Path | None,
        typer.Option("--plot", help="Save the trajectory plot (.png, .pdf, .svg)."),
    ] = None,
    dt: DtOpt = 0.01,
    rtol: RtolOpt = 1e-8,
    atol: AtolOpt = 1e-8,
    no_gait: NoGaitOpt = False,
) -> None:
    """Simulate strides from the periodic gait and print a per-stride summary."""
    with errors():
        _check_run_options(steps, dt, rtol, atol)
        check_suffix(out, DATA_SUFFIXES, "--out")
        check_plot_suffix(plot)
        console = make_console()
        params, preset_used = build_params_and_preset(preset_name, sets, params_file)
        _check_run_options(steps, dt, rtol, atol, params)
        params, state, gait = _start(params, no_gait, console)
        traj = _run(
            params,
            state,
            steps,
            dt,
            rtol,
            atol,
            {
                "command": "simulate",
                "preset": preset_used,
                "set": list(sets or []),
                "params_file": None if params_file is None else str(params_file),
                "gait": _gait_meta(gait),
            },
        )
        console.print(_steps_table(traj))
        console.print(_status_line(traj))
        if out is not None:
            traj.save(out)
            console.print(f"wrote {out} ({file_size(out)}) and {out.with_suffix('.json')}")
        if plot is not None:
            _save_plot(traj, plot)
            console.print(f"wrote {plot} ({file_size(plot)})")
    if traj.status.is_error:
        raise typer.Exit(code=1)


@commands.command("animate")
def animate_cmd(
    out: Annotated[Path, typer.Option("--out", "-o", help="Animation file (.gif or .mp4).")],
    preset_name: PresetOpt = None,
    steps: StepsOpt = 10,
    sets: SetOpt = None,
    params_file: ParamsOpt = None,
    fps: Annotated[float, typer.Option("--fps", help="Frames per second.")] = 30.0,
    speed: Annotated[
        float, typer.Option("--speed", help="Playback speed vs real time for a 1 m leg.")
    ] = 0.25,
    dpi: Annotated[float, typer.Option("--dpi", help="Resolution of the 640x360 frames.")] = 100.0,
    dt: DtOpt = 0.01,
    rtol: RtolOpt = 1e-8,
    atol: AtolOpt = 1e-8,
    no_gait: NoGaitOpt = False,
) -> None:
    """Simulate and write an animation of the runner (.gif or .mp4)."""
    with errors():
        _check_run_options(steps, dt, rtol, atol)
        check_suffix(out, _ANIM_SUFFIXES, "--out")
        check_number(fps, "--fps", lower=0.0, upper=1000.0, lower_open=True)
        check_number(speed, "--speed", lower=0.0, upper=100.0, lower_open=True)
        check_number(dpi, "--dpi", lower=10.0, upper=1000.0)
        console = make_console()
        params = build_params(preset_name, sets, params_file)
        _check_run_options(steps, dt, rtol, atol, params)
        params, state, gait = _start(params, no_gait, console)
        traj = _run(params, state, steps, dt, rtol, atol, {"command": "animate"})
        console.print(_status_line(traj))
        _write_animation(traj, out, fps, speed, dpi)
        console.print(f"wrote {out} ({file_size(out)})")


@commands.command("demo")
def demo_cmd(
    out_dir: Annotated[
        Path, typer.Option("--out-dir", help="Directory for run.csv, run.json, run.png, run.gif.")
    ] = Path("tslip-demo"),
    steps: StepsOpt = 20,
) -> None:
    """Solve the Table 2.1 passive gait, simulate it, write data, plot and animation."""
    from ..model.parameters import preset, preset_description

    with errors():
        _check_run_options(steps, 0.01, 1e-8, 1e-8, preset("table2.1"))
        check_output(out_dir / "run.csv", "--out-dir")
        console = make_console()
        t_start = time.perf_counter()
        name = "table2.1"
        console.print(f"tslip {__version__} demo: {preset_description(name)}")
        params, state, gait = _start(preset(name), False, console)
        assert gait is not None
        traj = _run(
            params,
            state,
            steps,
            0.01,
            1e-8,
            1e-8,
            {"command": "demo", "preset": name, "gait": _gait_meta(gait)},
        )
        console.print(_steps_table(traj))
        console.print(_status_line(traj))
        out_dir.mkdir(parents=True, exist_ok=True)
        written = [
            traj.save(out_dir / "run.csv"),
            out_dir / "run.json",
            _save_plot(traj, out_dir / "run.png"),
            _write_animation(traj, out_dir / "run.gif", 30.0, 0.25, 100.0),
        ]
        ts, tf = gait.stance_time, gait.flight_time
        summary = Table(title="periodic gait (Table 2.1, passive)", box=box.SIMPLE_HEAD)
        summary.add_column("quantity")
        summary.add_column("value", justify="right")
        summary.add_column("unit")
        summary.add_row("stance time t_s", f"{ts:.4f}", "g^-1/2 L^1/2")
        summary.add_row("flight time t_f", f"{tf:.4f}", "g^-1/2 L^1/2")
        summary.add_row("duty factor d = t_s/(t_s+t_f)", f"{ts / (ts + tf):.4f}", "-")
        summary.add_row("step frequency f = 1/(t_s+t_f)", f"{1.0 / (ts + tf):.4f}", "g^1/2 L^-1/2")
        summary.add_row("periodicity residual", f"{gait.residual:.1e}", "-")
        summary.add_row("max relative energy drift", f"{_energy_drift(traj):.1e}", "-")
        console.print(summary)
        for path in written:
            console.print(f"wrote {path} ({file_size(path)})")
        console.print(f"done in {time.perf_counter() - t_start:.1f} s")
