"""The TSLIP in three dimensions: touch-down -> stance -> lift-off -> flight -> touch-down.

Issue 43, Part 2. The model (:class:`~tslip.spatial.trunk_parameters.TrunkParams`;
equations in :mod:`tslip.spatial._trunk_kernels`): a rigid trunk of mass ``m``
and principal inertias ``(J_roll, J_yaw, J)`` about its axes ``(x_b, y_b, z_b)``
(forward, along the trunk to the hip, right), the hip on the trunk axis at
``H = c + r y_b`` (the planar model's, eq. A.3), massless spring legs from the
hip to a point foot with the planar leg law (eq. 2.1, its exponent and thrust).

* Touch-down state (:class:`TrunkTouchdown`): the 13 numbers ``y = (c, v, q,
  w_b)`` (CoM, its velocity, the unit quaternion trunk -> world, the body
  angular velocity), the foot ``p`` on the ground and the ``side`` of the leg
  that has landed (``+1`` right, ``-1`` left). A touch-down fails (a fall at the
  touch-down instant, in this order) when the foot is on the far side of the
  body's mid-plane from its leg, ``s (p - c) . n < 0`` with ``n = h x e_y`` and
  ``h`` the trunk's horizontal heading (:attr:`TrunkStatus.FALL_CROSSED_LEG`);
  when the hip is at or below the ground; when the body moves backward,
  ``v . h < 0``; or when the leg lengthens (docs/conventions.md, "Events").
* Stance: the foot fixed; lift-off at the first downward zero of the vertical
  foot force (eq. 2.8; the planar rule for a power-law leg). The hip torque of
  the planar controller acts about ``z_b``; the trunk receives its component
  across the leg (a point foot takes no torque about the leg).
* Flight: ballistic CoM, torque-free trunk (Euler's equations on the same
  Runge-Kutta core). The other leg (``side = -s``) is placed locally: its
  direction in the trunk frame is ``d = (cos a, -sin a cos(splay), s sin a
  sin(splay))`` with the planar hip angle ``a(t)`` (eq. 2.17 with the planar
  retraction clock and stop; under ``leg_reset="global"`` ``a`` is the leg's
  pitch plus the trunk's pitch ``asin(x_b . e_y)``, the yaw-pitch-roll pitch).
  Touch-down is the first downward zero of the foot height ``H_y + l0 (R d)_y``
  (eq. 2.9 in 3-D); the hip reaching the ground first is a fall.

The planar limit (``splay = 0``, no roll, yaw or lateral motion) is the planar
:func:`tslip.step` in every planar variable (:func:`from_planar`,
:func:`to_planar`; tests/spatial/test_trunk_planar.py).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._results import Result, frame
from ..model.state import TouchdownState
from ..simulation.options import IntegratorOptions
from . import _trunk_kernels as kn
from . import _trunk_stride as ks
from .trunk_parameters import TrunkParams

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["TrunkStatus", "TrunkTouchdown", "TrunkStep", "trunk_step", "trunk_stance",
           "from_planar", "to_planar", "trunk_energy", "STATE_NAMES", "STATE_UNITS"]

#: Names of the 13 state components (:mod:`tslip.spatial._trunk_kernels`).
STATE_NAMES: tuple[str, ...] = ("x", "y", "z", "vx", "vy", "vz", "qw", "qx", "qy", "qz",
                                "w_roll", "w_yaw", "w_pitch")
#: Their units (thesis Table 3.1).
STATE_UNITS: dict[str, str] = {
    **dict.fromkeys(("x", "y", "z"), "L"), **dict.fromkeys(("vx", "vy", "vz"), "g^1/2 L^1/2"),
    **dict.fromkeys(("qw", "qx", "qy", "qz"), "-"),
    **dict.fromkeys(("w_roll", "w_yaw", "w_pitch"), "rad g^1/2 L^-1/2")}
#: A touch-down's one-row table: the state, the foot, the side.
_TD_UNITS: dict[str, str] = {**STATE_UNITS, **dict.fromkeys(("foot_x", "foot_y", "foot_z"), "L"),
                             "side": "-"}
#: A stride's one-row table: outcome, durations, the next touch-down (NaN after a fall) and
#: the lift-off state (``lo_`` + a state name).
_STEP_UNITS: dict[str, str] = {
    "status": "-", "stance_time": "g^-1/2 L^1/2", "flight_time": "g^-1/2 L^1/2",
    "n_steps": "-", **_TD_UNITS, **{f"lo_{k}": u for k, u in STATE_UNITS.items()}}


class TrunkStatus(enum.IntEnum):
    """Outcome of a 3-D TSLIP stride (module docstring)."""

    OK = kn.ST_OK
    FALL_BACKWARD = kn.ST_FALL_BACKWARD
    FALL_HIP_GROUND = kn.ST_FALL_HIP_GROUND
    FALL_NO_TOUCHDOWN = kn.ST_FALL_NO_TOUCHDOWN
    FALL_LENGTHENING = kn.ST_FALL_LENGTHENING
    FALL_CROSSED_LEG = kn.ST_FALL_CROSSED_LEG
    STEP_UNDERFLOW = kn.ST_ERR_STEP_UNDERFLOW
    MAX_STEPS = kn.ST_ERR_MAX_STEPS
    TIMEOUT = kn.ST_ERR_TIMEOUT
    NONFINITE = kn.ST_ERR_NONFINITE

    @property
    def is_fall(self) -> bool:
        return 0 < self.value < 10

    @property
    def is_error(self) -> bool:
        return self.value >= 10


@dataclass(frozen=True, repr=False)
class TrunkTouchdown(Result):
    """The state at a touch-down: ``y`` (13, :data:`STATE_NAMES`), the foot ``p`` (3, on
    the ground) and the ``side`` of the leg that has landed (+1 right, -1 left).

    A :class:`~tslip._results.Result`: it saves, loads (bit for bit) and tabulates (one
    row, :meth:`to_dataframe`) like the planar results.
    """

    y: np.ndarray
    foot: np.ndarray
    side: int = 1

    def __post_init__(self) -> None:
        y = np.array(self.y, dtype=float).reshape(-1)
        foot = np.array(self.foot, dtype=float).reshape(-1)
        if y.shape != (kn.NSTATE,) or not np.all(np.isfinite(y)):
            raise ValueError(f"TrunkTouchdown.y must be 13 finite numbers, got shape {y.shape}")
        if foot.shape != (3,) or not np.all(np.isfinite(foot)):
            raise ValueError(f"TrunkTouchdown.foot must be 3 finite numbers, got {foot}")
        if self.side not in (1, -1):
            raise ValueError(f"TrunkTouchdown.side must be 1 (right) or -1 (left), "
                             f"got {self.side!r}")
        nq = float(np.linalg.norm(y[6:10]))
        if nq == 0.0:
            raise ValueError("TrunkTouchdown.y: the quaternion y[6:10] must not be 0")
        y[6:10] /= nq
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "foot", foot)

    @property
    def R(self) -> np.ndarray:
        """The trunk's rotation matrix (columns ``x_b, y_b, z_b`` in the world)."""
        return rotation(self.y)

    def to_dataframe(self) -> pd.DataFrame:
        """One row: the state (:data:`STATE_NAMES`), ``foot_x..z`` and ``side``, with units."""
        return frame([self._row()], _TD_UNITS)

    def _row(self) -> dict[str, float]:
        return {**dict(zip(STATE_NAMES, self.y.tolist())),
                **dict(zip(("foot_x", "foot_y", "foot_z"), self.foot.tolist())),
                "side": self.side}

    @classmethod
    def _from_fields(cls, fields: dict[str, Any]) -> TrunkTouchdown:
        """Checked as a new touch-down, then with the stored bits: the constructor
        renormalises the quaternion, which may move its last bit."""
        checked = cls(**fields)
        y = np.array(fields["y"], dtype=float)
        if abs(float(np.linalg.norm(y[6:10])) - 1.0) > 1e-9:
            raise ValueError("TrunkTouchdown.y: the stored quaternion y[6:10] is not a unit "
                             "quaternion")
        return cls._unchecked(y, checked.foot, checked.side)

    @classmethod
    def _unchecked(cls, y: np.ndarray, foot: np.ndarray, side: int) -> TrunkTouchdown:
        """A touch-down the stride kernel computed (finite, unit quaternion, the foot on
        the ground): the checks and copies of ``__init__`` skipped (they cost more than a
        tenth of a stride)."""
        td = object.__new__(cls)
        td.__dict__.update(y=y, foot=foot, side=side)  # frozen: its fields live in __dict__
        return td


