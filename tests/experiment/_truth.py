"""Marker tracks (metres) taken from a synthetic run's ground truth, as a tracker would give.

The run's front/rear trunk markers and its near/hind feet become the
``front``, ``rear``, ``foot1`` and ``foot2`` tracks, every point of full quality.
"""

from __future__ import annotations

import pandas as pd


def truth_tracks(run) -> pd.DataFrame:  # noqa: ANN001 - a tslip.experiment.synth.SyntheticRun
    tru = run.truth
    tracks = pd.DataFrame({"frame": tru["frame"], "t": tru["t"], "body_q": 1, "foot1_q": 1,
                           "foot2_q": 1})
    for m, src in (("front", "front"), ("rear", "rear"), ("foot1", "near"), ("foot2", "hind")):
        tracks[f"{m}_x_m"] = tru[f"{src}_x_m"]
        tracks[f"{m}_y_m"] = tru[f"{src}_y_m"]
    return tracks
