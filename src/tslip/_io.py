"""Atomic file writes: a crash never leaves a half-written result."""

from __future__ import annotations

import json
import os
import tempfile
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["atomic_write", "git_hash", "read_toml", "write_json", "write_table"]


def atomic_write(path: str | Path, write: Callable[[str], None]) -> Path:
    """Call ``write(tmp_path)`` then rename the temporary file onto ``path``.

    The temporary file sits beside ``path`` (same file system, so the rename
    is atomic) and gets the usual permissions (``0666 & ~umask``).
    """
    path = Path(path)
    tmp = ""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=path.suffix)
        os.close(fd)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        write(tmp)
        os.replace(tmp, path)
    except OSError as exc:  # name the user's file, never the temporary one
        if tmp and exc.filename not in (None, tmp, str(path)) and str(tmp) not in str(exc):
            raise
        raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from None
    finally:
        if tmp and os.path.exists(tmp):
            os.unlink(tmp)
    return path


def _json_default(o: Any) -> Any:
    """NumPy scalars and arrays as Python numbers and lists; anything else as text."""
    if hasattr(o, "tolist"):
        return o.tolist()
    return str(o)


def write_json(path: str | Path, data: Any, indent: int = 2) -> Path:
    """Write ``data`` as JSON atomically (NumPy values converted, others as text)."""
    text = json.dumps(data, indent=indent, default=_json_default)
    return atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


def write_table(df, path: str | Path) -> Path:  # noqa: ANN001 - pandas.DataFrame
    """Write a DataFrame to ``.csv`` or ``.parquet`` atomically."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".csv":
        return atomic_write(path, lambda tmp: df.to_csv(tmp, index=False))
    if suffix == ".parquet":
        return atomic_write(path, lambda tmp: df.to_parquet(tmp, index=False))
    raise ValueError(f"output file must end in .csv or .parquet, got {str(path)!r}")


def read_toml(path: str | Path, what: str) -> dict:
    """Parse a TOML file; a missing or malformed file is a one-line ``ValueError``.

    ``what`` names the file in the message, e.g. ``"parameter file"``.
    """
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:
        raise ValueError(f"{what} {str(path)!r} does not exist") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{what} {str(path)!r} is not valid TOML: {exc}") from None


def git_hash() -> str | None:
    """The source checkout's commit, if the package runs from one."""
    import subprocess

    try:
        out = subprocess.run(["git", "rev-parse", "HEAD"], cwd=Path(__file__).parent,
                             capture_output=True, text=True, timeout=5)
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None if out.returncode == 0 else None
