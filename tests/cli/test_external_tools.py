"""ffmpeg's failures are errors, and run.json records what ran (issue 11, items 4-5)."""

from __future__ import annotations

import json

import imageio_ffmpeg
import numpy as np
import pytest
from typer.testing import CliRunner

import tslip
from tslip._io import atomic_write, write_mp4
from tslip.cli.main import app

runner = CliRunner()


def _frames(n, h, w):
    rng = np.random.default_rng(0)
    return [rng.integers(0, 255, size=(h, w, 3), dtype=np.uint8) for _ in range(n)]


def test_write_mp4_writes_every_frame_at_its_size(tmp_path):
    import cv2

    out = write_mp4(tmp_path / "v.mp4", _frames(7, 48, 64), 25.0)
    cap = cv2.VideoCapture(str(out))
    shapes = []
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        shapes.append(frame.shape)
    cap.release()
    assert shapes == [(48, 64, 3)] * 7
    assert [p.name for p in tmp_path.iterdir()] == ["v.mp4"]


def test_write_mp4_refuses_odd_sizes_before_ffmpeg(tmp_path, monkeypatch):
    monkeypatch.setattr(imageio_ffmpeg, "get_ffmpeg_exe", lambda: pytest.fail("ffmpeg ran"))
    with pytest.raises(ValueError, match="even frame width and height, got 101 x 77 px"):
        write_mp4(tmp_path / "v.mp4", _frames(2, 77, 101), 25.0)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("exe", ["/bin/false", "/bin/true"])  # exit 1; exit 0 writing nothing
def test_failed_or_empty_encode_is_an_error_and_leaves_no_file(tmp_path, monkeypatch, exe):
    monkeypatch.setattr(imageio_ffmpeg, "get_ffmpeg_exe", lambda: exe)
    with pytest.raises(OSError, match="ffmpeg could not encode") as info:
        write_mp4(tmp_path / "v.mp4", _frames(3, 64, 64), 25.0)
    assert str(tmp_path / "v.mp4") in str(info.value)
    assert list(tmp_path.iterdir()) == []


def test_synth_video_reports_a_failed_encode(tmp_path, monkeypatch):
    monkeypatch.setattr(imageio_ffmpeg, "get_ffmpeg_exe", lambda: "/bin/false")
    out = tmp_path / "v.mp4"
    res = runner.invoke(app, ["synth-video", "--duration", "0.01", "--fps", "200", "--width",
                              "128", "--height", "96", "--out", str(out)])
    assert res.exit_code == 1, res.output
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ffmpeg could not encode")
    assert str(out) in lines[0] and "Traceback" not in res.output
    assert list(tmp_path.iterdir()) == []


def test_animate_reports_a_failed_encode(tmp_path, monkeypatch):
    from tslip.plotting.animation import animate

    traj = tslip.simulate(tslip.preset("table2.1"),
                          tslip.TouchdownState(1.05, 0.0, 5.0, -0.3, 0.0), 1)
    monkeypatch.setattr(imageio_ffmpeg, "get_ffmpeg_exe", lambda: "/bin/true")
    with pytest.raises(OSError, match="ffmpeg could not encode"):
        animate(traj, tmp_path / "a.mp4", fps=10, size=(160, 96))
    assert list(tmp_path.iterdir()) == []


def test_temp_file_errors_name_the_users_file(tmp_path):
    def fail(tmp):
        raise PermissionError(13, "Permission denied", tmp)

    with pytest.raises(PermissionError) as info:
        atomic_write(tmp_path / "x.csv", fail)
    assert info.value.filename == str(tmp_path / "x.csv")
    assert list(tmp_path.iterdir()) == []


def test_run_json_records_the_preset_and_values_that_ran(tmp_path):
    toml = tmp_path / "p.toml"
    toml.write_text('preset = "table6.1"\n[params]\nk = 9\n')
    out = tmp_path / "run.csv"
    res = runner.invoke(app, ["simulate", "--steps", "2", "--params", str(toml), "--out",
                              str(out)])
    assert res.exit_code == 0, res.output
    meta = json.loads(out.with_suffix(".json").read_text())
    assert meta["preset"] == "table6.1"
    assert meta["params"]["k"] == 9.0
    assert meta["params"]["v0"] == tslip.preset("table6.1").v0
    assert meta["params"]["controller"]["type"] == "local_velocity"


@pytest.fixture(scope="module")
def biped_run():
    from tslip.biped import BipedParams, BipedState, simulate

    return simulate(BipedParams(), BipedState.thesis(), n_steps=1)


@pytest.mark.parametrize("suffix", [".mp4", ".gif"])
def test_biped_animation_has_one_frame_per_time_step(tmp_path, biped_run, suffix):
    import cv2
    from PIL import Image, ImageSequence

    from tslip.plotting.biped import animate_biped

    out = animate_biped(biped_run, tmp_path / f"b{suffix}", fps=20, speed=1.0)
    if suffix == ".gif":
        with Image.open(out) as im:
            shapes = [(f.height, f.width) for f in ImageSequence.Iterator(im)]
    else:  # read back with OpenCV: imageio's ffmpeg reader leaks its pipes
        cap, shapes = cv2.VideoCapture(str(out)), []
        while (frame := cap.read())[0]:
            shapes.append(frame[1].shape[:2])
        cap.release()
    duration = biped_run.time[-1] - biped_run.time[0]
    assert len(shapes) == len(np.arange(biped_run.time[0], biped_run.time[-1], 1.0 / 20))
    assert len(shapes) == pytest.approx(duration * 20, abs=1)
    assert set(shapes) == {(240, 480)}  # 6 x 3 in at 80 dpi
    assert [p.name for p in tmp_path.iterdir()] == [out.name]


def test_biped_animation_reports_a_failed_encode(tmp_path, monkeypatch, biped_run):
    from tslip.plotting.biped import animate_biped

    monkeypatch.setattr(imageio_ffmpeg, "get_ffmpeg_exe", lambda: "/bin/false")
    with pytest.raises(OSError, match="ffmpeg could not encode"):
        animate_biped(biped_run, tmp_path / "b.mp4", fps=20, speed=1.0)
    assert list(tmp_path.iterdir()) == []
