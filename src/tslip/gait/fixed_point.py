"""Periodic gaits: fixed points of the touch-down map (thesis Section 2.8).

Unknowns (docs/conventions.md): the touch-down velocity angle ``delta``, pitch
``phi``, pitch rate ``phid`` and the leg reset angle ``alpha_r``, plus
``alphad_ref`` (local velocity control) or ``tau_c`` (constant torque with
damping); ``v0`` and ``beta0`` are fixed. The residual is the next
touch-down's ``(beta, phi, phid, delta, v)`` minus ``(beta0, phi, phid,
delta, v0)``.

:class:`GaitProblem` states the search as pure functions of the free
variables ``z``: the residual, the thesis's cost ``C1`` (eq. 2.20) and the
two-stage cost ``C`` (eqs 2.21-2.22) within bounds (eqs 2.23-2.24). Two
searches work on it, both outside the simulation:

* ``method="newton"`` (default): damped Newton on the residual with its
  exact Jacobian (variational equations, :meth:`GaitProblem.residual_jacobian`),
  from automatic starting guesses, stopping at the requested residual; where
  Newton fails from a start, Levenberg-Marquardt least squares with finite
  differences takes over from the same start. The problem is packed once
  per call (:mod:`tslip.simulation._packed`), so a residual costs about one
  compiled stride. It reaches the exact fixed point in a few milliseconds.
* ``method="cma"``: the thesis's own method, CMA-ES (Hansen's ``cma``
  package) on eq. 2.22. It returns a *near*-fixed point, ``C1 < 1e-4``,
  with the smallest non-trivial Floquet multiplier it found there; by
  default a Newton polish then takes it to the exact fixed point nearby.

The thesis's fixed points were approximate to ``C1 < 1e-4`` (a residual
norm up to 1e-2), and CMA-ES pushes them to the edge of that ball where the
multiplier is smallest: on Table 2.1 it reports 0.9855 where the exact fixed
point has 0.9944, and it moves the mass-offset stability limit from
r = 0.849 (exact) to about 0.92. Multipliers near 1 from the thesis can
therefore differ in the second or third decimal from the exact ones.
``C1`` here is eq. 2.20 on the 5-D section residual above.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import time
import warnings
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from scipy.optimize import least_squares

from ..model import _pack as pk
from ..model.controllers import ConstantTorque, GlobalPD, LocalVelocity
from ..model.parameters import Params
from ..model.state import TouchdownState
from ..simulation import _packed
from ..simulation.integrate import step_map
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status

__all__ = [
    "Gait",
    "GaitProblem",
    "CMAReport",
    "find_gait",
    "gait_residual",
    "newton_solve",
    "cma_minimize",
    "C1_THRESHOLD",
    "C1_OFFSET",
]

Method = Literal["newton", "cma"]

#: ``epsilon`` of eq. 2.22: switch from ``C1`` to ``C2`` below this.
C1_THRESHOLD = 1e-4
#: Offset added to ``C1`` in eq. 2.22 so it exceeds ``C2`` for ``|lambda| < 5``.
C1_OFFSET = 25.0

#: Default options of gait search and Floquet multipliers, built (and checked) once:
#: tolerance 1e-12 with DOP853.
TIGHT = IntegratorOptions.tight("dop853")

_FALL_PENALTY = 10.0
_MAX_STARTS = 13  # automatic guesses tried by Newton: the first 5 plus the 8 best of the scan
_TWO_PI = 2.0 * math.pi


@dataclass(frozen=True, slots=True)
class CMAReport:
    """What the CMA-ES search of eq. 2.22 found, before any polish.

    Attributes
    ----------
    seed : int
        Seed of the run; the same seed reproduces it exactly.
    evaluations, iterations : int
        Cost evaluations and CMA-ES generations used.
    z : tuple of float
        Best free variables ``(delta, phi, phid, alpha_r[, alphad_ref | tau_c])``.
    c1 : float
        Eq. 2.20 at ``z``: squared periodicity residual [-].
    c2 : float
        Eq. 2.21 at ``z``: largest squared non-trivial multiplier magnitude,
        NaN when ``c1 >= C1_THRESHOLD``.
    cost : float
        Eq. 2.22 at ``z``.
    stop : str
        Why CMA-ES stopped (its termination criteria).
    seconds : float
        Wall time of the CMA-ES run [s] (not compared by ``==``).
    """

    seed: int
    evaluations: int
    iterations: int
    z: tuple[float, ...]
    c1: float
    c2: float
    cost: float
    stop: str
    seconds: float = field(default=math.nan, compare=False)

    @property
    def max_nontrivial(self) -> float:
        """``sqrt(c2)``: the largest non-trivial multiplier magnitude at ``z``."""
        return math.sqrt(self.c2) if math.isfinite(self.c2) else math.nan


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
        Max-norm of the periodicity residual [-].
    stance_time, flight_time : float
        Durations of the stride's phases [g^-1/2 L^1/2].
    converged : bool
        ``residual <= tol``.
    message : str
        How the search went (both residuals for ``method="cma"``).
    method : {"newton", "cma"}
        The search that produced the gait.
    cma : CMAReport or None
        The CMA-ES result before polishing (``method="cma"`` only).
    """

    state: TouchdownState
    params: Params
    residual: float
    stance_time: float
    flight_time: float
    converged: bool
    message: str
    method: str = "newton"
    cma: CMAReport | None = None


