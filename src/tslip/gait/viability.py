"""Viability and basins of attraction on the apex section (as the *vibly* package).

Three results, all numpy arrays on a grid with its coordinates:

* :func:`state_action_map` -> :class:`StateActionMap`: for every grid state
  at the apex (apex height ``y``; for the TSLIP two section variables, e.g.
  ``(y, phid)``) and every grid action (a parameter, e.g. the touch-down
  angle ``alpha_r``), the next apex state after one stride at fixed total
  energy, or the reason it failed. All cells run in one call of the
  batched compiled kernels (:func:`tslip.simulation.step_batch`).
* :func:`viability` -> :class:`Viability`: the viable state-action pairs
  and states, by vibly's iteration (:mod:`tslip.gait._viable`, which also
  states the cell rules ``"bracket"`` and ``"nearest"``).
* :func:`basin` -> :class:`Basin`: from every grid start state at the
  apex, the strides until the runs reach a gait, or fall
  (:func:`tslip.simulation.run_batch`).

A map of any discrete system can be built from arrays
(:meth:`StateActionMap.from_arrays`); :func:`viability` works on it the
same way. Each result has ``to_dataframe()`` (one row per cell, grid
coordinates first, units in ``df.attrs["units"]``) and ``save``/``load``
to Parquet that round-trip bit for bit (:mod:`tslip.gait._gridtable`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import check_number
from ..model.parameters import PARAMETER_TABLE, Params
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status
from . import _viable
from ._gridtable import grid_columns, load_table, save_table
from .continuation import get_param, set_param

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes

    from .fixed_point import Gait

__all__ = ["StateActionMap", "Viability", "Basin", "state_action_map", "viability", "basin",
           "SECTION_UNITS"]

#: Units of the apex-section variables a grid can span.
SECTION_UNITS = {"y": "L", "xd": "g^1/2 L^1/2", "phi": "rad", "phid": "rad g^1/2 L^-1/2"}
_PARAM_UNITS = {row.name: row.unit for row in PARAMETER_TABLE}


def _unit(name: str) -> str:
    return SECTION_UNITS.get(name, _PARAM_UNITS.get(name, "-"))


def _short(axes: Sequence[np.ndarray], names: Sequence[str]) -> str:
    return " x ".join(f"{n} {len(g)} [{g[0]:.4g}, {g[-1]:.4g}]" for n, g in zip(names, axes))


def _params_dict(p: Params | None) -> dict[str, Any] | None:
    return None if p is None else p.to_dict()


def _params_from(d: dict[str, Any] | None) -> Params | None:
    return None if d is None else Params.from_dict(d)


# ---------------------------------------------------------------------------
# the state-action map
# ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class StateActionMap:
    """One stride from every grid state with every grid action.

    Attributes
    ----------
    names : tuple of str
        Names of the state variables (one or two), e.g. ``("y",)``.
    grid : tuple of ndarray
        The state grid axes (strictly increasing), one per name.
    action : str
        Name of the action, e.g. ``"alpha_r"``.
    actions : ndarray
        The action grid (strictly increasing).
    next : ndarray, shape (*state shape, n_actions, n_names)
        The next state; NaN where the stride failed.
    status : ndarray of int, shape (*state shape, n_actions)
        :class:`tslip.Status` codes; 0 (``OK``) where the stride succeeded.
    energy : float
        Total energy of every cell [MgL] (NaN for a map built from arrays).
    params : Params or None
        The base parameters (None for a map built from arrays).
    meta : dict
        How it was computed (options, seconds, ...).
    """

    names: tuple[str, ...]
    grid: tuple[np.ndarray, ...]
    action: str
    actions: np.ndarray
    next: np.ndarray
    status: np.ndarray
    energy: float = math.nan
    params: Params | None = None
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        shape = self.shape
        if self.next.shape != shape + (len(self.names),):
            raise ValueError(f"next must have shape {shape + (len(self.names),)}, got "
                             f"{self.next.shape}")
        if self.status.shape != shape:
            raise ValueError(f"status must have shape {shape}, got {self.status.shape}")

    @classmethod
    def from_arrays(cls, states: Mapping[str, Sequence[float] | np.ndarray],
                    actions: tuple[str, Sequence[float] | np.ndarray], next: np.ndarray,
                    failed: np.ndarray | None = None) -> StateActionMap:
        """A map of any discrete system: its grids, successors and failures.

        ``next`` has shape (*state shape, n_actions[, n_states]) (the last
        axis may be left out for one state variable); ``failed`` (bool, same
        shape without that axis) marks the pairs that fail at once (status
        1), default: where ``next`` is not finite.
        """
        names, grid = _state_grid(states)
        action, acts = _action_grid(actions)
        nxt = np.asarray(next, dtype=float)
        shape = tuple(len(g) for g in grid) + (len(acts),)
        if nxt.shape == shape and len(names) == 1:
            nxt = nxt[..., None]
        if nxt.shape != shape + (len(names),):
            raise ValueError(f"next must have shape {shape + (len(names),)}, got {nxt.shape}")
        bad = ~np.all(np.isfinite(nxt), axis=-1)
        if failed is not None:
            f = np.asarray(failed, dtype=bool)
            if f.shape != shape:
                raise ValueError(f"failed must have shape {shape}, got {f.shape}")
            bad = bad | f
        nxt = np.where(bad[..., None], np.nan, nxt)
        return cls(names, grid, action, acts, nxt, bad.astype(np.int64))

    @property
    def shape(self) -> tuple[int, ...]:
        """(*state grid shape, n_actions)."""
        return tuple(len(g) for g in self.grid) + (len(self.actions),)

    @property
    def failed(self) -> np.ndarray:
        """Pairs whose stride failed (a fall, no apex, an error)."""
        return self.status != Status.OK

    def __repr__(self) -> str:
        e = "" if math.isnan(self.energy) else f", energy {self.energy:.6g}"
        return (f"StateActionMap({_short(self.grid, self.names)} x {self.action} "
                f"{len(self.actions)} [{self.actions[0]:.4g}, {self.actions[-1]:.4g}]{e}; "
                f"{int(self.failed.sum())} of {self.failed.size} fail)")

    def to_dataframe(self) -> pd.DataFrame:
        """One row per (state, action) cell: coordinates, next state, status."""
        import pandas as pd

        cols = grid_columns(list(self.grid) + [self.actions])
        data: dict[str, Any] = dict(zip(list(self.names) + [self.action], cols))
        for j, n in enumerate(self.names):
            data[f"next_{n}"] = self.next[..., j].ravel()
        data["status"] = self.status.ravel()
        df = pd.DataFrame(data)
        units = {n: _unit(n) for n in list(self.names) + [self.action]}
        units.update({f"next_{n}": _unit(n) for n in self.names})
        units["status"] = "-"
        df.attrs["units"] = units
        return df

    def _meta(self) -> dict[str, Any]:
        return {"kind": "StateActionMap", "names": list(self.names),
                "grid": [g.tolist() for g in self.grid], "action": self.action,
                "actions": self.actions.tolist(), "energy": self.energy,
                "params": _params_dict(self.params), "meta": self.meta}

    @classmethod
    def _from(cls, df: pd.DataFrame, m: dict[str, Any]) -> StateActionMap:
        grid = tuple(np.array(g, dtype=float) for g in m["grid"])
        acts = np.array(m["actions"], dtype=float)
        shape = tuple(len(g) for g in grid) + (len(acts),)
        nxt = np.stack([df[f"next_{n}"].to_numpy(float).reshape(shape) for n in m["names"]],
                       axis=-1)
        return cls(tuple(m["names"]), grid, m["action"], acts, nxt,
                   df["status"].to_numpy(np.int64).reshape(shape), float(m["energy"]),
                   _params_from(m["params"]), dict(m["meta"]))

    def save(self, path: str | Path) -> Path:
        """Write the table and the grid to a ``.parquet`` file."""
        return save_table(self.to_dataframe(), self._meta(), path)

    @classmethod
    def load(cls, path: str | Path) -> StateActionMap:
        """Read a map written by :meth:`save`."""
        df, m = load_table(path, "StateActionMap")
        return cls._from(df, m)


def _state_grid(states: Mapping[str, Any]) -> tuple[tuple[str, ...], tuple[np.ndarray, ...]]:
    if not isinstance(states, Mapping) or not 1 <= len(states) <= 2:
        raise ValueError("states must be a dict of one or two grids, e.g. {'y': grid}, got "
                         f"{states!r}")
    names = tuple(str(n) for n in states)
    return names, tuple(_viable.check_grid(states[n], f"states[{n!r}]") for n in names)


def _action_grid(actions: Any) -> tuple[str, np.ndarray]:
    if not (isinstance(actions, tuple) and len(actions) == 2 and isinstance(actions[0], str)):
        raise ValueError("actions must be (name, grid), e.g. ('alpha_r', grid), got "
                         f"{actions!r}")
    return actions[0], _viable.check_grid(actions[1], f"actions[{actions[0]!r}]")


# ---------------------------------------------------------------------------
# viability
# ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Viability:
    """The viable part of a state-action map.

    Attributes
    ----------
    map : StateActionMap
    rule : {"bracket", "nearest"}
        The cell rule (:mod:`tslip.gait._viable`).
    q : ndarray of bool, shape map.shape
        Viable state-action pairs: the stride does not fail and leads to a
        state from which some action is again viable, for ever.
    s : ndarray of bool, shape (*state shape)
        Viable states: some action is viable.
    sweeps : int
        Sweeps of the iteration that removed pairs.
    """

    map: StateActionMap
    rule: str
    q: np.ndarray
    s: np.ndarray
    sweeps: int

    def __repr__(self) -> str:
        m = self.map
        return (f"Viability({_short(m.grid, m.names)} x {m.action} {len(m.actions)}, "
                f"{self.rule}: {int(self.q.sum())} of {self.q.size} pairs and "
                f"{int(self.s.sum())} of {self.s.size} states viable, {self.sweeps} sweeps)")

    @property
    def viable_fraction(self) -> float:
        """Share of the state-action grid that is viable."""
        return float(self.q.mean())

    def to_dataframe(self) -> pd.DataFrame:
        """The map's table plus ``viable`` (the pair) and ``state_viable``."""
        df = self.map.to_dataframe()
        n_a = len(self.map.actions)
        df["viable"] = self.q.ravel()
        df["state_viable"] = np.repeat(self.s.ravel(), n_a)
        df.attrs["units"].update(viable="-", state_viable="-")
        return df

    def save(self, path: str | Path) -> Path:
        """Write the table, grid and rule to a ``.parquet`` file."""
        meta = dict(self.map._meta(), kind="Viability", rule=self.rule, sweeps=self.sweeps)
        return save_table(self.to_dataframe(), meta, path)

    @classmethod
    def load(cls, path: str | Path) -> Viability:
        """Read a result written by :meth:`save`."""
        df, m = load_table(path, "Viability")
        smap = StateActionMap._from(df, m)
        q = df["viable"].to_numpy(bool).reshape(smap.shape)
        s = df["state_viable"].to_numpy(bool).reshape(smap.shape)[..., 0]
        return cls(smap, m["rule"], q, s, int(m["sweeps"]))

    def plot(self, ax: Axes | None = None) -> Any:
        """The viable set over state and action (:func:`tslip.plotting.viability.plot_viability`)."""
        from ..plotting.viability import plot_viability

        return plot_viability(self, ax=ax)


