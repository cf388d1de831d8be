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
computed again. Lines are data only, read by the package's one strict reader
(:func:`tslip._lines.read_lines`, schema :data:`SCHEMA`): a line that is not an
object of a string ``key`` and a ``record`` of numbers, strings, booleans and
nulls (not UTF-8, not JSON, nested too deep, another shape) is ignored with one
warning naming the file and its lines, and its point computed again; nothing
in it is evaluated. The file and ``cache/`` are opened without following a
link (:mod:`tslip._safefile`): a link there is refused, never written through.
Records of another configuration (the code, the base parameters, the
resolution changed) sit in another file: they are never read by this
configuration and never deleted, so changing a study back reuses them.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from .._lines import SCALAR, STRING, MapOf, Schema, read_lines
from .._safefile import open_below

__all__ = ["SCHEMA", "SUFFIX", "Writer", "read"]

SUFFIX = ".jsonl"
#: A line of the store: a point's key and its record of plain values.
SCHEMA = Schema({"key": STRING, "record": MapOf(SCALAR)})


class Writer:
    """Appends records to ``path``, each as one line in one write; a context manager.

    The file (and its folders below ``root``, the output folder; default the
    file's own folder) is opened on the first record, never through a link, and
    closed on exit. ``path`` None keeps nothing (a study run without a folder).
    """

    def __init__(self, path: str | Path | None, root: str | Path | None = None) -> None:
        self.path = None if path is None else Path(path)
        self.root = Path(root) if root is not None else (
            None if self.path is None else self.path.parent)
        self._fd: int | None = None

    def add(self, key: str, record: dict[str, Any]) -> None:
        """Append the record of point ``key``: it is saved when this returns."""
        if self.path is None:
            return
        line = (json.dumps({"key": key, "record": record}) + "\n").encode()
        if self._fd is None:
            assert self.root is not None
            self._fd = open_below(self.root, self.path,
                                  os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o666)
        view = memoryview(line)
        while view:
            view = view[os.write(self._fd, view):]

    def __enter__(self) -> Writer:
        return self

    def __exit__(self, *exc: object) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None


def read(path: str | Path, *, repair: bool = False,
         root: str | Path | None = None) -> dict[str, dict[str, Any]]:
    """The records in ``path`` by point key (empty if there is no file).

    ``root`` is the output folder (default: the file's folder); nothing below it
    is followed if it is a link. Bad lines are ignored with one warning; a torn
    last line is ignored, and with ``repair`` (only by the run that holds the
    folder's lock) also cut off the file, so the next append starts a line of
    its own.
    """
    path = Path(path)
    out: dict[str, dict[str, Any]] = {}
    what = ("its point is computed again", "their points are computed again")
    for item in read_lines(path.parent if root is None else root, path, SCHEMA, repair=repair,
                           constants=True, what=what):
        out.setdefault(item["key"], item["record"])
    return out
