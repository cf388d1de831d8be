"""The state-action map on the apex section (as the *vibly* package): its grid and cells.

A :class:`StateActionMap` holds, for every grid state at the apex (apex
height ``y``; for the TSLIP up to three section variables, ``(y, phi, phid)``)
and every grid action (one or two parameters, e.g. the touch-down angle
``alpha_r``), the next apex state after one stride at fixed total energy, or
the reason it failed. :func:`state_action_map` computes one; all cells run in
one call of the batched compiled kernels (:func:`map_cells`, through
:func:`tslip.gait.section.apex_map_states`). A map of any discrete system can
be built from arrays (:meth:`StateActionMap.from_arrays`). The same map held
on disk chunk by chunk is :class:`tslip.gait.mapstore.StoredMap`; its viability
kernel is :func:`tslip.gait.viability.viability`. Every name here is also
importable from :mod:`tslip.gait.viability`, where it lived before
the split (after 0.3.0).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import check_number
from .._results import Result, with_units
from ..model.parameters import Params
from ..model.units import COLUMN_UNITS, param_unit
from ..simulation.options import IntegratorOptions
from ..simulation.result import Status
from . import _viable, section
from .continuation import set_param

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["StateActionMap", "state_action_map", "STATE_NAMES", "SECTION_UNITS",
           "check_map_inputs", "map_cells", "grid_columns"]

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


class _MapGrid:
    """The grid part of a state-action map, in memory or stored (names, grid, actions)."""

    __slots__ = ()
    names: tuple[str, ...]
    grid: tuple[np.ndarray, ...]
    action: str | tuple[str, ...]
    actions: np.ndarray | tuple[np.ndarray, ...]
    energy: float

    @property
    def action_names(self) -> tuple[str, ...]:
        """The action names, one or two, in the order of the map's action axes."""
        return (self.action,) if isinstance(self.action, str) else tuple(self.action)

    @property
    def action_grids(self) -> tuple[np.ndarray, ...]:
        """The action grids, one per name of :attr:`action_names`."""
        return (self.actions,) if isinstance(self.actions, np.ndarray) else tuple(self.actions)

    @property
    def shape(self) -> tuple[int, ...]:
        # (grid shape..., action shape...); no docstring, so the API docs leave it out: a
        # second documented ``shape`` makes numpydoc's "shape (n,)" type cross-references
        # ambiguous
        return tuple(len(g) for g in self.grid) + tuple(len(a) for a in self.action_grids)

    @property
    def n_actions(self) -> int:
        """Action grid points (the product over the action axes)."""
        return int(np.prod([len(a) for a in self.action_grids]))

    def _label(self) -> str:
        e = "" if math.isnan(self.energy) else f", energy {self.energy:.6g}"
        return (f"{_short(self.grid, self.names)} x "
                f"{_short(self.action_grids, self.action_names)}{e}")

    def _frame(self, start: int, nxt: np.ndarray, status: np.ndarray) -> pd.DataFrame:
        """The table rows of the states ``start, start + 1, ...`` (C order) x every action:
        ``nxt`` (n_points, n_actions, n_names) and ``status`` (n_points, n_actions)."""
        import pandas as pd

        n_a = self.n_actions
        idx = np.unravel_index(np.arange(start, start + len(status)),
                               tuple(len(g) for g in self.grid))
        data: dict[str, Any] = {n: np.repeat(g[i], n_a)
                                for n, g, i in zip(self.names, self.grid, idx)}
        data.update({n: np.tile(c, len(status))
                     for n, c in zip(self.action_names, grid_columns(self.action_grids))})
        for j, n in enumerate(self.names):
            data[f"next_{n}"] = nxt[..., j].ravel()
        data["status"] = np.asarray(status).ravel()
        units = {n: _unit(n) for n in list(self.names) + list(self.action_names)}
        units.update({f"next_{n}": _unit(n) for n in self.names}, status="-")
        return with_units(pd.DataFrame(data), units)


