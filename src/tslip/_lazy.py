"""Names of a package loaded from its modules on first use (PEP 562).

A package that re-exports many names (``tslip.spatial``, ``tslip.plotting``)
would import every module, and what they import, when any one is needed:
:func:`lazy_names` gives it the module ``__getattr__`` and ``__dir__`` that
import a name's module only when the name is first read, and keep the value
in the package for later look-ups.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Mapping

__all__ = ["lazy_names"]


def lazy_names(package: str, table: Mapping[str, tuple[str, str]],
               ) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """``(__getattr__, __dir__)`` for ``package``, whose public names ``table`` maps to
    ``(submodule, name there)``; an unknown name is an ``AttributeError``."""

    def __getattr__(name: str) -> object:  # noqa: N807 - the module hook's name
        if name not in table:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, attr = table[name]
        value = getattr(importlib.import_module(f".{module}", package), attr)
        setattr(sys.modules[package], name, value)  # later look-ups find it directly
        return value

    def __dir__() -> list[str]:  # noqa: N807 - the module hook's name
        mod = sys.modules[package]
        return sorted({*vars(mod), *getattr(mod, "__all__", ())})

    return __getattr__, __dir__
