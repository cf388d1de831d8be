"""The biped's old status enum, served by the shared :class:`tslip.Status` until 0.4.

``tslip.biped.BipedStatus`` (deprecated: reaching it warns, see
:mod:`tslip._renamed`) still answers as the old enum did: its member names,
including the four that the shared enum spells differently
(:data:`OLD_MEMBERS`), give the shared members; called with one of the old
biped codes (``BipedStatus(12)``) it translates it as the kernels' codes are
(:func:`tslip.biped.simulate.to_status`); and ``isinstance(s, BipedStatus)``
holds for every :class:`tslip.Status`.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterator
from typing import Any

from ..simulation.result import Status

__all__ = ["BipedStatus", "OLD_MEMBERS", "SIMULATE_ALIASES"]

#: Old biped member name -> shared member name, where they differ.
OLD_MEMBERS: dict[str, str] = {
    "FALL_HIP": "FALL_HIP_GROUND",
    "ERR_MAX_STEPS": "MAX_STEPS",
    "ERR_STEP_UNDERFLOW": "STEP_UNDERFLOW",
    "ERR_NONFINITE": "NONFINITE",
}


class _BipedStatusType(type):
    """Class behaviour of :class:`BipedStatus`: members, lookup by code, isinstance."""

    def __getattr__(cls, name: str) -> Status:
        if name.startswith("_"):
            raise AttributeError(name)
        try:
            return Status[OLD_MEMBERS.get(name, name)]
        except KeyError:
            raise AttributeError(f"BipedStatus has no member {name!r}") from None

    def __getitem__(cls, name: str) -> Status:
        return Status[OLD_MEMBERS.get(name, name)]

    def __call__(cls, code: Any) -> Status:
        from .simulate import to_status

        return to_status(int(code))

    def __instancecheck__(cls, obj: object) -> bool:
        return isinstance(obj, Status)

    def __iter__(cls) -> Iterator[Status]:
        return iter(Status)


class BipedStatus(metaclass=_BipedStatusType):
    """Deprecated: the biped's statuses are :class:`tslip.Status` (removed in 0.4)."""


def _simulate(name: str) -> Callable[[], Any]:
    # the module, not the function tslip.biped.simulate that shadows it
    return lambda: getattr(importlib.import_module("tslip.biped.simulate"), name)


#: Old names of :mod:`tslip.biped` and :mod:`tslip.biped.simulate`: (new name, getter).
SIMULATE_ALIASES: dict[str, tuple[str, Callable[[], Any]]] = {
    "BipedStatus": ("tslip.Status", lambda: BipedStatus),
    "BipedTrajectory": ("tslip.biped.Trajectory", _simulate("Trajectory")),
    "StrideResult": ("tslip.biped.StepResult", _simulate("StepResult")),
    "stride": ("tslip.biped.step", _simulate("step")),
}
