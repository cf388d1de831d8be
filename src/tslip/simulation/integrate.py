"""Public simulation API: one stride, the Poincare map, runs, and batches.

This module validates inputs, calls the compiled kernels in :mod:`._kernels`,
and turns their flat arrays into typed results.

Over 600 lines: one concept, the simulation's public API (a stride, the map and its
Jacobian, a recorded run, batches), each a checked wrapper of one kernel call.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from .._checks import check_fits, check_number
from .._results import Result, with_units
from ..model import _pack as pk
from ..model.parameters import Params
from ..model.state import TouchdownState
from ..model.terrain import Terrain
from ..model.units import COLUMN_UNITS
from . import _kernels as kn
from ._threads import choose
from .options import IntegratorOptions
from .result import (
    Event,
    EventList,
    IntegrationError,
    RunTable,
    Status,
    StepList,
    StepResult,
    Trajectory,
)

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "Disturbance",
    "step",
    "step_map",
    "step_jacobian",
    "simulate",
    "step_batch",
    "run_batch",
    "MapResult",
    "BatchStep",
    "BatchRun",
]

_FLAT = Terrain.flat(0.0)
_REC_ROWS = 4096


@dataclass(frozen=True, slots=True)
class Disturbance:
    """A disturbance applied at touch-down number ``at_step`` (0: the first).

    ``dxd`` (push) and ``dphid`` (pitch rate) change the touch-down state,
    keeping the other CoM velocity components; the leg rates follow from the
    kinematics (eq. A.5). ``dh`` changes the ground height of every later
    touch-down (dh < 0: a step down), as in docs/conventions.md.
    """

    at_step: int = 0
    dh: float = 0.0
    dxd: float = 0.0
    dphid: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "at_step",
                           check_number(self.at_step, "Disturbance.at_step", lower=0, integer=True))
        for name in ("dh", "dxd", "dphid"):
            object.__setattr__(self, name, check_number(getattr(self, name), f"Disturbance.{name}"))


#: The default options, built (and validated) once: ``step_map`` runs once a stride.
_DEFAULT_OPTIONS = IntegratorOptions()
#: ... packed once (never written into)
_DEFAULT_O = _DEFAULT_OPTIONS.packed()
_F64 = np.dtype(float)
#: ``Status`` by code (the enum's own lookup costs a microsecond, once a stride in ``step_map``)
_STATUS = {int(s): s for s in Status}
_new_tuple = tuple.__new__  # a NamedTuple without its Python-level __new__


def _options(options: IntegratorOptions | None) -> np.ndarray:
    return _DEFAULT_O.copy() if options is None else options.packed()


def _as_state(state: TouchdownState | Sequence[float] | np.ndarray) -> TouchdownState:
    if isinstance(state, TouchdownState):
        return state
    arr = np.asarray(state, dtype=float)
    if arr.shape == (5,):
        return TouchdownState.from_section(arr)
    if arr.shape == (7,):
        return TouchdownState(*map(float, arr))
    raise ValueError(
        f"state must be a TouchdownState or have 5 or 7 entries, got shape {arr.shape}"
    )


def _section_values(q: Sequence[float] | np.ndarray, h: float) -> tuple[list[float], float]:
    """The entries ``[beta, phi, xd, yd, phid]`` of a checked section, and the checked ``h``."""
    qa = q if type(q) is np.ndarray and q.dtype is _F64 else np.asarray(q, dtype=float)
    if qa.shape != (5,):
        raise ValueError(f"q (beta, phi, xd, yd, phid) must have 5 entries, got shape {qa.shape}")
    # plain floats: this runs once a stride in every analysis, where NumPy's ufuncs cost more;
    # the sum is finite unless an entry is not (or it overflows: then each is checked)
    vals = qa.tolist()
    if not math.isfinite(sum(vals)) and not all(map(math.isfinite, vals)):
        raise ValueError(f"q (beta, phi, xd, yd, phid) must be finite, got {vals}")
    if not (type(h) is float and math.isfinite(h)):
        h = float(check_number(h, "h", unit="L"))
    return vals, h


def _section(q: Sequence[float] | np.ndarray, h: float) -> np.ndarray:
    """The touch-down vector ``(beta, phi, xd, yd, phid, x=0, h)`` of a checked section."""
    vals, h = _section_values(q, h)
    return np.array([*vals, 0.0, h])


#: Bytes a recorded stride holds per sample row (a compact row: the stance record row,
#: time and state) and per stride (the kernel's start, output and info rows); checked
#: against tracemalloc for Table 2.1 and 6.1 (tests/simulation/test_input_checks.py). The
#: columns derived on first read (``Trajectory.data``) take ``NTRAJ / NREC`` times more.
_ROW_BYTES = 8.0 * pk.NREC
_STRIDE_BYTES = 8.0 * (pk.NTD + pk.NOUT + pk.NRI)


def trajectory_bytes_per_stride(params: Params, dt: float) -> float:
    """Memory one stride of :func:`simulate` needs at sample interval ``dt``, estimated.

    Rows come from the stance time ``t_s ~ 2 l0 cos(beta0) / v0`` (the foot
    sweeps about ``2 l0 cos(beta0)`` at speed ``v0``; cf. eq. 3.10) sampled
    every ``dt``; flight is left out, so this errs low and never refuses a run
    that fits.
    """
    t_s = 2.0 * params.l0 * math.cos(params.beta0) / params.v0
    return _STRIDE_BYTES + _ROW_BYTES * (t_s / dt + 2.0)


def check_simulation_size(params: Params, n_steps: int, dt: float, name: str = "n_steps") -> None:
    """Refuse a :func:`simulate` run whose trajectory cannot fit in memory (before any work)."""
    check_fits(n_steps, trajectory_bytes_per_stride(params, dt), name, "the trajectory")


def _check_params(params: Params) -> Params:
    if not isinstance(params, Params):
        raise ValueError(f"params must be a tslip.Params, got {type(params).__name__}")
    return params


def _run_stride(
    P: np.ndarray, O: np.ndarray, td: np.ndarray, terrain: Terrain, rec_dt: float, rows: int
) -> tuple[int, np.ndarray, np.ndarray]:
    tx, th = terrain.arrays()
    out = np.empty(pk.NOUT)
    while True:
        rec = np.empty((rows, pk.NREC))
        status = int(kn.stride(P, O, td, tx, th, rec, rec_dt, out))
        if out[pk.OUT_RECOVF] == 0.0:
            return status, out, rec[: int(out[pk.OUT_NREC])]
        rows *= 4


def step(
    params: Params,
    state: TouchdownState | Sequence[float] | np.ndarray,
    *,
    terrain: Terrain | None = None,
    options: IntegratorOptions | None = None,
    raise_on_failure: bool = False,
) -> StepResult:
    """Simulate one stride from the state just after touch-down.

    Parameters
    ----------
    params : Params
    state : TouchdownState or array_like, shape (5,) or (7,)
        The touch-down state (see :class:`TouchdownState`).
    terrain : Terrain, optional
        Ground for the next touch-down (default: flat at height 0).
    options : IntegratorOptions, optional
    raise_on_failure : bool
        Raise :class:`IntegrationError` on a numerical failure instead of
        returning its status (a fall is never an exception).

    Returns
    -------
    StepResult

    Examples
    --------
    >>> import tslip
    >>> p = tslip.preset("table2.1")
    >>> s = tslip.TouchdownState(beta=1.05, phi=0.0, xd=5.0, yd=-0.3, phid=0.0)
    >>> r = tslip.step(p, s)
    >>> r.ok, r.stance_time > 0
    (True, True)
    """
    params = _check_params(params)
    start = _as_state(state)
    status, out, rec = _run_stride(
        pk.pack_params(params), _options(options), start.as_array(), terrain or _FLAT, 0.0,
        _REC_ROWS,
    )
    result = StepResult.from_kernel(params, start, status, out, rec, at_steps=True)
    if raise_on_failure and result.status.is_error:
        raise IntegrationError(result.status.reason)
    return result


class MapResult(NamedTuple):
    """Result of :func:`step_map`."""

    q: np.ndarray  # next section (beta, phi, xd, yd, phid); NaN after a fall
    stance_time: float
    flight_time: float
    status: Status


def step_map(
    params: Params,
    q: Sequence[float] | np.ndarray,
    *,
    h: float = 0.0,
    options: IntegratorOptions | None = None,
    packed: np.ndarray | None = None,
) -> MapResult:
    """The Poincare (touch-down to touch-down) map on the 5-D section.

    ``q = (beta, phi, xd, yd, phid)`` just after touch-down on level ground
    at height ``h``. This is the map every gait analysis calls; it skips all
    recording. ``packed`` may carry ``pack_params(params)`` to save time in
    tight loops.
    """
    # lean, as it runs once a stride in every analysis (benchmarks/bench_limit.py)
    P = pk.packed_params(_check_params(params)) if packed is None else packed
    vals, h = _section_values(q, h)
    out = np.empty(pk.NOUT)
    if options is None:
        O = _DEFAULT_O
    else:
        O = options.packed()
    status = kn.section_map(P, O, *vals, h, out)
    return _new_tuple(MapResult, (out[pk.OUT_TD : pk.OUT_TD + 5], out.item(pk.OUT_TS),
                                  out.item(pk.OUT_TF), _STATUS[status]))


def step_jacobian(
    params: Params,
    q: Sequence[float] | np.ndarray,
    *,
    h: float = 0.0,
    options: IntegratorOptions | None = None,
) -> tuple[MapResult, np.ndarray]:
    """The Poincare map and its exact Jacobian ``dq'/dq`` (5 x 5).

    The stance sensitivity is the variational equation integrated by the same
    Dormand-Prince steps (internal differentiation), corrected at lift-off by
    the saltation (event-time) term; the closed-form flight is differentiated
    analytically, including the touch-down time. For a power-law leg
    (``leg_exponent != 1``) the sensitivity is integrated with error control of its own
    within each step, since the leg's stiffness ``|x|^(n-1)`` is not smooth where the
    spring force vanishes. See :mod:`tslip.simulation._variational`. The Jacobian is NaN
    after a fall.

    Raises
    ------
    ValueError
        For ``leg_exponent < 1``: the leg stiffness is infinite at touch-down.
    """
    from . import _variational as va
    from ._packed import check_exact

    P = pk.pack_params(params)
    check_exact(P)
    td = _section(q, h)
    out = np.empty(pk.NOUT)
    J = np.empty((5, 5))
    tx, th = _FLAT.arrays()
    status = Status(int(va.stride_jacobian(P, _options(options), td, tx, th + h, J, out)))
    res = MapResult(out[pk.OUT_TD : pk.OUT_TD + 5].copy(), float(out[pk.OUT_TS]),
                    float(out[pk.OUT_TF]), status)
    return res, J


def simulate(
    params: Params,
    state: TouchdownState | Sequence[float] | np.ndarray,
    n_steps: int,
    terrain: Terrain | None = None,
    *,
    disturbance: Disturbance | None = None,
    dt: float = 0.01,
    options: IntegratorOptions | None = None,
) -> Trajectory:
    """Simulate ``n_steps`` strides and sample the motion every ``dt``.

    The run stops early at a fall or an integration error (see
    :attr:`Trajectory.status`). Touch-down and lift-off instants are always
    samples, so events are never rounded to the grid. The strides run and are
    sampled in compiled code (one call, two with a disturbance); the
    :class:`StepResult` of a stride and the events are built when first read.

    Examples
    --------
    >>> import tslip
    >>> p = tslip.preset("table2.1")
    >>> s = tslip.TouchdownState(beta=1.05, phi=0.0, xd=5.0, yd=-0.3, phid=0.0)
    >>> traj = tslip.simulate(p, s, n_steps=3)
    >>> len(traj.steps)
    3
    """
    params = _check_params(params)
    n_steps = int(check_number(n_steps, "n_steps", lower=1, integer=True))
    dt = float(check_number(dt, "dt", unit="g^-1/2 L^1/2", lower=0.0, lower_open=True))
    check_simulation_size(params, n_steps, dt)
    terrain = terrain or _FLAT
    start = _as_state(state)
    run = _Recording(params, options, n_steps, dt)
    td = start.as_array()
    at = n_steps if disturbance is None else min(disturbance.at_step, n_steps)
    status = run.strides(td, terrain, 0, at)
    if disturbance is not None and status == Status.OK and at < n_steps:
        td[pk.TD_XD] += disturbance.dxd
        td[pk.TD_PHID] += disturbance.dphid
        if disturbance.dh != 0.0:  # every later touch-down: ground moved by dh
            terrain = terrain.shifted_after(_foot_x(params, TouchdownState(*td.tolist())),
                                            disturbance.dh)
        status = run.strides(td, terrain, at, n_steps)
    meta = {
        "dt": dt,
        "start": dataclasses.asdict(start),
        "options": dataclasses.asdict(options or _DEFAULT_OPTIONS),
        "disturbance": None if disturbance is None else dataclasses.asdict(disturbance),
    }
    return run.trajectory(status, terrain, meta)


#: The rows :class:`_Recording` allocates beyond those a run fills are trimmed off at its end
#: only if they are more than ``1 / TRIM_SPARE`` of the allocation (a run that stopped
#: early); the few spare rows of a run that went its length (5 % and 64) are kept, the
#: trajectory's rows a view of them. Trimmed, a large array went back to the C allocator
#: smaller than the next run's request, which glibc then maps afresh (its threshold for
#: mapping follows the size last freed), so that a loop of runs faulted in every page of
#: its rows anew: 474 minor page faults per 1000 Table 6.1 strides at ``dt = 0.01``
#: (4 MB), none kept; about 1.5 ms (those rows filled afresh 2.1 ms, reused 0.6 ms), 0.08
#: of the time of the strides unrecorded (``benchmarks/bench_limit.py``; 2026-12-06).
TRIM_SPARE = 8


class _Recording:
    """The buffers of one :func:`simulate` run, which :func:`_kernels.record_run` fills.

    Compact rows (the stance record rows, a time for each flight sample) are
    allocated for a few strides first, then, once the kernel reports them full,
    for the rest of the run at the rows per stride seen so far (geometric growth
    if that falls short); many unused rows are trimmed at the end
    (:data:`TRIM_SPARE`). The trajectory's columns are derived from them when
    first read (:class:`~.result.RunTable`).
    """

    def __init__(self, params: Params, options: IntegratorOptions | None, n_steps: int,
                 dt: float) -> None:
        self.params = params
        self.P = pk.packed_params(params)
        self.O = _DEFAULT_O if options is None else options.packed()
        self.n_steps = n_steps
        self.dt = dt
        t_s = 2.0 * params.l0 * math.cos(params.beta0) / params.v0  # as in the memory estimate
        rows = int(min(n_steps, 8) * 2.0 * (t_s / dt + 2.0)) + 16
        self.rows = np.empty((rows, pk.NREC))
        self.starts = np.empty((n_steps, pk.NTD))
        self.outs = np.empty((n_steps, pk.NOUT))
        self.info = np.empty((n_steps, pk.NRI))
        self.pos = np.zeros(3)  # next row, its time, next stride

    def strides(self, td: np.ndarray, terrain: Terrain, first: int, last: int) -> Status:
        """Run strides ``first .. last - 1`` from ``td`` (updated to the next touch-down)."""
        tx, th = terrain.arrays()
        close = last == self.n_steps
        while True:
            st = int(kn.record_run(self.P, self.O, td, tx, th, first, last, close, self.dt,
                                self.rows, self.starts, self.outs, self.info, self.pos))
            if st != pk.RUN_FULL:
                return _STATUS[st]
            first = int(self.pos[2])
            self._grow()

    def _grow(self) -> None:
        row, done = int(self.pos[0]), int(self.pos[2])
        cap = len(self.rows)
        rows = 2 * cap
        if done > 0:
            rows = max(row + math.ceil((self.n_steps - done) * 1.05 * row / done) + 64,
                       cap + cap // 2)
        grown = np.empty((rows, pk.NREC))
        grown[:row] = self.rows[:row]
        self.rows = grown

    def trajectory(self, status: Status, terrain: Terrain, meta: dict) -> Trajectory:
        rows, n = int(self.pos[0]), int(self.pos[2])
        if len(self.rows) - rows > len(self.rows) // TRIM_SPARE:
            self.rows.resize((rows, pk.NREC), refcheck=False)  # trim in place, no copy
        else:  # a few spare rows: kept (see TRIM_SPARE)
            self.rows = self.rows[:rows]
        starts, outs, info = self.starts[:n], self.outs[:n], self.info[:n]
        steps = StepList(self.params, starts, outs, info, self.rows)
        last = None
        if status == Status.OK and n == self.n_steps:
            td = TouchdownState(*outs[-1, pk.OUT_TD : pk.OUT_TD + 7].tolist())
            last = Event("touchdown", n, float(self.pos[1]), *_com_xy(self.params, td),
                         _foot_x(self.params, td), td.h)
        return Trajectory(data=RunTable(self.P, steps), steps=steps,  # type: ignore[arg-type]
                          events=EventList(steps, last), status=status, params=self.params,
                          terrain=terrain, meta=meta)


def _foot_x(params: Params, td: TouchdownState) -> float:
    """Foot x at touch-down (eq. A.3 with l = l0)."""
    return td.x + params.l0 * math.cos(td.beta) - params.r * math.sin(td.phi)


def _com_xy(params: Params, td: TouchdownState) -> tuple[float, float]:
    return td.x, td.h + params.l0 * math.sin(td.beta) - params.r * math.cos(td.phi)


# ---------------------------------------------------------------------------
# Batches: one compiled call over many rows
# ---------------------------------------------------------------------------


#: Columns of a touch-down state row (``TouchdownState.as_array()``).
_TD_COLUMNS = ("beta", "phi", "xd", "yd", "phid", "x", "h")


@dataclass(frozen=True, eq=False)
class BatchStep(Result):
    """Result of :func:`step_batch` (row-aligned arrays)."""

    states: np.ndarray  # (n, 7) next touch-down states, NaN where not OK
    stance_time: np.ndarray
    flight_time: np.ndarray
    status: np.ndarray  # int codes of :class:`Status`
    raw: np.ndarray  # (n, NOUT) kernel output

    def __repr__(self) -> str:
        return f"BatchStep({len(self.status)} rows; {_status_counts(self.status)})"

    def to_dataframe(self) -> pd.DataFrame:
        """One row per batch row: status, stride times and the next touch-down state."""
        import pandas as pd

        df = pd.DataFrame({"row": np.arange(len(self.status)),
                           "status": [Status(int(c)).name for c in self.status],
                           "stance_time": self.stance_time, "flight_time": self.flight_time})
        for k, name in enumerate(_TD_COLUMNS):
            df[name] = self.states[:, k]
        return with_units(df, COLUMN_UNITS)


@dataclass(frozen=True, eq=False)
class BatchRun(Result):
    """Result of :func:`run_batch` (row-aligned arrays)."""

    n_done: np.ndarray  # completed strides per row
    status: np.ndarray  # final status code per row
    t_fall: np.ndarray  # time of the fall, NaN if none
    touchdowns: np.ndarray  # (n, n_steps + 1, 7) touch-down states

    def __repr__(self) -> str:
        return (f"BatchRun({len(self.status)} rows, {self.touchdowns.shape[1] - 1} strides "
                f"asked; {_status_counts(self.status)})")

    def to_dataframe(self) -> pd.DataFrame:
        """One row per row and touch-down (NaN after a fall), with the row's outcome."""
        import pandas as pd

        n, m = self.touchdowns.shape[:2]
        df = pd.DataFrame({
            "row": np.repeat(np.arange(n), m), "step": np.tile(np.arange(m), n),
            "n_done": np.repeat(self.n_done, m),
            "status": np.repeat([Status(int(c)).name for c in self.status], m),
            "t_fall": np.repeat(self.t_fall, m)})
        flat = self.touchdowns.reshape(n * m, 7)
        for k, name in enumerate(_TD_COLUMNS):
            df[name] = flat[:, k]
        return with_units(df, {**COLUMN_UNITS, "n_done": "-"})

    def plot(self, ax: Axes | None = None) -> Figure:
        """Touch-down speed stride by stride, a line per row."""
        from ..plotting.results import plot_batch_run

        return plot_batch_run(self, ax)


