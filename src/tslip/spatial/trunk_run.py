"""A recorded multi-stride run of the 3-D TSLIP: its trajectory as a table.

Issue 43 ("around both parts"): the 3-D counterpart of :func:`tslip.simulate`.
:func:`trunk_run` takes ``n_steps`` strides with :func:`~tslip.spatial.trunk.trunk_step`
(whose statuses, touch-downs and durations it reports) and records each one: the
stance by :func:`~tslip.spatial.trunk.trunk_stance` (its ``records``, the start and
each accepted integrator step, then the lift-off), the flight by the same compiled
flight phase as ``trunk_step`` with its recording buffer (lift-off, each accepted
step, the touch-down). The samples are the integrator's own steps, not a fixed
``dt``: :meth:`TrunkRun.sample` interpolates them (cubic Hermite in the CoM and the
quaternion with their derivatives ``v`` and ``q w_b / 2``, exact for the ballistic
flight's CoM; linear in the rest), which the animation
(:func:`tslip.plotting.spatial.animate_run`) uses.

Columns (:data:`RUN_COLUMNS`, units :data:`RUN_UNITS`, thesis Table 3.1): time, stride,
``stance`` (1 in stance, 0 in flight), ``side`` (the leg on the ground in stance, the
one about to land in flight: +1 right, -1 left), the 13 state components
(:data:`~tslip.spatial.trunk.STATE_NAMES`: CoM, its velocity, the unit quaternion
trunk -> world, the body angular velocity), the attitude ``yaw, pitch, roll`` of
``R = R_y(yaw) R_z(pitch) R_x(roll)`` (docs/analyses/spatial_tslip.md), the hip
``c + r y_b`` (eq. A.3), the foot (the stance foot on the ground; in flight the swing
leg's foot at rest length, ``hip + l0 R d(t)``, whose height reaching 0 is the
touch-down) and the energy (:func:`~tslip.spatial.trunk.trunk_energy`, the spring's
with rest length ``l0`` in stance: constant for the passive, undamped model).
At a touch-down or lift-off two rows share the time, one of each phase.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import check_number
from .._results import Result, frame
from ..model._pack import O_MAXSTEPS, O_TMAX_FLIGHT
from ..simulation.options import IntegratorOptions
from . import _trunk_kernels as kn
from .trunk import (
    STATE_NAMES,
    STATE_UNITS,
    TrunkStatus,
    TrunkTouchdown,
    rotation,
    trunk_energy,
    trunk_stance,
    trunk_step,
)
from .trunk_parameters import TrunkParams

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["RUN_COLUMNS", "RUN_UNITS", "TrunkRun", "trunk_run", "attitude"]

#: The columns of :attr:`TrunkRun.data` (module docstring).
RUN_COLUMNS: tuple[str, ...] = ("t", "stride", "stance", "side", *STATE_NAMES, "yaw", "pitch",
                                "roll", "hip_x", "hip_y", "hip_z", "foot_x", "foot_y",
                                "foot_z", "energy")
#: Their units (thesis Table 3.1).
RUN_UNITS: dict[str, str] = {
    "t": "g^-1/2 L^1/2", "stride": "-", "stance": "-", "side": "-", **STATE_UNITS,
    **dict.fromkeys(("hip_x", "hip_y", "hip_z", "foot_x", "foot_y", "foot_z"), "L"),
    **dict.fromkeys(("yaw", "pitch", "roll"), "rad"), "energy": "MgL"}
_C = {name: i for i, name in enumerate(RUN_COLUMNS)}
_Y = slice(_C["x"], _C["x"] + kn.NSTATE)  # the 13 state components
#: Touch-down rows: the state (13), the foot (3) and the side.
_TD_COLUMNS = 17


def attitude(R: np.ndarray) -> tuple[float, float, float]:
    """``(yaw, pitch, roll)`` of ``R = R_y(yaw) R_z(pitch) R_x(roll)`` [rad] (as
    :func:`tslip.spatial.trunk_section.section`)."""
    yaw = math.atan2(-R[2, 0], R[0, 0])
    pitch = math.atan2(R[1, 0], math.hypot(R[0, 0], R[2, 0]))
    roll = math.atan2(-R[1, 2], R[1, 1])
    return yaw, pitch, roll


@dataclass(frozen=True, repr=False)
class TrunkRun(Result):
    """A recorded run of the 3-D TSLIP (module docstring).

    Attributes
    ----------
    params : TrunkParams
    data : ndarray, shape (n, len(RUN_COLUMNS))
        The samples, columns :data:`RUN_COLUMNS` (``run["roll"]`` is a column).
    touchdowns : ndarray, shape (k, 17)
        Each stride's touch-down (state, foot, side), then the last one reached (also
        the touch-down of a crossed leg, where the run ended).
    stance_times, flight_times : ndarray, shape (strides,)
        Each stride's durations from :func:`~tslip.spatial.trunk.trunk_step` (0 where
        the phase did not happen).
    status : TrunkStatus
        How the run ended: ``OK`` after all strides, else the fall or error.
    fall_stride : int
        The stride (0-based) the run ended in; -1 if it did not fail.
    """

    params: TrunkParams
    data: np.ndarray
    touchdowns: np.ndarray
    stance_times: np.ndarray
    flight_times: np.ndarray
    status: TrunkStatus
    fall_stride: int = -1

    def __getitem__(self, name: str) -> np.ndarray:
        """A column of :attr:`data` by its name (:data:`RUN_COLUMNS`)."""
        if name not in _C:
            raise KeyError(f"no column {name!r}; one of {', '.join(RUN_COLUMNS)}")
        return self.data[:, _C[name]]

    @property
    def n_strides(self) -> int:
        """Strides taken (the failing one included)."""
        return len(self.stance_times)

    @property
    def states(self) -> list[TrunkTouchdown]:
        """:attr:`touchdowns` as :class:`~tslip.spatial.trunk.TrunkTouchdown` objects."""
        return [TrunkTouchdown(r[:13].copy(), r[13:16].copy(), int(r[16]))
                for r in self.touchdowns]

    def _repr_fields(self) -> dict[str, Any]:
        t = self.data[:, 0]
        return {"strides": self.n_strides, "samples": len(t),
                "t_end": float(t[-1]) if len(t) else 0.0, "status": self.status}

    def to_dataframe(self) -> pd.DataFrame:
        """The samples, one row each, units in ``attrs`` (:data:`RUN_UNITS`)."""
        return frame({c: self.data[:, i].copy() for i, c in enumerate(RUN_COLUMNS)},
                     RUN_UNITS)

    def _table_fields(self) -> tuple[str, ...]:
        return ("data",)

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        data = df[list(RUN_COLUMNS)].to_numpy(dtype=np.float64)
        return {**fields, "data": np.ascontiguousarray(data)}

    def plot(self, ax: Axes | None = None) -> Figure:
        """The CoM path and the footholds from the side and from above, or the view from
        above on ``ax`` (:func:`tslip.plotting.spatial.plot_run`)."""
        from ..plotting.spatial import plot_run

        return plot_run(self, ax)

    def sample(self, times: np.ndarray) -> np.ndarray:
        """Rows (:data:`RUN_COLUMNS`) at ``times`` [g^-1/2 L^1/2], clipped to the run.

        Between two samples of one phase: cubic Hermite in the CoM (derivative ``v``) and
        the quaternion (``q w_b / 2``, then normalised), linear in the rest, the attitude
        and the hip from the quaternion, the foot from the interpolated leg vector (of
        length ``l0`` in flight). Across a touch-down or lift-off the nearer sample.
        """
        d = self.data
        ts = np.asarray(times, dtype=float)
        if len(d) == 0:
            raise ValueError("the run has no samples")
        if len(d) == 1:
            return np.repeat(d, len(ts), axis=0)
        t = d[:, 0]
        k = np.clip(np.searchsorted(t, ts, side="right") - 1, 0, len(t) - 2)
        a, b = d[k], d[k + 1]
        h = b[:, 0] - a[:, 0]
        w = np.clip(np.where(h > 0, (ts - a[:, 0]) / np.where(h > 0, h, 1.0), 0.0), 0.0, 1.0)
        jump = a[:, _C["stance"]] != b[:, _C["stance"]]
        w = np.where(jump | (h <= 0), np.round(w), w)
        out = a * (1.0 - w)[:, None] + b * w[:, None]
        h1, h2, h3, h4 = _hermite(w)
        c0, c1 = _C["x"], _C["x"] + 3
        v0, v1 = _C["vx"], _C["vx"] + 3
        out[:, c0:c1] = (h1[:, None] * a[:, c0:c1] + h2[:, None] * h[:, None] * a[:, v0:v1]
                         + h3[:, None] * b[:, c0:c1] + h4[:, None] * h[:, None] * b[:, v0:v1])
        q0, q1 = _C["qw"], _C["qw"] + 4
        qa, qb = a[:, q0:q1], b[:, q0:q1]
        q = (h1[:, None] * qa + h2[:, None] * h[:, None] * _qdot(qa, a[:, _C["w_roll"]:])
             + h3[:, None] * qb + h4[:, None] * h[:, None] * _qdot(qb, b[:, _C["w_roll"]:]))
        out[:, q0:q1] = q / np.linalg.norm(q, axis=1)[:, None]
        leg_a = a[:, _C["foot_x"]:_C["foot_x"] + 3] - a[:, _C["hip_x"]:_C["hip_x"] + 3]
        leg_b = b[:, _C["foot_x"]:_C["foot_x"] + 3] - b[:, _C["hip_x"]:_C["hip_x"] + 3]
        leg = leg_a * (1.0 - w)[:, None] + leg_b * w[:, None]
        for i, row in enumerate(out):
            y = row[_Y]
            R = rotation(y)
            row[_C["yaw"]:_C["yaw"] + 3] = attitude(R)
            hip = y[0:3] + self.params.r * R[:, 1]
            row[_C["hip_x"]:_C["hip_x"] + 3] = hip
            if row[_C["stance"]] > 0.5:  # the foot stays where it landed
                continue
            n = float(np.linalg.norm(leg[i]))
            row[_C["foot_x"]:_C["foot_x"] + 3] = hip + (self.params.l0 / n * leg[i] if n > 0
                                                        else 0.0)
        return out


def _hermite(w: np.ndarray) -> tuple[np.ndarray, ...]:
    """The cubic Hermite basis at ``w`` in [0, 1] (values at 0, 1 and slopes)."""
    w2, w3 = w * w, w * w * w
    return 2 * w3 - 3 * w2 + 1, w3 - 2 * w2 + w, -2 * w3 + 3 * w2, w3 - w2


def _qdot(q: np.ndarray, wb: np.ndarray) -> np.ndarray:
    """``q (0, w_b) / 2``: the quaternion's rate with the body angular velocity ``w_b``."""
    qw, qx, qy, qz = q.T
    wx, wy, wz = wb[:, 0], wb[:, 1], wb[:, 2]
    return 0.5 * np.column_stack([-(qx * wx + qy * wy + qz * wz), qw * wx + qy * wz - qz * wy,
                                  qw * wy + qz * wx - qx * wz, qw * wz + qx * wy - qy * wx])


