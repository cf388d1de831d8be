"""One report of a periodic gait: everything the thesis asks of a gait.

:func:`analyse` solves the gait and collects its stability (Section 3.1.2),
stride properties with their theory (Section 3.4.3), robustness limits
(Section 3.1.3), the ground impulse's response to pitch (Section 3.2) and
the no-slip check (Appendix C) into a plain ``dict`` of numbers and strings,
ready for JSON. The command line prints it (``tslip gait``).
"""

from __future__ import annotations

import math
from dataclasses import asdict
from typing import Any

from ..model.parameters import Params
from ..simulation.options import IntegratorOptions
from .fixed_point import Gait, find_gait
from .impulse import pitch_disturbance_response
from .robustness import robustness_report
from .stability import floquet
from .stride import friction_ratio, stride_properties

__all__ = ["analyse", "gait_summary"]


def _num(x: float) -> float | None:
    """JSON-safe float (NaN and infinities become None)."""
    x = float(x)
    return x if math.isfinite(x) else None


def gait_summary(gait: Gait) -> dict[str, Any]:
    """The gait's state, solved parameters and residual."""
    s = gait.state
    return {
        "converged": gait.converged,
        "residual": _num(gait.residual),
        "message": gait.message,
        "state": {"beta": s.beta, "phi": s.phi, "xd": s.xd, "yd": s.yd, "phid": s.phid,
                  "v": s.v, "delta": s.delta},
        "params": gait.params.to_dict(),
        "stance_time": gait.stance_time,
        "flight_time": gait.flight_time,
    }


def analyse(
    params: Params,
    *,
    gait: Gait | None = None,
    robustness: bool = True,
    n_steps: int = 25,
    mu: float = 1.0,
    options: IntegratorOptions | None = None,
) -> dict[str, Any]:
    """Solve the periodic gait of ``params`` and analyse it.

    Parameters
    ----------
    params : Params
    gait : Gait, optional
        An already solved gait (skips :func:`find_gait`).
    robustness : bool
        Compute the three robustness limits (refused for an unconverged or
        unstable gait; the reason is reported instead).
    n_steps : int
        Strides a disturbed run must survive.
    mu : float
        Friction coefficient for the no-slip check.

    Returns
    -------
    dict
        Keys ``gait``, ``floquet``, ``stride``, ``robustness``, ``impulse``,
        ``friction``; sections that cannot be computed hold ``{"error": ...}``.
    """
    gait = gait or find_gait(params)
    out: dict[str, Any] = {"gait": gait_summary(gait)}
    try:
        fl = floquet(gait, options=options)
        out["floquet"] = {
            "multipliers": [{"re": float(z.real), "im": float(z.imag), "abs": float(abs(z)),
                             "trivial": bool(t), "trivial_kind": kind}
                            for z, t, kind in zip(fl.multipliers, fl.trivial, fl.trivial_kinds)],
            "max_nontrivial": fl.max_nontrivial,
            "stability": fl.stability,
        }
    except ValueError as exc:
        out["floquet"] = {"error": str(exc)}
    sp = stride_properties(gait)
    out["stride"] = {k: _num(v) for k, v in asdict(sp).items() if k not in ("params", "state")}
    if robustness:
        try:
            rr = robustness_report(gait, n_steps=n_steps, options=options)
            out["robustness"] = {
                lim.kind: {"limit": _num(lim.limit), "fall_stride": lim.fall_stride,
                           "status": lim.status.name if lim.status is not None else None}
                for lim in rr.limits
            }
        except ValueError as exc:
            out["robustness"] = {"error": str(exc)}
    try:
        pr = pitch_disturbance_response(gait)
        out["impulse"] = {
            "nominal": {k: _num(getattr(pr.nominal, k))
                        for k in ("I_x", "I_y", "x_p", "torque", "direction")},
            "pitch": [
                {"dphi": float(d), "torque": _num(imp.torque), "restoring": bool(rest),
                 "hip_distance_over_r": _num(hd), "direction_change": _num(dc)}
                for d, imp, rest, hd, dc in zip(pr.dphis, pr.impulses, pr.restoring,
                                                pr.hip_distance, pr.direction_change)
            ],
        }
    except ValueError as exc:
        out["impulse"] = {"error": str(exc)}
    try:
        fr = friction_ratio(gait.params, gait.state, mu=mu)
        out["friction"] = {"mu": mu, "max_ratio": _num(fr.max_ratio),
                           "slip_fraction": _num(fr.slip_fraction),
                           "first_slip": _num(fr.first_slip)}
    except ValueError as exc:
        out["friction"] = {"error": str(exc)}
    return out
