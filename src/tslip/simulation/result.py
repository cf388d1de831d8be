"""Typed results: status, one stride (:class:`StepResult`), a run (:class:`Trajectory`).

Over 600 lines: one concept, a run's typed results, which all read one recorded table.
"""

from __future__ import annotations

import enum
import functools
import math
import operator
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, overload

import numpy as np

from .._results import Result, with_units
from ..model import _pack as pk
from ..model.parameters import Params
from ..model.state import TouchdownState
from ..model.terrain import Terrain
from ..model.units import COLUMN_UNITS

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "Status", "LiftoffState", "StepResult", "StepList", "Trajectory", "Event", "EventList",
    "IntegrationError", "Outcome",
]


class IntegrationError(RuntimeError):
    """The integrator could not proceed (not a fall: a numerical failure)."""


#: Codes only the biped reaches (the TSLIP's kernels return those of
#: ``model._pack.ST_*``); the biped kernels' own codes are translated to the
#: shared ones at one boundary (:func:`tslip.biped.simulate.to_status`). 20 is
#: left for the apex map's ``NO_APEX``.
ST_FALL_PITCH = 6
ST_FALL_LEG = 7
ST_T_END = 21


@enum.unique  # two names on one code would silently make one an alias of the other
class Status(enum.IntEnum):
    """Outcome of a stride or a run, for the TSLIP and the biped (Appendix E) alike.

    Codes: 0 ``OK``; 1-9 falls (:attr:`fell`); 10-19 integration errors
    (:attr:`is_error`); 20+ outcomes that are neither (``T_END``: a biped run
    stopped at its end time; ``NO_APEX``: the flight after lift-off has no apex,
    so the apex return map has no next state, docs/conventions.md). The codes
    are stored in caches and results, so a member keeps its number; new
    members take a free code in their range.
    """

    OK = pk.ST_OK
    FALL_BACKWARD = pk.ST_FALL_BACKWARD
    FALL_HIP_GROUND = pk.ST_FALL_HIP_GROUND
    FALL_NO_TOUCHDOWN = pk.ST_FALL_NO_TOUCHDOWN
    FALL_TRIP = pk.ST_FALL_TRIP
    FALL_LENGTHENING = pk.ST_FALL_LENGTHENING
    FALL_PITCH = ST_FALL_PITCH
    FALL_LEG = ST_FALL_LEG
    STEP_UNDERFLOW = pk.ST_ERR_STEP_UNDERFLOW
    MAX_STEPS = pk.ST_ERR_MAX_STEPS
    STANCE_TIMEOUT = pk.ST_ERR_STANCE_TIMEOUT
    FLIGHT_TIMEOUT = pk.ST_ERR_FLIGHT_TIMEOUT
    NONFINITE = pk.ST_ERR_NONFINITE
    T_END = ST_T_END
    NO_APEX = pk.ST_NO_APEX

    @property
    def fell(self) -> bool:
        """True for a fall (eqs 2.10-2.11, a trip, or a biped fall), not for an error."""
        return 0 < self.value < 10

    @property
    def is_error(self) -> bool:
        """True if the integration itself failed (codes 10-19)."""
        return 10 <= self.value < 20

    @property
    def reason(self) -> str:
        """One-line human-readable explanation."""
        return _REASONS[self]


_REASONS = {
    Status.OK: "ok",
    Status.FALL_BACKWARD: "fall: the CoM moved backward, xdot_m < 0 (eq. 2.10)",
    Status.FALL_HIP_GROUND: ("fall: the hip reached the ground (eq. 2.11; TSLIP: in stance; "
                             "biped: either hip, in any phase)"),
    Status.FALL_NO_TOUCHDOWN: ("fall: no touch-down (TSLIP: the hip reached the ground in flight "
                               "before the foot; biped: no right touch-down within "
                               "BipedOptions.stride_time_max)"),
    Status.FALL_TRIP: "fall: the foot hit a step riser (terrain)",
    Status.FALL_LENGTHENING: ("fall: the leg touched down while lengthening (ld > 0), so the "
                              "spring would pull on the ground; it cannot push"),
    Status.FALL_PITCH: "fall: body pitch beyond +-pi/2",
    Status.FALL_LEG: "fall: a thigh or shank length reached zero",
    Status.STEP_UNDERFLOW: "error: step size fell below h_min (IntegratorOptions, BipedOptions)",
    Status.MAX_STEPS: ("error: more than max_steps integrator steps (IntegratorOptions: in one "
                       "stance; BipedOptions: in the run)"),
    Status.STANCE_TIMEOUT: "error: stance longer than IntegratorOptions.t_max_stance",
    Status.FLIGHT_TIMEOUT: "error: flight longer than IntegratorOptions.t_max_flight",
    Status.NONFINITE: "error: the state became NaN or infinite",
    Status.T_END: "reached the end time",
    Status.NO_APEX: ("no apex: the runner lifted off moving down (or touched down while "
                     "rising), so the flight has no apex and the apex map no next state"),
}


