"""Atomic file writes: a crash never leaves a half-written result (tables, JSON, MP4)."""

from __future__ import annotations

import itertools
import json
import os
import tempfile
import tomllib
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

__all__ = ["atomic_write", "git_hash", "read_toml", "save_figure", "write_json", "write_mp4",
           "write_table", "write_text"]


def atomic_write(path: str | Path, write: Callable[[str], object]) -> Path:
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
        name = exc.filename
        if name is None or not Path(name).name.startswith(f".{path.name}."):
            raise
        raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from None
    finally:
        if tmp and os.path.exists(tmp):
            os.unlink(tmp)
    return path


def save_figure(fig: Any, path: str | Path, **kwargs: Any) -> Path:
    """Save a matplotlib figure atomically, in the format its suffix names (``.png``,
    ``.pdf``, ``.svg``): a link at ``path`` is replaced, never written through."""
    fmt = Path(path).suffix.lstrip(".").lower() or "png"
    return atomic_write(path, lambda tmp: fig.savefig(tmp, format=fmt, **kwargs))


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) atomically: a link at ``path`` is replaced, never written
    through."""
    return atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


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

    ``what`` names the file in the message, e.g. ``"parameter file"``. A UTF-8
    byte-order mark (some Windows editors write one) is accepted.
    """
    try:
        return tomllib.loads(Path(path).read_text(encoding="utf-8-sig"))
    except FileNotFoundError:
        raise ValueError(f"{what} {str(path)!r} does not exist") from None
    except IsADirectoryError:
        raise ValueError(f"{what} {str(path)!r} is a directory; give a .toml file") from None
    except UnicodeDecodeError:
        raise ValueError(f"{what} {str(path)!r} is not valid TOML (not UTF-8 text)") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{what} {str(path)!r} is not valid TOML: {exc}") from None


#: Seconds a :func:`git_hash` answer is reused (``tslip reproduce`` records it for each of
#: its studies; each ``git`` call costs tens of milliseconds).
GIT_HASH_SECONDS = 60.0
_git_cache: list[Any] = []  # [monotonic time, answer] of the last git call


def git_hash() -> str | None:
    """The source checkout's commit, if the package runs from one (asked at most once a minute)."""
    import subprocess
    import time

    now = time.monotonic()
    if _git_cache and now - _git_cache[0] < GIT_HASH_SECONDS:
        return _git_cache[1]
    try:
        out = subprocess.run(["git", "rev-parse", "HEAD"], cwd=Path(__file__).parent,
                             capture_output=True, text=True, timeout=5)
        answer = out.stdout.strip() or None if out.returncode == 0 else None
    except (OSError, subprocess.SubprocessError):
        answer = None
    _git_cache[:] = [now, answer]
    return answer


def write_mp4(
    path: str | Path,
    frames: Iterable[Any],
    fps: float,
    *,
    crf: int = 23,
    preset: str = "medium",
    progress: Callable[[int, int], None] | None = None,
    total: int = 0,
) -> Path:
    """Encode RGB ``uint8`` frames (height, width, 3) to an H.264 ``.mp4``, atomically.

    The one place that runs ffmpeg (the binary of imageio-ffmpeg). libx264 with
    yuv420p needs an even width and height: other sizes are refused before
    ffmpeg starts. ffmpeg's exit status and the size of its output are checked:
    a failed or empty encode raises ``OSError`` naming ``path`` and ffmpeg's
    last message, and leaves no file behind.
    """
    import subprocess

    import imageio_ffmpeg

    path = Path(path)
    it = iter(frames)
    first = next(it, None)
    if first is None:
        raise ValueError(f"no frames to write to {str(path)!r}")
    height, width = first.shape[:2]
    if first.ndim != 3 or first.shape[2] != 3 or first.dtype.name != "uint8":
        raise ValueError(f"frames must be uint8 arrays of shape (height, width, 3), got "
                         f"{first.dtype} {first.shape}")
    if width % 2 or height % 2:
        raise ValueError(f"an .mp4 (libx264, yuv420p) needs an even frame width and height, "
                         f"got {width} x {height} px")

    def encode(tmp: str) -> None:
        cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-y", "-loglevel", "error", "-f", "rawvideo",
               "-pix_fmt", "rgb24", "-s", f"{width}x{height}", "-r", f"{fps:.10g}", "-i", "-",
               "-an", "-c:v", "libx264", "-pix_fmt", "yuv420p", "-crf", str(crf),
               "-preset", preset, "-f", "mp4", tmp]
        with tempfile.TemporaryFile() as log:
            proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                                    stderr=log)
            assert proc.stdin is not None
            try:
                for k, frame in enumerate(itertools.chain([first], it)):
                    if frame.shape != first.shape or frame.dtype != first.dtype:
                        raise ValueError(f"frame {k} has shape {frame.shape}, expected "
                                         f"{first.shape}")
                    proc.stdin.write(frame.tobytes())
                    if progress is not None:
                        progress(k + 1, total)
            except BrokenPipeError:
                pass  # ffmpeg stopped: its status and message are reported below
            finally:
                try:
                    proc.stdin.close()
                except BrokenPipeError:
                    pass
                code = proc.wait()
            log.seek(0)
            lines = log.read().decode(errors="replace").strip().splitlines()
        if code != 0 or os.path.getsize(tmp) == 0:
            why = lines[-1].strip() if lines else f"exit status {code}"
            raise OSError(f"ffmpeg could not encode {str(path)!r}: {why}")

    return atomic_write(path, encode)
