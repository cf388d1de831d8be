"""Floquet multipliers of the touch-down map (thesis Section 3.1.2, Appendix B).

The multipliers are the eigenvalues of the Jacobian ``A = dP/dq`` of the
stride map on the 5-D section ``q = (beta, phi, xd, yd, phid)`` at a fixed
point (eqs B.1-B.4). Two ways to get ``A``:

* ``method="exact"``: variational equations through the Dormand-Prince steps
  plus saltation terms at lift-off and touch-down
  (:func:`tslip.simulation.step_jacobian`); for a power-law leg with an error
  control of its own, as exact for ``1 < n < 2`` (a stance that ends where the
  spring force and its non-smooth stiffness ``|x|^(n-1)`` vanish) as for ``n = 1``;
  ``n < 1`` has none and falls back to ``"fd"``;
* ``method="fd"``: first-order central differences, eq. B.2: ten strides.

A conservative model (passive without damping) keeps its energy, so ``A`` has
the multiplier 1 with the energy gradient as left eigenvector: a structural
("trivial") multiplier, excluded from the largest multiplier as in eq. 2.21.

With ``r = 0`` and a hip torque that does not depend on the pitch, the pitch
decouples (:func:`pitch_decoupled`): ``phi`` and ``phid`` pass through a
stride as ``(phi + phid T, phid)``, a Jordan block with two multipliers exactly
1. The stability is then evaluated on the section that excludes the decoupled
pitch, ``(beta, xd, yd)``, and the two pitch multipliers are reported as
trivial (docs/conventions.md, "Poincare section and periodic gaits").

``section="apex"``: the multipliers of the apex return map on ``(y, xd, phi,
phid)`` (:mod:`tslip.gait.section`), ``A_apex = dpi/dq A dsigma/da`` with the
closed-form derivatives of the touch-down -> apex (``pi``) and apex ->
touch-down (``sigma``) conversions, or by central differences of the apex
map itself (``method="fd"``). They are the touch-down multipliers without the
one that is exactly 0 when the touch-down angle follows from the rest of the
state (a leg set at a fixed angle): return maps of one flow on two sections
are conjugate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from scipy.linalg import lapack

from .._results import Result, frame
from ..model import _pack as pk
from ..model.parameters import Params
from ..simulation import _packed
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status
from .fixed_point import TIGHT, Gait
from .section import (
    apex_map_states,
    apex_to_touchdown,
    apex_to_touchdown_jacobian,
    touchdown_to_apex,
    touchdown_to_apex_jacobian,
)

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["Floquet", "floquet", "eigvals", "map_jacobian", "apex_jacobian", "conserved_gradients",
           "pitch_decoupled", "nontrivial_jacobian", "classify_stability"]

Stability = Literal["asymptotic", "neutral", "unstable"]
TrivialKind = Literal["", "energy", "pitch"]
#: Indices of the section without the pitch: (beta, xd, yd) of (beta, phi, xd, yd, phid).
_NO_PITCH = [0, 2, 3]
#: The same on the apex section (y, xd, phi, phid): (y, xd).
_NO_PITCH_APEX = [0, 1]


@dataclass(frozen=True, repr=False)
class Floquet(Result):
    """Floquet multipliers of a periodic gait.

    Attributes
    ----------
    multipliers : ndarray of complex, shape (5,) or (4,)
        Eigenvalues of the stride map's Jacobian, largest magnitude first
        (4 on the apex section).
    trivial : ndarray of bool, shape (5,)
        Structural multipliers at 1: the conserved energy, and the decoupled
        pitch (:func:`pitch_decoupled`).
    max_nontrivial : float
        Largest magnitude among the others.
    stability : {"asymptotic", "neutral", "unstable"}
        From the non-trivial multipliers only: a conservative gait labelled
        "asymptotic" is asymptotically stable on its energy level (a change
        of energy moves it to the neighbouring gait of its family).
    jacobian : ndarray, shape (5, 5) or (4, 4)
    method : str
        The method used: ``"exact"`` or ``"fd"``, also when ``"exact"`` was asked for
        and fell back (a leg spring exponent below 1, :func:`floquet`).
    trivial_kinds : tuple of str, length 5
        Why each multiplier is trivial: ``"energy"``, ``"pitch"`` (two, with
        the stability evaluated on the section without the pitch), or ``""``.
    """

    multipliers: np.ndarray
    trivial: np.ndarray
    max_nontrivial: float
    stability: Stability
    jacobian: np.ndarray = field(repr=False)
    method: str = "exact"
    trivial_kinds: tuple[TrivialKind, ...] = ()
    section: str = "touchdown"

    def _repr_fields(self) -> dict[str, Any]:
        return {"stability": self.stability, "max_nontrivial": self.max_nontrivial,
                "method": self.method}

    def to_dataframe(self) -> pd.DataFrame:
        """One row per multiplier, largest first: parts, magnitude, whether and why trivial."""
        m = np.asarray(self.multipliers)
        kinds = list(self.trivial_kinds) or [""] * len(m)
        return frame({"k": np.arange(1, len(m) + 1), "real": m.real, "imag": m.imag,
                      "abs": np.abs(m), "trivial": np.asarray(self.trivial, dtype=bool),
                      "trivial_kind": kinds}, dict.fromkeys(
                          ("k", "real", "imag", "abs", "trivial", "trivial_kind"), "-"))

    def plot(self, ax: Axes | None = None) -> Figure:
        """The multipliers in the complex plane with the unit circle."""
        from ..plotting.results import plot_floquet

        return plot_floquet(self, ax)

    @property
    def magnitudes(self) -> np.ndarray:
        """``|multipliers|``."""
        return np.abs(self.multipliers)

    @property
    def stable(self) -> bool:
        """At least neutrally stable (the thesis's condition for robustness)."""
        return self.stability != "unstable"


def eigvals(A: np.ndarray) -> np.ndarray:
    """Eigenvalues of the real square matrix ``A`` (complex), as ``np.linalg.eigvals``.

    Both call LAPACK's ``dgeev`` without eigenvectors; this calls it through
    scipy's wrapper, a third of ``np.linalg.eigvals``'s cost on a 5 x 5 (most
    of that is numpy's argument handling), which is most of the cost of
    :func:`floquet` once the Jacobian is known. Raises
    ``np.linalg.LinAlgError`` for infs or NaNs, as numpy does.
    """
    A = np.asarray(A, dtype=float)
    if not np.isfinite(A).all():
        raise np.linalg.LinAlgError("Array must not contain infs or NaNs")
    if A.size == 0:
        return np.empty(0, dtype=complex)
    wr, wi, _, _, info = lapack.dgeev(A, compute_vl=0, compute_vr=0)
    if info != 0:
        raise np.linalg.LinAlgError("Eigenvalues did not converge")
    return wr + 1j * wi


def classify_stability(max_nontrivial: float, unit_tol: float = 1e-6) -> Stability:
    """The stability rule of both models' :class:`Floquet` (eq. 2.21's largest multiplier).

    "unstable" above ``1 + unit_tol`` (and for NaN: a perturbed stride fell),
    "neutral" within ``unit_tol`` of 1, "asymptotic" below.
    """
    if not max_nontrivial <= 1.0 + unit_tol:
        return "unstable"
    return "neutral" if max_nontrivial >= 1.0 - unit_tol else "asymptotic"


def conserved_gradients(params: Params, q: np.ndarray) -> list[np.ndarray]:
    """Gradients on the section of the quantities the stride map conserves.

    Energy ``E = m (xd^2 + yd^2)/2 + J phid^2/2 + m g (l0 sin beta - r cos phi)``
    when nothing dissipates or adds work (no torque, no leg damping, no leg
    thrust); the pitch rate too when in addition ``r = 0``.
    """
    p = params
    no_torque = not any(p.controller.torque_coefficients())
    if not (no_torque and p.c_l == 0.0 and p.leg_thrust == 0.0):
        return []
    b, ph, xd, yd, phd = q
    grads = [np.array([p.m * p.g * p.l0 * math.cos(b), p.m * p.g * p.r * math.sin(ph),
                       p.m * xd, p.m * yd, p.J * phd])]
    if p.r == 0.0:
        grads.append(np.array([0.0, 0.0, 0.0, 0.0, 1.0]))
    return grads


def pitch_decoupled(params: Params) -> bool:
    """Whether the pitch decouples from the stride map's other section variables.

    True when ``r = 0`` (the CoM at the hip: gravity exerts no pitch moment)
    and the hip torque ``a0 + a1 phi + a2 betad + a3 phid`` does not depend on
    the pitch (``a1 = a3 = 0``), and in addition either exerts no torque at
    all or the leg resets in the inertial frame (``leg_reset="global"``, so
    the touch-down angle does not depend on ``phi``). Then the Jacobian on
    ``(beta, phi, xd, yd, phid)`` is block triangular with the pitch block
    ``[[1, T], [0, 1]]`` (``T`` the stride time; ``phid = 0`` at a fixed
    point). Controllers: :class:`~tslip.model.controllers.Passive` always;
    ``ConstantTorque`` with ``c_h = 0`` under the global reset; ``GlobalPD``
    and ``LocalVelocity`` only with zero gains.
    """
    a0, a1, a2, a3 = params.controller.torque_coefficients()
    if params.r != 0.0 or a1 != 0.0 or a3 != 0.0:
        return False
    return (a0 == 0.0 and a2 == 0.0) or params.leg_reset == "global"


def nontrivial_jacobian(params: Params, q: np.ndarray, A: np.ndarray) -> np.ndarray:
    """The stride map's Jacobian ``A`` at ``q`` with its structural multipliers removed.

    Without the decoupled pitch (:func:`pitch_decoupled`), then restricted to
    the kernel of the conserved energy's gradient, which is invariant at a
    fixed point and nearly so near one (the eq. 2.21 cost of the gait search).
    """
    grads = conserved_gradients(params, q)
    if pitch_decoupled(params):
        A = A[np.ix_(_NO_PITCH, _NO_PITCH)]
        grads = [gr[_NO_PITCH] for gr in grads[:1]]  # the energy; the pitch rate went above
    if grads:
        Q = np.linalg.svd(np.array(grads))[2][len(grads):].T  # orthonormal basis of ker
        A = Q.T @ A @ Q
    return A


def map_jacobian(
    params: Params,
    q: np.ndarray,
    *,
    method: Literal["exact", "fd"] = "exact",
    step: float = 1e-5,
    options: IntegratorOptions | None = None,
) -> np.ndarray:
    """Jacobian of the stride map at ``q`` (5 x 5), exact or by eq. B.2.

    Default options: tolerance 1e-12 with DOP853 (about 2.5 times faster than
    dopri5 at this tolerance). The inputs are checked and packed once; the
    strides run on the packed arrays (:mod:`tslip.simulation._packed`), the
    ten of ``"fd"`` one after another in the calling thread.
    """
    options = options or TIGHT
    q = np.asarray(q, dtype=float)
    if q.shape != (5,) or not np.isfinite(q).all():
        raise ValueError(f"q (beta, phi, xd, yd, phid) must be 5 finite numbers, got {q!r}")
    if method not in ("exact", "fd"):
        raise ValueError(f"method must be 'exact' or 'fd', got {method!r}")
    P, O = pk.pack_params(params), options.packed()  # noqa: E741 - the kernels' names
    out = np.empty(pk.NOUT)
    if method == "exact":
        J = np.empty((5, 5))
        st = Status(_packed.stride_jacobian(P, O, q, 0.0, J, out))
        if st != Status.OK:
            raise ValueError(f"the stride from this state fails: {st.reason}")
        return J
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"step must be in (0, inf), got {step!r}")
    E = np.eye(5) * step
    nxt = np.empty((10, 5))
    for i, row in enumerate(np.vstack([q + E, q - E])):
        if _packed.stride_map(P, O, row, 0.0, out) != Status.OK:
            raise ValueError("a perturbed stride fails; use a smaller step")
        nxt[i] = out[pk.OUT_TD : pk.OUT_TD + 5]
    return (nxt[:5] - nxt[5:]).T / (2.0 * step)


