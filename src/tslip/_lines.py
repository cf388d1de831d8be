"""The one strict reader of the package's JSON-lines stores.

A store (a study's point records, a design search's evaluations) is a file of
JSON lines, each a record of plain data with a declared :class:`Schema`: its
fields and their types. :func:`read_lines` decodes each line with a strict
decoder (plain JSON values, no hooks, never evaluated) and keeps the lines
that match the schema. A bad line (not UTF-8, not JSON, nested deeper than the
decoder's recursion limit, of another shape or a field of another type, or
torn: the last line without its newline, from a write that was killed) is
treated as missing: the caller computes its entry again. Bad lines are named
in one warning per file read (the file and each line's number and fault);
nothing in a line can raise out of the reader.

Files are opened with :func:`tslip._safefile.open_below`: never through a link.
"""

from __future__ import annotations

import json
import logging
import math
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ._safefile import open_below

__all__ = ["BOOL", "NUMBER", "NUMBER_OR_NULL", "SCALAR", "STRING", "ListOf", "MapOf", "Schema",
           "read_lines"]

log = logging.getLogger("tslip")

#: Bad lines named in a warning (the rest counted).
_NAMED = 5


class _Type:
    """A JSON value's allowed type: ``fault(v)`` is None if ``v`` is one, else why not."""

    def __init__(self, name: str, ok: Callable[[Any], bool]) -> None:
        self.name, self.ok = name, ok

    def fault(self, value: Any) -> str | None:
        return None if self.ok(value) else f"not {self.name}"


def _number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


#: A string.
STRING = _Type("a string", lambda v: isinstance(v, str))
#: ``true`` or ``false``.
BOOL = _Type("true or false", lambda v: isinstance(v, bool))
#: A finite number (not a boolean).
NUMBER = _Type("a finite number", lambda v: _number(v) and math.isfinite(v))
#: A finite number or ``null`` (a missing or non-finite value).
NUMBER_OR_NULL = _Type("a finite number or null",
                       lambda v: v is None or (_number(v) and math.isfinite(v)))
#: A string, number, boolean or null (not a list or an object).
SCALAR = _Type("a string, number, boolean or null",
               lambda v: v is None or isinstance(v, (str, bool, int, float)))


@dataclass(frozen=True)
class ListOf:
    """A list of items of one type; ``length`` fixes its length."""

    item: _Type
    length: int | None = None

    def fault(self, value: Any) -> str | None:
        if not isinstance(value, list):
            return "not a list"
        if self.length is not None and len(value) != self.length:
            return f"a list of {len(value)} items, not {self.length}"
        for i, v in enumerate(value):
            if (why := self.item.fault(v)) is not None:
                return f"item {i}: {why}"
        return None


@dataclass(frozen=True)
class MapOf:
    """An object of any string keys, each value of one type."""

    value: _Type

    def fault(self, value: Any) -> str | None:
        if not isinstance(value, dict):
            return "not an object"
        for k, v in value.items():
            if (why := self.value.fault(v)) is not None:
                return f"field {k!r}: {why}"
        return None


@dataclass(frozen=True)
class Schema:
    """An object of exactly these fields (name -> type: a basic type, :class:`ListOf`,
    :class:`MapOf` or a nested :class:`Schema`)."""

    fields: Mapping[str, Any] = field(default_factory=dict)

    def fault(self, value: Any) -> str | None:
        if not isinstance(value, dict):
            return "not an object"
        if value.keys() != self.fields.keys():
            missing = sorted(self.fields.keys() - value.keys())
            extra = sorted(value.keys() - self.fields.keys())
            return ("without field " + repr(missing[0]) if missing
                    else "with an unknown field " + repr(extra[0]))
        for k, t in self.fields.items():
            if (why := t.fault(value[k])) is not None:
                return f"field {k!r}: {why}"
        return None


def _refuse_constant(name: str) -> None:
    raise ValueError(f"non-standard JSON constant {name}")


_STRICT = json.JSONDecoder(parse_constant=_refuse_constant)
_LENIENT = json.JSONDecoder()  # also NaN and Infinity (a study's records hold NaN)


def decode_line(raw: bytes, schema: Schema, *, constants: bool = False) -> tuple[Any, str | None]:
    """``(value, None)`` for a line matching ``schema``; ``(None, why not)`` otherwise.

    ``constants`` accepts ``NaN``, ``Infinity`` and ``-Infinity``. Never raises
    for any line.
    """
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        return None, "not UTF-8 text"
    try:
        value = (_LENIENT if constants else _STRICT).decode(text)
    except RecursionError:
        return None, "nested too deep"
    except ValueError as exc:  # also numbers too long to convert
        return None, "not JSON" if isinstance(exc, json.JSONDecodeError) else \
            " ".join(str(exc).split())[:80]
    try:
        why = schema.fault(value)
    except RecursionError:  # pragma: no cover - the schema descends a fixed depth
        why = "nested too deep"
    return (value, None) if why is None else (None, why)


def read_lines(
    root: str | Path,
    path: str | Path,
    schema: Schema,
    *,
    repair: bool = False,
    constants: bool = False,
    skip: Callable[[Any], bool] | None = None,
    what: tuple[str, str] = ("its entry is computed again", "their entries are computed again"),
) -> list[Any]:
    """The records of ``path`` (a file inside the output folder ``root``) that match
    ``schema``, in file order; empty without a file.

    ``repair`` (only by the run that holds the folder's lock) also cuts a torn
    last line off the file, so that the next append starts a line of its own.
    ``skip(value)`` marks a decoded line as not this reader's (e.g. another code
    version's): dropped without a warning. ``what`` ends the warning, for one bad
    line and for several (what happens to their entries). ``constants``: see :func:`decode_line`.
    """
    flags = os.O_RDWR if repair else os.O_RDONLY
    try:
        fd = open_below(root, path, flags)
    except FileNotFoundError:
        return []
    try:
        with os.fdopen(fd, "r+b" if repair else "rb", closefd=False) as fh:
            data = fh.read()
        *lines, torn = data.split(b"\n")
        if torn and repair:
            os.ftruncate(fd, len(data) - len(torn))
    finally:
        os.close(fd)
    out: list[Any] = []
    bad: list[tuple[int, str]] = []
    for n, raw in enumerate(lines, 1):
        value, why = decode_line(raw, schema, constants=constants)
        if why is not None:
            if skip is not None and why != "not UTF-8 text" and _skipped(raw, skip, constants):
                continue
            bad.append((n, why))
        elif skip is None or not skip(value):
            out.append(value)
    if torn:
        bad.append((len(lines) + 1, "torn (no newline at its end: a write was killed)"))
    if bad:
        named = "; ".join(f"line {n}: {why}" for n, why in bad[:_NAMED])
        more = f"; and {len(bad) - _NAMED} more" if len(bad) > _NAMED else ""
        log.warning("ignoring %d bad line%s of %s (%s%s); %s", len(bad),
                    "s" if len(bad) > 1 else "", path, named, more, what[len(bad) > 1])
    return out


def _skipped(raw: bytes, skip: Callable[[Any], bool], constants: bool) -> bool:
    """Whether a line that does not match the schema is one ``skip`` drops silently."""
    try:
        value = (_LENIENT if constants else _STRICT).decode(raw.decode("utf-8"))
    except (ValueError, RecursionError):
        return False
    try:
        return bool(skip(value))
    except Exception:  # noqa: BLE001 - a hostile line must not raise out of the reader
        return False
