"""Plots of parameter studies (:class:`tslip.sweeps.StudyResult`).

The thesis's figure types: non-trivial multiplier magnitudes against the
swept parameter with the stable domain shaded green (4.8, 4.12, ...), the
three robustness panels (4.9, 4.13, ...), the stable region of a k x beta0
grid (4.10), stance and flight time against eqs. 3.10-3.11 (4.11) and the
four controllers overlaid (4.24, 4.25). Results in, Figure out.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from ..model.units import UNIT
from .notation import axis_label
from .sweeps import _STABLE_GREEN, _runs, param_label

if TYPE_CHECKING:
    from ..gait.allgaits import StableRegion
    from ..sweeps.run import StudyResult

__all__ = ["plot_study_multipliers", "plot_study_robustness", "plot_stable_grid",
           "plot_stable_region",
           "plot_stride_times", "plot_controllers_multipliers", "plot_controllers_robustness"]

_ROB = (("step_down", axis_label(r"max step-down $\Delta h$", UNIT["length"])),
        ("push", axis_label(r"max push $\Delta\dot{x}$", UNIT["speed"])),
        ("pitch_rate", axis_label(r"max pitch rate $\Delta\dot{\phi}$",
                                  UNIT["angular_velocity"])))
_LAMBDA = r"$|\lambda|$"


def _stable(frame) -> np.ndarray:  # noqa: ANN001 - DataFrame
    return (frame["converged"].to_numpy(bool)
            & frame["stability"].isin(["asymptotic", "neutral"]).to_numpy()
            & (frame["max_nontrivial"].to_numpy(float) < 1.0))


def _shade(ax: Axes, x: np.ndarray, mask: np.ndarray, color: str = _STABLE_GREEN,
           alpha: float = 1.0) -> None:
    for i, j in _runs(mask):
        lo = x[i] - (0.5 * (x[i] - x[i - 1]) if i > 0 else 0.0)
        hi = x[j] + (0.5 * (x[j + 1] - x[j]) if j + 1 < len(x) else 0.0)
        ax.axvspan(lo, hi, color=color, lw=0, zorder=0, alpha=alpha)


def _split_trivial(frame) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001
    """|lambda| per point: the non-trivial ones (the ``n_trivial`` values closest to 1
    removed) and the trivial ones (the removed values, NaN elsewhere)."""
    n = sum(f"abs_lambda_{j}" in frame for j in range(1, 11))  # planar 5, 3-D 3 or 10
    mags = frame[[f"abs_lambda_{j}" for j in range(1, n + 1)]].to_numpy(float).copy()
    trivial = np.full_like(mags, np.nan)
    for i, n in enumerate(frame["n_trivial"].to_numpy(int)):
        for _ in range(n):
            k = np.nanargmin(np.abs(mags[i] - 1.0)) if np.isfinite(mags[i]).any() else None
            if k is not None:
                trivial[i, k], mags[i, k] = mags[i, k], np.nan
    return mags, trivial


def _nontrivial(frame) -> np.ndarray:  # noqa: ANN001
    """|lambda| per point with the ``n_trivial`` values closest to 1 removed."""
    return _split_trivial(frame)[0]


def _fig(ax: Axes | None, size: tuple[float, float]) -> tuple[Figure, Axes]:
    if ax is None:
        fig = Figure(figsize=size, layout="constrained")
        return fig, fig.add_subplot()
    return ax.figure, ax  # type: ignore[return-value]


def _xlim(ax: Axes, result: StudyResult) -> None:
    """The study's whole swept range (the same on every panel of a figure pair)."""
    values = np.asarray(result.spec.axes[-1].values, float)
    lo, hi = float(values.min()), float(values.max())
    pad = 0.03 * (hi - lo) if hi > lo else 0.5
    ax.set_xlim(lo - pad, hi + pad)