@dataclass(frozen=True, slots=True)
class LiftoffState:
    """State at lift-off (or where the stance ended)."""

    x: float
    y: float
    xd: float
    yd: float
    phi: float
    phid: float
    l: float  # noqa: E741 - thesis symbol
    beta: float
    ld: float
    betad: float

    @classmethod
    def from_out(cls, out: np.ndarray) -> LiftoffState:
        return cls(*map(float, out[pk.OUT_LO : pk.OUT_LO + 10]))


class Outcome:
    """``fell``, ``ok`` and ``reason`` of a stride with a ``status`` (both models' StepResult)."""

    __slots__ = ()
    status: Status

    @property
    def fell(self) -> bool:
        """True if the runner fell in this stride."""
        return self.status.fell

    @property
    def ok(self) -> bool:
        """True if the stride ended in its touch-down (the biped's: the right foot's)."""
        return self.status == Status.OK

    @property
    def reason(self) -> str:
        """Why the stride ended as it did."""
        return self.status.reason


@dataclass(frozen=True, slots=True)
class StepResult(Result, Outcome):
    """One stride: touch-down, stance, lift-off, flight, next touch-down.

    Attributes
    ----------
    state : TouchdownState or None
        The next touch-down state (``None`` after a fall or an error).
    stance_time, flight_time : float
        Durations [g^-1/2 L^1/2]; for a fall, up to the fall.
    status : Status
    liftoff : LiftoffState
    grf : ndarray, shape (n, 4)
        Stance samples ``(t, F_x, F_y, tau)`` at the integrator's steps, with
        ``t`` since touch-down.
    stance : ndarray, shape (n, 7)
        Stance samples ``(t, l, beta, phi, ld, betad, phid)``.
    foot_x : float
        Foot position of this stance [L].
    foot_clearance : float
        Foot height above ground right after the leg reset [L].
    fy_negative_at_touchdown : bool
        ``F_y < 0`` right at touch-down (possible with a hip torque).
    n_integrator_steps : int
    """

    state: TouchdownState | None
    stance_time: float
    flight_time: float
    status: Status
    liftoff: LiftoffState
    grf: np.ndarray
    stance: np.ndarray
    foot_x: float
    foot_clearance: float
    fy_negative_at_touchdown: bool
    n_integrator_steps: int
    start: TouchdownState
    params: Params

    def __repr__(self) -> str:
        """One line: status, phase durations and integrator steps (not the records)."""
        return (f"StepResult({self.status.name}, stance_time={self.stance_time:.6g}, "
                f"flight_time={self.flight_time:.6g}, "
                f"n_integrator_steps={self.n_integrator_steps})")

    def to_dataframe(self) -> pd.DataFrame:
        """The stance samples: ``t`` since touch-down, leg and pitch states, GRF, hip torque."""
        import pandas as pd

        cols = ["t", "l", "beta", "phi", "ld", "betad", "phid"]
        df = pd.DataFrame(self.stance, columns=cols)
        for k, name in enumerate(("Fx", "Fy", "tau"), 1):
            df[name] = self.grf[:, k]
        return with_units(df, COLUMN_UNITS)

    def plot(self, ax: Axes | None = None) -> Figure:
        """The ground reaction force and hip torque over the stance."""
        from ..plotting.results import plot_step

        return plot_step(self, ax)

    @classmethod
    def from_kernel(cls, params: Params, start: TouchdownState, status: int, out: np.ndarray,
                    rec: np.ndarray, *, at_steps: bool) -> StepResult:
        """From :func:`~tslip.simulation._kernels.stride`'s output ``out`` and stance record.

        ``rec`` holds the record rows (``REC_*``: time and stance state) as the kernel
        wrote them, at each accepted step (``at_steps``, :func:`tslip.step`) or on
        :func:`tslip.simulate`'s grid; the forces are derived from them
        (:func:`._record.stance_forces`, which needs to know which).
        """
        st = Status(status)
        nxt = TouchdownState(*out[pk.OUT_TD : pk.OUT_TD + 7].tolist()) if st == Status.OK else None
        nstep = out[pk.OUT_NSTEP]
        return cls(
            state=nxt,
            stance_time=float(out[pk.OUT_TS]),
            flight_time=float(out[pk.OUT_TF]),
            status=st,
            liftoff=LiftoffState.from_out(out),
            grf=_forces(params, rec, float(out[pk.OUT_TSW]), at_steps),
            stance=rec[:, : pk.REC_PHID + 1].copy(),
            foot_x=float(out[pk.OUT_XF]),
            foot_clearance=float(out[pk.OUT_CLEAR]),
            fy_negative_at_touchdown=bool(out[pk.OUT_FYNEG] == 1.0),
            n_integrator_steps=int(nstep) if math.isfinite(nstep) else 0,
            start=start,
            params=params,
        )


    @property
    def impulse(self) -> tuple[float, float]:
        """Ground impulse over the stance ``(I_x, I_y)`` (eq. 3.3), from momentum.

        ``I = m (v_LO - v_TD) + (0, m g t_s)``, exact for the model because
        the leg is massless.
        """
        p = self.params
        return (
            p.m * (self.liftoff.xd - self.start.xd),
            p.m * (self.liftoff.yd - self.start.yd) + p.m * p.g * self.stance_time,
        )


