"""Results that save, load, tabulate and print alike (the :class:`Result` base).

Every result object of ``tslip`` (a trajectory, a stride, a gait, its Floquet
multipliers, a robustness analysis, a study, ...) is a frozen dataclass that
derives from :class:`Result` and so has

* a one-line ``repr``: the class name and its scalar fields, arrays by shape;
* ``to_dataframe()``: a tidy ``pandas.DataFrame`` with the unit of every
  column in ``df.attrs["units"]`` (model units of thesis Table 3.1, e.g.
  ``"L"``, ``"g^-1/2 L^1/2"``, ``"rad"``, ``"-"`` for a pure number);
* ``save(path)``: to ``.json`` (the whole object), or to ``.parquet`` /
  ``.csv`` (the table) with a ``.json`` beside it holding the rest of the
  object; either way with a run record (``tslip`` version, code hash, git
  commit, UTC date, parameters);
* ``load(path)`` (a classmethod) and :func:`load` (``tslip.load``) for a
  file of any result;
* ``plot(ax=None)`` where a figure makes sense, defined by the subclass.

The file format
---------------
A saved object is a tree of JSON values; what JSON cannot say is tagged:
``{"__type__": "tslip.gait.stability:Floquet", "fields": {...}}`` for a
dataclass (a field left at its default ``None`` omitted),
``{"__enum__": ..., "value": ...}`` for an enum member,
``{"__ndarray__": dtype, "shape": ..., "data": ...}`` for an array (a list
for small arrays, base64 of the little-endian bytes for large ones, so the
values come back bit for bit), ``{"__float__": "nan"}`` for a non-finite
number, and ``__tuple__``, ``__complex__``, ``__scalar__`` (a NumPy scalar),
``__dict__`` (a dict with keys that are not plain text) and ``__frame__``
(a DataFrame).

Loading is safe: a file can name only dataclasses and enums defined in
``tslip`` (their modules are imported) and :class:`Result` subclasses of
modules already imported. Anything else (``tslip._io:os.system``, a class
of another package) is refused before anything is called. A missing,
damaged or foreign file is a one-line ``ValueError``.
"""

from __future__ import annotations

import base64
import binascii
import dataclasses
import datetime
import enum
import importlib
import json
import math
import re
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from ._io import atomic_write, git_hash, write_table

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["Result", "FrameTable", "load", "with_units", "frame", "run_record", "encode", "decode",
           "FORMAT"]

#: Name and version of the file format, stored in every file.
FORMAT_NAME, FORMAT_VERSION = "tslip-result", 1
FORMAT: dict[str, Any] = {"name": FORMAT_NAME, "version": FORMAT_VERSION}
#: Arrays with more elements than this are stored as base64 bytes, smaller ones as lists.
_LIST_MAX = 100
#: The table suffixes; ``.json`` holds a whole object (or a table's companion record).
TABLE_SUFFIXES = (".parquet", ".csv")
SUFFIXES = (".json", *TABLE_SUFFIXES)

R = TypeVar("R", bound="Result")


