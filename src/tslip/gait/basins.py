"""Basins of attraction on the apex section: where runs from a grid of apex states go.

:func:`basin` runs every grid start state (apexes at a gait's total energy)
for a number of strides in one compiled :func:`tslip.run_batch` call and
counts the strides until each reaches the gait, or falls: a :class:`Basin`.
Both names are also importable from :mod:`tslip.gait.viability`, where they
lived before the split (after 0.3.0).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import check_number
from .._results import Result, with_units
from ..model import _pack as pk
from ..model.parameters import Params
from ..simulation.integrate import run_batch
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status
from . import section
from .stability import pitch_decoupled
from .statemap import _apex_rows, _short, _unit, check_map_inputs, grid_columns

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes

    from .fixed_point import Gait

__all__ = ["Basin", "basin"]


@dataclass(frozen=True, eq=False, repr=False)
class Basin(Result):
    """Where runs from a grid of apex states go under a gait's parameters.

    Attributes
    ----------
    names, grid : as :class:`StateActionMap`
        The start states at the apex, at the gait's energy.
    steps : ndarray of int, shape (grid shape...)
        Strides until the touch-down state is within ``tol`` of the gait's
        (0: it starts there); -1 if it never was.
    n_done : ndarray of int
        Strides completed (``n_steps`` unless it fell).
    status : ndarray of int
        :class:`tslip.Status` of the last stride (OK if it did not fall).
    n_steps : int
    tol : float
    energy : float
    params : Params
    gait : ndarray
        The gait's touch-down section ``(beta, phi, xd, yd, phid)``.
    """

    names: tuple[str, ...]
    grid: tuple[np.ndarray, ...]
    steps: np.ndarray
    n_done: np.ndarray
    status: np.ndarray
    n_steps: int
    tol: float
    energy: float
    params: Params
    gait: np.ndarray
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def converged(self) -> np.ndarray:
        """Starts whose run reached the gait."""
        return self.steps >= 0

    @property
    def fell(self) -> np.ndarray:
        """Starts whose run fell (or failed) within ``n_steps``."""
        return self.status != Status.OK

    def __repr__(self) -> str:
        return (f"Basin({_short(self.grid, self.names)}, {self.n_steps} strides: "
                f"{int(self.converged.sum())} reach the gait, {int(self.fell.sum())} fall, of "
                f"{self.steps.size})")

    def to_dataframe(self) -> pd.DataFrame:
        """One row per start: its coordinates, ``steps``, ``n_done``, ``status``."""
        import pandas as pd

        data: dict[str, Any] = dict(zip(self.names, grid_columns(self.grid)))
        data.update(steps=self.steps.ravel(), n_done=self.n_done.ravel(),
                    status=self.status.ravel())
        return with_units(pd.DataFrame(data), {**{n: _unit(n) for n in self.names},
                                               "steps": "-", "n_done": "-", "status": "-"})

    def _table_fields(self) -> tuple[str, ...]:
        return ("steps", "n_done", "status")

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        shape = tuple(len(g) for g in fields["grid"])
        return dict(fields, **{c: df[c].to_numpy(np.int64).reshape(shape)
                               for c in ("steps", "n_done", "status")})

    def plot(self, ax: Axes | None = None) -> Any:
        """Strides to the gait over the start grid (:func:`tslip.plotting.viability.plot_basin`)."""
        from ..plotting.viability import plot_basin

        return plot_basin(self, ax=ax)


def basin(params: Params, gait: Gait, states: Mapping[str, Sequence[float] | np.ndarray],
          n_steps: int, *, tol: float = 1e-6,
          options: IntegratorOptions | None = None) -> Basin:
    """Strides to reach ``gait`` (or to fall) from every grid start state at its energy.

    The start states are apexes at the gait's total energy
    (:func:`tslip.gait.section.energy` of its touch-down); each descends to
    its touch-down under ``gait.params`` and runs ``n_steps`` strides, all
    rows in one compiled :func:`tslip.run_batch` call. A run has reached the
    gait at the first touch-down whose section ``(beta, phi, xd, yd, phid)``
    is within ``tol`` (max norm) of the gait's, leaving out ``phi`` when the
    pitch is decoupled (:func:`tslip.gait.stability.pitch_decoupled`: every
    pitch is then a fixed point).

    Parameters
    ----------
    params : Params
        Checked against ``gait.params`` (the gait's solved ``alpha_r`` is used).
    gait : Gait
    states : dict
        One or two apex variables and their grids (as :func:`state_action_map`).
    n_steps : int
    tol : float
    options : IntegratorOptions, optional
        Default ``IntegratorOptions.tight("dop853")``.
    """
    n_steps = int(check_number(n_steps, "n_steps", lower=1, integer=True))
    tol = float(check_number(tol, "tol", lower=0.0, lower_open=True))
    p = gait.params
    if dataclasses.replace(params, alpha_r=p.alpha_r) != p:
        raise ValueError("params must be the gait's parameters (gait.params) up to alpha_r")
    E = section.total_energy(p, gait.state)
    names, grid, _, _, _ = check_map_inputs(p, states, ("alpha_r", [p.alpha_r]), E)
    options = options or IntegratorOptions.tight("dop853")
    t0 = time.perf_counter()
    pts = np.stack(grid_columns(grid), axis=1)
    rows = _apex_rows(p, names, pts, E)
    A = np.hstack([rows, np.zeros((len(rows), 2))])
    td, st, _ = section._touchdowns(np.tile(pk.pack_params(p), (len(A), 1)), A,
                                    options.packed())
    shape = tuple(len(g) for g in grid)
    steps = np.full(len(A), -1, dtype=np.int64)
    n_done = np.zeros(len(A), dtype=np.int64)
    status = st.astype(np.int64)
    go = np.flatnonzero(st == Status.OK)
    target = gait.state.section()
    if go.size:
        run = run_batch(p, td[go], n_steps, options=options)
        hist = run.touchdowns[:, :, :5]
        err = np.abs(hist - target)
        if pitch_decoupled(p):
            err[:, :, 1] = 0.0
        near = np.all(err <= tol, axis=-1)  # NaN rows (after a fall) are never near
        first = np.where(near.any(axis=1), np.argmax(near, axis=1), -1)
        steps[go], n_done[go], status[go] = first, run.n_done, run.status
    return Basin(names, grid, steps.reshape(shape), n_done.reshape(shape),
                 status.reshape(shape), n_steps, tol, E, p, target,
                 {"options": dataclasses.asdict(options), "seconds": time.perf_counter() - t0})
