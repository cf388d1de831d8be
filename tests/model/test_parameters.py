"""Parameters: table == dataclass, validation messages, presets, TOML."""

import dataclasses
import math

import numpy as np
import pytest

import tslip
from tslip.model.parameters import PARAMETER_TABLE, Params, preset_description


def test_table_matches_dataclass_fields_and_defaults():
    fields = {f.name: f for f in dataclasses.fields(Params)}
    for row in PARAMETER_TABLE:
        f = fields[row.name]
        assert f.default == row.default
        assert f.metadata["unit"] == row.unit
        assert f.metadata["symbol"] == row.symbol
    assert {r.name for r in PARAMETER_TABLE} == set(fields) - {"controller", "leg_reset",
                                                                "retraction", "alpha_stop"}
    assert fields["alpha_stop"].default is None  # optional: no stop (not a table row)


def test_defaults_are_table_2_1():
    p = tslip.preset("table2.1")
    assert (p.v0, p.J, p.m, p.r, p.g, p.k, p.beta0, p.omega_r) == (
        5.0, 0.1, 1.0, 0.3, 1.0, 25.0, 1.05, 1.0)
    assert isinstance(p.controller, tslip.Passive)


def test_table_6_1_preset():
    p = tslip.preset("table6.1")
    assert (p.v0, p.k, p.beta0, p.omega_r, p.c_l) == (1.90, 8.0, 0.93, 1.50, 0.32)
    assert p.controller == tslip.LocalVelocity(Kd=0.40, alphad_ref=2.42)


@pytest.mark.parametrize("name", tslip.presets())
def test_every_preset_builds_and_has_description(name):
    assert isinstance(tslip.preset(name), Params)
    assert preset_description(name)


def test_replace_leaves_original_intact():
    p = tslip.preset("table2.1")
    q = dataclasses.replace(p, k=30.0)
    assert p.k == 25.0 and q.k == 30.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.k = 1.0  # type: ignore[misc]


@pytest.mark.parametrize(
    ("field", "value"),
    [("m", 0.0), ("m", -1.0), ("k", 0.0), ("k", -5.0), ("l0", 0.0), ("J", 0.0), ("J", -0.1),
     ("g", 0.0), ("v0", 0.0), ("beta0", 0.0), ("beta0", math.pi / 2), ("beta0", 2.0),
     ("c_l", -0.1), ("r", math.nan), ("k", math.inf), ("omega_r", math.nan),
     ("alpha_r", -math.inf), ("m", math.nan)],
)
def test_invalid_parameter_names_field_and_range(field, value):
    with pytest.raises(ValueError) as exc:
        dataclasses.replace(tslip.preset("table2.1"), **{field: value})
    msg = str(exc.value)
    assert msg.startswith(f"{field} [")
    assert "(" in msg or "[" in msg  # the allowed range is stated
    assert "\n" not in msg


@pytest.mark.parametrize(
    ("ctrl", "kw", "field"),
    [(tslip.GlobalPD, {"Kp": -1.0}, "Kp"), (tslip.GlobalPD, {"Kd": math.nan}, "Kd"),
     (tslip.LocalVelocity, {"Kd": -0.1}, "Kd"), (tslip.ConstantTorque, {"c_h": -1.0}, "c_h"),
     (tslip.ConstantTorque, {"tau_c": math.inf}, "tau_c")],
)
def test_invalid_controller_gain(ctrl, kw, field):
    with pytest.raises(ValueError, match=rf"{ctrl.__name__}\.{field}"):
        ctrl(**kw)


def test_unknown_preset_and_controller_and_field():
    with pytest.raises(ValueError, match="preset must be one of"):
        tslip.preset("nope")
    with pytest.raises(ValueError, match="controller must be one of"):
        Params.from_dict({"controller": "bogus"})
    with pytest.raises(ValueError, match="unknown parameter 'foo'"):
        Params.from_dict({"foo": 1})
    with pytest.raises(ValueError, match="controller must be one of"):
        Params(controller="passive")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="leg_reset"):
        Params(leg_reset="sideways")  # type: ignore[arg-type]


