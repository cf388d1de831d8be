"""Ground reaction impulse of a stance and its response to pitch (Section 3.2).

The ground reaction force over one stance is reduced to a single impulse
``I = (I_x, I_y)`` (eq. 3.3) applied at the point ``(x_p, y_p)`` relative to
the centre of mass (eq. 3.5). Its moment about the CoM decides whether a
pitch disturbance is corrected: the thesis's metacentric argument (Figures
1.1 d, 4.1-4.3, 6.2) is that the impulse stays directed at the hip, so that a
CoM displaced from under the hip feels a restoring torque.

Quadrature and exact checks
---------------------------
The force is sampled on a uniform grid of spacing ``dt`` from the
integrator's dense output, plus the lift-off instant, and integrated with
Simpson's rule. Two exact identities of the model check it, because the
leg is massless and gravity acts at the CoM:

* linear momentum: ``I = m (v_LO - v_TD) + (0, m g t_s)``
  (:attr:`StepResult.impulse`);
* angular momentum about the CoM: ``int (x F_y - y F_x) dt = J (phid_LO - phid_TD)``.

:attr:`Impulse.quadrature_error` is the largest deviation from both. Simpson's
error falls as ``dt^4``: for the passive gait pitched by 0.5 rad it is 1.4e-6
at ``dt = 1e-2``, 7e-11 at ``dt = 1e-3`` (the default) and 1e-12 at
``dt = 3e-4`` with :meth:`IntegratorOptions.tight`; with the default
tolerances ``rtol = atol = 1e-8`` the integrator limits it to about 1e-8.

Sign conventions (docs/conventions.md)
---------------------------------
x forward, y up, moments counter-clockwise positive, i.e. in the direction
of positive pitch ``phi``. A pitch disturbance ``dphi > 0`` swings the CoM
forward of the hip, so a restoring moment is negative.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._results import Result, frame
from ..model.parameters import Params
from ..model.state import TouchdownState
from ..model.units import COLUMN_UNITS, UNIT
from ..simulation.integrate import simulate
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status, Trajectory
from .fixed_point import Gait

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "Impulse",
    "ImpulseLinearisation",
    "PitchResponse",
    "stance_impulse",
    "impulse_linearisation",
    "pitch_disturbance_response",
    "summarise_pitch_response",
    "Y_P_SINGULAR_ANGLE",
]

#: ``y_p`` (eq. 3.5) is flagged ill-conditioned when the impulse is within this
#: angle [rad] of vertical, i.e. ``|I_x| < Y_P_SINGULAR_ANGLE * |I|``.
Y_P_SINGULAR_ANGLE = 1e-3


#: Units of the impulse tables (Table 3.1).
_IMPULSE_UNITS = {**COLUMN_UNITS, "time": UNIT["time"], "I_x": UNIT["impulse"],
                  "I_y": UNIT["impulse"], "torque": UNIT["angular_impulse"],
                  "direction": UNIT["angle"], "dphi": UNIT["angle"],
                  "direction_change": UNIT["angle"], "hip_distance": "r",
                  "x_p_follows_hip": "-", "restoring": "-", "stance_time": UNIT["time"],
                  "dI_x": UNIT["impulse"] + " rad^-1", "dI_y": UNIT["impulse"] + " rad^-1",
                  "dx_p": "L rad^-1", "dy_p": "L rad^-1",
                  "dtorque": UNIT["angular_impulse"] + " rad^-1", "ddirection": "rad rad^-1",
                  "y_p_ill_conditioned": "-"}


@dataclass(frozen=True, slots=True, eq=False, repr=False)
class Impulse(Result):
    """Ground reaction impulse of one stance (eqs 3.3 and 3.5).

    Positions are relative to the CoM [L]; time since touch-down
    [g^-1/2 L^1/2]; forces [Mg]; impulses [M g^1/2 L^1/2].

    Attributes
    ----------
    I_x, I_y : float
        Impulse components (eq. 3.3), exact from the momentum change.
    x_p : float
        ``int x F_y dt / int F_y dt`` (eq. 3.5) [L]: where the vertical
        impulse acts, relative to the CoM.
    y_p : float
        ``int y F_x dt / int F_x dt`` (eq. 3.5) [L]. Singular as
        ``I_x -> 0``, which holds at every periodic gait (the flight is
        ballistic, so periodicity forces ``I_x = m Delta xdot = 0``); then only
        the line of action, not a height on it, is defined. NaN if
        ``int F_x dt`` is exactly zero. See :attr:`y_p_ill_conditioned`.
    torque : float
        Moment of the impulse about the CoM, ``x_p I_y - y_p I_x =
        int (x F_y - y F_x) dt`` [M g^1/2 L^3/2], counter-clockwise (positive
        pitch) positive; exact from ``J (phid_LO - phid_TD)``.
    direction : float
        Angle of the impulse from the +x axis, ``atan2(I_y, I_x)`` [rad]
        (pi/2: straight up).
    hip_touchdown, hip_liftoff : tuple of float
        Hip position relative to the CoM at touch-down and lift-off [L],
        ``(-r sin phi, r cos phi)``.
    hip_mean : tuple of float
        Hip position relative to the CoM averaged over the stance with the
        weight ``F_y`` (the weight of ``x_p``) [L].
    stance_time : float
        [g^-1/2 L^1/2].
    quadrature_error : float
        Largest deviation of the quadrature from the exact linear and
        angular impulses [M g^1/2 L^1/2 or M g^1/2 L^3/2].
    time, F_x, F_y, x, y, hip_x, hip_y : ndarray, shape (n,)
        Stance samples: time since touch-down, ground reaction force, foot
        and hip positions relative to the CoM.
    state : TouchdownState or BipedState
        State at the start of the stance.
    params : Params or BipedParams
    """

    I_x: float
    I_y: float
    x_p: float
    y_p: float
    torque: float
    direction: float
    hip_touchdown: tuple[float, float]
    hip_liftoff: tuple[float, float]
    hip_mean: tuple[float, float]
    stance_time: float
    quadrature_error: float
    time: np.ndarray
    F_x: np.ndarray
    F_y: np.ndarray
    x: np.ndarray
    y: np.ndarray
    hip_x: np.ndarray
    hip_y: np.ndarray
    state: TouchdownState | Any
    params: Params | Any

    def _repr_fields(self) -> dict[str, Any]:
        return {k: getattr(self, k) for k in ("I_x", "I_y", "x_p", "y_p", "torque",
                                              "direction", "stance_time")}

    def to_dataframe(self) -> pd.DataFrame:
        """The stance samples: time, GRF, and foot and hip positions relative to the CoM."""
        return frame({k: getattr(self, k) for k in ("time", "F_x", "F_y", "x", "y", "hip_x",
                                                    "hip_y")}, _IMPULSE_UNITS)

    def plot(self, ax: Axes | None = None) -> Figure:
        """The forces of the stance at the foot, and the impulse's line of action."""
        from ..plotting.gait import plot_pitch_impulse

        return plot_pitch_impulse([self], ax)

    @property
    def magnitude(self) -> float:
        """``|I|`` [M g^1/2 L^1/2]."""
        return math.hypot(self.I_x, self.I_y)

    @property
    def lean(self) -> float:
        """Angle of the impulse from vertical, forward positive [rad]."""
        return math.atan2(self.I_x, self.I_y)

    @property
    def y_p_ill_conditioned(self) -> bool:
        """True if the impulse is within :data:`Y_P_SINGULAR_ANGLE` of vertical."""
        return abs(self.I_x) < Y_P_SINGULAR_ANGLE * self.magnitude

    def line_x(self, y: float | np.ndarray) -> float | np.ndarray:
        """Return x [L] on the impulse's line of action at height ``y`` [L] (rel. CoM).

        The line is the set of points ``p`` with ``p_x I_y - p_y I_x =
        torque``; it is well defined even where ``y_p`` is not.
        """
        return (self.torque + np.asarray(y) * self.I_x) / self.I_y

    def line_distance(self, px: float, py: float) -> float:
        """Signed distance [L] from the point ``(px, py)`` (rel. CoM) to the line.

        Positive when the point lies to the right of the impulse's direction
        (in front of the line for an upward impulse).
        """
        return (px * self.I_y - py * self.I_x - self.torque) / self.magnitude


