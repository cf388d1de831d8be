"""Plots of the gait analyses: ground impulse, step down, velocity angle, friction.

Each function takes a result from :mod:`tslip.gait.impulse`,
:mod:`tslip.gait.energy` or :mod:`tslip.gait.stride` (and optional axes),
draws with the matplotlib object API only and returns the
:class:`~matplotlib.figure.Figure`. Units are the dimensionless units of
thesis Table 3.1.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.figure import Figure

from .trajectories import LABELS, ground_profile

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..gait.energy import StepDownResponse, VelocityAngleCase
    from ..gait.impulse import Impulse, ImpulseLinearisation, PitchResponse
    from ..gait.stride import FrictionCheck

__all__ = [
    "plot_pitch_impulse",
    "plot_impulse_linearisation",
    "plot_step_down_response",
    "plot_velocity_angle_effect",
    "plot_friction",
]


def _axes_list(ax: Axes | Sequence[Axes] | None, n: int, fig_size: tuple[float, float],
               **kw: Any) -> tuple[Figure, list[Axes]]:
    """``n`` axes: a new row of panels, ``ax`` repeated ``n`` times, or ``ax`` itself."""
    if ax is None:
        fig = Figure(figsize=fig_size, layout="constrained")
        return fig, list(np.atleast_1d(fig.subplots(1, n, **kw)).ravel())
    if isinstance(ax, Sequence):
        axes = list(ax)
        if len(axes) != n:
            raise ValueError(f"ax must hold {n} axes, got {len(axes)}")
    else:
        axes = [ax] * n
    return axes[0].get_figure(), axes  # type: ignore[return-value]


# ---------------------------------------------------------------------------
# Pitch disturbance: ground reaction forces and the resultant impulse
# ---------------------------------------------------------------------------


def plot_pitch_impulse(
    impulses: PitchResponse | Sequence[Impulse],
    ax: Axes | Sequence[Axes] | None = None,
    *,
    labels: Sequence[str] | None = None,
    n_arrows: int = 15,
    force_scale: float | None = None,
) -> Figure:
    """Ground reaction forces and resultant impulse relative to the CoM.

    Like thesis Figures 4.2, 4.3 and 6.2: the ground reaction force drawn
    as arrows at the foot position relative to the CoM during the stance,
    the line of action of the resultant impulse with an arrow along it, the
    CoM (origin), the trunk and the ``F_y``-weighted mean hip position.

    Parameters
    ----------
    impulses : PitchResponse or sequence of Impulse
    ax : Axes or sequence of Axes, optional
        One axes: every impulse overlaid in its own colour. A sequence: one
        axes per impulse. Default: a new figure with one panel per impulse.
    labels : sequence of str, optional
        Default: ``"dphi = ..."`` for a :class:`PitchResponse`, the
        touch-down pitch otherwise.
    n_arrows : int
        Force arrows per stance, at interior instants evenly spaced in time.
    force_scale : float, optional
        Arrow length per unit force [L / Mg]; default draws the largest
        arrow 0.35 L long.

    Returns
    -------
    Figure
    """
    imps = list(impulses)
    if not imps:
        raise ValueError("impulses must hold at least one Impulse")
    if labels is None:
        dphis = getattr(impulses, "dphis", None)
        if dphis is not None:
            labels = [rf"$\Delta\phi$ = {d:+.2f} rad" for d in dphis]
        else:
            labels = [rf"$\phi_{{TD}}$ = {i.state.phi:+.2f} rad" for i in imps]
    fig, axes = _axes_list(ax, len(imps), (4.0 * len(imps), 4.2), sharex=True, sharey=True)
    overlay = len(set(map(id, axes))) == 1
    # arrows at interior instants evenly spaced in time (the samples need not be)
    sels = [np.unique(np.searchsorted(i.time, np.linspace(0.0, i.time[-1], n_arrows + 2)[1:-1]))
            for i in imps]
    f_max = max(float(np.max(np.hypot(i.F_x[s], i.F_y[s]))) for i, s in zip(imps, sels))
    scale = force_scale if force_scale is not None else 0.35 / f_max
    i_max = max(i.magnitude for i in imps)
    for k, (imp, a, label, sel) in enumerate(zip(imps, axes, labels, sels, strict=True)):
        color = f"C{k}" if overlay else "C0"
        a.plot(imp.x, imp.y, color="0.5", lw=0.8)
        a.quiver(imp.x[sel], imp.y[sel], imp.F_x[sel] * scale, imp.F_y[sel] * scale,
                 angles="xy", scale_units="xy", scale=1.0, color=color, alpha=0.45, width=0.006)
        y_foot = float(np.mean(imp.y))
        y_top = imp.hip_mean[1] + 0.15
        ys = np.array([y_foot, y_top])
        a.plot(imp.line_x(ys), ys, color=color, lw=1.8, ls="--",
               label=f"{label}: impulse line")
        length = 0.6 * imp.magnitude / i_max
        x0 = float(imp.line_x(y_foot))
        a.annotate("", xy=(x0 + length * math.cos(imp.direction),
                           y_foot + length * math.sin(imp.direction)),
                   xytext=(x0, y_foot),
                   arrowprops={"arrowstyle": "-|>", "color": color, "lw": 2.2})
        hx, hy = imp.hip_mean
        a.plot([0.0, hx], [0.0, hy], color=color, lw=3, alpha=0.6, solid_capstyle="round")
        a.plot(hx, hy, marker="o", ms=7, mfc="white", mec=color, ls="none")
        a.plot(0.0, 0.0, marker="o", ms=8, color="k", ls="none")
        if not overlay:
            a.set_title(label, fontsize="medium")
            a.text(0.02, 0.98, f"torque {imp.torque:+.3f}\n"
                   rf"$x_p$ {imp.x_p:+.3f} L, lean {math.degrees(imp.lean):+.1f}$^\circ$",
                   transform=a.transAxes, fontsize="small", va="top")
        a.set_aspect("equal", adjustable="box")
        a.set_xlabel(r"$x - x_m$ [L]")
        a.axhline(y_foot, color="0.3", lw=0.6)
    axes[0].set_ylabel(r"$y - y_m$ [L]")
    if overlay:
        axes[0].legend(fontsize="small", loc="upper right")
    fig.suptitle("ground reaction forces and impulse (CoM at origin, hip: open circle)")
    return fig


def plot_impulse_linearisation(lin: ImpulseLinearisation, ax: Axes | None = None) -> Figure:
    """Bar chart of ``d(I_x, I_y, x_p, y_p)/dphi`` (thesis Figure 4.1).

    A ``y_p`` gradient that is ill-conditioned (the impulse is vertical, so
    ``y_p`` is 0/0) is drawn hatched at zero height with its value written
    beside it.

    Parameters
    ----------
    lin : ImpulseLinearisation
    ax : Axes, optional

    Returns
    -------
    Figure
    """
    if ax is None:
        fig = Figure(figsize=(5.0, 3.6), layout="constrained")
        ax = fig.subplots()
    else:
        fig = ax.get_figure()  # type: ignore[assignment]
    names = [r"$\partial x_p$", r"$\partial y_p$", r"$\partial I_x$", r"$\partial I_y$"]
    vals = [lin.dx_p, lin.dy_p, lin.dI_x, lin.dI_y]
    shown = [0.0 if (n == 1 and lin.y_p_ill_conditioned) else v for n, v in enumerate(vals)]
    bars = ax.bar(names, shown, color=["C0", "C1", "C2", "C3"])
    if lin.y_p_ill_conditioned:
        bars[1].set_hatch("//")
        bars[1].set_edgecolor("C1")
        ax.text(1, 0.5, f"ill-conditioned:\n$I_x \\approx 0$\n({lin.dy_p:.3g})",
                transform=ax.get_xaxis_transform(), ha="center", va="center",
                fontsize="small")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel(r"quantity $q$: $x_p, y_p$ [L]; $I_x, I_y$ [M g$^{1/2}$ L$^{1/2}$]")
    ax.set_ylabel(r"$\partial q / \partial\phi$ [unit of $q$ / rad]")
    ax.set_title(r"impulse linearised in pitch ($\Delta\phi$ = " f"{lin.dphi:g} rad)")
    return fig


# ---------------------------------------------------------------------------
# Step down: Figures 4.5 and 4.6
# ---------------------------------------------------------------------------


def _plot_xd_height(resp: StepDownResponse, ax: Axes) -> None:
    ax.plot(resp.stride, resp.xd, marker="o", ms=3, color="C0", label=LABELS["xd"])
    ax.set_xlabel("touch-down number [-]")
    ax.set_ylabel(LABELS["xd"], color="C0")
    ax2 = ax.twinx()
    ax2.plot(resp.stride, resp.height, marker="s", ms=3, color="C3", label="height")
    ax2.set_ylabel(r"$y_m - h$ at touch-down [L]", color="C3")
    ax.set_title(f"touch-down values after a step of {resp.dh:+.2f} L "
                 f"(corr {resp.phase_correlation:+.2f})", fontsize="medium")


def plot_step_down_response(
    resp: StepDownResponse, ax: Axes | None = None, *, n_path_strides: int = 5
) -> Figure:
    """CoM path and touch-down values after a ground step (Figures 4.5, 4.6).

    Parameters
    ----------
    resp : StepDownResponse
    ax : Axes, optional
        Draw only the Figure 4.5 panel (forward speed and CoM height at
        touch-down per stride, on twin y axes) into it. By default a new
        figure also gets the Figure 4.6 panel above: the CoM path with the
        ground, stance phases shaded and the leg and trunk drawn at each
        touch-down.
    n_path_strides : int
        Strides shown in the path panel (to equal scale).

    Returns
    -------
    Figure
    """
    if ax is not None:
        _plot_xd_height(resp, ax)
        return ax.get_figure()  # type: ignore[return-value]
    fig = Figure(figsize=(10, 6.5), layout="constrained")
    ax_path, ax_td = fig.subplots(2, 1, height_ratios=[1.0, 1.3])
    traj = resp.trajectory
    p = traj.params
    rows = traj["step"] < n_path_strides
    x, y = traj["x"][rows], traj["y"][rows]
    x_lo, x_hi = float(np.min(x)) - 0.3, float(np.max(x)) + 0.8
    gx, gy = ground_profile(traj, margin=0.5)
    gx = np.clip(gx, x_lo, x_hi)
    ax_path.fill_between(gx, gy, np.min(gy) - 0.3, color="0.75", lw=0, zorder=1)
    ax_path.plot(gx, gy, color="k", lw=1.2)
    stance = traj["stance"][rows] > 0.5
    for i, k in enumerate(np.unique(traj["step"][rows]).astype(int)):
        xs = x[stance & (traj["step"][rows] == k)]
        if xs.size:
            ax_path.axvspan(float(xs[0]), float(xs[-1]), color="C0", alpha=0.12, lw=0,
                            label="stance" if i == 0 else None)
    ax_path.plot(x, y, color="C0", lw=1.3, label="CoM")
    for s in traj.touchdowns[: n_path_strides + 1]:
        hip = (s.x - p.r * math.sin(s.phi), s.h + p.l0 * math.sin(s.beta))
        foot = (hip[0] + p.l0 * math.cos(s.beta), s.h)
        com_y = hip[1] - p.r * math.cos(s.phi)
        ax_path.plot([hip[0], foot[0]], [hip[1], foot[1]], color="C2", lw=1.2)
        ax_path.plot([s.x, hip[0]], [com_y, hip[1]], color="C1", lw=3, alpha=0.8)
        ax_path.plot(s.x, com_y, "ko", ms=3)
    ax_path.set_xlim(x_lo, x_hi)
    ax_path.set_ylim(float(np.min(gy)) - 0.1, float(np.max(traj["hip_y"][rows])) + 0.2)
    ax_path.set_aspect("equal", adjustable="box")
    ax_path.set_xlabel(LABELS["x"])
    ax_path.set_ylabel(LABELS["y"])
    ax_path.legend(loc="lower left", fontsize="small", ncols=2)
    ax_path.set_title(f"first {n_path_strides} strides: CoM path; leg (green) and trunk "
                      "(orange) at touch-down", fontsize="medium")
    _plot_xd_height(resp, ax_td)
    return fig


# ---------------------------------------------------------------------------
# Velocity angle at touch-down: Figure 4.7
# ---------------------------------------------------------------------------


def plot_velocity_angle_effect(
    cases: Sequence[VelocityAngleCase], ax: Sequence[Axes] | None = None
) -> Figure:
    """CoM path, vertical and horizontal GRF per velocity-angle change (Fig. 4.7).

    Parameters
    ----------
    cases : sequence of VelocityAngleCase
    ax : sequence of three Axes, optional
        For the path, ``F_y`` and ``F_x`` panels; default a new figure.

    Returns
    -------
    Figure
    """
    if ax is None:
        fig = Figure(figsize=(7, 7.5), layout="constrained")
        axes = list(fig.subplots(3, 1))
    else:
        axes = list(ax)
        if len(axes) != 3:
            raise ValueError(f"ax must hold 3 axes, got {len(axes)}")
        fig = axes[0].get_figure()
    ax_path, ax_fy, ax_fx = axes
    for k, c in enumerate(cases):
        color = f"C{k}"
        label = rf"$\Delta\delta$ = {c.ddelta:+.3f} rad"
        tr = c.trajectory
        ax_path.plot(tr["x"], tr["y"], color=color, label=label)
        lo = int(np.flatnonzero(tr["stance"] > 0.5)[-1])
        ax_path.plot(tr["x"][lo], tr["y"][lo], marker="|", ms=12, color=color)
        imp = c.impulse
        ax_fy.plot(imp.time, imp.F_y, color=color, label=label)
        ax_fx.plot(imp.time, imp.F_x, color=color,
                   label=rf"$I_x$ = {imp.I_x:+.4f}")
    ax_path.set_xlabel(LABELS["x"])
    ax_path.set_ylabel(LABELS["y"])
    ax_path.set_title("CoM path over one stride (bar: lift-off)", fontsize="medium")
    ax_path.legend(fontsize="small")
    ax_fy.set_ylabel(r"$F_y$ [Mg]")
    ax_fy.set_xlabel(LABELS["t"])
    ax_fx.set_ylabel(r"$F_x$ [Mg]")
    ax_fx.set_xlabel(LABELS["t"])
    ax_fx.axhline(0.0, color="k", lw=0.5)
    ax_fx.legend(fontsize="small")
    return fig


# ---------------------------------------------------------------------------
# No-slip check: Figure C.1
# ---------------------------------------------------------------------------


def plot_friction(
    checks: FrictionCheck | Sequence[FrictionCheck],
    ax: Axes | Sequence[Axes] | None = None,
    *,
    titles: Sequence[str] | None = None,
) -> Figure:
    """Horizontal ground force against the friction limit (thesis Figure C.1).

    Parameters
    ----------
    checks : FrictionCheck or sequence of FrictionCheck
        One panel each (side by side by default).
    ax : Axes or sequence of Axes, optional
    titles : sequence of str, optional

    Returns
    -------
    Figure
    """
    items = [checks] if not isinstance(checks, Sequence) else list(checks)
    fig, axes = _axes_list(ax, len(items), (4.5 * len(items), 3.4), sharey=True)
    for k, (c, a) in enumerate(zip(items, axes, strict=True)):
        s = c.time / c.stance_time
        a.plot(s, np.abs(c.F_x), color="C0", label=r"$|F_x|$")
        a.plot(s, c.mu * c.F_y, color="C3", ls="--", label=rf"$\mu F_y$ ($\mu$ = {c.mu:g})")
        a.fill_between(s, 0.0, np.abs(c.F_x), where=np.abs(c.F_x) > c.mu * c.F_y,
                       color="C0", alpha=0.3, lw=0, label="slip")
        a.set_xlabel(r"$t / t_s$ [-]")
        title = titles[k] if titles is not None else ""
        a.set_title(f"{title}\nslip in {100 * c.slip_fraction:.1f} % of stance".strip(),
                    fontsize="medium")
        a.set_xlim(0.0, 1.0)
    axes[0].set_ylabel(r"force [Mg]")
    axes[0].legend(fontsize="small")
    return fig
