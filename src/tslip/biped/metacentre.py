"""Metacentric pitch test of the biped (Section E.3.3, Figure E.4).

At a right touch-down the body pitch is changed by ``dtheta`` about the hip
with both legs kept fixed in the world (hip angles change by ``-dtheta``),
and the first right stance is run. Its ground reaction forces are reduced to
the same :class:`~tslip.gait.impulse.Impulse` as the TSLIP's (eqs 3.3 and
3.5), taken about the whole-body centre of mass, and summarised by the same
:func:`~tslip.gait.impulse.summarise_pitch_response`; the metacentric claim of
Section E.4.3 is that the change in the impulse's moment about the CoM
restores the pitch while its magnitude and direction hardly change.

Exact checks
------------
Gravity acts at the body CoMs and the actuators are internal, so over the
stance (from touch-down ``t_0`` to lift-off ``t_1``)

* ``I = p(t_1) - p(t_0) + (0, M g (t_1 - t_0))`` and
* ``int (p_f - c) x F dt = L_c(t_1) - L_c(t_0)``

with the momenta of :func:`~tslip.biped.dynamics.momentum`. The reported
``I`` and moment are these exact values; the quadrature of the recorded
forces (trapezoidal rule on the integrator's accepted steps) gives ``x_p``,
``y_p`` and the mean hip position, and its deviation from the exact values is
:attr:`Impulse.quadrature_error` (about 2e-5 at the thesis's tolerance 1e-8).
Simpson's rule is not used: the forces have kinks where the controller
switches phase (eq. E.29), and a parabola across a kink on the integrator's
uneven steps was off by 3e-4.

Sign conventions
----------------
x forward, z up (called ``y`` in :class:`Impulse`), moments counter-clockwise
positive. The biped's pitch ``theta_b`` is clockwise positive (eq. E.2), so a
restoring moment change has the sign of ``dtheta``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..gait.impulse import Impulse, PitchResponse, summarise_pitch_response
from .dynamics import foot_position, hip_position, momentum
from .parameters import BipedParams, BipedState
from .simulate import BipedOptions, simulate

__all__ = ["pitched_state", "biped_stance_impulse", "metacentric_test", "metacentric_table"]


def pitched_state(params: BipedParams, state: BipedState, dtheta: float) -> BipedState:
    """Rotate the trunk by ``dtheta`` about the hip with the legs fixed in the world.

    The hip stays where it is, both hip angles change by ``-dtheta`` so that
    the leg angles ``theta_b + theta_h`` (eq. E.3) are unchanged, and all
    velocities are kept (Section E.3.3).
    """
    q = state.q.copy()
    hip = hip_position(params, q)
    q[2] += dtheta
    q[5] -= dtheta
    q[8] -= dtheta
    q[:2] = hip - params.r_1 * np.array([math.sin(q[2]), math.cos(q[2])])
    return BipedState(q, state.qd.copy())


def biped_stance_impulse(params: BipedParams, state: BipedState, t0: float = 0.0,
                         options: BipedOptions | None = None) -> Impulse:
    """Ground reaction impulse of the right stance that starts at ``(t0, state)``.

    The forces of both feet are summed (a left foot still on the ground
    counts); the force samples are placed at their centre of pressure.

    Raises
    ------
    ValueError
        If the right foot does not lift off (a fall or integrator failure).
    """
    tr = simulate(params, state, 1, t0=t0, options=options)
    lo = [e.t for e in tr.events if e.kind == "liftoff_R"]
    if not lo:
        raise ValueError(f"the right stance did not end in a lift-off: {tr.status.reason}")
    t = tr.time
    rows = np.flatnonzero(t <= lo[0])
    rows = rows[np.r_[True, np.diff(t[rows]) > 0.0]]
    t = t[rows] - t[rows[0]]
    y = tr.data[rows, 1:19]
    fx = tr["Fx_R"][rows] + tr["Fx_L"][rows]
    fz = tr["Fz_R"][rows] + tr["Fz_L"][rows]
    mom = [momentum(params, yi) for yi in y]
    com = np.array([m[0] for m in mom])
    q = y[:, :9]
    feet = [foot_position(params, q, leg) - com for leg in (0, 1)]  # eq. E.8, rel. CoM
    fxs = (tr["Fx_R"][rows], tr["Fx_L"][rows])
    fzs = (tr["Fz_R"][rows], tr["Fz_L"][rows])
    moment = sum(r[:, 0] * fzk - r[:, 1] * fxk for r, fxk, fzk in zip(feet, fxs, fzs))
    w = np.where(fz != 0.0, fz, 1.0)
    x = (feet[0][:, 0] * fzs[0] + feet[1][:, 0] * fzs[1]) / w
    z = (feet[0][:, 1] * fzs[0] + feet[1][:, 1] * fzs[1]) / w
    one = np.abs(fzs[1]) == 0.0
    x[one], z[one] = feet[0][one, 0], feet[0][one, 1]
    hip = hip_position(params, q) - com

    def quad(f: np.ndarray) -> float:
        return float(np.trapezoid(f, t))

    ix_q, iz_q = quad(fx), quad(fz)
    sx = quad(sum(r[:, 0] * fzk for r, fzk in zip(feet, fzs)))
    sz = quad(sum(r[:, 1] * fxk for r, fxk in zip(feet, fxs)))
    dp = mom[-1][1] - mom[0][1]
    I_x, I_z = float(dp[0]), float(dp[1] + params.total_mass * params.g * t[-1])
    torque = mom[-1][2] - mom[0][2]
    err = max(abs(ix_q - I_x), abs(iz_q - I_z), abs(quad(moment) - torque))
    return Impulse(
        I_x=I_x, I_y=I_z, x_p=sx / iz_q, y_p=sz / ix_q if ix_q != 0.0 else math.nan,
        torque=float(torque), direction=math.atan2(I_z, I_x),
        hip_touchdown=(float(hip[0, 0]), float(hip[0, 1])),
        hip_liftoff=(float(hip[-1, 0]), float(hip[-1, 1])),
        hip_mean=(quad(hip[:, 0] * fz) / iz_q, quad(hip[:, 1] * fz) / iz_q),
        stance_time=float(t[-1]), quadrature_error=float(err),
        time=t, F_x=fx, F_y=fz, x=x, y=z, hip_x=hip[:, 0], hip_y=hip[:, 1],
        state=state, params=params,
    )


def metacentric_test(params: BipedParams, state: BipedState, t0: float = 0.0,
                     pitches: Sequence[float] = (0.0, 0.5, -0.5),
                     options: BipedOptions | None = None) -> PitchResponse:
    """Ground reaction impulses of the first right stance after pitch changes.

    Parameters
    ----------
    params : BipedParams
    state : BipedState
        State at a right touch-down (for example a periodic gait's section).
    t0 : float
        Its time (sets the controller phase).
    pitches : sequence of float
        Pitch changes ``dtheta`` [rad] (thesis: 0, +0.5, -0.5).
    options : BipedOptions, optional

    Returns
    -------
    PitchResponse
        ``restoring[i]`` is True when the change of the moment about the
        whole-body CoM opposes ``pitches[i]``; ``hip_distance`` is in units
        of ``r_1``.

    Raises
    ------
    ValueError
        If a pitched stance ends in a fall instead of a lift-off.

    References
    ----------
    Thesis Section E.3.3 and Figure E.4; eqs 3.3 and 3.5.
    """
    pitches = tuple(float(d) for d in pitches)
    imps = [biped_stance_impulse(params, pitched_state(params, state, d), t0, options)
            for d in pitches]
    nominal = next((i for d, i in zip(pitches, imps, strict=True) if d == 0.0), None)
    if nominal is None:
        nominal = biped_stance_impulse(params, state, t0, options)
    return summarise_pitch_response(pitches, imps, nominal, params.r_1, pitch_sign=-1.0)


def metacentric_table(response: PitchResponse) -> list[dict[str, float | bool | None]]:
    """One row per pitch change: the numbers behind Figure E.4.

    Columns: ``dtheta`` [rad]; impulse ``I_x``, ``I_z``, ``magnitude``
    [M g^1/2 L^1/2] and its change relative to the nominal stance;
    ``lean`` from vertical and its change [deg]; ``x_p`` [L] (eq. 3.5, rel.
    CoM); ``torque`` and its change ``dtorque`` about the CoM [M g^1/2 L^3/2,
    counter-clockwise]; ``restoring``; ``hip_distance`` [r_1];
    ``stance_time``; ``quadrature_error``.
    """
    nom = response.nominal
    rows = []
    for d, imp, rest, dist in zip(response.dphis, response.impulses, response.restoring,
                                  response.hip_distance, strict=True):
        rows.append({
            "dtheta": d, "I_x": imp.I_x, "I_z": imp.I_y, "magnitude": imp.magnitude,
            "magnitude_change": imp.magnitude / nom.magnitude - 1.0,
            "lean_deg": math.degrees(imp.lean),
            "lean_change_deg": math.degrees(imp.lean - nom.lean),
            "x_p": imp.x_p, "torque": imp.torque, "dtorque": imp.torque - nom.torque,
            "restoring": rest, "hip_distance": dist, "stance_time": imp.stance_time,
            "quadrature_error": imp.quadrature_error,
        })
    return rows