class Result:
    """Base of the result dataclasses: repr, table, save/load (see the module docstring).

    A subclass is a frozen dataclass declared with ``repr=False`` (so the
    short repr here is kept) and defines :meth:`to_dataframe`, usually with
    :func:`with_units`. It may override:

    * :meth:`_repr_fields`, the fields the one-line repr shows;
    * :meth:`_fields` / :meth:`_from_fields`, what is stored and how the
      object is built back (default: the dataclass's ``init`` fields);
    * :meth:`_table_fields` / :meth:`_from_table`, the fields that a
      ``.parquet`` / ``.csv`` table already holds, left out of its companion
      ``.json`` and rebuilt from the table when loading.
    """

    __slots__ = ()

    # -- repr ----------------------------------------------------------------
    def _repr_fields(self) -> dict[str, Any]:
        """What the repr shows: the scalar fields, arrays by shape, sequences by length."""
        out: dict[str, Any] = {}
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            if not f.repr:
                continue
            v = getattr(self, f.name)
            if v is None or isinstance(v, (bool, int, float, str, enum.Enum, np.generic)):
                out[f.name] = v
            elif isinstance(v, np.ndarray):
                out[f.name] = _Shape(v)
            elif isinstance(v, (list, tuple)) and not dataclasses.is_dataclass(v):
                out[f.name] = _Shape(v)
        return out

    def __repr__(self) -> str:
        """One line: the class name and :meth:`_repr_fields`."""
        parts = [f"{k}={_short(v)}" for k, v in self._repr_fields().items()]
        text = f"{type(self).__name__}({', '.join(parts)})"
        return text if len(text) <= 200 else text[:195] + " ...)"

    # -- table ---------------------------------------------------------------
    def to_dataframe(self) -> pd.DataFrame:
        """A tidy table of the result, units in ``df.attrs["units"]``."""
        raise NotImplementedError(f"{type(self).__name__} has no table")

    # -- what is stored -------------------------------------------------------
    def _fields(self) -> dict[str, Any]:
        """The state that :meth:`save` stores (default: the dataclass's init fields)."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)  # type: ignore
                if f.init}

    @classmethod
    def _from_fields(cls: type[R], fields: dict[str, Any]) -> R:
        """Build the object back from :meth:`_fields`."""
        return cls(**fields)

    def _summary(self) -> dict[str, Any]:
        """Readable facts put at the top level of the saved record (default: none).

        Not read back: :meth:`_fields` is the state. The record's own keys
        (``format``, ``run``, ``table``, ``result``) take precedence.
        """
        return {}

    def _table_fields(self) -> tuple[str, ...]:
        """Fields of :meth:`_fields` that the table holds (left out of a table's record)."""
        return ()

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        """``fields`` completed with :meth:`_table_fields` read back from the table ``df``."""
        return fields

    # -- files ---------------------------------------------------------------
    def save(self, path: str | Path) -> Path:
        """Write the result to ``.json``, or to ``.parquet`` / ``.csv`` with a ``.json`` record.

        Atomic: a crash never leaves a half-written file. Returns ``path``.
        """
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in SUFFIXES:
            raise ValueError(f"path must end in one of {', '.join(SUFFIXES)}, got {str(path)!r}")
        record: dict[str, Any] = {**encode(self._summary(), "summary"), "format": FORMAT,
                                  "run": run_record(self)}
        if suffix == ".json":
            record["result"] = encode(self)
            _write_text(path, record)
            return path
        df = self.to_dataframe()
        table = set(self._table_fields())
        rest = {k: v for k, v in self._fields().items() if k not in table}
        record["table"] = {"file": path.name, "fields": sorted(table),
                           "units": dict(df.attrs.get("units", {})),
                           "dtypes": {str(c): str(t) for c, t in df.dtypes.items()}}
        record["result"] = {"__type__": _name(type(self)), "fields": _encode_fields(rest)}
        out = df.copy()
        out.attrs = {}  # the units are in the record; pyarrow would store attrs as JSON text
        write_table(out, path)
        _write_text(path.with_suffix(".json"), record)
        return path

    @classmethod
    def load(cls: type[R], path: str | Path) -> R:
        """Read a result saved by :meth:`save`; it must be a ``cls``."""
        obj = load(path)
        if not isinstance(obj, cls):
            raise ValueError(f"{str(path)!r} holds a {type(obj).__name__}, not a {cls.__name__}")
        return obj


class FrameTable:
    """Mixin of a :class:`Result` whose table is its DataFrame field ``frame`` (a study's
    points, a design search's evaluations): saved as the ``.parquet``/``.csv`` table,
    read back without the units in ``attrs`` (``to_dataframe`` adds them)."""

    def _table_fields(self) -> tuple[str, ...]:
        return ("frame",)

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        df = df.copy()
        df.attrs = {}
        return {**fields, "frame": df}


class _Shape:
    """An array or sequence in a repr: its shape (and dtype) or its length."""

    def __init__(self, v: Any) -> None:
        if isinstance(v, np.ndarray):
            self.text = f"<{'x'.join(map(str, v.shape)) or 'scalar'} {v.dtype}>"
        else:
            self.text = f"<{len(v)} items>"

    def __repr__(self) -> str:
        return self.text


def _short(v: Any) -> str:
    if isinstance(v, enum.Enum):
        return v.name
    if isinstance(v, (float, np.floating)) and not isinstance(v, bool):
        return f"{float(v):.6g}"
    if isinstance(v, str) and len(v) > 40:
        return repr(v[:37] + "...")
    return repr(v)


def with_units(df: pd.DataFrame, units: Mapping[str, str]) -> pd.DataFrame:
    """Set ``df.attrs["units"]`` to the unit of each column; a column without one is an error.

    ``units`` may name more columns than ``df`` has (a shared table of units).
    """
    names = df.columns.tolist()  # iterating a pandas 3 string Index costs about 1 us a label
    missing = [c for c in names if c not in units]
    if missing:
        raise ValueError(f"no unit for the column(s) {', '.join(map(str, missing))}")
    df.attrs["units"] = {str(c): units[c] for c in names}
    return df


def frame(data: Mapping[str, Any] | list[dict[str, Any]], units: Mapping[str, str]
          ) -> pd.DataFrame:
    """A DataFrame of ``data`` (columns, or a list of rows) with :func:`with_units`."""
    import pandas as pd

    return with_units(pd.DataFrame(data), units)


def run_record(obj: object) -> dict[str, Any]:
    """Provenance of a saved result: version, code hash, git commit, UTC date, parameters."""
    from . import __version__
    from ._codehash import code_hash

    module = type(obj).__module__
    try:
        chash: str | None = code_hash(module)
    except ValueError:  # a Result subclass outside tslip
        chash = None
    params = getattr(obj, "params", None)
    to_dict = getattr(params, "to_dict", None)
    return {
        "tslip_version": __version__,
        "code_hash": chash,
        "git": git_hash(),
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "class": _name(type(obj)),
        "params": to_dict() if callable(to_dict) else None,
    }


def _write_text(path: Path, record: dict[str, Any]) -> None:
    text = json.dumps(record, indent=1, allow_nan=False)
    atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


# -- encoding -----------------------------------------------------------------
def _name(cls: type) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


def _float(x: float) -> Any:
    return x if math.isfinite(x) else {"__float__": repr(x)}


def _encode_fields(fields: Mapping[str, Any]) -> dict[str, Any]:
    return {k: encode(v, k) for k, v in fields.items()}


def encode(obj: Any, where: str = "result") -> Any:
    """``obj`` as JSON values, tagged where JSON has no type (see the module docstring).

    ``where`` names the field in the error for a value that cannot be saved.
    """
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, enum.Enum):
        return {"__enum__": _name(type(obj)), "value": encode(obj.value, where)}
    if isinstance(obj, np.generic):  # before int and float: np.float64 is a float
        return {"__scalar__": obj.dtype.str, "value": encode(obj.item(), where)}
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, float):
        return _float(float(obj))
    if isinstance(obj, complex):
        return {"__complex__": [_float(obj.real), _float(obj.imag)]}
    if isinstance(obj, np.ndarray):
        return _encode_array(obj, where)
    if isinstance(obj, Result) and dataclasses.is_dataclass(obj):
        return {"__type__": _name(type(obj)), "fields": _encode_fields(obj._fields())}
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        # a field left at its default None is omitted (e.g. Params.alpha_stop: no stop)
        return {"__type__": _name(type(obj)),
                "fields": _encode_fields({f.name: getattr(obj, f.name)
                                          for f in dataclasses.fields(obj) if f.init and not (
                                              f.default is None and getattr(obj, f.name) is None)})}
    if isinstance(obj, tuple):
        return {"__tuple__": [encode(v, where) for v in obj]}
    if isinstance(obj, list):
        return [encode(v, where) for v in obj]
    if isinstance(obj, dict):
        if all(isinstance(k, str) and not k.startswith("__") for k in obj):
            return {k: encode(v, f"{where}.{k}") for k, v in obj.items()}
        return {"__dict__": [[encode(k, where), encode(v, where)] for k, v in obj.items()]}
    if isinstance(obj, Path):
        return {"__path__": str(obj)}
    if type(obj).__name__ == "DataFrame" and type(obj).__module__.startswith("pandas"):
        return {"__frame__": {"columns": [encode(c, where) for c in obj.columns],
                              "dtypes": [str(t) for t in obj.dtypes],
                              "data": [_encode_array(obj.iloc[:, k].to_numpy(), where)
                                       for k in range(obj.shape[1])],
                              "index": _encode_array(obj.index.to_numpy(), where),
                              "attrs": encode(dict(obj.attrs), where)}}
    raise TypeError(f"cannot save {where}: a {type(obj).__name__} is not a number, text, "
                    f"array, container, tslip dataclass or enum")