@dataclass(frozen=True, eq=False, repr=False)
class StateActionMap(_MapGrid, Result):
    """One stride from every grid state with every grid action.

    Attributes
    ----------
    names : tuple of str
        Names of the state variables (one to three), e.g. ``("y",)``.
    grid : tuple of ndarray
        The state grid axes (strictly increasing), one per name.
    action : str or tuple of two str
        Name of the action, e.g. ``"alpha_r"``; for two actions their names,
        e.g. ``("alpha_r", "k")`` (:attr:`action_names` is always a tuple).
    actions : ndarray or tuple of two ndarray
        The action grid (strictly increasing), or one per action
        (:attr:`action_grids` is always a tuple).
    next : ndarray, shape (grid shape..., action shape..., n_names)
        The next state; NaN where the stride failed.
    status : ndarray of int, shape (grid shape..., action shape...)
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
    action: str | tuple[str, ...]
    actions: np.ndarray | tuple[np.ndarray, ...]
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
                    actions: Any, next: np.ndarray,
                    failed: np.ndarray | None = None) -> StateActionMap:
        """A map of any discrete system: its grids, successors and failures.

        ``actions`` is ``(name, grid)`` or ``{name: grid}`` with one or two
        entries; ``next`` has shape ``(*grid shape, *action shape[, n_states])``
        (the last axis may be left out for one state variable); ``failed``
        (bool, same shape without that axis) marks the pairs that fail at
        once (status 1), default: where ``next`` is not finite.
        """
        names, grid = _state_grid(states)
        action, acts = _action_grid(actions)
        nxt = np.asarray(next, dtype=float)
        shape = tuple(len(g) for g in grid) + tuple(len(a) for a in acts)
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
        return cls(names, grid, *_action_fields(action, acts), nxt, bad.astype(np.int64))

    @property
    def failed(self) -> np.ndarray:
        """Pairs whose stride failed (a fall, no apex, an error)."""
        return self.status != Status.OK

    def __repr__(self) -> str:
        return (f"StateActionMap({self._label()}; "
                f"{int(self.failed.sum())} of {self.failed.size} fail)")

    def to_dataframe(self) -> pd.DataFrame:
        """One row per (state, action) cell: coordinates, next state, status."""
        n = int(np.prod([len(g) for g in self.grid]))
        return self._frame(0, self.next.reshape(n, self.n_actions, -1),
                           self.status.reshape(n, -1))

    def _table_fields(self) -> tuple[str, ...]:
        return ("next", "status")

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        """``next`` and ``status`` back from the table; the grid comes from the record."""
        acts = fields["actions"]
        acts = (acts,) if isinstance(acts, np.ndarray) else acts
        shape = tuple(len(g) for g in fields["grid"]) + tuple(len(a) for a in acts)
        nxt = np.stack([df[f"next_{n}"].to_numpy(float).reshape(shape)
                        for n in fields["names"]], axis=-1)
        return dict(fields, next=nxt, status=df["status"].to_numpy(np.int64).reshape(shape))


def _state_grid(states: Mapping[str, Any]) -> tuple[tuple[str, ...], tuple[np.ndarray, ...]]:
    if not isinstance(states, Mapping) or not 1 <= len(states) <= 3:
        raise ValueError("states must be a dict of one to three grids, e.g. {'y': grid}, got "
                         f"{states!r}")
    names = tuple(str(n) for n in states)
    return names, tuple(_viable.check_grid(states[n], f"states[{n!r}]") for n in names)


def _action_grid(actions: Any) -> tuple[tuple[str, ...], tuple[np.ndarray, ...]]:
    """``(name, grid)`` or ``{name: grid}`` (one or two entries) as names and checked grids."""
    if isinstance(actions, Mapping):
        if not 1 <= len(actions) <= 2:
            raise ValueError("actions must be a dict of one or two {name: grid} entries, got "
                             f"{len(actions)}")
        names = tuple(str(n) for n in actions)
        return names, tuple(_viable.check_grid(actions[n], f"actions[{n!r}]") for n in names)
    if not (isinstance(actions, tuple) and len(actions) == 2 and isinstance(actions[0], str)):
        raise ValueError("actions must be (name, grid) or {name: grid} (one or two entries), "
                         f"e.g. ('alpha_r', grid), got {actions!r}")
    return (actions[0],), (_viable.check_grid(actions[1], f"actions[{actions[0]!r}]"),)


def _action_fields(names: tuple[str, ...], grids: tuple[np.ndarray, ...]
                   ) -> tuple[str | tuple[str, ...], np.ndarray | tuple[np.ndarray, ...]]:
    """A map's ``action`` and ``actions``: a name and a grid for one action, tuples for two."""
    return (names[0], grids[0]) if len(names) == 1 else (names, grids)

