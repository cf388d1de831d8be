"""``tslip spatial ...``: the 3-D spring-mass runner of Seipel & Holmes (issue 43, Part 1),
the 3-D TSLIP's lateral multipliers (Part 2: ``tslip spatial lateral``) and its recorded
runs (``tslip spatial run``, ``tslip spatial animate``: a front and a side view).

:data:`spatial_app` is added to the app as the ``spatial`` command group by
:mod:`tslip.cli.main`. Each command imports the model when it runs (a fast ``--help``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from .._checks import check_number, check_output, parse_number
from .._io import write_text
from ._common import (
    DATA_SUFFIXES,
    Failed,
    check_plot_suffix,
    check_suffix,
    errors,
    file_size,
    make_console,
    progress_bar,
)

__all__ = ["spatial_app"]

spatial_app = typer.Typer(help="3-D running: the spring-mass runner of Seipel & Holmes 2005 "
                               "(symmetric gaits, multipliers, the paper's claims), the "
                               "TSLIP's lateral multipliers and its runs (data, plot, "
                               "animation).", no_args_is_help=True)


def _params(preset_name: str, sets: list[str] | None) -> Any:
    import dataclasses

    from ..spatial import TrunkParams, preset

    p = preset(preset_name)
    if isinstance(p, TrunkParams):
        raise ValueError(f"--preset must be slip3d or slip3d-feedback here, got "
                         f"{preset_name!r} (the 3-D TSLIP: tslip spatial lateral)")
    changes: dict[str, Any] = {}
    names = {f.name for f in dataclasses.fields(p)}
    for item in sets or []:
        key, sep, value = item.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or not key or not value:
            raise ValueError(f"--set expects key=value, got {item!r}")
        if key not in names:
            raise ValueError(f"--set {key}: not a parameter; one of {', '.join(sorted(names))}")
        changes[key] = value if key == "heading" else parse_number(value, f"--set {key}")
    return dataclasses.replace(p, **changes)


@spatial_app.command("gait")
def gait_cmd(
    energy: Annotated[float, typer.Option("--energy", "-E", help="Total energy [MgL].")],
    preset_name: Annotated[str, typer.Option(
        "--preset", help="slip3d or slip3d-feedback.")] = "slip3d",
    sets: Annotated[list[str] | None, typer.Option(
        "--set", "-s", metavar="KEY=VALUE",
        help="Override a parameter, e.g. k_lat=1.5 or heading=velocity.")] = None,
) -> None:
    """Find the left-right symmetric gaits at this energy and print their multipliers."""
    with errors():
        from ..spatial import floquet, symmetric_gaits

        p = _params(preset_name, sets)
        gaits = symmetric_gaits(p, energy=energy)
        if not gaits:
            raise Failed(f"no symmetric gait found at energy {energy:g} MgL")
        c = make_console()
        c.print(f"{p}")
        for g in gaits:
            f = floquet(g)
            a = g.apex
            mult = ", ".join(f"{z:.4g}" for z in f.nontrivial)
            c.print(f"apex y {a.y:.6f} L, vx {a.vx:.6f}, vz {a.vz:.6f}: non-trivial "
                    f"multipliers {mult} ({'stable' if f.largest < 1.0 else 'unstable'})")


@spatial_app.command("claims")
def claims_cmd(
    out: Annotated[Path | None, typer.Option("--out", help="Markdown file (.md).")] = None,
    small: Annotated[bool, typer.Option(
        "--small", help="One point of each grid axis (seconds instead of minutes).")] = False,
) -> None:
    """Judge the paper's two claims on the grid of docs/analyses/spatial.md."""
    with errors():
        if out is not None:
            check_output(out, "--out", (".md",))
        from ..spatial.claims import main as claims_main

        claims_main((["--out", str(out)] if out is not None else []) + (["--small"] if small
                                                                          else []))


