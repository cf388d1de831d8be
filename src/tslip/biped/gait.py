"""Biped stride map, periodic-gait search, Floquet multipliers, tracking, robustness.

The Poincare section is the state just after a right-foot touch-down (Section
E.2.6). The controller is clocked by time (eqs E.25-E.27), so the section
state is ``z = (q[1:], qd, rho_R)``: eq. E.35's state without ``x_b`` plus the
right-leg phase at touch-down, which eq. E.36 leaves out. Without it a stride
whose duration differs from ``T`` would count as periodic although the next
stride starts at a different controller phase.

Over 600 lines: one concept, the biped's section map and the analyses that iterate it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .._renamed import accepts_n_strides, module_getattr, warn_renamed
from .._results import Result, frame
from ..gait._cma import ask_tell
from ..gait.stability import Floquet as _TslipFloquet
from ..gait.stability import TrivialKind, classify_stability
from ..simulation.result import Status
from . import _kernels as kn
from . import _pack as pk
from .dynamics import controller_references, leg_phase
from .parameters import BIPED_PARAMETER_TABLE, STATE_FIELDS, BipedParams, BipedState
from .simulate import BIPED_UNITS, BipedOptions, Trajectory, simulate, step

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "SECTION_FIELDS",
    "to_section",
    "from_section",
    "step_map",
    "Floquet",
    "floquet",
    "strides_until_fall",
    "TrackingErrors",
    "tracking_errors",
    "Gait",
    "find_periodic_gait",
    "refine_periodic_gait",
    "section_multipliers",
    "REFINE_OPTIONS",
    "DISTURBANCES",
    "survives_disturbance",
    "disturbed_outcome",
    "disturbance_limit",
]

SECTION_FIELDS: tuple[str, ...] = STATE_FIELDS[1:] + ("rho_R",)
NZ = 18


def _wrap(d: NDArray[np.float64]) -> NDArray[np.float64]:
    """Wrap the phase difference (last entry) to [-0.5, 0.5)."""
    d = d.copy()
    d[-1] = (d[-1] + 0.5) % 1.0 - 0.5
    return d


def to_section(params: BipedParams, y: NDArray[np.float64], t: float) -> NDArray[np.float64]:
    """Section vector ``(q[1:], qd, rho_R)`` of a state ``y`` at time ``t``."""
    return np.concatenate([np.asarray(y, dtype=np.float64)[1:], [leg_phase(params, t, 0)]])


def from_section(params: BipedParams, z: NDArray[np.float64]) -> tuple[NDArray[np.float64],
                                                                       float]:
    """State ``y`` (with ``x_b = 0``) and start time ``t0`` of a section vector."""
    z = np.asarray(z, dtype=np.float64)
    if z.shape != (NZ,):
        raise ValueError(f"section vector must have shape ({NZ},), got {z.shape}")
    y = np.concatenate([[0.0], z[:17]])
    t0 = ((z[17] - params.rho0) % 1.0) * params.T
    return y, t0


def step_map(params: BipedParams, z: NDArray[np.float64],
             options: BipedOptions | None = None) -> tuple[NDArray[np.float64], Status]:
    """One stride from section vector ``z``: the next section vector and status."""
    y, t0 = from_section(params, z)
    res = step(params, y, t0, options=options)
    if res.status != Status.OK:
        return np.full(NZ, np.nan), res.status
    return to_section(params, res.state, res.t), res.status


@dataclass(frozen=True, repr=False)
class Floquet(_TslipFloquet):
    """Multipliers of the linearised stride map at a section vector.

    The TSLIP's :class:`tslip.gait.Floquet` (its fields, :attr:`stable`,
    :attr:`magnitudes` and stability rule), at the biped's section, with:

    Attributes
    ----------
    multipliers : ndarray, shape (17,), complex
        Multipliers of the reduced map (section without ``z_b``, see
        :func:`section_multipliers`), sorted by decreasing magnitude. The
        18-dimensional map only adds a zero multiplier for ``z_b``. None is
        trivial (``trivial`` all False): nothing is conserved.
    jacobian : ndarray, shape (17, 17)
        Jacobian of the reduced map ``w -> P(z(w))[1:]``, ``w = z[1:]``.
    max_nontrivial : float
        Largest magnitude (NaN, and ``stability`` "unstable", if a perturbed
        stride fell).
    residual : float
        ``|P(z) - z|`` (phase wrapped); near zero only at a periodic gait.
    z : ndarray, shape (18,)
        The section vector.
    """

    residual: float = math.nan
    z: NDArray[np.float64] = field(default_factory=lambda: np.full(NZ, np.nan), repr=False)

    @property
    def largest(self) -> float:
        """Deprecated name of :attr:`max_nontrivial` (removed in tslip 0.4)."""
        warn_renamed("Floquet.largest", "Floquet.max_nontrivial")
        return self.max_nontrivial


def _on_section(params: BipedParams, z: NDArray[np.float64]) -> NDArray[np.float64]:
    """``z`` with the phase wrapped and ``z_b`` restored to the section constraint."""
    z = np.array(z, dtype=np.float64)
    z[17] %= 1.0
    z[0] = _ground_height(params, from_section(params, z)[0])
    return z


def _reduced_jacobian(params: BipedParams, z: NDArray[np.float64], step: float,
                      central: bool, options: BipedOptions
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64], Status]:
    """Jacobian of ``w -> P(z(w))[1:]`` by finite differences on the section.

    Every perturbed start is put back on the section (right foot on the
    ground), so the columns are derivatives along the section. Step
    ``step * max(1, |w_j|)``. Returns ``(A, P(z), status)``; ``A`` is NaN
    where a perturbed stride falls.
    """
    z = _on_section(params, z)
    z1, st = step_map(params, z, options)
    A = np.empty((NZ - 1, NZ - 1))
    for j in range(1, NZ):
        h = step * max(1.0, abs(z[j]))
        zp = z.copy()
        zp[j] += h
        zp1, _ = step_map(params, _on_section(params, zp), options)
        if central:
            zm = z.copy()
            zm[j] -= h
            zm1, _ = step_map(params, _on_section(params, zm), options)
            A[:, j - 1] = _wrap(zp1 - zm1)[1:] / (2 * h)
        else:
            A[:, j - 1] = _wrap(zp1 - z1)[1:] / h
    return A, z1, st


def _sorted_eigvals(A: NDArray[np.float64]) -> NDArray[np.complex128]:
    if not np.all(np.isfinite(A)):
        return np.full(A.shape[0], np.nan + 0j)
    ev = np.linalg.eigvals(A).astype(np.complex128)
    return ev[np.argsort(-np.abs(ev))]


_NOT_TRIVIAL: TrivialKind = ""
_NONE_TRIVIAL = (_NOT_TRIVIAL,) * (NZ - 1)  # the biped's map conserves nothing


def floquet(params: BipedParams, z: NDArray[np.float64], *, eps: float = 1e-5,
            options: BipedOptions | None = None, unit_tol: float = 1e-6) -> Floquet:
    """Floquet multipliers of the stride map on the touch-down section.

    Central differences of the reduced map of :func:`section_multipliers`:
    ``z_b`` is eliminated by the section constraint (the right foot is on the
    ground) and restored after every perturbation, so the multipliers are
    those of the map on the section. (Perturbing ``z_b`` off the section, as
    an earlier version did, starts strides with the foot in or above the
    ground and gives wrong multipliers.) Step ``eps * max(1, |z_j|)``;
    integrator ``options`` default to :data:`REFINE_OPTIONS` (the map's
    integration noise must be far below ``eps``). A run that falls within a
    perturbed stride gives NaN multipliers. Magnitudes within ``unit_tol`` of
    1 count as neutral (the TSLIP's rule, :func:`tslip.gait.stability.classify_stability`).
    """
    options = options or REFINE_OPTIONS
    z = _on_section(params, np.asarray(z, dtype=np.float64))
    A, z1, st = _reduced_jacobian(params, z, eps, True, options)
    ev = _sorted_eigvals(A)
    res = float(np.linalg.norm(_wrap(z1 - z))) if st == Status.OK else math.inf
    largest = float(np.abs(ev[0]))
    return Floquet(multipliers=ev, trivial=np.zeros(ev.size, dtype=bool),
                   max_nontrivial=largest, stability=classify_stability(largest, unit_tol),
                   jacobian=A, method="fd", trivial_kinds=_NONE_TRIVIAL[: ev.size], residual=res,
                   z=z)


def strides_until_fall(params: BipedParams, state: BipedState | NDArray[np.float64],
                       t0: float = 0.0, max_strides: int = 50,
                       options: BipedOptions | None = None) -> tuple[int, Trajectory]:
    """Completed strides before a fall (``max_strides`` if none), and the run."""
    tr = simulate(params, state, max_strides, t0=t0, options=options)
    return tr.n_steps, tr


@dataclass(frozen=True)
class TrackingErrors:
    """RMS and max controller tracking errors over a run (Figure E.2).

    ``thigh_ref_range`` [L] and ``hip_ref_range`` [rad]: max - min of each
    reference over the same samples, the scale that makes the two errors
    comparable (an error in L against one in rad); NaN if not computed.
    """

    thigh_rms: float
    thigh_max: float
    hip_rms: float
    hip_max: float
    shank_range: tuple[float, float]
    thigh_ref_range: float = math.nan
    hip_ref_range: float = math.nan


def tracking_errors(tr: Trajectory, leg: int = 0, t_from: float = -math.inf,
                    t_to: float = math.inf) -> TrackingErrors:
    """Thigh-length and hip-angle tracking errors of a leg (eqs E.29, E.32)."""
    m = (tr.time >= t_from) & (tr.time <= t_to)
    t = tr.time[m]
    side = "R" if leg == 0 else "L"
    ref = controller_references(tr.params, leg_phase(tr.params, t, leg))
    e_l = tr[f"l_t{side}"][m] - ref[:, 0]
    e_h = tr[f"theta_h{side}"][m] - ref[:, 2]
    ls = tr[f"l_s{side}"][m]
    return TrackingErrors(float(np.sqrt(np.mean(e_l**2))), float(np.abs(e_l).max()),
                          float(np.sqrt(np.mean(e_h**2))), float(np.abs(e_h).max()),
                          (float(ls.min()), float(ls.max())),
                          float(np.ptp(ref[:, 0])) if t.size else math.nan,
                          float(np.ptp(ref[:, 2])) if t.size else math.nan)


@dataclass(frozen=True, repr=False)
class Gait(Result):
    """A periodic gait of the biped: the outcome of :func:`find_periodic_gait`.

    Never raised on non-convergence. The biped's counterpart of
    :class:`tslip.Gait` (both are :class:`tslip.protocols.GaitLike`).

    Attributes
    ----------
    converged : bool
        Residual below ``tol``.
    residual : float
        Best ``|P(z) - z|`` reached.
    z : ndarray, shape (18,)
        Best section vector.
    params : BipedParams
        Parameters with the best free parameter values.
    message : str
    evaluations : int
    history : list of float
        Best residual after each stage.
    """

    converged: bool
    residual: float
    z: NDArray[np.float64]
    params: BipedParams
    message: str
    evaluations: int
    history: list[float] = field(default_factory=list)
    multipliers: NDArray[np.complex128] | None = field(default=None, repr=False)

    def _repr_fields(self) -> dict[str, Any]:
        return {"converged": self.converged, "residual": self.residual,
                "evaluations": self.evaluations}

    def to_dataframe(self) -> pd.DataFrame:
        """One row: the section vector (:data:`SECTION_FIELDS`) and the search's outcome."""
        row: dict[str, Any] = dict(zip(SECTION_FIELDS, np.asarray(self.z).tolist()))
        row.update(residual=self.residual, converged=self.converged,
                   evaluations=self.evaluations, message=self.message)
        return frame([row], BIPED_UNITS)

    def plot(self, ax: Axes | None = None) -> Figure:
        """The right foot's path relative to the hip over one stride of the gait."""
        from ..plotting.biped import plot_foot_path

        y, t0 = from_section(self.params, self.z)
        return plot_foot_path(simulate(self.params, y, 1, t0=t0), ax=ax)


#: Free section entries of the thesis search (starred in Table E.2): pitch
#: rate, right-leg rates and the whole left leg.
THESIS_FREE_STATE: tuple[str, ...] = (
    "theta_b_d", "l_tR_d", "l_sR_d", "theta_hR_d", "l_tL", "l_sL", "theta_hL", "l_tL_d",
    "l_sL_d", "theta_hL_d",
)


def find_periodic_gait(
    params: BipedParams,
    z0: NDArray[np.float64],
    *,
    free_state: Sequence[str] = THESIS_FREE_STATE + ("rho_R",),
    free_params: Sequence[str] = (),
    bounds: dict[str, tuple[float, float]] | None = None,
    cma_evals: int = 600,
    sigma0: float = 0.05,
    lsq_evals: int = 200,
    tol: float = 1e-8,
    seed: int = 1,
    options: BipedOptions | None = None,
    objective: Any = None,
) -> Gait:
    """Search a periodic gait: CMA-ES (``cma``) then least squares on the stride map.

    The residual is ``P(z) - z`` on the section (eq. E.36 plus the phase).
    The right foot stays on the ground at the start: ``z_b`` follows from
    the other coordinates. ``objective`` (optional) adds a scalar penalty to
    the CMA-ES cost (used by the stable-gait search).

    Returns
    -------
    Gait
        With ``converged=False`` and the best residual when the search stalls.
    """
    from scipy.optimize import least_squares

    names = list(free_state) + list(free_params)
    bad = [n for n in free_state if n not in SECTION_FIELDS]
    bad += [n for n in free_params if not hasattr(params, n)]
    if bad:
        raise ValueError(f"unknown free variable(s) {bad}")
    if not names:
        raise ValueError("no free variables given")
    idx = [SECTION_FIELDS.index(n) for n in free_state]
    z0 = np.asarray(z0, dtype=np.float64)
    x0 = np.concatenate([z0[idx], [float(getattr(params, n)) for n in free_params]])
    bounds = bounds or {}
    lo = np.array([bounds.get(n, (-np.inf, np.inf))[0] for n in names])
    hi = np.array([bounds.get(n, (-np.inf, np.inf))[1] for n in names])
    nev = [0]

    def unpack(x: NDArray[np.float64]) -> tuple[BipedParams, NDArray[np.float64]]:
        p = params.replace(**{n: float(v) for n, v in zip(free_params, x[len(idx):],
                                                           strict=True)})
        z = z0.copy()
        z[idx] = x[: len(idx)]
        z[17] %= 1.0
        y, _ = from_section(p, z)
        z[0] = _ground_height(p, y)
        return p, z

    def residual(x: NDArray[np.float64]) -> NDArray[np.float64]:
        nev[0] += 1
        try:
            p, z = unpack(x)
        except ValueError:
            return np.full(NZ, 10.0)
        z1, st = step_map(p, z, options)
        if st != Status.OK:
            return np.full(NZ, 10.0)
        return _wrap(z1 - z)

    def cost(x: NDArray[np.float64]) -> float:
        r = residual(x)
        c = float(r @ r)
        if objective is not None and c < 1.0:
            c += float(objective(*unpack(x)))
        return c

    history: list[float] = []
    best_x = x0
    best = float(np.linalg.norm(residual(x0)))
    history.append(best)
    if cma_evals > 0:
        finite = np.isfinite(lo) & np.isfinite(hi)  # one open side: CMA-ES leaves it free
        xb, _, _, _, _ = ask_tell(
            lambda X: [cost(x) for x in X], x0, sigma0, seed=seed, max_evals=cma_evals,
            tolerances={"tolfun": 1e-14},
            lower=np.where(finite, lo, -np.inf) if finite.any() else None,
            upper=np.where(finite, hi, np.inf) if finite.any() else None)
        rb = float(np.linalg.norm(residual(xb)))
        if rb < best:
            best, best_x = rb, xb
        history.append(best)
    if lsq_evals > 0 and best < 10.0:
        lb = np.where(np.isfinite(lo), lo, -np.inf)
        ub = np.where(np.isfinite(hi), hi, np.inf)
        xs = np.clip(best_x, lb + 1e-12, ub - 1e-12)
        sol = least_squares(residual, xs, bounds=(lb, ub), max_nfev=lsq_evals, xtol=1e-15,
                            ftol=1e-15, gtol=1e-15, diff_step=1e-7)
        rb = float(np.linalg.norm(residual(sol.x)))
        if rb < best:
            best, best_x = rb, sol.x
        history.append(best)
    p, z = unpack(best_x)
    ok = best < tol
    msg = (f"periodic gait found, residual {best:.2e}" if ok else
           f"no periodic gait to tolerance {tol:g}: best residual {best:.2e}")
    return Gait(ok, best, z, p, msg, nev[0], history)


def _ground_height(p: BipedParams, y: NDArray[np.float64]) -> float:
    """``z_b`` that puts the right foot at the ground (section constraint)."""
    P = pk.pack_params(p)
    _, zf, _, _ = kn.foot_state(P, y, 0)
    return float(y[1] - zf)


#: Integrator options of the Newton refinement: tighter than the thesis's 1e-8
#: so that the stride map is smooth well below the 1e-8 residual target; the
#: 8th-order pair takes 2.5 times fewer steps than dopri5 at this tolerance
#: (``benchmarks/bench_biped.py``).
REFINE_OPTIONS = BipedOptions(rtol=1e-11, atol=1e-11, max_steps=200_000, stride_time_max=3.0,
                              method="dop853")


def refine_periodic_gait(
    params: BipedParams,
    z0: NDArray[np.float64],
    *,
    free_params: Sequence[str] = ("T", "theta_f", "theta_s", "Kp_h", "Kd_h"),
    tol: float = 1e-8,
    max_iter: int = 30,
    fd_step: float = 1e-6,
    options: BipedOptions | None = None,
    multipliers: bool = True,
) -> Gait:
    """Drive ``|P(z) - z|`` below ``tol`` by Levenberg-Marquardt shooting.

    Well-posed section: every section entry except ``z_b`` is free (``z_b``
    follows from the right foot being on the ground, and its residual from
    the others), i.e. 17 unknowns for the 17 independent equations of
    ``P(z) = z`` including the controller phase ``rho_R`` (which forces the
    stride to last exactly ``T``). ``free_params`` adds parameters (as the
    thesis frees starred parameters); the system is then underdetermined and
    the step starts Levenberg-Marquardt damped (``mu = 1e-6``, scaled by
    ``diag(J^T J)``) and becomes the minimum-norm Gauss-Newton step as ``mu``
    falls; the damping picks the gait found (see the report). The Jacobian is
    a forward difference with step ``fd_step * max(1, |x|)`` at
    :data:`REFINE_OPTIONS` tolerances. Never raises on non-convergence.

    With ``multipliers`` the Floquet multipliers of the reduced 17-dimensional
    map (section without ``z_b``) are computed at the result by
    :func:`section_multipliers` (central differences, 34 extra strides); the
    18-dimensional map adds a zero.
    """
    options = options or REFINE_OPTIONS
    free_params = tuple(free_params)
    bad = [n for n in free_params if n not in {r.name for r in BIPED_PARAMETER_TABLE}]
    if bad:
        raise ValueError(f"unknown free parameter(s) {bad}")
    z0 = np.asarray(z0, dtype=np.float64)
    if z0.shape != (NZ,):
        raise ValueError(f"section vector must have shape ({NZ},), got {z0.shape}")
    x = np.concatenate([z0[1:], [float(getattr(params, n)) for n in free_params]])
    nev = [0]

    def unpack(x: NDArray[np.float64]) -> tuple[BipedParams, NDArray[np.float64]]:
        p = params.replace(**{n: float(v) for n, v in zip(free_params, x[NZ - 1:],
                                                           strict=True)})
        z = np.concatenate([[0.0], x[: NZ - 1]])
        z[17] %= 1.0
        y, _ = from_section(p, z)
        z[0] = _ground_height(p, y)
        return p, z

    def res(x: NDArray[np.float64]) -> NDArray[np.float64] | None:
        nev[0] += 1
        try:
            p, z = unpack(x)
        except ValueError:
            return None
        z1, st = step_map(p, z, options)
        return None if st != Status.OK else _wrap(z1 - z)

    def jac(x: NDArray[np.float64], r: NDArray[np.float64], cols: int) -> NDArray[np.float64]:
        J = np.empty((NZ, cols))
        for j in range(cols):
            h = fd_step * max(1.0, abs(x[j]))
            xp = x.copy()
            xp[j] += h
            rp = res(xp)
            if rp is None:
                xp[j] -= 2 * h
                h = -h
                rp = res(xp)
            J[:, j] = np.nan if rp is None else (rp - r) / h
        return J

    r = res(x)
    if r is None:
        return Gait(False, math.inf, z0, params,
                                "no periodic gait: the start state falls within a stride",
                                nev[0], [math.inf])
    n = float(np.linalg.norm(r))
    history = [n]
    mu = 1e-6
    for _ in range(max_iter):
        if n <= tol:
            break
        J = jac(x, r, x.size)
        if not np.all(np.isfinite(J)):
            break
        improved = False
        for _ in range(10):
            if mu <= 1e-9:
                dx = np.linalg.lstsq(J, -r, rcond=None)[0]
            else:
                A = J.T @ J
                dx = np.linalg.solve(A + mu * np.diag(np.diag(A) + 1e-12), -J.T @ r)
            rn = res(x + dx)
            if rn is not None and float(np.linalg.norm(rn)) < n:
                x, r, n = x + dx, rn, float(np.linalg.norm(rn))
                mu = max(mu / 10.0, 1e-10)
                improved = True
                break
            mu = max(10.0 * mu, 1e-4)
        history.append(n)
        if not improved:
            break
    p, z = unpack(x)
    ev = None
    if multipliers and math.isfinite(n):
        ev = section_multipliers(p, z, options=options)
    ok = n <= tol
    msg = (f"periodic gait found, residual {n:.2e}" if ok else
           f"no periodic gait to tolerance {tol:g}: best residual {n:.2e}")
    return Gait(ok, n, z, p, msg, nev[0], history, ev)


def section_multipliers(params: BipedParams, z: NDArray[np.float64], *,
                        fd_step: float = 1e-5, central: bool = True,
                        options: BipedOptions | None = None) -> NDArray[np.complex128]:
    """Multipliers of the reduced stride map ``w -> P(z(w))[1:]``, ``w = z[1:]``.

    ``z_b`` is eliminated by the section constraint (right foot on the
    ground), so these are the 17 non-trivial multipliers; sorted by
    decreasing magnitude. Central (or, with ``central=False``, forward)
    differences with step ``fd_step * max(1, |w_j|)`` at ``options`` (default
    :data:`REFINE_OPTIONS`); NaN if a perturbed stride falls. At the stored
    gait the largest magnitude changes by 3e-5 between central steps 1e-5 and
    1e-4; below 1e-5 the integration noise shows (2e-4 at 1e-6).
    """
    options = options or REFINE_OPTIONS
    A, _, _ = _reduced_jacobian(params, z, fd_step, central, options)
    return _sorted_eigvals(A)


#: Disturbances of the robustness search (docs/conventions.md, "Disturbances for
#: robustness", adapted to the biped): magnitudes are signed by ``sign``.
DISTURBANCES: tuple[str, ...] = ("step_down", "push", "pitch_rate")


@accepts_n_strides
def survives_disturbance(params: BipedParams, z: NDArray[np.float64], kind: str,
                         value: float, n_steps: int = 25,
                         options: BipedOptions | None = None) -> tuple[bool, str]:
    """Run ``n_steps`` from the gait ``z`` with one disturbance; (survived, status).

    The run of :func:`disturbed_outcome`; the status is its name, or
    ``"NO_FLIGHT"`` if a step-down finds no flight phase to be placed in.
    """
    st, done = disturbed_outcome(params, z, kind, value, n_steps, options)
    if st is None:
        return False, "NO_FLIGHT"
    return done >= n_steps, st.name


def disturbed_outcome(params: BipedParams, z: NDArray[np.float64], kind: str, value: float,
                      n_steps: int = 25, options: BipedOptions | None = None
                      ) -> tuple[Status | None, int]:
    """``(status, strides done)`` of ``n_steps`` strides from the gait ``z``, disturbed once.

    ``step_down``: the ground is shifted by ``value`` [L] (negative: down)
    for every touch-down after the first right stance (the body is shifted by
    ``-value`` in the middle of the first flight phase after a lift-off).
    ``push``: ``value`` added to ``xd_b`` of the section state.
    ``pitch_rate``: ``value`` added to the body pitch rate with the leg
    (absolute) angular rates kept, i.e. subtracted from both hip-angle rates.
    The status is ``None`` if a step-down finds no flight phase; a fall in
    the first right stance of a step-down has 0 strides done.
    """
    if kind not in DISTURBANCES:
        raise ValueError(f"unknown disturbance {kind!r}; known: {list(DISTURBANCES)}")
    y, t0 = from_section(params, z)
    if kind == "push":
        y[9] += value
    elif kind == "pitch_rate":
        y[11] += value
        y[14] -= value
        y[17] -= value
    if kind != "step_down":
        tr = simulate(params, y, n_steps, t0=t0, options=options)
        return tr.status, tr.n_steps
    # first right stance on the original ground; cut in the middle of the first
    # interval after a lift-off in which both feet are in the air
    first = simulate(params, y, 1, t0=t0, options=options)
    t_cut = math.inf
    evs = first.events
    for i, e in enumerate(evs[:-1]):
        if e.kind.startswith("liftoff"):
            tm = 0.5 * (e.t + evs[i + 1].t)
            row = min(int(first.time.searchsorted(tm)), first.data.shape[0] - 1)
            if first["contact_R"][row] == 0.0 and first["contact_L"][row] == 0.0:
                t_cut = tm
                break
    if not math.isfinite(t_cut):
        return None, 0
    part = simulate(params, y, 1, t0=t0, t_end=t_cut, options=options)
    if part.status != Status.T_END:
        return part.status, 0
    y1 = part.final_state.copy()
    y1[1] -= value
    tr = simulate(params, y1, n_steps, t0=float(part.stats["t_end"]),
                  contact=part.final_contact, options=options)
    return tr.status, tr.n_steps


@accepts_n_strides
def disturbance_limit(params: BipedParams, z: NDArray[np.float64], kind: str, *,
                      sign: float = -1.0, n_steps: int = 25, tol: float = 1e-3,
                      options: BipedOptions | None = None) -> Any:
    """Largest survivable magnitude of a disturbance (``tslip.gait.robustness.limit_search``).

    Returns the :class:`~tslip.gait.robustness.LimitSearch`; the signed
    limit is ``sign * result.lo``.
    """
    from ..gait.robustness import limit_search
    from .robustness import GRID_STEPS

    if kind not in DISTURBANCES:
        raise ValueError(f"unknown disturbance {kind!r}; known: {list(DISTURBANCES)}")
    def survives(m: NDArray[np.float64]) -> NDArray[np.bool_]:
        return np.array([survives_disturbance(params, z, kind, sign * float(v), n_steps,
                                              options)[0] for v in np.ravel(m)])

    return limit_search(survives, h=GRID_STEPS[kind], tol=tol, ladder=8, k=1,
                        max_magnitude=10.0)


#: Old names (deprecated, removed in 0.4): docs/model.md, "Vocabulary".
__getattr__ = module_getattr(__name__, {
    "stride_map": ("tslip.biped.gait.step_map", lambda: step_map),
    "FloquetResult": ("tslip.biped.gait.Floquet", lambda: Floquet),
    "GaitSearchResult": ("tslip.biped.gait.Gait", lambda: Gait),
})