def _encode_array(a: np.ndarray, where: str) -> dict[str, Any]:
    if a.dtype.kind not in "biufcUSO":
        raise TypeError(f"cannot save {where}: an array of dtype {a.dtype}")
    out: dict[str, Any] = {"__ndarray__": a.dtype.str, "shape": list(a.shape)}
    if a.dtype.kind == "O":
        out["data"] = [encode(v, where) for v in a.ravel().tolist()]
    elif a.dtype.kind in "US" or a.size <= _LIST_MAX:
        flat = a.ravel()
        if a.dtype.kind == "c":
            out["data"] = [[_float(z.real), _float(z.imag)] for z in flat.tolist()]
        elif a.dtype.kind == "f":
            out["data"] = [_float(x) for x in flat.tolist()]
        elif a.dtype.kind == "S":
            out["data"] = [x.decode("latin-1") for x in flat.tolist()]
        else:
            out["data"] = flat.tolist()
    else:
        le = a.astype(a.dtype.newbyteorder("<"), copy=False)
        out["__ndarray__"] = le.dtype.str
        out["b64"] = base64.b64encode(np.ascontiguousarray(le).tobytes()).decode("ascii")
    return out


# -- decoding -----------------------------------------------------------------
_IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")

#: Classes a file may name where they lived before a module was split: the old name ->
#: the class's own name now (``tslip.gait.viability`` was split after 0.3.0). Such files
#: keep loading; saving writes the new name.
MOVED = {"tslip.gait.viability:StateActionMap": "tslip.gait.statemap:StateActionMap",
         "tslip.gait.viability:Basin": "tslip.gait.basins:Basin"}


