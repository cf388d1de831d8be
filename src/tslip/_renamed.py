"""Old names kept for one release: each use warns (``DeprecationWarning``) and still works.

The TSLIP and the biped share one vocabulary (docs/model.md, "Vocabulary");
the names the biped used before it, and ``n_strides`` for a stride count,
are served from here until :data:`REMOVED_IN`. Two tools:

* :func:`module_getattr` builds a module's ``__getattr__`` (PEP 562) that
  resolves an old name to the new object, with a warning;
* :func:`accepts_n_strides` lets a function that counts strides with
  ``n_steps`` still take the old keyword ``n_strides``.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Callable
from typing import Any, TypeVar

__all__ = ["REMOVED_IN", "warn_renamed", "module_getattr", "accepts_n_strides"]

#: The release that removes the old names.
REMOVED_IN = "0.4"

F = TypeVar("F", bound=Callable[..., Any])


def warn_renamed(old: str, new: str, *, stacklevel: int = 3) -> None:
    """Warn that ``old`` is deprecated in favour of ``new``."""
    warnings.warn(f"{old} is deprecated and will be removed in tslip {REMOVED_IN}; use {new}",
                  DeprecationWarning, stacklevel=stacklevel)


def module_getattr(module: str, aliases: dict[str, tuple[str, Callable[[], Any]]]
                   ) -> Callable[[str], Any]:
    """A module ``__getattr__`` serving ``aliases``: old name -> (new name, getter).

    The getter is called on each access (so it can import lazily); the
    warning names the module, the old and the new name.
    """

    def __getattr__(name: str) -> Any:
        entry = aliases.get(name)
        if entry is None:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        new, get = entry
        warn_renamed(f"{module}.{name}", new)
        return get()

    return __getattr__


def accepts_n_strides(fn: F) -> F:
    """Let ``fn(..., n_steps=...)`` still be called with the old keyword ``n_strides``.

    The old keyword warns; giving both is a ``TypeError``, as for any keyword
    given twice.
    """

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        if "n_strides" in kwargs:
            if "n_steps" in kwargs:
                raise TypeError(f"{fn.__name__}() got both n_steps and the deprecated n_strides")
            warn_renamed(f"the keyword n_strides of {fn.__module__}.{fn.__qualname__}",
                         "n_steps")
            kwargs["n_steps"] = kwargs.pop("n_strides")
        return fn(*args, **kwargs)

    return wrapper  # type: ignore[return-value]
