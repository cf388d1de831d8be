"""Height and velocity after a change in ground height (Sections 3.3, 4.2).

The passive TSLIP model is conservative: after a step in the ground of
``dh`` the potential energy ``m g dh`` it loses (``dh < 0``: a step down)
reappears as kinetic energy, so the touch-down speed settles at
``v_inf = sqrt(v0^2 - 2 g dh)`` (eqs 3.6-3.8). It gets there through a
multi-stride oscillation in which CoM height and forward speed swap energy
(Figures 4.5, 4.6), driven by the touch-down velocity angle: landing steeper
gives a longer stance, a shorter flight and a forward-directed impulse
(Figure 4.7).

Sign convention (as :class:`tslip.Disturbance`): ``dh`` is the change of the
ground height, negative for a step down. All quantities are in the
dimensionless units of thesis Table 3.1.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._results import Result, frame
from ..model.dynamics import spring_energy
from ..model.state import TouchdownState
from ..model.units import COLUMN_UNITS
from ..simulation.integrate import Disturbance, simulate, step
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status, Trajectory
from .fixed_point import Gait
from .impulse import Impulse, _impulse_from_run, _stance_run

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "expected_velocity_change",
    "HeightChangeResult",
    "velocity_after_height_change",
    "StepDownResponse",
    "step_down_response",
    "StrideWork",
    "stride_work",
    "VelocityAngleCase",
    "velocity_angle_effect",
]


def expected_velocity_change(v0: float, dh: float, g: float = 1.0) -> float:
    """Speed change from the energy balance, ``-v0 + sqrt(v0^2 - 2 g dh)`` (eq. 3.8).

    Parameters
    ----------
    v0 : float
        Touch-down speed before the change [g^1/2 L^1/2].
    dh : float
        Change of the ground height [L]; negative for a step down, which
        increases the speed.
    g : float
        Gravity [g].

    Returns
    -------
    float
        ``Delta v = v_inf - v0`` [g^1/2 L^1/2].

    Raises
    ------
    ValueError
        If the step up is higher than the kinetic energy allows
        (``v0^2 < 2 g dh``).

    References
    ----------
    Thesis eqs 3.6-3.8. The derivation assumes the apex height above the
    ground returns to its old value and neglects the rotational energy.

    Examples
    --------
    >>> round(expected_velocity_change(5.0, -0.2), 6)
    0.039841
    """
    disc = v0 * v0 - 2.0 * g * dh
    if disc < 0.0:
        raise ValueError(
            f"a step up of dh = {dh} L needs v0 >= sqrt(2 g dh) = {math.sqrt(2 * g * dh):.4g}"
            f" g^1/2 L^1/2, got v0 = {v0}"
        )
    return -v0 + math.sqrt(disc)


def _height(gait: Gait, s: TouchdownState) -> float:
    """CoM height above the ground at touch-down, ``l0 sin(beta) - r cos(phi)`` (eq. 2.9)."""
    return gait.params.l0 * math.sin(s.beta) - gait.params.r * math.cos(s.phi)


@dataclass(frozen=True, slots=True, eq=False, repr=False)
class HeightChangeResult(Result):
    """Converged touch-down speed after a change in ground height.

    Attributes
    ----------
    dh : float
        Ground-height change [L] (negative: step down).
    v0 : float
        Touch-down speed of the gait [g^1/2 L^1/2].
    v_final : float
        Mean touch-down speed over the last ``n_average`` strides
        [g^1/2 L^1/2]; NaN after a fall.
    dv : float
        ``v_final - v0`` [g^1/2 L^1/2].
    dv_expected : float
        Eq. 3.8 [g^1/2 L^1/2].
    spread : float
        Peak-to-peak touch-down speed over the averaging window: the
        amplitude of the remaining oscillation [g^1/2 L^1/2].
    drift : float
        Difference between the means of the window's second and first
        halves [g^1/2 L^1/2]: how far ``v_final`` is from settled.
    converged : bool
        No fall, and ``|drift| <= tol``.
    speeds : ndarray, shape (n,)
        Touch-down speeds, stride 0 (on the old ground) first.
    n_average : int
        Window length [strides].
    status : Status
        Outcome of the run (a fall ends it early).
    """

    dh: float
    v0: float
    v_final: float
    dv: float
    dv_expected: float
    spread: float
    drift: float
    converged: bool
    speeds: np.ndarray
    n_average: int
    status: Status

    def to_dataframe(self) -> pd.DataFrame:
        """One row per touch-down: its speed ``v``, and whether it is in the averaging window."""
        n = len(self.speeds)
        return frame({"step": np.arange(n), "v": self.speeds,
                      "averaged": np.arange(n) >= n - self.n_average},
                     {**COLUMN_UNITS, "averaged": "-"})

    def plot(self, ax: Axes | None = None) -> Figure:
        """Touch-down speeds, with the speed eq. 3.8 predicts."""
        from ..plotting.results import plot_series

        return plot_series(self.speeds, ax, level=self.v0 + self.dv_expected,
                           title=f"after a height change of {self.dh:+.3g} L (dashed: eq. 3.8)")


def velocity_after_height_change(
    gait: Gait,
    dh: float,
    *,
    n_steps: int = 200,
    n_average: int = 50,
    tol: float = 1e-4,
    options: IntegratorOptions | None = None,
) -> HeightChangeResult:
    """Run a gait over a ground step and measure its final speed (Figure 4.4).

    The first stance is on the old ground, every later touch-down on ground
    moved by ``dh`` (:class:`tslip.Disturbance`). The passive model does not
    settle in a few strides: its touch-down speed oscillates around the new
    steady state with a slowly decaying amplitude (Figure 4.5). The final
    speed is therefore the mean over the last ``n_average`` strides; a
    decaying oscillation averages out to about its amplitude divided by the
    window length, and ``drift`` reports how much the mean still moves.

    Parameters
    ----------
    gait : Gait
    dh : float
        Ground-height change [L] (negative: step down).
    n_steps : int
        Strides to run.
    n_average : int
        Strides at the end to average over (at most ``n_steps``).
    tol : float
        Largest ``|drift|`` [g^1/2 L^1/2] for ``converged``.
    options : IntegratorOptions, optional

    Returns
    -------
    HeightChangeResult

    Raises
    ------
    ValueError
        For ``leg_thrust != 0``: the thrust adds energy every stride, so eq. 3.8's
        balance does not hold.

    References
    ----------
    Thesis Sections 3.3 and 4.2, eq. 3.8, Figure 4.4.
    """
    if not (isinstance(n_average, int) and 2 <= n_average <= n_steps):
        raise ValueError(f"n_average must be an integer in [2, n_steps], got {n_average!r}")
    if gait.params.leg_thrust != 0.0:
        raise ValueError(f"leg_thrust must be 0 for the energy balance of eq. 3.8 (a "
                         f"conservative model), got {gait.params.leg_thrust!r}")
    v0 = gait.state.v
    dv_expected = expected_velocity_change(v0, dh, gait.params.g)
    traj = simulate(gait.params, gait.state, n_steps, disturbance=Disturbance(dh=dh),
                    dt=1e3, options=options)
    speeds = np.array([s.v for s in traj.touchdowns])
    if traj.status != Status.OK or len(speeds) < n_steps + 1:
        return HeightChangeResult(
            dh=float(dh), v0=v0, v_final=math.nan, dv=math.nan, dv_expected=dv_expected,
            spread=math.nan, drift=math.nan, converged=False, speeds=speeds,
            n_average=n_average, status=traj.status,
        )
    window = speeds[-n_average:]
    half = n_average // 2
    drift = float(np.mean(window[half:]) - np.mean(window[:half]))
    v_final = float(np.mean(window))
    return HeightChangeResult(
        dh=float(dh), v0=v0, v_final=v_final, dv=v_final - v0, dv_expected=dv_expected,
        spread=float(np.ptp(window)), drift=drift, converged=abs(drift) <= tol,
        speeds=speeds, n_average=n_average, status=traj.status,
    )


@dataclass(frozen=True, slots=True, eq=False, repr=False)
class StepDownResponse(Result):
    """Touch-down states stride by stride after a ground step (Figs 4.5, 4.6).

    Arrays have one entry per touch-down; entry 0 is the first touch-down,
    on the old ground, entries 1.. are on the ground moved by ``dh``.

    Attributes
    ----------
    dh : float
        Ground-height change [L].
    stride : ndarray of int
        Touch-down index.
    x, y : ndarray
        CoM position [L].
    height : ndarray
        CoM height above the ground under the foot, ``y - h`` [L].
    xd, yd : ndarray
        CoM velocity [g^1/2 L^1/2].
    speed : ndarray
        ``|v|`` [g^1/2 L^1/2].
    delta : ndarray
        Velocity angle ``atan2(yd, xd)`` [rad].
    beta, phi : ndarray
        Leg angle and pitch [rad].
    h : ndarray
        Ground height [L].
    trajectory : Trajectory
        The run, sampled for plotting.
    """

    dh: float
    stride: np.ndarray
    x: np.ndarray
    y: np.ndarray
    height: np.ndarray
    xd: np.ndarray
    yd: np.ndarray
    speed: np.ndarray
    delta: np.ndarray
    beta: np.ndarray
    phi: np.ndarray
    h: np.ndarray
    trajectory: Trajectory

    def _repr_fields(self) -> dict[str, Any]:
        return {"dh": self.dh, "touchdowns": len(self.stride), "xd_last": self.xd[-1],
                "height_last": self.height[-1], "trajectory": self.trajectory}

    def to_dataframe(self) -> pd.DataFrame:
        """One row per touch-down (entry 0 on the old ground)."""
        return frame({"step": self.stride, **{k: getattr(self, k) for k in (
            "x", "y", "height", "xd", "yd", "speed", "delta", "beta", "phi", "h")}},
            {**COLUMN_UNITS, "height": "L", "speed": COLUMN_UNITS["v"]})

    def plot(self, ax: Axes | None = None) -> Figure:
        """Figures 4.5 and 4.6; on ``ax`` only the touch-down values (Figure 4.5)."""
        from ..plotting.gait import plot_step_down_response

        return plot_step_down_response(self, ax)

    @property
    def phase_correlation(self) -> float:
        """Correlation of ``height`` and ``xd`` after the step [-].

        Negative when height and forward speed oscillate in opposite phase
        (Figure 4.5). Uses the touch-downs on the new ground (entries 1..).
        """
        return float(np.corrcoef(self.height[1:], self.xd[1:])[0, 1])


def step_down_response(
    gait: Gait,
    dh: float = -0.2,
    n_steps: int = 30,
    *,
    dt: float = 0.01,
    options: IntegratorOptions | None = None,
) -> StepDownResponse:
    """Follow a gait over a ground step, stride by stride (Figures 4.5, 4.6).

    Parameters
    ----------
    gait : Gait
    dh : float
        Ground-height change [L]; the thesis uses a 0.2 L step down.
    n_steps : int
        Strides to run.
    dt : float
        Sample spacing of the stored trajectory [g^-1/2 L^1/2].
    options : IntegratorOptions, optional

    Returns
    -------
    StepDownResponse
        With as many entries as touch-downs reached (fewer after a fall;
        see ``trajectory.status``).

    References
    ----------
    Thesis Section 4.2, Figures 4.5 and 4.6.

    Examples
    --------
    >>> import tslip
    >>> r = step_down_response(tslip.find_gait(tslip.preset("table2.1")), n_steps=20)
    >>> r.phase_correlation < 0
    True
    """
    traj = simulate(gait.params, gait.state, n_steps, disturbance=Disturbance(dh=dh), dt=dt,
                    options=options)
    tds = traj.touchdowns

    def col(f: Callable[[TouchdownState], float]) -> np.ndarray:
        return np.array([f(s) for s in tds], dtype=float)

    h = col(lambda s: s.h)
    height = col(lambda s: _height(gait, s))
    return StepDownResponse(
        dh=float(dh), stride=np.arange(len(tds)), x=col(lambda s: s.x), y=h + height,
        height=height, xd=col(lambda s: s.xd), yd=col(lambda s: s.yd),
        speed=col(lambda s: s.v), delta=col(lambda s: s.delta), beta=col(lambda s: s.beta),
        phi=col(lambda s: s.phi), h=h, trajectory=traj,
    )


@dataclass(frozen=True, slots=True, eq=False, repr=False)
class VelocityAngleCase(Result):
    """One stride from the gait with the touch-down velocity angle changed.

    Attributes
    ----------
    ddelta : float
        Change of the velocity angle [rad]; negative: more downward, as
        after a step down.
    delta : float
        Touch-down velocity angle ``delta* + ddelta`` [rad].
    stance_time, flight_time : float
        [g^-1/2 L^1/2]; the flight runs to the next touch-down.
    liftoff_delta : float
        Velocity angle at lift-off [rad]; smaller is a flatter lift-off.
    impulse : Impulse
        The stance's ground impulse, with the force samples (Figure 4.7
        middle and bottom).
    trajectory : Trajectory
        The stride, for the CoM path (Figure 4.7 top).
    """

    ddelta: float
    delta: float
    stance_time: float
    flight_time: float
    liftoff_delta: float
    impulse: Impulse
    trajectory: Trajectory

    def to_dataframe(self) -> pd.DataFrame:
        """One row: the velocity angles, stride times and the stance's impulse."""
        return frame([{"ddelta": self.ddelta, "delta": self.delta,
                       "stance_time": self.stance_time, "flight_time": self.flight_time,
                       "liftoff_delta": self.liftoff_delta, "I_x": self.impulse.I_x,
                       "I_y": self.impulse.I_y}],
                     {**COLUMN_UNITS, "ddelta": "rad", "liftoff_delta": "rad",
                      "I_x": "M g^1/2 L^1/2", "I_y": "M g^1/2 L^1/2"})

    def plot(self, ax: Axes | None = None) -> Figure:
        """Figure 4.7 for this case; on ``ax`` the stride's CoM path."""
        from ..plotting.gait import plot_velocity_angle_effect
        from ..plotting.trajectories import plot_path

        return plot_velocity_angle_effect([self]) if ax is None else plot_path(self.trajectory,
                                                                               ax)