@spatial_app.command("lateral")
def lateral_cmd(
    out: Annotated[Path | None, typer.Option("--out", help="Markdown file (.md).")] = None,
    small: Annotated[bool, typer.Option(
        "--small", help="One point of each table (seconds instead of a minute).")] = False,
    r: Annotated[float | None, typer.Option(
        "--r", help="One gait only: mass offset r [L] (default 0.3).")] = None,
    splay: Annotated[float | None, typer.Option(
        "--splay", help="One gait only: splay [rad] (default 0.05).")] = None,
    k_splay: Annotated[float | None, typer.Option(
        "--k-splay", help="One gait only: splay per roll angle (default 0).")] = None,
    k_trail: Annotated[float | None, typer.Option(
        "--k-trail", help="One gait only: placement yaw per roll angle (default 0).")] = None,
) -> None:
    """Lateral multipliers of the 3-D Table 2.1 TSLIP (docs/analyses/spatial_tslip.md): the
    tables over splay, r and the roll couplings, or one gait (--r, --splay, --k-splay,
    --k-trail)."""
    with errors():
        if out is not None:
            check_output(out, "--out", (".md",))
        one = {key: v for key, v in (("r", r), ("splay", splay), ("k_splay", k_splay),
                                     ("k_trail", k_trail)) if v is not None}
        from ..spatial import lateral

        if not one:
            lateral.main((["--out", str(out)] if out is not None else [])
                         + (["--small"] if small else []))
            return
        p = lateral.table21_params(**one)  # refuses a bad field in one line
        text = lateral.markdown([lateral.lateral_point(p)]) + "\n"
        if out is not None:
            write_text(out, text)  # atomically: a link at --out is replaced
        else:
            make_console().print(text, markup=False)


# -- the 3-D TSLIP's runs ------------------------------------------------------------------

StepsOpt = Annotated[int, typer.Option("--steps", "-n", help="Number of strides.")]
ROpt = Annotated[float | None, typer.Option(
    "--r", help="Mass offset r \\[L] (default 0.3; a change solves the gait, slower).")]
SplayOpt = Annotated[float | None, typer.Option(
    "--splay", help="Splay \\[rad] (default 0.05; a change solves the gait).")]
KSplayOpt = Annotated[float | None, typer.Option(
    "--k-splay", help="Splay per roll angle (default 0; a change solves the gait).")]
KTrailOpt = Annotated[float | None, typer.Option(
    "--k-trail", help="Placement yaw per roll angle (default 0; a change solves the gait).")]
PushOpt = Annotated[float, typer.Option(
    "--push", help="Lateral push added to vz at the first touch-down \\[g^1/2 L^1/2].")]


def _trunk_start(r: float | None, splay: float | None, k_splay: float | None,
                 k_trail: float | None, push: float, console: Any) -> tuple[Any, Any]:
    """The 3-D Table 2.1 TSLIP and its symmetric gait's right touch-down, pushed by ``push``:
    the stored gait (``lateral.TABLE21_3D_SECTION``) or, for changed parameters, the gait
    the continuation of ``tslip spatial lateral`` reaches."""
    from ..spatial import lateral
    from ..spatial.trunk_section import from_section

    check_number(push, "--push", unit="g^1/2 L^1/2")
    one = {key: v for key, v in (("r", r), ("splay", splay), ("k_splay", k_splay),
                                 ("k_trail", k_trail)) if v is not None}
    p = lateral.table21_params(**one)  # refuses a bad field in one line
    if p == lateral.table21_params():
        x = lateral.TABLE21_3D_SECTION.copy()
    else:
        console.print("solving the symmetric gait by continuation from the planar Table 2.1 "
                      "gait ...")
        x = lateral.table21_gait(p)
    x[6] += push
    return p, from_section(p, x, 1)


def _run_table(run: Any) -> Any:
    from rich import box
    from rich.table import Table

    table = Table(box=box.SIMPLE_HEAD, pad_edge=False, show_edge=False,
                  title="per stride: the touch-down, stance and flight times")
    for name in ("stride", "side", "roll", "yaw", "vz", "z", "t_s", "t_f"):
        table.add_column(name, justify="right", no_wrap=True)
    from ..spatial.trunk import rotation
    from ..spatial.trunk_run import attitude

    for i, td in enumerate(run.touchdowns[:run.n_strides]):
        yaw, _, roll = attitude(rotation(td[:13]))
        table.add_row(str(i), "right" if td[16] > 0 else "left", f"{roll:+.5f}",
                      f"{yaw:+.5f}", f"{td[5]:+.5f}", f"{td[2]:+.5f}",
                      f"{run.stance_times[i]:.4f}", f"{run.flight_times[i]:.4f}")
    return table


