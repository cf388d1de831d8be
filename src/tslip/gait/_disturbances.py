"""The three disturbances of Section 3.1.3 and the runs that start from them.

Where and with which sign each disturbance is applied, and the placements of a
push or pitch-rate change, are described in the module notes of
:mod:`tslip.gait.robustness` (which re-exports these names) and in
docs/conventions.md, "Disturbances for robustness".
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Literal

import numpy as np

from ..model import _pack as pk
from ..model.parameters import Params
from ..model.state import TouchdownState
from ..model.terrain import Terrain
from ..simulation import _kernels as kn
from ..simulation import _packed
from ..simulation.integrate import BatchRun, run_batch, step
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status
from .fixed_point import Gait

__all__ = ["KINDS", "PLACEMENTS", "UNITS", "run_disturbed"]

Kind = Literal["step_down", "push", "pitch_rate"]

#: The three disturbances of thesis Section 3.1.3, in the thesis's order.
KINDS: tuple[Kind, ...] = ("step_down", "push", "pitch_rate")

Placement = Literal["touchdown", "touchdown_hip", "liftoff", "apex"]

#: Where a push or pitch-rate disturbance can be applied (:mod:`tslip.gait.robustness` notes).
PLACEMENTS: tuple[Placement, ...] = ("touchdown", "touchdown_hip", "liftoff", "apex")

#: Unit of each disturbance (Table 3.1, dimensionless units).
UNITS: dict[str, str] = {
    "step_down": "L",
    "push": "g^1/2 L^1/2",
    "pitch_rate": "rad g^1/2 L^-1/2",
}

_SECTION_COLUMN = {"push": 2, "pitch_rate": 4}  # xd, phid in TouchdownState.as_array()
_FLIGHT_COLUMN = {"push": 2, "pitch_rate": 5}  # xd, phid in the lift-off (x, y, xd, yd, phi, phid)
_DEFAULT_OPTIONS = IntegratorOptions()  # the thesis's 1e-8, built (and checked) once


def run_disturbed(
    params: Params,
    state: TouchdownState,
    kind: Kind,
    values: Sequence[float] | np.ndarray,
    *,
    n_steps: int = 25,
    options: IntegratorOptions | None = None,
    placement: Placement = "touchdown",
) -> BatchRun:
    """Run ``n_steps`` strides after each disturbance, in one batch.

    Parameters
    ----------
    params : Params
    state : TouchdownState
        Touch-down state that starts stride 0 (the gait's).
    kind : {"step_down", "push", "pitch_rate"}
    values : array_like, shape (n,)
        Signed disturbances: ``dh`` [L] (negative: step down), ``dxd``
        [g^1/2 L^1/2] (negative: backward push) or ``dphid``
        [rad g^1/2 L^-1/2].
    n_steps : int
    options : IntegratorOptions, optional
    placement : {"touchdown", "touchdown_hip", "liftoff", "apex"}
        Where a push or pitch-rate change is applied (:mod:`tslip.gait.robustness` notes); a
        step-down is always ``"touchdown"``.

    Returns
    -------
    BatchRun
        Row ``i`` for ``values[i]``; with ``"touchdown"`` the same runs as
        :func:`tslip.simulate` with ``Disturbance(at_step=0, dh=|dxd=|dphid=values[i])``.
        For the flight placements the rows start at the touch-down after the
        disturbance; a fall in that flight has ``n_done = 0`` and its status.
    """
    _check_kind(kind)
    _check_placement(kind, placement)
    d = np.asarray(values, dtype=float).reshape(-1)
    if not np.all(np.isfinite(d)):
        raise ValueError("disturbance values must be finite")
    if placement in ("liftoff", "apex"):
        return _run_flight_disturbed(params, state, kind, d, placement, n_steps, options)
    S = np.tile(state.as_array(), (len(d), 1))
    if placement == "touchdown_hip":  # hip velocity xd - r cos(phi) phid, yd - r sin(phi) phid held
        S[:, 2] += params.r * math.cos(state.phi) * d
        S[:, 3] += params.r * math.sin(state.phi) * d
    terrain: list[Terrain] | None = None
    if kind == "step_down":
        xf = state.x + params.l0 * math.cos(state.beta) - params.r * math.sin(state.phi)
        ground = Terrain.flat(state.h)
        terrain = [ground.shifted_after(xf, float(v)) for v in d]
    else:
        S[:, _SECTION_COLUMN[kind]] += d
    return run_batch(params, S, n_steps, terrain=terrain, options=options)


def _run_flight_disturbed(params: Params, state: TouchdownState, kind: Kind, d: np.ndarray,
                          placement: str, n_steps: int,
                          options: IntegratorOptions | None) -> BatchRun:
    """Stride 0 undisturbed; the change at lift-off or apex; flight; ``n_steps`` strides."""
    s0 = step(params, state, options=options)
    if not s0.ok:
        raise ValueError(f"the undisturbed stride 0 ended: {s0.reason}")
    lo = np.array([getattr(s0.liftoff, f) for f in ("x", "y", "xd", "yd", "phi", "phid")])
    P = pk.pack_params(params)
    O = (options or IntegratorOptions()).packed()  # noqa: E741 - kernels' name
    fs = np.empty(10)
    if placement == "apex":
        t_a = min(max(lo[3], 0.0) / params.g, s0.flight_time)
        # the leg's retraction clock keeps running (the apex clock starts at t_a) and a
        # retraction stop reached by t_a holds the leg there (stop_binds)
        ta = kn.retraction_start(P, lo[3])
        if _packed.stop_binds(P, lo[3], t_a):
            P[pk.P_ALPHA] = kn.stop_angle(P)
        else:
            P[pk.P_ALPHA] += P[pk.P_OMEGA] * max(t_a - ta, 0.0)
        kn.flight_state(P, lo, t_a, fs)  # (the CoM part does not depend on alpha_r)
        lo = fs[:6].copy()
    tx, th = Terrain.flat(state.h).arrays()
    S = np.full((len(d), 7), np.nan)
    st0 = np.zeros(len(d), dtype=np.int64)
    res = np.empty(3)
    for i, di in enumerate(d):
        lo_i = lo.copy()
        lo_i[_FLIGHT_COLUMN[kind]] += di
        st0[i] = kn.find_touchdown(P, O, lo_i, tx, th, res)
        if st0[i] == Status.OK:
            kn.flight_state(P, lo_i, res[0], fs)
            S[i] = (fs[6], fs[4], fs[2], fs[3], fs[5], fs[0], res[1])
    n = len(d)
    n_done = np.zeros(n, dtype=np.int64)
    t_fall = np.full(n, np.nan)
    hist = np.full((n, int(n_steps) + 1, 7), np.nan)
    status = st0.copy()
    ok = st0 == Status.OK
    if ok.any():
        run = run_batch(params, S[ok], n_steps, options=options)
        n_done[ok], status[ok], t_fall[ok], hist[ok] = (run.n_done, run.status, run.t_fall,
                                                        run.touchdowns)
    return BatchRun(n_done, status, t_fall, hist)


def _check_kind(kind: str) -> None:
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")


def _check_placement(kind: str, placement: str) -> None:
    if placement not in PLACEMENTS:
        raise ValueError(f"placement must be one of {PLACEMENTS}, got {placement!r}")
    if placement != "touchdown" and kind == "step_down":
        raise ValueError(f"placement must be 'touchdown' for a step-down, got {placement!r}")
    if placement == "touchdown_hip" and kind != "pitch_rate":
        raise ValueError(f"placement 'touchdown_hip' is for kind 'pitch_rate', got {kind!r}")

def _touchdown_runner(gait: Gait, kind: Kind, placement: Placement, n_steps: int,
                      options: IntegratorOptions | None) -> Callable[[float], tuple[int, int]]:
    """``d -> (status, strides done)``: one run of :func:`run_disturbed` (touch-down placements).

    The same disturbed start and terrain as :func:`run_disturbed` builds for
    each row, run in the calling thread on arrays packed once
    (:func:`tslip.simulation._packed.run`), stopping at the first fall.
    """
    params, state = gait.params, gait.state
    P = pk.pack_params(params)
    O = (options or _DEFAULT_OPTIONS).packed()  # noqa: E741 - the kernels' name
    td0 = state.as_array()
    flat = Terrain.flat(0.0).arrays()
    xf = state.x + params.l0 * math.cos(state.beta) - params.r * math.sin(state.phi)
    hip = (params.r * math.cos(state.phi), params.r * math.sin(state.phi))

    def run_one(d: float) -> tuple[int, int]:
        td = td0.copy()
        tx, th = flat
        if placement == "touchdown_hip":
            td[2] += hip[0] * d
            td[3] += hip[1] * d
        if kind == "step_down":
            tx, th = Terrain.flat(state.h).shifted_after(xf, d).arrays()
        else:
            td[_SECTION_COLUMN[kind]] += d
        return _packed.run(P, O, td, n_steps, tx, th)

    return run_one
