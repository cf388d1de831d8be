"""The viability iteration on a discrete state-action map (after vibly's ``compute_QV``).

A state-action map on a grid gives, for every grid state ``s`` and grid
action ``a``, whether the step fails and, if not, the successor state
``s' = f(s, a)`` (any real value, on the grid or between its points). The
viability kernel is the largest set of state-action pairs from which the
system never fails (Zaytsev, Wolfslag & Ruina 2018; Heim & Sprowitz 2019,
the *vibly* package). It is found by iterating from "every pair that does
not fail at once" and removing, each sweep, every pair whose successor does
not land in the current set of viable states, until nothing changes. The
iteration only removes pairs, so it ends, after at most as many sweeps as
there are pairs.

What "lands in a viable state" means for a successor between grid points is
the *cell rule*:

``"bracket"`` (default, tslip's own, conservative): the successor counts
    viable only if **every** grid point of the grid cell around it is a
    viable state: the two bracketing points in one dimension, the four
    corners of its grid rectangle in two. A successor on a grid point
    (within :data:`SNAP` of a grid spacing) needs only that point. A
    successor outside the grid's range (beyond :data:`SNAP` of a spacing)
    is not viable: nothing is assumed about what lies outside the grid.
``"nearest"``: the successor counts viable if the nearest grid point is;
    outside the grid's range it is not viable, as for ``"bracket"``.
``"vibly"`` (vibly's rule, ``compute_QV`` on a map binned by
    ``compute_Q_map``): per axis ``b = np.digitize(s', grid)``, so
    ``grid[b-1] <= s' < grid[b]``; the successor counts viable if every grid
    point of the product of ``{b-1, b}`` over the axes that lies inside the
    grid is a viable state. A successor exactly on a grid point needs that
    point and the next one up; one above the top needs the top point, one
    below the bottom the bottom point (outside the grid it is kept when the
    edge state is viable). The one difference from vibly: vibly stores a
    failed step as the raveled bin 0 and so also drops a successor that
    lies below the bottom on every axis; here that successor is kept when
    the bottom corner is viable, and only failed steps fail.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np

__all__ = ["RULES", "SNAP", "CHUNK_ROWS", "check_grid", "encode_chunks", "successor_cells",
           "viable_sets", "viable_sets_chunked"]

#: Cell rules of :func:`successor_cells`.
RULES = ("bracket", "nearest", "vibly")
#: A successor within this fraction of a grid spacing of a grid point is on it.
SNAP = 1e-9
#: State-action rows per chunk of :func:`viable_sets_chunked`'s sweep (its temporaries,
#: a few bytes a row, stay in the processor's cache).
CHUNK_ROWS = 1 << 16


def check_grid(values: object, name: str) -> np.ndarray:
    """A grid axis as a float array: finite, 1-D, non-empty, strictly increasing."""
    try:
        g = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a sequence of numbers, got {values!r}") from None
    if g.ndim != 1 or g.size == 0:
        raise ValueError(f"{name} must be a non-empty 1-D grid, got shape {g.shape}")
    if not np.all(np.isfinite(g)):
        raise ValueError(f"{name} must be finite")
    if g.size > 1 and not np.all(np.diff(g) > 0):
        raise ValueError(f"{name} must be strictly increasing")
    return g


def _bracket_1d(g: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per value: index of the grid point below and above it, and whether it is inside."""
    n = g.size
    if n == 1:
        inside = np.abs(x - g[0]) <= SNAP * max(1.0, abs(g[0]))
        zero = np.zeros(x.shape, dtype=np.int64)
        return zero, zero, inside
    lo = np.clip(np.searchsorted(g, x, side="right") - 1, 0, n - 2)
    hi = lo + 1
    width = g[hi] - g[lo]
    on_lo = np.abs(x - g[lo]) <= SNAP * width
    on_hi = np.abs(x - g[hi]) <= SNAP * width
    hi = np.where(on_lo, lo, hi)
    lo = np.where(on_hi & ~on_lo, hi, lo)
    inside = ((x >= g[0]) & (x <= g[-1])) | on_lo | on_hi
    return lo.astype(np.int64), hi.astype(np.int64), inside


