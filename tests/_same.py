"""Bit-for-bit comparison of result objects, written for the tests (not tslip's code)."""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Sequence
from typing import Any

import numpy as np


def _floats_same(a: np.ndarray, b: np.ndarray) -> bool:
    """Same bits, except that any NaN equals any NaN (JSON text keeps no NaN payload)."""
    if a.dtype.kind == "c":
        return _floats_same(a.real.copy(), b.real.copy()) and _floats_same(a.imag.copy(),
                                                                           b.imag.copy())
    na, nb = np.isnan(a), np.isnan(b)
    return bool(np.array_equal(na, nb)) and a[~na].tobytes() == b[~nb].tobytes()


def same(a: Any, b: Any, where: str = "obj") -> None:
    """Assert that ``b`` is ``a`` rebuilt: same types, same bits, recursively."""
    if isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray), f"{where}: {type(b).__name__} is not an array"
        assert a.dtype == b.dtype and a.shape == b.shape, (where, a.dtype, b.dtype, a.shape,
                                                           b.shape)
        if a.dtype.kind in "fc":
            assert _floats_same(a, b), f"{where}: values differ"
        elif a.dtype.kind == "O":
            for i, (x, y) in enumerate(zip(a.ravel(), b.ravel())):
                same(x, y, f"{where}[{i}]")
        else:
            assert np.array_equal(a, b), f"{where}: values differ"
        return
    if type(a).__name__ == "DataFrame":
        assert list(a.columns) == list(b.columns), where
        for c in a.columns:
            same(a[c].to_numpy(), b[c].to_numpy(), f"{where}[{c!r}]")
        return
    assert type(a) is type(b), f"{where}: {type(a).__name__} != {type(b).__name__}"
    if dataclasses.is_dataclass(a):
        for f in dataclasses.fields(a):
            same(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
    elif isinstance(a, enum.Enum):
        assert a is b, where
    elif isinstance(a, (float, np.floating)):
        assert (math.isnan(a) and math.isnan(b)) or np.array(a).tobytes() == np.array(
            b).tobytes(), f"{where}: {a!r} != {b!r}"
    elif isinstance(a, (complex, np.complexfloating)):
        same(np.array([a]), np.array([b]), where)
    elif isinstance(a, dict):
        assert list(a) == list(b), f"{where}: keys {list(a)} != {list(b)}"
        for k in a:
            same(a[k], b[k], f"{where}[{k!r}]")
    elif isinstance(a, Sequence) and not isinstance(a, str):
        assert len(a) == len(b), f"{where}: length {len(a)} != {len(b)}"
        for i, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{where}[{i}]")
    else:
        assert a == b, f"{where}: {a!r} != {b!r}"
