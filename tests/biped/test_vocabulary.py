"""One vocabulary for the TSLIP and the biped: one Status enum, and the old names warn.

The old biped names are kept for one release (removed in 0.4): each must
warn with a DeprecationWarning and still give what it gave.
"""

import importlib

import numpy as np
import pytest

import tslip
from tslip.biped import BipedParams, BipedState
from tslip.biped import _pack as bpk

Status = tslip.Status

#: The TSLIP's codes as released in 0.2 (stored in caches and results): they must not move.
RELEASED_TSLIP_CODES = {
    "OK": 0, "FALL_BACKWARD": 1, "FALL_HIP_GROUND": 2, "FALL_NO_TOUCHDOWN": 3, "FALL_TRIP": 4,
    "FALL_LENGTHENING": 5, "STEP_UNDERFLOW": 10, "MAX_STEPS": 11, "STANCE_TIMEOUT": 12,
    "FLIGHT_TIMEOUT": 13, "NONFINITE": 14,
}

#: The biped's own enum as released in 0.2: name -> code (falls 10-19, errors 20+, T_END 1).
OLD_BIPED = {
    "OK": 0, "T_END": 1, "FALL_HIP": 10, "FALL_BACKWARD": 11, "FALL_PITCH": 12, "FALL_LEG": 13,
    "FALL_NO_TOUCHDOWN": 14, "ERR_MAX_STEPS": 20, "ERR_STEP_UNDERFLOW": 21, "ERR_NONFINITE": 22,
}


def _old_kind(code: int) -> str:
    """How the 0.2 biped enum classified its code."""
    return "ok" if code == 0 else "end" if code == 1 else "fall" if code < 20 else "error"


def _kind(s: Status) -> str:
    return ("ok" if s == Status.OK else "fall" if s.fell else "error" if s.is_error
            else "end")


# -- one Status -----------------------------------------------------------------------

def test_the_tslip_codes_keep_their_released_numbers():
    for name, code in RELEASED_TSLIP_CODES.items():
        assert Status[name].value == code, name


def test_code_ranges_falls_errors_and_other_outcomes():
    assert len(Status.__members__) == len(Status)  # no member is an alias of another
    for s in Status:
        assert s.fell == (1 <= s.value <= 9), s
        assert s.is_error == (10 <= s.value <= 19), s
        assert s.reason and "\n" not in s.reason
    assert not Status.T_END.fell and not Status.T_END.is_error and Status.T_END.value >= 20


def test_every_biped_kernel_code_translates_to_a_status_of_the_same_kind():
    from tslip.biped.simulate import to_status

    codes = {v for k, v in vars(bpk).items() if k.startswith("ST_")}
    assert codes == set(OLD_BIPED.values()) == set(bpk.STATUS_NAMES)
    for code in codes:
        assert _kind(to_status(code)) == _old_kind(code), code
    assert len({to_status(c) for c in codes}) == len(codes)  # nothing merged


def test_a_biped_run_reports_the_shared_status():
    from tslip.biped import simulate, step

    tr = simulate(BipedParams(), BipedState.thesis(), 20)  # Table E.2 falls by its pitch
    assert type(tr.status) is Status and tr.status is Status.FALL_PITCH and tr.fell
    one = step(BipedParams(), BipedState.thesis().to_array(), 0.0)
    assert type(one.status) is Status and one.ok and not one.fell and one.reason == "ok"


# -- the old names: each warns and still works -----------------------------------------

@pytest.mark.parametrize("module, old, new", [
    ("tslip.biped", "BipedTrajectory", "Trajectory"),
    ("tslip.biped", "StrideResult", "StepResult"),
    ("tslip.biped", "stride", "step"),
    ("tslip.biped.simulate", "BipedTrajectory", "Trajectory"),
    ("tslip.biped.simulate", "StrideResult", "StepResult"),
    ("tslip.biped.simulate", "stride", "step"),
    ("tslip.biped.gait", "stride_map", "step_map"),
    ("tslip.biped.gait", "FloquetResult", "Floquet"),
    ("tslip.biped.gait", "GaitSearchResult", "Gait"),
    ("tslip.experiment.render", "render_frames", "camera_frames"),
])
def test_an_old_name_warns_and_is_the_new_object(module, old, new):
    m = importlib.import_module(module)
    target = importlib.import_module("tslip.biped.simulate") if module == "tslip.biped" else m
    with pytest.warns(DeprecationWarning, match=rf"{old} is deprecated.*0\.4.*{new}"):
        got = getattr(m, old)
    assert got is getattr(target, new)


def test_from_import_of_an_old_name_warns():
    with pytest.warns(DeprecationWarning, match="BipedTrajectory"):
        from tslip.biped.simulate import BipedTrajectory  # noqa: F401


def test_unknown_names_are_still_attribute_errors():
    for module in ("tslip.biped", "tslip.biped.simulate", "tslip.biped.gait",
                   "tslip.experiment.render"):
        with pytest.raises(AttributeError, match="no_such_name"):
            importlib.import_module(module).no_such_name  # noqa: B018


@pytest.mark.parametrize("module", ["tslip.biped", "tslip.biped.simulate"])
def test_old_biped_status_warns_and_answers_as_the_old_enum(module):
    with pytest.warns(DeprecationWarning, match="BipedStatus is deprecated.*tslip.Status"):
        BipedStatus = importlib.import_module(module).BipedStatus
    renamed = {"FALL_HIP": "FALL_HIP_GROUND", "ERR_MAX_STEPS": "MAX_STEPS",
               "ERR_STEP_UNDERFLOW": "STEP_UNDERFLOW", "ERR_NONFINITE": "NONFINITE"}
    for name, code in OLD_BIPED.items():
        new = Status[renamed.get(name, name)]
        assert getattr(BipedStatus, name) is new, name  # its members
        assert BipedStatus[name] is new, name
        assert BipedStatus(code) is new, code  # its old codes, as stored by 0.2
        assert _kind(new) == _old_kind(code)
        assert isinstance(new, BipedStatus)
    assert not isinstance(0, BipedStatus)
    assert list(BipedStatus) == list(Status)
    with pytest.raises(AttributeError):
        BipedStatus.NOT_A_MEMBER  # noqa: B018


def test_the_old_names_of_a_biped_step_and_run_still_simulate():
    import tslip.biped as biped

    with pytest.warns(DeprecationWarning):
        stride = biped.stride
    with pytest.warns(DeprecationWarning):
        StrideResult = biped.StrideResult
    res = stride(BipedParams(), BipedState.thesis().to_array(), 0.0)
    new = biped.step(BipedParams(), BipedState.thesis().to_array(), 0.0)
    assert isinstance(res, StrideResult) and res.t == new.t
    np.testing.assert_array_equal(res.state, new.state)


def test_every_name_in_the_docs_vocabulary_table_exists():
    """docs/model.md, "Vocabulary": each dotted tslip name it cites resolves."""
    import re
    from pathlib import Path

    text = (Path(__file__).parents[2] / "docs" / "model.md").read_text()
    section = text[text.index("## Vocabulary"):]
    names = set(re.findall(r"`(?:\{\w+\}`)?(tslip(?:\.\w+)+)", section))
    assert len(names) >= 15, names
    for name in sorted(names):
        parts = name.split(".")
        for cut in range(len(parts), 0, -1):  # the longest importable module prefix
            try:
                obj = importlib.import_module(".".join(parts[:cut]))
                break
            except ImportError:
                continue
        for attr in parts[cut:]:
            obj = getattr(obj, attr)  # AttributeError names the missing one
        assert obj is not None, name
