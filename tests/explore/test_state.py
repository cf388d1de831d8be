"""The explorer's controls and URL query: ranges from the validators, values parsed as data."""

import dataclasses
import math
from urllib.parse import parse_qsl

import pytest

from tslip import GlobalPD, LocalVelocity, Params, preset
from tslip.explore.state import CONTROLS, GAINS, ExploreState, control_for, parse_query
from tslip.model.parameters import PARAMETER_TABLE


def test_each_control_carries_the_unit_and_range_of_its_parameter_table_row():
    rows = {r.name: r for r in PARAMETER_TABLE}
    for c in CONTROLS:
        row = rows[c.name]
        assert (c.unit, c.lower, c.upper, c.lower_open, c.upper_open) == (
            row.unit, row.lower, row.upper, row.lower_open, row.upper_open)
        assert c.unit in c.title and c.range_text in c.title


def test_slider_spans_lie_inside_the_valid_range_so_a_slider_cannot_send_a_bad_value():
    base = preset("table2.1")
    for c in CONTROLS:
        for value in (c.start, c.end):  # Params refuses any value outside the range
            dataclasses.replace(base, **{c.name: value})
    for kind, gains in GAINS.items():
        for c in gains:
            ctrl = {"global_pd": GlobalPD, "local_velocity": LocalVelocity}.get(kind)
            if ctrl is not None:
                for value in (c.start, c.end):
                    ctrl(**{c.name: value})


def test_a_slider_span_widens_to_hold_a_preset_value_outside_it():
    k = control_for("k")
    assert k.span(100.0) == (k.start, 100.0)
    assert k.span(1.0) == (1.0, k.end)


def test_a_query_sets_the_parameters_as_params_would():
    state, errors = parse_query({"preset": "table6.1", "k": "9.5", "r": "-0.2",
                                 "retraction": "apex", "Kd": "0.7"})
    assert errors == []
    want = dataclasses.replace(preset("table6.1"), k=9.5, r=-0.2, retraction="apex",
                               controller=LocalVelocity(Kd=0.7, alphad_ref=2.42))
    assert state.params == want


def test_the_future_research_leg_is_a_control_with_its_parameter_range():
    state, errors = parse_query({"preset": "table6.1", "leg_exponent": "1.5",
                                 "leg_thrust": "0.05"})
    assert errors == []
    assert (state.params.leg_exponent, state.params.leg_thrust) == (1.5, 0.05)
    state, errors = parse_query({"preset": "table6.1", "leg_exponent": "0.4"})
    assert len(errors) == 1 and "leg_exponent" in errors[0] and "0.5" in errors[0]
    assert state.params.leg_exponent == 1.0


def test_the_retraction_stop_is_in_the_query_only_when_set():
    state, errors = parse_query({"preset": "table6.1", "alpha_stop": "1.34"})
    assert errors == [] and state.params.alpha_stop == 1.34
    assert "alpha_stop=1.34" in state.query()
    assert parse_query(dict(parse_qsl(state.query())))[0] == state
    free, errors = parse_query({"preset": "table6.1", "alpha_stop": "none"})
    assert errors == [] and free.params.alpha_stop is None
    assert "alpha_stop" not in free.query()
    for bad in ("4", "0", "nan", "x"):
        state, errors = parse_query({"preset": "table6.1", "alpha_stop": bad})
        assert state.params.alpha_stop is None
        assert len(errors) == 1 and errors[0].startswith("alpha_stop"), errors


def test_a_query_can_switch_the_controller_and_set_its_gains():
    state, errors = parse_query({"controller": "global_pd", "Kp": "7", "phi_ref": "0.1"})
    assert errors == []
    assert state.params.controller == GlobalPD(Kp=7.0, phi_ref=0.1)


@pytest.mark.parametrize(("entry", "words"), [
    (("k", "-1"), ["k", "(0, inf)"]),
    (("k", "nan"), ["k", "nan"]),
    (("beta0", "2"), ["beta0", "1.5708"]),
    (("v0", "abc"), ["v0", "number", "'abc'"]),
    (("c_l", "inf"), ["c_l", "inf"]),
    (("preset", "table9"), ["preset", "table2.1"]),
    (("controller", "pid"), ["controller", "local_velocity"]),
    (("retraction", "never"), ["retraction", "'liftoff'"]),
    (("fraction", "3"), ["fraction", "[0, 2]"]),
    (("disturbance", "kick"), ["disturbance", "push"]),
    (("bogus", "1"), ["unknown", "'bogus'"]),
])
def test_a_bad_entry_is_refused_by_name_and_the_rest_still_applies(entry, words):
    state, errors = parse_query({"preset": "table6.1", "r": "0.25", entry[0]: entry[1]}
                                if entry[0] != "preset" else {entry[0]: entry[1], "r": "0.25"})
    assert len(errors) == 1
    assert all(w in errors[0] for w in words), errors[0]
    assert state.params.r == 0.25
    if entry[0] == "k":
        assert state.params.k == preset("table6.1").k  # the refused value keeps the preset's


def test_the_query_of_a_state_parses_back_to_the_same_state():
    p = dataclasses.replace(preset("table2.1-global-pd"), k=31.25, beta0=1.1, omega_r=0.3,
                            controller=GlobalPD(Kp=4.0, Kd=0.25, phi_ref=0.05))
    state = ExploreState("table2.1-global-pd", p, "pitch_rate", 0.75)
    back, errors = parse_query(dict(parse_qsl(state.query())))
    assert errors == []
    assert back == state


def test_floats_survive_the_query_exactly():
    p = dataclasses.replace(preset("table2.1"), v0=math.pi)
    back, _ = parse_query(dict(parse_qsl(ExploreState("table2.1", p).query())))
    assert back.params.v0 == math.pi
    assert isinstance(back.params, Params)


@pytest.mark.parametrize(("value", "ok"), [
    (math.nextafter(0.0, -1.0), False), (-0.05, False), (0.0, True), (0.05, True),
    (2.0, True), (math.nextafter(2.0, 3.0), False)])
def test_the_fraction_is_refused_on_each_side_of_0_to_2(value, ok):
    """A negative fraction would turn the runner's disturbance the other way (the limit's
    sign is its direction): refused from the URL and by the state itself."""
    state, errors = parse_query({"preset": "table6.1", "fraction": repr(value)})
    if ok:
        assert errors == [] and state.fraction == value
        assert ExploreState("table6.1", preset("table6.1"), "push", value).fraction == value
    else:
        assert len(errors) == 1 and errors[0].startswith("fraction [-] must be in [0, 2]")
        assert state.fraction == 0.5  # the default kept
        with pytest.raises(ValueError, match=r"fraction \[-\] must be in \[0, 2\]"):
            ExploreState("table6.1", preset("table6.1"), "push", value)