def _forces(params: Params, rec: np.ndarray, tsw: float, at_steps: bool) -> np.ndarray:
    """``StepResult.grf`` (``t, F_x, F_y, tau`` a row) of the record rows ``rec``."""
    from ._record import stance_forces

    grf = np.empty((len(rec), 4))
    stance_forces(pk.packed_params(params), np.ascontiguousarray(rec), tsw, at_steps, grf)
    return grf


@dataclass(frozen=True, slots=True)
class Event:
    """A touch-down, lift-off or fall, with time and CoM / foot position."""

    kind: str  # "touchdown" | "liftoff" | "fall"
    step: int
    t: float
    x: float
    y: float
    foot_x: float
    foot_y: float


#: Columns of :attr:`Trajectory.data`, in order (the kernels write them: ``_pack.TR_*``).
TRAJECTORY_COLUMNS: tuple[str, ...] = pk.TRAJ_COLUMNS

#: Trajectory columns that hold a stance record row ``(l, beta, phi, ld, betad, phid)``
#: (``_pack.REC_L ..``), after its time since touch-down.
_REC_FROM_TRAJ = [pk.TR_L, pk.TR_BETA, pk.TR_PHI, pk.TR_LD, pk.TR_BETAD, pk.TR_PHID]


class StepList(Sequence[StepResult]):
    """The :class:`StepResult` of each stride of a recorded run, each built when first read.

    :func:`tslip.simulate` keeps its strides as the kernel wrote them: the
    touch-down states ``starts`` (n, 7), the stride outputs ``outs`` (n, NOUT),
    the ``info`` rows (n, NRI; status and rows of each stride), and ``rec``, one
    row (NREC) per trajectory sample: a stance sample's record row (``REC_*``,
    time since touch-down and stance state, on the grid: the forces are derived
    from it), a flight sample's time since lift-off.
    Building a thousand result objects would cost more than the run.
    """

    __slots__ = ("_params", "_starts", "_outs", "_info", "_rec", "_items")

    def __init__(self, params: Params, starts: np.ndarray, outs: np.ndarray, info: np.ndarray,
                 rec: np.ndarray) -> None:
        self._params = params
        self._starts = starts
        self._outs = outs
        self._info = info
        self._rec = rec
        self._items: list[StepResult | None] = [None] * len(starts)

    def __len__(self) -> int:
        return len(self._items)

    @overload
    def __getitem__(self, i: int) -> StepResult: ...

    @overload
    def __getitem__(self, i: slice) -> list[StepResult]: ...

    def __getitem__(self, i: int | slice) -> StepResult | list[StepResult]:
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        n = len(self._items)
        k = operator.index(i)
        if not -n <= k < n:
            raise IndexError("stride index out of range")
        k %= n
        item = self._items[k]
        if item is None:
            item = self._items[k] = self._build(k)
        return item

    def _build(self, k: int) -> StepResult:
        inf = self._info[k]
        a, b = int(inf[pk.RI_ROW0]), int(inf[pk.RI_ROW0] + inf[pk.RI_NSTANCE])
        rec = self._rec[a:b]
        start = TouchdownState(*self._starts[k].tolist())
        return StepResult.from_kernel(self._params, start, int(inf[pk.RI_STATUS]), self._outs[k],
                                      rec, at_steps=False)

    def __iter__(self) -> Iterator[StepResult]:
        return (self[k] for k in range(len(self)))

    def __repr__(self) -> str:
        return f"<{len(self)} strides>"


