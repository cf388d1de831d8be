"""Tracking speed at 1024 x 816 px on one core (target >= 150 frames/s).

Renders a synthetic Table 6.1 recording (1000 Hz), writes it as H.264 mp4,
then times (a) tracking frames already in memory, (b) decoding the mp4 alone
and (c) decoding + tracking from the mp4 file, as ``tslip track`` does. Each
timing is the best of ``--repeat`` runs (the machine may be shared).

    taskset -c 0 python benchmarks/bench_tracking.py [--frames 600] [--repeat 3]
"""

from __future__ import annotations

import argparse
import math
import os
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=600)
    ap.add_argument("--repeat", type=int, default=1, help="best of this many runs")
    args = ap.parse_args()
    import cv2

    cv2.setNumThreads(1)
    import tslip
    from tslip.experiment.render import camera_frames, write_video
    from tslip.experiment.synth import Camera, synthesize
    from tslip.experiment.video import Calibration, TrackerOptions, track_frames, track_video

    cam = Camera()
    g = tslip.find_gait(tslip.preset("table6.1"))
    run = synthesize(g.params, g.state, args.frames / cam.fps, camera=cam)
    cal = Calibration(cam.px_per_m, cam.ground_px, cam.hip_px)
    opt = TrackerOptions.for_scale(cam.px_per_m)
    t0 = time.perf_counter()
    frames = list(camera_frames(run))
    t_render = time.perf_counter() - t0
    t_mem = math.inf
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        res = track_frames(iter(frames), cal, opt, fps=cam.fps)
        t_mem = min(t_mem, time.perf_counter() - t0)
    n = len(frames)
    del frames
    t_dec = t_file = math.inf
    with tempfile.TemporaryDirectory() as d:
        path = write_video(run, Path(d) / "bench.mp4")
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            cap = cv2.VideoCapture(str(path))
            buf = None
            while True:
                ok, buf = cap.read(buf) if buf is not None else cap.read()
                if not ok:
                    break
            cap.release()
            t_dec = min(t_dec, time.perf_counter() - t0)
            t0 = time.perf_counter()
            res2 = track_video(path, cal, opt)
            t_file = min(t_file, time.perf_counter() - t0)
    print(f"{cam.width}x{cam.height} px, {n} frames, one core (cv2.setNumThreads(1)), "
          f"best of {args.repeat}")
    print(f"render (numpy):            {n / t_render:7.1f} frames/s")
    print(f"track, frames in memory:   {n / t_mem:7.1f} frames/s  "
          f"(body detected {100 * res.body_detection_rate:.1f} %)")
    print(f"decode mp4 only:           {n / t_dec:7.1f} frames/s")
    print(f"decode mp4 + track:        {n / t_file:7.1f} frames/s  "
          f"(body detected {100 * res2.body_detection_rate:.1f} %)  target >= 150")


if __name__ == "__main__":
    main()
