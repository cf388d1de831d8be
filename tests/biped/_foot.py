"""The foot's height and vertical speed from the state (eq. E.8), written out for tests."""

from __future__ import annotations

import numpy as np


def foot(p, y, leg):
    """Height and vertical speed of foot ``leg`` (0 right, 1 left) of state ``y``."""
    gam = y[2] + y[5 + 3 * leg]
    s = y[3 + 3 * leg] + y[4 + 3 * leg]
    sd = y[12 + 3 * leg] + y[13 + 3 * leg]
    z = y[1] + p.r_1 * np.cos(y[2]) - s * np.cos(gam)
    zd = (y[10] - p.r_1 * np.sin(y[2]) * y[11] - sd * np.cos(gam)
          + s * np.sin(gam) * (y[11] + y[14 + 3 * leg]))
    return z, zd
