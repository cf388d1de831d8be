"""A study's point records on disk: one JSON-lines file, appended to point by point.

A study folder's ``cache/`` holds one file per study configuration,
``<configuration key>.jsonl`` (the key hashes what every point's key holds
but the point's own axis values: :func:`tslip.sweeps.run.study_keys`), one
line per final point::

    {"key": "<point key>", "record": {"v0": 4.0, "converged": true, ...}}

A line is written with one ``write`` on a file opened for appending, so the
workers of a run append to the same file without mixing their lines, and a
point is saved the moment it is final. A write killed midway leaves a torn
last line (no newline at its end): readers ignore it, and the next run (which
holds the folder's lock) cuts it off before appending, so that point is
computed again. Lines are data only, read with a strict JSON decoder: a line
that is not an object of a string ``key`` and a ``record`` of numbers,
strings, booleans and nulls is ignored (its point computed again), never
evaluated. Records of another configuration (the code, the base parameters,
the resolution changed) sit in another file: they are never read by this
configuration and never deleted, so changing a study back reuses them.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

__all__ = ["SUFFIX", "Writer", "read"]

SUFFIX = ".jsonl"
_DECODER = json.JSONDecoder()  # strict: plain JSON values, no hooks
_SCALARS = (str, int, float, bool, type(None))


class Writer:
    """Appends records to ``path``, each as one line in one write; a context manager.

    The file (and its folder) is opened on the first record and closed on
    exit. ``path`` None keeps nothing (a study run without a folder).
    """

    def __init__(self, path: str | Path | None) -> None:
        self.path = None if path is None else Path(path)
        self._fd: int | None = None

    def add(self, key: str, record: dict[str, Any]) -> None:
        """Append the record of point ``key``: it is saved when this returns."""
        if self.path is None:
            return
        line = (json.dumps({"key": key, "record": record}) + "\n").encode()
        if self._fd is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o666)
        view = memoryview(line)
        while view:
            view = view[os.write(self._fd, view):]

    def __enter__(self) -> Writer:
        return self

    def __exit__(self, *exc: object) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None


def read(path: str | Path, *, repair: bool = False) -> dict[str, dict[str, Any]]:
    """The records in ``path`` by point key (empty if there is no file).

    A torn last line is ignored; with ``repair`` (only by the run that holds
    the folder's lock) it is also cut off the file, so the next append starts
    a line of its own.
    """
    try:
        data = Path(path).read_bytes()
    except FileNotFoundError:
        return {}
    *lines, torn = data.split(b"\n")
    if torn and repair:
        with open(path, "r+b") as fh:
            fh.truncate(len(data) - len(torn))
    out: dict[str, dict[str, Any]] = {}
    for raw in lines:
        item = _decode(raw)
        if item is not None:
            out.setdefault(item[0], item[1])
    return out


def _decode(raw: bytes) -> tuple[str, dict[str, Any]] | None:
    """``(key, record)`` of one line, or None if it is not such a line."""
    try:
        item = _DECODER.decode(raw.decode("utf-8"))
    except ValueError:  # UnicodeDecodeError is a ValueError too
        return None
    if not (isinstance(item, dict) and item.keys() == {"key", "record"}):
        return None
    key, rec = item["key"], item["record"]
    if not (isinstance(key, str) and isinstance(rec, dict)
            and all(isinstance(v, _SCALARS) for v in rec.values())):
        return None
    return key, rec
