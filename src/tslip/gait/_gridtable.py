"""Grid results as tables: one row per cell, grid coordinates first, saved to Parquet.

The viability results (:mod:`tslip.gait.viability`) are numpy arrays on a
grid. Their table form has one row per grid cell in C order (the first
grid axis slowest), the grid coordinates as the first columns, and the
units in ``df.attrs["units"]``. :func:`save_table` writes it to Parquet
with the result's description (grid axes, names, parameters, ...) as JSON
in the file's schema metadata, so :func:`load_table` gives back the same
arrays bit for bit (Parquet stores float64 exactly; JSON writes floats by
``repr``, which round-trips).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .._io import atomic_write

__all__ = ["grid_columns", "load_table", "save_table", "META_KEY"]

#: Schema-metadata key of the result's description.
META_KEY = b"tslip"


def grid_columns(axes: Sequence[np.ndarray]) -> list[np.ndarray]:
    """The coordinates of every cell of the grid, one column per axis (C order)."""
    mesh = np.meshgrid(*axes, indexing="ij")
    return [m.ravel() for m in mesh]


def save_table(df: Any, meta: dict[str, Any], path: str | Path) -> Path:
    """Write ``df`` (with ``meta`` and its units) to ``path`` (``.parquet``) atomically."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = Path(path)
    if path.suffix.lower() != ".parquet":
        raise ValueError(f"path must end in .parquet, got {str(path)!r}")
    table = pa.Table.from_pandas(df, preserve_index=False)
    info = dict(meta, units=dict(df.attrs.get("units", {})))
    table = table.replace_schema_metadata({**(table.schema.metadata or {}),
                                           META_KEY: json.dumps(info).encode()})
    return atomic_write(path, lambda tmp: pq.write_table(table, tmp))


def load_table(path: str | Path, kind: str) -> tuple[Any, dict[str, Any]]:
    """The table and the description saved by :func:`save_table`; ``kind`` must match."""
    import pyarrow.parquet as pq

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{kind} file {str(path)!r} does not exist")
    try:
        table = pq.read_table(path)
        meta = json.loads((table.schema.metadata or {})[META_KEY])
    except (OSError, KeyError, ValueError) as exc:
        raise ValueError(f"{str(path)!r} is not a saved tslip {kind} ({exc})") from None
    if meta.get("kind") != kind:
        raise ValueError(f"{str(path)!r} holds a {meta.get('kind')!r}, not a {kind!r}")
    df = table.to_pandas()
    df.attrs["units"] = meta.get("units", {})
    return df, meta
