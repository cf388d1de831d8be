"""Checks of user input shared by the API and the CLI.

One function per kind of check, each raising a one-line ``ValueError`` that
names the field and what is allowed:

* :func:`check_number` - a number field: bool and text rejected, NumPy
  scalars accepted, finite, in range, integer where an integer is meant;
* :func:`check_fields` - every numeric field of a parameter dataclass, by its metadata;
* :func:`parse_number` - the same for text from the command line (``--set``);
* :func:`check_fits` - a size against the memory available, before the work;
* :func:`check_output` - an output path: suffix allowed, directory writable;
* :func:`check_name` - a name that becomes a folder name (a study's, a viability map's).
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import os
import re
import tempfile
from pathlib import Path
from typing import Any

__all__ = ["check_number", "check_fields", "parse_number", "check_fits", "available_memory",
           "check_output", "check_name"]

#: What a name that becomes a folder name may be: no path separators, and no leading
#: dot (so neither "." nor "..", which would write into the current folder or its parent).
NAME_RULE = r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$"


def _range(lower: float, upper: float, lower_open: bool, upper_open: bool) -> str:
    left = "(" if lower_open or lower == -math.inf else "["
    right = ")" if upper_open or upper == math.inf else "]"
    return f"{left}{_num(lower)}, {_num(upper)}{right}"


def _num(x: float) -> str:
    """A bound as text: whole numbers in full (4294967295, not 4.29497e+09)."""
    return str(int(x)) if math.isfinite(x) and float(x).is_integer() and abs(x) < 1e16 \
        else f"{x:g}"


def check_number(
    value: object,
    name: str,
    *,
    unit: str = "",
    lower: float = -math.inf,
    upper: float = math.inf,
    lower_open: bool = False,
    upper_open: bool = False,
    integer: bool = False,
) -> float | int:
    """Return ``value`` as a Python ``float`` (or ``int`` if ``integer``) after checking it.

    Accepted: Python and NumPy ints and floats (``np.int64(30)``, ``np.float32(1.5)``).
    Rejected, with a message naming ``name`` and the allowed range: ``bool``
    (``True`` is not 1), text, NaN or infinite values, values outside
    ``[lower, upper]`` (open ends when ``lower_open`` / ``upper_open``), and,
    when ``integer``, any float (``2.7`` and ``2.0`` alike: no silent rounding).
    """
    label = f"{name} [{unit}]" if unit else name
    kind = "an integer" if integer else "a number"
    bounded = math.isfinite(lower) or math.isfinite(upper)
    rng = _range(lower, upper, lower_open, upper_open) if bounded else ""
    where = f" in {rng}" if bounded else ""
    if isinstance(value, bool) or type(value).__name__ == "bool_" or not isinstance(
        value, numbers.Real
    ):
        raise ValueError(f"{label} must be {kind}{where}, got {value!r}")
    if integer:
        if not isinstance(value, numbers.Integral):
            raise ValueError(f"{label} must be {kind}{where}, got {value!r}")
        out: float | int = int(value)
    else:
        out = float(value)
        if not math.isfinite(out):
            raise ValueError(f"{label} must be finite{' and in ' + rng if bounded else ''}, "
                             f"got {value!r}")
    bad_lo = out <= lower if lower_open else out < lower
    bad_hi = out >= upper if upper_open else out > upper
    if bad_lo or bad_hi:
        raise ValueError(f"{label} must be {kind}{where}, got {value!r}")
    return out


def check_fields(obj: Any, prefix: str = "") -> None:
    """Check every numeric field of a frozen dataclass with :func:`check_number`.

    A field is numeric when its metadata carries a ``lower`` bound; its
    ``upper``, ``lower_open``, ``upper_open`` and ``unit`` set the rest, and an
    ``int`` annotation makes it an integer field. The checked value (a plain
    ``float`` or ``int``, so NumPy scalars are accepted) is written back.
    """
    for f in dataclasses.fields(obj):
        md = f.metadata
        if "lower" not in md:
            continue
        value = check_number(
            getattr(obj, f.name), f"{prefix}{f.name}", unit=md.get("unit", ""),
            lower=md["lower"], upper=md.get("upper", math.inf),
            lower_open=md.get("lower_open", False), upper_open=md.get("upper_open", False),
            integer=f.type in (int, "int"),
        )
        object.__setattr__(obj, f.name, value)


def parse_number(text: str, name: str, **bounds: object) -> float | int:
    """:func:`check_number` for text, e.g. the value of ``--set k=30``.

    ``integer=True`` accepts only whole-number text (``"3"``, not ``"3.0"``).
    """
    integer = bool(bounds.get("integer", False))
    text = text.strip()
    try:
        value: float | int = int(text) if integer else float(text)
    except ValueError:
        kind = "an integer" if integer else "a number"
        raise ValueError(f"{name} must be {kind}, got {text!r}") from None
    return check_number(value, name, **bounds)  # type: ignore[arg-type]


def available_memory() -> int:
    """Bytes of memory available to a new allocation (Linux ``MemAvailable``)."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return int(os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        return 2**62


def _bytes(n: float) -> str:
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n / 1e3:.3g} kB"


def check_fits(count: int, bytes_each: float, name: str, what: str) -> None:
    """Refuse ``count`` items of ``bytes_each`` that cannot fit in memory, before the work.

    The message gives the estimate and the largest count that fits, e.g.
    ``--steps 1000000000 needs about 12 TB for the trajectory; at most 1900000
    fit in memory (22.9 GB available)``.
    """
    need = float(count) * float(bytes_each)
    free = available_memory()
    if need > free:
        most = int(free // bytes_each)
        raise ValueError(f"{name} {count} needs about {_bytes(need)} for {what}; at most "
                         f"{most} fit in memory ({_bytes(free)} available)")


def check_output(path: str | os.PathLike[str], option: str,
                 suffixes: tuple[str, ...] | None = None) -> Path:
    """Check an output path before the work: suffix allowed, directory writable.

    The nearest existing ancestor directory must accept a new file (probed by
    creating and removing a temporary file there). Errors name ``option`` and
    the user's path, never a temporary file.
    """
    path = Path(path)
    if suffixes is not None and path.suffix.lower() not in suffixes:
        raise ValueError(f"{option} must end in {' or '.join(suffixes)}, got {str(path)!r}")
    if path.is_dir() and suffixes is not None:
        raise ValueError(f"{option} {str(path)!r} is a directory; give a file name")
    parent = path.parent
    while not parent.exists():
        if parent == parent.parent:
            break
        parent = parent.parent
    if not parent.is_dir():
        raise ValueError(f"{option} {str(path)!r}: {str(parent)!r} is not a directory")
    try:
        with tempfile.TemporaryFile(dir=parent):
            pass
    except OSError as exc:
        raise ValueError(f"{option} {str(path)!r}: cannot write in {str(parent)!r} "
                         f"({exc.strerror or exc})") from None
    return path


def check_name(value: object, field: str) -> str:
    """``value`` as a name that becomes a folder name: it must match :data:`NAME_RULE`."""
    if not isinstance(value, str) or not re.fullmatch(NAME_RULE[1:-1], value):
        raise ValueError(f"{field} must match {NAME_RULE} (a letter or digit, then up to 63 "
                         f"letters, digits, '_', '.' or '-'), got {value!r}")
    return value
