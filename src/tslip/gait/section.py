"""The apex Poincare section: apex states, apex <-> touch-down, the apex return map.

The SLIP literature (Seyfarth et al. 2002; vibly) works on the apex of the
flight, where the CoM moves horizontally (``yd = 0``): the state there is
the apex height ``y`` above the ground, the horizontal speed ``xd``, the
pitch ``phi`` and pitch rate ``phid`` (:class:`ApexState`). The flight is
ballistic (eq. 2.7: only gravity acts, the pitch rate is constant, the leg
is massless), so apex and touch-down convert in closed form:

* :func:`touchdown_to_apex`: back along the parabola from a touch-down, with
  the CoM height at touch-down from eq. 2.9 (``y_m = h + l0 sin beta - r cos
  phi``) and the time since the apex ``T = -yd / g`` (eq. 3.11 is twice it
  for a symmetric flight);
* :func:`apex_to_touchdown`: forward to the first downward zero of the foot
  height of eq. 2.9. When the leg angle and the hip's offset stay fixed in
  the descent (the SLIP: ``leg_reset="global"`` and no retraction; or a
  level, non-rotating trunk) this is ``T = sqrt(2 (y - y_td) / g)``; otherwise
  the kernels' certified root of eq. 2.9 (``find_touchdown``) from the apex.

The leg angle at touch-down must follow from the apex state: the apex is a
Poincare section only when the retraction clock does not run from lift-off
(``omega_r = 0``, or retraction timed from the apex). A lift-off clock with
``omega_r != 0`` raises ``ValueError`` here.

The apex return map (:func:`apex_map`, :func:`apex_map_states`, and
:func:`apex_map_batch` at fixed total energy over apex heights and leg
angles) runs apex -> touch-down -> stance and flight (:func:`tslip.step_batch`'s
kernel) -> the apex after the lift-off, ``T = yd_LO / g`` later. A lift-off
moving down (``yd_LO < 0``), or a touch-down while still rising, leaves that
flight without an apex: :attr:`Status.NO_APEX`, an outcome that is neither a
fall nor an error (docs/conventions.md). Falls of the flight *after* the next
apex belong to the next application of the map.

Total energy (:func:`total_energy`): ``E = m (xd^2 + yd^2)/2 + J phid^2/2 + m g
(y_m - h)``, measured from the ground under the state, with no spring energy
(``l = l0`` in flight and at touch-down). It is conserved in flight, so the
apex and touch-down of one flight have the same energy.

API (stable; the viability analysis builds on it)::

    ApexState(y, xd, phi=0, phid=0, x=0, h=0)      # .section(), .from_energy(params, y, E)
    total_energy(params, state) -> float            # TouchdownState or ApexState
    touchdown_to_apex(params, td) -> ApexState
    apex_to_touchdown(params, apex) -> TouchdownState
    apex_map(params, apex, options=None) -> ApexStep            # one apex to the next
    apex_map_states(params, states, alpha_r=None, options=None) -> ApexBatch   # rows (n, 4|6)
    apex_map_batch(params, y, alpha_r=None, *, energy, phi=0, phid=0,
                   options=None) -> ApexBatch       # y, alpha_r broadcast; fixed energy

``alpha_r`` is the action: the leg angle set at lift-off, which is the
touch-down angle of the SLIP preset (global reset, no retraction).
"""

from __future__ import annotations

import math
from dataclasses import astuple, dataclass
from typing import NamedTuple

import numpy as np

from .._checks import check_number
from ..model import _pack as pk
from ..model.parameters import Params
from ..model.state import TouchdownState
from ..simulation.integrate import step_batch_packed
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status

__all__ = [
    "ApexState",
    "ApexStep",
    "ApexBatch",
    "APEX_NAMES",
    "total_energy",
    "touchdown_to_apex",
    "apex_to_touchdown",
    "apex_map",
    "apex_map_states",
    "apex_map_batch",
    "apex_section_ok",
    "touchdown_to_apex_jacobian",
    "apex_to_touchdown_jacobian",
]

#: Names of the 4-D apex-section vector, in order.
APEX_NAMES: tuple[str, ...] = ("y", "xd", "phi", "phid")