@dataclass(frozen=True, repr=False)
class TrunkStep(Result):
    """One stride: the next touch-down (``None`` after a fall or error), the durations,
    the lift-off state (13; NaN if none) and the integrator's accepted steps.

    A :class:`~tslip._results.Result` (one row, :meth:`to_dataframe`)."""

    status: TrunkStatus
    state: TrunkTouchdown | None
    stance_time: float
    flight_time: float
    liftoff: np.ndarray
    n_steps: int

    @property
    def ok(self) -> bool:
        return self.status == TrunkStatus.OK

    def to_dataframe(self) -> pd.DataFrame:
        """One row: ``status`` (its name), the durations, ``n_steps``, the next touch-down
        (NaN after a fall) and the lift-off state as ``lo_<name>``, with units."""
        td = (self.state._row() if self.state is not None
              else dict.fromkeys(_TD_UNITS, math.nan))
        row = {"status": self.status.name, "stance_time": self.stance_time,
               "flight_time": self.flight_time, "n_steps": self.n_steps, **td,
               **{f"lo_{k}": v for k, v in zip(STATE_NAMES, np.asarray(self.liftoff).tolist())}}
        return frame([row], _STEP_UNITS)


def rotation(y: np.ndarray) -> np.ndarray:
    """``R`` of the (renormalised) quaternion ``y[6:10]``."""
    R = np.empty((3, 3))
    kn.rotation(np.asarray(y, dtype=float), R)
    return R


