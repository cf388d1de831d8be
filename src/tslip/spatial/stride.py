"""The 3-D spring-mass runner's step: apex -> touch-down -> stance -> apex, and its Jacobian.

One step (issue 43, Part 1; Seipel & Holmes 2005) from an apex of the flight
(vertical velocity 0) before a step of side ``s``:

* descent (closed form, ballistic): the mass falls from the apex height ``y``
  to the touch-down height ``l0 sin(beta0)`` in ``T = sqrt(2 (y - l0 sin beta0) / g)``;
  an apex at or below it is :attr:`SpatialStatus.APEX_LOW`;
* touch-down: the foot placed as :mod:`tslip.spatial.parameters` says. A mass
  moving away from the foot, ``(c - p) . v >= 0``, has no stance:
  :attr:`SpatialStatus.NO_STANCE`;
* stance: the compiled loop of :mod:`tslip.spatial._kernels` to lift-off (leg
  at rest length while extending) or to the mass reaching the ground
  (:attr:`SpatialStatus.FALL`);
* flight to the next apex (closed form), ``T = vy / g`` after lift-off; a
  lift-off moving down (``vy < 0``) has no apex: :attr:`SpatialStatus.NO_APEX`.
  The next step is the other leg's (``side = -s``).

The apex section is ``(y, vx, vz)`` (:data:`SECTION_NAMES`); the positions ``x``
and ``z`` ride along (flat ground: the step does not depend on them).
:func:`step_jacobian` is the exact derivative of the section map (the stance's
variational equations with the lift-off event's correction, and the closed-form
flights and foot placement), for :mod:`tslip.spatial.gait`.
"""

from __future__ import annotations

import enum
import math
from dataclasses import astuple, dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from .._checks import check_number
from .._results import Result, frame
from ..simulation.options import IntegratorOptions
from . import _kernels as kn
from .parameters import SpatialParams

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["SpatialStatus", "SpatialApex", "APEX_UNITS", "SpatialStep", "SECTION_NAMES",
           "apex_step", "apex_steps", "section_map", "step_jacobian", "energy", "mirror"]

#: Names of the apex-section vector, in order.
SECTION_NAMES: tuple[str, ...] = ("y", "vx", "vz")


class SpatialStatus(enum.IntEnum):
    """Outcome of a step of the 3-D spring-mass runner (module docstring)."""

    OK = kn.ST_OK
    FALL = kn.ST_FALL
    APEX_LOW = kn.ST_APEX_LOW
    NO_STANCE = kn.ST_NO_STANCE
    NO_APEX = kn.ST_NO_APEX
    STEP_UNDERFLOW = kn.ST_ERR_STEP_UNDERFLOW
    MAX_STEPS = kn.ST_ERR_MAX_STEPS
    STANCE_TIMEOUT = kn.ST_ERR_STANCE_TIMEOUT
    NONFINITE = kn.ST_ERR_NONFINITE


#: Units of the apex's fields (its table's columns; thesis Table 3.1).
APEX_UNITS: dict[str, str] = {"y": "L", "vx": "g^1/2 L^1/2", "vz": "g^1/2 L^1/2", "x": "L",
                              "z": "L", "side": "-"}


@dataclass(frozen=True, slots=True, repr=False)
class SpatialApex(Result):
    """State at an apex (vertical velocity 0) before a step of side ``side``.

    A :class:`~tslip._results.Result`: it saves, loads and tabulates (one row) like the
    planar results.

    Parameters
    ----------
    y : float
        Height of the mass above the ground [L].
    vx, vz : float
        Forward and rightward velocity [g^1/2 L^1/2].
    x, z : float
        Position of the mass [L].
    side : int
        The leg that lands next: +1 right, -1 left.
    """

    y: float
    vx: float
    vz: float = 0.0
    x: float = 0.0
    z: float = 0.0
    side: int = 1

    def __post_init__(self) -> None:
        for name in ("y", "vx", "vz", "x", "z"):
            object.__setattr__(self, name, check_number(getattr(self, name),
                                                        f"SpatialApex.{name}"))
        if self.side not in (1, -1) or isinstance(self.side, bool):
            raise ValueError(f"SpatialApex.side must be 1 (right) or -1 (left), "
                             f"got {self.side!r}")
        object.__setattr__(self, "side", int(self.side))

    @classmethod
    def from_energy(cls, params: SpatialParams, y: float, energy: float, vz: float = 0.0,
                    side: int = 1) -> SpatialApex:
        """The apex at height ``y`` and lateral speed ``vz`` with total energy ``energy``
        [MgL]: ``m (vx^2 + vz^2)/2 + m g y``, solved for ``vx > 0``."""
        kin = 2.0 * (energy - params.m * params.g * y) / params.m - vz * vz
        if not kin > 0.0:
            raise ValueError(f"energy [MgL] must exceed m g y + m vz^2/2 = "
                             f"{params.m * (params.g * y + 0.5 * vz * vz):.6g} at this "
                             f"apex, got {energy!r}")
        return cls(y, math.sqrt(kin), vz, side=side)

    def section(self) -> np.ndarray:
        """The apex-section vector ``(y, vx, vz)``."""
        return np.array([self.y, self.vx, self.vz])

    def as_array(self) -> np.ndarray:
        """All fields ``(y, vx, vz, x, z, side)``."""
        return np.array(astuple(self), dtype=float)

    def to_dataframe(self) -> pd.DataFrame:
        """One row: the fields, units in ``attrs`` (:data:`APEX_UNITS`)."""
        return frame([{k: getattr(self, k) for k in APEX_UNITS}], APEX_UNITS)