def viability(smap: StateActionMap, rule: str = "bracket") -> Viability:
    """The viability kernel of a state-action map, by vibly's iteration.

    Starting from every pair whose stride does not fail, each sweep keeps a
    pair only if its successor lands in a viable state by ``rule``, and a
    state is viable while some action from it is, until nothing changes
    (:func:`tslip.gait._viable.viable_sets`).

    Cell rule (``rule``), for a successor between grid points:

    * ``"bracket"`` (default, conservative): viable only if every grid point
      of the cell around it (2 in 1-D, 4 in 2-D) is a viable state; on a grid
      point, only that point.
    * ``"nearest"``: viable if the nearest grid point is.

    Under both, a successor outside the grid's range is not viable, and so
    is a failed stride (a fall, a flight with no apex, an integration error).

    Parameters
    ----------
    smap : StateActionMap
    rule : {"bracket", "nearest"}

    Returns
    -------
    Viability
    """
    if rule not in _viable.RULES:
        raise ValueError(f"rule must be one of {list(_viable.RULES)}, got {rule!r}")
    n_states = int(np.prod([len(g) for g in smap.grid]))
    d = len(smap.names)
    ok = ~smap.failed.ravel()
    cells = _viable.successor_cells(smap.grid, smap.next.reshape(-1, d), ok, rule)
    q, s, sweeps = _viable.viable_sets(cells, ok, n_states)
    return Viability(smap, rule, q.reshape(smap.shape), s.reshape(smap.shape[:-1]), sweeps)