def successor_cells(axes: Sequence[np.ndarray], nxt: np.ndarray, ok: np.ndarray,
                    rule: str = "bracket") -> np.ndarray:
    """Flat state indices each successor needs viable; ``-1`` where it cannot be.

    Parameters
    ----------
    axes : sequence of d 1-D arrays
        The state grid (strictly increasing axes).
    nxt : ndarray, shape (n, d)
        Successor states (ignored where ``ok`` is false).
    ok : ndarray of bool, shape (n,)
        The step did not fail.
    rule : {"bracket", "nearest", "vibly"}
        The cell rule (module docstring).

    Returns
    -------
    ndarray of int32, shape (n, 2**d) for ``"bracket"`` and ``"vibly"``, (n, 1) for ``"nearest"``
        Indices into the flattened (C-order) state grid (a point may repeat);
        a row with a ``-1`` is a successor that counts as not viable whatever
        the states are: a failed step, or one beyond the grid under
        ``"bracket"`` and ``"nearest"`` (``"vibly"`` bins a successor beyond
        the grid onto its edge points, so it needs no extra bin). This is the
        compact successor encoding: 4 bytes a corner, whatever the rule.
    """
    if int(np.prod([len(g) for g in axes])) >= np.iinfo(np.int32).max:
        raise ValueError("the state grid must have fewer than 2**31 - 1 points for int32 cells")
    if rule not in RULES:
        raise ValueError(f"rule must be one of {list(RULES)}, got {rule!r}")
    nxt = np.asarray(nxt, dtype=float)
    shape = tuple(len(g) for g in axes)
    valid = np.asarray(ok, dtype=bool) & np.all(np.isfinite(nxt), axis=1)
    x = np.where(valid[:, None], nxt, np.array([g[0] for g in axes]))
    if rule == "vibly":
        # per axis the in-grid points of {b-1, b}: clipped onto the grid, a pair (0, 0) or
        # (n-1, n-1) is the one edge point
        pairs = []
        for j, g in enumerate(axes):
            b = np.digitize(x[:, j], g)  # g[b-1] <= x < g[b]
            pairs.append((np.clip(b - 1, 0, g.size - 1), np.clip(b, 0, g.size - 1)))
    else:
        brackets = [_bracket_1d(g, x[:, j]) for j, g in enumerate(axes)]
        for _, _, inside in brackets:
            valid &= inside
        pairs = [(lo, hi) for lo, hi, _ in brackets]
    if rule == "nearest":
        idx = [np.where(np.abs(x[:, j] - g[hi]) < np.abs(x[:, j] - g[lo]), hi, lo)
               for j, (g, (lo, hi)) in enumerate(zip(axes, pairs))]
        cells = np.ravel_multi_index(tuple(idx), shape)[:, None]
    else:
        corners = [np.ravel_multi_index(tuple(pairs[j][c] for j, c in enumerate(pick)), shape)
                   for pick in itertools.product((0, 1), repeat=len(shape))]
        cells = np.stack(corners, axis=1)
    cells = cells.astype(np.int32)
    cells[~valid] = -1
    return cells


def encode_chunks(axes: Sequence[np.ndarray], nxt: np.ndarray, ok: np.ndarray,
                  rule: str = "bracket", rows: int = CHUNK_ROWS) -> list[np.ndarray]:
    """:func:`successor_cells` chunk by chunk: the compact map for :func:`viable_sets_chunked`.

    A failed row gets ``-1`` in every column, so the chunks alone say which
    pairs fail; the float successors are needed only ``rows`` at a time.
    """
    nxt = np.asarray(nxt, dtype=float)
    ok = np.asarray(ok, dtype=bool)
    out = []
    for i in range(0, len(nxt), rows):
        c = successor_cells(axes, nxt[i:i + rows], ok[i:i + rows], rule)
        c[~ok[i:i + rows]] = -1
        out.append(c)
    return out