def energy(params: SpatialParams, apex: SpatialApex) -> float:
    """Total mechanical energy at an apex [MgL]: ``m (vx^2 + vz^2)/2 + m g y``."""
    return params.m * (0.5 * (apex.vx**2 + apex.vz**2) + params.g * apex.y)


def mirror(apex: SpatialApex) -> SpatialApex:
    """The mirror image in the sagittal plane ``z = 0``: ``z``, ``vz`` and the side negated."""
    return SpatialApex(apex.y, apex.vx, -apex.vz, apex.x, -apex.z, -apex.side)


class SpatialStep(NamedTuple):
    """Result of :func:`apex_step`: one apex to the next."""

    apex: SpatialApex | None  # the next apex (None unless OK)
    status: SpatialStatus
    foot: np.ndarray | None  # foot position (3,) [L] (None if no touch-down)
    touchdown: np.ndarray | None  # mass position and velocity at touch-down (6,)
    liftoff: np.ndarray | None  # mass position and velocity at lift-off or the fall (6,)
    stance_time: float  # [g^-1/2 L^1/2]
    time: float  # apex to apex (NaN unless OK)
    gamma: float  # the azimuth used at touch-down [rad]


def _heading(params: SpatialParams, vx: float, vz: float) -> tuple[float, float]:
    """The heading ``h = (cos psi, 0, sin psi)`` as ``(cos psi, sin psi)``."""
    if params.heading == "fixed":
        return 1.0, 0.0
    sp = math.hypot(vx, vz)
    if sp == 0.0:  # no horizontal velocity: no direction; the fixed heading stands in
        return 1.0, 0.0
    return vx / sp, vz / sp


def _placement(params: SpatialParams, side: int, vx: float, vz: float
               ) -> tuple[np.ndarray, float, float]:
    """Leg vector ``q0 = c - p`` at touch-down, the azimuth ``gamma`` and the horizontal
    foot direction angle ``phi = psi + s gamma`` (``h`` at angle ``psi`` from +x towards +z)."""
    ch, sh = _heading(params, vx, vz)
    v_n = -sh * vx + ch * vz  # n = h x e_y = (-sin psi, 0, cos psi)
    gamma = params.gamma0 + params.k_lat * side * v_n
    phi = math.atan2(sh, ch) + side * gamma
    cb, sb = math.cos(params.beta0), math.sin(params.beta0)
    q0 = -params.l0 * np.array([cb * math.cos(phi), -sb, cb * math.sin(phi)])
    return q0, gamma, phi


def apex_step(params: SpatialParams, apex: SpatialApex,
              options: IntegratorOptions | None = None) -> SpatialStep:
    """One step from ``apex`` to the next apex (module docstring).

    Examples
    --------
    >>> from tslip.spatial import SpatialParams, SpatialApex, apex_step, energy
    >>> p = SpatialParams(gamma0=0.05)
    >>> s = apex_step(p, SpatialApex.from_energy(p, 1.0, 2.2))
    >>> s.status.name, s.apex.side, abs(energy(p, s.apex) - 2.2) < 1e-6
    ('OK', -1, True)
    """
    O = (options or IntegratorOptions()).packed()  # noqa: E741
    p = params
    nan = math.nan
    drop = apex.y - p.touchdown_height
    if not drop > 0.0:
        return SpatialStep(None, SpatialStatus.APEX_LOW, None, None, None, nan, nan, nan)
    T = math.sqrt(2.0 * drop / p.g)
    c = np.array([apex.x + apex.vx * T, p.touchdown_height, apex.z + apex.vz * T])
    v = np.array([apex.vx, -p.g * T, apex.vz])
    q0, gamma, _ = _placement(p, apex.side, apex.vx, apex.vz)
    foot = c - q0
    td = np.concatenate([c, v])
    if float(q0 @ v) >= 0.0:
        return SpatialStep(None, SpatialStatus.NO_STANCE, foot, td, None, nan, nan, gamma)
    out = np.empty(kn.NOUT)
    st = SpatialStatus(int(kn.stance(p.packed(), O, np.concatenate([q0, v]), out)))
    ts = float(out[kn.OUT_T])
    y = out[kn.OUT_Y : kn.OUT_Y + 6]
    lo = np.concatenate([foot + y[:3], y[3:6]]) if np.all(np.isfinite(y)) else None
    if st != SpatialStatus.OK:
        return SpatialStep(None, st, foot, td, lo, ts, nan, gamma)
    assert lo is not None
    if lo[4] < 0.0:
        return SpatialStep(None, SpatialStatus.NO_APEX, foot, td, lo, ts, nan, gamma)
    Tu = lo[4] / p.g
    nxt = SpatialApex(lo[1] + 0.5 * lo[4] * Tu, lo[3], lo[5], lo[0] + lo[3] * Tu,
                      lo[2] + lo[5] * Tu, -apex.side)
    return SpatialStep(nxt, st, foot, td, lo, ts, float(T + ts + Tu), gamma)