def _status_counts(codes: np.ndarray) -> str:
    """``"OK 998, FALL_NO_TOUCHDOWN 2"``: how many rows ended in each status."""
    values, counts = np.unique(np.asarray(codes, dtype=int), return_counts=True)
    return ", ".join(f"{Status(int(v)).name} {int(c)}" for v, c in zip(values, counts))


def _batch_inputs(
    params: Params | Sequence[Params],
    states: np.ndarray | Sequence[TouchdownState],
    terrain: Terrain | Sequence[Terrain] | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    if isinstance(states, np.ndarray):
        S = np.atleast_2d(np.asarray(states, dtype=float))
    else:
        S = np.array([_as_state(s).as_array() for s in states], dtype=float)
    if S.ndim != 2 or S.shape[1] not in (5, 7):
        raise ValueError(f"states must have shape (n, 5) or (n, 7), got {S.shape}")
    if S.shape[1] == 5:
        S = np.hstack([S, np.zeros((len(S), 2))])
    if not np.all(np.isfinite(S)):
        raise ValueError("states must be finite")
    n = len(S)
    if isinstance(params, Params):
        Ps = np.tile(pk.pack_params(params), (n, 1))
    else:
        plist = [_check_params(p) for p in params]
        if len(plist) != n:
            raise ValueError(f"got {len(plist)} parameter sets for {n} states")
        Ps = np.array([pk.pack_params(p) for p in plist])
    if terrain is None or isinstance(terrain, Terrain):
        tx, th = (terrain or _FLAT).arrays()
        TX = np.tile(tx, (n, 1))
        TH = np.tile(th, (n, 1))
    else:
        tlist = list(terrain)
        if len(tlist) != n:
            raise ValueError(f"got {len(tlist)} terrains for {n} states")
        nb = max(len(t.breakpoints) for t in tlist)
        TX = np.full((n, nb), np.inf)
        TH = np.empty((n, nb + 1))
        for i, t in enumerate(tlist):
            tx, th = t.arrays()
            TX[i, : len(tx)] = tx
            TH[i, : len(th)] = th
            TH[i, len(th) :] = th[-1]
    return Ps, S, TX, TH


def step_batch(
    params: Params | Sequence[Params],
    states: np.ndarray | Sequence[TouchdownState],
    *,
    terrain: Terrain | Sequence[Terrain] | None = None,
    options: IntegratorOptions | None = None,
) -> BatchStep:
    """One stride for each row of ``states`` in a single compiled call.

    ``params`` is one :class:`Params` for all rows or one per row; ``states``
    has shape (n, 5) (section on ground height 0) or (n, 7). Small batches
    run serially in the calling thread, large ones on numba's threads
    (:mod:`tslip.simulation._threads`).
    """
    Ps, S, TX, TH = _batch_inputs(params, states, terrain)
    return step_batch_packed(Ps, _options(options), S, TX, TH)


def step_batch_packed(Ps: np.ndarray, O: np.ndarray, S: np.ndarray,  # noqa: E741
                      TX: np.ndarray | None = None, TH: np.ndarray | None = None) -> BatchStep:
    """:func:`step_batch` on packed, checked rows: parameters ``Ps`` (n, NP), options
    ``O``, touch-down states ``S`` (n, 7); flat ground at height 0 unless ``TX``/``TH``
    (the analyses that write per-row unknowns into ``Ps``, e.g. the apex map)."""
    n = len(S)
    if TX is None or TH is None:
        TX, TH = np.empty((n, 0)), np.zeros((n, 1))
    OUT = np.empty((n, pk.NOUT))
    status = np.empty(n, dtype=np.int64)
    kernel = choose(kn.stride_batch_serial, kn.stride_batch, n)
    kernel(Ps, O, S, TX, TH, OUT, status)
    nxt = OUT[:, pk.OUT_TD : pk.OUT_TD + 7].copy()
    nxt[status != 0] = np.nan
    return BatchStep(nxt, OUT[:, pk.OUT_TS].copy(), OUT[:, pk.OUT_TF].copy(), status, OUT)


def run_batch(
    params: Params | Sequence[Params],
    states: np.ndarray | Sequence[TouchdownState],
    n_steps: int,
    *,
    terrain: Terrain | Sequence[Terrain] | None = None,
    options: IntegratorOptions | None = None,
) -> BatchRun:
    """Run ``n_steps`` strides for every row in one compiled call (parallel when large).

    Terrain may differ per row (e.g. one step-down height per row), which is
    how robustness searches evaluate many disturbances at once.
    """
    n_steps = int(check_number(n_steps, "n_steps", lower=1, integer=True))
    Ps, S, TX, TH = _batch_inputs(params, states, terrain)
    n = len(S)
    check_fits(n_steps, n * 7 * 8.0, "n_steps", f"the touch-downs of {n} runs")
    hist = np.full((n, int(n_steps) + 1, 7), np.nan)
    status = np.empty(n, dtype=np.int64)
    n_done = np.empty(n, dtype=np.int64)
    t_fall = np.empty(n)
    kernel = choose(kn.run_batch_serial, kn.run_batch, n)
    kernel(Ps, _options(options), S, int(n_steps), TX, TH, hist, status, n_done, t_fall)
    return BatchRun(n_done, status, t_fall, hist)