def _heading(R: np.ndarray) -> np.ndarray:
    """The trunk's horizontal heading (unit), for Python callers (the kernel's twin:
    :func:`tslip.spatial._trunk_stride.heading`)."""
    h = np.array([R[0, 0], 0.0, R[2, 0]])
    return h / math.hypot(h[0], h[2])


def _crossed(side: int, foot: np.ndarray, c: np.ndarray, h: np.ndarray) -> bool:
    """The foot on the far side of the mid-plane: ``s (p - c) . n < 0``, ``n = h x e_y``
    (the kernel's twin: :func:`tslip.spatial._trunk_stride.crossed`)."""
    return side * (-(foot[0] - c[0]) * h[2] + (foot[2] - c[2]) * h[0]) < 0.0


_DEFAULT_O = IntegratorOptions().packed()
#: The last options and parameters packed (parameters for both sides): the stride's
#: callers repeat the same objects, and packing cost a tenth of a stride. Both are
#: frozen; the kernel does not write into the arrays. Each a tuple, read once a call.
_LAST_O: tuple[IntegratorOptions | None, np.ndarray] = (None, _DEFAULT_O)
_LAST_P: tuple[TrunkParams | None, np.ndarray, np.ndarray] = (None, _DEFAULT_O, _DEFAULT_O)
_NO_ROWS = np.empty((0, 1 + kn.NSTATE))
#: The statuses that come with the next touch-down: a stride, and a leg landing across.
_LANDED = (TrunkStatus.OK, TrunkStatus.FALL_CROSSED_LEG)
_STATUS = {int(s): s for s in TrunkStatus}


def _options(options: IntegratorOptions | None) -> np.ndarray:
    global _LAST_O
    if options is None:
        return _DEFAULT_O
    last = _LAST_O
    if last[0] is not options:
        last = (options, options.packed())
        _LAST_O = last
    return last[1]


def _packed(params: TrunkParams, side: int) -> np.ndarray:
    """``params.packed(side)``, kept for the last ``params``."""
    global _LAST_P
    last = _LAST_P
    if last[0] is not params:
        last = (params, params.packed(1), params.packed(-1))
        _LAST_P = last
    return last[1] if side == 1 else last[2]


def touchdown_fall(params: TrunkParams, state: TrunkTouchdown) -> TrunkStatus:
    """The fall a stance starts in (module docstring), else ``OK``: the kernel's rule
    (:func:`tslip.spatial._trunk_stride.touchdown_fall`)."""
    P = params.packed(state.side)
    P[kn.P_FOOT:kn.P_FOOT + 3] = state.foot
    return TrunkStatus(ks.touchdown_fall(P, state.y, np.empty((3, 3)), np.empty(16)))


def _stride(params: TrunkParams, state: TrunkTouchdown, options: IntegratorOptions | None,
            fly: bool, rows: int) -> tuple[TrunkStatus, np.ndarray, np.ndarray]:
    out = np.empty(ks.NSOUT)
    rec = np.empty((rows, 1 + kn.NSTATE)) if rows else _NO_ROWS
    status = ks.stride(_packed(params, state.side), _options(options), state.y, state.foot,
                       fly, rec, out)
    return _STATUS[status], out, rec