class RunTable:
    """The columns of a recorded run before they are derived: ``Trajectory.data`` until read.

    :func:`tslip.simulate` records each stance's record rows and each flight
    sample's time (:class:`StepList`'s arrays); :meth:`columns` derives the
    trajectory's columns from them in one compiled pass
    (:func:`._record.fill_table`: CoM and hip from the leg, eqs A.3-A.5; flight
    in closed form, eq. 2.7), with the stride kernel's formulas and vectorised sines
    and cosines (within 1 ulp of libm's, :mod:`._sincos`).
    """

    __slots__ = ("_P", "_steps")

    def __init__(self, P: np.ndarray, steps: StepList) -> None:  # noqa: N803 - the kernels' name
        self._P = P
        self._steps = steps

    def __len__(self) -> int:
        return len(self._steps._rec)

    def columns(self) -> np.ndarray:
        """A new ``(NTRAJ, rows)`` array: trajectory column ``j`` is its row ``j``."""
        table, step, stance = self.typed()
        table[pk.TR_STEP] = step
        table[pk.TR_STANCE] = stance
        return table

    def typed(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(table, step, stance)``: new arrays as :meth:`columns` but for the stride and
        phase columns, which come as integers and booleans (``(1, rows)`` each, as the
        trajectory's frame holds them) and are not in ``table``'s rows ``TR_STEP`` and
        ``TR_STANCE`` (left unset)."""
        from ._record import fill_table

        sl = self._steps
        n = len(sl._rec)
        table = np.empty((pk.NTRAJ, n))
        step, stance = np.empty((1, n), dtype=np.int64), np.empty((1, n), dtype=bool)
        fill_table(self._P, sl._rec, sl._starts, sl._outs, sl._info, len(sl), table, step[0],
                   stance[0])
        return table, step, stance


class _Data:
    """``Trajectory.data``: the array it was given, or a :class:`RunTable` derived on first read.

    A data descriptor, so the frozen dataclass's ``__init__`` stores through it and
    reading the field derives the columns once (kept column-major: each column of
    ``data`` is contiguous, and :meth:`Trajectory.to_dataframe` needs no transpose).
    """

    def __get__(self, obj: Trajectory | None, owner: type | None = None) -> np.ndarray:
        if obj is None:
            raise AttributeError("data")  # no class-level default: the field is required
        value = obj.__dict__["_data"]
        if isinstance(value, RunTable):
            value = obj.__dict__["_data"] = value.columns().T
        return value

    def __set__(self, obj: Trajectory, value: np.ndarray | RunTable) -> None:
        obj.__dict__["_data"] = value


class EventList(Sequence[Event]):
    """The touch-down, lift-off and fall events of a recorded run, built when first read.

    From the arrays of the run's :class:`StepList`; ``last`` is the touch-down
    that ends the run (``None`` if it ended in a fall or an error).
    """

    __slots__ = ("_steps", "_last", "_items")

    def __init__(self, steps: StepList, last: Event | None) -> None:
        self._steps = steps
        self._last = last
        self._items: list[Event] | None = None

    def _list(self) -> list[Event]:
        if self._items is None:
            self._items = self._build()
        return self._items

    def _build(self) -> list[Event]:
        sl = self._steps
        events: list[Event] = []
        for i, (s, out, inf) in enumerate(zip(sl._starts.tolist(), sl._outs.tolist(),
                                               sl._info.tolist())):
            t0, xf = inf[pk.RI_T0], out[pk.OUT_XF]
            x_lo, y_lo = out[pk.OUT_LO], out[pk.OUT_LO + 1]
            events.append(Event("touchdown", i, t0, s[pk.TD_X], inf[pk.RI_TDY], xf, s[pk.TD_H]))
            st = Status(int(inf[pk.RI_STATUS]))
            if st == Status.OK:
                events.append(Event("liftoff", i, t0 + out[pk.OUT_TS], x_lo, y_lo, xf,
                                    inf[pk.RI_LOFY]))
            elif st.fell:
                events.append(Event("fall", i, t0 + out[pk.OUT_TS] + out[pk.OUT_TF], x_lo, y_lo,
                                    math.nan, math.nan))
        if self._last is not None:
            events.append(self._last)
        return events

    def __len__(self) -> int:
        return len(self._list())

    @overload
    def __getitem__(self, i: int) -> Event: ...

    @overload
    def __getitem__(self, i: slice) -> list[Event]: ...

    def __getitem__(self, i: int | slice) -> Event | list[Event]:
        return self._list()[i]

    def __iter__(self) -> Iterator[Event]:
        return iter(self._list())

    def __repr__(self) -> str:
        return repr(self._list())


@dataclass(frozen=True)
class Trajectory(Result):
    """A multi-stride run, sampled in time.

    ``data`` has the columns of :data:`TRAJECTORY_COLUMNS`: time, step index,
    stance flag, CoM position and velocity, pitch, leg length and angle with
    rates, local hip angle, foot and hip positions, GRF, hip torque and total
    mechanical energy. ``terrain`` is the ground the run used (including a
    step-down from a :class:`Disturbance`). ``steps`` holds the :class:`StepResult`
    of each stride, ``events`` the touch-down, lift-off and fall events (from
    :func:`tslip.simulate`: a :class:`StepList` and an :class:`EventList`, built on access).
    """

    if TYPE_CHECKING:
        data: np.ndarray
    else:
        data: _Data = _Data()  # an array, or a RunTable derived into one on first read
    steps: Sequence[StepResult]
    events: Sequence[Event]
    status: Status
    params: Params
    terrain: Terrain = field(default_factory=Terrain)
    meta: dict[str, Any] = field(default_factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.data[:, TRAJECTORY_COLUMNS.index(name)]

    def __repr__(self) -> str:
        """One line: strides, samples, time span and status (not the data)."""
        t = self.data[:, 0]
        span = f"t {t[0]:.6g} to {t[-1]:.6g}" if len(t) else "no samples"
        return (f"Trajectory({len(self.steps)} strides, {len(t)} samples, {span}, "
                f"status {self.status.name})")

    @property
    def time(self) -> np.ndarray:
        """Sample times [g^-1/2 L^1/2]."""
        return self["t"]

    @property
    def fell(self) -> bool:
        """True if the run ended in a fall."""
        return self.status.fell

    @property
    def touchdowns(self) -> list[TouchdownState]:
        """Touch-down states: the start of each stride, then the last one."""
        out = [s.start for s in self.steps]
        if self.steps and self.steps[-1].state is not None:
            out.append(self.steps[-1].state)
        return out

    def to_dataframe(self) -> pd.DataFrame:
        """Time series as a tidy ``pandas.DataFrame``, one row per sample (units in attrs)."""

        value = self.__dict__["_data"]
        # new column-major arrays that the frame owns and takes without a copy
        if isinstance(value, RunTable):
            return with_units(_frame(*value.typed()), COLUMN_UNITS)
        return with_units(_frame(self.data.T.copy()), COLUMN_UNITS)

    def plot(self, ax: Axes | None = None) -> Figure:
        """Four panels (:func:`~tslip.plotting.plot_trajectory`), or the CoM path on ``ax``."""
        from ..plotting.trajectories import plot_path, plot_trajectory

        return plot_trajectory(self) if ax is None else plot_path(self, ax)

    # -- what save stores: the samples (the table) and the kernel's stride records
    def _fields(self) -> dict[str, Any]:
        out: dict[str, Any] = {"data": self.data, "status": self.status, "params": self.params,
                               "terrain": self.terrain, "meta": self.meta}
        st, ev = self.steps, self.events
        if isinstance(st, StepList) and isinstance(ev, EventList) and ev._steps is st:
            out["strides"] = {"starts": st._starts, "outs": st._outs, "info": st._info,
                              "tloc": st._rec[:, pk.REC_T].copy(), "last": ev._last}
        else:
            out["steps"], out["events"] = tuple(st), tuple(ev)
        return out

    @classmethod
    def _from_fields(cls, fields: dict[str, Any]) -> Trajectory:
        fields = dict(fields)
        rec = fields.pop("strides", None)
        if rec is not None:
            rows = np.column_stack((rec["tloc"], fields["data"][:, _REC_FROM_TRAJ]))
            steps = StepList(fields["params"], rec["starts"], rec["outs"], rec["info"], rows)
            fields["steps"], fields["events"] = steps, EventList(steps, rec["last"])
        return cls(**fields)

    def _table_fields(self) -> tuple[str, ...]:
        return ("data",)

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        data = df[list(TRAJECTORY_COLUMNS)].to_numpy(dtype=np.float64)
        return {**fields, "data": np.ascontiguousarray(data)}

    def _summary(self) -> dict[str, Any]:
        from .. import __version__

        return {
            "tslip_version": __version__,
            "params": self.params.to_dict(),
            "status": self.status.name,
            "reason": self.status.reason,
            "n_steps": len(self.steps),
            "terrain": {"breakpoints": self.terrain.breakpoints, "heights": self.terrain.heights},
            **self.meta,
        }

    def steps_dataframe(self) -> pd.DataFrame:
        """One row per stride: touch-down state, times, outcome."""
        import pandas as pd

        rows = []
        for i, s in enumerate(self.steps):
            rows.append(
                {
                    "step": i, "beta": s.start.beta, "phi": s.start.phi, "xd": s.start.xd,
                    "yd": s.start.yd, "phid": s.start.phid, "v": s.start.v,
                    "delta": s.start.delta, "x": s.start.x, "h": s.start.h,
                    "stance_time": s.stance_time, "flight_time": s.flight_time,
                    "foot_x": s.foot_x, "foot_clearance": s.foot_clearance,
                    "status": s.status.name,
                }
            )
        return with_units(pd.DataFrame(rows, columns=_STEP_COLUMNS), COLUMN_UNITS)


def _frame(table: np.ndarray, step: np.ndarray | None = None,
           stance: np.ndarray | None = None) -> pd.DataFrame:
    """The frame of a column-major trajectory ``table`` (``NTRAJ x rows``), sharing its memory.

    Time and the columns from ``x`` on stay float blocks of ``table`` (pandas stores
    a block column-major too); ``step`` and ``stance`` are integer and boolean
    columns: the arrays given (``(1, rows)``, as :meth:`RunTable.typed` makes them),
    or else ``table``'s rows converted. pandas 3's block constructor does this
    without a copy; earlier versions insert the three columns one by one.
    """
    import pandas as pd

    names = list(TRAJECTORY_COLUMNS)
    first = pk.TR_X  # the typed columns come before it: time, step, stance
    if step is None or stance is None:
        step = table[pk.TR_STEP : pk.TR_STEP + 1].astype(np.int64)
        stance = table[pk.TR_STANCE : pk.TR_STANCE + 1].astype(bool)
    try:
        from pandas.api.internals import create_dataframe_from_blocks
    except ImportError:  # pandas < 3
        df = pd.DataFrame(table[first:].T, columns=names[first:], copy=False)
        df.insert(0, "t", table[pk.TR_T])
        df.insert(1, "step", step[0])
        df.insert(2, "stance", stance[0])
        return df
    blocks = [(table[pk.TR_T : pk.TR_T + 1], np.array([pk.TR_T])),
              (step, np.array([pk.TR_STEP])), (stance, np.array([pk.TR_STANCE])),
              (table[first:], np.arange(first, pk.NTRAJ))]
    return create_dataframe_from_blocks(blocks, index=pd.RangeIndex(table.shape[1]),
                                        columns=_column_index().copy())


@functools.cache
def _column_index() -> pd.Index:
    """The trajectory frame's column labels, built once: from the strings it took 69 us a
    frame (pandas 3's string dtype), a shallow copy takes 5 us. Each frame gets its own
    copy: the labels are immutable, but an ``Index``'s ``name`` is not, and a frame's
    must not reach the next."""
    import pandas as pd

    return pd.Index(list(TRAJECTORY_COLUMNS))


_STEP_COLUMNS = ["step", "beta", "phi", "xd", "yd", "phid", "v", "delta", "x", "h",
                 "stance_time", "flight_time", "foot_x", "foot_clearance", "status"]
