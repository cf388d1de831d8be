"""Public simulation API: one stride, the Poincare map, runs, and batches.

This module validates inputs, calls the compiled kernels in :mod:`._kernels`,
and turns their flat arrays into typed results.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .._checks import check_fits, check_number
from ..model import _pack as pk
from ..model.parameters import Params
from ..model.state import TouchdownState
from ..model.terrain import Terrain
from . import _kernels as kn
from ._threads import choose
from .options import IntegratorOptions
from .result import (
    TRAJECTORY_COLUMNS,
    Event,
    IntegrationError,
    LiftoffState,
    Status,
    StepResult,
    Trajectory,
)

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
#: ``rec`` of a stride that records nothing (``kn.stride`` straight, not its
#: ``stride_simple`` wrapper: one kernel level less to compile on first use)
_NO_REC = np.empty((0, pk.NREC))


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


def _options(options: IntegratorOptions | None) -> np.ndarray:
    return (options or _DEFAULT_OPTIONS).packed()


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


def _section(q: Sequence[float] | np.ndarray, h: float) -> np.ndarray:
    """The touch-down vector ``(beta, phi, xd, yd, phid, x=0, h)`` of a checked section."""
    qa = np.asarray(q, dtype=float)
    if qa.shape != (5,):
        raise ValueError(f"q (beta, phi, xd, yd, phid) must have 5 entries, got shape {qa.shape}")
    # plain floats: this runs once a stride in every analysis, where NumPy's ufuncs cost more
    if not all(map(math.isfinite, qa.tolist())):
        raise ValueError(f"q (beta, phi, xd, yd, phid) must be finite, got {qa.tolist()}")
    td = np.zeros(pk.NTD)
    td[:5] = qa
    td[6] = h if type(h) is float and math.isfinite(h) else check_number(h, "h", unit="L")
    return td


#: Bytes a recorded stride holds per sample row (the table, its stance record and
#: the copies made while stacking) and per stride (result objects); measured with
#: tracemalloc for Table 2.1 and 6.1 (tests/simulation/test_input_checks.py).
_ROW_BYTES = 480.0
_STRIDE_BYTES = 2000.0


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


def _step_result(
    params: Params, start: TouchdownState, status: int, out: np.ndarray, rec: np.ndarray
) -> StepResult:
    st = Status(status)
    nxt = (
        TouchdownState(*map(float, out[pk.OUT_TD : pk.OUT_TD + 7])) if st == Status.OK else None
    )
    return StepResult(
        state=nxt,
        stance_time=float(out[pk.OUT_TS]),
        flight_time=float(out[pk.OUT_TF]),
        status=st,
        liftoff=LiftoffState.from_out(out),
        grf=rec[:, [pk.REC_T, pk.REC_FX, pk.REC_FY, pk.REC_TAU]].copy(),
        stance=rec[:, : pk.REC_PHID + 1].copy(),
        foot_x=float(out[pk.OUT_XF]),
        foot_clearance=float(out[pk.OUT_CLEAR]),
        fy_negative_at_touchdown=bool(out[pk.OUT_FYNEG] == 1.0),
        n_integrator_steps=int(out[pk.OUT_NSTEP]) if math.isfinite(out[pk.OUT_NSTEP]) else 0,
        start=start,
        params=params,
    )


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
    result = _step_result(params, start, status, out, rec)
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
    P = pk.pack_params(params) if packed is None else packed
    td = _section(q, h)
    out = np.empty(pk.NOUT)
    tx, th = _FLAT.arrays()
    th = th + h
    status = Status(int(kn.stride(P, _options(options), td, tx, th, _NO_REC, 0.0, out)))
    return MapResult(
        out[pk.OUT_TD : pk.OUT_TD + 5].copy(), float(out[pk.OUT_TS]), float(out[pk.OUT_TF]),
        status,
    )


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
    analytically, including the touch-down time. See
    :mod:`tslip.simulation._variational`. The Jacobian is NaN after a fall.
    """
    from . import _variational as va

    P = pk.pack_params(params)
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
    samples, so events are never rounded to the grid.

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
    td = _as_state(state)
    P = pk.pack_params(params)
    O = _options(options)
    steps: list[StepResult] = []
    events: list[Event] = []
    chunks: list[np.ndarray] = []
    t0 = 0.0
    status = Status.OK
    for i in range(int(n_steps)):
        if disturbance is not None and disturbance.at_step == i:
            td = TouchdownState(
                td.beta, td.phi, td.xd + disturbance.dxd, td.yd, td.phid + disturbance.dphid,
                td.x, td.h,
            )
            if disturbance.dh != 0.0:  # every later touch-down: ground moved by dh
                terrain = terrain.shifted_after(_foot_x(params, td), disturbance.dh)
        st, out, rec = _run_stride(P, O, td.as_array(), terrain, dt, _REC_ROWS)
        res = _step_result(params, td, st, out, rec)
        steps.append(res)
        chunks.append(_stance_rows(params, res, rec, i, t0))
        events.append(Event("touchdown", i, t0, *_com_xy(params, td), res.foot_x, td.h))
        status = res.status
        if status != Status.OK:
            lo = res.liftoff
            if status.fell:
                events.append(
                    Event("fall", i, t0 + res.stance_time + res.flight_time, lo.x, lo.y,
                          math.nan, math.nan)
                )
            if res.flight_time > 0:
                chunks.append(_flight_rows(P, params, out, i, t0, dt, final=True))
            break
        lo = res.liftoff
        t_lo = t0 + res.stance_time
        hip_y = lo.y + params.r * math.cos(lo.phi)
        events.append(
            Event("liftoff", i, t_lo, lo.x, lo.y, res.foot_x, hip_y - lo.l * math.sin(lo.beta))
        )
        last = i == n_steps - 1
        chunks.append(_flight_rows(P, params, out, i, t0, dt, final=last))
        t0 = t_lo + res.flight_time
        td = res.state  # type: ignore[assignment]
        if last:
            events.append(
                Event("touchdown", i + 1, t0, *_com_xy(params, td), _foot_x(params, td), td.h)
            )
    data = np.vstack(chunks) if chunks else np.empty((0, len(TRAJECTORY_COLUMNS)))
    meta = {
        "dt": dt,
        "start": dataclasses.asdict(_as_state(state)),
        "options": dataclasses.asdict(options or _DEFAULT_OPTIONS),
        "disturbance": None if disturbance is None else dataclasses.asdict(disturbance),
    }
    return Trajectory(data=data, steps=steps, events=events, status=status, params=params,
                      terrain=terrain, meta=meta)


