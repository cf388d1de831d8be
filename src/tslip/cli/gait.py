"""``tslip gait`` (one gait's report) and ``tslip continue`` (a branch)."""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Annotated, Any

import typer
from rich import box
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

from .._checks import check_fits, check_number, check_output
from .._io import save_figure
from ._common import (
    DATA_SUFFIXES,
    ParamsOpt,
    PresetOpt,
    SetOpt,
    build_params,
    check_plot_suffix,
    check_suffix,
    errors,
    fail,
    file_size,
    make_console,
)

__all__ = ["commands", "gait_cmd", "continue_cmd"]

#: ``gait`` and ``continue``, added to the app by :mod:`tslip.cli.main`.
commands = typer.Typer()

#: Memory one branch point holds at least: its gait, multipliers and table row.
_POINT_BYTES = 2000.0


#: Why a multiplier is trivial (tslip.gait.stability.Floquet.trivial_kinds).
_TRIVIAL = {"energy": "trivial (conserved energy)", "pitch": "trivial (decoupled pitch, r = 0)"}


def _fmt(x: Any, digits: int = 4) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    if isinstance(x, float):
        return f"{x:.{digits}f}" if abs(x) >= 1e-3 or x == 0 else f"{x:.2e}"
    return str(x)


def _table(title: str, *cols: str) -> Table:
    t = Table(title=title, box=box.SIMPLE_HEAD, title_justify="left", pad_edge=False)
    for i, c in enumerate(cols):
        t.add_column(c, justify="left" if i == 0 else "right")
    return t


def _print_report(rep: dict[str, Any]) -> None:
    console = make_console()
    g = rep["gait"]
    console.print(f"gait: {g['message']}")
    t = _table("touch-down state of the gait", "beta", "phi", "xd", "yd", "phid", "v", "delta")
    t.add_row(*(_fmt(g["state"][k]) for k in ("beta", "phi", "xd", "yd", "phid", "v", "delta")))
    console.print(t)
    p = g["params"]
    ctrl = {k: v for k, v in p["controller"].items() if k != "type"}
    solved = ", ".join([f"alpha_r = {p['alpha_r']:.6f}"]
                       + [f"{k} = {v:.6f}" for k, v in ctrl.items()])
    console.print(f"solved: {solved} ({p['controller']['type']})")
    fl = rep["floquet"]
    if "error" in fl:
        console.print(f"multipliers: {fl['error']}")
    else:
        t = _table(f"Floquet multipliers: {fl['stability']}, largest non-trivial "
                   f"{fl['max_nontrivial']:.4f}", "lambda", "|lambda|", "")
        for m in fl["multipliers"]:
            z = complex(m["re"], m["im"])
            t.add_row(f"{z.real:+.5f}{z.imag:+.5f}j", f"{m['abs']:.5f}",
                      _TRIVIAL.get(m.get("trivial_kind", ""), "") if m["trivial"] else "")
        console.print(t)
    s = rep["stride"]
    t = _table("stride", "quantity", "model", "theory", "source")
    t.add_row("stance time t_s", _fmt(s["stance_time"]), _fmt(s["stance_time_predicted"]),
              "eq. 3.10")
    t.add_row("flight time t_f", _fmt(s["flight_time"]), _fmt(s["flight_time_predicted"]),
              "eq. 3.11")
    t.add_row("duty factor", _fmt(s["duty_factor"]), "", "t_s / (t_s + t_f)")
    t.add_row("step frequency", _fmt(s["step_frequency"]), "", "1 / (t_s + t_f)")
    t.add_row("bounce time t_b", "", _fmt(s["bounce_time"]), "eq. 3.9")
    t.add_row("fast-running index", "", _fmt(s["fast_running_index"]), "eq. 3.12")
    console.print(t)
    rb = rep.get("robustness")
    if rb is not None:
        if "error" in rb:
            console.print(f"robustness: {rb['error']}")
        else:
            t = _table("robustness (largest survived disturbance, 25 strides)", "disturbance",
                       "limit", "first failing run")
            for kind, r in rb.items():
                t.add_row(kind, _fmt(r["limit"]), f"{r['status']} in stride {r['fall_stride']}"
                          if r["status"] else "")
            console.print(t)
    im = rep["impulse"]
    if "error" in im:
        console.print(f"impulse: {im['error']}")
    else:
        n = im["nominal"]
        t = _table(f"ground impulse: I = ({n['I_x']:.4f}, {n['I_y']:.4f}), x_p = "
                   f"{n['x_p']:.4f}; response to pitch", "dphi", "torque", "restoring",
                   "distance to hip / r", "direction change")
        for row in im["pitch"]:
            t.add_row(_fmt(row["dphi"], 2), _fmt(row["torque"]),
                      "yes" if row["restoring"] else "no", _fmt(row["hip_distance_over_r"]),
                      _fmt(row["direction_change"]))
        console.print(t)
    fr = rep["friction"]
    if "error" in fr:
        console.print(f"no-slip: {fr['error']}")
    else:
        console.print(f"no-slip (mu = {fr['mu']:g}): |F_x|/F_y exceeds mu in "
                      f"{100 * fr['slip_fraction']:.1f}% of stance"
                      + (f", from t/t_s = {fr['first_slip']:.2f}" if fr["first_slip"] else ""))


