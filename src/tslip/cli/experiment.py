"""``tslip synth-video | track | process | fit | experiment``: the experiment pipeline.

Each command writes a file the next one reads: a video (+ ground truth),
a tracks table, a steps table, the fit (tables 6.2/6.3 and figures).
Problems print as one line naming the frame range; a fatal one exits
non-zero after writing what was tracked.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from .._checks import check_number, check_output
from .._io import save_figure, write_json, write_table
from ._common import DATA_SUFFIXES, PresetOpt, SetOpt, build_params, errors, fail, make_console

if TYPE_CHECKING:  # imported by the commands that read tables (a fast --help)
    import pandas as pd

__all__ = ["commands", "synth_video_cmd", "track_cmd", "process_cmd", "fit_cmd", "experiment_cmd"]

#: ``synth-video``, ``track``, ``process``, ``fit``, ``experiment``, added to the app by
#: :mod:`tslip.cli.main`.
commands = typer.Typer()

_SPACING = 0.18
_MARKER_R = 0.025
_FOOT_R = 0.016


def _bar(label: str) -> Progress:
    return Progress(TextColumn(label), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                    console=make_console(stderr=True), transient=True)


#: Columns `tslip process` reads from a tracks table (written by `tslip track`).
_TRACK_COLUMNS = ("t", "body_q", "front_x_m", "front_y_m", "rear_x_m", "rear_y_m",
                  "foot1_x_m", "foot1_y_m", "foot1_q", "foot2_x_m", "foot2_y_m", "foot2_q")
#: Columns `tslip fit` reads from a steps table (written by `tslip process`).
_STEP_COLUMNS = ("step", "tau", "stance_time", "flight_time", "y", "l", "beta", "phi", "xd",
                 "yd", "ld", "betad", "phid")


def _read_table(path: Path, columns: tuple[str, ...], what: str) -> pd.DataFrame:
    """Read a .csv/.parquet table that must have numeric ``columns`` (one-line errors)."""
    import pandas as pd

    if path.suffix.lower() not in DATA_SUFFIXES:
        raise ValueError(f"{what} must be a .csv or .parquet table, got {str(path)!r}")
    if not path.is_file():
        raise ValueError(f"{what} {str(path)!r} does not exist")
    try:
        table = pd.read_parquet(path) if path.suffix.lower() == ".parquet" else pd.read_csv(path)
    except Exception as exc:  # pandas and pyarrow raise many kinds for a broken file
        why = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ValueError(f"{what} {str(path)!r} cannot be read: {why}") from None
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise ValueError(f"{what} {str(path)!r} lacks column {missing[0]!r}; it needs "
                         f"{', '.join(columns)}")
    bad = [c for c in columns if not pd.api.types.is_numeric_dtype(table[c])]
    if bad:
        raise ValueError(f"{what} {str(path)!r}: column {bad[0]!r} must hold numbers")
    return table


@commands.command("synth-video")
def synth_video_cmd(
    out: Annotated[Path, typer.Option("--out", "-o", help="Video: .mp4 or a folder of PNGs.")]
    = Path("synthetic.mp4"),
    preset_name: PresetOpt = "table6.1",
    sets: SetOpt = None,
    duration: Annotated[float, typer.Option("--duration", help="Length \\[s].")] = 1.0,
    fps: Annotated[float, typer.Option("--fps", help="Frame rate \\[Hz].")] = 1000.0,
    width: Annotated[int, typer.Option("--width", help="Frame width \\[px].")] = 1024,
    height: Annotated[int, typer.Option("--height", help="Frame height \\[px].")] = 816,
    field_width: Annotated[float, typer.Option("--field-width",
                                               help="Scene width in the frame \\[m].")] = 0.88,
    noise: Annotated[float, typer.Option("--noise", help="Sensor noise \\[grey levels].")] = 3.0,
    seed: Annotated[int, typer.Option("--seed", help="Noise seed.")] = 0,
    biped_gait: Annotated[str | None, typer.Option(
        "--biped-gait", metavar="FILE.json|NAME",
        help="Render the two-legged model (Appendix E) from this gait, as written by `tslip "
             "biped search` or stored (converged-e2, optimised), instead of the preset's "
             "TSLIP gait.")] = None,
) -> None:
    """Render a simulated run as a treadmill video with a ground-truth CSV.

    The run is the preset's TSLIP gait, or with --biped-gait the two-legged
    model of Appendix E (--preset is then unused).
    """
    with errors():
        from ..experiment.render import check_mp4_size, write_video
        from ..experiment.synth import (
            Camera,
            RenderOptions,
            check_recording,
            synthesize,
            synthesize_biped,
        )
        from ..gait import find_gait

        cam = Camera(width=width, height=height, fps=fps, field_width=field_width)
        render = RenderOptions(noise=noise, seed=seed)
        check_recording(duration, cam)
        if out.suffix.lower() == ".mp4":
            check_mp4_size(width, height)
            check_output(out, "--out")
        elif out.suffix:
            raise ValueError(f"--out must be an .mp4 file or a folder (no suffix), got "
                             f"{str(out)!r}")
        else:
            check_output(out / "frame_000000.png", "--out")
        if biped_gait is not None:
            if sets:
                raise ValueError("--set changes the TSLIP preset; it cannot be combined with "
                                 "--biped-gait")
            from ..biped.stored import load_gait

            bp, y, t0, gd = load_gait(biped_gait)
            run = synthesize_biped(bp, y, duration, t0=t0, camera=cam, options=render)
            model: dict[str, Any] = {"model": "biped", "gait_file": str(biped_gait),
                                     "params": bp.to_dict(), "z": list(gd["z"]), "t0": t0}
        else:
            params = build_params(preset_name, sets, None)
            gait = find_gait(params)
            if not gait.converged:
                fail(f"no periodic gait for the preset: {gait.message}", 1)
            run = synthesize(gait.params, gait.state, duration, camera=cam, options=render)
            model = {"params": gait.params.to_dict()}
        with _bar("rendering") as bar:
            task = bar.add_task("frames", total=run.n_frames)
            write_video(run, out, progress=lambda d, n: bar.update(task, completed=d))
        truth = out.with_name(out.stem + ".truth.csv") if out.suffix else out / "truth.csv"
        write_table(run.truth, truth)
        write_json(truth.with_suffix(".json"), {
            **model, "fps": fps, "px_per_m": cam.px_per_m,
            "ground_y_px": cam.ground_px, "belt_speed_m_s": run.belt_speed,
            "stance_time": run.stance_time, "flight_time": run.flight_time,
            "geometry": {"r": run.geometry.r, "a": run.geometry.a, "b": run.geometry.b,
                         "marker_radius": run.geometry.marker_radius,
                         "foot_radius": run.geometry.foot_radius}})
        c = make_console()
        c.print(f"wrote {out} ({run.n_frames} frames, {width}x{height} px at {fps:g} Hz)")
        c.print(f"wrote {truth}")


def _track(video: Path, out: Path, fps: float | None, scale: float | None,
           ground: float | None, max_frames: int | None) -> Any:
    from ..experiment.video import (
        Calibration,
        TrackerOptions,
        measure_calibration,
        open_video,
        track_video,
    )

    if (scale is None) != (ground is None):
        raise ValueError("give both --scale and --ground, or neither (measured from the frame)")
    check_output(out, "--out", DATA_SUFFIXES)
    if fps is not None:
        check_number(fps, "--fps", unit="Hz", lower=0.0, upper=1e5, lower_open=True)
    if scale is not None:
        check_number(scale, "--scale", unit="px/m", lower=0.0, lower_open=True)
        check_number(ground, "--ground", unit="px", lower=0.0)
    if max_frames is not None:
        check_number(max_frames, "--max-frames", lower=1, integer=True)
    if scale is None or ground is None:  # both or neither (checked above)
        frames, _, _ = open_video(video)
        first = next(frames, None)
        if first is None:
            raise ValueError(f"no frames could be decoded from {str(video)!r} (frames 0-0)")
        cal = measure_calibration(first, _SPACING, marker_radius_m=_MARKER_R)
    else:
        cal = Calibration(px_per_m=scale, ground_y=ground, x0=0.0)
    opt = TrackerOptions.for_scale(cal.px_per_m, marker_radius=_MARKER_R,
                                   marker_spacing=_SPACING, foot_radius=_FOOT_R)
    with _bar("tracking") as bar:
        task = bar.add_task("frames", total=None)
        res = track_video(video, cal, opt, fps=fps, max_frames=max_frames,
                          progress=lambda d, n: bar.update(task, completed=d, total=n or None))
    write_table(res.tracks, out)
    write_json(out.with_suffix(".json"), {
        "video": str(video), "fps": res.fps, "px_per_m": cal.px_per_m, "ground_y_px":
        cal.ground_y, "x0_px": cal.x0, "problems": res.problems, "fatal": res.fatal,
        "body_detection_rate": res.body_detection_rate})
    c = make_console()
    c.print(f"tracked {len(res.tracks)} frames: body markers in "
            f"{100 * res.body_detection_rate:.1f} % (scale {cal.px_per_m:.1f} px/m, ground at "
            f"row {cal.ground_y:.1f})")
    for p in res.problems:
        typer.echo(f"warning: {p}", err=True)
    c.print(f"wrote {out}")
    if res.fatal:
        fail(res.problems[-1] if res.problems else "tracking failed", 1)
    return res


@commands.command("track")
def track_cmd(
    video: Annotated[Path, typer.Argument(help="Video (.mp4) or folder of frames.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="Tracks table (.csv/.parquet).")]
    = Path("tracks.csv"),
    fps: Annotated[float | None, typer.Option("--fps", help="Frame rate \\[Hz] (default: "
                                              "from the file).")] = None,
    scale: Annotated[float | None, typer.Option("--scale", help="Image scale \\[px/m] (default: "
                                                "measured from the disc spacing).")] = None,
    ground: Annotated[float | None, typer.Option("--ground", help="Ground row \\[px] (give "
                                                 "--scale with it).")] = None,
    max_frames: Annotated[int | None, typer.Option(
        "--max-frames", help="Track only the first N frames (default: all).")] = None,
) -> None:
    """Track body discs and feet in a video; write per-frame positions."""
    with errors():
        _track(video, out, fps, scale, ground, max_frames)


def _process(tracks_path: Path, out: Path) -> Any:
    import numpy as np

    from ..experiment.signals import process_tracks

    check_output(out, "--out", DATA_SUFFIXES)
    tracks = _read_table(tracks_path, _TRACK_COLUMNS, "tracks table")
    if len(tracks) < 2:
        raise ValueError(f"too few frames in {str(tracks_path)!r}: {len(tracks)}")
    dt = float(np.median(np.diff(tracks["t"].to_numpy(float))))
    if not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"tracks table {str(tracks_path)!r}: column 't' must increase "
                         "(frame times in s)")
    fps = 1.0 / dt
    data = process_tracks(tracks, fps)
    table = data.samples.merge(data.steps[["step", "stance_time", "flight_time"]], on="step")
    write_table(table, out)
    write_json(out.with_suffix(".json"), {"belt_speed_m_s": data.belt_speed,
                                           "problems": data.problems, **data.meta})
    write_table(data.frames, out.with_name(out.stem + ".frames" + out.suffix))
    c = make_console()
    st = data.steps
    c.print(f"{len(st)} near-foot steps: t_s = {st.stance_time.mean():.4f} +- "
            f"{st.stance_time.std(ddof=0):.4f}, t_f = {st.flight_time.mean():.4f} +- "
            f"{st.flight_time.std(ddof=0):.4f} [g^-1/2 L^1/2]; belt {data.belt_speed:.3f} m/s")
    for p in data.problems:
        typer.echo(f"warning: {p}", err=True)
    c.print(f"wrote {out}")
    return data


@commands.command("process")
def process_cmd(
    tracks: Annotated[Path, typer.Argument(help="Tracks table from `tslip track`.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="Steps table (.csv/.parquet).")]
    = Path("steps.csv"),
) -> None:
    """Filter tracks, compute states, split and resample the near-foot steps."""
    with errors():
        _process(tracks, out)


def _fit(steps_path: Path, out_dir: Path, frames: Any = None) -> Any:
    from ..experiment.fit import fit_model
    from ..experiment.signals import average_steps
    from ..plotting.experiment import plot_foot_trajectory, plot_step_average

    check_output(out_dir / "fit.json", "--out-dir")
    table = _read_table(steps_path, _STEP_COLUMNS, "steps table")
    steps = table.groupby("step")[["stance_time", "flight_time"]].first().reset_index()
    avg = average_steps(table, steps)
    if avg.n_steps < 2:
        raise ValueError(f"too few steps to fit in {str(steps_path)!r}: {avg.n_steps}")
    res = fit_model(avg)
    out_dir.mkdir(parents=True, exist_ok=True)
    write_table(res.times, out_dir / "table6_2.csv")
    write_table(res.scores, out_dir / "table6_3.csv")
    write_json(out_dir / "fit.json", {"values": res.values, "params": res.params.to_dict(),
                                       "stance_time": res.stance_time,
                                       "flight_time": res.flight_time, "converged":
                                       res.converged, "message": res.message,
                                       "n_steps": avg.n_steps, "n_evals": res.n_evals})
    save_figure(plot_step_average(avg, res), out_dir / "figure6_1.png", dpi=90)
    if frames is not None:
        save_figure(plot_foot_trajectory(frames), out_dir / "figureD_2.png", dpi=90)
    c = make_console()
    c.print(res.message)
    c.print("fitted: " + ", ".join(f"{k} = {v:.4f}" for k, v in res.values.items()))
    c.print(res.times.to_string(index=False, float_format=lambda x: f"{x:.4f}"))
    c.print(res.scores.to_string(index=False, float_format=lambda x: f"{x:.3f}"))
    c.print(f"wrote {out_dir}/table6_2.csv, table6_3.csv, fit.json, figure6_1.png")
    if not res.converged:
        fail(res.message, 1)
    return res


@commands.command("fit")
def fit_cmd(
    steps: Annotated[Path, typer.Argument(help="Steps table from `tslip process`.")],
    out_dir: Annotated[Path, typer.Option("--out-dir", "-o", help="Folder for tables, "
                                          "figure and fit.json.")] = Path("fit"),
) -> None:
    """Fit TSLIP (local velocity control + leg damping) to the step averages."""
    with errors():
        _fit(steps, out_dir)


@commands.command("experiment")
def experiment_cmd(
    video: Annotated[Path, typer.Argument(help="Video (.mp4) or folder of frames.")],
    out_dir: Annotated[Path, typer.Option(
        "--out-dir", "-o", help="Folder for tracks.csv, steps.csv and the fit's tables, "
        "figures and fit.json.")] = Path("experiment"),
    fps: Annotated[float | None, typer.Option("--fps", help="Frame rate \\[Hz] (default: "
                                              "from the file).")] = None,
    scale: Annotated[float | None, typer.Option("--scale", help="Image scale \\[px/m] (default: "
                                                "measured from the disc spacing; give "
                                                "--ground with it).")] = None,
    ground: Annotated[float | None, typer.Option("--ground", help="Ground row \\[px] (give "
                                                 "--scale with it).")] = None,
) -> None:
    """Run track -> process -> fit and write everything into one folder."""
    with errors():
        t0 = time.perf_counter()
        check_output(out_dir / "tracks.csv", "--out-dir")  # the files make the folder
        _track(video, out_dir / "tracks.csv", fps, scale, ground, None)
        data = _process(out_dir / "tracks.csv", out_dir / "steps.csv")
        _fit(out_dir / "steps.csv", out_dir, data)
        make_console().print(f"done in {time.perf_counter() - t0:.1f} s"
                         if math.isfinite(t0) else "done")