#: Statuses the kernels return only from the flight after lift-off (``find_touchdown``).
_FLIGHT_STATUSES = (pk.ST_FALL_NO_TOUCHDOWN, pk.ST_FALL_TRIP, pk.ST_ERR_FLIGHT_TIMEOUT)


@dataclass(frozen=True, slots=True)
class ApexState:
    """State at the apex of a flight (``yd = 0``).

    Parameters
    ----------
    y : float
        CoM height above the ground ``h`` [L].
    xd : float
        Horizontal CoM speed [g^1/2 L^1/2].
    phi : float
        Trunk pitch [rad].
    phid : float
        Pitch rate [rad g^1/2 L^-1/2].
    x : float
        CoM horizontal position [L].
    h : float
        Ground height [L].
    """

    y: float
    xd: float
    phi: float = 0.0
    phid: float = 0.0
    x: float = 0.0
    h: float = 0.0

    def __post_init__(self) -> None:
        for name, value in zip(("y", "xd", "phi", "phid", "x", "h"), astuple(self)):
            object.__setattr__(self, name, check_number(value, f"ApexState.{name}"))

    @classmethod
    def from_energy(cls, params: Params, y: float, energy: float, *, phi: float = 0.0,
                    phid: float = 0.0, x: float = 0.0, h: float = 0.0) -> ApexState:
        """The apex at height ``y`` with total energy ``energy`` [MgL] (forward speed)."""
        xd = _apex_speed(params, np.array([float(y)]), float(energy), float(phid))[0]
        return cls(y, float(xd), phi, phid, x, h)

    def section(self) -> np.ndarray:
        """The 4-D apex-section vector ``(y, xd, phi, phid)``."""
        return np.array([self.y, self.xd, self.phi, self.phid])

    def as_array(self) -> np.ndarray:
        """All six fields ``(y, xd, phi, phid, x, h)``."""
        return np.array(astuple(self), dtype=float)


def total_energy(params: Params, state: TouchdownState | ApexState) -> float:
    """Total mechanical energy of a flight or touch-down state [MgL] (module docstring).

    ``m (xd^2 + yd^2)/2 + J phid^2/2 + m g (y_m - h)`` with ``y_m - h`` the
    apex height, or ``l0 sin beta - r cos phi`` at touch-down (eq. 2.9).
    """
    p = params
    if isinstance(state, ApexState):
        return 0.5 * p.m * state.xd**2 + 0.5 * p.J * state.phid**2 + p.m * p.g * state.y
    if isinstance(state, TouchdownState):
        height = p.l0 * math.sin(state.beta) - p.r * math.cos(state.phi)
        return (0.5 * p.m * (state.xd**2 + state.yd**2) + 0.5 * p.J * state.phid**2
                + p.m * p.g * height)
    raise ValueError(f"state must be a TouchdownState or an ApexState, got {type(state).__name__}")


def touchdown_to_apex(params: Params, state: TouchdownState) -> ApexState:
    """The apex of the flight that ends in the touch-down ``state`` (closed form, eq. 2.7).

    The parabola's vertex ``T = -yd / g`` before the touch-down, the pitch
    turning at its constant rate: ``y = l0 sin beta - r cos phi + yd^2 / (2 g)``
    (eq. 2.9), ``phi_apex = phi - phid T``, ``x_apex = x - xd T``.

    Raises
    ------
    ValueError
        If ``state.yd > 0``: a touch-down while rising has no apex before it.
    """
    if state.yd > 0.0:
        raise ValueError(f"TouchdownState.yd must be <= 0 (moving down) for an apex before "
                         f"the touch-down, got {state.yd!r}")
    p = params
    T = -state.yd / p.g
    y = p.l0 * math.sin(state.beta) - p.r * math.cos(state.phi) + 0.5 * state.yd**2 / p.g
    return ApexState(y=y, xd=state.xd, phi=state.phi - state.phid * T, phid=state.phid,
                     x=state.x - state.xd * T, h=state.h)


def apex_section_ok(params: Params) -> bool:
    """Whether the touch-down leg angle follows from the apex state (the apex is a section).

    True without retraction (``omega_r = 0``) or with retraction timed from
    the apex (``retraction="apex"``); a retraction clock running from
    lift-off needs the time since lift-off.
    """
    return params.omega_r == 0.0 or params.retraction == "apex"