def trunk_stance(params: TrunkParams, state: TrunkTouchdown, *,
                 options: IntegratorOptions | None = None, rows: int = 0,
                 ) -> tuple[TrunkStatus, float, np.ndarray, np.ndarray, int]:
    """The stance from ``state``: ``(status, duration, end state, records, steps)``.

    ``records`` holds ``(t, y)`` at the start and at each accepted step, up to
    ``rows`` rows (a leg thrust's switch restarts the step sequence, so its
    rows continue in time). The touch-down's own falls are not checked here
    (:func:`trunk_step` does).
    """
    status, out, rec = _stride(params, state, options, False, rows)
    y = out[ks.S_LO:ks.S_LO + kn.NSTATE].copy()
    return status, float(out[ks.S_TS]), y, rec[:int(out[ks.S_NREC])], int(out[ks.S_NSTEP])


def trunk_step(params: TrunkParams, state: TrunkTouchdown, *,
               options: IntegratorOptions | None = None) -> TrunkStep:
    """One stride from the touch-down ``state`` to the other leg's touch-down: one call
    of the compiled stride (:func:`tslip.spatial._trunk_stride.stride`)."""
    if not isinstance(params, TrunkParams):
        raise TypeError(f"params must be TrunkParams, got {type(params).__name__}")
    status, out, _ = _stride(params, state, options, True, 0)
    td = None
    if math.isfinite(out[ks.S_TD]):  # the flight reached the next touch-down
        td = TrunkTouchdown._unchecked(out[ks.S_TD:ks.S_TD + kn.NSTATE],
                                       out[ks.S_FOOT:ks.S_FOOT + 3], -state.side)
    return TrunkStep(status, td if status in _LANDED else None, float(out[ks.S_TS]),
                     float(out[ks.S_TF]), out[ks.S_LO:ks.S_LO + kn.NSTATE],
                     int(out[ks.S_NSTEP]))



def from_planar(params: TrunkParams, td: TouchdownState, side: int = 1) -> TrunkTouchdown:
    """The 3-D touch-down of a planar one (flat ground at height 0 only): the CoM and
    foot of eq. A.3 in the x-y plane, the trunk pitched by ``phi`` about z."""
    if td.h != 0.0:
        raise ValueError(f"from_planar: the 3-D model runs on flat ground at 0, got h={td.h}")
    b, ph = td.beta, td.phi
    c = [td.x, params.l0 * math.sin(b) - params.r * math.cos(ph), 0.0]
    foot = [td.x - params.r * math.sin(ph) + params.l0 * math.cos(b), 0.0, 0.0]
    y = np.array([*c, td.xd, td.yd, 0.0, math.cos(ph / 2), 0.0, 0.0, math.sin(ph / 2),
                  0.0, 0.0, td.phid])
    return TrunkTouchdown(y, np.array(foot), side)


def to_planar(params: TrunkParams, state: TrunkTouchdown) -> TouchdownState:
    """The planar variables of a 3-D touch-down: the leg's angle ``beta`` from +x down to
    the leg, the trunk's pitch ``phi`` (yaw-pitch-roll), ``xd, yd``, the rate about ``z_b``
    and ``x`` (docs/conventions.md)."""
    y = state.y
    R = rotation(y)
    e = state.foot - (y[0:3] + params.r * R[:, 1])
    beta = math.atan2(-e[1], e[0])
    phi = math.atan2(R[1, 0], math.hypot(R[0, 0], R[2, 0]))
    return TouchdownState(beta, phi, float(y[3]), float(y[4]), float(y[12]), float(y[0]), 0.0)


def trunk_energy(params: TrunkParams, y: np.ndarray, foot: np.ndarray | None = None,
                 l_rest: float | None = None) -> float:
    """Kinetic + gravity energy, plus the leg spring's with the foot at ``foot`` [MgL]."""
    y = np.asarray(y, dtype=float)
    w = y[10:13]
    Jd = np.array([params.J_roll, params.J_yaw, params.J])
    E = 0.5 * params.m * float(y[3:6] @ y[3:6]) + 0.5 * float(w @ (Jd * w))
    E += params.m * params.g * float(y[1])
    if foot is not None:
        R = rotation(y)
        l = float(np.linalg.norm(np.asarray(foot) - y[0:3] - params.r * R[:, 1]))
        lr = params.l0 if l_rest is None else l_rest
        n = params.leg_exponent
        x = abs(lr - l) / params.l0
        E += params.k * params.l0**2 * x ** (n + 1) / (n + 1)
    return E