def apex_jacobian(
    gait: Gait,
    *,
    method: Literal["exact", "fd"] = "exact",
    step: float = 1e-5,
    options: IntegratorOptions | None = None,
) -> np.ndarray:
    """Jacobian of the apex return map (4 x 4) at the gait's apex (module docstring).

    ``"exact"``: the touch-down map's exact Jacobian between the closed-form
    conversion derivatives; ``"fd"``: central differences of
    :func:`tslip.gait.section.apex_map_states`, one batch of 8 rows.

    Raises
    ------
    ValueError
        If the apex is no section for the gait's parameters (a retraction
        clock from lift-off) or a stride fails.
    """
    p = gait.params
    apex = touchdown_to_apex(p, gait.state)
    if method == "exact":
        td = apex_to_touchdown(p, apex)
        A = map_jacobian(p, td.section(), method="exact", options=options)
        return (touchdown_to_apex_jacobian(p, gait.state) @ A
                @ apex_to_touchdown_jacobian(p, apex, td))
    if method != "fd":
        raise ValueError(f"method must be 'exact' or 'fd', got {method!r}")
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"step must be in (0, inf), got {step!r}")
    a = apex.section()
    E = np.eye(4) * step
    b = apex_map_states(p, np.vstack([a + E, a - E]), options=options or TIGHT)
    if not np.all(b.ok):
        raise ValueError("a perturbed apex map fails; use a smaller step")
    nxt = np.column_stack([b.y, b.xd, b.phi, b.phid])
    return (nxt[:4] - nxt[4:]).T / (2.0 * step)


