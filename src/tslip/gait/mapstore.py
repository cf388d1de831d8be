"""A state-action map held on disk chunk by chunk and read on demand (a run's chunk store).

:class:`StoredMap` is what :func:`tslip.sweeps.viability.run_viability` with an
output folder returns as its result's ``map``: the grid of a
:class:`tslip.gait.statemap.StateActionMap` and the files of its chunks,
never the whole map in memory, so a map larger than memory is never loaded
whole. :func:`read_chunk` reads one chunk as data only (no pickle). Both
names are also importable from :mod:`tslip.gait.viability`, where they lived
before the split (after 0.3.0).
"""

from __future__ import annotations

import functools
import math
import zipfile
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..model.parameters import Params
from ..simulation.result import Status
from .statemap import StateActionMap, _MapGrid

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["StoredMap", "read_chunk"]


@dataclass(frozen=True, eq=False, repr=False)
class StoredMap(_MapGrid):
    """A state-action map held on disk chunk by chunk, read on demand (a run's chunk store).

    What :func:`tslip.sweeps.viability.run_viability` with an output folder
    returns as its result's ``map``: the grid of a :class:`StateActionMap`
    and the files of its chunks (consecutive blocks of the grid's states in
    C order, each with every action; :func:`read_chunk`), never the whole
    map in memory. :func:`viability` works on it chunk by chunk. ``next``,
    ``status`` and :meth:`to_dataframe` read every chunk (the whole map in
    memory, once: for maps that fit), as does :meth:`load`.

    Attributes
    ----------
    names, grid, action, actions, energy, params, meta : as :class:`StateActionMap`
    folder : Path
        The chunk store (``cache/`` of the run's folder).
    files : tuple of str
        The chunk files in ``folder``, in the order of the states.
    points : tuple of int
        State points in each chunk.
    """

    names: tuple[str, ...]
    grid: tuple[np.ndarray, ...]
    action: str | tuple[str, ...]
    actions: np.ndarray | tuple[np.ndarray, ...]
    folder: Path
    files: tuple[str, ...]
    points: tuple[int, ...]
    energy: float = math.nan
    params: Params | None = None
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        n = int(np.prod([len(g) for g in self.grid]))
        if len(self.files) != len(self.points) or sum(self.points) != n:
            raise ValueError(f"the chunks must cover the {n} states of the grid, got "
                             f"{sum(self.points)} in {len(self.files)} files")

    def read(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Chunk ``k``: ``next`` (n_points, n_actions, n_names) and ``status``
        (n_points, n_actions); ``ValueError`` if the file is gone or not that data."""
        got = read_chunk(self.folder / self.files[k], self.points[k], self.n_actions,
                         len(self.names))
        if got is None:
            raise ValueError(f"chunk {self.folder / self.files[k]} is missing or damaged; rerun "
                             "the viability run to compute it again")
        return got

    def chunks(self) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """Every chunk in order, one read at a time."""
        return (self.read(k) for k in range(len(self.files)))

    @property
    def failed(self) -> np.ndarray:
        """Pairs whose stride failed (one byte a pair, read chunk by chunk)."""
        return np.concatenate([st != Status.OK for _, st in self.chunks()]).reshape(self.shape)

    @functools.cached_property
    def _loaded(self) -> StateActionMap:
        parts = list(self.chunks())
        shape = self.shape
        nxt = np.concatenate([p[0] for p in parts]).reshape(shape + (len(self.names),))
        status = np.concatenate([p[1] for p in parts]).reshape(shape)
        return StateActionMap(self.names, self.grid, self.action, self.actions, nxt, status,
                              self.energy, self.params, self.meta)

    def load(self) -> StateActionMap:
        """The whole map in memory (read once, then kept)."""
        return self._loaded

    @property
    def next(self) -> np.ndarray:
        """:attr:`StateActionMap.next`, read from the store (:meth:`load`)."""
        return self.load().next

    @property
    def status(self) -> np.ndarray:
        """:attr:`StateActionMap.status`, read from the store (:meth:`load`)."""
        return self.load().status

    def __repr__(self) -> str:
        return f"StoredMap({self._label()}; {len(self.files)} chunks in {self.folder})"

    def to_dataframe(self) -> pd.DataFrame:
        return self.load().to_dataframe()

    def _fields(self) -> dict[str, Any]:
        return self.load()._fields()

    def save(self, path: str | Path) -> Path:
        """The map in memory (:meth:`load`) saved as a :class:`StateActionMap`."""
        return self.load().save(path)


def read_chunk(path: str | Path, n_points: int, n_actions: int,
               n_names: int) -> tuple[np.ndarray, np.ndarray] | None:
    """A stored chunk's ``(next, status)``, or None if it is not exactly that data.

    Data only: read with ``allow_pickle=False`` (an object array is refused),
    the two arrays and nothing else, ``next`` float64 of shape
    ``(n_points, n_actions, n_names)`` and ``status`` an integer array of
    shape ``(n_points, n_actions)``. Anything else (damaged, foreign, a
    pickle) is None.
    """
    try:
        with open(path, "rb") as f, np.load(f, allow_pickle=False) as z:
            if sorted(z.files) != ["next", "status"]:
                return None
            nxt, status = z["next"], z["status"]
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
        return None
    if (nxt.dtype != np.float64 or status.dtype.kind not in "iu"
            or nxt.shape != (n_points, n_actions, n_names)
            or status.shape != (n_points, n_actions)):
        return None
    return nxt, status.astype(np.int64)