def _foot_x(params: Params, td: TouchdownState) -> float:
    """Foot x at touch-down (eq. A.3 with l = l0)."""
    return td.x + params.l0 * math.cos(td.beta) - params.r * math.sin(td.phi)


def _com_xy(params: Params, td: TouchdownState) -> tuple[float, float]:
    return td.x, td.h + params.l0 * math.sin(td.beta) - params.r * math.cos(td.phi)


def _energy(p: Params, y: np.ndarray, xd: np.ndarray, yd: np.ndarray, phid: np.ndarray,
            l: np.ndarray) -> np.ndarray:  # noqa: E741
    """Total mechanical energy: kinetic + gravity + leg spring [MgL]."""
    return (0.5 * p.m * (xd**2 + yd**2) + 0.5 * p.J * phid**2 + p.m * p.g * y
            + 0.5 * p.k * (p.l0 - l) ** 2)


def _stance_rows(p: Params, res: StepResult, rec: np.ndarray, i: int, t0: float) -> np.ndarray:
    t, l, b, ph, ld, bd, phd, fx, fy, tau = rec.T
    xf, h = res.foot_x, res.start.h
    sb, cb, sp, cp = np.sin(b), np.cos(b), np.sin(ph), np.cos(ph)
    x = xf - l * cb + p.r * sp
    y = h + l * sb - p.r * cp
    xd = -ld * cb + l * sb * bd + p.r * cp * phd
    yd = ld * sb + l * cb * bd + p.r * sp * phd
    n = len(t)
    cols = {
        "t": t0 + t, "step": np.full(n, i), "stance": np.ones(n), "x": x, "y": y, "xd": xd,
        "yd": yd, "phi": ph, "phid": phd, "l": l, "beta": b, "ld": ld, "betad": bd,
        "alpha": b + ph, "foot_x": np.full(n, xf), "foot_y": np.full(n, h),
        "hip_x": xf - l * cb, "hip_y": h + l * sb, "Fx": fx, "Fy": fy, "tau": tau,
        "energy": _energy(p, y, xd, yd, phd, l),
    }
    return np.column_stack([cols[c] for c in TRAJECTORY_COLUMNS])


def _flight_rows(P: np.ndarray, p: Params, out: np.ndarray, i: int, t0: float, dt: float,
                 final: bool) -> np.ndarray:
    ts_, tf = float(out[pk.OUT_TS]), float(out[pk.OUT_TF])
    lo = out[pk.OUT_LO : pk.OUT_LO + 6].copy()
    ts = np.arange(dt, tf, dt)
    if ts.size and tf - ts[-1] < 1e-9:
        ts = ts[:-1]
    if final:
        ts = np.append(ts, tf)
    fs = np.empty((len(ts), 10))
    kn.flight_samples(P, lo, ts, fs)
    x, y, xd, yd, ph, phd, b, foot_x, foot_y, hip_y = fs.T
    n = len(ts)
    betad = np.full(n, p.omega_r) if p.leg_reset == "global" else p.omega_r - phd
    zeros = np.zeros(n)
    l = np.full(n, p.l0)  # noqa: E741
    cols = {
        "t": t0 + ts_ + ts, "step": np.full(n, i), "stance": zeros, "x": x, "y": y, "xd": xd,
        "yd": yd, "phi": ph, "phid": phd, "l": l, "beta": b, "ld": zeros, "betad": betad,
        "alpha": b + ph, "foot_x": foot_x, "foot_y": foot_y, "hip_x": x - p.r * np.sin(ph),
        "hip_y": hip_y, "Fx": zeros, "Fy": zeros, "tau": zeros,
        "energy": _energy(p, y, xd, yd, phd, l),
    }
    return np.column_stack([cols[c] for c in TRAJECTORY_COLUMNS])


# ---------------------------------------------------------------------------
# Batches: one compiled call over many rows
# ---------------------------------------------------------------------------


class BatchStep(NamedTuple):
    """Result of :func:`step_batch` (row-aligned arrays)."""

    states: np.ndarray  # (n, 7) next touch-down states, NaN where not OK
    stance_time: np.ndarray
    flight_time: np.ndarray
    status: np.ndarray  # int codes of :class:`Status`
    raw: np.ndarray  # (n, NOUT) kernel output


class BatchRun(NamedTuple):
    """Result of :func:`run_batch` (row-aligned arrays)."""

    n_done: np.ndarray  # completed strides per row
    status: np.ndarray  # final status code per row
    t_fall: np.ndarray  # time of the fall, NaN if none
    touchdowns: np.ndarray  # (n, n_steps + 1, 7) touch-down states


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
    n = len(S)
    OUT = np.empty((n, pk.NOUT))
    status = np.empty(n, dtype=np.int64)
    kernel = choose(kn.stride_batch_serial, kn.stride_batch, n)
    kernel(Ps, _options(options), S, TX, TH, OUT, status)
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

