"""Correlation/VAF (eqs 5.1-5.2) hand cases; contact detection; too few steps."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from tslip.experiment.signals import contact_events, correlation, process_tracks, vaf


def test_perfect_fit_gives_one_and_hundred_percent() -> None:
    y = np.sin(np.linspace(0, 3, 50))
    assert correlation(y, y) == pytest.approx(1.0, abs=1e-12)
    assert vaf(y, y) == pytest.approx(100.0, abs=1e-9)


def test_constant_offset_keeps_correlation_lowers_vaf() -> None:
    y = np.array([1.0, 2.0, 3.0, 4.0])
    # var(y) = 1.25; y - (y + 1) = -1 has zero variance -> VAF stays 100 (eq. 5.2 uses var);
    # the uncentred form that an offset lowers is tested below
    assert correlation(y, y + 1.0) == pytest.approx(1.0, abs=1e-12)
    assert vaf(y, y + 1.0) == pytest.approx(100.0, abs=1e-9)  # eq. 5.2 as printed
    # a scaled copy: corr 1, VAF = (1 - var(-0.5 y) / var(y)) * 100 = 75 %
    assert correlation(y, 1.5 * y + 2.0) == pytest.approx(1.0, abs=1e-12)
    assert vaf(y, 1.5 * y) == pytest.approx(75.0, abs=1e-9)
    # offset plus noise-free ramp error: yhat = y + (0, 0, 0, 1)
    yh = y + np.array([0.0, 0.0, 0.0, 1.0])
    assert vaf(y, yh) == pytest.approx((1 - np.var([0, 0, 0, 1.0]) / 1.25) * 100, abs=1e-9)
    assert vaf(y, yh) < 100.0


def test_uncentred_vaf_lowers_for_constant_offset() -> None:
    y = np.array([1.0, 2.0, 3.0, 4.0])   # mean 2.5, var(y) = 5 / 4 = 1.25
    # perfect fit: 100 % in both forms
    assert vaf(y, y, centred=False) == pytest.approx(100.0, abs=1e-12)
    # offset +1: mean((-1)^2) = 1 -> (1 - 1 / 1.25) * 100 = 20 %; eq. 5.2 gives 100 %
    assert vaf(y, y + 1.0, centred=False) == pytest.approx(20.0, abs=1e-9)
    assert vaf(y, y + 1.0, centred=True) == pytest.approx(100.0, abs=1e-9)
    assert correlation(y, y + 1.0) == pytest.approx(1.0, abs=1e-12)
    # offset 0.5: (1 - 0.25 / 1.25) * 100 = 80 %
    assert vaf(y, y - 0.5, centred=False) == pytest.approx(80.0, abs=1e-9)
    # scaled copy 1.5 y: residual -0.5 y = (-0.5, -1, -1.5, -2), mean square 7.5 / 4 = 1.875
    # -> (1 - 1.875 / 1.25) * 100 = -50 %; the centred form gives 75 %
    assert vaf(y, 1.5 * y, centred=False) == pytest.approx(-50.0, abs=1e-9)
    assert vaf(y, 1.5 * y, centred=True) == pytest.approx(75.0, abs=1e-9)
    # zero-mean residual (0, 1, -1, 0): both forms (1 - 0.5 / 1.25) * 100 = 60 %
    yh = y + np.array([0.0, 1.0, -1.0, 0.0])
    assert vaf(y, yh, centred=False) == pytest.approx(60.0, abs=1e-9)
    assert vaf(y, yh, centred=True) == pytest.approx(60.0, abs=1e-9)
    # anti-correlated, y = (1, 2, 3): residual 2 y, mean square 56 / 3, var(y) = 2 / 3
    y3 = np.array([1.0, 2.0, 3.0])
    assert vaf(y3, -y3, centred=False) == pytest.approx((1 - 28.0) * 100, abs=1e-9)
    # constant measurement: undefined
    assert np.isnan(vaf(np.ones(3), np.zeros(3), centred=False))


def test_anticorrelated_gives_minus_one() -> None:
    y = np.array([1.0, 2.0, 3.0])
    assert correlation(y, -y) == pytest.approx(-1.0, abs=1e-12)
    assert vaf(y, -y) == pytest.approx(-300.0, abs=1e-9)  # var(2y)/var(y) = 4


def test_contact_events_subframe_touchdown() -> None:
    fs = 500.0
    t = np.arange(200) / fs
    # foot falls at 2 m/s, lands at t = 0.1013 s, lifts at 0.2507 s
    h = np.maximum(np.maximum(2.0 * (0.1013 - t), 0.0), 2.0 * (t - 0.2507))
    ev = contact_events(h, t, 0.0, 0.003)
    assert len(ev) == 1
    assert abs(ev[0][0] - 0.1013) < 1e-4   # 0.05 frame
    assert abs(ev[0][1] - 0.2507) < 1e-4


def test_too_few_steps_names_frames() -> None:
    n = 100
    tracks = pd.DataFrame({"frame": np.arange(n), "t": np.arange(n) / 500.0, "body_q": 1,
                           "foot1_q": 1, "foot2_q": 1})
    for m in ("front", "rear", "foot1", "foot2"):
        tracks[f"{m}_x_m"] = 0.1 if m == "front" else -0.1
        tracks[f"{m}_y_m"] = 0.3 if m in ("front", "rear") else 0.05
    with pytest.raises(ValueError, match=r"too few steps to average.*frames 0-99"):
        process_tracks(tracks, 500.0)


def test_contact_events_on_a_sinking_stance() -> None:
    """A compliant ground: the foot sinks 7 mm during the stance, below the
    threshold above the lowest level; touch-down and lift-off are still found
    at the corners, to 0.2 frame with 0.2 mm of noise."""
    fs = 500.0
    t = np.arange(300) / fs
    td, lo = 0.1013, 0.2507
    h = np.where(t < td, 1.5 * (td - t), 2.0 * (t - lo) + 40.0 * (t - lo) ** 2)
    m = (t >= td) & (t <= lo)
    h[m] = -0.007 * np.sin(np.pi * (t[m] - td) / (lo - td))
    h += np.random.default_rng(1).normal(0.0, 2e-4, t.size)
    ev = contact_events(h, t, float(np.percentile(h, 5)), 0.003)
    assert len(ev) == 1
    assert abs(ev[0][0] - td) < 0.2 / fs and abs(ev[0][1] - lo) < 0.2 / fs
    assert ev[0][2] == 51 and ev[0][3] == 125  # the frames between the two instants


def test_vaf_is_measured_against_the_measurement_not_the_model() -> None:
    """Eq. 5.2 normalises by var(y), the measurement: a model at half the
    measured amplitude leaves 1 - var(0.5 y) / var(y) = 75 %; one at twice
    the amplitude leaves 1 - var(-y) / var(y) = 0 %. Swapping y and yhat
    would give 0 % and 75 %."""
    y = np.sin(np.linspace(0.0, 5.0, 80)) + 0.3
    assert vaf(y, 0.5 * y) == pytest.approx(75.0, abs=1e-9)
    assert vaf(y, 2.0 * y) == pytest.approx(0.0, abs=1e-9)
    assert vaf(y, 2.0 * y, centred=False) == pytest.approx(
        (1 - np.mean(y ** 2) / np.var(y)) * 100, abs=1e-9)
    # and a model with no variance (a constant) explains nothing: 0 %
    assert vaf(y, np.full_like(y, 7.0)) == pytest.approx(0.0, abs=1e-9)
