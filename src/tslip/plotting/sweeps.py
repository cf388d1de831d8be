"""Plots of results along a parameter: multipliers over a continuation branch."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

if TYPE_CHECKING:
    from ..gait.continuation import Branch

__all__ = ["plot_branch", "param_label", "symbol_tex"]

_STABLE_GREEN = "#c8eec8"


def symbol_tex(symbol: str) -> str:
    """A parameter's symbol as written in the parameter table, in mathtext:
    ``"beta_0"`` -> ``$\\beta_{0}$``, ``"phidot_r"`` -> ``$\\dot{\\phi}_{r}$``."""
    from .notation import GREEK

    base, _, sub = symbol.partition("_")
    dot = base.endswith("dot") and base != "dot"
    base = base.removesuffix("dot") if dot else base
    tex = f"\\{base}" if base in GREEK else base
    tex = f"\\dot{{{tex}}}" if dot else tex
    return f"${tex}_{{{sub}}}$" if sub else f"${tex}$"


def param_label(name: str) -> str:
    """Axis label of a swept parameter: its symbol and unit (thesis Table 3.1), in mathtext.

    Symbols and units are those of :data:`tslip.model.parameters.PARAMETER_TABLE`
    and of the controllers' field metadata (dotted ``"controller.<gain>"`` names,
    as :mod:`tslip.gait.continuation` takes them); ``omega_r_bar`` (eq. 2.18) is
    a ratio, ``[-]``. A name the package does not know is returned as is.
    """
    from dataclasses import fields

    from ..model.controllers import CONTROLLERS
    from ..model.parameters import PARAMETER_TABLE
    from ..model.units import param_unit
    from .notation import axis_label

    if name == "omega_r_bar":
        return axis_label(r"$\bar{\omega}_r = \omega_r l_0 / v_0$", "-")
    unit = param_unit(name)
    if unit is None:
        return name
    gain = name.removeprefix("controller.")
    symbols = {row.name: row.symbol for row in PARAMETER_TABLE}
    symbols.update({f.name: str(f.metadata["symbol"]) for cls in CONTROLLERS.values()
                    for f in fields(cls) if "symbol" in f.metadata})
    return axis_label(symbol_tex(symbols.get(gain, gain)), unit)


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Index ranges ``[i, j]`` of consecutive True entries."""
    out, start = [], None
    for i, m in enumerate(mask):
        if m and start is None:
            start = i
        if not m and start is not None:
            out.append((start, i - 1))
            start = None
    if start is not None:
        out.append((start, len(mask) - 1))
    return out


def plot_branch(branch: Branch, ax: Axes | None = None) -> Figure:
    """Multiplier magnitudes along a branch; the stable domain shaded green.

    As the thesis's eigenvalue figures (4.8, 4.12, 4.14, 4.16, ...): each
    non-trivial ``|lambda|`` against the parameter, the unit circle as a
    dashed line, and green where the gait is at least neutrally stable.
    """
    if ax is None:
        fig = Figure(figsize=(6.4, 3.6), layout="constrained")
        ax = fig.add_subplot()
    else:
        fig = ax.figure  # type: ignore[assignment]
    v = branch.values
    stable = branch.stable
    for i, j in _runs(stable):
        lo = v[i] - (0.5 * (v[i] - v[i - 1]) if i > 0 else 0.0)
        hi = v[j] + (0.5 * (v[j + 1] - v[j]) if j + 1 < len(v) else 0.0)
        ax.axvspan(lo, hi, color=_STABLE_GREEN, lw=0, zorder=0)
    mags = np.abs(branch.multipliers).astype(float)
    mags[branch.trivial] = np.nan
    mags = np.sort(mags, axis=1)[:, ::-1]
    for k in range(mags.shape[1]):
        ax.plot(v, mags[:, k], "o", ms=3, color="C0", label="|λ|" if k == 0 else None)
    ax.axhline(1.0, color="k", ls="--", lw=0.8)
    ax.set_xlabel(param_label(branch.param))
    ax.set_ylabel(r"non-trivial $|\lambda|$ [-]")
    ax.set_ylim(0, max(1.5, float(np.nanmin([np.nanmax(mags), 3.0])) if np.isfinite(mags).any()
                       else 1.5))
    ax.set_title(f"Floquet multipliers along {branch.param} (green: stable)")
    return fig
