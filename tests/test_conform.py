"""``tslip._conform.check``: each rule accepts what its annotation states and refuses the rest."""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Mapping, Sequence
from typing import Any, Literal, TypedDict

import numpy as np
import pytest

from tslip._conform import check
from tslip.model.parameters import preset
from tslip.model.state import TouchdownState
from tslip.simulation import simulate


class _Box(TypedDict):
    lo: float
    hi: tuple[float, float]


@dataclasses.dataclass(frozen=True)
class _Point:
    x: float
    tag: str | None
    items: tuple[int, ...]


@pytest.mark.parametrize("value, tp", [
    (1.5, float), (2, float), (np.float64(0.5), float), (np.int64(3), int), (3, int),
    (True, bool), (np.bool_(False), bool), ("a", str), (None, None), (None, float | None),
    (np.zeros(3), np.ndarray), (np.zeros(2, dtype=np.int64), np.ndarray),
    ((1.0, 2.0), tuple[float, float]), ((), tuple[float, ...]), ((1, 2.5), tuple[float, ...]),
    ([1, 2], list[int]), ([1, 2], Sequence[int]), ((1, 2), Sequence[int]),
    ({"a": 1.0}, dict[str, float]), ({"a": 1.0}, Mapping[str, float]),
    ({"lo": 0.0, "hi": (1.0, 2.0)}, _Box), ("x", Literal["x", "y"]), (object(), Any),
    (_Point(1.0, None, (1, 2)), _Point), (_Point(1.0, "t", ()), _Point),
])
def test_conforming_values_pass(value, tp) -> None:
    check(value, tp)


@pytest.mark.parametrize("value, tp, where", [
    (True, float, "data"), ("1.5", float, "data"), (1.5, int, "data"), (True, int, "data"),
    (1, bool, "data"), (1, str, "data"), (0.0, None, "data"), ("a", float | None, "data"),
    (np.array(["a"], dtype=object), np.ndarray, "data"), ([1.0], np.ndarray, "data"),
    (np.array(["a"]), np.ndarray, "data"),
    ([1.0, 2.0], tuple[float, float], "data"), ((1.0,), tuple[float, float], "data"),
    ((1.0, "b"), tuple[float, ...], "data[1]"), ((1, 2), list[int], "data"),
    (["a"], list[int], "data[0]"), ("ab", Sequence[str], "data"),
    ({1: 1.0}, dict[str, float], "data key"), ({"a": "b"}, dict[str, float], "data['a']"),
    ([("a", 1.0)], dict[str, float], "data"),
    ({"lo": 0.0}, _Box, "data"), ({"lo": 0.0, "hi": (1.0, 2.0), "x": 1}, _Box, "data"),
    ({"lo": 0.0, "hi": (1.0,)}, _Box, "data['hi']"), ("z", Literal["x", "y"], "data"),
    (1, Literal[True], "data"),
    (_Point("1", None, ()), _Point, "data.x"), (_Point(1.0, 2, ()), _Point, "data.tag"),
    (_Point(1.0, None, (1.5,)), _Point, "data.items[0]"), ({"x": 1.0}, _Point, "data"),
])
def test_other_values_fail_naming_the_field(value, tp, where) -> None:
    with pytest.raises(ValueError, match=rf"^{re.escape(where)}: expected "):
        check(value, tp)


def test_a_recorded_run_checks_through_its_descriptor_and_lazy_steps() -> None:
    """``Trajectory.data`` is a descriptor (checked as the array it returns) and its
    ``steps`` a sequence the run builds from its arrays on first read (not a list or
    tuple: its items are not checked, which would build them)."""
    from tslip.simulation.result import Trajectory

    p = preset("table2.1")
    run = simulate(p, TouchdownState(beta=1.2, phi=0.0, xd=1.0, yd=-0.3, phid=0.0), 2, dt=0.05)
    check(run, Trajectory)
    with pytest.raises(ValueError, match=r"^run\.params: expected"):
        check(dataclasses.replace(run, params=None), Trajectory, "run")
