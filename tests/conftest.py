"""Shared test fixtures: a seeded random generator and a headless matplotlib."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")  # headless: never open a window in tests

import numpy as np  # noqa: E402
import pytest  # noqa: E402

SEED = 20190704


@pytest.fixture
def rng() -> np.random.Generator:
    """A freshly seeded generator, so every test draws reproducible numbers."""
    return np.random.default_rng(SEED)