def viable_sets(cells: np.ndarray, ok: np.ndarray, n_states: int,
                max_iter: int | None = None) -> tuple[np.ndarray, np.ndarray, int]:
    """Iterate to the viable state-action pairs and viable states.

    ``cells`` (n_states * n_actions, m) from :func:`successor_cells`, rows in
    (state, action) C order; ``ok`` the same rows' "did not fail". Starting
    from ``Q = ok``, each sweep sets ``S = any over actions of Q`` and keeps
    in ``Q`` only the pairs whose ``m`` cells are all in ``S`` (a ``-1`` is
    never in it), until ``Q`` stops changing.

    Returns
    -------
    q : ndarray of bool, shape (n_states, n_actions)
        Viable state-action pairs.
    s : ndarray of bool, shape (n_states,)
        Viable states (some action is viable).
    sweeps : int
        Sweeps that removed something.
    """
    n = cells.shape[0]
    if n % n_states:
        raise ValueError(f"{n} rows are not a multiple of {n_states} states")
    q = (np.asarray(ok, dtype=bool) & np.all(cells >= 0, axis=1)).reshape(n_states, -1)
    cells = cells.reshape(n_states, q.shape[1], -1)
    limit = q.size + 1 if max_iter is None else max_iter
    sweeps = 0
    while True:
        s = q.any(axis=1)
        s_pad = np.append(s, False)  # index -1: never viable
        q_new = q & s_pad[cells].all(axis=-1)
        if np.array_equal(q_new, q) or sweeps >= limit:
            return q, s, sweeps
        q = q_new
        sweeps += 1


def viable_sets_chunked(chunks: Sequence[np.ndarray], n_states: int, n_actions: int,
                        max_iter: int | None = None) -> tuple[np.ndarray, np.ndarray, int]:
    """:func:`viable_sets` on the compact map held in chunks, never the whole map's temporaries.

    ``chunks`` are int32 cell arrays (from :func:`encode_chunks`, or read
    one at a time from a chunk store: any sequence whose items are arrays),
    consecutive blocks of the (state, action) rows in C order, each row's
    ``-1`` meaning "not viable whatever the states" (a failed pair has one).
    Each sweep computes the states ``S`` from ``Q`` at its start and then
    updates ``Q`` chunk by chunk from that ``S`` (the same sweeps as
    :func:`viable_sets`, so the same ``sweeps`` count); memory beyond the
    chunks is ``Q`` (one byte a pair) and one chunk's temporaries.

    Returns
    -------
    q, s, sweeps : as :func:`viable_sets`
    """
    n = n_states * n_actions
    q = np.empty(n, dtype=bool)
    bounds = []
    start = 0
    for k in range(len(chunks)):
        c = chunks[k]
        if c.ndim != 2 or c.dtype.kind != "i":
            raise ValueError(f"chunk {k} must be a 2-D integer cell array, got {c.dtype} "
                             f"shape {c.shape}")
        stop = start + len(c)
        if stop > n:
            raise ValueError(f"the chunks hold more than {n} rows ({n_states} states x "
                             f"{n_actions} actions)")
        q[start:stop] = np.all(c >= 0, axis=1)
        bounds.append((start, stop))
        start = stop
    if start != n:
        raise ValueError(f"the chunks hold {start} rows, not {n} ({n_states} states x "
                         f"{n_actions} actions)")
    q2 = q.reshape(n_states, n_actions)
    limit = n + 1 if max_iter is None else max_iter
    sweeps = 0
    s_pad = np.zeros(n_states + 1, dtype=bool)  # index -1 (the last): never viable
    while True:
        np.any(q2, axis=1, out=s_pad[:n_states])
        if sweeps >= limit:
            return q2, s_pad[:n_states].copy(), sweeps
        before = np.count_nonzero(q)
        for k, (a, b) in enumerate(bounds):
            live = q[a:b]
            if live.any():
                live &= _all_rows(np.take(s_pad, chunks[k]))
        if np.count_nonzero(q) == before:
            return q2, s_pad[:n_states].copy(), sweeps
        sweeps += 1


def _all_rows(b: np.ndarray) -> np.ndarray:
    """``b.all(axis=1)`` of a C-contiguous bool array; rows of 2, 4 or 8 read as one integer
    each (a bool is one byte, 0 or 1), which is many times faster than the reduction."""
    m = b.shape[1]
    if m in (2, 4, 8):
        ones = int.from_bytes(b"\x01" * m, "little")
        return np.asarray(b.view(f"<u{m}")[:, 0] == ones)
    return np.asarray(b.all(axis=1))
