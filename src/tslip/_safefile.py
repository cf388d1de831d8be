"""Files opened inside an output folder without following a symbolic link.

Output folders are copied, shared and downloaded, so a folder may hold a
symbolic link where the package writes (a study's ``cache/`` or one of its
files, a ``.lock``, ``evaluations.jsonl``): written through, it would append
to, truncate or fill the link's target, any file of the user's. Every file the
package appends to, locks or repairs in place inside an output folder is
opened here: the output folder itself is the user's choice (it may be a link),
every folder below it is opened with ``O_NOFOLLOW`` one component at a time
(created when missing), and the file with ``O_NOFOLLOW`` too. A link, a
non-regular file or a file with other hard links is refused with one line
naming it (:class:`UnsafePath`, a ``ValueError``: exit 2 from the CLI). Whole
files written by an atomic rename (:func:`tslip._io.atomic_write`) replace a
link instead of writing through it and need no more than :func:`folder` for
the folders below the output folder.
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

__all__ = ["UnsafePath", "folder", "open_below"]

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_DIRECTORY = getattr(os, "O_DIRECTORY", 0)
_NONBLOCK = getattr(os, "O_NONBLOCK", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)
#: ``dir_fd`` (openat) makes the walk immune to a folder swapped for a link midway.
_AT = os.open in os.supports_dir_fd and os.mkdir in os.supports_dir_fd and bool(_NOFOLLOW)


class UnsafePath(ValueError):
    """A symbolic link (or another non-regular file) where the package would write."""


def _refuse(path: Path, what: str) -> UnsafePath:
    return UnsafePath(f"refusing to write through {path}: it is {what}; remove it or choose "
                      "another output folder")


def _parts(root: Path, path: Path) -> tuple[str, ...]:
    rel = Path(os.path.relpath(path, root))
    if rel.parts[:1] == ("..",) or rel.is_absolute():
        raise ValueError(f"{path} is not inside the output folder {root}")
    return () if rel == Path(".") else rel.parts


def _is_link(name: str, dir_fd: int | None, full: Path) -> bool:
    try:
        mode = (os.lstat(name, dir_fd=dir_fd) if dir_fd is not None else os.lstat(full)).st_mode
    except FileNotFoundError:
        return False
    return stat.S_ISLNK(mode)


def _open_dir(name: str, dir_fd: int, full: Path, create: bool) -> int:
    """fd of the folder ``name`` in ``dir_fd``, never through a link (created if asked)."""
    flags = os.O_RDONLY | _DIRECTORY | _NOFOLLOW | _CLOEXEC
    for attempt in (0, 1):
        try:
            return os.open(name, flags, dir_fd=dir_fd)
        except FileNotFoundError:
            if not create or attempt:
                raise
            try:
                os.mkdir(name, 0o777, dir_fd=dir_fd)
            except FileExistsError:  # made meanwhile (another worker): open it
                pass
        except OSError as exc:
            if exc.errno in (errno.ELOOP, errno.ENOTDIR, errno.EMLINK):
                if _is_link(name, dir_fd, full):
                    raise _refuse(full, "a symbolic link") from None
                raise UnsafePath(f"{full} is not a folder; remove it or choose another "
                                 "output folder") from None
            raise
    raise AssertionError("unreachable")  # pragma: no cover


def _walk(root: Path, parts: tuple[str, ...], create: bool) -> int:
    """fd of ``root/parts...``: root followed (the user named it), the rest never."""
    if create:
        root.mkdir(parents=True, exist_ok=True)
    fd = os.open(root, os.O_RDONLY | _DIRECTORY | _CLOEXEC)
    full = root
    try:
        for name in parts:
            full = full / name
            nxt = _open_dir(name, fd, full, create)
            os.close(fd)
            fd = nxt
    except BaseException:
        os.close(fd)
        raise
    return fd


def folder(root: str | Path, path: str | Path, *, create: bool = True) -> Path:
    """``path``, a folder at or below the output folder ``root``, checked (and created).

    Every folder below ``root`` on the way must be a real folder, not a link.
    Without ``create`` a missing folder raises ``FileNotFoundError``.
    """
    root, path = Path(root), Path(path)
    parts = _parts(root, path)
    if not _AT:  # pragma: no cover - no openat (Windows): check each component by name
        full = root
        for name in parts:
            full = full / name
            if full.is_symlink():
                raise _refuse(full, "a symbolic link")
        if create:
            path.mkdir(parents=True, exist_ok=True)
        return path
    os.close(_walk(root, parts, create))
    return path


def open_below(root: str | Path, path: str | Path, flags: int, mode: int = 0o666) -> int:
    """A file descriptor of ``path``, a file inside the output folder ``root``.

    ``flags`` as for :func:`os.open`; with ``O_CREAT`` the folders between ``root``
    and the file are created too (without it, a missing one raises
    ``FileNotFoundError``). Neither the file nor a folder below ``root`` is followed
    if it is a link: that, a file that is not a regular file, or one with other hard
    links, is refused (:class:`UnsafePath`).
    """
    root, path = Path(root), Path(path)
    parts = _parts(root, path)
    if not parts:
        raise ValueError(f"{path} is the output folder, not a file in it")
    create = bool(flags & os.O_CREAT)
    flags |= _NOFOLLOW | _NONBLOCK | _CLOEXEC  # non-blocking: a FIFO cannot hang the open
    if _AT:
        dfd = _walk(root, parts[:-1], create)
        try:
            fd = _open_file(parts[-1], flags, mode, dfd, path)
        finally:
            os.close(dfd)
    else:  # pragma: no cover - no openat (Windows)
        folder(root, path.parent, create=create)
        if path.is_symlink():
            raise _refuse(path, "a symbolic link")
        fd = os.open(path, flags, mode)
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise _refuse(path, "not a regular file")
        if st.st_nlink > 1:
            raise _refuse(path, f"a hard link ({st.st_nlink} names for one file)")
        if _NONBLOCK:
            os.set_blocking(fd, True)
    except BaseException:
        os.close(fd)
        raise
    return fd


def _open_file(name: str, flags: int, mode: int, dfd: int, full: Path) -> int:
    try:
        return os.open(name, flags, mode, dir_fd=dfd)
    except OSError as exc:
        if exc.errno in (errno.ELOOP, errno.EMLINK) or _is_link(name, dfd, full):
            raise _refuse(full, "a symbolic link") from None
        if exc.errno in (errno.EISDIR, errno.ENXIO):
            raise _refuse(full, "not a regular file") from None
        raise
