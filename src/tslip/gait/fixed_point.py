"""Periodic gaits: fixed points of the touch-down map (thesis Section 2.8).

Unknowns (CONVENTIONS.md): the touch-down velocity angle ``delta``, pitch
``phi``, pitch rate ``phid`` and the leg reset angle ``alpha_r``, plus
``alphad_ref`` (local velocity control) or ``tau_c`` (constant torque);
``v0`` and ``beta0`` are fixed. The residual is the next touch-down's
``(beta, phi, phid, delta, v)`` minus ``(beta0, phi, phid, delta, v0)``.

This module solves it by Levenberg-Marquardt least squares on the map with
finite differences, from automatic starting guesses.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from ..model.controllers import ConstantTorque, GlobalPD, LocalVelocity
from ..model.parameters import Params
from ..model.state import TouchdownState
from ..simulation.integrate import step_map
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status

__all__ = ["Gait", "find_gait", "gait_residual"]

_FALL_PENALTY = 10.0


@dataclass(frozen=True, slots=True)
class Gait:
    """A periodic gait (fixed point of the touch-down map).

    Attributes
    ----------
    state : TouchdownState
        The touch-down state of the gait.
    params : Params
        Parameters with ``alpha_r`` (and the controller's ``alphad_ref`` or
        ``tau_c``) set to the solved values.
    residual : float
        Max-norm of the periodicity residual.
    stance_time, flight_time : float
    converged : bool
        ``residual <= tol``.
    message : str
    """

    state: TouchdownState
    params: Params
    residual: float
    stance_time: float
    flight_time: float
    converged: bool
    message: str


def _unknown_names(params: Params) -> list[str]:
    names = ["delta", "phi", "phid", "alpha_r"]
    if isinstance(params.controller, LocalVelocity):
        names.append("alphad_ref")
    elif isinstance(params.controller, ConstantTorque) and (
        params.c_l > 0 or params.controller.c_h > 0
    ):
        names.append("tau_c")
    return names


def _apply(params: Params, names: list[str], z: np.ndarray) -> tuple[Params, TouchdownState]:
    values = dict(zip(names, map(float, z)))
    p = dataclasses.replace(params, alpha_r=values["alpha_r"])
    if "alphad_ref" in values:
        p = dataclasses.replace(
            p, controller=dataclasses.replace(p.controller, alphad_ref=values["alphad_ref"])
        )
    if "tau_c" in values:
        ctrl = dataclasses.replace(p.controller, tau_c=values["tau_c"])
        p = dataclasses.replace(p, controller=ctrl)
    s = TouchdownState.from_velocity(
        v=p.v0, delta=values["delta"], beta=p.beta0, phi=values["phi"], phid=values["phid"]
    )
    return p, s


def gait_residual(params: Params, state: TouchdownState,
                  options: IntegratorOptions | None = None) -> tuple[np.ndarray, float, float]:
    """Periodicity residual ``(beta, phi, phid, delta, v)`` of one stride.

    Returns ``(residual, stance_time, flight_time)``; after a fall the
    residual is a constant penalty vector.
    """
    q = state.section()
    res = step_map(params, q, h=0.0, options=options)
    if res.status != Status.OK:
        return np.full(5, _FALL_PENALTY), res.stance_time, res.flight_time
    b, ph, xd, yd, phd = res.q
    r = np.array([
        b - params.beta0,
        ph - state.phi,
        phd - state.phid,
        math.atan2(yd, xd) - state.delta,
        math.hypot(xd, yd) - params.v0,
    ])
    return r, res.stance_time, res.flight_time


def _guesses(params: Params, names: list[str]) -> list[np.ndarray]:
    out = []
    for delta in (-0.05, -0.12, -0.25, -0.4, -0.02):
        tf = 2.0 * params.v0 * math.sin(-delta) / params.g
        z = [delta, 0.0, 0.0, params.beta0 - params.omega_r * tf]
        if params.leg_reset == "global":
            z[3] = params.beta0 - params.omega_r * tf
        if "alphad_ref" in names:
            ts = 2.0 * params.l0 * (math.pi / 2 - params.beta0) / params.v0
            z.append((math.pi - 2 * params.beta0) / ts)
        if "tau_c" in names:
            z.append(0.1)
        out.append(np.array(z))
    return out


def find_gait(
    params: Params,
    *,
    v0: float | None = None,
    beta0: float | None = None,
    guess: np.ndarray | None = None,
    tol: float = 1e-10,
    options: IntegratorOptions | None = None,
) -> Gait:
    """Find a periodic gait at the nominal speed ``v0`` and angle ``beta0``.

    Parameters
    ----------
    params : Params
        Model; ``params.v0`` and ``params.beta0`` are used unless overridden.
    v0, beta0 : float, optional
        Override the nominal speed and touch-down angle.
    guess : ndarray, optional
        Starting unknowns ``(delta, phi, phid, alpha_r[, alphad_ref | tau_c])``;
        by default several automatic guesses are tried.
    tol : float
        Max-norm residual for ``converged``.
    options : IntegratorOptions, optional
        Defaults to tolerance 1e-12 so the residual can reach ``tol``.

    Returns
    -------
    Gait
        ``converged=False`` with the best residual when none was found (the
        global PD controller has one equation more than unknowns).
    """
    if v0 is not None or beta0 is not None:
        params = dataclasses.replace(
            params, v0=params.v0 if v0 is None else v0,
            beta0=params.beta0 if beta0 is None else beta0,
        )
    options = options or IntegratorOptions.tight()
    names = _unknown_names(params)

    def fun(z: np.ndarray) -> np.ndarray:
        p, s = _apply(params, names, z)
        return gait_residual(p, s, options)[0]

    best: tuple[float, np.ndarray] | None = None
    starts = [np.asarray(guess, dtype=float)] if guess is not None else _guesses(params, names)
    for z0 in starts:
        if len(z0) != len(names):
            raise ValueError(f"guess must have {len(names)} entries {names}, got {len(z0)}")
        try:
            sol = least_squares(fun, z0, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                                max_nfev=400 * len(names), diff_step=1e-7)
        except ValueError:
            continue
        err = float(np.max(np.abs(sol.fun)))
        if best is None or err < best[0]:
            best = (err, sol.x)
        if err <= tol:
            break
    if best is None:  # every start failed inside the solver
        z = starts[0]
        p, s = _apply(params, names, z)
        r, ts, tf = gait_residual(p, s, options)
        return Gait(state=s, params=p, residual=float(np.max(np.abs(r))), stance_time=ts,
                    flight_time=tf, converged=False,
                    message="no periodic gait found: the least-squares solver failed to start")
    err, z = best
    p, s = _apply(params, names, z)
    r, ts, tf = gait_residual(p, s, options)
    converged = bool(err <= tol)
    if converged:
        msg = f"periodic gait found, residual {err:.2e}"
    elif isinstance(params.controller, GlobalPD):
        msg = (f"no exact fixed point: global PD has more equations than unknowns; "
               f"best residual {err:.2e}")
    else:
        msg = f"no periodic gait found; best residual {err:.2e}"
    return Gait(state=s, params=p, residual=err, stance_time=ts, flight_time=tf,
                converged=converged, message=msg)



