"""checked_replace: dataclasses.replace that checks only the changed fields, identically."""

import dataclasses
import math

import numpy as np
import pytest

import tslip
from tslip.gait.problem import checked_replace
from tslip.model.controllers import ConstantTorque, GlobalPD, LocalVelocity, Passive
from tslip.model.parameters import PARAMETER_TABLE


def _same_outcome(obj, **change):
    """Both give equal copies, or both raise the same ValueError."""
    try:
        want = dataclasses.replace(obj, **change)
    except ValueError as exc:
        with pytest.raises(ValueError) as got:
            checked_replace(obj, **change)
        assert str(got.value) == str(exc)
        return "error"
    got = checked_replace(obj, **change)
    assert got == want and type(got) is type(want)
    for f in dataclasses.fields(want):  # the same types too (check_number's floats)
        assert type(getattr(got, f.name)) is type(getattr(want, f.name)), f.name
    return "ok"


@pytest.mark.parametrize("row", PARAMETER_TABLE, ids=lambda r: r.name)
def test_every_params_field_checked_as_replace_checks_it(row):
    p = tslip.preset("table2.1")
    inside = [getattr(p, row.name) * 1.1 + 0.01, np.float64(0.5), 2, row.lower, row.upper]
    outside = [math.nan, math.inf, -math.inf, True, "1", row.lower - 1.0, row.upper + 1.0]
    outcomes = {_same_outcome(p, **{row.name: v}) for v in inside + outside}
    assert "error" in outcomes  # NaN at least is refused


@pytest.mark.parametrize("ctrl", [GlobalPD(), LocalVelocity(Kd=0.5, alphad_ref=2.0),
                                  ConstantTorque(tau_c=0.1, c_h=0.2)])
def test_every_controller_gain_checked_as_replace_checks_it(ctrl):
    for f in dataclasses.fields(ctrl):
        for v in (0.3, -0.3, 0, math.nan, True):
            _same_outcome(ctrl, **{f.name: v})


def test_other_changes_take_the_full_check():
    p = tslip.preset("table2.1")
    assert _same_outcome(p, controller=LocalVelocity()) == "ok"  # another controller type
    assert _same_outcome(p, leg_reset="sideways") == "error"
    assert _same_outcome(p, controller="passive") == "error"
    assert checked_replace(p, controller=Passive()) == p
