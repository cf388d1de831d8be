"""Floquet multipliers of the touch-down map (thesis Section 3.1.2, Appendix B).

The multipliers are the eigenvalues of the Jacobian ``A = dP/dq`` of the
stride map on the 5-D section ``q = (beta, phi, xd, yd, phid)`` at a fixed
point (eqs B.1-B.4). Two ways to get ``A``:

* ``method="exact"``: variational equations through the Dormand-Prince steps
  plus saltation terms at lift-off and touch-down
  (:func:`tslip.simulation.step_jacobian`);
* ``method="fd"``: first-order central differences, eq. B.2: ten strides.

A conservative model (passive without damping) keeps its energy, so ``A`` has
the multiplier 1 with the energy gradient as left eigenvector: a structural
("trivial") multiplier, excluded from the largest multiplier as in eq. 2.21.
With ``r = 0`` and no hip torque the pitch rate is conserved too, giving a
second one (docs/conventions.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from ..model import _pack as pk
from ..model.parameters import Params
from ..simulation import _packed
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status
from .fixed_point import TIGHT, Gait

__all__ = ["Floquet", "floquet", "map_jacobian", "conserved_gradients"]

Stability = Literal["asymptotic", "neutral", "unstable"]


@dataclass(frozen=True)
class Floquet:
    """Floquet multipliers of a periodic gait.

    Attributes
    ----------
    multipliers : ndarray of complex, shape (5,)
        Eigenvalues of the stride map's Jacobian, largest magnitude first.
    trivial : ndarray of bool, shape (5,)
        Structural multipliers at 1 from conserved quantities.
    max_nontrivial : float
        Largest magnitude among the others.
    stability : {"asymptotic", "neutral", "unstable"}
    jacobian : ndarray, shape (5, 5)
    method : str
    """

    multipliers: np.ndarray
    trivial: np.ndarray
    max_nontrivial: float
    stability: Stability
    jacobian: np.ndarray = field(repr=False)
    method: str = "exact"

    @property
    def magnitudes(self) -> np.ndarray:
        """``|multipliers|``."""
        return np.abs(self.multipliers)

    @property
    def stable(self) -> bool:
        """At least neutrally stable (the thesis's condition for robustness)."""
        return self.stability != "unstable"


def conserved_gradients(params: Params, q: np.ndarray) -> list[np.ndarray]:
    """Gradients on the section of the quantities the stride map conserves.

    Energy ``E = m (xd^2 + yd^2)/2 + J phid^2/2 + m g (l0 sin beta - r cos phi)``
    when nothing dissipates or adds work (no torque, no leg damping); the pitch
    rate too when in addition ``r = 0``.
    """
    p = params
    no_torque = not any(p.controller.torque_coefficients())
    if not (no_torque and p.c_l == 0.0):
        return []
    b, ph, xd, yd, phd = q
    grads = [np.array([p.m * p.g * p.l0 * math.cos(b), p.m * p.g * p.r * math.sin(ph),
                       p.m * xd, p.m * yd, p.J * phd])]
    if p.r == 0.0:
        grads.append(np.array([0.0, 0.0, 0.0, 0.0, 1.0]))
    return grads


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
    if q.shape != (5,) or not np.all(np.isfinite(q)):
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


def floquet(
    gait: Gait,
    *,
    method: Literal["exact", "fd"] = "exact",
    step: float = 1e-5,
    options: IntegratorOptions | None = None,
    unit_tol: float = 1e-6,
) -> Floquet:
    """Floquet multipliers and stability of a periodic gait.

    Parameters
    ----------
    gait : Gait
        From :func:`tslip.find_gait`.
    method : {"exact", "fd"}
        Variational equations with saltation, or central differences (eq. B.2).
    step : float
        Finite-difference step (``method="fd"``); results are insensitive to
        it between about 1e-6 and 1e-4 at the default tolerance 1e-12.
    unit_tol : float
        Magnitudes within this of 1 count as neutral.

    Returns
    -------
    Floquet
    """
    q = gait.state.section()
    A = map_jacobian(gait.params, q, method=method, step=step, options=options)
    lam, W = np.linalg.eig(A.T)  # left eigenvectors of A are the columns of W
    order = np.argsort(-np.abs(lam), kind="stable")
    lam, W = lam[order], W[:, order]
    trivial = np.zeros(5, dtype=bool)
    grads = conserved_gradients(gait.params, q)
    # one structural multiplier per conserved quantity: those closest to 1
    # (the trivial tolerance is loose: a double root at 1 splits by sqrt(eps))
    for _ in grads:
        cand = [i for i in np.argsort(np.abs(lam - 1.0)) if not trivial[i]]
        if cand and abs(lam[cand[0]] - 1.0) < 1e-4:
            trivial[cand[0]] = True
    others = np.abs(lam[~trivial])
    max_nt = float(others.max()) if others.size else 0.0
    if max_nt > 1.0 + unit_tol:
        stability: Stability = "unstable"
    elif trivial.any() or max_nt >= 1.0 - unit_tol:
        stability = "neutral"
    else:
        stability = "asymptotic"
    return Floquet(multipliers=lam, trivial=trivial, max_nontrivial=max_nt,
                   stability=stability, jacobian=A, method=method)