def velocity_angle_effect(
    gait: Gait,
    ddeltas: Sequence[float] = (-0.05, 0.0, 0.05),
    *,
    dt: float = 1e-3,
    options: IntegratorOptions | None = None,
) -> tuple[VelocityAngleCase, ...]:
    """One stride per change of the touch-down velocity angle (Figure 4.7).

    The speed, leg angle, pitch and pitch rate of the gait's touch-down
    state are kept; only the direction of the CoM velocity turns by
    ``ddelta``.

    Parameters
    ----------
    gait : Gait
    ddeltas : sequence of float
        Velocity-angle changes [rad].
    dt : float
        Sample spacing [g^-1/2 L^1/2] of the stance quadrature and path.
    options : IntegratorOptions, optional

    Returns
    -------
    tuple of VelocityAngleCase

    References
    ----------
    Thesis Sections 3.3 and 4.2, Figure 4.7.
    """
    s0 = gait.state
    out = []
    for dd in ddeltas:
        s = TouchdownState.from_velocity(v=s0.v, delta=s0.delta + dd, beta=s0.beta, phi=s0.phi,
                                         phid=s0.phid, x=s0.x, h=s0.h)
        traj = _stance_run(gait.params, s, dt, options)
        res = traj.steps[0]
        lo = res.liftoff
        out.append(VelocityAngleCase(
            ddelta=float(dd), delta=s.delta, stance_time=res.stance_time,
            flight_time=res.flight_time, liftoff_delta=math.atan2(lo.yd, lo.xd),
            impulse=_impulse_from_run(traj, dt), trajectory=traj,
        ))
    return tuple(out)


