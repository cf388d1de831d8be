"""
The video pipeline on a synthetic recording
===========================================

Thesis Chapters 5-6 film a robot at high speed, track its markers, average its steps
and fit the model. Here the recording is synthetic (rendered from a simulated Table 6.1
gait, so the truth is known): track the markers with OpenCV, process the tracks into the
model's signals, average the steps, and fit the model, scored by correlation and VAF
(Table 6.3).
"""

# %%

import tslip
from tslip.experiment import average_steps, fit_model, process_tracks
from tslip.experiment.render import camera_frames
from tslip.experiment.synth import Camera, synthesize
from tslip.experiment.video import TrackerOptions, measure_calibration, track_frames
from tslip.plotting.experiment import plot_step_average

gait = tslip.find_gait(tslip.preset("table6.1"))
camera = Camera(width=512, height=408, fps=500.0)
run = synthesize(gait.params, gait.state, 1.6, camera=camera)   # 1.6 s of video

first = next(camera_frames(run, stop=1))
cal = measure_calibration(first, 0.18)       # scale from the two body discs, 0.18 m apart
tracks = track_frames(camera_frames(run), cal, TrackerOptions.for_scale(cal.px_per_m),
                      fps=camera.fps)
print(f"tracked {len(tracks.tracks)} frames at {cal.px_per_m:.1f} px/m")

data = process_tracks(tracks.tracks, camera.fps)
avg = average_steps(data.samples.merge(data.steps[["step", "stance_time", "flight_time"]],
                                       on="step"), data.steps)
fit = fit_model(avg)
print({k: round(v, 3) for k, v in fit.values.items()}, "(truth: k 8, beta0 0.93, c_l 0.32)")
print(fit.scores.to_string(index=False, float_format=lambda x: f"{x:.3f}"))
fig = plot_step_average(avg, fit)   # thesis Figure 6.1; fig.savefig("fit.png") writes it