# ---------------------------------------------------------------------------
# the problem: pure functions of the free variables
# ---------------------------------------------------------------------------


def _unknown_names(params: Params) -> tuple[str, ...]:
    names = ["delta", "phi", "phid", "alpha_r"]
    if isinstance(params.controller, LocalVelocity):
        names.append("alphad_ref")
    elif isinstance(params.controller, ConstantTorque) and (
        params.c_l > 0 or params.controller.c_h > 0
    ):
        names.append("tau_c")
    return tuple(names)


def gait_residual(params: Params, state: TouchdownState,
                  options: IntegratorOptions | None = None) -> tuple[np.ndarray, float, float]:
    """Periodicity residual ``(beta, phi, phid, delta, v)`` of one stride.

    Parameters
    ----------
    params : Params
        Model, with the gait's ``beta0`` and ``v0``.
    state : TouchdownState
        Candidate touch-down state.
    options : IntegratorOptions, optional
        Integrator settings.

    Returns
    -------
    residual : ndarray, shape (5,)
        Next touch-down's ``(beta, phi, phid, delta, v)`` minus
        ``(beta0, phi, phid, delta, v0)`` [rad, rad, rad g^1/2 L^-1/2, rad,
        g^1/2 L^1/2]; after a fall a constant penalty vector (10 each).
    stance_time, flight_time : float
        Phase durations [g^-1/2 L^1/2] (NaN after a fall in that phase).
    """
    q = state.section()
    res = step_map(params, q, h=0.0, options=options)
    out = np.full(pk.NOUT, math.nan)
    out[pk.OUT_TD : pk.OUT_TD + 5] = res.q
    out[pk.OUT_TS], out[pk.OUT_TF] = res.stance_time, res.flight_time
    return _section_residual(q, int(res.status), out, params)


def _section_residual(q: np.ndarray, status: int, out: np.ndarray,
                      params: Params) -> tuple[np.ndarray, float, float]:
    """:func:`gait_residual` of the stride from section ``q`` that filled ``out``."""
    ts, tf = float(out[pk.OUT_TS]), float(out[pk.OUT_TF])
    if status != Status.OK:
        return np.full(5, _FALL_PENALTY), ts, tf
    b, ph, xd, yd, phd = out[pk.OUT_TD : pk.OUT_TD + 5].tolist()
    r = np.array([
        b - params.beta0,
        ph - q[1],
        phd - q[4],
        math.atan2(yd, xd) - math.atan2(q[3], q[2]),
        math.hypot(xd, yd) - params.v0,
    ])
    return r, ts, tf


