"""A study's or viability map's name becomes a folder name (``studies/<name>``,
``viability/<name>``): it must match ``^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$``, so "." and
".." (the current folder and its parent), paths and hidden names are refused."""

import re

import pytest

from tslip.model.parameters import preset
from tslip.sweeps import Axis, StudySpec
from tslip.sweeps.viability import ViabilitySpec

BAD = [".", "..", "../x", "a/b", "a\\b", ".hidden", "-x", "_x", "a b", "", "é", "a" * 65,
       "x\n"]
GOOD = ["a", "mass-offset", "grid_v2", "k.beta0", "A9", "a" * 64]
RULE = re.escape("must match ^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$")


def _study(name):
    return StudySpec(name, preset("table2.1"), axes=(Axis("r", (0.1,)),))


def _viability(name):
    return ViabilitySpec.from_dict({
        "name": name, "preset": "slip", "energy": 2.6,
        "state": [{"name": "y", "from": 0.9, "to": 2.2, "points": 3}],
        "action": {"name": "alpha_r", "from": 1.0, "to": 1.45, "points": 3}})


@pytest.mark.parametrize("make, field", [(_study, "study name"),
                                         (_viability, "viability name")])
@pytest.mark.parametrize("name", BAD)
def test_a_name_that_is_no_plain_folder_name_is_one_line(make, field, name):
    with pytest.raises(ValueError, match=f"^{field} {RULE}") as exc:
        make(name)
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize("make", [_study, _viability])
@pytest.mark.parametrize("name", GOOD)
def test_plain_names_are_kept(make, name):
    assert make(name).name == name