def test_non_numeric_value():
    with pytest.raises(ValueError, match=r"^k \[MgL\^-1\] must be a number"):
        Params.from_dict({"k": "stiff"})


def test_normalised_retraction_rate_eq_2_18():
    p = tslip.preset("table2.1")
    assert p.omega_r_bar == pytest.approx(p.omega_r * p.l0 / p.v0)
    q = p.with_omega_r_bar(1.0)  # zero foot speed over ground
    assert q.omega_r == pytest.approx(p.v0 / p.l0)
    assert Params.from_dict({"omega_r_bar": 0.5}, base=p).omega_r == pytest.approx(2.5)


def test_from_dict_roundtrip_and_toml(tmp_path):
    p = dataclasses.replace(tslip.preset("table6.1"), r=0.4)
    assert Params.from_dict(p.to_dict()) == p
    f = tmp_path / "p.toml"
    f.write_text('preset = "table2.1"\nk = 30\n[controller]\ntype = "local_velocity"\n'
                 'Kd = 0.7\nalphad_ref = 4.0\n')
    q = Params.from_toml(f)
    assert q.k == 30.0 and q.controller == tslip.LocalVelocity(Kd=0.7, alphad_ref=4.0)
    with pytest.raises(ValueError, match="does not exist"):
        Params.from_toml(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("k = = 3")
    with pytest.raises(ValueError, match="not valid TOML"):
        Params.from_toml(bad)


def test_retraction_clock_field(tmp_path):
    from tslip.model.units import Scaling, from_si, to_si

    assert Params().retraction == "liftoff"  # the thesis's clock (eq. 2.17)
    p = Params(retraction="apex", k=30.0)
    assert p.to_dict()["retraction"] == "apex"
    assert Params.from_dict(p.to_dict()) == p
    assert Params.from_dict({"retraction": "apex"}, base=tslip.preset("slip")).retraction == "apex"
    f = tmp_path / "p.toml"
    f.write_text('[params]\npreset = "table6.1"\nretraction = "apex"\n')
    assert Params.from_toml(f) == dataclasses.replace(tslip.preset("table6.1"),
                                                      retraction="apex")
    s = Scaling(M=80.0, g=9.81, L=1.0)
    si = to_si(p, s)
    assert si["retraction"] == "apex" and from_si(si, s).retraction == "apex"
    for bad in ("Apex", "touchdown", 0, None):
        with pytest.raises(ValueError) as exc:
            Params(retraction=bad)  # type: ignore[arg-type]
        assert str(exc.value) == f"retraction must be 'liftoff' or 'apex', got {bad!r}"


def test_touchdown_state_validation_and_section():
    s = tslip.TouchdownState.from_velocity(v=2.0, delta=-0.1, beta=1.0, phi=0.2, phid=0.3)
    assert s.v == pytest.approx(2.0) and s.delta == pytest.approx(-0.1)
    assert tslip.TouchdownState.from_section(s.section()) == s
    with pytest.raises(ValueError, match="TouchdownState.xd must be finite"):
        tslip.TouchdownState(1.0, 0.0, math.nan, 0.0, 0.0)


def test_touchdown_state_fields_are_plain_floats():
    # the fields are checked one by one, and a finite float is kept as it is: any other
    # number becomes a Python float, as check_number returns it; bools are refused
    s = tslip.TouchdownState(np.float64(1.0), 0, np.float32(5.5), -0.3, np.int64(2), x=3)
    assert [type(getattr(s, n)) for n in ("beta", "phi", "xd", "yd", "phid", "x", "h")] \
        == [float] * 7
    assert (s.beta, s.phi, s.xd, s.phid, s.x) == (1.0, 0.0, 5.5, 2.0, 3.0)
    assert s.as_array().tolist() == [1.0, 0.0, 5.5, -0.3, 2.0, 3.0, 0.0]
    with pytest.raises(ValueError, match="TouchdownState.phid must be a number"):
        tslip.TouchdownState(1.0, 0.0, 5.0, -0.3, True)