def _simpson(f: np.ndarray, t: np.ndarray) -> float:
    from scipy.integrate import simpson  # here: scipy.integrate imports scipy.optimize, which
    # every tslip command would pay 0.2-0.5 s for

    return float(simpson(f, x=t))


def _clean_grid(t: np.ndarray, dt: float) -> np.ndarray:
    """Select strictly increasing samples with no gap below ``1e-6 dt``.

    The lift-off row can fall within rounding of the last grid sample; a
    near-duplicate abscissa would make the non-uniform Simpson weights blow up.
    """
    keep = [0]
    for i in range(1, len(t)):
        if t[i] - t[keep[-1]] > 1e-6 * dt:
            keep.append(i)
        elif i == len(t) - 1:  # keep the lift-off row itself
            keep[-1] = i
    return np.asarray(keep)


def _stance_run(
    params: Params, state: TouchdownState, dt: float, options: IntegratorOptions | None
) -> Trajectory:
    if not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"dt [g^-1/2 L^1/2] must be in (0, inf), got {dt!r}")
    traj = simulate(params, state, 1, dt=dt, options=options)
    res = traj.steps[0]
    # a flight that fails (fall or error) still follows a complete stance
    lifted_off = res.status == Status.OK or res.flight_time > 0.0
    if not lifted_off:
        raise ValueError(f"the stance did not end in a lift-off: {res.reason}")
    return traj