# ---------------------------------------------------------------------------
# one stride's energy balance (powered gaits)
# ---------------------------------------------------------------------------

#: Rows of the recorded stance in :func:`stride_work` (trapezoid rule: the
#: integrals' relative error is about ``1 / STRIDE_WORK_SAMPLES**2``).
STRIDE_WORK_SAMPLES = 20_000


@dataclass(frozen=True)
class StrideWork:
    """The energy balance of one stride from touch-down to the next [M g L].

    The total energy ``E`` (kinetic + gravity + leg spring, the ``energy``
    column of :func:`tslip.simulate`) changes in stance by the hip's work and
    the leg damper's loss, and drops at lift-off by the spring energy the leg
    still holds: lift-off is ``F_y = 0`` (eq. 2.8), which with leg damping or
    a hip torque comes before the leg is back at its rest length, and the
    massless leg then returns to ``l0`` without doing work on the body. In
    flight ``E`` is constant. The leg thrust (``Params.leg_thrust = d``) adds
    ``V(l0 (1 + d) - l_min) - V(l0 - l_min)`` at its switch. So
    ``change = hip - damper - liftoff + thrust`` up to the quadrature error
    (:attr:`residual`), and a periodic gait has ``hip + thrust = damper + liftoff``:
    what the hip actuator and the thrust put in per stride.
    """

    hip: float  #: hip actuator's net work, the integral of ``tau (phid + betad)`` over stance
    damper: float  #: leg damper's loss, the integral of ``c_l ld^2`` over stance
    liftoff: float  #: spring energy left in the leg at lift-off, lost with it
    change: float  #: ``E`` at the next touch-down minus ``E`` at this one
    thrust: float = 0.0  #: the leg thrust's work at its switch (0 without thrust)

    @property
    def residual(self) -> float:
        """``change - (hip - damper - liftoff + thrust)``: the quadrature error (0 in exact
        arithmetic)."""
        return self.change - (self.hip - self.damper - self.liftoff + self.thrust)