def plot_study_multipliers(result: StudyResult, ax: Axes | None = None, *,
                           title: str | None = None) -> Figure:
    """``|lambda|`` against the swept parameter; the stable domain green.

    The non-trivial multipliers as dots; the trivial ones (the energy
    multiplier 1 of a conservative gait, :func:`tslip.gait.floquet`) as open
    grey circles, so that a gait whose energy mode stops being trivial (leg
    damping, Figure 4.12) is compared with its undamped neighbour's 1.
    """
    fig, ax = _fig(ax, (6.4, 3.4))
    f = result.frame
    param = result.spec.axes[-1].param
    x = f[param].to_numpy(float)
    _shade(ax, x, _stable(f))
    mags, trivial = _split_trivial(f)
    for k in range(mags.shape[1]):
        ax.plot(x, mags[:, k], "o", ms=3, color="C0",
                label=f"{_LAMBDA} non-trivial" if k == 0 else None)
    if np.isfinite(trivial).any():
        ax.plot(np.repeat(x, trivial.shape[1]), trivial.ravel(), "o", ms=7, mfc="none",
                mec="k", mew=0.8, zorder=3, label=f"{_LAMBDA} trivial (energy)")
    none = ~f["converged"].to_numpy(bool)
    if none.any():
        ax.plot(x[none], np.zeros(none.sum()), "x", color="C3", ms=4, label="no periodic gait")
    ax.axhline(1.0, color="k", ls="--", lw=0.8)
    ax.fill_between([], [], color=_STABLE_GREEN, label="stable domain")  # legend entry only
    top = np.nanmax(mags) if np.isfinite(mags).any() else 1.5
    ax.set_ylim(0, min(max(1.5, top * 1.05), 3.0))
    _xlim(ax, result)
    ax.set_xlabel(param_label(param))
    ax.set_ylabel(f"{_LAMBDA} [-]")
    ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize=7, frameon=False)
    ax.set_title(title or f"Floquet multipliers: {result.spec.description}", fontsize=9)
    return fig


def plot_study_robustness(result: StudyResult, axes: Sequence[Axes] | None = None, *,
                          label: str | None = None, color: str = "C0",
                          shade: bool = True, title: str | None = None) -> Figure:
    """The three robustness limits (step-down, push, pitch rate) against the parameter,
    over the study's whole swept range (as its multipliers panel)."""
    if axes is None:
        fig = Figure(figsize=(6.4, 6.0), layout="constrained")
        axes = list(fig.subplots(3, 1, sharex=True))
    else:
        fig = axes[0].figure  # type: ignore[assignment]
    f = result.frame
    param = result.spec.axes[-1].param
    x = f[param].to_numpy(float)
    for a, (col, ylabel) in zip(axes, _ROB):
        if shade:
            _shade(a, x, _stable(f))
        a.plot(x, f[col].to_numpy(float) if col in f else np.full(len(x), np.nan), "o-",
               ms=3, lw=1, color=color, label=label)
        a.set_ylabel(ylabel, fontsize=8)
        _xlim(a, result)
    axes[-1].set_xlabel(param_label(param))
    if label:  # one of several studies on these axes: a legend above them, no title
        axes[0].legend(loc="lower left", bbox_to_anchor=(0.0, 1.02), ncols=4, fontsize=7,
                       frameon=False)
    else:
        axes[0].set_title(title or f"Robustness: {result.spec.description}", fontsize=9)
    return fig


#: Figure 4.10's three classes: colour and legend text, by code 0, 1, 2.
GRID_CLASSES: tuple[tuple[str, str], ...] = (
    ("white", "no periodic gait"),
    ("#f4b6b6", "periodic gait, unstable"),
    (_STABLE_GREEN, "stable (non-trivial |λ| < 1)"),
)


