"""Bad inputs through the Python API (issue 11): each a one-line ``ValueError`` naming the field.

Plus the positive side of the same checks: NumPy scalars are numbers, and an
integer-valued float is a number where a float is meant.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import tslip
from tslip import _checks
from tslip.biped import BipedParams
from tslip.experiment.synth import Camera, RenderOptions
from tslip.model.controllers import controller_from_dict
from tslip.model.parameters import Params
from tslip.simulation import Disturbance, IntegratorOptions
from tslip.sweeps import StudySpec
from tslip.sweeps.spec import Axis

P = tslip.preset("table2.1")
Q = [1.05, 0.0, 5.0, -0.3, 0.0]
S = tslip.TouchdownState(*Q)


def _spec(**kw):
    data = {"axis": [{"param": "r", "values": [0.1, 0.2]}]}
    data.update(kw)
    return StudySpec.from_dict(data)


def _design(**kw):
    from tslip.biped.design import stable_gait_search

    return stable_gait_search(BipedParams(), np.zeros(5), **kw)


def _params_toml(tmp_path, text):
    path = tmp_path / "p.toml"
    path.write_text(text)
    return Params.from_toml(path)


#: (id, call, text the message must contain)
CASES = [
    # Params fields: bool is not a number, text is not a number, ranges
    ("k bool", lambda: Params(k=True), "k [MgL^-1] must be a number"),
    ("k numpy bool", lambda: Params(k=np.bool_(True)), "k [MgL^-1] must be a number"),
    ("k str", lambda: Params(k="30"), "k [MgL^-1] must be a number"),
    ("k None", lambda: Params(k=None), "k [MgL^-1] must be a number"),
    ("k complex", lambda: Params(k=1j), "k [MgL^-1] must be a number"),
    ("k list", lambda: Params(k=[30.0]), "k [MgL^-1] must be a number"),
    ("k nan", lambda: Params(k=math.nan), "k [MgL^-1] must be finite"),
    ("k inf", lambda: Params(k=math.inf), "k [MgL^-1] must be finite"),
    ("k numpy nan", lambda: Params(k=np.float32("nan")), "k [MgL^-1] must be finite"),
    ("k zero", lambda: Params(k=0.0), "k [MgL^-1] must be a number in (0, inf)"),
    ("k negative int64", lambda: Params(k=np.int64(-3)), "k [MgL^-1] must be a number in (0"),
    ("m zero", lambda: Params(m=0), "m [M] must be a number in (0, inf)"),
    ("J negative", lambda: Params(J=-0.1), "J [ML^2] must be"),
    ("l0 zero", lambda: Params(l0=0.0), "l0 [L] must be"),
    ("g negative", lambda: Params(g=-1.0), "g [g] must be"),
    ("v0 zero", lambda: Params(v0=0.0), "v0 [g^1/2 L^1/2] must be"),
    ("beta0 too big", lambda: Params(beta0=2.0), "beta0 [rad] must be a number in (0, 1.5708)"),
    ("beta0 zero", lambda: Params(beta0=0.0), "beta0 [rad] must be"),
    ("c_l negative", lambda: Params(c_l=-0.1), "c_l [Mg^1/2 L^-1/2] must be"),
    ("r nan", lambda: Params(r=math.nan), "r [L] must be finite"),
    ("omega_r inf", lambda: Params(omega_r=-math.inf), "omega_r [rad g^1/2 L^-1/2] must be"),
    ("alpha_r str", lambda: Params(alpha_r="1"), "alpha_r [rad] must be a number"),
    ("leg_reset", lambda: Params(leg_reset="sideways"), "leg_reset must be 'local' or 'global'"),
    ("retraction", lambda: Params(retraction="apogee"),
     "retraction must be 'liftoff' or 'apex', got 'apogee'"),
    ("retraction None", lambda: Params(retraction=None), "retraction must be 'liftoff' or 'apex'"),
    ("controller", lambda: Params(controller="passive"), "controller must be one of"),
    ("omega_r_bar nan", lambda: P.with_omega_r_bar(math.nan), "omega_r_bar [-] must be finite"),
    # Params.from_dict: the TOML / JSON path
    ("from_dict bool", lambda: Params.from_dict({"k": True}), "k [MgL^-1] must be a number"),
    ("from_dict str", lambda: Params.from_dict({"k": "30"}), "k [MgL^-1] must be a number"),
    ("from_dict unknown", lambda: Params.from_dict({"kk": 3}), "unknown parameter 'kk'"),
    ("from_dict preset vs base", lambda: Params.from_dict({"preset": "table6.1"}, base=P),
     "preset 'table6.1' conflicts with the base parameters"),
    ("from_dict preset int", lambda: Params.from_dict({"preset": 5}), "preset must be one of"),
    ("from_dict preset unknown", lambda: Params.from_dict({"preset": "x"}),
     "preset must be one of"),
    ("from_dict omega both", lambda: Params.from_dict({"omega_r": 1.0, "omega_r_bar": 0.2}),
     "give omega_r or omega_r_bar"),
    ("from_dict omega_r_bar bool", lambda: Params.from_dict({"omega_r_bar": True}),
     "omega_r_bar [-] must be a number"),
    ("from_dict omega_r_bar str", lambda: Params.from_dict({"omega_r_bar": "0.2"}),
     "omega_r_bar [-] must be a number"),
    ("from_dict leg_reset int", lambda: Params.from_dict({"leg_reset": 1}),
     "leg_reset must be 'local' or 'global'"),
    ("from_dict retraction int", lambda: Params.from_dict({"retraction": 1}),
     "retraction must be 'liftoff' or 'apex', got 1"),
    ("from_dict leg_reset bool", lambda: Params.from_dict({"leg_reset": True}),
     "leg_reset must be 'local' or 'global'"),
    ("controller gain bool", lambda: controller_from_dict({"type": "global_pd", "Kp": True}),
     "controller.Kp must be a number"),
    ("controller gain str", lambda: controller_from_dict({"type": "global_pd", "Kp": "5"}),
     "controller.Kp must be a number"),
    ("controller gain nan", lambda: controller_from_dict({"type": "global_pd", "Kp": math.nan}),
     "must be finite"),
    ("controller type", lambda: controller_from_dict({"type": "pid"}),
     "controller must be one of"),
    ("controller field", lambda: controller_from_dict({"type": "passive", "Kd": 1.0}),
     "has no field 'Kd'"),
    # TouchdownState and the section map (issue: NaN gave NaNs with status MAX_STEPS)
    ("state nan", lambda: tslip.TouchdownState(math.nan, 0, 5, -0.3, 0),
     "TouchdownState.beta must be finite"),
    ("state inf", lambda: tslip.TouchdownState(1.0, 0, math.inf, -0.3, 0),
     "TouchdownState.xd must be finite"),
    ("state bool", lambda: tslip.TouchdownState(1.0, True, 5, -0.3, 0),
     "TouchdownState.phi must be a number"),
    ("state str", lambda: tslip.TouchdownState(1.0, 0, "5", -0.3, 0),
     "TouchdownState.xd must be a number"),
    ("state h nan", lambda: tslip.TouchdownState(*Q, h=math.nan), "TouchdownState.h must be"),
    ("from_section shape", lambda: tslip.TouchdownState.from_section(np.zeros(4)),
     "section vector must have shape (5,)"),
    ("step_map nan", lambda: tslip.step_map(P, [math.nan, 0, 5, -0.3, 0]),
     "q (beta, phi, xd, yd, phid) must be finite"),
    ("step_map inf", lambda: tslip.step_map(P, [1.05, 0, math.inf, -0.3, 0]),
     "q (beta, phi, xd, yd, phid) must be finite"),
    ("step_map shape", lambda: tslip.step_map(P, [1.05, 0, 5]), "must have 5 entries"),
    ("step_map h nan", lambda: tslip.step_map(P, Q, h=math.nan), "h [L] must be finite"),
    ("step_jacobian nan", lambda: tslip.step_jacobian(P, [1.05, math.nan, 5, -0.3, 0]),
     "q (beta, phi, xd, yd, phid) must be finite"),
    ("step nan", lambda: tslip.step(P, [1.05, 0, math.nan, -0.3, 0]),
     "TouchdownState.xd must be finite"),
    ("step params", lambda: tslip.step({"k": 30}, S), "params must be a tslip.Params"),
    ("step shape", lambda: tslip.step(P, np.zeros(6)), "state must be a TouchdownState"),
    # simulate, run_batch: types and sizes (issue: out-of-memory tracebacks)
    ("simulate n_steps 0", lambda: tslip.simulate(P, S, 0), "n_steps must be an integer in [1"),
    ("simulate n_steps float", lambda: tslip.simulate(P, S, 2.7), "n_steps must be an integer"),
    ("simulate n_steps whole float", lambda: tslip.simulate(P, S, 2.0),
     "n_steps must be an integer"),
    ("simulate n_steps bool", lambda: tslip.simulate(P, S, True), "n_steps must be an integer"),
    ("simulate n_steps huge", lambda: tslip.simulate(P, S, 10**9),
     "n_steps 1000000000 needs about"),
    ("simulate dt tiny", lambda: tslip.simulate(P, S, 20, dt=1e-12), "n_steps 20 needs about"),
    ("simulate dt 0", lambda: tslip.simulate(P, S, 2, dt=0.0), "dt [g^-1/2 L^1/2] must be"),
    ("simulate dt nan", lambda: tslip.simulate(P, S, 2, dt=math.nan), "dt [g^-1/2 L^1/2] must"),
    ("simulate dt str", lambda: tslip.simulate(P, S, 2, dt="0.01"), "dt [g^-1/2 L^1/2] must"),
    ("simulate state nan", lambda: tslip.simulate(P, [1.05, 0, 5, math.nan, 0], 2),
     "TouchdownState.yd must be finite"),
    ("run_batch huge", lambda: tslip.run_batch(P, np.tile(Q, (1000, 1)), 10**9),
     "n_steps 1000000000 needs about"),
    ("run_batch n_steps float", lambda: tslip.run_batch(P, np.array([Q]), 1.5),
     "n_steps must be an integer"),
    ("run_batch nan", lambda: tslip.run_batch(P, np.array([[math.nan, 0, 5, -0.3, 0]]), 2),
     "states must be finite"),
    ("step_batch shape", lambda: tslip.step_batch(P, np.zeros((2, 4))),
     "states must have shape (n, 5) or (n, 7)"),
    ("disturbance at_step", lambda: Disturbance(at_step=-1), "Disturbance.at_step must be"),
    ("disturbance at_step float", lambda: Disturbance(at_step=1.5),
     "Disturbance.at_step must be an integer"),
    ("disturbance dh nan", lambda: Disturbance(dh=math.nan), "Disturbance.dh must be finite"),
    ("disturbance dxd str", lambda: Disturbance(dxd="0.1"), "Disturbance.dxd must be a number"),
    ("options rtol", lambda: IntegratorOptions(rtol=0.0), "IntegratorOptions.rtol must be"),
    ("options atol nan", lambda: IntegratorOptions(atol=math.nan), "IntegratorOptions.atol"),
    # study specs (issue: points = 2.7 became 2)
    ("axis points float", lambda: Axis.from_dict({"param": "r", "from": 0, "to": 1,
                                                  "points": 2.7}),
     "axis r: points must be an integer"),
    ("axis points whole float", lambda: Axis.from_dict({"param": "r", "from": 0, "to": 1,
                                                        "points": 3.0}),
     "axis r: points must be an integer"),
    ("axis points bool", lambda: Axis.from_dict({"param": "r", "from": 0, "to": 1,
                                                 "points": True}),
     "axis r: points must be an integer"),
    ("axis points huge", lambda: Axis.linspace("r", 0.0, 1.0, 10**9),
     "axis r: points 1000000000 needs about"),
    ("axis from str", lambda: Axis.from_dict({"param": "r", "from": "0", "to": 1}),
     "axis r: from must be a number"),
    ("axis to bool", lambda: Axis.from_dict({"param": "r", "from": 0, "to": True}),
     "axis r: to must be a number"),
    ("axis from nan", lambda: Axis.linspace("r", math.nan, 1.0, 3), "axis r: from must be finite"),
    ("axis values bool", lambda: Axis.from_dict({"param": "r", "values": [0.1, True]}),
     "axis r: values entry must be a number"),
    ("axis values str", lambda: Axis.from_dict({"param": "r", "values": ["0.1"]}),
     "axis r: values entry must be a number"),
    ("axis values empty", lambda: Axis.from_dict({"param": "r", "values": []}), "empty range"),
    ("axis both", lambda: Axis.from_dict({"param": "r", "values": [0.1], "from": 0}),
     "give values or from/to/points"),
    ("axis missing to", lambda: Axis.from_dict({"param": "r", "from": 0}), "missing 'to'"),
    ("axis no param", lambda: Axis.from_dict({"from": 0, "to": 1}), "needs a param name"),
    ("spec n_steps bool", lambda: _spec(n_steps=True), "n_steps must be an integer"),
    ("spec n_steps float", lambda: _spec(n_steps=2.5), "n_steps must be an integer"),
    ("spec n_steps 0", lambda: _spec(n_steps=0), "n_steps must be an integer in [1"),
    ("spec preset int", lambda: _spec(preset=3), "study preset must be a string"),
    ("spec name int", lambda: _spec(name=3), "study name must be a string"),
    ("spec preset in params", lambda: _spec(params={"preset": "table6.1"}),
     "give preset at the top level"),
    ("spec params bool", lambda: _spec(params={"k": True}), "k [MgL^-1] must be a number"),
    ("spec analyses", lambda: _spec(analyses=[1]), "analyses must be a list of names"),
    ("spec unknown", lambda: _spec(colour="red"), "unknown study key 'colour'"),
    ("spec grid huge", lambda: StudySpec.from_dict(
        {"axis": [{"param": "r", "from": 0.1, "to": 0.5, "points": 10**5},
                  {"param": "k", "from": 20, "to": 30, "points": 10**5}]}),
     "points 10000000000 needs about"),
    # the synthetic camera and rendering
    ("camera width float", lambda: Camera(width=512.5), "width [px] must be an integer"),
    ("camera width small", lambda: Camera(width=10), "width [px] must be an integer in [64"),
    ("camera height huge", lambda: Camera(height=10**6), "height [px] must be an integer in"),
    ("camera width bool", lambda: Camera(width=True), "width [px] must be an integer"),
    ("camera fps 0", lambda: Camera(fps=0), "fps [Hz] must be a number in (0"),
    ("camera fps nan", lambda: Camera(fps=math.nan), "fps [Hz] must be finite"),
    ("camera field_width", lambda: Camera(field_width=-1), "field_width [m] must be"),
    ("render noise", lambda: RenderOptions(noise=-1), "noise [grey levels] must be"),
    ("render exposure", lambda: RenderOptions(exposure=2), "exposure [-] must be"),
    ("render seed", lambda: RenderOptions(seed=1.5), "seed must be an integer"),
    # the biped and its design search (issue: popsize 0 gave a TypeError)
    ("biped bool", lambda: BipedParams(Kp_h=True), "Kp_h [MgL rad^-1] must be a number"),
    ("biped nan", lambda: BipedParams(Kp_h=math.nan), "Kp_h [MgL rad^-1] must be finite"),
    ("biped negative", lambda: BipedParams(Kp_h=-1.0), "Kp_h [MgL rad^-1] must be a number in"),
    ("biped unknown", lambda: BipedParams.from_dict({"foo": 1}), "unknown biped parameter"),
    ("biped actuated", lambda: BipedParams(actuated=1), "actuated must be True or False"),
    ("design popsize 0", lambda: _design(popsize=0), "popsize must be an integer in [2"),
    ("design popsize float", lambda: _design(popsize=8.0), "popsize must be an integer"),
    ("design max_evals", lambda: _design(max_evals=0), "max_evals must be an integer in [1"),
    ("design budget", lambda: _design(budget_s=0.0), "budget_s [s] must be a number in (0"),
    ("design sigma0", lambda: _design(sigma0=2.0), "sigma0 must be a number in (0, 1]"),
    ("design processes", lambda: _design(processes=0), "processes must be an integer in [1"),
    ("design names", lambda: _design(names=("nope",)), "names must be design variables"),
]


@pytest.mark.parametrize("call, expected", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_input_raises_one_line_value_error(call, expected):
    with pytest.raises(ValueError) as info:
        call()
    message = str(info.value)
    assert "\n" not in message
    assert expected in message, message


def test_the_api_corpus_is_large():
    assert len(CASES) >= 100
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize("text, expected", [
    ('preset = "table6.1"\n[params]\npreset = "table2.1"\n', "preset given twice"),
    ("k = 30\n[params]\nr = 0.2\n", "top-level key 'k' beside the [params] table"),
    ("params = 3\n", "params must be a table"),
    ("k = true\n", "k [MgL^-1] must be a number"),
    ("k = 3\nk = 4\n", "is not valid TOML"),
])
def test_parameter_files_are_strict(tmp_path, text, expected):
    with pytest.raises(ValueError, match=None) as info:
        _params_toml(tmp_path, text)
    assert expected in str(info.value) and str(tmp_path / "p.toml") in str(info.value)


def test_numpy_scalars_are_numbers():
    p = Params(k=np.int64(30), r=np.float32(0.25), J=np.float16(0.125))
    assert (p.k, p.r, p.J) == (30.0, 0.25, 0.125)
    assert all(type(v) is float for v in (p.k, p.r, p.J))
    assert Params.from_dict({"k": np.int64(30), "omega_r_bar": np.float32(0.5)}).k == 30.0
    s = tslip.TouchdownState(np.float32(1.0), np.int64(0), 5, -0.3, 0)
    assert type(s.beta) is float and s.phi == 0.0
    traj = tslip.simulate(P, S, np.int64(1))
    assert len(traj.steps) == 1
    assert Axis.linspace("r", np.float64(0.1), 0.2, np.int32(3)).values[-1] == pytest.approx(0.2)


def test_file_preset_with_the_same_base_is_accepted(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text('preset = "table6.1"\nk = 9\n')
    p = Params.from_toml(path, base=tslip.preset("table6.1"))
    assert p == dataclasses.replace(tslip.preset("table6.1"), k=9.0)


def test_memory_limit_follows_the_memory_available(monkeypatch):
    """The same run is refused when the machine has less memory (and the message says so)."""
    per = tslip.simulation.integrate.trajectory_bytes_per_stride(P, 0.01)
    monkeypatch.setattr(_checks, "available_memory", lambda: int(per * 100.5))
    tslip.simulate(P, S, 2)  # 2 strides fit
    with pytest.raises(ValueError, match=r"n_steps 101 needs about .*at most 100 fit"):
        tslip.simulate(P, S, 101)


def test_check_output_names_the_users_path_not_a_temp_file(tmp_path):
    blocker = tmp_path / "file.txt"
    blocker.write_text("x")
    with pytest.raises(ValueError, match="is not a directory") as info:
        _checks.check_output(blocker / "sub" / "x.csv", "--out", (".csv",))
    assert str(blocker / "sub" / "x.csv") in str(info.value)
    assert _checks.check_output(tmp_path / "new" / "x.csv", "--out", (".csv",)).name == "x.csv"
    assert not (tmp_path / "new").exists()  # checking creates nothing