def _impulse_from_run(traj: Trajectory, dt: float) -> Impulse:
    p = traj.params
    res = traj.steps[0]
    st = (traj["stance"] > 0.5) & (traj["step"] == 0)
    idx = np.flatnonzero(st)
    idx = idx[_clean_grid(traj["t"][idx], dt)]
    t = traj["t"][idx] - traj["t"][idx[0]]
    fx, fy = traj["Fx"][idx], traj["Fy"][idx]
    x = traj["foot_x"][idx] - traj["x"][idx]
    y = traj["foot_y"][idx] - traj["y"][idx]
    hx = traj["hip_x"][idx] - traj["x"][idx]
    hy = traj["hip_y"][idx] - traj["y"][idx]

    ix_q, iy_q = _simpson(fx, t), _simpson(fy, t)
    sx, sy = _simpson(x * fy, t), _simpson(y * fx, t)
    I_x, I_y = res.impulse
    torque = p.J * (res.liftoff.phid - res.start.phid)
    err = max(abs(ix_q - I_x), abs(iy_q - I_y), abs((sx - sy) - torque))
    hip_mean = (_simpson(hx * fy, t) / iy_q, _simpson(hy * fy, t) / iy_q)
    return Impulse(
        I_x=float(I_x),
        I_y=float(I_y),
        x_p=sx / iy_q,
        y_p=sy / ix_q if ix_q != 0.0 else math.nan,
        torque=float(torque),
        direction=math.atan2(I_y, I_x),
        hip_touchdown=(float(hx[0]), float(hy[0])),
        hip_liftoff=(float(hx[-1]), float(hy[-1])),
        hip_mean=(float(hip_mean[0]), float(hip_mean[1])),
        stance_time=float(res.stance_time),
        quadrature_error=float(err),
        time=t, F_x=fx.copy(), F_y=fy.copy(), x=x, y=y, hip_x=hx, hip_y=hy,
        state=res.start,
        params=p,
    )