def _resolve(name: Any) -> type:
    """The class ``"module:Qual.Name"`` names, if a file may build it; else ``ValueError``.

    Allowed: dataclasses and enums defined in ``tslip`` (whose module is
    imported here if it is not yet), and :class:`Result` subclasses of any
    module already imported; a name of :data:`MOVED` is read as the class's name
    now. Nothing else is looked up or called, and no
    ``__main__`` (``python -m tslip`` runs the command line when imported).
    """
    if not isinstance(name, str) or name.count(":") != 1:
        raise ValueError(f"bad class name {name!r}")
    name = MOVED.get(name, name)
    module, qual = name.split(":")
    mparts, qparts = module.split("."), qual.split(".")
    if not all(_IDENT.match(p) for p in mparts + qparts) or any(
            p.startswith("__") for p in mparts + qparts):
        raise ValueError(f"bad class name {name!r}")
    in_tslip = mparts[0] == "tslip"
    if in_tslip:
        mod = importlib.import_module(module)
    elif module in sys.modules:
        mod = sys.modules[module]
    else:
        raise ValueError(f"the class {name!r} is not tslip's and its module is not imported")
    obj: Any = mod
    for p in qparts:
        obj = getattr(obj, p, None)
        if obj is None:
            raise ValueError(f"no class {name!r}")
    if not isinstance(obj, type):
        raise ValueError(f"{name!r} is not a class")
    own = obj.__module__ == module and obj.__qualname__ == qual
    if own and issubclass(obj, Result):
        return obj
    if own and in_tslip and (dataclasses.is_dataclass(obj) or issubclass(obj, enum.Enum)):
        return obj
    raise ValueError(f"{name!r} is not a tslip dataclass, enum or Result")


