"""Automatic TSLIP fit to step-averaged measurements (Section 5.7, Tables 6.1-6.3).

The thesis tuned the model by hand. Here a bounded least-squares search
(:func:`scipy.optimize.least_squares`) adjusts the free parameters (by
default v0, k, beta0, c_l and the derivative gain K_d of the local velocity
controller); for each candidate the periodic gait is solved
(:func:`tslip.find_gait`, which sets alpha_r and alphad_ref), and the
residual compares the model's stance with the measured mean on the
normalised step time, plus heavily weighted stance and flight durations so
they match to within 0.01 dimensionless time (Table 6.2).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from scipy.optimize import least_squares

from .._results import Result, with_units
from ..model.parameters import Params, preset
from .signals import SIGNALS, StepAverage, correlation, vaf

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..gait.fixed_point import Gait

__all__ = ["FitResult", "fit_model", "model_curves", "fit_scores", "stride_table",
           "FIT_SIGNALS"]

#: Signals compared in stance by the fit residual.
FIT_SIGNALS = ("y", "l", "beta", "phi", "xd", "yd")
_BOUNDS = {"v0": (0.5, 4.0), "k": (2.0, 40.0), "beta0": (0.5, 1.45), "c_l": (0.0, 2.0),
           "Kd": (0.0, 3.0), "omega_r": (0.0, 5.0)}


#: Units of the score table (Table 6.3): correlations are pure numbers, VAF is in %.
SCORE_UNITS = {"signal": "-", "unit": "-", "corr_stance": "-", "vaf_stance": "%",
               "corr_full": "-", "vaf_full": "%"}


@dataclass(frozen=True, repr=False)
class FitResult(Result):
    """A fitted TSLIP model and its scores.

    Attributes
    ----------
    params : Params
        Fitted model with the solved alpha_r and alphad_ref.
    values : dict of str to float
        Fitted free parameters (dimensionless, Table 3.1).
    stance_time, flight_time : float
        Model stride times [g^-1/2 L^1/2].
    curves : pandas.DataFrame
        Model :data:`~tslip.experiment.signals.SIGNALS` on the measured ``tau``.
    scores : pandas.DataFrame
        Table 6.3: ``signal``, ``corr_stance``, ``vaf_stance`` [%], ``corr_full``,
        ``vaf_full`` [%].
    times : pandas.DataFrame
        Table 6.2: measured mean, std and model of t_s, t_f, d and f.
    cost : float
        Final least-squares cost [-].
    n_evals : int
    converged : bool
        Stance and flight durations within ``time_tol`` of the measurement.
    message : str
    """

    params: Params
    values: dict[str, float]
    stance_time: float
    flight_time: float
    curves: pd.DataFrame
    scores: pd.DataFrame
    times: pd.DataFrame
    cost: float
    n_evals: int
    converged: bool
    message: str

    def _repr_fields(self) -> dict[str, Any]:
        return {**self.values, "cost": self.cost, "n_evals": self.n_evals,
                "converged": self.converged}

    def to_dataframe(self) -> pd.DataFrame:
        """Table 6.3: correlation and VAF of each signal, in stance and over the stride."""
        return with_units(self.scores.copy(), SCORE_UNITS)

    def plot(self, ax: Axes | None = None) -> Figure:
        """VAF of each signal in stance and over the stride (Table 6.3 as bars)."""
        from ..plotting.experiment import plot_fit_scores

        return plot_fit_scores(self, ax)


def _set(base: Params, values: dict[str, float]) -> Params:
    ctrl = {k: v for k, v in values.items() if k in ("Kd",)}
    top = {k: v for k, v in values.items() if k not in ("Kd",)}
    p = Params.from_dict(top, base=base) if top else base
    if ctrl:
        p = dataclasses.replace(p, controller=dataclasses.replace(p.controller, **ctrl))
    return p


def model_curves(params: Params, tau: np.ndarray, *, guess: np.ndarray | None = None
                 ) -> tuple[pd.DataFrame, float, float, Gait]:
    """Model signals of one periodic stride on the normalised step time.

    Returns
    -------
    curves : pandas.DataFrame
        :data:`SIGNALS` at ``tau`` (plus ``stance``).
    stance_time, flight_time : float
        [g^-1/2 L^1/2]
    gait : Gait
    """
    from ..gait import find_gait
    from ..simulation import simulate

    gait = find_gait(params, guess=guess)
    if not gait.converged:
        raise ValueError(f"no periodic gait: {gait.message}")
    ts, tf = gait.stance_time, gait.flight_time
    traj = simulate(gait.params, gait.state, 1, dt=(ts + tf) / 400)
    t = traj["t"]
    tt = tau * (ts + tf)
    cols = {"xd": "xd", "yd": "yd", "y": "y", "l": "l", "beta": "beta", "phi": "phi",
            "ld": "ld", "betad": "betad", "phid": "phid"}
    out = {name: np.interp(tt, t, traj[c]) for name, c in cols.items()}
    out["stance"] = tt <= ts
    return pd.DataFrame(out), ts, tf, gait


def fit_model(avg: StepAverage, *, base: Params | None = None,
              free: tuple[str, ...] = ("v0", "k", "beta0", "c_l", "Kd"),
              start: dict[str, float] | None = None, time_tol: float = 0.01,
              max_nfev: int = 60) -> FitResult:
    """Fit the TSLIP model with local velocity control and leg damping.

    Parameters
    ----------
    avg : StepAverage
        Step-averaged measurement.
    base : Params, optional
        Fixed parameters (m, J, r, omega_r, controller type); default the
        structure of Table 6.1 with r, J and omega_r as given there.
    free : tuple of str
        Parameters to fit (names of Params fields, or ``Kd``).
    start : dict, optional
        Starting values; by default v0 and beta0 from the measured touch-down,
        k = 10, c_l = 0.1, K_d = 0.2 (not the generating values).
    time_tol : float
        Required match of t_s and t_f [g^-1/2 L^1/2].
    max_nfev : int
        Budget of residual evaluations (each solves one periodic gait).

    Returns
    -------
    FitResult
    """
    base = base or preset("table6.1")
    m0 = avg.mean.iloc[0]
    guess0 = {"v0": float(math.hypot(m0["xd"], m0["yd"])), "beta0": float(m0["beta"]),
              "k": 10.0, "c_l": 0.1, "Kd": 0.2, "omega_r": base.omega_r}
    guess0.update(start or {})
    unknown = [f for f in free if f not in _BOUNDS]
    if unknown:
        raise ValueError(f"cannot fit {unknown}; choose from {sorted(_BOUNDS)}")
    x0 = np.array([guess0[f] for f in free])
    lo = np.array([_BOUNDS[f][0] for f in free])
    hi = np.array([_BOUNDS[f][1] for f in free])
    x0 = np.clip(x0, lo + 1e-6, hi - 1e-6)
    ts_m = float(np.mean(avg.stance_time))
    tf_m = float(np.mean(avg.flight_time))
    d_m = ts_m / (ts_m + tf_m)
    sel = avg.tau <= d_m - 0.01
    meas = {s: avg.mean[s].to_numpy()[sel] for s in FIT_SIGNALS}
    scale = {s: max(float(np.std(meas[s])), 1e-3) for s in FIT_SIGNALS}
    n_res = sum(int(sel.sum()) for _ in FIT_SIGNALS) + 2
    n_evals = [0]

    def residual(x: np.ndarray) -> np.ndarray:
        n_evals[0] += 1
        p = _set(base, dict(zip(free, map(float, x))))
        try:
            curves, ts, tf, _ = model_curves(p, avg.tau)
        except (ValueError, RuntimeError):
            return np.full(n_res, 10.0)
        # model stance on the measured stance fraction: compare in stance-normalised time
        tau_s = avg.tau[sel] / d_m
        t_model = tau_s * ts / (ts + tf)
        r = [(np.interp(t_model, avg.tau, curves[s].to_numpy()) - meas[s]) / scale[s]
             / math.sqrt(sel.sum()) for s in FIT_SIGNALS]
        w = 1.0 / (0.2 * time_tol)
        return np.concatenate(r + [np.array([w * (ts - ts_m), w * (tf - tf_m)])])

    sol = least_squares(residual, x0, bounds=(lo, hi), x_scale=np.maximum(np.abs(x0), 0.1),
                        diff_step=1e-4, max_nfev=max_nfev)
    values = dict(zip(free, map(float, sol.x)))
    p = _set(base, values)
    curves, ts, tf, gait = model_curves(p, avg.tau)
    ok = abs(ts - ts_m) <= time_tol and abs(tf - tf_m) <= time_tol
    msg = (f"fit {'converged' if ok else 'did not match the stride times'}: "
           f"t_s {ts:.4f} vs {ts_m:.4f}, t_f {tf:.4f} vs {tf_m:.4f}; {sol.message}")
    return FitResult(params=gait.params, values=values, stance_time=ts, flight_time=tf,
                     curves=curves, scores=fit_scores(avg, curves, d_m),
                     times=stride_table(avg, ts, tf), cost=float(sol.cost),
                     n_evals=n_evals[0], converged=ok, message=msg)


def fit_scores(avg: StepAverage, curves: pd.DataFrame, duty: float | None = None
               ) -> pd.DataFrame:
    """Table 6.3: correlation (eq. 5.1) and VAF (eq. 5.2) per signal.

    Stance scores use the samples before the measured mean lift-off
    (``tau <= duty``), full-stride scores all samples.
    """
    if duty is None:
        duty = float(np.mean(avg.duty_factor))
    st = avg.tau <= duty
    rows = []
    for s in SIGNALS:
        y, yh = avg.mean[s].to_numpy(), curves[s].to_numpy()
        rows.append({"signal": s, "unit": SIGNALS[s],
                     "corr_stance": correlation(y[st], yh[st]), "vaf_stance": vaf(y[st], yh[st]),
                     "corr_full": correlation(y, yh), "vaf_full": vaf(y, yh)})
    return pd.DataFrame(rows)


def stride_table(avg: StepAverage, ts: float, tf: float) -> pd.DataFrame:
    """Table 6.2: measured mean and std of t_s, t_f, d, f against the model."""
    rows = [("stance_time", avg.stance_time, ts, "g^-1/2 L^1/2"),
            ("flight_time", avg.flight_time, tf, "g^-1/2 L^1/2"),
            ("duty_factor", avg.duty_factor, ts / (ts + tf), "-"),
            ("step_frequency", avg.step_frequency, 1.0 / (ts + tf), "g^1/2 L^-1/2")]
    return pd.DataFrame([{"quantity": q, "measured_mean": float(np.mean(v)),
                          "measured_std": float(np.std(v)), "model": float(m), "unit": u}
                         for q, v, m, u in rows])
