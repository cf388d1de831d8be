"""Integrator options: tolerances and limits, never hard-coded in kernels."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._checks import check_fields
from ..model._pack import (
    METHODS,
    NO,
    O_ATOL,
    O_H0,
    O_HMIN,
    O_MAXSTEPS,
    O_METHOD,
    O_RTOL,
    O_TMAX_FLIGHT,
    O_TMAX_STANCE,
)

__all__ = ["IntegratorOptions"]


def _m(description: str, lower: float, lower_open: bool = True) -> dict:
    return {"description": description, "lower": lower, "lower_open": lower_open,
            "upper_open": True}


@dataclass(frozen=True, slots=True, kw_only=True)
class IntegratorOptions:
    """Runge-Kutta settings for the stance phase.

    The thesis used Dormand-Prince 5(4) with ``rtol = atol = 1e-8``
    (Section 2.7); those are the defaults. ``method="dop853"`` selects the
    8th-order pair of :mod:`tslip.simulation._rk`, which needs far fewer
    right-hand sides at tight tolerances.
    """

    rtol: float = field(default=1e-8, metadata=_m("relative tolerance", 0.0))
    atol: float = field(default=1e-8, metadata=_m("absolute tolerance", 0.0))
    h0: float = field(default=0.0, metadata=_m("first step size (0: automatic)", 0.0, False))
    max_steps: int = field(default=100_000, metadata=_m("max steps in one stance", 0.0))
    t_max_stance: float = field(default=50.0, metadata=_m("max stance duration", 0.0))
    t_max_flight: float = field(default=1000.0, metadata=_m("max flight duration", 0.0))
    h_min: float = field(default=1e-13, metadata=_m("smallest step before giving up", 0.0))
    method: str = field(default="dopri5", metadata={"description": "Runge-Kutta pair",
                                                     "choices": METHODS})

    def __post_init__(self) -> None:
        check_fields(self, prefix="IntegratorOptions.")
        if self.method not in METHODS:
            raise ValueError(f"IntegratorOptions.method must be one of {', '.join(METHODS)}, "
                             f"got {self.method!r}")

    def packed(self) -> np.ndarray:
        """The O vector for the kernels."""
        o = np.zeros(NO)
        o[O_RTOL], o[O_ATOL], o[O_H0] = self.rtol, self.atol, self.h0
        o[O_MAXSTEPS], o[O_TMAX_STANCE] = self.max_steps, self.t_max_stance
        o[O_TMAX_FLIGHT], o[O_HMIN] = self.t_max_flight, self.h_min
        o[O_METHOD] = METHODS.index(self.method)
        return o

    @classmethod
    def tight(cls, method: str = "dopri5") -> IntegratorOptions:
        """Tolerance 1e-12: gait search, continuation, Floquet and reference comparisons.

        At this tolerance ``method="dop853"`` needs about 257 right-hand sides
        for a Table 6.1 stride against 848 for dopri5: strides 3 to 5 times and
        exact Jacobians 2.5 times faster (``benchmarks/bench_rk.py``).
        """
        return cls(rtol=1e-12, atol=1e-12, method=method)