def _unfloat(v: Any) -> float:
    if isinstance(v, dict):
        text = v.get("__float__")
        if text not in ("nan", "inf", "-inf"):
            raise ValueError(f"bad number {v!r}")
        return float(text)
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ValueError(f"bad number {v!r}")
    return float(v)


def decode(data: Any) -> Any:
    """The object :func:`encode` made ``data`` from; a class it may not build is a ValueError."""
    if data is None or isinstance(data, (bool, int, float, str)):
        return data
    if isinstance(data, list):
        return [decode(v) for v in data]
    if not isinstance(data, dict):
        raise ValueError(f"unexpected {type(data).__name__}")
    if "__type__" in data:
        cls = _resolve(data["__type__"])
        fields = data.get("fields")
        if not isinstance(fields, dict):
            raise ValueError(f"no fields for {data['__type__']}")
        values = {str(k): decode(v) for k, v in fields.items()}
        return _build(cls, values)
    if "__enum__" in data:
        cls = _resolve(data["__enum__"])
        if not issubclass(cls, enum.Enum):
            raise ValueError(f"{data['__enum__']!r} is not an enum")
        return cls(decode(data.get("value")))
    if "__ndarray__" in data:
        return _decode_array(data)
    if "__float__" in data:
        return _unfloat(data)
    if "__tuple__" in data:
        return tuple(decode(v) for v in _list(data["__tuple__"]))
    if "__complex__" in data:
        re_, im = _list(data["__complex__"])
        return complex(_unfloat(re_), _unfloat(im))
    if "__scalar__" in data:
        return np.dtype(_dtype(data["__scalar__"])).type(decode(data.get("value")))
    if "__dict__" in data:
        return {decode(k): decode(v) for k, v in _list(data["__dict__"])}
    if "__path__" in data:
        return Path(str(data["__path__"]))
    if "__frame__" in data:
        import pandas as pd

        fr = data["__frame__"]
        cols = [decode(c) for c in _list(fr["columns"])]
        arrays = [_decode_array(a) for a in _list(fr["data"])]
        dtypes: list[Any] = [str(t) for t in _list(fr["dtypes"])]
        if not len(cols) == len(arrays) == len(dtypes):
            raise ValueError("a table's columns, data and dtypes differ in length")
        df = pd.DataFrame(dict(enumerate(arrays)), index=_decode_array(fr["index"]))
        for k, t in enumerate(dtypes):
            if str(df[k].dtype) != t:
                df[k] = df[k].astype(t)
        df.columns = pd.Index(cols)
        if isinstance(df.index, pd.Index) and df.index.equals(pd.RangeIndex(len(df))):
            df.index = pd.RangeIndex(len(df))
        df.attrs = decode(fr.get("attrs", {}))
        return df
    return {k: decode(v) for k, v in data.items()}


def _build(cls: type, values: dict[str, Any]) -> Any:
    if issubclass(cls, Result):
        return cls._from_fields(values)
    if not dataclasses.is_dataclass(cls):
        raise ValueError(f"{cls.__name__} is not a dataclass")
    return cls(**values)


def _list(v: Any) -> list:
    if not isinstance(v, list):
        raise ValueError(f"expected a list, got {type(v).__name__}")
    return v


def _dtype(text: Any) -> np.dtype:
    if not isinstance(text, str):
        raise ValueError(f"bad dtype {text!r}")
    dt = np.dtype(text)
    if dt.kind not in "biufcUSO":
        raise ValueError(f"bad dtype {text!r}")
    return dt


def _decode_array(data: dict[str, Any]) -> np.ndarray:
    dt = _dtype(data["__ndarray__"])
    shape = tuple(int(n) for n in _list(data["shape"]))
    if "b64" in data:
        raw = base64.b64decode(data["b64"], validate=True)
        return np.frombuffer(raw, dtype=dt).reshape(shape).copy()
    flat = _list(data["data"])
    if dt.kind == "O":
        out = np.empty(len(flat), dtype=object)
        out[:] = [decode(v) for v in flat]
        return out.reshape(shape)
    if dt.kind == "c":
        vals: list = [complex(_unfloat(a), _unfloat(b)) for a, b in flat]
    elif dt.kind == "f":
        vals = [_unfloat(x) for x in flat]
    elif dt.kind == "S":
        vals = [str(x).encode("latin-1") for x in flat]
    else:
        vals = flat
    return np.array(vals, dtype=dt).reshape(shape)


