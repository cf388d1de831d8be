"""The public API: documented, units on every parameter, docstring examples run."""

import dataclasses
import doctest
import importlib

import pytest

import tslip

DOCTEST_MODULES = [
    "tslip.model.parameters",
    "tslip.model.terrain",
    "tslip.model.units",
    "tslip.simulation.integrate",
    "tslip.gait.robustness",
    "tslip.gait.section",
    "tslip.gait.allgaits",
    "tslip.gait.problem",
]


def test_public_names_exist_and_are_documented():
    for name in tslip.__all__:
        obj = getattr(tslip, name)
        if name != "__version__":
            assert obj.__doc__ and obj.__doc__.strip(), f"tslip.{name} has no docstring"


def test_every_parameter_and_gain_has_a_unit_and_description():
    classes = [tslip.Params, tslip.GlobalPD, tslip.LocalVelocity, tslip.ConstantTorque]
    for cls in classes:
        for f in dataclasses.fields(cls):
            if f.name in ("controller", "leg_reset", "retraction"):
                continue
            assert "unit" in f.metadata and f.metadata["description"], (cls, f.name)


@pytest.mark.parametrize("module", DOCTEST_MODULES)
def test_docstring_examples(module):
    result = doctest.testmod(importlib.import_module(module), optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