def stance_impulse(
    params: Params,
    state: TouchdownState,
    *,
    dt: float = 1e-3,
    options: IntegratorOptions | None = None,
) -> Impulse:
    """Ground reaction impulse and its point of application for one stance.

    Parameters
    ----------
    params : Params
    state : TouchdownState
        State just after touch-down.
    dt : float
        Sample spacing [g^-1/2 L^1/2] of the dense output for the quadrature.
    options : IntegratorOptions, optional
        Integrator settings (default: the thesis's 1e-8 tolerances).

    Returns
    -------
    Impulse

    Raises
    ------
    ValueError
        If the stance ends in a fall instead of a lift-off, or ``dt <= 0``.

    References
    ----------
    Thesis Section 3.2, eqs 3.3 and 3.5.

    Examples
    --------
    >>> import tslip
    >>> from tslip.gait.impulse import stance_impulse
    >>> g = tslip.find_gait(tslip.preset("table2.1"))
    >>> imp = stance_impulse(g.params, g.state)
    >>> round(imp.I_y, 4), abs(imp.I_x) < 1e-6, imp.quadrature_error < 1e-7
    (0.4529, True, True)
    """
    return _impulse_from_run(_stance_run(params, state, dt, options), dt)


def _pitched(state: TouchdownState, dphi: float) -> TouchdownState:
    """Add ``dphi`` to the touch-down pitch; keep the CoM velocity and leg angle."""
    return dataclasses.replace(state, phi=state.phi + dphi)


@dataclass(frozen=True, slots=True, eq=False, repr=False)
class ImpulseLinearisation(Result):
    """Derivatives of the impulse with respect to the pitch ``phi`` (eq. 3.4).

    Central differences ``(f(phi* + dphi) - f(phi* - dphi)) / (2 dphi)`` at
    the gait's touch-down state, as in thesis Figure 4.1.

    Attributes
    ----------
    dI_x, dI_y : float
        ``dI/dphi`` [M g^1/2 L^1/2 rad^-1].
    dx_p, dy_p : float
        ``d(x_p, y_p)/dphi`` [L rad^-1]. ``dy_p`` is unreliable when
        ``y_p_ill_conditioned`` (see :attr:`Impulse.y_p`).
    dtorque : float
        ``d(torque)/dphi`` [M g^1/2 L^3/2 rad^-1]; negative means a
        restoring moment for small disturbances.
    ddirection : float
        ``d(direction)/dphi`` [rad rad^-1].
    y_p_ill_conditioned : bool
        The impulse at ``phi* +- dphi`` is within :data:`Y_P_SINGULAR_ANGLE`
        of vertical, so ``y_p`` (and ``dy_p``) carry no information.
    dphi : float
        Half the difference step [rad].
    nominal, plus, minus : Impulse
        At ``phi*``, ``phi* + dphi`` and ``phi* - dphi``.
    """

    dI_x: float
    dI_y: float
    dx_p: float
    dy_p: float
    dtorque: float
    ddirection: float
    y_p_ill_conditioned: bool
    dphi: float
    nominal: Impulse
    plus: Impulse
    minus: Impulse

    def to_dataframe(self) -> pd.DataFrame:
        """One row: the six derivatives, the conditioning flag and the step ``dphi``."""
        return frame([{k: getattr(self, k) for k in (
            "dI_x", "dI_y", "dx_p", "dy_p", "dtorque", "ddirection", "y_p_ill_conditioned",
            "dphi")}], _IMPULSE_UNITS)

    def plot(self, ax: Axes | None = None) -> Figure:
        """The gradients of Figure 4.1 as bars."""
        from ..plotting.gait import plot_impulse_linearisation

        return plot_impulse_linearisation(self, ax)

    def as_dict(self) -> dict[str, float]:
        """Return the four gradients of Figure 4.1 plus torque and direction."""
        return {
            "I_x": self.dI_x, "I_y": self.dI_y, "x_p": self.dx_p, "y_p": self.dy_p,
            "torque": self.dtorque, "direction": self.ddirection,
        }


