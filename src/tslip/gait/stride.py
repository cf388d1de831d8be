"""Stride timing of a gait and the no-slip check of its stance.

Stance and flight durations, duty factor and step frequency (thesis Table
6.2), with the closed-form predictions of Section 3.4.3 and Appendix D.1:
the spring-mass bounce time (eq. 3.9), the geometric stance time (eq.
3.10), the ballistic flight time (eq. 3.11) and the fast-running index (eq.
3.12). :func:`friction_ratio` checks the no-slip assumption of Appendix C.

All quantities are in the dimensionless units of thesis Table 3.1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._results import Result, frame
from ..model._pack import packed_params
from ..model.parameters import Params
from ..model.state import TouchdownState
from ..model.units import COLUMN_UNITS, UNIT
from ..simulation._kernels import stance_initial
from ..simulation.options import IntegratorOptions
from .fixed_point import Gait
from .impulse import _impulse_from_run, _stance_run

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "StrideProperties",
    "stride_properties",
    "bounce_time",
    "predicted_stance_time",
    "predicted_flight_time",
    "fast_running_index",
    "FrictionCheck",
    "friction_ratio",
]


def bounce_time(params: Params, leg_speed: float | None = None) -> float:
    """Half period of the spring-mass bounce, ``pi sqrt(m/k)`` (eq. 3.9).

    For a power-law leg (``leg_exponent = n != 1``, docs/model.md) the period
    depends on the amplitude: the bounce ``m l'' = F_s(l)`` from ``l = l0`` at
    the leg speed ``|ldot| = leg_speed`` compresses to ``x_max = ((n+1) m ldot^2 /
    (2 k l0^2))^(1/(n+1))`` (``V(x_max)`` equal to the kinetic energy) and lasts
    ``t_b = 2 sqrt((n+1) m / (2 k)) x_max^((1-n)/2) I_n``, ``I_n = int_0^1 (1 -
    u^(n+1))^(-1/2) du = sqrt(pi) G(1/(n+1)) / ((n+1) G(1/(n+1) + 1/2))``
    (``G`` the gamma function); ``n = 1`` gives eq. 3.9 for any amplitude.

    Parameters
    ----------
    params : Params
    leg_speed : float, optional
        ``|ldot|`` at touch-down [g^1/2 L^1/2]; required when ``n != 1``.

    Returns
    -------
    float
        ``t_b`` [g^-1/2 L^1/2].

    Examples
    --------
    >>> import tslip
    >>> round(bounce_time(tslip.preset("table2.1")), 4)
    0.6283
    """
    n = params.leg_exponent
    if n == 1.0:
        return math.pi * math.sqrt(params.m / params.k)
    if leg_speed is None or not (math.isfinite(leg_speed) and leg_speed > 0):
        raise ValueError(f"leg_speed must be in (0, inf) for leg_exponent {n:g} != 1 (the "
                         f"bounce time of a non-linear spring depends on its amplitude), "
                         f"got {leg_speed!r}")
    p = params
    x_max = ((n + 1) * p.m * leg_speed**2 / (2 * p.k * p.l0**2)) ** (1 / (n + 1))
    a = 1 / (n + 1)
    integral = math.sqrt(math.pi) * math.gamma(a) / ((n + 1) * math.gamma(a + 0.5))
    return 2 * math.sqrt((n + 1) * p.m / (2 * p.k)) * x_max ** ((1 - n) / 2) * integral


def predicted_stance_time(params: Params, v0: float | None = None) -> float:
    """Stance time of fast running, ``2 l0 (pi/2 - beta0) / v0`` (eq. 3.10).

    Parameters
    ----------
    params : Params
    v0 : float, optional
        Touch-down speed [g^1/2 L^1/2]; default ``params.v0``.

    Returns
    -------
    float
        ``t_s`` [g^-1/2 L^1/2]: the time to sweep the leg symmetrically
        from ``beta0`` to ``pi - beta0`` at the speed ``v0`` (small-angle
        approximation of the chord, Appendix D.1).
    """
    v0 = params.v0 if v0 is None else v0
    return 2.0 * params.l0 * (math.pi / 2.0 - params.beta0) / v0


def predicted_flight_time(
    yd: float, g: float = 1.0, *, v0: float | None = None, delta: float | None = None
) -> tuple[float, float]:
    """Ballistic flight time (eq. 3.11): exact and small-angle forms.

    Parameters
    ----------
    yd : float
        Vertical CoM velocity at touch-down [g^1/2 L^1/2]; its magnitude is
        used (a symmetric flight leaves with ``-yd``).
    g : float
        Gravity [g].
    v0, delta : float, optional
        Touch-down speed [g^1/2 L^1/2] and velocity angle [rad] for the
        approximation ``2 v0 |delta| / g``; NaN if not given.

    Returns
    -------
    (float, float)
        ``2 |yd| / g`` and ``2 v0 |delta| / g`` [g^-1/2 L^1/2].
    """
    approx = math.nan if v0 is None or delta is None else 2.0 * v0 * abs(delta) / g
    return 2.0 * abs(yd) / g, approx


def fast_running_index(params: Params, v0: float | None = None,
                       leg_speed: float | None = None) -> float:
    """Fast-running index ``I_fr = pi v0 sqrt(m/k) / (l0 (pi - 2 beta0))`` (eq. 3.12).

    The ratio of the bounce time (eq. 3.9) to the geometric stance time
    (eq. 3.10); the thesis calls ``I_fr > 2`` (about) fast running.

    Parameters
    ----------
    params : Params
    v0 : float, optional
        Speed [g^1/2 L^1/2]; default ``params.v0``.
    leg_speed : float, optional
        Touch-down ``|ldot|`` for a power-law leg (:func:`bounce_time`).

    Returns
    -------
    float
        ``I_fr`` [-].

    Examples
    --------
    The Planar Elliptical Runner at 4.4 m/s with l0 = 0.5 m (Section 5.2):

    >>> import math, tslip
    >>> round(fast_running_index(tslip.preset("table6.1"), v0=4.4 / math.sqrt(9.81 * 0.5)), 2)
    1.72
    """
    return bounce_time(params, leg_speed) / predicted_stance_time(params, v0)


_STRIDE_UNITS = {**COLUMN_UNITS, **dict.fromkeys(
    ("bounce_time", "stance_time_predicted", "flight_time_predicted",
     "flight_time_small_angle"), UNIT["time"]), "step_frequency": UNIT["frequency"],
    "duty_factor": "-", "fast_running_index": "-", "mu": "-", "ratio": "-"}


@dataclass(frozen=True, slots=True, repr=False)
class StrideProperties(Result):
    """Stride timing of a periodic gait with its closed-form predictions.

    Times in [g^-1/2 L^1/2], frequency in [g^1/2 L^-1/2].

    Attributes
    ----------
    stance_time, flight_time : float
        Measured ``t_s`` and ``t_f``.
    duty_factor : float
        ``t_s / (t_s + t_f)`` [-] (Table 6.2).
    step_frequency : float
        ``1 / (t_s + t_f)`` (Table 6.2).
    bounce_time : float
        ``t_b = pi sqrt(m/k)`` (eq. 3.9); for a power-law leg at the touch-down
        leg speed (:func:`bounce_time`).
    stance_time_predicted : float
        ``2 l0 (pi/2 - beta0) / v0`` (eq. 3.10).
    flight_time_predicted : float
        ``2 |ydot_TD| / g`` (eq. 3.11, exact for a symmetric flight).
    flight_time_small_angle : float
        ``2 v0 |delta| / g`` (eq. 3.11, approximation).
    fast_running_index : float
        ``t_b / t_s`` with eq. 3.10 for ``t_s`` (eq. 3.12) [-].
    params : Params
    state : TouchdownState
    """

    stance_time: float
    flight_time: float
    duty_factor: float
    step_frequency: float
    bounce_time: float
    stance_time_predicted: float
    flight_time_predicted: float
    flight_time_small_angle: float
    fast_running_index: float
    params: Params
    state: TouchdownState

    @property
    def stride_time(self) -> float:
        """``t_s + t_f`` [g^-1/2 L^1/2]."""
        return self.stance_time + self.flight_time

    def _repr_fields(self) -> dict[str, Any]:
        return {k: getattr(self, k) for k in ("stance_time", "flight_time", "duty_factor",
                                              "step_frequency", "fast_running_index")}

    def to_dataframe(self) -> pd.DataFrame:
        """One row: the measured times and their closed-form predictions."""
        return frame([{k: getattr(self, k) for k in (
            "stance_time", "flight_time", "stride_time", "duty_factor", "step_frequency",
            "bounce_time", "stance_time_predicted", "flight_time_predicted",
            "flight_time_small_angle", "fast_running_index")}], _STRIDE_UNITS)


def stride_properties(gait: Gait) -> StrideProperties:
    """Stride timing of a gait (Section 3.4.3, Table 6.2, Figure 4.11).

    Parameters
    ----------
    gait : Gait
        The stance and flight times are the gait's own (from
        :func:`tslip.find_gait`), the predictions use ``gait.params`` and the
        touch-down state.

    Returns
    -------
    StrideProperties

    Examples
    --------
    >>> import tslip
    >>> s = stride_properties(tslip.find_gait(tslip.preset("table6.1")))
    >>> round(s.duty_factor, 2), round(s.step_frequency, 2)
    (0.83, 1.41)
    """
    p, s = gait.params, gait.state
    ts, tf = float(gait.stance_time), float(gait.flight_time)
    y0 = np.empty(6)
    stance_initial(packed_params(p), s.as_array(), y0)  # eq. A.5 inverted
    ld = abs(float(y0[3]))
    tf_exact, tf_approx = predicted_flight_time(s.yd, p.g, v0=s.v, delta=s.delta)
    return StrideProperties(
        stance_time=ts,
        flight_time=tf,
        duty_factor=ts / (ts + tf),
        step_frequency=1.0 / (ts + tf),
        bounce_time=bounce_time(p, ld),
        stance_time_predicted=predicted_stance_time(p, s.v),
        flight_time_predicted=tf_exact,
        flight_time_small_angle=tf_approx,
        fast_running_index=fast_running_index(p, s.v, ld),
        params=p,
        state=s,
    )


@dataclass(frozen=True, slots=True, eq=False, repr=False)
class FrictionCheck(Result):
    """Horizontal ground force against static friction over a stance (App. C).

    Attributes
    ----------
    mu : float
        Static friction coefficient [-] (``F_f = mu F_y``, eq. C.1).
    time : ndarray, shape (n,)
        Time since touch-down [g^-1/2 L^1/2].
    F_x, F_y : ndarray, shape (n,)
        Ground reaction force [Mg].
    ratio : ndarray, shape (n,)
        ``|F_x| / F_y`` [-]; ``inf`` where ``F_y <= 0`` and ``F_x != 0``,
        NaN where both vanish.
    slip_fraction : float
        Fraction of the stance time in which ``|F_x| > mu F_y`` [-], from
        the zero crossings of ``|F_x| - mu F_y`` interpolated linearly
        between samples (error about ``dt^2``).
    first_slip : float
        Normalised stance time ``t / t_s`` [-] of the first sample where
        friction is exceeded, NaN if never.
    max_ratio : float
        Largest ``|F_x| / F_y`` [-] over the samples with ``F_y`` above 1e-3
        of its peak. (With a hip torque the ratio diverges at lift-off, where
        ``F_y -> 0`` while ``F_x -> tau sin(beta) / l`` does not.)
    stance_time : float
        [g^-1/2 L^1/2].
    """

    mu: float
    time: np.ndarray
    F_x: np.ndarray
    F_y: np.ndarray
    ratio: np.ndarray
    slip_fraction: float
    first_slip: float
    max_ratio: float
    stance_time: float

    @property
    def slips(self) -> bool:
        """True if friction is exceeded anywhere in the stance."""
        return self.slip_fraction > 0.0

    def to_dataframe(self) -> pd.DataFrame:
        """The stance samples: time, GRF and ``|F_x| / F_y``."""
        return frame({"t": self.time, "F_x": self.F_x, "F_y": self.F_y, "ratio": self.ratio},
                     _STRIDE_UNITS)

    def plot(self, ax: Axes | None = None) -> Figure:
        """``|F_x|`` against ``mu F_y`` over the stance (thesis Figure C.1)."""
        from ..plotting.gait import plot_friction

        return plot_friction(self, ax)


def _positive_measure(t: np.ndarray, g: np.ndarray) -> float:
    """Length of ``{t : g(t) > 0}`` for piecewise-linear ``g`` on samples ``t``."""
    total = 0.0
    for i in range(len(t) - 1):
        a, b, h = g[i], g[i + 1], t[i + 1] - t[i]
        if a > 0.0 and b > 0.0:
            total += h
        elif a > 0.0 or b > 0.0:  # one sign change in the interval
            total += h * max(a, b) / (abs(a) + abs(b))
    return total


def friction_ratio(
    params: Params,
    state: TouchdownState,
    mu: float = 1.0,
    *,
    dt: float = 1e-3,
    options: IntegratorOptions | None = None,
) -> FrictionCheck:
    """Check the no-slip assumption over one stance (Appendix C, Figure C.1).

    Parameters
    ----------
    params : Params
    state : TouchdownState
        State just after touch-down.
    mu : float
        Static friction coefficient [-]; the thesis uses 1.0 (dry rubber on
        concrete).
    dt : float
        Sample spacing [g^-1/2 L^1/2].
    options : IntegratorOptions, optional

    Returns
    -------
    FrictionCheck

    References
    ----------
    Thesis Appendix C, eq. C.1.

    Examples
    --------
    >>> import tslip
    >>> g = tslip.find_gait(tslip.preset("table2.1"))
    >>> friction_ratio(g.params, g.state).slips
    False
    """
    if not (math.isfinite(mu) and mu >= 0):
        raise ValueError(f"mu [-] must be finite and >= 0, got {mu!r}")
    imp = _impulse_from_run(_stance_run(params, state, dt, options), dt)
    t, fx, fy = imp.time, imp.F_x, imp.F_y
    ax = np.abs(fx)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(fy > 0.0, ax / np.where(fy > 0.0, fy, 1.0),
                         np.where(ax > 0.0, np.inf, np.nan))
    excess = ax - mu * fy
    slip = _positive_measure(t, excess) / imp.stance_time
    over = np.flatnonzero(excess > 0.0)
    first = float(t[over[0]] / imp.stance_time) if over.size else math.nan
    pos = fy > 1e-3 * np.max(fy)
    return FrictionCheck(
        mu=float(mu), time=t, F_x=fx, F_y=fy, ratio=ratio, slip_fraction=float(slip),
        first_slip=first, max_ratio=float(np.max(ratio[pos])) if pos.any() else math.nan,
        stance_time=imp.stance_time,
    )