@dataclass(frozen=True, slots=True)
class GaitProblem:
    """The periodic-gait search of Section 2.8 as pure functions of ``z``.

    ``z = (delta, phi, phid, alpha_r[, alphad_ref | tau_c])``: touch-down
    velocity angle [rad], pitch [rad], pitch rate [rad g^1/2 L^-1/2], leg
    reset angle [rad], and the controller reference hip rate
    [rad g^1/2 L^-1/2] or constant torque [MgL].

    Parameters
    ----------
    params : Params
        Model with the gait's fixed ``v0`` and ``beta0``. ``alpha_r`` and the
        controller reference are overwritten by ``z``; a constant-torque
        controller without leg or hip damping gets ``tau_c = 0`` (energy
        balance, Section 2.4).
    options : IntegratorOptions
        Integrator settings for every stride.

    Examples
    --------
    >>> import tslip
    >>> prob = GaitProblem.from_params(tslip.preset("table2.1"))
    >>> prob.names
    ('delta', 'phi', 'phid', 'alpha_r')
    >>> g = find_gait(prob.params)
    >>> bool(prob.c1(prob.encode(g)) < 1e-20)
    True
    """

    params: Params
    options: IntegratorOptions
    names: tuple[str, ...] = ()
    # packed once (validation happened when params and options were built):
    # P with z's alpha_r and controller reference written in per evaluation
    _P: np.ndarray = field(init=False, repr=False, compare=False)
    _O: np.ndarray = field(init=False, repr=False, compare=False)
    _ref_gain: float = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not self.names:
            object.__setattr__(self, "names", _unknown_names(self.params))
        base = ("delta", "phi", "phid", "alpha_r")
        if self.names[:4] != base or not (
                len(self.names) == 4 or self.names[4:] in (("alphad_ref",), ("tau_c",))):
            raise ValueError(f"names must be {base} and at most one of 'alphad_ref', 'tau_c', "
                             f"got {self.names}")
        # as pack_params(decode(z)[0]) but for alpha_r and the reference, which
        # _stride writes in: tau = P[P_C0] + ..., P_C0 = Kd * alphad_ref (eq. 2.14)
        # or tau_c (eq. 2.15; 0 without damping, as in decode)
        P = pk.pack_params(self.params)
        ctrl = self.params.controller
        if isinstance(ctrl, ConstantTorque) and "tau_c" not in self.names:
            P[pk.P_C0] = 0.0
        object.__setattr__(self, "_P", P)
        object.__setattr__(self, "_O", self.options.packed())
        gain = getattr(ctrl, "Kd", 1.0) if "alphad_ref" in self.names else 1.0
        object.__setattr__(self, "_ref_gain", float(gain))

    @classmethod
    def from_params(cls, params: Params, options: IntegratorOptions | None = None) -> GaitProblem:
        """Problem for ``params``.

        Default options: tolerance 1e-12 with DOP853, which needs about a
        third of dopri5's right-hand sides there (``IntegratorOptions.tight``).
        """
        return cls(params=params, options=options or TIGHT)

    @property
    def size(self) -> int:
        """Number of free variables."""
        return len(self.names)

    # -- z <-> (params, state) ------------------------------------------------
    def decode(self, z: Sequence[float] | np.ndarray) -> tuple[Params, TouchdownState]:
        """Parameters and touch-down state for the free variables ``z``."""
        if len(z) != self.size:
            raise ValueError(f"guess must have {self.size} entries {list(self.names)}, "
                             f"got {len(z)}")
        values = dict(zip(self.names, map(float, z)))
        ctrl = self.params.controller
        if "alphad_ref" in values and isinstance(ctrl, LocalVelocity):  # (the name implies it)
            ctrl = dataclasses.replace(ctrl, alphad_ref=values["alphad_ref"])
        if "tau_c" in values and isinstance(ctrl, ConstantTorque):
            ctrl = dataclasses.replace(ctrl, tau_c=values["tau_c"])
        elif isinstance(ctrl, ConstantTorque) and ctrl.tau_c != 0.0:
            ctrl = dataclasses.replace(ctrl, tau_c=0.0)  # no damping: no torque
        p = dataclasses.replace(self.params, alpha_r=values["alpha_r"], controller=ctrl)
        s = TouchdownState.from_velocity(
            v=p.v0, delta=values["delta"], beta=p.beta0, phi=values["phi"], phid=values["phid"]
        )
        return p, s

    def encode(self, gait: Gait) -> np.ndarray:
        """Free variables of a gait (a warm start for nearby parameters)."""
        s, p = gait.state, gait.params
        out = {"delta": s.delta, "phi": s.phi, "phid": s.phid, "alpha_r": p.alpha_r,
               "alphad_ref": getattr(p.controller, "alphad_ref", math.nan),
               "tau_c": getattr(p.controller, "tau_c", math.nan)}
        z = np.array([out[n] for n in self.names], dtype=float)
        if not np.all(np.isfinite(z)):
            raise ValueError(f"the gait's controller has no {list(self.names)[-1]!r}")
        return z

    # -- costs ----------------------------------------------------------------
    def _stride(self, z: Sequence[float] | np.ndarray, jacobian: bool = False,
                ) -> tuple[np.ndarray, np.ndarray, int, np.ndarray, np.ndarray | None]:
        """``P``, section ``q`` and one stride at ``z`` on the packed arrays.

        Writes ``alpha_r`` and the controller reference of ``z`` into ``P``
        exactly as :meth:`decode` followed by ``pack_params`` would.
        """
        if len(z) != self.size:
            raise ValueError(f"guess must have {self.size} entries {list(self.names)}, "
                             f"got {len(z)}")
        zf = [float(v) for v in z]
        if not all(map(math.isfinite, zf)):
            raise ValueError(f"z must be finite, got {zf}")
        P = self._P.copy()
        P[pk.P_ALPHA] = zf[3]
        if self.size == 5:
            P[pk.P_C0] = self._ref_gain * zf[4]
        p = self.params
        delta = zf[0]
        q = np.array([p.beta0, zf[1], p.v0 * math.cos(delta), p.v0 * math.sin(delta), zf[2]])
        out = np.empty(pk.NOUT)
        if jacobian:
            J = np.empty((5, 5))
            return P, q, _packed.stride_jacobian(P, self._O, q, 0.0, J, out), out, J
        return P, q, _packed.stride_map(P, self._O, q, 0.0, out), out, None

    def evaluate(self, z: Sequence[float] | np.ndarray) -> tuple[np.ndarray, float, float]:
        """Residual, stance and flight time at ``z`` (see :func:`gait_residual`)."""
        _, q, st, out, _ = self._stride(z)
        return _section_residual(q, st, out, self.params)

    def residual_jacobian(self, z: Sequence[float] | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Residual (5,) and its Jacobian ``dr/dz`` (5 x size) at ``z``.

        The chain ``z -> q -> q' -> r``: ``dq'/dq`` exact from the variational
        equations (:func:`tslip.step_jacobian`), ``dq'/d alpha_r`` exact from
        the flight's touch-down time, ``dq'/d(alphad_ref | tau_c)`` by a
        central difference (the reference acts in stance, outside the
        variational equations). After a fall the Jacobian is NaN.
        """
        P, q, st, out, Jq = self._stride(z, jacobian=True)
        r, _, _ = _section_residual(q, st, out, self.params)
        n = self.size
        if st != Status.OK or Jq is None or not np.all(np.isfinite(Jq)):
            return r, np.full((5, n), math.nan)
        delta = float(z[0])
        v0 = self.params.v0
        dq = np.zeros((5, n))  # dq/dz, q = (beta0, phi, v0 cos delta, v0 sin delta, phid)
        dq[2, 0], dq[3, 0] = -v0 * math.sin(delta), v0 * math.cos(delta)
        dq[1, 1] = 1.0
        dq[4, 2] = 1.0
        dqn = Jq @ dq  # dq'/dz through the state
        dqn[:, 3] += _packed.alpha_r_column(P, out)
        if n == 5:
            ref = float(z[4])
            h = 1e-5 * max(1.0, abs(ref))
            cols = []
            for sgn in (1.0, -1.0):
                zz = np.array(z, dtype=float)
                zz[4] = ref + sgn * h
                _, _, s2, o2, _ = self._stride(zz)
                if s2 != Status.OK:
                    return r, np.full((5, n), math.nan)
                cols.append(o2[pk.OUT_TD : pk.OUT_TD + 5].copy())
            dqn[:, 4] += (cols[0] - cols[1]) / (2.0 * h)
        # r = (beta', phi' - phi, phid' - phid, atan2(yd', xd') - delta, |v'| - v0)
        _, _, xd, yd, _ = out[pk.OUT_TD : pk.OUT_TD + 5]
        v2 = xd * xd + yd * yd
        v = math.sqrt(v2)
        D = np.zeros((5, 5))  # dr/dq'
        D[0, 0] = D[1, 1] = D[2, 4] = 1.0
        D[3, 2], D[3, 3] = -yd / v2, xd / v2
        D[4, 2], D[4, 3] = xd / v, yd / v
        Jr = D @ dqn
        Jr[1, 1] -= 1.0
        Jr[2, 2] -= 1.0
        Jr[3, 0] -= 1.0
        return r, Jr

    def residual(self, z: Sequence[float] | np.ndarray) -> np.ndarray:
        """Periodicity residual (5,) at ``z``; the Newton search's function."""
        return self.evaluate(z)[0]

    def c1(self, z: Sequence[float] | np.ndarray) -> float:
        """Eq. 2.20: squared periodicity residual ``|r(z)|^2`` [-]."""
        r = self.residual(z)
        return float(r @ r)

    def c2(self, z: Sequence[float] | np.ndarray,
           jacobian: Literal["fd", "exact"] = "fd") -> float:
        """Eq. 2.21: largest squared non-trivial multiplier magnitude at ``z``.

        The structural multipliers (the energy's; the decoupled pitch's at
        ``r = 0``) are removed by :func:`~tslip.gait.stability.nontrivial_jacobian`.
        NaN when a perturbed stride falls.
        """
        from .stability import map_jacobian, nontrivial_jacobian

        p, s = self.decode(z)
        q = s.section()
        try:
            A = map_jacobian(p, q, method=jacobian, options=self.options)
        except ValueError:
            return math.nan
        if not np.all(np.isfinite(A)):
            return math.nan
        lam = np.linalg.eigvals(nontrivial_jacobian(p, q, A))
        return float(np.max(np.abs(lam)) ** 2) if lam.size else 0.0

    def cost(self, z: Sequence[float] | np.ndarray, *, eps: float = C1_THRESHOLD,
             offset: float = C1_OFFSET, jacobian: Literal["fd", "exact"] = "fd") -> float:
        """Eq. 2.22: ``C1 + offset`` if ``C1 > eps``, else ``C2``.

        Where ``C2`` cannot be evaluated (a perturbed stride falls) the
        candidate counts as not periodic, ``C1 + offset``.
        """
        c1 = self.c1(z)
        if c1 > eps:
            return c1 + offset
        c2 = self.c2(z, jacobian)
        return c2 if math.isfinite(c2) else c1 + offset

    # -- bounds and starting guesses -------------------------------------------
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds of ``z`` (eqs 2.23-2.24).

        ``delta`` in [-pi/2, 0] (landing while moving down), ``phi`` in
        [-pi/2, pi/2], ``phid`` in [-10, 10] rad g^1/2 L^-1/2, ``alpha_r`` in
        [-2 pi, 2 pi] (long flights retract the leg by more than pi),
        ``alphad_ref`` in [0, 5 v0/l0 + 10] rad g^1/2 L^-1/2 (positive in
        stance, docs/conventions.md; the nominal hip rate is about ``v0/l0``),
        ``|tau_c| <= 10 + 2 (c_l + c_h) v0 / l0`` MgL (the torque balances the
        dampers, about ``c_h v0 / l0`` at the hip). They span every gait found
        over the thesis's parameter ranges (Sections 3.4-3.7) and keep CMA-ES
        away from strides that cannot be integrated.
        """
        p = self.params
        tau_max = 10.0 + 2.0 * (p.c_l + getattr(p.controller, "c_h", 0.0)) * p.v0 / p.l0
        lo = {"delta": -math.pi / 2, "phi": -math.pi / 2, "phid": -10.0, "alpha_r": -_TWO_PI,
              "alphad_ref": 0.0, "tau_c": -tau_max}
        hi = {"delta": 0.0, "phi": math.pi / 2, "phid": 10.0, "alpha_r": _TWO_PI,
              "alphad_ref": 5.0 * p.v0 / p.l0 + 10.0, "tau_c": tau_max}
        return (np.array([lo[n] for n in self.names]), np.array([hi[n] for n in self.names]))

    def scales(self) -> np.ndarray:
        """Initial CMA-ES standard deviation of each free variable.

        0.2 rad for ``delta`` and ``phi``, 0.5 for ``phid`` and ``alpha_r``,
        ``0.5 max(1, v0/l0)`` for ``alphad_ref`` and ``0.2 (1 + (c_l + c_h)
        v0/l0)`` for ``tau_c``: wide enough to leave the basin of a poor
        starting guess (smaller steps often stalled at ``C1 ~ 1e-2``).
        """
        p = self.params
        damping = (p.c_l + getattr(p.controller, "c_h", 0.0)) * p.v0 / p.l0
        s = {"delta": 0.2, "phi": 0.2, "phid": 0.5, "alpha_r": 0.5,
             "alphad_ref": 0.5 * max(1.0, p.v0 / p.l0), "tau_c": 0.2 * (1.0 + damping)}
        return np.array([s[n] for n in self.names])

    def guesses(self) -> Iterator[np.ndarray]:
        """Automatic starting points, most likely first (lazily).

        The first five are the original list (``delta`` from -0.05 to -0.4,
        level trunk, ``alpha_r`` from the symmetric flight time of eq. 3.11
        and the retraction of eq. 2.17). Then a scan: ``delta`` on a grid
        from -0.005 to -1.2 with ``alpha_r`` offsets of +-0.15 rad and
        controller references from an energy balance (x0.5, x1, x2), ranked
        by ``C1`` after one stride each; candidates that fall are dropped.
        """
        first = (-0.05, -0.12, -0.25, -0.4, -0.02)
        for d in first:
            yield self._guess(d)
        scored: list[tuple[float, int, np.ndarray]] = []
        for d in (-0.005, -0.01, -0.02, -0.035, -0.05, -0.075, -0.1, -0.15, -0.2, -0.3, -0.4,
                  -0.5, -0.65, -0.8, -1.0, -1.2):
            for da in (0.0, -0.15, 0.15):
                for f in ((1.0, 0.5, 2.0) if self.size == 5 else (1.0,)):
                    if d in first and da == 0.0 and f == 1.0:
                        continue  # already tried
                    z = self._guess(d, f)
                    z[3] += da
                    c1 = self.c1(z)
                    if math.isfinite(c1) and c1 < 5 * _FALL_PENALTY**2:
                        scored.append((c1, len(scored), z))
        scored.sort(key=lambda t: (t[0], t[1]))
        for _, _, z in scored:
            yield z

    def _guess(self, delta: float, factor: float = 1.0) -> np.ndarray:
        p = self.params
        tf = 2.0 * p.v0 * math.sin(-delta) / p.g  # eq. 3.11, symmetric stance
        z = [delta, 0.0, 0.0, p.beta0 - p.omega_r * tf]  # eq. 2.17 with phi = 0
        ts = 2.0 * p.l0 * (math.pi / 2 - p.beta0) / p.v0  # eq. 3.10
        if "alphad_ref" in self.names:
            z.append(factor * (math.pi - 2 * p.beta0) / ts)
        if "tau_c" in self.names:
            # energy balance: tau_c * (pi - 2 beta0) = dissipated energy, with
            # ldot(t) = ldot0 cos(pi t / ts) in the leg and alpha_dot = const
            # at the hip
            dalpha = max(math.pi - 2 * p.beta0, 0.1)
            ldot0 = p.v0 * math.cos(p.beta0 + delta)
            c_h = p.controller.c_h if isinstance(p.controller, ConstantTorque) else 0.0
            loss = p.c_l * ldot0**2 * ts / 2 + c_h * dalpha**2 / ts
            z.append(0.1 if loss == 0 else factor * loss / dalpha)
        return np.array(z)


# ---------------------------------------------------------------------------
# searches: they see only pure functions of z
# ---------------------------------------------------------------------------


def newton_solve(
    residual: Callable[[np.ndarray], np.ndarray],
    starts: Iterable[np.ndarray],
    *,
    tol: float = 1e-10,
    max_starts: int | None = None,
    jacobian: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None,
) -> tuple[np.ndarray | None, float, int]:
    """Solve ``residual(z) = 0`` from each start: Newton, then least squares.

    Parameters
    ----------
    residual : callable
        Pure function ``z -> r(z)``, shape (n_eq,).
    starts : iterable of ndarray
        Starting points, tried in order until one reaches ``tol``.
    tol : float
        Max-norm residual that counts as solved.
    max_starts : int, optional
        Try at most this many starts.
    jacobian : callable, optional
        ``z -> (r(z), dr/dz)``. With it and as many equations as unknowns,
        each start first runs a damped Newton iteration (:func:`_newton`)
        that stops as soon as the residual reaches ``tol``; where it fails,
        the start falls back to Levenberg-Marquardt least squares with
        finite differences (``scipy.optimize.least_squares``, tolerances
        1e-15), the only method used without ``jacobian``. A start where
        Newton stalls (no step of at least ``_NEWTON_MIN_STEP`` lowers
        ``|r|``) with ``max|r|`` above :data:`STALL_GIVE_UP` is given up
        without least squares: it sits at a local minimum of ``|r|`` that
        is not a root.

    Returns
    -------
    z : ndarray or None
        Best point found (None if the solver failed on every start).
    err : float
        Its max-norm residual (inf if none).
    n_starts : int
        Starts tried.
    """
    best: tuple[float, np.ndarray] | None = None
    n = 0
    for z0 in starts:
        if max_starts is not None and n >= max_starts:
            break
        n += 1
        z0 = np.asarray(z0, dtype=float)
        if jacobian is not None:
            z, err = _newton(residual, jacobian, z0, tol)
            if z is not None and err <= tol:
                return z, err, n
            if z is not None and err > STALL_GIVE_UP:  # stalled far from a root: next start
                if best is None or err < best[0]:
                    best = (err, z)
                continue
        try:
            sol = least_squares(residual, z0, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                                max_nfev=400 * len(z0), diff_step=1e-7)
        except ValueError:
            continue
        err = float(np.max(np.abs(sol.fun)))
        if best is None or err < best[0]:
            best = (err, sol.x)
        if err <= tol:
            break
    if best is None:
        return None, math.inf, n
    return best[1], best[0], n


_NEWTON_MAX_ITER = 25
_NEWTON_MIN_STEP = 1.0 / 64
#: Max-norm residual above which a start where Newton stalls is given up without least
#: squares (:func:`newton_solve`). Over every point of the thesis studies (``tslip
#: reproduce``, quick and full: 1557 stalled starts) Newton stalled only at residuals of
#: 1.4e-4 or more, and least squares from those starts never reached a gait (it ended at
#: about half the stalled residual), at a third of the studies' solve time.
STALL_GIVE_UP = 1e-5


def _newton(residual: Callable[[np.ndarray], np.ndarray],
            fj: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], z0: np.ndarray,
            tol: float) -> tuple[np.ndarray | None, float]:
    """Damped Newton on a square system; ``(z, max-norm residual)`` or ``(None, inf)``.

    Each iteration solves ``J dz = -r`` (least squares where ``J`` is
    singular, as at ``r = 0`` where the pitch is undetermined) and halves
    the step until ``|r|`` decreases (Armijo). It stops at ``max|r| <= tol``;
    unless the residual is already below ``tol / 100`` (the usual case, as
    convergence is quadratic) it takes one more step with the Jacobian at
    hand, kept only if it lowers the residual (one stride). It gives up
    after ``_NEWTON_MAX_ITER`` iterations or at a non-finite Jacobian (a
    fall), returning ``(None, inf)``, and at a step shorter than
    ``_NEWTON_MIN_STEP`` (a stall), returning the point reached and its
    residual (above ``tol``).
    """
    try:
        r, J = fj(z0)
    except ValueError:
        return None, math.inf
    z = z0
    nrm = float(np.linalg.norm(r))
    for it in range(_NEWTON_MAX_ITER + 1):
        if not (np.all(np.isfinite(J)) and math.isfinite(nrm)):
            return None, math.inf
        err = float(np.max(np.abs(r)))
        if err > tol and it == _NEWTON_MAX_ITER:
            return None, math.inf
        dz = np.linalg.lstsq(J, -r, rcond=None)[0]
        if err <= tol:
            if err <= 1e-2 * tol:  # done (the map's Jacobian at z is kept for floquet)
                return z, err
            try:  # one polishing step with the Jacobian at hand
                rp = residual(z + dz)
            except ValueError:
                return z, err
            errp = float(np.max(np.abs(rp)))
            return (z + dz, errp) if errp < err else (z, err)
        t = 1.0
        while True:
            zn = z + t * dz
            try:
                rn, Jn = fj(zn)
                nn = float(np.linalg.norm(rn))
            except ValueError:
                nn = math.inf
            if nn <= (1.0 - 1e-4 * t) * nrm:
                break
            t *= 0.5
            if t < _NEWTON_MIN_STEP:
                return z, err
        z, r, J, nrm = zn, rn, Jn, nn
    return None, math.inf  # not reached


def _cma_seed(seed: int) -> int:
    """A non-zero 32-bit seed for ``cma`` (which reads 0 as "use the clock")."""
    s = int(np.random.SeedSequence(seed).generate_state(1)[0])
    return s or 1


def cma_minimize(
    cost: Callable[[np.ndarray], float],
    x0: np.ndarray,
    *,
    sigma0: float = 1.0,
    stds: np.ndarray | None = None,
    lower: np.ndarray | None = None,
    upper: np.ndarray | None = None,
    seed: int = 1,
    max_evals: int = 3000,
    popsize: int | None = None,
) -> tuple[np.ndarray, float, int, int, str]:
    """Minimise ``cost`` with CMA-ES (``cma`` package, ask/tell), quietly.

    Parameters
    ----------
    cost : callable
        Pure function ``z -> float``.
    x0 : ndarray, shape (n,)
        Initial mean.
    sigma0 : float
        Initial step size, multiplied per coordinate by ``stds``.
    stds : ndarray, shape (n,), optional
        Per-coordinate scaling of ``sigma0``.
    lower, upper : ndarray, shape (n,), optional
        Box bounds (eqs 2.23-2.24), handled by ``cma``'s bound transform.
    seed : int
        Any non-negative integer; equal seeds give identical runs. The
        global NumPy random state is restored afterwards.
    max_evals : int
        Budget of cost evaluations.
    popsize : int, optional
        Population size (default ``4 + 3 ln n``).

    Returns
    -------
    x : ndarray
        Best point evaluated.
    f : float
        Its cost.
    evaluations, iterations : int
    stop : str
        Termination criteria that fired.

    References
    ----------
    N. Hansen, "The CMA Evolution Strategy: A Tutorial", arXiv:1604.00772.
    """
    import cma

    x0 = np.asarray(x0, dtype=float)
    opts: dict[str, Any] = {
        "seed": _cma_seed(seed), "verbose": -9, "verb_disp": 0, "verb_log": 0,
        "maxfevals": int(max_evals), "tolfun": 1e-13, "tolfunhist": 1e-14, "tolx": 1e-14,
        "tolflatfitness": 20,
    }
    if stds is not None:
        opts["CMA_stds"] = list(map(float, stds))
    if lower is not None or upper is not None:
        lo = None if lower is None else list(map(float, lower))
        hi = None if upper is None else list(map(float, upper))
        opts["bounds"] = [lo, hi]
    if popsize is not None:
        opts["popsize"] = int(popsize)
    # cma seeds and draws from NumPy's legacy global generator: put it back after
    state = np.random.get_state()  # noqa: NPY002
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", module=r"cma(\.|$)")
            es = cma.CMAEvolutionStrategy(x0, sigma0, opts)
            best_x, best_f = x0.copy(), math.inf
            while not es.stop():
                X = es.ask()
                F = [float(cost(np.asarray(x))) for x in X]
                es.tell(X, F)
                i = int(np.argmin(F))
                if F[i] < best_f:
                    best_x, best_f = np.array(X[i], dtype=float), F[i]
            stop = ", ".join(f"{k}={v}" for k, v in es.stop().items())
            return best_x, best_f, int(es.countevals), int(es.countiter), stop
    finally:
        np.random.set_state(state)  # noqa: NPY002


# ---------------------------------------------------------------------------
# the entry point
# ---------------------------------------------------------------------------


def _wrap(prob: GaitProblem, z: np.ndarray) -> np.ndarray:
    """Shift ``phi`` and ``alpha_r`` together by whole turns so ``phi`` is in (-pi, pi].

    The touch-down leg angle depends on ``alpha_r - phi`` only (local reset),
    so the gait is unchanged; this matters at ``r = 0``, where the pitch is
    undetermined and the solver may wander.
    """
    turns = math.floor((z[1] + math.pi) / _TWO_PI)
    if turns == 0 or prob.params.leg_reset != "local":
        return z
    z = z.copy()
    z[1] -= turns * _TWO_PI
    z[3] -= turns * _TWO_PI
    return z


def _make_gait(prob: GaitProblem, z: np.ndarray, tol: float, message: str,
               method: str = "newton", cma: CMAReport | None = None) -> Gait:
    p, s = prob.decode(z)
    r, ts, tf = prob.evaluate(z)
    err = float(np.max(np.abs(r)))
    return Gait(state=s, params=p, residual=err, stance_time=ts, flight_time=tf,
                converged=bool(err <= tol), message=message, method=method, cma=cma)


def _failure_reason(prob: GaitProblem, err: float, n_starts: int) -> str:
    if isinstance(prob.params.controller, GlobalPD):
        return (f"no exact fixed point: global PD has more equations than unknowns; "
                f"best residual {err:.2e}")
    return (f"no periodic gait found from {n_starts} starting guesses; best residual "
            f"{err:.2e} (the gait may not exist here, e.g. below the minimum speed or "
            f"past a fold of the branch)")


def _newton_gait(prob: GaitProblem, starts: Iterable[np.ndarray], tol: float,
                 max_starts: int | None) -> Gait:
    starts = iter(starts)
    first = next(starts)
    # global PD has more equations than unknowns and no exact fixed point: least squares only
    exact = not isinstance(prob.params.controller, GlobalPD)
    z, err, n = newton_solve(prob.residual, itertools.chain([first], starts), tol=tol,
                             max_starts=max_starts,
                             jacobian=prob.residual_jacobian if exact else None)
    if z is None:  # every start failed inside the solver
        g = _make_gait(prob, first, tol, "")
        return dataclasses.replace(
            g, converged=False,
            message="no periodic gait found: the least-squares solver failed to start")
    z = _wrap(prob, z)
    msg = (f"periodic gait found, residual {err:.2e}" if err <= tol
           else _failure_reason(prob, err, n))
    return _make_gait(prob, z, tol, msg)


def _cma_gait(prob: GaitProblem, starts: Iterable[np.ndarray], tol: float, seed: int | None,
              max_evals: int, polish: bool, jacobian: Literal["fd", "exact"]) -> Gait:
    if seed is None:
        seed = int(np.random.default_rng().integers(2**32))
    starts = list(starts)
    if len(starts) == 1:
        x0 = starts[0]
    else:  # the lowest C1 among the automatic guesses
        c1s = [prob.c1(z) for z in starts]
        x0 = starts[int(np.argmin(c1s))]
    lo, hi = prob.bounds()
    x0 = np.clip(x0, lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))
    t0 = time.perf_counter()
    x, f, nev, nit, stop = cma_minimize(
        lambda z: prob.cost(z, jacobian=jacobian), x0, stds=prob.scales(), lower=lo,
        upper=hi, seed=seed, max_evals=max_evals)
    seconds = time.perf_counter() - t0
    c1 = prob.c1(x)
    c2 = prob.c2(x, jacobian) if c1 <= C1_THRESHOLD else math.nan
    report = CMAReport(seed=seed, evaluations=nev, iterations=nit, z=tuple(map(float, x)),
                       c1=c1, c2=c2, cost=f, stop=stop, seconds=seconds)
    head = f"CMA-ES (seed {seed}, {nev} evaluations, {seconds:.2f} s): C1 {c1:.2e}"
    if c1 <= C1_THRESHOLD:
        head += f" < {C1_THRESHOLD:g}, max |lambda| {math.sqrt(c2):.6f}"
    else:
        head += f" > {C1_THRESHOLD:g}: no near-periodic point"
        if c1 < 10 * C1_THRESHOLD:
            head += (f" (if its multipliers exceed sqrt({C1_OFFSET:g}), eq. 2.22 ranks "
                     "non-periodic points first)")
    r_cma = float(np.max(np.abs(prob.residual(x))))
    head += f", residual {r_cma:.2e}"
    if not polish:
        return _make_gait(prob, x, tol, head, "cma", report)
    z, err, _ = newton_solve(prob.residual, [x], tol=tol, jacobian=prob.residual_jacobian)
    if z is None or err > r_cma:  # polishing did not help: keep the CMA-ES point
        return _make_gait(prob, x, tol, head + "; Newton polish failed", "cma", report)
    z = _wrap(prob, z)
    return _make_gait(prob, z, tol, head + f"; Newton polish: residual {err:.2e}", "cma",
                      report)


def find_gait(
    params: Params,
    *,
    v0: float | None = None,
    beta0: float | None = None,
    guess: np.ndarray | None = None,
    tol: float = 1e-10,
    options: IntegratorOptions | None = None,
    method: Method = "newton",
    seed: int | None = None,
    max_evals: int = 3000,
    polish: bool = True,
    jacobian: Literal["fd", "exact"] = "fd",
) -> Gait:
    """Find a periodic gait at the nominal speed ``v0`` and angle ``beta0``.

    Parameters
    ----------
    params : Params
        Model; ``params.v0`` and ``params.beta0`` are used unless overridden.
    v0, beta0 : float, optional
        Override the nominal speed [g^1/2 L^1/2] and touch-down angle [rad].
    guess : ndarray, optional
        Starting unknowns ``(delta, phi, phid, alpha_r[, alphad_ref | tau_c])``;
        by default the automatic guesses of :meth:`GaitProblem.guesses`.
    tol : float
        Max-norm residual for ``converged``.
    options : IntegratorOptions, optional
        Defaults to tolerance 1e-12 with DOP853 so the residual can reach ``tol``.
    method : {"newton", "cma"}
        ``"newton"``: Newton on the residual (exact fixed point), with
        Levenberg-Marquardt as the fallback from each start.
        ``"cma"``: CMA-ES on the two-stage cost of eqs 2.20-2.22, as in the
        thesis: it minimises the largest non-trivial multiplier among points
        with ``C1 < 1e-4``, so its result is a near-fixed point (reported in
        ``gait.cma``), then polished by Newton unless ``polish=False``. As in
        the thesis, the offset 25 of eq. 2.22 assumes ``|lambda| < 5``: for
        more unstable gaits CMA-ES stays just above ``C1 = 1e-4`` (the
        polish still finds the fixed point).
    seed : int, optional
        CMA-ES seed; the same seed gives the identical result. ``None`` draws
        one (reported in ``gait.cma.seed``).
    max_evals : int
        CMA-ES budget of cost evaluations (about 0.1 ms each for ``C1``,
        1 ms for ``C2``).
    polish : bool
        Newton-polish the CMA-ES result to the exact fixed point nearby.
    jacobian : {"fd", "exact"}
        Multipliers in ``C2``: central differences (eq. B.2, as the thesis)
        or the variational equations.

    Returns
    -------
    Gait
        ``converged=False`` with the best residual and the reason when no
        start reaches ``tol`` (the global PD controller has one equation more
        than unknowns; some parameters have no gait at all).

    Raises
    ------
    ValueError
        For a ``guess`` of the wrong length or an unknown ``method``.

    References
    ----------
    Thesis Section 2.8, eqs 2.19-2.24; docs/conventions.md "Poincare section and
    periodic gaits".

    Examples
    --------
    >>> import tslip
    >>> g = find_gait(tslip.preset("table2.1"))
    >>> g.converged, round(g.params.alpha_r, 4)
    (True, 0.7935)
    """
    if method not in ("newton", "cma"):
        raise ValueError(f"method must be 'newton' or 'cma', got {method!r}")
    if v0 is not None or beta0 is not None:
        params = dataclasses.replace(
            params, v0=params.v0 if v0 is None else v0,
            beta0=params.beta0 if beta0 is None else beta0,
        )
    prob = GaitProblem.from_params(params, options)
    if guess is not None:
        z0 = np.asarray(guess, dtype=float)
        if z0.shape != (prob.size,):
            raise ValueError(f"guess must have {prob.size} entries {list(prob.names)}, "
                             f"got {z0.size}")
        starts: Iterable[np.ndarray] = [z0]
    else:
        starts = prob.guesses()
    if method == "cma":
        if max_evals < 1:
            raise ValueError(f"max_evals must be >= 1, got {max_evals!r}")
        return _cma_gait(prob, starts, tol, seed, max_evals, polish, jacobian)
    return _newton_gait(prob, starts, tol, None if guess is not None else _MAX_STARTS)
