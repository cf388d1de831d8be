"""Viability and basins of attraction on the apex section (as the *vibly* package).

Three results, all numpy arrays on a grid with its coordinates:

* :func:`state_action_map` -> :class:`StateActionMap`: for every grid state
  at the apex (apex height ``y``; for the TSLIP up to three section
  variables, ``(y, phi, phid)``) and every grid action (a parameter, e.g. the touch-down
  angle ``alpha_r``), the next apex state after one stride at fixed total
  energy, or the reason it failed. All cells run in one call of the
  batched compiled kernels (:func:`tslip.simulation.step_batch`).
* :func:`viability` -> :class:`Viability`: the viable state-action pairs
  and states, by the iteration of vibly's ``compute_QV`` on a compact
  successor encoding held in chunks (:mod:`tslip.gait._viable`, which also
  states the cell rules: tslip's conservative ``"bracket"`` (the default),
  ``"nearest"``, and vibly's own ``"vibly"``); for a 3-D map its volume
  fraction, slices and projections (:class:`ViableSection`).
* :func:`basin` -> :class:`Basin`: from every grid start state at the
  apex, the strides until the runs reach a gait, or fall
  (:func:`tslip.simulation.run_batch`).

A map of any discrete system can be built from arrays
(:meth:`StateActionMap.from_arrays`); :func:`viability` works on it the
same way. Each result is a :class:`tslip._results.Result`:
``to_dataframe()`` has one row per cell, grid coordinates first, units in
``df.attrs["units"]``; ``save``/``load`` (and ``tslip.load``) to
``.parquet`` (the table, with the grid and parameters in the ``.json``
record beside it), ``.csv`` or ``.json`` round-trip bit for bit.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import check_number
from .._results import Result, with_units
from ..model import _pack as pk
from ..model.parameters import Params
from ..model.units import COLUMN_UNITS, param_unit
from ..simulation.integrate import run_batch
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status
from . import _viable, section
from .continuation import set_param
from .stability import pitch_decoupled

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes

    from .fixed_point import Gait

__all__ = ["StateActionMap", "Viability", "ViableSection", "Basin", "state_action_map",
           "viability", "basin", "STATE_NAMES", "SECTION_UNITS", "check_map_inputs",
           "map_cells"]

#: Apex variables a grid can span (the forward speed follows from the energy).
STATE_NAMES = ("y", "phi", "phid")

#: Units of the apex-section variables a grid can span.
SECTION_UNITS = {n: COLUMN_UNITS[n] for n in ("y", "xd", "phi", "phid")}


def _unit(name: str) -> str:
    return SECTION_UNITS.get(name) or param_unit(name) or "-"


def _short(axes: Sequence[np.ndarray], names: Sequence[str]) -> str:
    return " x ".join(f"{n} {len(g)} [{g[0]:.4g}, {g[-1]:.4g}]" for n, g in zip(names, axes))


def grid_columns(axes: Sequence[np.ndarray]) -> list[np.ndarray]:
    """The coordinates of every cell of a grid, one column per axis (C order)."""
    return [m.ravel() for m in np.meshgrid(*axes, indexing="ij")]


# ---------------------------------------------------------------------------
# the state-action map
# ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False, repr=False)
class StateActionMap(Result):
    """One stride from every grid state with every grid action.

    Attributes
    ----------
    names : tuple of str
        Names of the state variables (one to three), e.g. ``("y",)``.
    grid : tuple of ndarray
        The state grid axes (strictly increasing), one per name.
    action : str
        Name of the action, e.g. ``"alpha_r"``.
    actions : ndarray
        The action grid (strictly increasing).
    next : ndarray, shape (grid shape..., n_actions, n_names)
        The next state; NaN where the stride failed.
    status : ndarray of int, shape (grid shape..., n_actions)
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

        ``next`` has shape ``(*grid shape, n_actions[, n_states])`` (the last
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
        # (grid shape..., n_actions); no docstring, so the API docs leave it out: a second
        # documented ``shape`` makes numpydoc's "shape (n,)" type cross-references ambiguous
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
        units = {n: _unit(n) for n in list(self.names) + [self.action]}
        units.update({f"next_{n}": _unit(n) for n in self.names}, status="-")
        return with_units(pd.DataFrame(data), units)

    def _table_fields(self) -> tuple[str, ...]:
        return ("next", "status")

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        """``next`` and ``status`` back from the table; the grid comes from the record."""
        shape = tuple(len(g) for g in fields["grid"]) + (len(fields["actions"]),)
        nxt = np.stack([df[f"next_{n}"].to_numpy(float).reshape(shape)
                        for n in fields["names"]], axis=-1)
        return dict(fields, next=nxt, status=df["status"].to_numpy(np.int64).reshape(shape))


def _state_grid(states: Mapping[str, Any]) -> tuple[tuple[str, ...], tuple[np.ndarray, ...]]:
    if not isinstance(states, Mapping) or not 1 <= len(states) <= 3:
        raise ValueError("states must be a dict of one to three grids, e.g. {'y': grid}, got "
                         f"{states!r}")
    names = tuple(str(n) for n in states)
    return names, tuple(_viable.check_grid(states[n], f"states[{n!r}]") for n in names)


def _action_grid(actions: Any) -> tuple[str, np.ndarray]:
    """``(name, grid)`` or ``{name: grid}`` (one entry) as ``(name, checked grid)``."""
    if isinstance(actions, Mapping):
        if len(actions) != 1:
            raise ValueError("actions must be a dict of one {name: grid} (two actions are not "
                             f"supported yet), got {len(actions)} entries")
        actions = next(iter(actions.items()))
        actions = (str(actions[0]), actions[1])
    if not (isinstance(actions, tuple) and len(actions) == 2 and isinstance(actions[0], str)):
        raise ValueError("actions must be (name, grid) or {name: grid}, e.g. ('alpha_r', "
                         f"grid), got {actions!r}")
    return actions[0], _viable.check_grid(actions[1], f"actions[{actions[0]!r}]")


# ---------------------------------------------------------------------------
# viability
# ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False, repr=False)
class Viability(Result):
    """The viable part of a state-action map.

    Attributes
    ----------
    map : StateActionMap
    rule : {"bracket", "nearest", "vibly"}
        The cell rule (:mod:`tslip.gait._viable`).
    q : ndarray of bool, shape map.shape
        Viable state-action pairs: the stride does not fail and leads to a
        state from which some action is again viable, for ever.
    s : ndarray of bool, shape (grid shape...)
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

    @property
    def volume_fraction(self) -> float:
        """Share of the state grid that is viable: the viable set's volume on the grid."""
        return float(self.s.mean())

    def slice(self, name: str) -> ViableSection:
        """The viable states at the grid value of ``name`` nearest 0 (a 3-D map's section).

        The grid of ``name`` must reach 0 (its first value <= 0 <= its last).
        """
        j = self._third(name)
        g = self.map.grid[j]
        if not g[0] <= 0.0 <= g[-1]:
            raise ValueError(f"states[{name!r}] must contain 0 (first <= 0 <= last) to slice "
                             f"at 0, got [{g[0]:g}, {g[-1]:g}]")
        i = int(np.argmin(np.abs(g)))
        return self._section(j, "slice", float(g[i]), np.take(self.s, i, axis=j))

    def projection(self, name: str) -> ViableSection:
        """The states viable for some grid value of ``name`` (a 3-D map's shadow)."""
        j = self._third(name)
        return self._section(j, "projection", math.nan, np.asarray(self.s.any(axis=j)))

    def _third(self, name: str) -> int:
        names = self.map.names
        if len(names) != 3 or name == "y" or name not in names:
            raise ValueError(f"name must be one of {[n for n in names if n != 'y']} of a "
                             f"map over three state variables, got {name!r} of {list(names)}")
        return names.index(name)

    def _section(self, j: int, kind: str, at: float, s: np.ndarray) -> ViableSection:
        m = self.map
        keep = [k for k in range(3) if k != j]
        return ViableSection(tuple(m.names[k] for k in keep), tuple(m.grid[k] for k in keep),
                             s, kind, m.names[j], at, self.rule, m.energy)

    def to_dataframe(self) -> pd.DataFrame:
        """The map's table plus ``viable`` (the pair) and ``state_viable``."""
        df = self.map.to_dataframe()
        df["viable"] = self.q.ravel()
        df["state_viable"] = np.repeat(self.s.ravel(), len(self.map.actions))
        return with_units(df, dict(df.attrs["units"], viable="-", state_viable="-"))

    def _fields(self) -> dict[str, Any]:
        """The map's fields (flat, so a table holds its arrays once) and the kernel's."""
        return dict(self.map._fields(), rule=self.rule, q=self.q, s=self.s,
                    sweeps=self.sweeps)

    @classmethod
    def _from_fields(cls, fields: dict[str, Any]) -> Viability:
        f = dict(fields)
        own = {k: f.pop(k) for k in ("rule", "q", "s", "sweeps")}
        return cls(StateActionMap(**f), **own)

    def _table_fields(self) -> tuple[str, ...]:
        return ("next", "status", "q", "s")

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        out = StateActionMap._from_table(df, fields)
        shape = out["status"].shape
        q = df["viable"].to_numpy(bool).reshape(shape)
        return dict(out, q=q, s=df["state_viable"].to_numpy(bool).reshape(shape)[..., 0])

    def plot(self, ax: Axes | None = None) -> Any:
        """The viable set (:func:`tslip.plotting.viability.plot_viability`)."""
        from ..plotting.viability import plot_viability

        return plot_viability(self, ax=ax)


@dataclass(frozen=True, eq=False, repr=False)
class ViableSection(Result):
    """Viable states of a 3-D viability result over two of its variables.

    Attributes
    ----------
    names, grid : as :class:`StateActionMap`, the two variables kept
    s : ndarray of bool, shape (grid shape...)
        Viable states.
    kind : {"slice", "projection"}
        ``"slice"``: at the grid value ``at`` of ``over`` (the one nearest 0);
        ``"projection"``: viable for some grid value of ``over`` (``at`` NaN).
    over : str
        The variable left out.
    at : float
    rule : str
    energy : float
    """

    names: tuple[str, ...]
    grid: tuple[np.ndarray, ...]
    s: np.ndarray
    kind: str
    over: str
    at: float
    rule: str
    energy: float

    @property
    def label(self) -> str:
        """Which section it is, e.g. ``"slice at phi = 0"`` or ``"projection over phid"``."""
        if self.kind == "slice":
            return f"slice at {self.over} = {self.at:.4g}"
        return f"projection over {self.over} (viable for some {self.over})"

    @property
    def fraction(self) -> float:
        """Share of the section's grid that is viable."""
        return float(self.s.mean())

    def __repr__(self) -> str:
        return (f"ViableSection({_short(self.grid, self.names)}, {self.label}: "
                f"{int(self.s.sum())} of {self.s.size} viable)")

    def to_dataframe(self) -> pd.DataFrame:
        """One row per state of the section: its coordinates and ``viable``."""
        import pandas as pd

        data: dict[str, Any] = dict(zip(self.names, grid_columns(self.grid)))
        data["viable"] = self.s.ravel()
        return with_units(pd.DataFrame(data), {**{n: _unit(n) for n in self.names},
                                               "viable": "-"})

    def _table_fields(self) -> tuple[str, ...]:
        return ("s",)

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        shape = tuple(len(g) for g in fields["grid"])
        return dict(fields, s=df["viable"].to_numpy(bool).reshape(shape))

    def plot(self, ax: Axes | None = None) -> Any:
        """The section (:func:`tslip.plotting.viability.plot_section`)."""
        from ..plotting.viability import plot_section

        return plot_section(self, ax=ax)


def viability(smap: StateActionMap, rule: str = "bracket") -> Viability:
    """The viability kernel of a state-action map, by the iteration of vibly's ``compute_QV``.

    Starting from every pair whose stride does not fail, each sweep keeps a
    pair only if its successor lands in a viable state by ``rule``, and a
    state is viable while some action from it is, until nothing changes
    (:func:`tslip.gait._viable.viable_sets_chunked`, on the compact int32
    successor cells of :func:`tslip.gait._viable.encode_chunks`).

    Cell rule (``rule``), for a successor between grid points:

    * ``"bracket"`` (default, tslip's, conservative): viable only if every
      grid point of the cell around it (2 in 1-D, 4 in 2-D, 8 in 3-D) is a viable
      state; on a grid point (within 1e-9 of a spacing), only that point;
      outside the grid's range, never.
    * ``"nearest"``: viable if the nearest grid point is; outside the grid's
      range, never.
    * ``"vibly"`` (vibly's rule): per axis ``b = np.digitize(s', grid)``;
      viable if every grid point of the product of ``{b-1, b}`` that lies
      inside the grid is a viable state. On a grid point it needs that point
      and the next one up; above the top, the top point; below the bottom,
      the bottom point. Unlike vibly, which stores a failure as bin 0, a
      successor below the bottom on every axis is not taken for a failure.

    Under every rule a failed stride (a fall, a flight with no apex, an
    integration error) is not viable.

    Parameters
    ----------
    smap : StateActionMap
    rule : {"bracket", "nearest", "vibly"}

    Returns
    -------
    Viability
    """
    if rule not in _viable.RULES:
        raise ValueError(f"rule must be one of {list(_viable.RULES)}, got {rule!r}")
    n_states = int(np.prod([len(g) for g in smap.grid]))
    d = len(smap.names)
    ok = ~smap.failed.ravel()
    chunks = _viable.encode_chunks(smap.grid, smap.next.reshape(-1, d), ok, rule)
    q, s, sweeps = _viable.viable_sets_chunked(chunks, n_states, len(smap.actions))
    return Viability(smap, rule, q.reshape(smap.shape), s.reshape(smap.shape[:-1]), sweeps)


# ---------------------------------------------------------------------------
# the physical map: apex to apex at fixed energy (tslip.gait.section)
# ---------------------------------------------------------------------------


def _with_action(params: Params, name: str, value: float) -> Params:
    """``params`` with the action set: ``alpha_r`` directly, others by :func:`set_param`."""
    if name == "alpha_r":
        return dataclasses.replace(params, alpha_r=float(value))
    return set_param(params, name, value)


def check_map_inputs(params: Params, states: Mapping[str, Any], actions: Any,
                     energy: float) -> tuple[tuple[str, ...], tuple[np.ndarray, ...], str,
                                             np.ndarray, float]:
    """Check a physical map's inputs (one-line ``ValueError`` naming the field); return them
    as ``(names, grid, action, actions, energy)``."""
    if not isinstance(params, Params):
        raise ValueError(f"params must be a tslip.Params, got {type(params).__name__}")
    names, grid = _state_grid(states)
    bad = [n for n in names if n not in STATE_NAMES]
    if bad:
        raise ValueError(f"states: unknown apex variable {bad[0]!r}; allowed: "
                         f"{list(STATE_NAMES)} (xd follows from the energy)")
    if "y" not in names:
        raise ValueError("states must include the apex height 'y'")
    action, acts = _action_grid(actions)
    for v in (acts[0], acts[-1]):
        try:
            p = _with_action(params, action, v)
        except ValueError as exc:
            also = " (or 'alpha_r', the leg angle)" if "unknown parameter" in str(exc) else ""
            raise ValueError(f"actions[{action!r}]: {exc}{also}") from None
    E = float(check_number(energy, "energy [MgL]", lower=0.0, lower_open=True))
    if not section.apex_section_ok(p):
        raise ValueError("params: the apex is a Poincare section only if the touch-down angle "
                         "follows from the apex state (omega_r = 0, or retraction timed from "
                         f"the apex), got omega_r={p.omega_r!r} with the lift-off clock")
    j = names.index("y")
    phid_sq = max(float(np.max(grid[names.index("phid")] ** 2)) if "phid" in names else 0.0, 0.0)
    for v in (acts[0], acts[-1]):
        p = _with_action(params, action, v)
        y_max = (E - 0.5 * p.J * phid_sq) / (p.m * p.g)
        if grid[j][-1] >= y_max:
            raise ValueError(f"states['y'] must stay below {y_max:.6g} L at energy {E:g} MgL "
                             f"(no forward speed left there), got up to {grid[j][-1]:g}")
    return names, grid, action, acts, E


def _apex_rows(params: Params, names: Sequence[str], points: np.ndarray,
               energy: float) -> np.ndarray:
    """Apex rows ``(y, xd, phi, phid)`` at ``points`` (n, len(names)), ``xd`` from the energy."""
    cols = {n: points[:, j] for j, n in enumerate(names)}
    y = cols["y"]
    phi = cols.get("phi", np.zeros(len(y)))
    phid = cols.get("phid", np.zeros(len(y)))
    kin = energy - params.m * params.g * y - 0.5 * params.J * phid**2
    xd = np.sqrt(np.maximum(2.0 * kin / params.m, 0.0))
    return np.column_stack([y, xd, phi, phid])


def map_cells(params: Params, names: Sequence[str], points: np.ndarray,
              actions: tuple[str, np.ndarray], energy: float,
              options: IntegratorOptions | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The apex map at ``points`` (n, d) x every action: next states (n, n_a, d), status.

    One batched call (:func:`tslip.gait.section.apex_map_states`, whose
    stances run in one compiled :func:`tslip.step_batch` kernel) for an
    ``alpha_r`` action; one per action value for a parameter action.
    """
    options = options or IntegratorOptions.tight("dop853")
    action, acts = actions
    pts = np.asarray(points, dtype=float).reshape(-1, len(names))
    n, n_a = len(pts), len(acts)
    if action == "alpha_r":
        rows = _apex_rows(params, names, pts, energy)
        b = section.apex_map_states(params, np.repeat(rows, n_a, axis=0),
                                    np.tile(acts, n), options=options)
        nxt = np.stack([getattr(b, k) for k in names], axis=-1).reshape(n, n_a, len(names))
        status = np.asarray(b.status, dtype=np.int64).reshape(n, n_a)
    else:
        nxt = np.empty((n, n_a, len(names)))
        status = np.empty((n, n_a), dtype=np.int64)
        for k, v in enumerate(acts):  # one batch per action value, over every state
            p = _with_action(params, action, float(v))
            b = section.apex_map_states(p, _apex_rows(p, names, pts, energy), options=options)
            nxt[:, k] = np.stack([getattr(b, c) for c in names], axis=-1)
            status[:, k] = b.status
    nxt[status != Status.OK] = np.nan
    return nxt, status


def state_action_map(params: Params, states: Mapping[str, Sequence[float] | np.ndarray],
                     actions: tuple[str, Sequence[float] | np.ndarray], *, energy: float,
                     options: IntegratorOptions | None = None) -> StateActionMap:
    """The apex return map at fixed total energy over a grid of apex states and actions.

    Parameters
    ----------
    params : Params
        Model whose apex is a Poincare section (no retraction clock from
        lift-off; :func:`tslip.gait.section.apex_section_ok`), e.g.
        ``preset("slip")``.
    states : dict
        One to three apex variables and their grids: ``{"y": heights}`` [L]
        for the SLIP; for the TSLIP e.g. ``{"y": ..., "phid": ...}`` or all
        three ``{"y": ..., "phi": ..., "phid": ...}`` (:data:`STATE_NAMES`;
        any left out is 0 at the apex, so a map over fewer variables is the
        slice of the 3-D map at 0, bit for bit).
    actions : (str, array) or {str: array}
        The action and its grid: ``("alpha_r", angles)`` or
        ``{"alpha_r": angles}`` (one entry) (the leg angle set
        at lift-off, the SLIP's touch-down angle [rad]) or any parameter
        :func:`tslip.gait.continuation.set_param` accepts (e.g. ``"k"``).
    energy : float
        Total energy [MgL] (:func:`tslip.gait.section.energy`): the forward
        speed at each apex is ``xd = sqrt(2 (E - m g y - J phid^2 / 2) / m)``.
    options : IntegratorOptions, optional
        Default ``IntegratorOptions.tight("dop853")`` (tolerance 1e-12).

    Returns
    -------
    StateActionMap
        A stride fails (status not OK) for a fall, an apex too low for the
        leg to reach the ground (``FALL_NO_TOUCHDOWN``), a lift-off moving
        down (``NO_APEX``) or an integration error.
    """
    names, grid, action, acts, E = check_map_inputs(params, states, actions, energy)
    options = options or IntegratorOptions.tight("dop853")
    t0 = time.perf_counter()
    pts = np.stack(grid_columns(grid), axis=1)
    nxt, status = map_cells(params, names, pts, (action, acts), E, options)
    shape = tuple(len(g) for g in grid) + (len(acts),)
    return StateActionMap(names, grid, action, acts, nxt.reshape(shape + (len(names),)),
                          status.reshape(shape), E, params,
                          {"options": dataclasses.asdict(options),
                           "seconds": time.perf_counter() - t0})


# ---------------------------------------------------------------------------
# basins of attraction
# ---------------------------------------------------------------------------


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