def _check_section(params: Params) -> None:
    if not apex_section_ok(params):
        raise ValueError(
            "the apex section needs the touch-down leg angle to follow from the apex state: "
            f"omega_r must be 0 with retraction from lift-off, got omega_r={params.omega_r!r} "
            "(retraction timed from the apex has no such limit)")


def apex_to_touchdown(params: Params, apex: ApexState,
                      options: IntegratorOptions | None = None) -> TouchdownState:
    """The touch-down that ends the descent from ``apex`` (eqs 2.7, 2.9).

    Closed form ``T = sqrt(2 (y - y_td) / g)`` with ``y_td = l0 sin beta - r
    cos phi`` when the leg angle ``beta`` and the hip offset stay fixed in the
    descent; otherwise the first downward zero of eq. 2.9 found by the
    kernels' certified search from the apex (module docstring).

    Raises
    ------
    ValueError
        If the apex is no Poincare section for ``params`` (:func:`apex_section_ok`),
        or the foot does not reach the ground before the hip (e.g. an apex
        lower than the touch-down height ``l0 sin beta``).
    """
    _check_section(params)
    A = apex.as_array()[None, :]
    P = pk.pack_params(params)[None, :]
    td, st, _ = _touchdowns(P, A, (options or IntegratorOptions()).packed())
    if st[0] != Status.OK:
        raise ValueError(f"no touch-down from this apex: {Status(int(st[0])).reason}")
    return TouchdownState(*td[0].tolist())


# ---------------------------------------------------------------------------
# vectorised pieces on packed rows
# ---------------------------------------------------------------------------


def _apex_speed(params: Params, y: np.ndarray, E: float, phid: float | np.ndarray
                ) -> np.ndarray:
    """Forward speed at apex height ``y`` and energy ``E`` (:func:`total_energy` solved for xd)."""
    p = params
    kin = E - p.m * p.g * y - 0.5 * p.J * np.asarray(phid) ** 2
    if np.any(kin < 0.0) or not np.all(np.isfinite(kin)):
        y_max = (E - 0.5 * p.J * float(np.max(np.asarray(phid) ** 2))) / (p.m * p.g)
        raise ValueError(f"apex height y must be in (-inf, {y_max:.6g}] L at energy "
                         f"{E:g} MgL (no kinetic energy left above), got max {float(np.max(y))!r}")
    return np.sqrt(2.0 * kin / p.m)


