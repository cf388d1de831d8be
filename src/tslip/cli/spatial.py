"""``tslip spatial ...``: the 3-D spring-mass runner of Seipel & Holmes (issue 43, Part 1)
and the 3-D TSLIP's lateral multipliers (Part 2: ``tslip spatial lateral``).

:data:`spatial_app` is added to the app as the ``spatial`` command group by
:mod:`tslip.cli.main`. Each command imports the model when it runs (a fast ``--help``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from .._checks import check_output, parse_number
from .._io import write_text
from ._common import Failed, errors, make_console

__all__ = ["spatial_app"]

spatial_app = typer.Typer(help="3-D running: the spring-mass runner of Seipel & Holmes 2005 "
                               "(symmetric gaits, multipliers, the paper's claims) and the "
                               "TSLIP's lateral multipliers.", no_args_is_help=True)


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