def impulse_linearisation(
    gait: Gait,
    *,
    dphi: float = 1e-4,
    dt: float = 1e-3,
    options: IntegratorOptions | None = None,
) -> ImpulseLinearisation:
    """Linearise the ground impulse about a gait in the pitch angle (eq. 3.4).

    Parameters
    ----------
    gait : Gait
    dphi : float
        Central-difference step [rad].
    dt : float
        Quadrature sample spacing [g^-1/2 L^1/2].
    options : IntegratorOptions, optional
        Default :meth:`IntegratorOptions.tight` so that the differences are
        not swamped by integration error (``1e-12 / dphi`` is about 1e-8).

    Returns
    -------
    ImpulseLinearisation

    References
    ----------
    Thesis eq. 3.4 and Figure 4.1.
    """
    if not (math.isfinite(dphi) and dphi > 0):
        raise ValueError(f"dphi [rad] must be in (0, inf), got {dphi!r}")
    options = options or IntegratorOptions.tight()
    nom = stance_impulse(gait.params, gait.state, dt=dt, options=options)
    plus = stance_impulse(gait.params, _pitched(gait.state, dphi), dt=dt, options=options)
    minus = stance_impulse(gait.params, _pitched(gait.state, -dphi), dt=dt, options=options)

    def d(name: str) -> float:
        return (getattr(plus, name) - getattr(minus, name)) / (2.0 * dphi)

    return ImpulseLinearisation(
        dI_x=d("I_x"), dI_y=d("I_y"), dx_p=d("x_p"), dy_p=d("y_p"), dtorque=d("torque"),
        ddirection=d("direction"),
        y_p_ill_conditioned=plus.y_p_ill_conditioned or minus.y_p_ill_conditioned,
        dphi=float(dphi), nominal=nom, plus=plus, minus=minus,
    )


@dataclass(frozen=True, slots=True, eq=False, repr=False)
class PitchResponse(Result):
    """Impulses after pitch disturbances, with a metacentric summary.

    Behaves as the sequence of :class:`Impulse` (one per ``dphis`` entry).
    All tuples are aligned with ``dphis``.

    Attributes
    ----------
    dphis : tuple of float
        Pitch disturbances [rad] added to the gait's touch-down ``phi``.
    impulses : tuple of Impulse
    nominal : Impulse
        The undisturbed stance (``dphi = 0``).
    hip_distance : tuple of float
        Distance from the ``F_y``-weighted mean hip position to the line of
        action of the impulse, in units of ``r`` (NaN if ``r = 0``): about 0
        when the impulse is "directed at the hip".
    direction_change : tuple of float
        ``direction - nominal.direction`` [rad].
    x_p_follows_hip : tuple of float
        ``(x_p - x_p*) / (hip_x - hip_x*)`` with the ``F_y``-weighted mean
        hip: 1 when the point of application moves with the hip, 0 when it
        stays under the CoM; NaN for ``dphi = 0``.
    restoring : tuple of bool or None
        ``sign(torque - nominal.torque) == -sign(dphi)`` (in the pitch
        direction): the change of the moment about the CoM opposes the
        disturbance; ``None`` for ``dphi = 0``. At a TSLIP gait the nominal
        moment is zero (the pitch rate is periodic and constant in flight).
    """

    dphis: tuple[float, ...]
    impulses: tuple[Impulse, ...]
    nominal: Impulse
    hip_distance: tuple[float, ...]
    direction_change: tuple[float, ...]
    x_p_follows_hip: tuple[float, ...]
    restoring: tuple[bool | None, ...]

    def _repr_fields(self) -> dict[str, Any]:
        return {"dphis": self.dphis, "restoring": self.restoring}

    def to_dataframe(self) -> pd.DataFrame:
        """One row per disturbance: its impulse and the metacentric summary."""
        rows = [{"dphi": d, "I_x": imp.I_x, "I_y": imp.I_y, "x_p": imp.x_p, "y_p": imp.y_p,
                 "torque": imp.torque, "direction": imp.direction, "hip_distance": hd,
                 "direction_change": dc, "x_p_follows_hip": xf, "restoring": r}
                for d, imp, hd, dc, xf, r in zip(self.dphis, self.impulses, self.hip_distance,
                                                 self.direction_change, self.x_p_follows_hip,
                                                 self.restoring)]
        return frame(rows, _IMPULSE_UNITS)

    def plot(self, ax: Axes | None = None) -> Figure:
        """Forces and impulses of every disturbance (thesis Figure 4.2)."""
        from ..plotting.gait import plot_pitch_impulse

        return plot_pitch_impulse(self, ax)

    def __len__(self) -> int:
        """Return the number of disturbances."""
        return len(self.impulses)

    def __iter__(self) -> Iterator[Impulse]:
        """Iterate over the impulses, in the order of ``dphis``."""
        return iter(self.impulses)

    def __getitem__(self, i: int) -> Impulse:
        """Return the impulse for ``dphis[i]``."""
        return self.impulses[i]