def _touchdowns(Ps: np.ndarray, A: np.ndarray, O: np.ndarray  # noqa: E741
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Touch-down rows (n, 7), status (n,) and descent time (n,) from apex rows ``A`` (eq. 2.9).

    Closed form where the leg angle and the hip offset are constant in the
    descent; elsewhere the kernel ``find_touchdown`` from the apex as its start.
    """
    n = len(A)
    y, xd, ph, phd, x, h = A.T
    g, r, l0, om, alpha = (Ps[:, k] for k in (pk.P_G, pk.P_R, pk.P_L0, pk.P_OMEGA, pk.P_ALPHA))
    glob = Ps[:, pk.P_GLOBAL] != 0.0
    beta_rate = np.where(glob, om, om - phd)
    closed = (beta_rate == 0.0) & ((r == 0.0) | (phd == 0.0))
    td = np.full((n, pk.NTD), np.nan)
    st = np.full(n, pk.ST_OK, dtype=np.int64)
    beta = np.where(glob, alpha, alpha - ph)  # t = 0 (constant where closed)
    y_td = l0 * np.sin(beta) - r * np.cos(ph)
    drop = y - y_td
    c = closed & (drop > 0.0) & (l0 * np.sin(beta) > 0.0)
    T = np.where(c, np.sqrt(np.where(c, 2.0 * drop / g, 0.0)), np.nan)
    td[c] = np.column_stack([beta, ph + phd * T, xd, -g * T, phd, x + xd * T, h])[c]
    st[closed & ~c] = pk.ST_FALL_NO_TOUCHDOWN  # the foot is not above the ground at the apex
    rows = np.flatnonzero(~closed)
    if rows.size:
        from ..simulation import _kernels as kn

        res, fs, lo = np.empty(3), np.empty(10), np.empty(6)
        tx = np.empty(0)
        for i in rows:
            lo[:] = (x[i], h[i] + y[i], xd[i], 0.0, ph[i], phd[i])
            th = np.array([h[i]])
            s = int(kn.find_touchdown(Ps[i], O, lo, tx, th, res))
            if s != pk.ST_OK:
                st[i] = s
                continue
            kn.flight_state(Ps[i], lo, res[0], fs)
            td[i] = (fs[6], fs[4], fs[2], fs[3], fs[5], fs[0], h[i])
            T[i] = res[0]
    return td, st, T


class ApexBatch(NamedTuple):
    """Result of the batched apex map: the next apex per row (NaN where not OK).

    Arrays have the shape of the input grid; ``status`` holds :class:`Status`
    codes (``Status.NO_APEX`` for a lift-off moving down).
    """

    y: np.ndarray  # next apex height above the ground [L]
    xd: np.ndarray  # its forward speed [g^1/2 L^1/2]
    phi: np.ndarray
    phid: np.ndarray
    x: np.ndarray  # its CoM x [L]
    status: np.ndarray
    stance_time: np.ndarray  # [g^-1/2 L^1/2]
    time: np.ndarray  # apex to apex [g^-1/2 L^1/2]

    def __repr__(self) -> str:
        codes, counts = np.unique(self.status, return_counts=True)
        what = ", ".join(f"{Status(int(c)).name} {int(k)}" for c, k in zip(codes, counts))
        return f"ApexBatch({self.status.size} rows; {what})"

    @property
    def ok(self) -> np.ndarray:
        """Rows that reached the next apex."""
        return self.status == Status.OK


class ApexStep(NamedTuple):
    """Result of :func:`apex_map`: one apex to the next."""

    apex: ApexState | None  # the next apex (None unless status is OK)
    status: Status
    touchdown: TouchdownState | None  # the touch-down on the way
    stance_time: float
    time: float  # apex to apex


def _map_rows(Ps: np.ndarray, A: np.ndarray, O: np.ndarray  # noqa: E741
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Apex map on packed rows: next apex rows (n, 6), status, touch-downs, stance time, time."""
    n = len(A)
    td, st, t_down = _touchdowns(Ps, A, O)
    nxt = np.full((n, 6), np.nan)
    ts = np.full(n, np.nan)
    tt = np.full(n, np.nan)
    go = np.flatnonzero(st == pk.ST_OK)
    if go.size == 0:
        return nxt, st, td, ts, tt
    TH = td[go, pk.TD_H][:, None]
    b = step_batch_packed(Ps[go], O, td[go], np.empty((go.size, 0)), TH)
    raw, s2 = b.raw, np.asarray(b.status)
    lo = raw[:, pk.OUT_LO : pk.OUT_LO + 6]
    g = Ps[go, pk.P_G]
    t_up = lo[:, 3] / g  # lift-off to apex
    lifted = (s2 == pk.ST_OK) | np.isin(s2, _FLIGHT_STATUSES)
    rising_td = (s2 == pk.ST_OK) & (raw[:, pk.OUT_TD + pk.TD_YD] > 0.0)
    early_fall = (s2 != pk.ST_OK) & (raw[:, pk.OUT_TF] < t_up)  # a flight fall before the apex
    no_apex = lifted & ((lo[:, 3] < 0.0) | rising_td)
    ok = lifted & ~no_apex & ~early_fall
    out_st = np.where(ok, pk.ST_OK, np.where(no_apex, pk.ST_NO_APEX, s2))
    st[go] = out_st
    h = td[go, pk.TD_H]
    T = np.where(ok, t_up, np.nan)
    rows = np.column_stack([lo[:, 1] + 0.5 * lo[:, 3] * T - h,  # y + yd T - g T^2/2, T = yd/g
                            lo[:, 2], lo[:, 4] + lo[:, 5] * T, lo[:, 5], lo[:, 0] + lo[:, 2] * T,
                            h])
    nxt[go] = np.where(ok[:, None], rows, np.nan)
    ts[go] = raw[:, pk.OUT_TS]
    tt[go] = np.where(ok, t_down[go] + raw[:, pk.OUT_TS] + T, np.nan)
    return nxt, st, td, ts, tt


def _batch(nxt: np.ndarray, st: np.ndarray, ts: np.ndarray, tt: np.ndarray,
           shape: tuple[int, ...]) -> ApexBatch:
    y, xd, phi, phid, x = (nxt[:, k].reshape(shape) for k in range(5))
    return ApexBatch(y, xd, phi, phid, x, st.reshape(shape), ts.reshape(shape),
                     tt.reshape(shape))


def _rows_params(params: Params, alpha_r: np.ndarray | None, n: int) -> np.ndarray:
    Ps = np.tile(pk.pack_params(params), (n, 1))
    if alpha_r is not None:
        Ps[:, pk.P_ALPHA] = alpha_r
    return Ps


def apex_map(params: Params, apex: ApexState,
             options: IntegratorOptions | None = None) -> ApexStep:
    """One application of the apex return map: ``apex`` to the apex after the next lift-off.

    Parameters
    ----------
    params : Params
        Model; the leg angle law must make the apex a section (:func:`apex_section_ok`).
    apex : ApexState
    options : IntegratorOptions, optional
        Stance integration (default: dopri5 at 1e-8, the thesis's; gait analyses use 1e-12).

    Returns
    -------
    ApexStep
        ``status`` is a fall of the descent (``FALL_NO_TOUCHDOWN``) or the
        stance, ``NO_APEX`` for a lift-off moving down, or ``OK``.

    Examples
    --------
    >>> import tslip
    >>> from tslip.gait.section import ApexState, apex_map, total_energy
    >>> p = tslip.preset("slip")
    >>> a = ApexState.from_energy(p, 1.0, 2.2)
    >>> s = apex_map(p, a)
    >>> s.status.name, abs(total_energy(p, s.apex) - 2.2) < 1e-5
    ('OK', True)
    """
    _check_section(params)
    O = (options or IntegratorOptions()).packed()  # noqa: E741
    nxt, st, td, ts, tt = _map_rows(_rows_params(params, None, 1), apex.as_array()[None, :], O)
    status = Status(int(st[0]))
    return ApexStep(
        apex=ApexState(*nxt[0].tolist()) if status == Status.OK else None,
        status=status,
        touchdown=TouchdownState(*td[0].tolist()) if np.all(np.isfinite(td[0])) else None,
        stance_time=float(ts[0]), time=float(tt[0]),
    )


def apex_map_states(params: Params, states: np.ndarray, alpha_r: np.ndarray | None = None,
                    *, options: IntegratorOptions | None = None) -> ApexBatch:
    """The apex map for each row of ``states``: (n, 4) ``(y, xd, phi, phid)`` or (n, 6).

    ``alpha_r`` (optional, shape (n,)) sets each row's leg angle parameter.
    One compiled batch for the stances (:func:`tslip.step_batch`'s kernel).
    """
    _check_section(params)
    S = np.atleast_2d(np.asarray(states, dtype=float))
    if S.ndim != 2 or S.shape[1] not in (4, 6):
        raise ValueError(f"states must have shape (n, 4) or (n, 6), got {S.shape}")
    if S.shape[1] == 4:
        S = np.hstack([S, np.zeros((len(S), 2))])
    if not np.all(np.isfinite(S)):
        raise ValueError("states must be finite")
    a = None
    if alpha_r is not None:
        a = np.asarray(alpha_r, dtype=float).ravel()
        if a.shape != (len(S),) or not np.all(np.isfinite(a)):
            raise ValueError(f"alpha_r must be {len(S)} finite numbers, got shape {a.shape}")
    O = (options or IntegratorOptions()).packed()  # noqa: E741
    nxt, st, _, ts, tt = _map_rows(_rows_params(params, a, len(S)), S, O)
    return _batch(nxt, st, ts, tt, (len(S),))


def apex_map_batch(params: Params, y: np.ndarray | float, alpha_r: np.ndarray | float | None = None,
                   *, energy: float, phi: float = 0.0, phid: float = 0.0,
                   options: IntegratorOptions | None = None) -> ApexBatch:
    """The apex map at fixed total energy over apex heights and leg angles, in one batch.

    Parameters
    ----------
    params : Params
        Model (e.g. ``preset("slip")``).
    y : array_like
        Apex heights above the ground [L].
    alpha_r : array_like, optional
        Leg angle parameter per cell [rad] (the action: the touch-down angle
        of the SLIP preset); broadcast against ``y`` (pass a meshgrid, or
        ``y[:, None]`` and ``alpha_r[None, :]`` for a grid). Default
        ``params.alpha_r``.
    energy : float
        Total energy [MgL] (:func:`total_energy`); the forward speed at each apex
        follows from it. A height with no kinetic energy left is an error.
    phi, phid : float
        Pitch and pitch rate at the apex.
    options : IntegratorOptions, optional

    Returns
    -------
    ApexBatch
        Arrays of the broadcast shape of ``y`` and ``alpha_r``.
    """
    _check_section(params)
    E = check_number(energy, "energy", unit="MgL")
    yb = np.asarray(y, dtype=float)
    ab = np.asarray(params.alpha_r if alpha_r is None else alpha_r, dtype=float)
    yb, ab = np.broadcast_arrays(yb, ab)
    shape = yb.shape
    yf, af = yb.ravel(), ab.ravel()
    if not (np.all(np.isfinite(yf)) and np.all(np.isfinite(af))):
        raise ValueError("y and alpha_r must be finite")
    xd = _apex_speed(params, yf, E, phid)
    n = yf.size
    S = np.column_stack([yf, xd, np.full(n, float(phi)), np.full(n, float(phid)),
                         np.zeros(n), np.zeros(n)])
    O = (options or IntegratorOptions()).packed()  # noqa: E741
    nxt, st, _, ts, tt = _map_rows(_rows_params(params, af, n), S, O)
    return _batch(nxt, st, ts, tt, shape)


# ---------------------------------------------------------------------------
# derivatives of the conversions (the apex multipliers, tslip.gait.floquet)
# ---------------------------------------------------------------------------


def touchdown_to_apex_jacobian(params: Params, state: TouchdownState) -> np.ndarray:
    """``d(y, xd, phi, phid)_apex / d(beta, phi, xd, yd, phid)_td`` (4 x 5), of
    :func:`touchdown_to_apex`: ``y = l0 sin beta - r cos phi + yd^2/(2g)``,
    ``phi_apex = phi + phid yd / g``."""
    p = params
    D = np.zeros((4, 5))
    D[0, 0] = p.l0 * math.cos(state.beta)
    D[0, 1] = p.r * math.sin(state.phi)
    D[0, 3] = state.yd / p.g
    D[1, 2] = 1.0
    D[2, 1] = 1.0
    D[2, 3] = state.phid / p.g
    D[2, 4] = state.yd / p.g
    D[3, 4] = 1.0
    return D


def apex_to_touchdown_jacobian(params: Params, apex: ApexState,
                               state: TouchdownState) -> np.ndarray:
    """``d(beta, phi, xd, yd, phid)_td / d(y, xd, phi, phid)_apex`` (5 x 4) of
    :func:`apex_to_touchdown`, ``state`` being its touch-down.

    The descent time ``T`` solves eq. 2.9, ``F(T, a) = y - g T^2/2 + r cos(phi +
    phid T) - l0 sin beta(T, a) = 0`` with ``beta = alpha_r + omega T`` (``- phi(T)``
    for the local reset; ``omega = omega_r`` only with retraction from the
    apex), so ``dT/da = -F_a / F_T`` (implicit function theorem).
    """
    _check_section(params)
    p = params
    local = p.leg_reset == "local"
    T = -state.yd / p.g
    om = p.omega_r  # 0 unless the retraction runs from the apex (_check_section)
    ph_t = apex.phi + apex.phid * T
    b = state.beta
    cb, sph = math.cos(b), math.sin(ph_t)
    # partial derivatives of beta(T, a) and F(T, a) over a = (y, xd, phi, phid)
    db_dT = om - (apex.phid if local else 0.0)
    db_da = np.array([0.0, 0.0, -1.0 if local else 0.0, -T if local else 0.0])
    F_T = -p.g * T - p.r * sph * apex.phid - p.l0 * cb * db_dT  # the foot's vertical speed
    F_a = np.array([1.0, 0.0, -p.r * sph, -p.r * sph * T]) - p.l0 * cb * db_da
    dT = -F_a / F_T
    D = np.zeros((5, 4))
    D[0] = db_da + db_dT * dT
    D[1] = np.array([0.0, 0.0, 1.0, T]) + apex.phid * dT
    D[2, 1] = 1.0
    D[3] = -p.g * dT
    D[4, 3] = 1.0
    return D
