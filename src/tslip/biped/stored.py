"""Periodic biped gaits shipped with the package, and reading any gait file.

A gait file is the JSON written by ``tslip biped search`` or ``tslip biped
optimise``: ``params`` (the :class:`BipedParams` fields) and the section
vector ``z`` of :func:`tslip.biped.gait.to_section`, plus whatever the
command measured. Two are stored in ``tslip/biped/gaits/``:

``converged-e2``
    The periodic gait that shooting reaches from Table E.2 with free ``T``,
    ``theta_f``, ``theta_s``, ``Kp_h``, ``Kd_h`` (``tslip biped search``,
    residual 1.2e-9, largest multiplier 0.788).
``optimised``
    The most stable design found by ``tslip biped optimise`` (largest
    multiplier 0.1005; 0.1007 as stored, before controller switches were
    events); survives step-down -0.16, push -0.82 and pitch rate
    -3.26 over 25 strides; see its ``provenance`` and
    ``robustness_25_strides``).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .parameters import BipedParams

__all__ = ["STORED_GAITS", "gait_path", "load_gait"]

_DIR = Path(__file__).parent / "gaits"

#: Name -> file of the stored gaits.
STORED_GAITS: dict[str, str] = {"converged-e2": "converged_e2.json", "optimised": "optimised.json"}


def gait_path(name: str) -> Path:
    """Path of a stored gait (see :data:`STORED_GAITS`)."""
    if name not in STORED_GAITS:
        raise ValueError(f"stored gait must be one of {list(STORED_GAITS)}, got {name!r}")
    return _DIR / STORED_GAITS[name]


def load_gait(source: str | Path) -> tuple[BipedParams, NDArray[np.float64], float,
                                            dict[str, Any]]:
    """Read a gait: a stored name or a JSON file.

    Returns
    -------
    params : BipedParams
    y : ndarray, shape (18,)
        State at the right touch-down of the section.
    t0 : float
        Its time (the controller phase).
    data : dict
        The whole file (``z``, measured multipliers, ...).

    Raises
    ------
    ValueError
        One line naming the file: missing, unreadable, not JSON, or without
        a valid ``params`` and ``z``.
    """
    from .gait import from_section

    path = gait_path(str(source)) if str(source) in STORED_GAITS else Path(source)
    name = str(source)
    try:
        data = json.loads(path.read_text())
    except FileNotFoundError:
        raise ValueError(f"gait file {name!r} does not exist (stored gaits: "
                         f"{', '.join(STORED_GAITS)})") from None
    except json.JSONDecodeError as exc:
        raise ValueError(f"gait file {name!r} is not valid JSON: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"cannot read gait file {name!r}: {exc}") from None
    if not (isinstance(data, dict) and isinstance(data.get("params"), dict) and "z" in data):
        raise ValueError(f"gait file {name!r} needs a 'params' object and a section vector "
                         f"'z' (as written by `tslip biped search`)")
    try:
        p = BipedParams.from_dict(data["params"])
        y, t0 = from_section(p, np.asarray(data["z"], dtype=float))
    except (TypeError, ValueError) as exc:
        raise ValueError(f"gait file {name!r}: {exc}") from None
    return p, y, t0, data