def pitch_disturbance_response(
    gait: Gait,
    dphis: Sequence[float] = (0.0, 0.5, -0.5),
    *,
    dt: float = 1e-3,
    options: IntegratorOptions | None = None,
) -> PitchResponse:
    """Impulse of the first stance after a pitch disturbance at touch-down.

    The disturbance replaces ``phi`` by ``phi* + dphi`` in the gait's
    touch-down state; the leg angle and the CoM velocity are kept (Figure
    4.2), so the CoM moves relative to the hip.

    Parameters
    ----------
    gait : Gait
    dphis : sequence of float
        Pitch disturbances [rad].
    dt : float
        Quadrature sample spacing [g^-1/2 L^1/2].
    options : IntegratorOptions, optional

    Returns
    -------
    PitchResponse

    References
    ----------
    Thesis Sections 3.2, 4.1, 6.2; Figures 4.2, 4.3 and 6.2.
    """
    dphis = tuple(float(d) for d in dphis)
    imps = tuple(
        stance_impulse(gait.params, _pitched(gait.state, d), dt=dt, options=options)
        for d in dphis
    )
    nominal = next((i for d, i in zip(dphis, imps, strict=True) if d == 0.0), None)
    if nominal is None:
        nominal = stance_impulse(gait.params, gait.state, dt=dt, options=options)
    return summarise_pitch_response(dphis, imps, nominal, gait.params.r)


def summarise_pitch_response(
    dphis: Sequence[float],
    impulses: Sequence[Impulse],
    nominal: Impulse,
    offset: float,
    *,
    pitch_sign: float = 1.0,
) -> PitchResponse:
    """Metacentric summary of stance impulses after pitch disturbances.

    Shared by the TSLIP (:func:`pitch_disturbance_response`) and the biped
    (:func:`tslip.biped.metacentre.metacentric_test`).

    Parameters
    ----------
    dphis : sequence of float
        Pitch disturbances [rad], aligned with ``impulses``.
    impulses : sequence of Impulse
    nominal : Impulse
        The undisturbed stance.
    offset : float
        Hip-to-CoM distance [L] that scales ``hip_distance`` (``r`` of the
        TSLIP, ``r_1`` of the biped).
    pitch_sign : float
        +1 if positive pitch is counter-clockwise (TSLIP), -1 if clockwise
        (biped, eq. E.2). The moment in the pitch direction is
        ``pitch_sign * torque``.

    Returns
    -------
    PitchResponse
    """
    dphis = tuple(float(d) for d in dphis)
    imps = tuple(impulses)
    hx0 = nominal.hip_mean[0]
    dist, ddir, follow, restoring = [], [], [], []
    for d, imp in zip(dphis, imps, strict=True):
        dist.append(abs(imp.line_distance(*imp.hip_mean)) / offset if offset > 0 else math.nan)
        ddir.append(imp.direction - nominal.direction)
        dhx = imp.hip_mean[0] - hx0
        follow.append((imp.x_p - nominal.x_p) / dhx if d != 0.0 and dhx != 0.0 else math.nan)
        dtau = pitch_sign * (imp.torque - nominal.torque)
        restoring.append(None if d == 0.0 else bool(np.sign(dtau) == -np.sign(d)))
    return PitchResponse(
        dphis=dphis, impulses=imps, nominal=nominal, hip_distance=tuple(dist),
        direction_change=tuple(ddir), x_p_follows_hip=tuple(follow), restoring=tuple(restoring),
    )