def _status(run: Any) -> str:
    t = float(run["t"][-1]) if len(run.data) else 0.0
    if run.status.name == "OK":
        return f"status: OK, {run.n_strides} strides (t = {t:.3f} g^-1/2 L^1/2)"
    return f"status: {run.status.name} in stride {run.fall_stride} (t = {t:.3f})"


@spatial_app.command("run")
def run_cmd(
    steps: StepsOpt = 20,
    out: Annotated[Path | None, typer.Option(
        "--out", "-o", help="Write the samples (.csv or .parquet, + .json; or .json).")] = None,
    plot: Annotated[Path | None, typer.Option(
        "--plot", help="Save the CoM path from the side and above (.png, .pdf, .svg).")] = None,
    r: ROpt = None,
    splay: SplayOpt = None,
    k_splay: KSplayOpt = None,
    k_trail: KTrailOpt = None,
    push: PushOpt = 0.0,
) -> None:
    """Run the 3-D Table 2.1 TSLIP from its symmetric gait (optionally pushed sideways) and
    print its strides; the samples and a plot to files."""
    with errors():
        check_number(steps, "--steps", lower=1, upper=10_000, integer=True)
        check_suffix(out, (*DATA_SUFFIXES, ".json"), "--out")
        check_plot_suffix(plot)
        from ..spatial.trunk_run import trunk_run

        console = make_console()
        p, state = _trunk_start(r, splay, k_splay, k_trail, push, console)
        run = trunk_run(p, state, steps)
        console.print(_run_table(run))
        console.print(_status(run))
        if out is not None:
            run.save(out)  # atomically, with the run record
            console.print(f"wrote {out} ({file_size(out)})")
        if plot is not None:
            from .._io import save_figure

            save_figure(run.plot(), plot, dpi=110)
            console.print(f"wrote {plot} ({file_size(plot)})")
    if run.status.is_error:
        raise typer.Exit(code=1)


@spatial_app.command("animate")
def animate_cmd(
    out: Annotated[Path, typer.Option("--out", "-o", help="Animation file (.gif or .mp4).")],
    steps: StepsOpt = 6,
    r: ROpt = None,
    splay: SplayOpt = None,
    k_splay: KSplayOpt = None,
    k_trail: KTrailOpt = None,
    push: PushOpt = 0.0,
    fps: Annotated[float, typer.Option("--fps", help="Frames per second.")] = 30.0,
    speed: Annotated[float, typer.Option(
        "--speed", help="Playback speed vs real time for a 1 m leg.")] = 0.25,
    dpi: Annotated[float, typer.Option("--dpi", help="Resolution of the 800x360 frames.")
                   ] = 100.0,
) -> None:
    """Run the 3-D Table 2.1 TSLIP and write an animation with a front and a side view."""
    with errors():
        check_number(steps, "--steps", lower=1, upper=10_000, integer=True)
        check_suffix(out, (".gif", ".mp4"), "--out")
        check_number(fps, "--fps", lower=0.0, upper=1000.0, lower_open=True)
        check_number(speed, "--speed", lower=0.0, upper=100.0, lower_open=True)
        check_number(dpi, "--dpi", lower=10.0, upper=1000.0)
        from ..plotting.spatial import animate_run
        from ..spatial.trunk_run import trunk_run

        console = make_console()
        p, state = _trunk_start(r, splay, k_splay, k_trail, push, console)
        run = trunk_run(p, state, steps)
        console.print(_status(run))
        with progress_bar("frames") as bar:  # on stderr
            task = bar.add_task(f"rendering {out.name}", total=None)
            animate_run(run, out, fps=fps, speed=speed, dpi=dpi,
                        progress=lambda done, total: bar.update(task, completed=done,
                                                                total=total))
        console.print(f"wrote {out} ({file_size(out)})")