def apex_steps(params: SpatialParams, apex: SpatialApex, n: int,
               options: IntegratorOptions | None = None) -> tuple[list[SpatialApex],
                                                                  SpatialStatus]:
    """``n`` steps from ``apex``: the apexes reached (``apex`` first) and the last status."""
    n = int(check_number(n, "n", lower=0, integer=True))
    out = [apex]
    status = SpatialStatus.OK
    for _ in range(n):
        s = apex_step(params, out[-1], options)
        status = s.status
        if s.apex is None:
            break
        out.append(s.apex)
    return out, status


def section_map(params: SpatialParams, x: np.ndarray, side: int = 1,
                options: IntegratorOptions | None = None) -> np.ndarray:
    """The step map on the section ``(y, vx, vz)`` before a step of ``side``; NaN if not OK."""
    s = apex_step(params, SpatialApex(float(x[0]), float(x[1]), float(x[2]), side=side), options)
    return s.apex.section() if s.apex is not None else np.full(3, np.nan)


def step_jacobian(params: SpatialParams, x: np.ndarray, side: int = 1,
                  options: IntegratorOptions | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The next section vector and the exact 3 x 3 Jacobian of :func:`section_map` at ``x``.

    Chain rule through the three pieces: the descent and foot placement (closed
    form: ``dT/dy = 1/(g T)``; the leg vector turns with the foot direction
    angle ``phi = psi + s gamma``), the stance (the variational equations of
    :mod:`._kernels` with the lift-off event's correction ``(I - f grad(g)^T /
    grad(g).f) Phi``, ``g = l0 - |q|``), and the rise ``y' = q_y + vy^2 / (2 g)``.
    (The leg force vanishes at lift-off, so the stance field there is the flight's and
    the rise maps the correction's direction ``f`` to 0: the apex does not depend on
    when the lift-off happens along its parabola. The correction is kept for the
    lift-off state itself.)

    Raises
    ------
    ValueError
        If the step from ``x`` is not OK.
    """
    p = params
    opts = options or IntegratorOptions()
    y0, vx, vz = (float(u) for u in x)
    drop = y0 - p.touchdown_height
    if not drop > 0.0:
        raise ValueError(f"no step from this apex: {SpatialStatus.APEX_LOW.name}")
    T = math.sqrt(2.0 * drop / p.g)
    v = np.array([vx, -p.g * T, vz])
    q0, _, phi = _placement(p, side, vx, vz)
    # d(q0, v0) / d(y, vx, vz)
    D1 = np.zeros((6, 3))
    D1[4, 0] = -1.0 / T
    D1[3, 1] = 1.0
    D1[5, 2] = 1.0
    if p.heading == "fixed":
        dphi = np.array([0.0, 0.0, p.k_lat])  # phi = s gamma0 + k_lat vz (s^2 = 1)
    else:
        sp2 = vx * vx + vz * vz
        dphi = np.array([0.0, -vz / sp2, vx / sp2])
    cb = math.cos(p.beta0)
    dq_dphi = p.l0 * cb * np.array([math.sin(phi), 0.0, -math.cos(phi)])
    D1[:3, :] += np.outer(dq_dphi, dphi)
    if float(q0 @ v) >= 0.0:
        raise ValueError(f"no step from this apex: {SpatialStatus.NO_STANCE.name}")
    y_in = np.concatenate([q0, v, np.eye(6).ravel()])
    out = np.empty(kn.NOUT)
    st = SpatialStatus(int(kn.stance(p.packed(), opts.packed(), y_in, out)))
    if st != SpatialStatus.OK:
        raise ValueError(f"no step from this apex: {st.name}")
    ye = out[kn.OUT_Y : kn.OUT_Y + kn.NVAR]
    q, vl = ye[:3], ye[3:6]
    if vl[1] < 0.0:
        raise ValueError(f"no step from this apex: {SpatialStatus.NO_APEX.name}")
    Phi = ye[6:].reshape(6, 6)
    f = np.empty(kn.NVAR)
    kn.rhs(p.packed(), 6, ye[:6].copy(), f)
    f = f[:6]
    grad = np.concatenate([-q / np.linalg.norm(q), np.zeros(3)])
    D2 = (np.eye(6) - np.outer(f, grad) / float(grad @ f)) @ Phi
    D3 = np.zeros((3, 6))
    D3[0, 1] = 1.0
    D3[0, 4] = vl[1] / p.g
    D3[1, 3] = 1.0
    D3[2, 5] = 1.0
    nxt = np.array([q[1] + 0.5 * vl[1] ** 2 / p.g, vl[0], vl[2]])
    return nxt, D3 @ D2 @ D1