@commands.command("gait")
def gait_cmd(
    preset_name: PresetOpt = None,
    sets: SetOpt = None,
    params_file: ParamsOpt = None,
    method: Annotated[
        str, typer.Option("--method", help="Gait search: newton (least squares) or cma.")
    ] = "newton",
    seed: Annotated[int, typer.Option("--seed", help="CMA-ES seed.")] = 1,
    as_json: Annotated[bool, typer.Option("--json", help="Print the report as JSON.")] = False,
    plot: Annotated[
        Path | None,
        typer.Option("--plot", metavar="DIR", help="Write GRF / impulse figures to DIR."),
    ] = None,
    no_robustness: Annotated[
        bool, typer.Option("--no-robustness", help="Skip the robustness limits.")
    ] = False,
) -> None:
    """Solve the periodic gait and report stability, strides, robustness, impulse."""
    from ..gait import analyse, find_gait, impulse_linearisation
    from ..gait import pitch_disturbance_response as pitch_response
    from ..gait.stride import friction_ratio

    with errors():
        if method not in ("newton", "cma"):
            raise ValueError(f"--method must be 'newton' or 'cma', got {method!r}")
        check_number(seed, "--seed", lower=0, upper=2**32 - 1, integer=True)
        if plot is not None:
            check_output(plot / "friction.png", "--plot")
        params = build_params(preset_name, sets, params_file)
        gait = find_gait(params, method="cma" if method == "cma" else "newton", seed=seed)
        if not gait.converged:
            fail(gait.message, 1)
        rep = analyse(params, gait=gait, robustness=not no_robustness).to_dict()
        if as_json:
            typer.echo(json.dumps(rep, indent=2))
        else:
            _print_report(rep)
        if plot is not None:
            from ..plotting import plot_friction, plot_impulse_linearisation, plot_pitch_impulse

            figs = {
                "pitch_impulse.png": plot_pitch_impulse(pitch_response(gait)),
                "impulse_linearisation.png": plot_impulse_linearisation(
                    impulse_linearisation(gait)),
                "friction.png": plot_friction(friction_ratio(gait.params, gait.state)),
            }
            for name, fig in figs.items():
                save_figure(fig, plot / name)
                if not as_json:
                    make_console().print(f"wrote {plot / name} ({file_size(plot / name)})")


@commands.command("continue")
def continue_cmd(
    param: Annotated[str, typer.Option("--param", help="Parameter to vary, e.g. r, v0, "
                                       "omega_r_bar, controller.c_h.")],
    start: Annotated[float, typer.Option("--from", help="First value.")],
    stop: Annotated[float, typer.Option("--to", help="Last value.")],
    points: Annotated[int, typer.Option("--points", "-n", help="Number of values.")] = 50,
    preset_name: PresetOpt = None,
    sets: SetOpt = None,
    params_file: ParamsOpt = None,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="Save the branch (.csv or .parquet).")
    ] = None,
    plot: Annotated[
        Path | None, typer.Option("--plot", help="Save the multiplier plot (.png).")
    ] = None,
) -> None:
    """Follow the periodic gait along a parameter; print and save the branch."""
    import numpy as np

    from ..gait import continue_gait, get_param

    with errors():
        check_number(points, "--points", lower=2, integer=True)
        check_fits(points, _POINT_BYTES, "--points", "the branch")
        if not (math.isfinite(start) and math.isfinite(stop) and start < stop):
            raise ValueError(f"--from must be below --to (both finite), got {start}, {stop}")
        check_suffix(out, DATA_SUFFIXES, "--out")
        check_plot_suffix(plot)
        params = build_params(preset_name, sets, params_file)
        get_param(params, param)  # validates the name
        values = np.linspace(start, stop, points)
        console = make_console()
        t0 = time.perf_counter()
        with Progress(TextColumn(f"continuing along {param}"), BarColumn(),
                      MofNCompleteColumn(), TimeRemainingColumn(), console=make_console(True),
                      transient=True) as bar:
            task = bar.add_task("points", total=points)
            branch = continue_gait(params, param, values,
                                   progress=lambda i, n, v, g: bar.update(task, completed=i))
        df = branch.to_dataframe()
        t = _table(f"branch along {param} ({time.perf_counter() - t0:.1f} s)", param,
                   "gait", "max |lambda|", "stability", "t_s", "t_f")
        for row in df.itertuples():
            t.add_row(_fmt(row.value), "yes" if row.converged else "no",
                      _fmt(row.max_nontrivial), str(row.stability), _fmt(row.stance_time),
                      _fmt(row.flight_time))
        console.print(t)
        lo, hi = branch.exists()
        stable = branch.values[branch.stable]
        console.print(f"gait exists for {param} in [{_fmt(lo)}, {_fmt(hi)}]; "
                      + (f"stable in [{_fmt(stable.min())}, {_fmt(stable.max())}]"
                         if stable.size else "stable nowhere"))
        if out is not None:
            branch.save(out)  # the table, and its run record beside it (tslip.load reads both)
            console.print(f"wrote {out} ({file_size(out)}) and {out.with_suffix('.json')}")
        if plot is not None:
            from ..plotting import plot_branch

            save_figure(plot_branch(branch), plot)
            console.print(f"wrote {plot} ({file_size(plot)})")