def load(path: str | Path) -> Any:
    """Read any result saved by :meth:`Result.save` (``tslip.load``).

    ``path`` is the ``.json`` file, or the ``.parquet`` / ``.csv`` table
    (its record is the ``.json`` of the same name). A missing, damaged or
    foreign file, or one that names a class it may not build, is a one-line
    ``ValueError``.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise ValueError(f"path must end in one of {', '.join(SUFFIXES)}, got {str(path)!r}")
    rec_path = path.with_suffix(".json") if suffix in TABLE_SUFFIXES else path
    if not rec_path.is_file():
        raise ValueError(f"result file {str(rec_path)!r} does not exist")
    try:
        record = json.loads(rec_path.read_text(encoding="utf-8"))
        if not (isinstance(record, dict) and isinstance(record.get("format"), dict)
                and record["format"].get("name") == FORMAT_NAME):
            raise ValueError("not a saved tslip result")
        version = record["format"].get("version")
        if not isinstance(version, int) or version > FORMAT_VERSION:
            raise ValueError(f"format version {version!r} is newer than this tslip's "
                             f"{FORMAT_VERSION}")
        table = record.get("table")
        if table is None:
            return decode(record["result"])
        return _load_table(rec_path, record, table, suffix if suffix != ".json" else None)
    except (ValueError, TypeError, KeyError, AttributeError, IndexError, OverflowError,
            binascii.Error, UnicodeDecodeError, ImportError) as exc:
        why = " ".join(str(exc).split()) or type(exc).__name__
        raise ValueError(f"cannot load {str(path)!r}: {why}") from None
    except OSError as exc:  # a damaged parquet file, unreadable file
        raise ValueError(f"cannot load {str(path)!r}: {exc.strerror or exc}") from None


def _numeric(dtype: Any) -> bool:
    try:
        return np.dtype(str(dtype)).kind in "biufc"
    except TypeError:  # a pandas extension type, such as "str"
        return False


def _load_table(rec_path: Path, record: dict, table: Any, suffix: str | None) -> Any:
    import pandas as pd

    if not isinstance(table, dict) or not isinstance(table.get("file"), str):
        raise ValueError("bad table entry")
    name = table["file"]
    kind = Path(name).suffix.lower()  # the table beside the record, whatever its name now
    if kind not in TABLE_SUFFIXES or (suffix is not None and kind != suffix):
        raise ValueError(f"the record describes the table {name!r}")
    tab_path = rec_path.with_suffix(kind)
    if tab_path.suffix.lower() == ".parquet":
        df = pd.read_parquet(tab_path)
    elif tab_path.suffix.lower() == ".csv":
        dtypes = table.get("dtypes", {})
        if not isinstance(dtypes, dict):
            raise ValueError("bad table dtypes")
        # an empty cell is a missing number, but an empty text in a text column
        text = {c for c, t in dtypes.items() if not _numeric(t)}
        df = pd.read_csv(tab_path, keep_default_na=False,  # pandas >= 3: exact floats
                         na_values={c: [""] for c in dtypes if c not in text},
                         dtype={c: str for c in text})
        for c in df.columns:  # text has no types: an empty or all-integer column
            if c in dtypes and str(df[c].dtype) != dtypes[c]:
                df[c] = df[c].astype(dtypes[c])
    else:
        raise ValueError(f"bad table file {name!r}")
    df.attrs["units"] = dict(table.get("units", {}))
    res = record["result"]
    cls = _resolve(res["__type__"])
    if not issubclass(cls, Result):
        raise ValueError(f"{res['__type__']!r} is not a Result")
    fields = {str(k): decode(v) for k, v in res["fields"].items()}
    return cls._from_fields(cls._from_table(df, fields))
