"""Whether data read back from a file has the shape its type annotation states.

A report folder may be copied, shared or edited, so a value decoded from it
(:func:`tslip._results.decode`, which builds only ``tslip``'s dataclasses and
enums) is checked against the annotation of what the code would have
computed before anything uses it: :func:`check` raises a one-line
``ValueError`` naming the first field that differs.

What each annotation accepts:

* ``float``: a float or an int (not a bool); ``int``: an int (not a bool);
  ``bool``, ``str``, ``None``: that type (NumPy scalars count as their kind);
* ``np.ndarray``: an array of numbers or booleans (never of objects);
* ``tuple[X, ...]``, ``tuple[X, Y]``, ``list[X]``, ``dict[K, V]``,
  ``Mapping[K, V]``: that container, every item checked; ``Sequence[X]``: a list
  or tuple, every item checked, or another sequence but text, unchecked (a class's
  own view of its checked fields, e.g. a recorded run's ``steps``, built from its
  arrays on first read: checking its items would build them);
* a ``TypedDict``: a dict with exactly its keys, each value checked;
* a dataclass: an instance of it, every field checked against the class's
  own annotations (resolved with :func:`typing.get_type_hints`; a field whose
  annotation cannot be resolved is not checked, one typed by a descriptor has the
  type its ``__get__`` returns);
* ``X | Y``: either; ``Literal[...]``: one of its values; ``Any``: anything
  the decoder can build; any other class: an instance of it.
"""

from __future__ import annotations

import collections.abc
import dataclasses
import functools
import numbers
import types
import typing
from typing import Any

import numpy as np

__all__ = ["check"]


def check(value: Any, tp: Any, where: str = "data") -> None:
    """Raise ``ValueError("<where>: expected ..., got ...")`` unless ``value`` fits ``tp``."""
    why = _why(value, tp, where)
    if why is not None:
        raise ValueError(why)


@functools.cache
def _hints(cls: type) -> dict[str, Any]:
    """A dataclass's field annotations, resolved; a field that cannot be resolved: Any.

    A field typed by a descriptor class (e.g. ``Trajectory.data``) has the type its
    ``__get__`` returns.
    """
    try:
        hints = typing.get_type_hints(cls)
    except (NameError, TypeError, AttributeError):  # an annotation under TYPE_CHECKING only
        hints = {}
        for f in dataclasses.fields(cls):
            hints[f.name] = _resolved(f.name, f.type, cls.__module__)
    for name, tp in hints.items():
        if isinstance(tp, type) and hasattr(tp, "__get__"):
            try:
                hints[name] = typing.get_type_hints(tp.__get__).get("return", Any)
            except (NameError, TypeError, AttributeError):
                hints[name] = Any
    return hints


def _resolved(name: str, annotation: Any, module: str) -> Any:
    """One annotation resolved in ``module``'s names; Any if it cannot be."""
    try:
        return typing.get_type_hints(
            type("_One", (), {"__annotations__": {name: annotation}, "__module__": module}))[name]
    except (NameError, TypeError, AttributeError):
        return Any


def _name(tp: Any) -> str:
    return getattr(tp, "__name__", None) or str(tp).replace("typing.", "")


def _why(v: Any, tp: Any, where: str) -> str | None:  # noqa: C901 - one case per kind
    """None if ``v`` conforms to ``tp``, else why not (the first field that differs)."""
    if tp is Any or tp is object:
        return None
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    bad = f"{where}: expected {_name(tp)}, got {type(v).__name__}"
    if tp is None or tp is type(None):
        return None if v is None else bad
    if origin is typing.Union or origin is types.UnionType:
        if any(_why(v, a, where) is None for a in args):
            return None
        return bad
    if origin is typing.Literal:
        return None if any(type(v) is type(a) and v == a for a in args) else bad
    if tp is bool:
        return None if isinstance(v, (bool, np.bool_)) else bad
    if tp is float:
        ok = isinstance(v, (numbers.Real)) and not isinstance(v, (bool, np.bool_))
        return None if ok else bad
    if tp is int:
        ok = isinstance(v, numbers.Integral) and not isinstance(v, (bool, np.bool_))
        return None if ok else bad
    if tp is np.ndarray:
        return None if isinstance(v, np.ndarray) and v.dtype.kind in "biuf" else bad
    if origin is tuple:
        if not isinstance(v, tuple):
            return bad
        if len(args) == 2 and args[1] is Ellipsis:
            args = (args[0],) * len(v)
        elif not args:
            return None
        elif len(v) != len(args):
            return f"{where}: expected {len(args)} items, got {len(v)}"
        return _first((f"{where}[{i}]", x, a) for i, (x, a) in enumerate(zip(v, args)))
    if origin in (list, collections.abc.Sequence):
        if not isinstance(v, list if origin is list else collections.abc.Sequence) or \
                isinstance(v, (str, bytes)):
            return bad
        if not isinstance(v, (list, tuple)):  # built by its owner from its checked fields
            return None
        item = args[0] if args else Any
        return _first((f"{where}[{i}]", x, item) for i, x in enumerate(v))
    if origin in (dict, collections.abc.Mapping):
        if not isinstance(v, dict):
            return bad
        kt, vt = args if args else (Any, Any)
        return _first(pair for k, x in v.items()
                      for pair in ((f"{where} key", k, kt), (f"{where}[{k!r}]", x, vt)))
    if typing.is_typeddict(tp):
        if not isinstance(v, dict):
            return bad
        hints = typing.get_type_hints(tp)
        if set(v) != set(hints):
            return f"{where}: expected the keys {sorted(hints)}, got {sorted(map(str, v))}"
        return _first((f"{where}[{k!r}]", v[k], t) for k, t in hints.items())
    if isinstance(tp, type):
        if not isinstance(v, tp):
            return bad
        if dataclasses.is_dataclass(tp):
            cls: Any = type(v)
            hints = _hints(cls)
            return _first((f"{where}.{f.name}", getattr(v, f.name), hints.get(f.name, Any))
                          for f in dataclasses.fields(cls))
        return None
    return f"{where}: cannot check the annotation {tp!r}"


def _first(triples: Any) -> str | None:
    """The first reason among ``(where, value, type)`` triples, else None."""
    for where, v, tp in triples:
        why = _why(v, tp, where)
        if why is not None:
            return why
    return None
