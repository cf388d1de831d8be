"""How much memory a viability run over a grid holds, from the grid's size alone.

A state-action grid's cell count is the product of its axes' points: three
state axes of 100000 points and three actions are 3e15 cells, which no
machine holds. :func:`check_run_fits` refuses such a grid in one line (its
cells, the estimate of :func:`run_bytes`, the memory available) before
anything is allocated. It needs the axes' point counts only, so ``tslip
viability`` asks it straight from the spec's tables (:func:`grid_points`),
before it imports the kernels (seconds) or builds a grid;
:meth:`tslip.sweeps.viability.ViabilitySpec.check_fits` asks it again for
the parsed spec.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from ._checks import available_memory

__all__ = ["BLOCK_ROWS", "CHUNK_CELLS", "check_run_fits", "grid_points", "n_chunks",
           "run_bytes"]

#: Cells (state points x actions) per task and cache file of a viability run.
CHUNK_CELLS = 2000
#: Rows (state-action pairs) of one block of the kernel's iteration and of the table
#: written (:data:`tslip.gait._viable.CHUNK_ROWS`, the same number: a test checks it).
BLOCK_ROWS = 1 << 16
#: Bytes a chunk costs the run however small: its key, its file name and size in the
#: result's store, its bookkeeping in the iteration (Python objects, about 100 bytes each).
CHUNK_BYTES = 400
#: Bytes of one block's temporaries per pair beyond its map values: the block's frame for
#: ``results.parquet`` (about 12 columns of 8 bytes) and pyarrow's copy of it.
ROW_BYTES = 200


def n_chunks(states: Sequence[int], actions: Sequence[int],
             chunk_cells: int = CHUNK_CELLS) -> int:
    """Chunks of a grid of ``states`` x ``actions`` points: whole state points, about
    ``chunk_cells`` cells each (at least one state point)."""
    per = max(1, chunk_cells // math.prod(actions))
    return -(-math.prod(states) // per)


def run_bytes(states: Sequence[int], actions: Sequence[int], rule: str, stored: bool,
              chunk_cells: int = CHUNK_CELLS) -> int:
    """Estimated bytes a viability run over the grid holds, beyond the interpreter.

    ``states``, ``actions``: points of each state and action axis. ``stored``
    (a run with an output folder): the viable pairs (one byte a pair), the
    viable states (three bytes a state: the iteration's, its copy, the
    result's), each chunk's bookkeeping and one block's temporaries; the map
    and its successor cells stay on disk. Not stored: the map too, held twice
    while its chunks are joined (next states, 8 bytes a state variable, and the
    status, 8), its successor cells (4 bytes a grid corner of the cell rule: one
    for ``"nearest"``, 2**d otherwise), the failure flags and the pairs.
    """
    d, n_states = len(states), math.prod(states)
    pairs = n_states * math.prod(actions)
    corners = 1 if rule == "nearest" else 2 ** d
    block = min(pairs, BLOCK_ROWS) * (ROW_BYTES + 8 * (d + 1) + 4 * corners)
    per_pair = 1 if stored else 2 * 8 * (d + 1) + 4 * corners + 2
    return (pairs * per_pair + 3 * n_states
            + n_chunks(states, actions, chunk_cells) * CHUNK_BYTES + block)


def _size(n: float) -> str:
    """Bytes for a message: ``6.6 PB``, ``1.2 GB``, ``640 kB``."""
    for unit, size in (("EB", 1e18), ("PB", 1e15), ("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n / 1e3:.3g} kB"


def check_run_fits(name: str, states: Sequence[int], actions: Sequence[int], rule: str,
                   stored: bool, chunk_cells: int = CHUNK_CELLS) -> None:
    """Refuse a grid whose run (:func:`run_bytes`) does not fit in the memory available:
    one ``ValueError`` line with its cells, the estimate and the memory available."""
    need, free = run_bytes(states, actions, rule, stored, chunk_cells), available_memory()
    if need > free:
        grid = " x ".join(map(str, states))
        acts = " x ".join(map(str, actions))
        raise ValueError(f"viability grid {name}: {math.prod(states) * math.prod(actions)} "
                         f"cells ({grid} states x {acts} actions) need about {_size(need)} "
                         f"of memory, {_size(free)} available; use fewer points")


def _points(table: Any) -> int | None:
    if not isinstance(table, dict):
        return None
    if "values" in table:
        values = table["values"]
        return len(values) if isinstance(values, list) else None
    points = table.get("points")
    return points if isinstance(points, int) and not isinstance(points, bool) else None


def grid_points(data: dict[str, Any]) -> tuple[list[int], list[int]] | None:
    """The state and action axes' point counts of a viability spec's tables (as read from
    its TOML), or None if they cannot be read so (the spec's parse then says why)."""
    states = data.get("state")
    acts = data.get("actions") if "action" not in data else data["action"]
    if not isinstance(states, list) or not states:
        return None
    if isinstance(acts, dict) and "action" not in data:
        acts = list(acts.values())  # [actions.<name>] tables
    elif isinstance(acts, dict):
        acts = [acts]  # one [action] table
    if not isinstance(acts, list) or not acts:
        return None
    s, a = [_points(t) for t in states], [_points(t) for t in acts]
    if any(n is None or n < 1 for n in s + a):
        return None
    return [int(n) for n in s if n is not None], [int(n) for n in a if n is not None]
