"""One report of a periodic gait: everything the thesis asks of a gait.

:func:`analyse` solves the gait and collects its stability (Section 3.1.2),
stride properties with their theory (Section 3.4.3), robustness limits
(Section 3.1.3), the ground impulse's response to pitch (Section 3.2) and
the no-slip check (Appendix C) into a :class:`GaitReport` of those results;
:meth:`GaitReport.to_dict` gives the plain ``dict`` of numbers and strings
ready for JSON that the command line prints (``tslip gait``).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any

from .._results import Result, frame
from ..model.parameters import Params
from ..model.units import COLUMN_UNITS, UNIT
from ..simulation.options import IntegratorOptions
from .fixed_point import Gait, find_gait
from .impulse import PitchResponse, pitch_disturbance_response
from .robustness import UNITS as ROBUSTNESS_UNITS
from .robustness import RobustnessResult, robustness_report
from .stability import Floquet, floquet
from .stride import FrictionCheck, StrideProperties, friction_ratio, stride_properties

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["analyse", "gait_summary", "GaitReport"]


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


@dataclass(frozen=True, repr=False)
class GaitReport(Result):
    """Everything :func:`analyse` found about a gait: the results, or why one is missing.

    Attributes
    ----------
    gait : Gait
    stride : StrideProperties
    floquet, robustness, impulse, friction : result or None
        None when not computed (``robustness=False``) or refused; then
        ``errors`` holds the reason under the same name.
    mu : float
        Friction coefficient of the no-slip check [-].
    errors : dict of str to str
    """

    gait: Gait
    stride: StrideProperties
    floquet: Floquet | None
    robustness: RobustnessResult | None
    impulse: PitchResponse | None
    friction: FrictionCheck | None
    mu: float = 1.0
    errors: dict[str, str] = field(default_factory=dict)

    @property
    def params(self) -> Params:
        """The gait's parameters."""
        return self.gait.params

    def _repr_fields(self) -> dict[str, Any]:
        fl, rr = self.floquet, self.robustness
        return {"converged": self.gait.converged, "v": self.gait.state.v,
                "stability": fl.stability if fl else None,
                "max_nontrivial": fl.max_nontrivial if fl else None,
                **({lim.kind: lim.limit for lim in rr.limits} if rr else {}),
                "errors": len(self.errors)}

    def to_dataframe(self) -> pd.DataFrame:
        """One row: the gait, its multiplier, stride timing, limits and the no-slip check."""
        g, fl, rr, fr = self.gait, self.floquet, self.robustness, self.friction
        row: dict[str, Any] = {
            "converged": g.converged, "v": g.state.v, "delta": g.state.delta,
            "stance_time": g.stance_time, "flight_time": g.flight_time,
            "stability": fl.stability if fl else "", "max_nontrivial":
            fl.max_nontrivial if fl else math.nan, "duty_factor": self.stride.duty_factor,
            "step_frequency": self.stride.step_frequency}
        for kind in ROBUSTNESS_UNITS:
            lims = [lim for lim in rr.limits if lim.kind == kind] if rr else []
            row[kind] = lims[0].limit if lims else math.nan
        row.update(mu=self.mu, max_ratio=fr.max_ratio if fr else math.nan,
                   slip_fraction=fr.slip_fraction if fr else math.nan)
        return frame([row], {**COLUMN_UNITS, **ROBUSTNESS_UNITS, "max_nontrivial": "-",
                             "duty_factor": "-", "step_frequency": UNIT["frequency"],
                             "mu": "-", "max_ratio": "-", "slip_fraction": "-"})

    def plot(self, ax: Axes | None = None) -> Figure:
        """The multipliers (or, without them, the gait's path)."""
        return self.floquet.plot(ax) if self.floquet is not None else self.gait.plot(ax)

    def to_dict(self) -> dict[str, Any]:
        """Plain numbers and strings, ready for JSON (NaN and infinities as None).

        Keys ``gait``, ``floquet``, ``stride``, ``robustness`` (if asked for),
        ``impulse``, ``friction``; a section that could not be computed holds
        ``{"error": ...}``.
        """
        out: dict[str, Any] = {"gait": gait_summary(self.gait)}
        fl = self.floquet
        out["floquet"] = {"error": self.errors["floquet"]} if fl is None else {
            "multipliers": [{"re": float(z.real), "im": float(z.imag), "abs": float(abs(z)),
                             "trivial": bool(t), "trivial_kind": kind}
                            for z, t, kind in zip(fl.multipliers, fl.trivial, fl.trivial_kinds)],
            "max_nontrivial": fl.max_nontrivial,
            "stability": fl.stability,
        }
        out["stride"] = {k: _num(v) for k, v in asdict(self.stride).items()
                         if k not in ("params", "state")}
        rr = self.robustness
        if rr is not None:
            out["robustness"] = {
                lim.kind: {"limit": _num(lim.limit), "fall_stride": lim.fall_stride,
                           "status": lim.status.name if lim.status is not None else None}
                for lim in rr.limits
            }
        elif "robustness" in self.errors:
            out["robustness"] = {"error": self.errors["robustness"]}
        pr = self.impulse
        out["impulse"] = {"error": self.errors["impulse"]} if pr is None else {
            "nominal": {k: _num(getattr(pr.nominal, k))
                        for k in ("I_x", "I_y", "x_p", "torque", "direction")},
            "pitch": [
                {"dphi": float(d), "torque": _num(imp.torque), "restoring": bool(rest),
                 "hip_distance_over_r": _num(hd), "direction_change": _num(dc)}
                for d, imp, rest, hd, dc in zip(pr.dphis, pr.impulses, pr.restoring,
                                                pr.hip_distance, pr.direction_change)
            ],
        }
        fr = self.friction
        out["friction"] = {"error": self.errors["friction"]} if fr is None else {
            "mu": self.mu, "max_ratio": _num(fr.max_ratio),
            "slip_fraction": _num(fr.slip_fraction), "first_slip": _num(fr.first_slip)}
        return out


def analyse(
    params: Params,
    *,
    gait: Gait | None = None,
    robustness: bool = True,
    n_steps: int = 25,
    mu: float = 1.0,
    options: IntegratorOptions | None = None,
) -> GaitReport:
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
    GaitReport
        The results; :meth:`GaitReport.to_dict` for JSON.
    """
    gait = gait or find_gait(params)
    errors: dict[str, str] = {}

    def attempt(name: str, fn: Any) -> Any:
        try:
            return fn()
        except ValueError as exc:
            errors[name] = str(exc)
            return None

    fl = attempt("floquet", lambda: floquet(gait, options=options))
    rr = attempt("robustness", lambda: robustness_report(gait, n_steps=n_steps,
                                                         options=options)) if robustness else None
    pr = attempt("impulse", lambda: pitch_disturbance_response(gait))
    fr = attempt("friction", lambda: friction_ratio(gait.params, gait.state, mu=mu))
    return GaitReport(gait=gait, stride=stride_properties(gait), floquet=fl, robustness=rr,
                      impulse=pr, friction=fr, mu=float(mu), errors=errors)