def floquet(
    gait: Gait,
    *,
    method: Literal["exact", "fd"] = "exact",
    step: float = 1e-5,
    options: IntegratorOptions | None = None,
    unit_tol: float = 1e-6,
    section: Literal["touchdown", "apex"] | None = None,
) -> Floquet:
    """Floquet multipliers and stability of a periodic gait.

    Parameters
    ----------
    gait : Gait
        From :func:`tslip.find_gait`.
    method : {"exact", "fd"}
        Variational equations with saltation, or central differences (eq. B.2;
        on the apex section, of the apex map). ``"exact"`` for a leg spring
        exponent below 1 falls back to ``"fd"`` (its stiffness is infinite at
        touch-down; the result's ``method`` says ``"fd"``, the method used). Every
        exponent from 1 up is exact, within 1e-8 of an independent model at the
        default options for ``n`` 1.2-2.5 with and without leg damping and hip
        torque, including ``1 < n < 2`` without either, where lift-off is the zero
        of the spring force (``tests/gait/test_power_law_jacobian.py``).
    step : float
        Finite-difference step (``method="fd"``); results are insensitive to
        it between about 1e-6 and 1e-4 at the default tolerance 1e-12.
    unit_tol : float
        Magnitudes within this of 1 count as neutral.
    section : {"touchdown", "apex"}, optional
        The return map's section; default the gait's (``gait.section``). On
        the apex, 4 multipliers: the touch-down ones less the 0 of a leg set
        at a fixed angle (module docstring).

    Returns
    -------
    Floquet
    """
    section = gait.section if section is None else section
    if method == "exact" and gait.params.leg_exponent < 1.0:
        method = "fd"  # no exact Jacobian (tslip.simulation._packed.check_exact)
    if section not in ("touchdown", "apex"):
        raise ValueError(f"section must be 'touchdown' or 'apex', got {section!r}")
    q = gait.state.section()
    if section == "apex":
        A = apex_jacobian(gait, method=method, step=step, options=options)
        keep = _NO_PITCH_APEX
    else:
        A = map_jacobian(gait.params, q, method=method, step=step, options=options)
        keep = _NO_PITCH
    n = len(A)
    n_energy = len(conserved_gradients(gait.params, q)) > 0  # 0 or 1 energy multiplier
    if pitch_decoupled(gait.params):
        # the section without the decoupled pitch; its Jordan block [[1, T], [0, 1]]
        lam = np.concatenate([eigvals(A[np.ix_(keep, keep)]), [1.0, 1.0]])
        kinds: list[TrivialKind] = [""] * len(keep)
        kinds += ["pitch", "pitch"]
    else:
        lam = eigvals(A)
        kinds = [""] * n
    if n_energy:
        # the energy multiplier: the one closest to 1 (the tolerance is loose: a
        # double root at 1 splits by sqrt(eps))
        cand = [i for i in np.argsort(np.abs(lam - 1.0)) if kinds[i] == ""]
        if cand and abs(lam[cand[0]] - 1.0) < 1e-4:
            kinds[cand[0]] = "energy"
    order = np.argsort(-np.abs(lam), kind="stable")
    lam = lam[order]
    kinds = [kinds[i] for i in order]
    trivial = np.array([k != "" for k in kinds])
    others = np.abs(lam[~trivial])
    max_nt = float(others.max()) if others.size else 0.0
    stability = classify_stability(max_nt, unit_tol)
    return Floquet(multipliers=lam, trivial=trivial, max_nontrivial=max_nt,
                   stability=stability, jacobian=A, method=method,
                   trivial_kinds=tuple(kinds), section=section)
