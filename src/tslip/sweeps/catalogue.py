"""The thesis's parameter studies (Chapter 4, Appendix C) as data.

Every sweep figure is one :class:`~tslip.sweeps.StudySpec` (or a few, for
Figures 4.10, 4.11, 4.24-4.25) with a quick and a full resolution; the
figures that analyse a single gait (4.1-4.7, 6.2, C.1, and Appendix E's
biped) are small functions returning the analysis objects. Nothing here is
tuned to a reported number: base parameters are the presets of Tables 2.1
and 6.1 (and Tables E.1-E.4) and the ranges are those of Sections 3.4-3.7.

Choices the thesis leaves open
------------------------------
* Velocity (4.8, 4.9): Section 3.4.1 varies ``v0`` with "the passive TSLIP
  model with the configuration in Table 2.1", whose retraction is the absolute
  rate ``omega_r``: ``velocity`` holds it, and the claims are judged on it;
  ``velocity_bar`` holds ``omega_r_bar = omega_r l0 / v0`` (eq. 2.18, the form
  the thesis describes retraction by), shown beside as evidence.
* Stiffness (4.18, 4.19): ``k`` must be positive, so the sweep starts at
  ``k = 1`` instead of 0.
* Leg damping (4.12, 4.13) and hip damping (4.14, 4.15) use the constant
  torque controller with ``tau_c`` solved at each point; the hip-damping
  sweep keeps the preset's leg damping ``c_l = 0.5``.
* Global PD (4.24, 4.25) has one equation more than unknowns, so no exact
  fixed point exists; its sweep accepts a residual (max-norm) up to
  :data:`GLOBAL_PD_TOL` (the thesis accepted ``C1 < 1e-4``, eq. 2.22) and
  the report prints the residual reached.
* Figure 4.10 sweeps ``k`` in [5, 80] and ``beta0`` in [0.8, 1.5] with local
  velocity control; the thesis gives no ranges for this figure.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, TypedDict

import numpy as np

from ..gait import (
    continue_gait,
    find_gait,
    friction_ratio,
    impulse_linearisation,
    pitch_disturbance_response,
    step_down_response,
    velocity_after_height_change,
    velocity_angle_effect,
)
from ..model.parameters import Params, preset
from .spec import Axis, StudySpec

__all__ = [
    "Study", "STUDIES", "GLOBAL_PD_TOL", "GRID_SPEEDS", "RESOLUTIONS", "resolution_name",
    "studies", "study",
    "fig_impulse_linearisation", "fig_pitch_disturbance", "fig_height_change",
    "fig_step_down", "fig_velocity_angle", "fig_friction", "fig_mass_offset_boundary",
    "MassOffsetBoundary",
]

#: Max-norm residual accepted for the global PD gaits (no exact fixed point).
GLOBAL_PD_TOL = 1e-2
#: Speeds of the four Figure 4.10 panels [g^1/2 L^1/2].
GRID_SPEEDS = (2.0, 3.0, 4.0, 5.0)
#: Points per 1-D sweep and per grid axis.
QUICK_LINE, FULL_LINE = 12, 50
QUICK_GRID, FULL_GRID = 6, 40
#: Resolutions by name: (points per 1-D sweep, per grid axis). ``"tiny"`` is
#: for testing the whole pipeline, not for reading numbers off.
RESOLUTIONS: dict[str, tuple[int, int]] = {
    "tiny": (3, 3), "quick": (QUICK_LINE, QUICK_GRID), "full": (FULL_LINE, FULL_GRID)}


def resolution_name(resolution: bool | str) -> str:
    """``"quick"``/``"full"`` for a bool (quick or not), else the checked name."""
    if isinstance(resolution, bool):
        return "quick" if resolution else "full"
    if resolution not in RESOLUTIONS:
        raise ValueError(f"resolution must be one of {sorted(RESOLUTIONS)}, got {resolution!r}")
    return resolution
ROB = ("floquet", "robustness")


@dataclass(frozen=True)
class Study:
    """One study of the catalogue: its figures and its spec per resolution."""

    name: str
    figures: tuple[str, ...]
    spec: StudySpec

    def at(self, quick: bool | str) -> StudySpec:
        """The spec at quick (True) or full (False) resolution, or one of :data:`RESOLUTIONS`.

        An axis with one value is held, not swept.
        """
        line, grid = RESOLUTIONS[resolution_name(quick)]
        if sum(len(a.values) > 1 for a in self.spec.axes) == 1:
            return self.spec.with_resolution([line] * len(self.spec.axes))
        return self.spec.with_resolution([grid, grid])


def _p(name: str, **kw: Any) -> Params:
    return Params.from_dict(kw, base=preset(name)) if kw else preset(name)


def _line(name: str, figures: tuple[str, ...], base: Params, param: str, start: float,
          stop: float, analyses: tuple[str, ...] = ROB, description: str = "",
          **meta: Any) -> Study:
    spec = StudySpec(name, base, (Axis.linspace(param, start, stop, FULL_LINE),), analyses,
                     description=description, meta=dict(meta))
    return Study(name, figures, spec)


def _velocity_bar() -> Study:
    """Figure 4.9's speed line with ``omega_r_bar = omega_r l0 / v0`` (eq. 2.18) held.

    The thesis describes retraction by the normalised rate, so "varying
    velocity" may hold ``omega_r_bar`` (this study) or ``omega_r`` (the
    ``velocity`` study) fixed. The held rate is an axis with one value after
    the ``v0`` axis, so each point sets ``v0`` first and then ``omega_r``.
    """
    base = _p("table2.1")
    spec = StudySpec("velocity_bar", base,
                     (Axis.linspace("v0", 1.0, 10.0, FULL_LINE),
                      Axis("omega_r_bar", (base.omega_r_bar,))), ROB,
                     description=f"passive Table 2.1, v0 in [1, 10] with omega_r_bar = "
                                 f"{base.omega_r_bar:g} held (eq. 2.18)")
    return Study(spec.name, ("4.8", "4.9"), spec)


def _build() -> dict[str, Study]:
    out: list[Study] = [
        _line("velocity", ("4.8", "4.9"), _p("table2.1"), "v0", 1.0, 10.0,
              description="passive Table 2.1, v0 in [1, 10]"),
        _velocity_bar(),
    ]
    for v in GRID_SPEEDS:
        spec = StudySpec(
            f"grid_v{v:g}", _p("table2.1-local-velocity", v0=v),
            (Axis.linspace("k", 5.0, 80.0, FULL_GRID),
             Axis.linspace("beta0", 0.8, 1.5, FULL_GRID)),
            ("floquet",), description=f"local velocity control, v0 = {v:g}: k x beta0")
        out.append(Study(spec.name, ("4.10",), spec))
    st = ("floquet", "stride")
    out += [
        _line("stride_v0", ("4.11",), _p("table2.1"), "v0", 2.0, 10.0, st,
              "passive, stance/flight time vs v0"),
        _line("stride_k", ("4.11",), _p("table2.1"), "k", 5.0, 100.0, st,
              "passive, stance/flight time vs k"),
        _line("stride_beta0", ("4.11",), _p("table2.1"), "beta0", 0.8, 1.5, st,
              "passive, stance/flight time vs beta0"),
        _line("leg_damping", ("4.12", "4.13"), _p("table2.1-constant-torque"), "c_l", 0.0, 3.0,
              description="constant torque (tau_c solved), leg damping c_l in [0, 3]"),
        _line("hip_damping", ("4.14", "4.15"), _p("table2.1-constant-torque"),
              "controller.c_h", 0.0, 3.0,
              description="constant torque (tau_c solved, c_l 0.5), hip damping c_h in [0, 3]"),
        _line("mass_offset", ("4.16", "4.17", "4.24", "4.25"), _p("table2.1"), "r", -1.0, 1.0,
              description="passive, mass offset r in [-1, 1]"),
        _line("stiffness", ("4.18", "4.19"), _p("table2.1"), "k", 1.0, 200.0,
              description="passive, k in [1, 200] (k = 0 is not a spring)"),
        _line("touchdown_angle", ("4.20", "4.21"), _p("table2.1"), "beta0", 0.8, 1.5,
              description="passive, beta0 in [0.8, 1.5]"),
        _line("retraction", ("4.22", "4.23"), _p("table2.1"), "omega_r_bar", 0.0, 2.0,
              description="passive, normalised retraction rate in [0, 2]"),
        _line("controller_global_pd", ("4.24", "4.25"), _p("table2.1-global-pd"), "r", -1.0,
              1.0, description=f"global PD, r in [-1, 1] (residual <= {GLOBAL_PD_TOL:g})",
              tol=GLOBAL_PD_TOL, neutral_tol=0.01),
        _line("controller_local_velocity", ("4.24", "4.25"), _p("table2.1-local-velocity"), "r",
              -1.0, 1.0, description="local velocity control, r in [-1, 1]"),
        _line("controller_constant_torque", ("4.24", "4.25"), _p("table2.1-constant-torque"),
              "r", -1.0, 1.0, description="constant torque, c_l 0.5, r in [-1, 1]"),
    ]
    return {s.name: s for s in out}


#: Every sweep study of the thesis, by name.
STUDIES: dict[str, Study] = _build()


def studies(quick: bool | str = False) -> dict[str, StudySpec]:
    """All study specs at quick or full resolution (or a :data:`RESOLUTIONS` name), by name."""
    return {name: s.at(quick) for name, s in STUDIES.items()}


def study(name: str, quick: bool | str = False) -> StudySpec:
    """One study spec by name."""
    try:
        return STUDIES[name].at(quick)
    except KeyError:
        raise ValueError(f"unknown study {name!r}; known: {sorted(STUDIES)}") from None


# ---------------------------------------------------------------------------
# single-gait figures
# ---------------------------------------------------------------------------


def _gait(name: str, **kw: Any):  # noqa: ANN202 - Gait
    p = _p(name, **kw)
    tol = GLOBAL_PD_TOL if "global-pd" in name else 1e-10
    g = find_gait(p, tol=tol)
    if not g.converged:
        raise ValueError(f"no periodic gait for preset {name}: {g.message}")
    return g


def fig_impulse_linearisation():  # noqa: ANN201
    """Figure 4.1: d(I_x, I_y, x_p, y_p)/dphi for the passive Table 2.1 gait."""
    return impulse_linearisation(_gait("table2.1"))


def fig_pitch_disturbance(preset_name: str, dphi: float = 0.5):  # noqa: ANN201
    """Figures 4.2, 4.3, 6.2: impulses after pitch disturbances 0, +dphi, -dphi."""
    return pitch_disturbance_response(_gait(preset_name), (-dphi, 0.0, dphi))


def fig_height_change(quick: bool = False) -> dict[str, Any]:
    """Figure 4.4: converged speed change after ground steps, passive and local velocity."""
    dhs = (-0.2, -0.1, -0.05, 0.02, 0.05) if quick else (-0.2, -0.15, -0.1, -0.05, 0.02, 0.05)
    n_steps, n_avg = (120, 40) if quick else (200, 50)
    out: dict[str, Any] = {"dh": dhs}
    for key, name in (("passive", "table2.1"), ("local_velocity", "table2.1-local-velocity")):
        g = _gait(name)
        out[key] = [velocity_after_height_change(g, dh, n_steps=n_steps, n_average=n_avg)
                    for dh in dhs]
    return out


def fig_step_down(dh: float = -0.2, n_steps: int = 30):  # noqa: ANN201
    """Figures 4.5, 4.6: the passive gait over a 0.2 L step down."""
    return step_down_response(_gait("table2.1"), dh, n_steps)


def fig_velocity_angle(ddelta: float = 0.05):  # noqa: ANN201
    """Figure 4.7: one stride with the touch-down velocity angle changed by -/0/+ ddelta."""
    return velocity_angle_effect(_gait("table2.1"), (-ddelta, 0.0, ddelta))


def fig_friction() -> dict[str, Any]:
    """Figure C.1: |F_x| / F_y over stance, Table 2.1 and Table 6.1 gaits."""
    out = {}
    for key in ("table2.1", "table6.1"):
        g = _gait(key)
        out[key] = friction_ratio(g.params, g.state, 1.0)
    return out


#: Bisection tolerance [L] of Figure 4.16's stability boundary (the claim's "0.86" is
#: printed to 0.005).
BOUNDARY_TOL = 1e-3


class MassOffsetBoundary(TypedDict):
    """Figure 4.16's stability boundary (:func:`fig_mass_offset_boundary`)."""

    boundary: float
    bracket: tuple[float, float]
    tol: float