def plot_stable_grid(results: Mapping[float, StudyResult]) -> Figure:
    """Figure 4.10: one k x beta0 panel per speed; stable / unstable / no gait."""
    n = len(results)
    fig = Figure(figsize=(3.0 * n, 3.6), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, n, sharey=True))
    cmap = ListedColormap([c for c, _ in GRID_CLASSES])
    for a, (v, res) in zip(axes, results.items()):
        f = res.frame
        code = np.where(_stable(f), 2, np.where(f["converged"].to_numpy(bool), 1, 0))
        grid = code.reshape(res.spec.shape)
        k, b = res.spec.axes[0].values, res.spec.axes[1].values
        a.pcolormesh(b, k, grid, cmap=cmap, vmin=0, vmax=2, shading="nearest")
        a.set_title(f"$v_0$ = {v:g}: stable {np.mean(grid == 2):.0%}", fontsize=9)
        a.set_xlabel(param_label(res.spec.axes[1].param))
        a.set_ylabel(param_label(res.spec.axes[0].param))
    fig.legend(handles=[Patch(facecolor=c, edgecolor="0.4", lw=0.5, label=t)
                        for c, t in GRID_CLASSES],
               loc="outside lower center", ncols=len(GRID_CLASSES), fontsize=8)
    return fig


def plot_stable_region(region: StableRegion, ax: Axes | None = None) -> Figure:
    """A :func:`tslip.gait.stable_region` grid in the classes of Figure 4.10, with the
    most stable gait's largest non-trivial ``|lambda|`` printed in each cell."""
    fig, a = _fig(ax, (5.0, 4.0))
    code = np.where(region.n_stable > 0, 2, np.where(region.n_gaits > 0, 1, 0))
    y, x = region.values
    a.pcolormesh(x, y, code, cmap=ListedColormap([c for c, _ in GRID_CLASSES]), vmin=0, vmax=2,
                 shading="nearest", edgecolors="0.85", linewidth=0.3)
    if code.size <= 400:
        for (i, j), m in np.ndenumerate(region.max_nontrivial):
            if np.isfinite(m):
                a.text(float(x[j]), float(y[i]), f"{m:.2f}", ha="center", va="center", fontsize=6)
    a.set(xlabel=param_label(region.names[1]), ylabel=param_label(region.names[0]),
          title=f"energy {region.energy:g} MgL: stable {np.mean(code == 2):.0%}")
    a.legend(handles=[Patch(facecolor=c, edgecolor="0.4", lw=0.5, label=t)
                      for c, t in GRID_CLASSES], fontsize=7, loc="center left",
             bbox_to_anchor=(1.01, 0.5), frameon=False)  # beside the grid, never on it
    return fig


def plot_stride_times(results: Mapping[str, StudyResult]) -> Figure:
    """Figure 4.11: stance and flight time (model, dots) against eqs. 3.10-3.11 (lines)."""
    n = len(results)
    fig = Figure(figsize=(3.2 * n, 4.8), layout="constrained")
    axes = fig.subplots(2, n, squeeze=False)
    for j, res in enumerate(results.values()):
        f = res.frame
        param = res.spec.axes[-1].param
        x = f[param].to_numpy(float)
        for i, (col, lab, eq) in enumerate((("stance_time", "$t_s$", "3.10"),
                                            ("flight_time", "$t_f$", "3.11"))):
            a = axes[i, j]
            a.plot(x, f[col], "o", ms=3, label=f"{lab} model")
            pred = f.get(f"{col}_predicted")
            if pred is not None:
                a.plot(x, pred, "-", color="C1", label=f"{lab} eq. {eq}")
            a.set_xlabel(param_label(param))
            a.set_ylabel(axis_label(lab, UNIT["time"]))
            a.legend(fontsize=7)
    return fig


def plot_controllers_multipliers(results: Mapping[str, StudyResult]) -> Figure:
    """Figure 4.24: one multiplier panel per controller over r."""
    n = len(results)
    fig = Figure(figsize=(6.4, 2.2 * n), layout="constrained")
    axes = fig.subplots(n, 1, sharex=True)
    for a, (name, res) in zip(np.atleast_1d(axes), results.items()):
        plot_study_multipliers(res, a, title=name)
    return fig


def plot_controllers_robustness(results: Mapping[str, StudyResult]) -> Figure:
    """Figure 4.25: the three robustness panels with the controllers overlaid."""
    fig = Figure(figsize=(6.4, 6.0), layout="constrained")
    axes = list(fig.subplots(3, 1, sharex=True))
    for i, (name, res) in enumerate(results.items()):
        plot_study_robustness(res, axes, label=name, color=f"C{i}", shade=False)
    return fig
