"""``tslip biped ...``: simulate, search, animate and report the two-legged model.

:data:`biped_app` is added to the app as the ``biped`` command group by
:mod:`tslip.cli.main`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from .._checks import check_number, check_output, parse_number
from .._io import write_json
from ._common import errors, make_console

if TYPE_CHECKING:  # each command imports the biped when it runs (a fast --help)
    import numpy as np

    from ..biped import BipedParams

__all__ = ["biped_app"]

biped_app = typer.Typer(help="Two-legged running model with massed legs (thesis App. E).",
                        no_args_is_help=True)

SetOpt = Annotated[list[str] | None, typer.Option(
    "--set", "-s", metavar="KEY=VALUE", help="Override a biped parameter, e.g. Kp_h=0.8.")]
GaitOpt = Annotated[str | None, typer.Option(
    "--gait", metavar="FILE.json|NAME", help="Start from a gait written by `tslip biped search` "
    "or a stored one: converged-e2, optimised.")]
TslipOpt = Annotated[str | None, typer.Option(
    "--from-tslip", metavar="PRESET",
    help="Start from this TSLIP preset's periodic gait (Table E.2's '+' entries; the rest "
         "from Table E.2), e.g. table6.1.")]
StridesOpt = Annotated[int, typer.Option("--strides", "-n", help="Number of strides.")]
TolOpt = Annotated[float, typer.Option("--tol", help="Integrator rtol = atol.")]


def _params(sets: list[str] | None, base: BipedParams | None = None) -> BipedParams:
    from ..biped import BipedParams

    changes: dict[str, Any] = {}
    for item in sets or []:
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or not key or not value.strip():
            raise ValueError(f"--set expects key=value, got {item!r}")
        if key in changes:
            raise ValueError(f"--set {key} is given twice; give it once")
        if value.strip().lower() in ("true", "false"):
            changes[key] = value.strip().lower() == "true"
            continue
        changes[key] = parse_number(value, f"--set {key}")
    return BipedParams.from_dict(changes, base)


def _check_strides(strides: int, tol: float | None = None) -> None:
    check_number(strides, "--strides", lower=1, upper=100_000, integer=True)
    if tol is not None:
        check_number(tol, "--tol", lower=0.0, upper=1.0, lower_open=True, upper_open=True)


def _start(sets: list[str] | None, gait: str | Path | None,
           from_tslip: str | None = None) -> tuple[BipedParams, np.ndarray, float]:
    """Parameters, start state and start time: Table E.2, a TSLIP gait or a saved gait."""
    from ..biped import BipedState

    if gait is not None and from_tslip is not None:
        raise ValueError("give at most one of --gait and --from-tslip")
    if gait is None:
        p = _params(sets)
        if from_tslip is None:
            return p, BipedState.thesis().to_array(), 0.0
        from ..biped.anchor import tslip_start
        from ..gait.fixed_point import find_gait
        from ..model.parameters import preset

        g = find_gait(preset(from_tslip))
        if not g.converged:
            raise ValueError(f"TSLIP preset {from_tslip!r} has no converged gait "
                             f"(residual {g.residual:.1e})")
        return p, tslip_start(g.state, p).to_array(), 0.0
    from ..biped.stored import load_gait

    p0, y, t0, _ = load_gait(gait)
    return _params(sets, p0), y, t0


@biped_app.command("simulate")
def simulate_cmd(
    sets: SetOpt = None,
    gait: GaitOpt = None,
    from_tslip: TslipOpt = None,
    strides: StridesOpt = 20,
    tol: TolOpt = 1e-8,
    out: Annotated[Path | None, typer.Option("--out", help="CSV of the run.")] = None,
) -> None:
    """Run the biped from Table E.2 (or a gait) and report strides and tracking."""
    from ..biped import BipedOptions, simulate
    from ..biped.gait import tracking_errors

    with errors():
        _check_strides(strides, tol)
        if out is not None:
            check_output(out, "--out", (".csv", ".parquet"))
        p, y, t0 = _start(sets, gait, from_tslip)
        tr = simulate(p, y, strides, t0=t0, options=BipedOptions(rtol=tol, atol=tol))
        c = make_console()
        c.print(f"{tr.n_steps} strides, {tr.status.reason} (t = {tr.stats['t_end']:.3f})")
        if tr.n_steps:
            for leg, name in ((0, "right"), (1, "left")):
                te = tracking_errors(tr, leg, t0, tr.strides[0, 0])
                c.print(f"{name} leg, stride 1: RMS error from the controller's references "
                        f"(eqs E.29, E.32): thigh length {te.thigh_rms:.2e} L, hip angle "
                        f"{te.hip_rms:.3f} rad")
        if out is not None:
            tr.save(out)  # the table, and its run record beside it (tslip.load reads both)
            c.print(f"wrote {out} and {out.with_suffix('.json')}")


def _gait_summary(p: BipedParams, z: np.ndarray, ev: np.ndarray | None,
                  strides: int) -> tuple[dict[str, Any], list[str]]:
    """Multipliers and strides until fall of a gait: JSON entries and printed lines."""
    import numpy as np

    from ..biped import simulate
    from ..biped.gait import from_section

    data: dict[str, Any] = {}
    lines: list[str] = []
    if ev is not None and np.all(np.isfinite(ev)):
        data["multipliers"] = [[float(m.real), float(m.imag)] for m in ev]
        data["largest_multiplier"] = float(np.abs(ev[0]))
        top = ", ".join(f"{abs(m):.4f}" for m in ev[:4])
        lines.append(f"largest multiplier magnitude {abs(ev[0]):.4f} "
                     f"({'stable' if abs(ev[0]) < 1 else 'unstable'}; leading: {top})")
    elif ev is not None:
        lines.append("multipliers: a perturbed stride falls (NaN)")
    y, t0 = from_section(p, z)
    tr = simulate(p, y, strides, t0=t0)
    data["strides_until_fall"] = tr.n_steps
    data["fall_reason"] = tr.status.reason
    lines.append(f"strides until fall: {tr.n_steps} of {strides} ({tr.status.reason})")
    return data, lines


@biped_app.command("search")
def search_cmd(
    out: Annotated[Path, typer.Option("--out", help="JSON of the best gait.")],
    sets: SetOpt = None,
    gait: GaitOpt = None,
    from_tslip: TslipOpt = None,
    free_param: Annotated[list[str] | None, typer.Option(
        "--free-param", help="Parameter freed in the refinement (repeatable; default "
        "T, theta_f, theta_s, Kp_h, Kd_h).")] = None,
    cma_evals: Annotated[int, typer.Option(
        "--cma-evals", help="CMA-ES strides before the refinement (0: refine only).")] = 0,
    sigma0: Annotated[float, typer.Option("--sigma0", help="CMA-ES initial step size.")] = 0.05,
    seed: Annotated[int, typer.Option("--seed", help="CMA-ES random seed.")] = 1,
    max_iter: Annotated[int, typer.Option(
        "--max-iter", help="Levenberg-Marquardt iterations of the refinement.")] = 30,
    tol: Annotated[float, typer.Option("--tol", help="Periodicity residual target.")] = 1e-8,
    multipliers: Annotated[bool, typer.Option(
        "--multipliers/--no-multipliers", help="Compute the gait's Floquet multipliers.")] = True,
    strides: Annotated[int, typer.Option(
        "--strides", "-n", help="Strides run from the result (strides until fall).")] = 50,
) -> None:
    """Periodic gait: optional CMA-ES (eqs E.35-E.36), then shooting refinement."""
    from ..biped.gait import find_periodic_gait, refine_periodic_gait, to_section

    with errors():
        check_output(out, "--out", (".json",))
        _check_strides(strides, tol)
        check_number(cma_evals, "--cma-evals", lower=0, upper=10**7, integer=True)
        check_number(sigma0, "--sigma0", lower=0.0, upper=1.0, lower_open=True)
        check_number(max_iter, "--max-iter", lower=1, upper=10**5, integer=True)
        check_number(seed, "--seed", lower=0, upper=2**32 - 1, integer=True)
        p, y, t0 = _start(sets, gait, from_tslip)
        z0 = to_section(p, y, t0)
        free = tuple(free_param) if free_param else ("T", "theta_f", "theta_s", "Kp_h", "Kd_h")
        c = make_console()
        history: list[float] = []
        evals = 0
        if cma_evals > 0:
            cm = find_periodic_gait(p, z0, free_params=("rho0",), bounds={"rho0": (0.0, 0.999)},
                                    cma_evals=cma_evals, lsq_evals=0, sigma0=sigma0, seed=seed)
            c.print(f"CMA-ES: best residual {cm.residual:.2e} ({cm.evaluations} strides)")
            history += cm.history
            evals += cm.evaluations
            p, z0 = cm.params, cm.z
        res = refine_periodic_gait(p, z0, free_params=free, tol=tol, max_iter=max_iter,
                                   multipliers=multipliers)
        history += res.history
        evals += res.evaluations
        c.print(res.message + f" ({evals} strides simulated)")
        data: dict[str, Any] = {"converged": res.converged, "residual": res.residual,
                                "z": res.z.tolist(), "params": res.params.to_dict(),
                                "free_params": list(free), "history": history}
        if math.isfinite(res.residual):
            extra, lines = _gait_summary(res.params, res.z, res.multipliers, strides)
            data.update(extra)
            for line in lines:
                c.print(line)
        write_json(out, data)
        c.print(f"wrote {out}")


@biped_app.command("animate")
def animate_cmd(
    out: Annotated[Path, typer.Option("--out", help="GIF or MP4 file.")],
    sets: SetOpt = None,
    gait: GaitOpt = None,
    from_tslip: TslipOpt = None,
    strides: StridesOpt = 5,
    fps: Annotated[int, typer.Option("--fps", help="Frames per second of the animation.")] = 25,
) -> None:
    """Animate the runner with both legs."""
    from ..biped import simulate
    from ..plotting.biped import animate_biped

    with errors():
        check_output(out, "--out", (".gif", ".mp4"))
        _check_strides(strides)
        check_number(fps, "--fps", lower=1, upper=1000, integer=True)
        p, y, t0 = _start(sets, gait, from_tslip)
        tr = simulate(p, y, strides, t0=t0)
        animate_biped(tr, out, fps=fps)
        make_console().print(f"{tr.n_steps} strides, {tr.status.reason}; wrote {out}")


@biped_app.command("report")
def report_cmd(
    out_dir: Annotated[Path, typer.Option("--out-dir", help="Directory for figures/tables.")],
    sets: SetOpt = None,
    gait: GaitOpt = None,
    from_tslip: TslipOpt = None,
    strides: StridesOpt = 50,
    robustness: Annotated[bool, typer.Option(
        "--robustness/--no-robustness",
        help="Also find the step-down, push and pitch-rate limits (25 strides).")] = False,
) -> None:
    """Write Figures E.2-E.4, the multiplier and metacentric tables (and robustness limits)."""
    import pandas as pd

    from .._io import save_figure, write_table, write_text
    from ..biped import BipedState, simulate
    from ..biped.gait import floquet, to_section
    from ..biped.metacentre import metacentric_table, metacentric_test
    from ..plotting.biped import plot_foot_path, plot_metacentric, plot_tracking

    with errors():
        check_output(out_dir / "multipliers.csv", "--out-dir")
        _check_strides(strides)
        p, y, t0 = _start(sets, gait, from_tslip)
        out_dir.mkdir(parents=True, exist_ok=True)
        tr = simulate(p, y, strides, t0=t0)
        c = make_console()
        c.print(f"strides until fall: {tr.n_steps} ({tr.status.reason})")
        save_figure(plot_tracking(tr), out_dir / "fig_e2_tracking.png", dpi=120)
        save_figure(plot_foot_path(tr), out_dir / "fig_e3_foot_path.png", dpi=120)
        meta = metacentric_test(p, BipedState.from_array(y), t0)
        save_figure(plot_metacentric(meta), out_dir / "fig_e4_metacentric.png", dpi=120)
        table = pd.DataFrame(metacentric_table(meta))
        write_table(table, out_dir / "metacentric.csv")
        c.print("metacentric test (right stance, legs fixed in the world): " + "; ".join(
            f"dtheta {r.dtheta:+.1f}: |I| {r.magnitude_change:+.1%}, lean {r.lean_change_deg:+.1f}"
            f" deg, dtorque {r.dtorque:+.4f} ({'restoring' if r.restoring else 'not restoring'})"
            for r in table.itertuples() if r.dtheta != 0.0))
        fr = floquet(p, to_section(p, y, t0))
        rows = ["index,real,imag,abs"] + [
            f"{i},{m.real:.6g},{m.imag:.6g},{abs(m):.6g}" for i, m in enumerate(fr.multipliers)
        ]
        write_text(out_dir / "multipliers.csv", "\n".join(rows) + "\n")
        c.print(f"largest multiplier {fr.max_nontrivial:.3f} "
                f"(periodicity residual {fr.residual:.2e})")
        if robustness:
            from ..biped.gait import Gait
            from ..biped.robustness import robustness_report

            start = Gait(True, fr.residual, fr.z, p, "the report's start", 0)
            rep = robustness_report(start, n_steps=25, tol=1e-3, check=False)
            lim = {r.kind: r.limit for r in rep.limits}
            c.print("robustness (25 strides): " + ", ".join(
                f"{k} {v:.4f}" for k, v in lim.items()) + "  (TSLIP Table 6.1: step_down "
                "-0.119, push -0.725, pitch_rate -0.733)")
            write_json(out_dir / "robustness.json", lim)
        c.print(f"wrote figures, multipliers.csv and metacentric.csv to {out_dir}")


@biped_app.command("optimise")
def optimise_cmd(
    out: Annotated[Path, typer.Option("--out", help="JSON of the most stable gait found.")],
    gait: Annotated[str, typer.Option(
        "--gait", metavar="FILE.json|NAME",
        help="Converged gait to start from (warm start), a file or a stored name.")],
    budget: Annotated[float, typer.Option("--budget", help="Wall-clock seconds.")] = 600.0,
    max_evals: Annotated[int, typer.Option("--max-evals", help="Designs scored at most.")] = 400,
    popsize: Annotated[int, typer.Option("--popsize", help="CMA-ES designs per generation.")] = 8,
    sigma0: Annotated[float, typer.Option("--sigma0", help="CMA-ES step (bounds scaled "
                                          "to [0, 1]).")] = 0.08,
    seed: Annotated[int, typer.Option("--seed", help="CMA-ES random seed.")] = 3,
    processes: Annotated[int, typer.Option(
        "--processes", "-j", help="Processes scoring a generation (1: this one).")] = 1,
) -> None:
    """Beyond the thesis: minimise the largest multiplier over gains, sweep, duty, masses.

    The best gait is written to --out at every improvement; Ctrl-C stops
    with the best so far, and --gait OUT continues from it.
    """
    import numpy as np

    from ..biped import BipedParams
    from ..biped.design import DESIGN_BOUNDS, check_search_settings, stable_gait_search
    from ..biped.gait import section_multipliers, to_section

    with errors():
        check_output(out, "--out", (".json",))
        check_search_settings(
            {"budget_s": "--budget", "max_evals": "--max-evals", "popsize": "--popsize",
             "sigma0": "--sigma0", "seed": "--seed", "processes": "--processes"},
            budget_s=budget, max_evals=max_evals, popsize=popsize, sigma0=sigma0, seed=seed,
            processes=processes)
        p, y, t0 = _start(None, gait)
        z0 = to_section(p, y, t0)
        c = make_console()

        def checkpoint(b: dict[str, Any]) -> None:  # a usable --gait file at every new best
            write_json(out, {"design": b["design"], "bounds": DESIGN_BOUNDS,
                              "evaluations": b["evaluations"], "residual": b["residual"],
                              "largest_multiplier": b["score"], "converged": True,
                              "params": b["params"], "z": b["z"], "checkpoint": True})

        r = stable_gait_search(p, z0, budget_s=budget, max_evals=max_evals, popsize=popsize,
                               sigma0=sigma0, seed=seed, processes=processes, log=c.print,
                               on_improve=checkpoint)
        b = r.best
        data: dict[str, Any] = {"design": b.get("design"), "bounds": DESIGN_BOUNDS,
                                "evaluations": r.evaluations, "seconds": r.seconds,
                                "history": list(r.history), "residual": b["residual"],
                                "converged": b["score"] < 10.0, "interrupted": r.interrupted}
        if "z" in b:
            bp = BipedParams.from_dict(b["params"])
            data.update(params=b["params"], z=b["z"])
            ev = section_multipliers(bp, np.asarray(b["z"]))
            extra, lines = _gait_summary(bp, np.asarray(b["z"]), ev, 50)
            data.update(extra)
            for line in lines:
                c.print(line)
        c.print(f"best score {b['score']:.4f} after {r.evaluations} designs "
                f"({r.seconds:.0f} s)")
        write_json(out, data)
        c.print(f"wrote {out}")