def fig_mass_offset_boundary(step: float = 0.025, stop: float = 1.0,
                             tol: float = BOUNDARY_TOL) -> MassOffsetBoundary:
    """Figure 4.16: the largest r with a stable passive Table 2.1 gait, located by bisection.

    Continues the gait from Table 2.1's r upwards in steps of ``step`` to the
    first point without a stable gait (every non-trivial |lambda| below 1),
    then bisects that bracket, each midpoint continued from the last stable
    gait, until it is narrower than ``tol``. Returns ``boundary`` (the
    bracket's midpoint), ``bracket`` (last stable, first not stable) and ``tol``;
    ``boundary`` is NaN if no point up to ``stop`` loses stability.
    """
    base = preset("table2.1")
    n = int(math.floor((stop - base.r) / step + 1e-9)) + 1
    values = base.r + step * np.arange(n)

    def stable(branch: Any, i: int) -> bool:  # a gait (never None then), inside the circle
        return bool(branch.converged[i] and branch.gaits[i] is not None
                    and branch.max_nontrivial[i] < 1.0)

    b = continue_gait(base, "r", values)
    bad = [i for i in range(n) if not stable(b, i)]
    if not bad or bad[0] == 0:
        return {"boundary": math.nan, "bracket": (math.nan, math.nan), "tol": tol}
    lo, hi, gait = float(values[bad[0] - 1]), float(values[bad[0]]), b.gaits[bad[0] - 1]
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        m = continue_gait(gait, "r", [lo, mid])  # type: ignore[arg-type]  # stable: a gait
        if stable(m, 1):
            lo, gait = mid, m.gaits[1]
        else:
            hi = mid
    return {"boundary": 0.5 * (lo + hi), "bracket": (lo, hi), "tol": tol}


def fig_appendix_e(*args: Any, **kwargs: Any) -> dict[str, Any]:
    """Appendix E, the two-legged model: see :func:`tslip.sweeps.appendix_e.fig_appendix_e`."""
    from .appendix_e import fig_appendix_e as appendix_e

    return appendix_e(*args, **kwargs)