# ---------------------------------------------------------------------------
# the physical map: apex to apex at fixed energy (tslip.gait.section)
# ---------------------------------------------------------------------------


def _with_action(params: Params, name: str, value: float) -> Params:
    """``params`` with the action set: ``alpha_r`` directly, others by :func:`set_param`."""
    if name == "alpha_r":
        return dataclasses.replace(params, alpha_r=float(value))
    return set_param(params, name, value)


def _with_actions(params: Params, names: Sequence[str], values: Sequence[float]) -> Params:
    """``params`` with every action of ``names`` set to its value (:func:`_with_action`)."""
    for name, v in zip(names, values):
        params = _with_action(params, name, v)
    return params


def check_map_inputs(params: Params, states: Mapping[str, Any], actions: Any,
                     energy: float) -> tuple[tuple[str, ...], tuple[np.ndarray, ...], Any, Any,
                                             float]:
    """Check a physical map's inputs (one-line ``ValueError`` naming the field); return them
    as ``(names, grid, action, actions, energy)``, the actions as a map holds them
    (:class:`StateActionMap`: a name and a grid for one action, tuples for two)."""
    if not isinstance(params, Params):
        raise ValueError(f"params must be a tslip.Params, got {type(params).__name__}")
    names, grid = _state_grid(states)
    bad = [n for n in names if n not in STATE_NAMES]
    if bad:
        raise ValueError(f"states: unknown apex variable {bad[0]!r}; allowed: "
                         f"{list(STATE_NAMES)} (xd follows from the energy)")
    if "y" not in names:
        raise ValueError("states must include the apex height 'y'")
    anames, agrids = _action_grid(actions)
    corners = list(itertools.product(*[(g[0], g[-1]) for g in agrids]))
    for name, g in zip(anames, agrids):
        for v in (g[0], g[-1]):
            try:
                _with_action(params, name, v)
            except ValueError as exc:
                also = " (or 'alpha_r', the leg angle)" if "unknown parameter" in str(exc) else ""
                raise ValueError(f"actions[{name!r}]: {exc}{also}") from None
    E = float(check_number(energy, "energy [MgL]", lower=0.0, lower_open=True))
    j = names.index("y")
    phid_sq = max(float(np.max(grid[names.index("phid")] ** 2)) if "phid" in names else 0.0, 0.0)
    for vals in corners:
        try:
            p = _with_actions(params, anames, vals)
        except ValueError as exc:  # each action valid alone, not together
            raise ValueError(f"actions {list(anames)}: {exc}") from None
        if not section.apex_section_ok(p):
            raise ValueError("params: the apex is a Poincare section only if the touch-down "
                             "angle follows from the apex state (omega_r = 0, or retraction "
                             f"timed from the apex), got omega_r={p.omega_r!r} with the "
                             "lift-off clock")
        y_max = (E - 0.5 * p.J * phid_sq) / (p.m * p.g)
        if grid[j][-1] >= y_max:
            raise ValueError(f"states['y'] must stay below {y_max:.6g} L at energy {E:g} MgL "
                             f"(no forward speed left there), got up to {grid[j][-1]:g}")
    return (names, grid, *_action_fields(anames, agrids), E)


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


