"""Left-right symmetric gaits of the 3-D spring-mass runner and their Floquet multipliers.

A left-right symmetric gait (issue 43, Part 1; Seipel & Holmes 2005) is an apex
state ``x = (y, vx, vz)`` before a right step whose step map gives its mirror
image ``(y, vx, -vz)`` (``z`` negated too; under ``heading="velocity"`` up to a
rotation about the vertical), so that two steps return it up to a translation.

* ``heading="fixed"``: the unknowns are ``(y, vz)`` (``vx`` from the energy, or
  given as the forward speed), the residual ``(y' - y, vz' + vz)``; the forward
  speed then matches by the conservation of energy. A gait is isolated at fixed
  energy: :func:`symmetric_gaits` scans the apex height, solving the lateral
  residual for ``vz`` at each height (:func:`_lateral`), and refines each sign
  change of ``y' - y`` with a 2-D Newton solve.
* ``heading="velocity"``: the model is invariant under yaw, so the gait can be
  taken heading +x with ``vz = 0``; the apex after the right step is the same
  state turned about the vertical, and the unknown is ``y`` alone.

A solution whose step turns the horizontal velocity by 90 degrees or more (a hop
to and fro, which the residual of ``(y, vz)`` alone admits at low speed) is not
a running gait and is left out.

Floquet multipliers (:func:`floquet`) are those of the two-step map ``F_L o F_R``
on the section ``(y, vx, vz)``: its exact Jacobian, the product of
:func:`tslip.spatial.stride.step_jacobian` (variational equations), or central
differences of the map. Trivial multipliers equal 1 whatever the gait: the
energy (the map conserves ``m (vx^2 + vz^2)/2 + m g y``), and under
``heading="velocity"`` the heading (the direction ``(0, -vz, vx)`` of a rotation
about the vertical). They are set aside by reducing the Jacobian to the energy
level (coordinates ``(y, vz)``, ``vx`` from the energy) and, under
``"velocity"``, to the quotient by yaw (coordinate ``y``): the eigenvalues of
the reduced matrix are the non-trivial multipliers; the full matrix's other
eigenvalues are reported as the trivial ones.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import brentq, root

from .._checks import check_number
from .._results import Result, frame
from ..simulation.options import IntegratorOptions
from .parameters import SpatialParams
from .stride import APEX_UNITS, SpatialApex, section_map, step_jacobian

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["SymmetricGait", "Multipliers", "MULTIPLIER_UNITS", "symmetric_gaits", "floquet",
           "two_step_map", "two_step_jacobian"]


@dataclass(frozen=True, slots=True, repr=False)
class SymmetricGait(Result):
    """A left-right symmetric gait: the apex before its right step, and how well it closes.

    A :class:`~tslip._results.Result`; its table is one row, the apex with the energy and
    the residual.
    """

    params: SpatialParams
    apex: SpatialApex  # before the right step (side +1)
    energy: float  # [MgL]
    residual: float  # max |mirror(F_R(x)) - x| over (y, vx, vz) (rotation removed)

    def _repr_fields(self) -> dict[str, object]:
        a = self.apex
        return {"y": a.y, "vx": a.vx, "vz": a.vz, "energy": self.energy,
                "residual": self.residual}

    def to_dataframe(self) -> pd.DataFrame:
        """One row: the apex (:data:`~tslip.spatial.stride.APEX_UNITS`), ``energy`` [MgL]
        and ``residual`` [-]."""
        row = {k: getattr(self.apex, k) for k in APEX_UNITS}
        row.update(energy=self.energy, residual=self.residual)
        return frame([row], {**APEX_UNITS, "energy": "MgL", "residual": "-"})


#: Units of the multipliers' table.
MULTIPLIER_UNITS: dict[str, str] = {"real": "-", "imag": "-", "modulus": "-", "trivial": "-"}


@dataclass(frozen=True, slots=True, repr=False)
class Multipliers(Result):
    """Floquet multipliers of the two-step map at a symmetric gait (module docstring).

    A :class:`~tslip._results.Result`: its table has one row per eigenvalue of the full
    Jacobian (``trivial`` marks the ones set aside), ``plot()`` draws them in the unit
    circle.
    """

    all: np.ndarray  # eigenvalues of the 3 x 3 Jacobian of the two-step map
    nontrivial: np.ndarray  # eigenvalues of the reduced Jacobian (energy, heading removed)
    trivial: np.ndarray  # the other eigenvalues of the full Jacobian (1 in theory)
    jacobian: np.ndarray  # the 3 x 3 Jacobian
    method: str  # "exact" or "fd"

    @property
    def largest(self) -> float:
        """The largest non-trivial modulus: the gait is asymptotically stable (on its
        energy level, up to heading) when it is below 1."""
        return float(np.max(np.abs(self.nontrivial)))

    def _repr_fields(self) -> dict[str, object]:
        return {"largest": self.largest, "n_nontrivial": len(self.nontrivial),
                "method": self.method}

    def to_dataframe(self) -> pd.DataFrame:
        """The non-trivial multipliers, then the trivial ones: real and imaginary part,
        modulus, and whether it is trivial."""
        z = np.concatenate([np.asarray(self.nontrivial, dtype=complex),
                            np.asarray(self.trivial, dtype=complex)])
        triv = np.arange(len(z)) >= len(self.nontrivial)
        return frame({"real": z.real, "imag": z.imag, "modulus": np.abs(z), "trivial": triv},
                     MULTIPLIER_UNITS)

    def plot(self, ax: Axes | None = None) -> Figure:
        """The multipliers in the complex plane with the unit circle, trivial ones hollow
        (:func:`tslip.plotting.spatial.plot_multipliers`)."""
        from ..plotting.spatial import plot_multipliers

        return plot_multipliers(self.nontrivial, self.trivial, ax,
                                title=f"two-step map: max |lambda| = {self.largest:.4g}")


def _options(options: IntegratorOptions | None) -> IntegratorOptions:
    return options or IntegratorOptions.tight("dop853")


def _vx(p: SpatialParams, y: float, vz: float, energy: float | None, speed: float | None
        ) -> float:
    if speed is not None:
        return speed
    assert energy is not None
    kin = 2.0 * (energy / p.m - p.g * y) - vz * vz
    return math.sqrt(kin) if kin > 0.0 else math.nan


def two_step_map(params: SpatialParams, x: np.ndarray,
                 options: IntegratorOptions | None = None) -> np.ndarray:
    """``F_L(F_R(x))`` on the section ``(y, vx, vz)``; NaN where a step is not OK."""
    o = _options(options)
    return section_map(params, section_map(params, np.asarray(x, float), 1, o), -1, o)


def two_step_jacobian(params: SpatialParams, x: np.ndarray, method: str = "exact",
                      options: IntegratorOptions | None = None, eps: float = 1e-5
                      ) -> np.ndarray:
    """Jacobian of :func:`two_step_map` at ``x``: ``"exact"`` (variational equations) or
    ``"fd"`` (central differences of step ``eps`` times each component's scale)."""
    o = _options(options)
    x = np.asarray(x, float)
    if method == "exact":
        x1, J1 = step_jacobian(params, x, 1, o)
        _, J2 = step_jacobian(params, x1, -1, o)
        return J2 @ J1
    if method != "fd":
        raise ValueError(f"method must be 'exact' or 'fd', got {method!r}")
    J = np.empty((3, 3))
    for i in range(3):
        d = np.zeros(3)
        d[i] = eps * max(1.0, abs(x[i]))
        J[:, i] = (two_step_map(params, x + d, o) - two_step_map(params, x - d, o)) / (2 * d[i])
    return J


def floquet(gait: SymmetricGait, method: str = "exact",
            options: IntegratorOptions | None = None) -> Multipliers:
    """Floquet multipliers of the two-step map at ``gait`` (module docstring)."""
    p = gait.params
    x = gait.apex.section()
    J = two_step_jacobian(p, x, method, options)
    y, vx, vz = x
    # the energy level, coordinates (y, vz): dvx = -(g dy + vz dvz) / vx
    T = np.array([[1.0, 0.0], [-p.g / vx, -vz / vx], [0.0, 1.0]])
    if p.heading == "velocity":
        red = (J @ T)[[0], :1]  # y alone (the gait heads +x, vz = 0): the quotient by yaw
    else:
        red = (J @ T)[[0, 2], :]
    nontrivial = np.linalg.eigvals(red)
    full = np.linalg.eigvals(J)
    rest = list(full)
    for lam in nontrivial:  # remove the non-trivial ones from the full spectrum
        rest.pop(int(np.argmin([abs(r - lam) for r in rest])))
    return Multipliers(full, nontrivial, np.array(rest), J, method)


def _residual(p: SpatialParams, y: float, vz: float, energy: float | None,
              speed: float | None, o: IntegratorOptions) -> np.ndarray:
    vx = _vx(p, y, vz, energy, speed)
    if not vx > 0.0:
        return np.full(2, np.nan)
    x1 = section_map(p, np.array([y, vx, vz]), 1, o)
    return np.array([x1[0] - y, x1[2] + vz])


def _lateral(p: SpatialParams, y: float, energy: float | None, speed: float | None,
             o: IntegratorOptions, vz_max: float) -> float:
    """The ``vz`` at apex height ``y`` whose step mirrors it laterally (``vz' = -vz``): of
    the sign changes on a grid of ``[-vz_max, vz_max]``, the root nearest 0; NaN if none."""
    def f(vz: float) -> float:
        return float(_residual(p, y, vz, energy, speed, o)[1])

    grid = np.linspace(-vz_max, vz_max, 17)
    vals = [f(v) for v in grid]
    order = np.argsort(np.abs(0.5 * (grid[:-1] + grid[1:])))  # brackets nearest 0 first
    for i in order:
        a, b, fa, fb = grid[i], grid[i + 1], vals[i], vals[i + 1]
        if np.isfinite(fa) and np.isfinite(fb) and fa * fb <= 0.0:
            return float(brentq(f, a, b, xtol=1e-14, rtol=1e-14))
    return math.nan


def symmetric_gaits(params: SpatialParams, *, energy: float | None = None,
                    speed: float | None = None, n_heights: int = 60, vz_max: float = 0.6,
                    options: IntegratorOptions | None = None) -> list[SymmetricGait]:
    """All left-right symmetric gaits found by a scan of ``n_heights`` apex heights.

    Parameters
    ----------
    params : SpatialParams
    energy : float, optional
        Total energy [MgL] (one of ``energy``, ``speed``).
    speed : float, optional
        Forward speed at the apex ``vx`` [g^1/2 L^1/2].
    n_heights : int
        Apex heights scanned between the touch-down height and the top allowed
        by the energy (``energy``) or ``3 l0`` (``speed``), spaced quadratically
        (densest near the touch-down height).
    vz_max : float
        The lateral apex speeds searched lie in ``[-vz_max, vz_max]`` [g^1/2 L^1/2].
    options : IntegratorOptions, optional
        Default: dop853 at 1e-12.

    Returns
    -------
    list of SymmetricGait
        Ordered by apex height; empty if none is found.
    """
    p = params
    if (energy is None) == (speed is None):
        raise ValueError(f"symmetric_gaits needs exactly one of energy [MgL] or speed "
                         f"[g^1/2 L^1/2], got energy={energy!r}, speed={speed!r}")
    if energy is not None:
        energy = float(check_number(energy, "energy", unit="MgL", lower=0.0, lower_open=True))
        y_top = energy / (p.m * p.g)
    else:
        speed = float(check_number(speed, "speed", unit="g^1/2 L^1/2", lower=0.0,
                                   lower_open=True))
        y_top = 3.0 * p.l0
    n_heights = int(check_number(n_heights, "n_heights", lower=3, integer=True))
    vz_max = float(check_number(vz_max, "vz_max", lower=0.0, lower_open=True))
    o = _options(options)
    y_lo = p.touchdown_height
    # denser near the touch-down height, where the low-apex (fast) gaits lie
    ys = y_lo + (y_top - y_lo) * ((np.arange(n_heights) + 0.5) / n_heights) ** 2
    if p.heading == "velocity":
        vzs = np.zeros(len(ys))
    else:
        vzs = np.array([_lateral(p, y, energy, speed, o, vz_max) for y in ys])
    r = np.array([_residual(p, y, vz, energy, speed, o)[0] if np.isfinite(vz) else np.nan
                  for y, vz in zip(ys, vzs)])
    out = []
    for i in range(len(ys) - 1):
        if not (np.isfinite(r[i]) and np.isfinite(r[i + 1]) and r[i] * r[i + 1] <= 0.0):
            continue
        g = _refine(p, ys[i], ys[i + 1], vzs[i], vzs[i + 1], r[i], r[i + 1], energy, speed, o)
        if g is not None:
            out.append(g)
    return out


def _refine(p: SpatialParams, y0: float, y1: float, vz0: float, vz1: float, r0: float,
            r1: float, energy: float | None, speed: float | None, o: IntegratorOptions
            ) -> SymmetricGait | None:
    w = r0 / (r0 - r1) if r0 != r1 else 0.5
    y = y0 + w * (y1 - y0)
    if p.heading == "velocity":
        def fy(u: float) -> float:
            return float(_residual(p, u, 0.0, energy, speed, o)[0])
        y = float(brentq(fy, y0, y1, xtol=1e-14, rtol=1e-14))
        vz = 0.0
    else:
        sol = root(lambda u: _residual(p, u[0], u[1], energy, speed, o),
                   np.array([y, vz0 + w * (vz1 - vz0)]), method="hybr", tol=1e-14)
        # hybr may report "no further improvement" at the root itself: judge the residual
        if not (np.all(np.abs(sol.fun) < 1e-10)
                and min(y0, y1) - 1e-9 <= sol.x[0] <= max(y0, y1) + 1e-9):
            return None
        y, vz = float(sol.x[0]), float(sol.x[1])
    vx = _vx(p, y, vz, energy, speed)
    x = np.array([y, vx, vz])
    x1 = section_map(p, x, 1, o)
    if not float(x1[1] * vx + x1[2] * vz) > 0.0:
        return None  # the step turned the runner back (a hop to and fro, not a run)
    if p.heading == "velocity":  # undo the rotation about the vertical
        x1 = np.array([x1[0], math.hypot(x1[1], x1[2]), 0.0])
    res = float(np.max(np.abs(x1 * np.array([1.0, 1.0, -1.0]) - x)))
    if not res < 1e-8:
        return None
    E = p.m * (0.5 * (vx * vx + vz * vz) + p.g * y)
    return SymmetricGait(p, SpatialApex(y, vx, vz, side=1), E, res)