def stride_work(gait: Gait, *, samples: int = STRIDE_WORK_SAMPLES) -> StrideWork:
    """The hip's work, the damper's loss and the lift-off loss over one stride of ``gait``.

    Integrated by the trapezoid rule over ``samples`` rows of the recorded
    stance (:func:`tslip.simulate`); see :class:`StrideWork` for the balance.
    The hip power ``tau (phid + betad)`` is the torque times the rate of the
    hip angle between leg and trunk (eqs 2.12-2.16 give ``tau``). Raises a
    one-line ``ValueError`` if the stride does not end in a touch-down.

    Examples
    --------
    >>> from tslip import Params, find_gait
    >>> w = stride_work(find_gait(Params()))  # Table 2.1: passive, undamped
    >>> abs(w.hip) < 1e-12 and abs(w.damper) < 1e-12 and abs(w.liftoff) < 1e-9
    True
    """
    if samples < 100:
        raise ValueError(f"samples must be >= 100, got {samples}")
    run = simulate(gait.params, gait.state, 1, dt=gait.stance_time / samples)
    if run.status is not Status.OK:
        raise ValueError(f"the stride from this gait's state ends in {run.status.name}, "
                         "not a touch-down")
    st = run["stance"] > 0
    t = run["t"][st]
    hip_power = run["tau"][st] * (run["phid"][st] + run["betad"][st])
    damper_power = gait.params.c_l * run["ld"][st] ** 2
    last = int(np.flatnonzero(st)[-1])  # the lift-off row; the next is the same state in flight
    energy = run["energy"]
    p, thrust = gait.params, 0.0
    if p.leg_thrust > 0.0:  # the switch at l_min: step records a row there, exactly
        l_min = float(step(p, gait.state).stance[:, 1].min())
        thrust = float(spring_energy(p, l_min, p.l0 * (1.0 + p.leg_thrust))
                       - spring_energy(p, l_min, p.l0))
    return StrideWork(hip=float(np.trapezoid(hip_power, t)),
                      damper=float(np.trapezoid(damper_power, t)),
                      liftoff=float(energy[last] - energy[last + 1]),
                      change=float(energy[-1] - energy[0]), thrust=thrust)