def map_cells(params: Params, names: Sequence[str], points: np.ndarray, actions: Any,
              energy: float, options: IntegratorOptions | None = None
              ) -> tuple[np.ndarray, np.ndarray]:
    """The apex map at ``points`` (n, d) x every action: next states (n, n_a, d), status.

    ``actions`` as :func:`state_action_map` takes them (one or two); ``n_a``
    is the product of their grid sizes, the action columns in C order of the
    actions as given. One batched call (:func:`tslip.gait.section.apex_map_states`,
    whose stances run in one compiled :func:`tslip.step_batch` kernel) over
    the states and the ``alpha_r`` grid for each value of the other action (one
    call for an ``alpha_r`` action alone); without ``alpha_r``, one call per
    action value.
    """
    options = options or IntegratorOptions.tight("dop853")
    anames, agrids = _action_grid(actions)
    pts = np.asarray(points, dtype=float).reshape(-1, len(names))
    shape_a = tuple(len(g) for g in agrids)
    n, n_a, d = len(pts), int(np.prod(shape_a)), len(names)
    nxt = np.empty((n, n_a, d))
    status = np.empty((n, n_a), dtype=np.int64)
    columns = np.arange(n_a).reshape(shape_a)
    other = [k for k, a in enumerate(anames) if a != "alpha_r"]
    alphas = agrids[anames.index("alpha_r")] if "alpha_r" in anames else None
    for ix in itertools.product(*[range(shape_a[k]) for k in other]):
        p = _with_actions(params, [anames[k] for k in other],
                          [float(agrids[k][i]) for k, i in zip(other, ix)])
        pick: list[Any] = [slice(None)] * len(anames)
        for k, i in zip(other, ix):
            pick[k] = i
        cols = columns[tuple(pick)].ravel()
        rows = _apex_rows(p, names, pts, energy)
        if alphas is None:
            b = section.apex_map_states(p, rows, options=options)
        else:
            b = section.apex_map_states(p, np.repeat(rows, len(alphas), axis=0),
                                        np.tile(alphas, n), options=options)
        nxt[:, cols] = np.stack([getattr(b, c) for c in names], axis=-1).reshape(n, -1, d)
        status[:, cols] = np.asarray(b.status, dtype=np.int64).reshape(n, -1)
    nxt[status != Status.OK] = np.nan
    return nxt, status


def state_action_map(params: Params, states: Mapping[str, Sequence[float] | np.ndarray],
                     actions: tuple[str, Sequence[float] | np.ndarray]
                     | Mapping[str, Sequence[float] | np.ndarray], *, energy: float,
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
        ``{"alpha_r": angles}`` (the leg angle set
        at lift-off, the SLIP's touch-down angle [rad]) or any parameter
        :func:`tslip.gait.continuation.set_param` accepts (e.g. ``"k"``);
        a dict may hold two actions, e.g. ``{"alpha_r": angles, "omega_r":
        rates}`` (with ``retraction="apex"``: the lift-off clock is not an
        apex section): the map's last axes are the actions in that order.
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
    anames, agrids = _action_grid(actions)
    options = options or IntegratorOptions.tight("dop853")
    t0 = time.perf_counter()
    pts = np.stack(grid_columns(grid), axis=1)
    nxt, status = map_cells(params, names, pts, dict(zip(anames, agrids)), E, options)
    shape = tuple(len(g) for g in grid) + tuple(len(g) for g in agrids)
    return StateActionMap(names, grid, action, acts, nxt.reshape(shape + (len(names),)),
                          status.reshape(shape), E, params,
                          {"options": dataclasses.asdict(options),
                           "seconds": time.perf_counter() - t0})