def _rows(params: TrunkParams, rec: np.ndarray, t0: float, stride: int, stance: bool,
          side: int, foot: np.ndarray | None, P: np.ndarray | None) -> np.ndarray:
    """Table rows of recorded ``(t, y)``: a stance with its ``foot``, or a flight whose swing
    foot the flight parameters ``P`` place."""
    out = np.empty((len(rec), len(RUN_COLUMNS)))
    d = np.empty(3)
    for i, (t, *y_) in enumerate(rec):
        y = np.asarray(y_)
        R = rotation(y)
        hip = y[0:3] + params.r * R[:, 1]
        if stance:
            assert foot is not None
            p = foot
            energy = trunk_energy(params, y, foot)
        else:
            assert P is not None
            kn.leg_direction(P, R, t, d)
            p = hip + params.l0 * (R @ d)
            energy = trunk_energy(params, y)
        out[i] = (t0 + t, stride, 1.0 if stance else 0.0, side, *y, *attitude(R), *hip, *p,
                  energy)
    return out


def trunk_run(params: TrunkParams, state: TrunkTouchdown, n_steps: int = 10, *,
              options: IntegratorOptions | None = None) -> TrunkRun:
    """``n_steps`` strides from the touch-down ``state``, recorded (module docstring).

    The run stops at the first stride that does not end ``OK`` (a fall or an integration
    error, in :attr:`TrunkRun.status`). Raises ``ValueError`` in one line for
    ``n_steps < 1`` and ``TypeError`` for params that are not
    :class:`~tslip.spatial.trunk_parameters.TrunkParams`.

    Examples
    --------
    >>> from tslip.spatial import preset
    >>> from tslip.spatial.lateral import TABLE21_3D_SECTION, table21_params
    >>> from tslip.spatial.trunk_section import from_section
    >>> p = table21_params()
    >>> run = trunk_run(p, from_section(p, TABLE21_3D_SECTION), 4)
    >>> run.status.name, run.n_strides, run.to_dataframe().attrs["units"]["roll"]
    ('OK', 4, 'rad')
    """
    if not isinstance(params, TrunkParams):
        raise TypeError(f"params must be TrunkParams, got {type(params).__name__}")
    if not isinstance(state, TrunkTouchdown):
        raise TypeError(f"state must be a TrunkTouchdown, got {type(state).__name__}")
    n = int(check_number(n_steps, "n_steps", lower=1, integer=True))
    O = (options or IntegratorOptions()).packed()  # noqa: E741
    rows = int(O[O_MAXSTEPS]) + 1  # the start and every accepted step: all recorded
    blocks: list[np.ndarray] = []
    tds = [np.array([*state.y, *state.foot, state.side])]
    ts_, tf_ = [], []
    status, fall = TrunkStatus.OK, -1
    t0 = 0.0
    for i in range(n):
        r = trunk_step(params, state, options=options)
        ts_.append(r.stance_time)
        tf_.append(r.flight_time)
        if r.stance_time > 0.0:
            _, ts, ylo, rec, _ = trunk_stance(params, state, options=options, rows=rows)
            if np.all(np.isfinite(ylo)):
                rec = np.vstack([rec, np.concatenate([[ts], ylo])])
            blocks.append(_rows(params, rec, t0, i, True, state.side, state.foot, None))
        if r.flight_time > 0.0:
            side = -state.side
            P = params.packed(side)
            vy = r.liftoff[4]
            P[kn.P_TA] = vy / params.g if (params.retraction == "apex" and vy > 0.0) else 0.0
            out = np.empty(kn.NOUT)
            rec = np.empty((rows, 1 + kn.NSTATE))
            kn.run_phase(P, O, kn.FLIGHT, r.liftoff, O[O_TMAX_FLIGHT], out, rec)
            rec = rec[:int(out[kn.OUT_NREC])]
            y = out[kn.OUT_Y:kn.OUT_Y + kn.NSTATE].copy()
            if np.all(np.isfinite(y)):
                y[6:10] /= np.linalg.norm(y[6:10])
                rec = np.vstack([rec, np.concatenate([[out[kn.OUT_T]], y])])
            blocks.append(_rows(params, rec, t0 + r.stance_time, i, False, side, None, P))
        t0 += r.stance_time + r.flight_time
        if r.state is not None:
            tds.append(np.array([*r.state.y, *r.state.foot, r.state.side]))
        if not r.ok or r.state is None:
            status, fall = r.status, i
            break
        state = r.state
    data = np.vstack(blocks) if blocks else np.empty((0, len(RUN_COLUMNS)))
    return TrunkRun(params, np.ascontiguousarray(data), np.array(tds).reshape(-1, _TD_COLUMNS),
                    np.array(ts_, dtype=float), np.array(tf_, dtype=float), status, fall)
