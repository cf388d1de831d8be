"""Ground height as a piecewise-constant function of x.

A touch-down happens when the foot comes down to the terrain height beneath
it. A foot that meets a higher segment below its top (a step riser) trips,
which counts as a fall.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["Terrain"]


@dataclass(frozen=True, slots=True)
class Terrain:
    """Heights ``heights[i]`` on ``[breakpoints[i-1], breakpoints[i])``.

    Parameters
    ----------
    breakpoints : tuple of float
        Strictly increasing x positions [L] where the height changes.
    heights : tuple of float
        ``len(breakpoints) + 1`` ground heights [L].

    Examples
    --------
    >>> t = Terrain.step(x=2.0, dh=-0.2)
    >>> t.height(1.0), t.height(3.0)
    (0.0, -0.2)
    """

    breakpoints: tuple[float, ...] = ()
    heights: tuple[float, ...] = (0.0,)

    def __post_init__(self) -> None:
        bp = tuple(float(x) for x in self.breakpoints)
        hs = tuple(float(h) for h in self.heights)
        object.__setattr__(self, "breakpoints", bp)
        object.__setattr__(self, "heights", hs)
        if len(hs) != len(bp) + 1:
            raise ValueError(
                f"Terrain.heights must have len(breakpoints) + 1 = {len(bp) + 1} entries, "
                f"got {len(hs)}"
            )
        if not all(math.isfinite(v) for v in bp + hs):
            raise ValueError("Terrain.breakpoints and Terrain.heights must be finite")
        if any(b >= a for a, b in zip(bp[1:], bp[:-1])):
            raise ValueError("Terrain.breakpoints must be strictly increasing")

    @classmethod
    def flat(cls, h: float = 0.0) -> Terrain:
        """Level ground at height ``h``."""
        return cls((), (h,))

    @classmethod
    def step(cls, x: float, dh: float, h0: float = 0.0) -> Terrain:
        """Ground ``h0`` before ``x`` and ``h0 + dh`` after (dh < 0: step down)."""
        return cls((x,), (h0, h0 + dh))

    @classmethod
    def sequence(cls, breakpoints: Sequence[float], heights: Sequence[float]) -> Terrain:
        """A staircase from explicit breakpoints and heights."""
        return cls(tuple(breakpoints), tuple(heights))

    def height(self, x: float) -> float:
        """Ground height at ``x``."""
        return self.heights[int(np.searchsorted(self.breakpoints, x, side="right"))]

    def shifted_after(self, x: float, dh: float) -> Terrain:
        """This terrain with every height beyond ``x`` raised by ``dh``."""
        bp = list(self.breakpoints)
        hs = list(self.heights)
        k = int(np.searchsorted(bp, x, side="right"))
        if not (k > 0 and bp[k - 1] == x):
            bp.insert(k, x)
            hs.insert(k, hs[k])  # split segment k at x
            k += 1
        for i in range(k, len(hs)):
            hs[i] += dh
        return Terrain(tuple(bp), tuple(hs))

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """``(breakpoints, heights)`` as float64 arrays for the kernels."""
        return np.asarray(self.breakpoints, dtype=float), np.asarray(self.heights, dtype=float)
