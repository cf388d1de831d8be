"""The periodic-gait search of Section 2.8 as a problem in its free variables.

:class:`GaitProblem` states the search as pure functions of the free
variables ``z`` (docs/conventions.md, "Poincare section and periodic
gaits"): the residual and its exact Jacobian, the thesis's costs ``C1``
(eq. 2.20) and ``C`` (eqs 2.21-2.22), bounds (eqs 2.23-2.24) and automatic
starting guesses. The searches in :mod:`tslip.gait.fixed_point` see only
these functions. Split from that module, which re-exports every name.

What the search holds: the speed at the section (``fix="speed"``; the
touch-down speed ``v0``, or the apex's forward speed) or the total energy
(``fix="energy"``). At ``r = 0`` the undetermined pitch is held.

Over 600 lines: one concept, the search in its unknowns z, whose packing all parts share.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal, TypeVar

import numpy as np

from .._checks import check_number
from ..model import _pack as pk
from ..model.controllers import ConstantTorque, Controller, LocalVelocity, Passive
from ..model.parameters import Params
from ..model.state import TouchdownState
from ..simulation import _packed
from ..simulation.integrate import step_map
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status

if TYPE_CHECKING:
    from .fixed_point import Gait

__all__ = ["GaitProblem", "gait_residual", "nominal_energy", "C1_THRESHOLD", "C1_OFFSET",
           "TIGHT", "Fix", "Section"]

Fix = Literal["speed", "energy"]
Section = Literal["touchdown", "apex"]

#: ``epsilon`` of eq. 2.22: switch from ``C1`` to ``C2`` below this.
C1_THRESHOLD = 1e-4
#: Offset added to ``C1`` in eq. 2.22 so it exceeds ``C2`` for ``|lambda| < 5``.
C1_OFFSET = 25.0

#: Default options of gait search and Floquet multipliers, built (and checked) once:
#: tolerance 1e-12 with DOP853.
TIGHT = IntegratorOptions.tight("dop853")

_FALL_PENALTY = 10.0  # each entry of the residual after a fall (_PENALTY)
_TWO_PI = 2.0 * math.pi

_T = TypeVar("_T")


# ---------------------------------------------------------------------------
# copies of checked parameters, checking only what changes
# ---------------------------------------------------------------------------


@functools.cache
def _fields(cls: type) -> dict[str, dataclasses.Field[Any]]:
    return {f.name: f for f in dataclasses.fields(cls)}


def checked_replace(obj: _T, **changes: Any) -> _T:
    """``dataclasses.replace`` of ``Params`` and controllers, checking only the changes.

    Both check each numeric field on its own, by its metadata
    (:func:`tslip._checks.check_fields`), in ``__post_init__``; the fields of
    ``obj`` were checked when it was built. So a changed numeric field is
    checked here exactly as ``check_fields`` checks it (the same ``ValueError``)
    and the copy is made without checking the others again: the gait search
    and continuation patch a few fields of parameters checked once. Any other
    change (a choice, a controller of another type) and any other class take
    ``dataclasses.replace``.
    """
    cls: Any = type(obj)
    if cls.__post_init__ not in (Params.__post_init__, Controller.__post_init__):
        return dataclasses.replace(obj, **changes)  # type: ignore[type-var]
    fields = _fields(cls)
    prefix = "" if cls is Params else f"{cls.__name__}."
    checked = {}
    for name, value in changes.items():
        md = fields[name].metadata if name in fields else {}
        if "lower" in md:
            lo, hi = md["lower"], md.get("upper", math.inf)
            if (type(value) is float and fields[name].type not in (int, "int")
                    and (lo < value if md.get("lower_open") else lo <= value)
                    and (value < hi if md.get("upper_open") else value <= hi)
                    and math.isfinite(value)):
                checked[name] = value  # what check_number returns for it
                continue
            checked[name] = check_number(  # the rest, and the error message
                value, f"{prefix}{name}", unit=md.get("unit", ""), lower=lo, upper=hi,
                lower_open=md.get("lower_open", False), upper_open=md.get("upper_open", False),
                integer=fields[name].type in (int, "int"))
        elif name == "controller" and type(value) is type(getattr(obj, name)):
            checked[name] = value  # a controller is checked when built
        else:
            return dataclasses.replace(obj, **changes)  # type: ignore[type-var]
    new = object.__new__(cls)
    for name in fields:
        object.__setattr__(new, name, checked[name] if name in checked else getattr(obj, name))
    return new


# ---------------------------------------------------------------------------
# the problem: pure functions of the free variables
# ---------------------------------------------------------------------------


def thrust_solved(params: Params) -> bool:
    """Whether the gait search solves ``leg_thrust``: a passive hip with leg damping, whose
    loss only the thrust can make up (otherwise ``leg_thrust`` is a fixed parameter)."""
    return isinstance(params.controller, Passive) and params.c_l > 0


def _unknown_names(params: Params) -> tuple[str, ...]:
    """Free variables: ``(delta, phi, phid, alpha_r)`` and the controller reference.

    The reference is ``alphad_ref`` (local velocity control), ``tau_c`` (a constant torque
    with damping) or, for the passive hip with leg damping, the leg thrust ``leg_thrust``
    (issue 26: the energy the damper takes each stride comes back through the thrust).

    At ``r = 0`` with a torque that does not depend on the pitch, ``phi`` is
    undetermined (it does not enter the stride, or with the local reset only
    as ``alpha_r - phi``): it is held at 0. Without any hip torque ``phid`` is
    conserved and ``phi`` grows by ``phid T`` a stride, so a gait has
    ``phid = 0``: held too. Left free, both drift along a continuation.
    """
    names = ["delta", "phi", "phid", "alpha_r"]
    ctrl = params.controller
    if isinstance(ctrl, LocalVelocity):
        names.append("alphad_ref")
    elif isinstance(ctrl, ConstantTorque) and (params.c_l > 0 or ctrl.c_h > 0):
        names.append("tau_c")
    elif thrust_solved(params):
        names.append("leg_thrust")  # powered running: the thrust replaces what the damper takes
    a = ctrl.torque_coefficients()
    if params.r == 0.0 and a[1] == 0.0:
        names.remove("phi")
        # a constant torque without damping is 0 at a gait (energy balance, decode)
        torque_free = ("tau_c" not in names) if isinstance(ctrl, ConstantTorque) else not any(a)
        if torque_free:
            names.remove("phid")
    return tuple(names)


#: The controller references (and the leg thrust) a gait search may solve for.
_REFERENCES = ("alphad_ref", "tau_c", "leg_thrust")
#: The forms ``GaitProblem.names`` may take.
_ALLOWED_NAMES = frozenset(("delta", *mid, "alpha_r", *ext)
                           for mid in ((), ("phi",), ("phid",), ("phi", "phid"))
                           for ext in ((), ("alphad_ref",), ("tau_c",), ("leg_thrust",)))
#: What a stride's output vector and Jacobian hold before the kernel fills them.
_NAN_OUT = np.full(pk.NOUT, math.nan)
_NAN_J = np.full((5, 5), math.nan)
_NAN_OUT2 = np.full((2, pk.NOUT), math.nan)
#: ``dr/dq'`` but for the entries of the next touch-down's velocity (residual_jacobian).
_D0 = np.zeros((5, 5))
_D0[0, 0] = _D0[1, 1] = _D0[2, 4] = 1.0
#: The residual after a fall (copied: ``np.full`` costs four copies on a 5-vector).
_PENALTY = np.full(5, _FALL_PENALTY)
_F64 = np.dtype(np.float64)
_OK = int(Status.OK)


def _finite(a: np.ndarray) -> bool:
    """``np.isfinite(a).all()`` of a float array, at about half its cost on a 5 x 5.

    Each entry by ``math.isfinite``: no NumPy arithmetic, so an inf or a NaN sets
    no floating-point flag and warns of nothing (a dot with zeros, tried before,
    warned "invalid value" on an inf: ``inf * 0``).
    """
    return all(map(math.isfinite, a.ravel().tolist()))


def nominal_energy(params: Params) -> float:
    """Total energy [MgL] at touch-down at speed ``v0`` and angle ``beta0``, level trunk.

    ``m v0^2 / 2 + m g (l0 sin beta0 - r)`` (eq. 2.9 with ``phi = phid = 0``):
    the default of ``fix="energy"``.
    """
    p = params
    return 0.5 * p.m * p.v0**2 + p.m * p.g * (p.l0 * math.sin(p.beta0) - p.r)


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
    return _section_residual(tuple(q.tolist()), int(res.status), out.tolist(), params.beta0,
                             params.v0)


def _section_residual(q: tuple[float, ...], status: int, out: list[float], beta0: float,
                      v0: float) -> tuple[np.ndarray, float, float]:
    """:func:`gait_residual` of the stride from section ``q`` that filled ``out``.

    ``q`` and ``out`` (the kernel's ``out`` vector) as Python floats; ``beta0``:
    the touch-down angle and ``v0`` the touch-down speed the next touch-down must
    have (the search's).
    """
    ts, tf = out[pk.OUT_TS], out[pk.OUT_TF]
    if status != _OK:
        return _PENALTY.copy(), ts, tf
    b, ph, xd, yd, phd = out[pk.OUT_TD : pk.OUT_TD + 5]
    r = np.array([
        b - beta0,
        ph - q[1],
        phd - q[4],
        math.atan2(yd, xd) - math.atan2(q[3], q[2]),
        math.hypot(xd, yd) - v0,
    ])
    return r, ts, tf


@dataclass(frozen=True, slots=True)
class GaitProblem:
    """The periodic-gait search of Section 2.8 as pure functions of ``z``.

    ``z = (delta, phi, phid, alpha_r[, alphad_ref | tau_c])``: touch-down
    velocity angle [rad], pitch [rad], pitch rate [rad g^1/2 L^-1/2], leg
    reset angle [rad], and the controller reference hip rate
    [rad g^1/2 L^-1/2] or constant torque [MgL].

    At ``r = 0`` the undetermined pitch is held (``phi = 0``, and ``phid = 0``
    without hip torque; :func:`_unknown_names`), so ``z`` is shorter.

    Parameters
    ----------
    params : Params
        Model with the gait's fixed ``v0`` and ``beta0``. ``alpha_r`` and the
        controller reference are overwritten by ``z``; a constant-torque
        controller without leg or hip damping gets ``tau_c = 0`` (energy
        balance, Section 2.4).
    options : IntegratorOptions
        Integrator settings for every stride.
    fix : {"speed", "energy"}
        Hold the speed at the section (``v0``: the touch-down speed, or at the
        apex the forward speed ``xd``, so ``|v| = v0 / cos(delta)``), or the
        total energy ``energy`` (:func:`tslip.gait.section.total_energy`), from
        which the touch-down speed follows with eq. 2.9's height.
    section : {"touchdown", "apex"}
        Where ``fix="speed"`` holds the speed. The residual is the touch-down
        one either way: its zeros, the gaits, do not depend on the section.
    energy : float
        Total energy [MgL] held with ``fix="energy"``.

    Examples
    --------
    >>> import tslip
    >>> prob = GaitProblem.from_params(tslip.preset("table2.1"))
    >>> prob.names
    ('delta', 'phi', 'phid', 'alpha_r')
    >>> g = tslip.find_gait(prob.params)
    >>> bool(prob.c1(prob.encode(g)) < 1e-20)
    True
    """

    params: Params
    options: IntegratorOptions
    names: tuple[str, ...] = ()
    fix: Fix = "speed"
    section: Section = "touchdown"
    energy: float = math.nan
    # packed once (validation happened when params and options were built):
    # P with z's alpha_r and controller reference written in per evaluation
    _P: np.ndarray = field(init=False, repr=False, compare=False)
    _O: np.ndarray = field(init=False, repr=False, compare=False)
    _ref_gain: float = field(init=False, repr=False, compare=False)
    _ref_slot: int = field(init=False, repr=False, compare=False)
    _idx: dict[str, int] = field(init=False, repr=False, compare=False)
    _at: tuple[int, int, int, int, int] = field(init=False, repr=False, compare=False)
    # residual_jacobian's constant parts: dq/dz's ones, and what r subtracts of q (held
    # copies, read only)
    _dq0: np.ndarray = field(init=False, repr=False, compare=False)
    _dr0: np.ndarray = field(init=False, repr=False, compare=False)
    # whether the touch-down speed moves with z (else it is params.v0: :meth:`speed`)
    _moving_speed: bool = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not self.names:
            object.__setattr__(self, "names", _unknown_names(self.params))
        if tuple(self.names) not in _ALLOWED_NAMES:
            raise ValueError("names must be ('delta', ['phi'], ['phid'], 'alpha_r') and at most "
                             f"one of 'alphad_ref', 'tau_c', 'leg_thrust', got {self.names}")
        if self.fix not in ("speed", "energy"):
            raise ValueError(f"fix must be 'speed' or 'energy', got {self.fix!r}")
        if self.section not in ("touchdown", "apex"):
            raise ValueError(f"section must be 'touchdown' or 'apex', got {self.section!r}")
        if self.fix == "energy" and not math.isfinite(self.energy):
            raise ValueError(f"energy [MgL] must be finite with fix='energy', got {self.energy!r}")
        if self.fix == "energy":
            p = self.params
            e_min = p.m * p.g * (p.l0 * math.sin(p.beta0) - p.r)  # at rest, touching down
            if not self.energy > e_min:
                raise ValueError(f"energy must be in ({e_min:.6g}, inf) MgL (above the "
                                 f"touch-down potential at beta0), got {self.energy!r}")
        idx = {n: i for i, n in enumerate(self.names)}
        object.__setattr__(self, "_idx", idx)
        ref = self.names[-1] if self.names[-1] in _REFERENCES else ""
        object.__setattr__(self, "_at", tuple(idx.get(n, -1) for n in (
            "delta", "phi", "phid", "alpha_r", ref)))
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
        object.__setattr__(self, "_ref_slot", pk.P_THRUST if ref == "leg_thrust" else pk.P_C0)
        n, (i_delta, i_phi, i_phid, _, _) = len(self.names), self._at
        dq0, dr0 = np.zeros((5, n)), np.zeros((5, n))
        if i_phi >= 0:
            dq0[1, i_phi] = dr0[1, i_phi] = 1.0
        if i_phid >= 0:
            dq0[4, i_phid] = dr0[2, i_phid] = 1.0
        dr0[3, i_delta] = 1.0
        object.__setattr__(self, "_dq0", dq0)
        object.__setattr__(self, "_dr0", dr0)
        object.__setattr__(self, "_moving_speed",
                           not (self.fix == "speed" and self.section == "touchdown"))

    @classmethod
    def from_params(cls, params: Params, options: IntegratorOptions | None = None, *,
                    fix: Fix = "speed", section: Section = "touchdown",
                    energy: float | None = None) -> GaitProblem:
        """Problem for ``params``.

        Default options: tolerance 1e-12 with DOP853, which needs about a
        third of dopri5's right-hand sides there (``IntegratorOptions.tight``).
        ``fix="energy"`` holds ``energy``, by default :func:`nominal_energy`.
        """
        if fix == "speed" and energy is not None:
            raise ValueError("energy is held only with fix='energy'")
        e = math.nan
        if fix == "energy":
            e = nominal_energy(params) if energy is None else float(
                check_number(energy, "energy", unit="MgL"))
        return cls(params=params, options=options or TIGHT, fix=fix, section=section, energy=e)

    @property
    def size(self) -> int:
        """Number of free variables."""
        return len(self.names)

    # -- the speed the section holds ---------------------------------------------
    def speed(self, delta: float, phi: float = 0.0, phid: float = 0.0) -> float:
        """Touch-down speed at velocity angle ``delta`` (NaN where no state exists).

        ``v0``; ``v0 / cos(delta)`` for the apex's forward speed; from the
        energy, ``sqrt(2 (E - m g (l0 sin beta0 - r cos phi) - J phid^2 / 2) / m)``.
        """
        p = self.params
        if self.fix == "speed":
            if self.section == "touchdown":
                return p.v0
            c = math.cos(delta)
            return p.v0 / c if c > 0.0 else math.nan
        kin = (self.energy - p.m * p.g * (p.l0 * math.sin(p.beta0) - p.r * math.cos(phi))
               - 0.5 * p.J * phid * phid)
        return math.sqrt(2.0 * kin / p.m) if kin > 0.0 else math.nan

    def exists(self, z: Sequence[float] | np.ndarray) -> bool:
        """Whether a touch-down state exists at ``z`` (the energy held can reach it)."""
        try:
            delta, phi, phid, _, _ = self._unpack(z)
        except ValueError:
            return False
        return math.isfinite(self.speed(delta, phi, phid))

    def _speed_gradient(self, delta: float, phi: float, phid: float, v: float
                        ) -> list[tuple[int, float]]:
        """``d speed / d z`` by position in ``z``: the free ones of ``(delta, phi, phid)``."""
        p = self.params
        if self.fix == "speed":
            grad = [] if self.section == "touchdown" else [(0, v * math.tan(delta))]
        else:
            grad = [(1, -p.g * p.r * math.sin(phi) / v), (2, -p.J * phid / (p.m * v))]
        return [(self._at[k], g) for k, g in grad if self._at[k] >= 0]

    def _unpack(self, z: Sequence[float] | np.ndarray
                ) -> tuple[float, float, float, float, float]:
        """``(delta, phi, phid, alpha_r, reference)`` of ``z``; held values 0, no reference NaN."""
        if len(z) != len(self.names):
            raise ValueError(f"guess must have {self.size} entries {list(self.names)}, "
                             f"got {len(z)}")
        if type(z) is np.ndarray and z.dtype == _F64:
            zf = z.tolist()  # Python floats already
        else:
            zf = [float(v) for v in (z.tolist() if isinstance(z, np.ndarray) else z)]
        if not all(map(math.isfinite, zf)):
            raise ValueError(f"z must be finite, got {zf}")
        i_delta, i_phi, i_phid, i_alpha, i_ref = self._at
        return (zf[i_delta], zf[i_phi] if i_phi >= 0 else 0.0,
                zf[i_phid] if i_phid >= 0 else 0.0, zf[i_alpha],
                zf[i_ref] if i_ref >= 0 else math.nan)

    # -- z <-> (params, state) ------------------------------------------------
    def decode(self, z: Sequence[float] | np.ndarray) -> tuple[Params, TouchdownState]:
        """Parameters and touch-down state for the free variables ``z``.

        ``params.v0`` is the touch-down speed of ``z`` (:meth:`speed`).
        """
        delta, phi, phid, alpha_r, ref = self._unpack(z)
        v = self.speed(delta, phi, phid)
        if not math.isfinite(v):
            values = {"phi": 0.0, "phid": 0.0, **dict(zip(self.names, map(float, z)))}
            raise ValueError(f"no touch-down state at energy {self.energy:g} MgL with "
                             f"{values}")
        ctrl = self.params.controller
        ref_name = self.names[-1]
        if ref_name == "alphad_ref" and isinstance(ctrl, LocalVelocity):  # (the name implies it)
            ctrl = checked_replace(ctrl, alphad_ref=ref)
        if ref_name == "tau_c" and isinstance(ctrl, ConstantTorque):
            ctrl = checked_replace(ctrl, tau_c=ref)
        elif isinstance(ctrl, ConstantTorque) and ctrl.tau_c != 0.0:
            ctrl = checked_replace(ctrl, tau_c=0.0)  # no damping: no torque
        thrust = ref if ref_name == "leg_thrust" else self.params.leg_thrust
        p = checked_replace(self.params, alpha_r=alpha_r, controller=ctrl, v0=v,
                            leg_thrust=thrust)
        s = TouchdownState.from_velocity(v=v, delta=delta, beta=p.beta0, phi=phi, phid=phid)
        return p, s

    def encode(self, gait: Gait) -> np.ndarray:
        """Free variables of a gait (a warm start for nearby parameters).

        A gait whose search did not solve the leg thrust (no leg damping: a study's
        neighbour at ``c_l = 0``) gives the energy-balance guess of :meth:`guesses` for it.
        """
        s, p = gait.state, gait.params
        out = {"delta": s.delta, "phi": s.phi, "phid": s.phid, "alpha_r": p.alpha_r,
               "alphad_ref": getattr(p.controller, "alphad_ref", math.nan),
               "tau_c": getattr(p.controller, "tau_c", math.nan),
               "leg_thrust": getattr(p, "leg_thrust", math.nan)}
        if "leg_thrust" in self.names and not (math.isfinite(out["leg_thrust"])
                                               and out["leg_thrust"] > 0.0):
            out["leg_thrust"] = float(self._guess(float(s.delta))[-1])
        z = np.array([out[n] for n in self.names], dtype=float)
        if not np.all(np.isfinite(z)):
            raise ValueError(f"the gait's controller has no {list(self.names)[-1]!r}")
        return z

    # -- costs ----------------------------------------------------------------
    def _stride(self, x: tuple[float, float, float, float, float], jacobian: bool = False,
                ) -> tuple[np.ndarray, tuple[float, ...], int, np.ndarray, np.ndarray | None,
                           float]:
        """``P``, section ``q``, a stride at ``x = _unpack(z)`` on the packed arrays, the speed.

        Writes ``alpha_r`` and the controller reference of ``z`` into ``P``
        exactly as :meth:`decode` followed by ``pack_params`` would. Where no
        state exists at ``z`` (energy too low) the stride is a ``NONFINITE``.
        ``q`` is a tuple of floats (an array per stride cost more than its stride's
        other Python).
        """
        delta, phi, phid, alpha_r, ref = x
        P = self._P.copy()
        P[pk.P_ALPHA] = alpha_r
        if self._at[4] >= 0:
            P[self._ref_slot] = self._ref_gain * ref
        v = self.speed(delta, phi, phid) if self._moving_speed else self.params.v0
        q = (self.params.beta0, phi, v * math.cos(delta), v * math.sin(delta), phid)
        out = _NAN_OUT.copy()
        J = _NAN_J.copy() if jacobian else None
        if not math.isfinite(v):
            return P, q, int(Status.NONFINITE), out, J, v
        if J is not None:
            return P, q, _packed.stride_jacobian(P, self._O, q, 0.0, J, out), out, J, v
        return P, q, _packed.stride_map_at(P, self._O, q, 0.0, out), out, None, v

    def evaluate(self, z: Sequence[float] | np.ndarray) -> tuple[np.ndarray, float, float]:
        """Residual, stance and flight time at ``z`` (see :func:`gait_residual`)."""
        _, q, st, out, _, v = self._stride(self._unpack(z))
        return _section_residual(q, st, out.tolist(), self.params.beta0, v)

    def residual_jacobian(self, z: Sequence[float] | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Residual (5,) and its Jacobian ``dr/dz`` (5 x size) at ``z``.

        The chain ``z -> q -> q' -> r``: ``dq'/dq`` exact from the variational
        equations (:func:`tslip.step_jacobian`), ``dq'/d alpha_r`` exact from
        the flight's touch-down time, ``dq'/d(alphad_ref | tau_c)`` by a
        central difference (the reference acts in stance, outside the
        variational equations). After a fall the Jacobian is NaN.
        """
        x = self._unpack(z)
        P, q, st, out, Jq, v = self._stride(x, jacobian=True)
        o = out.tolist()
        r, _, _ = _section_residual(q, st, o, self.params.beta0, v)
        n = len(self.names)
        if st != _OK or Jq is None or not _finite(Jq):
            return r, np.full((5, n), math.nan)
        delta, phi, phid, _, ref = x
        i_delta, i_phi, i_phid, i_alpha, i_ref = self._at
        # the touch-down speed held (the usual search) has no gradient
        dv = self._speed_gradient(delta, phi, phid, v) if self._moving_speed else ()
        cd, sd = math.cos(delta), math.sin(delta)
        # dq/dz, q = (beta0, phi, v cos delta, v sin delta, phid): dq/dphi and dq/dphid
        # are ones (self._dq0)
        dq = self._dq0.copy()
        dq[2, i_delta], dq[3, i_delta] = -v * sd, v * cd
        for k, g in dv:  # the speed held by the section or the energy
            dq[2, k] += cd * g
            dq[3, k] += sd * g
        dqn = Jq @ dq  # dq'/dz through the state
        dqn[:, i_alpha] += _packed.alpha_r_column(P, out)
        if i_ref >= 0:
            h = 1e-5 * max(1.0, abs(ref))
            column = self._ref_column(P, q, ref, h)
            if column is None:
                return r, np.full((5, n), math.nan)
            dqn[:, i_ref] += column
        # r = (beta', phi' - phi, phid' - phid, atan2(yd', xd') - delta, |v'| - v0)
        _, _, xd, yd, _ = o[pk.OUT_TD : pk.OUT_TD + 5]
        v2 = xd * xd + yd * yd
        v = math.sqrt(v2)
        D = _D0.copy()  # dr/dq'
        D[3, 2], D[3, 3] = -yd / v2, xd / v2
        D[4, 2], D[4, 3] = xd / v, yd / v
        Jr = D @ dqn
        # minus dphi/dphi, dphid/dphid, ddelta/ddelta (self._dr0; x - 0.0 is x, bit for bit)
        Jr -= self._dr0
        for k, g in dv:
            Jr[4, k] -= g
        return r, Jr

    def _ref_column(self, P: np.ndarray, q: tuple[float, ...], ref: float, h: float
                    ) -> np.ndarray | None:
        """``dq'/d ref`` by a central difference of step ``h``; None if a stride fails.

        The strides start from the section ``q`` of the stride at ``ref`` with
        ``P`` as :meth:`_stride` wrote it, only the reference's slot changed (as ``_stride``
        writes it for ``ref +- h``; the slot is written back before returning).
        """
        slot = self._ref_slot
        kept = P[slot]
        outs = _NAN_OUT2.copy()  # one row per stride
        try:
            for out, value in zip(outs, (ref + h, ref - h)):
                P[slot] = self._ref_gain * value
                if _packed.stride_map_at(P, self._O, q, 0.0, out) != _OK:
                    return None
        finally:
            P[slot] = kept
        column = outs[0, pk.OUT_TD : pk.OUT_TD + 5] - outs[1, pk.OUT_TD : pk.OUT_TD + 5]
        column /= 2.0 * h
        return column

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
        from .stability import eigvals, map_jacobian, nontrivial_jacobian

        p, s = self.decode(z)
        q = s.section()
        if p.leg_exponent < 1.0:
            jacobian = "fd"  # no exact Jacobian (tslip.simulation._packed.check_exact)
        try:
            A = map_jacobian(p, q, method=jacobian, options=self.options)
        except ValueError:
            return math.nan
        if not np.all(np.isfinite(A)):
            return math.nan
        lam = eigvals(nontrivial_jacobian(p, q, A))
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
              "alphad_ref": 0.0, "tau_c": -tau_max, "leg_thrust": 0.0}
        hi = {"delta": 0.0, "phi": math.pi / 2, "phid": 10.0, "alpha_r": _TWO_PI,
              "alphad_ref": 5.0 * p.v0 / p.l0 + 10.0, "tau_c": tau_max, "leg_thrust": 0.5}
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
             "alphad_ref": 0.5 * max(1.0, p.v0 / p.l0), "tau_c": 0.2 * (1.0 + damping),
             "leg_thrust": 0.05}
        return np.array([s[n] for n in self.names])

    def guesses(self) -> Iterator[np.ndarray]:
        """Automatic starting points, most likely first (lazily).

        The first five are the original list (``delta`` from -0.05 to -0.4,
        level trunk, ``alpha_r`` from the symmetric flight time of eq. 3.11
        and the retraction of eq. 2.17, over half that time with the apex
        clock). Then a scan: ``delta`` on a grid
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
                has_ref = self.names[-1] in _REFERENCES
                for f in ((1.0, 0.5, 2.0) if has_ref else (1.0,)):
                    if d in first and da == 0.0 and f == 1.0:
                        continue  # already tried
                    z = self._guess(d, f)
                    z[self._idx["alpha_r"]] += da
                    c1 = self.c1(z)
                    if math.isfinite(c1) and c1 < 5 * _FALL_PENALTY**2:
                        scored.append((c1, len(scored), z))
        scored.sort(key=lambda t: (t[0], t[1]))
        for _, _, z in scored:
            yield z

    def _guess(self, delta: float, factor: float = 1.0) -> np.ndarray:
        p = self.params
        v = self.speed(delta)
        v = v if math.isfinite(v) else p.v0
        tf = 2.0 * v * math.sin(-delta) / p.g  # eq. 3.11, symmetric stance
        t_ret = tf / 2 if p.retraction == "apex" else tf  # a symmetric flight's apex: tf / 2
        named = {"delta": delta, "phi": 0.0, "phid": 0.0,
                 "alpha_r": p.beta0 - p.omega_r * t_ret}  # eq. 2.17 with phi = 0
        z = [named[n] for n in self.names if n in named]
        ts = 2.0 * p.l0 * (math.pi / 2 - p.beta0) / v  # eq. 3.10
        if "alphad_ref" in self.names:
            z.append(factor * (math.pi - 2 * p.beta0) / ts)
        if "tau_c" in self.names:
            # energy balance: tau_c * (pi - 2 beta0) = dissipated energy, with
            # ldot(t) = ldot0 cos(pi t / ts) in the leg and alpha_dot = const
            # at the hip
            dalpha = max(math.pi - 2 * p.beta0, 0.1)
            ldot0 = v * math.cos(p.beta0 + delta)
            c_h = p.controller.c_h if isinstance(p.controller, ConstantTorque) else 0.0
            loss = p.c_l * ldot0**2 * ts / 2 + c_h * dalpha**2 / ts
            z.append(0.1 if loss == 0 else factor * loss / dalpha)
        if "leg_thrust" in self.names:
            # energy balance: the damper's loss c_l ldot0^2 ts / 2 (ldot as above) equals
            # the thrust's work k l0^2 (d^2 + 2 d x) / 2 at the compression x = ldot0 ts /
            # (pi l0) of that sine (n = 1)
            ldot0 = v * math.cos(p.beta0 + delta)
            loss = p.c_l * ldot0**2 * ts / 2
            x = abs(ldot0) * ts / (math.pi * p.l0)
            d = -x + math.sqrt(x * x + 2.0 * loss / (p.k * p.l0**2))
            z.append(min(max(factor * d, 1e-4), 0.5))
        return np.array(z)
