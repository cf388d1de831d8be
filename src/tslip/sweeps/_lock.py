"""One writer per study folder: ``folder/.lock``.

The lock is an advisory ``flock`` on ``folder/.lock``; the file holds the
holder's pid, host and start time. The kernel releases the lock when its
process ends, however it ends, so a crashed or killed run never blocks the
next one: its lock is stale, and the next run takes it over (and says so
in one line for all the folders it locks, naming the old pid). A run that
ends normally empties the file. The file is never deleted: deleting a
locked file lets two later runs lock two different files. It is opened without
following a link (:func:`tslip._safefile.open_below`): a ``.lock`` (or a folder
below ``root``) that is a link is refused with one line, its target untouched
and unread.
"""

from __future__ import annotations

import json
import logging
import os
import re
import socket
import time
from collections.abc import Iterable, Iterator
from contextlib import AbstractContextManager, ExitStack, contextmanager
from pathlib import Path

from .._safefile import open_below

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows: no locking
    fcntl = None  # type: ignore[assignment]

__all__ = ["FolderLocked", "folder_lock", "folder_locks"]

log = logging.getLogger("tslip")


class FolderLocked(ValueError):
    """Another run holds the study folder (one line: the folder and the holder)."""


def _holder(fd: int) -> dict:
    """The holder the file records: its pid, host and start, each only if it is one
    (a file of other text names no holder and is never echoed)."""
    os.lseek(fd, 0, os.SEEK_SET)
    text = os.read(fd, 4096).decode(errors="replace").strip()
    if not text:
        return {}
    try:
        rec = json.loads(text)
    except (ValueError, RecursionError):
        rec = None
    if not isinstance(rec, dict):
        return {"pid": "?", "host": "?", "started": "?"}
    pid, host, started = rec.get("pid"), rec.get("host"), rec.get("started")
    return {"pid": pid if isinstance(pid, int) and not isinstance(pid, bool) else "?",
            "host": host if isinstance(host, str) and _HOST.fullmatch(host) else "?",
            "started": started if isinstance(started, str) and _TIME.fullmatch(started)
            else "?"}


_HOST = re.compile(r"[A-Za-z0-9_.:-]{1,255}")
_TIME = re.compile(r"\d{4}-\d\d-\d\d \d\d:\d\d:\d\d")


def _describe(h: dict) -> str:
    return f"pid {h.get('pid', '?')} on {h.get('host', '?')} (started {h.get('started', '?')})"


def folder_lock(folder: str | Path, *, wait: bool = False) -> AbstractContextManager[None]:
    """Hold ``folder/.lock`` for the block.

    ``folder`` may itself be a link (the user named it); ``.lock`` may not
    (:class:`tslip._safefile.UnsafePath`, a ValueError).

    Raises
    ------
    FolderLocked
        If another live process holds it and ``wait`` is false; with ``wait``
        the call blocks until that process ends.
    """
    return folder_locks([folder], wait=wait)


@contextmanager
def folder_locks(folders: Iterable[str | Path], *, wait: bool = False,
                 root: str | Path | None = None) -> Iterator[None]:
    """Hold every folder's lock for the block (:func:`folder_lock`); one warning line
    names the stale locks taken over (a killed run of many studies left one in each).

    ``root``, the output folder the folders lie in (default: each folder itself):
    no folder below it is followed if it is a link."""
    stale: list[tuple[Path, str]] = []
    # one holder record for every folder: a run that locks many names one start time in all
    # (the clock read per folder named a run that crossed a second as two holders)
    me = {"pid": os.getpid(), "host": socket.gethostname(),
          "started": time.strftime("%Y-%m-%d %H:%M:%S")}
    with ExitStack() as stack:
        for folder in folders:
            stack.enter_context(_lock(Path(folder), wait, stale,
                                      Path(folder) if root is None else Path(root), me))
        if stale:
            holders = sorted({who for _, who in stale})
            where = (str(stale[0][0]) if len(stale) == 1 else
                     f"{len(stale)} folders under {os.path.commonpath([f for f, _ in stale])}")
            log.warning("taking over the stale lock%s on %s from %s, which is no longer "
                        "running", "s" if len(stale) > 1 else "", where, " and ".join(holders))
        yield


@contextmanager
def _lock(folder: Path, wait: bool, stale: list[tuple[Path, str]], root: Path,
          me: dict) -> Iterator[None]:
    """Hold ``folder/.lock``, recording the holder ``me`` in it; a stale holder is added to
    ``stale``."""
    fd = open_below(root, folder / ".lock", os.O_RDWR | os.O_CREAT, 0o644)
    try:
        if fcntl is not None:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                who = _describe(_holder(fd))
                if not wait:
                    raise FolderLocked(f"study folder {folder} is in use by {who}; wait "
                                       "for that run to finish (or pass --wait)") from None
                log.warning("waiting for %s to release %s", who, folder)
                fcntl.flock(fd, fcntl.LOCK_EX)
        old = _holder(fd)
        if old:  # the last holder ended without releasing: crashed or killed
            stale.append((folder, _describe(old)))
        os.ftruncate(fd, 0)
        os.pwrite(fd, json.dumps(me).encode(), 0)
        try:
            yield
        finally:
            os.ftruncate(fd, 0)
    finally:
        os.close(fd)
