"""The explorer in a real browser (Playwright driving the system Chromium).

The page's widgets live in Bokeh's shadow DOM; the tests read them through
Bokeh's document in the page (``Bokeh.documents[0]``), the state the browser
shows, and change a control by setting its model's value there, which the page
sends to the server exactly as a dragged slider's value. The compute button
is clicked with the mouse.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from urllib.parse import parse_qs, urlparse

import pytest

import tslip

from .conftest import get

#: JavaScript: the model named ``name`` in the page's Bokeh document, or null.
_MODEL = "(name) => { const d = window.Bokeh && Bokeh.documents[0];" \
         " return d ? d.get_model_by_name(name) : null; }"
TEXT = f"(name) => {{ const m = ({_MODEL})(name); return m ? m.text : null; }}"
#: Where the docs page finds its screenshot (copied to the site's root; never committed).
SHOT = Path(__file__).parents[2] / "docs" / "_generated" / "extra" / "explore.png"
TIMEOUT = 60_000  # ms: the first gait of a page on a loaded machine


@pytest.fixture
def page(browser):
    ctx = browser.new_context(viewport={"width": 1300, "height": 1500})
    pg = ctx.new_page()
    yield pg
    ctx.close()


def open_page(page, server, query: str = "") -> None:
    page.goto(f"{server.url}/{query}")
    page.wait_for_function(f"() => ({TEXT})('multipliers')", timeout=TIMEOUT)


def text(page, name: str) -> str:
    return page.evaluate(TEXT, name)


def wait_text(page, name: str, contains: str) -> str:
    page.wait_for_function(f"([n, s]) => (({TEXT})(n) || '').includes(s)", arg=[name, contains],
                           timeout=TIMEOUT)
    return text(page, name)


def set_value(page, name: str, value: object) -> None:
    page.evaluate(f"([n, v]) => {{ ({_MODEL})(n).value = v; }}", [name, value])


def expected_largest(params: tslip.Params) -> str:
    """The page's text of the largest non-trivial multiplier, computed here."""
    return f"largest non-trivial {tslip.floquet(tslip.find_gait(params)).max_nontrivial:.4f}"


def test_moving_a_slider_redraws_the_gait_and_the_multipliers(page, server):
    p = tslip.preset("table6.1")
    open_page(page, server, "?preset=table6.1")
    assert expected_largest(p) in text(page, "multipliers")
    gait_x = page.evaluate(f"() => Array.from(({_MODEL})('gait_source').data.x)")
    set_value(page, "k", 9.0)
    moved = expected_largest(dataclasses.replace(p, k=9.0))
    assert moved != expected_largest(p)
    wait_text(page, "multipliers", moved)
    new_x = page.evaluate(f"() => Array.from(({_MODEL})('gait_source').data.x)")
    assert new_x != gait_x and len(new_x) > 10
    # the address bar holds the new state: the permalink
    page.wait_for_function("() => location.search.includes('k=9.0')", timeout=TIMEOUT)
    assert parse_qs(urlparse(page.url).query)["k"] == ["9.0"]
    # the robustness limits follow, then the runner after the disturbance
    limit = tslip.robustness(tslip.find_gait(dataclasses.replace(p, k=9.0)), "step_down")
    wait_text(page, "limits", f"step_down {limit:.4g} [L]")
    wait_text(page, "runner", "at the 2nd touch-down")
    check_the_runner_plays(page)
    SHOT.parent.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(SHOT), full_page=True)


def test_the_retraction_stop_reaches_the_limits_and_the_permalink(page, server):
    """Section 7.5's stop, switched on in the page at alpha_TD + 0.12 rad: the step-down
    limit shown is the one computed here with that stop (not the free gait's), and the
    address bar holds the angle; switched off, the angle leaves the address."""
    g = tslip.find_gait(tslip.preset("table6.1"))
    stop = round(g.state.beta + g.state.phi + 0.12, 2)
    stopped = tslip.robustness(dataclasses.replace(g, params=dataclasses.replace(
        g.params, alpha_stop=stop)), "step_down")
    assert abs(stopped - tslip.robustness(g, "step_down")) > 0.01  # the stop matters here
    open_page(page, server, "?preset=table6.1")
    set_value(page, "alpha_stop", stop)
    set_value(page, "stop", "on")
    wait_text(page, "limits", f"step_down {stopped:.4g} [L]")
    page.wait_for_function("() => location.search.includes('alpha_stop=')", timeout=TIMEOUT)
    assert parse_qs(urlparse(page.url).query)["alpha_stop"] == [repr(stop)]
    set_value(page, "stop", "off")
    page.wait_for_function("() => !location.search.includes('alpha_stop=')", timeout=TIMEOUT)


def check_the_runner_plays(page) -> None:
    """The runner's animation plays in the page, pauses, and shows the frame asked for."""
    pose = f"() => Array.from(({_MODEL})('runner_pose').data.x)"
    page.wait_for_function(f"() => ({pose})().length === 3", timeout=TIMEOUT)
    first = page.evaluate(pose)
    page.wait_for_function(f"(a) => ({pose})()[1] !== a[1]", arg=first, timeout=TIMEOUT)
    page.get_by_role("button", name="play / pause").click()
    page.wait_for_function(f"() => !({_MODEL})('runner_play').active", timeout=TIMEOUT)
    paused = page.evaluate(pose)
    page.wait_for_timeout(300)  # 9 frames at 30 a second
    assert page.evaluate(pose) == paused
    set_value(page, "runner_frame", 5)
    frame = page.evaluate(f"() => {{ const d = ({_MODEL})('runner_frames').data;"
                          " return [d.hip_x[5], d.com_x[5], d.foot_x[5]]; }")
    assert page.evaluate(pose) == pytest.approx(frame, abs=0)
    n = page.evaluate(f"() => ({_MODEL})('runner_frames').get_length()")
    assert n > 60  # six strides at 30 frames a second, a quarter of real time
    first, later = drawn_frame(page, 5), drawn_frame(page, n // 2)
    for i, d in ((5, first), (n // 2, later)):
        # one frame's polylines: the spring from hip to foot has 17 points (hip, the 2 x 7
        # + 1 points of its seven coils, foot: tslip animate's drawing), the trunk axis and
        # the force arrow two; the run's n frames would have n times as many
        assert len(d["leg"]["x"]) == len(d["leg"]["y"]) == 2 * 7 + 3, i
        assert len(d["axis"]["x"]) == len(d["grf"]["x"]) == 2, i
        assert (d["leg"]["x"][0], d["leg"]["x"][-1]) == (d["hip_x"], d["foot_x"]), i
        assert (d["leg"]["y"][0], d["leg"]["y"][-1]) == (d["hip_y"], d["foot_y"]), i
    assert first["leg"] != later["leg"] and first["axis"] != later["axis"]


def drawn_frame(page, i: int) -> dict:
    """What the runner's plot draws at frame ``i`` (its data sources), and the frame's joints."""
    set_value(page, "runner_frame", i)
    return page.evaluate(f"""(i) => {{
        const src = (name) => {{ const d = ({_MODEL})(name).data;
                                 return {{x: Array.from(d.x), y: Array.from(d.y)}}; }};
        const f = ({_MODEL})('runner_frames').data;
        return {{leg: src('runner_leg'), axis: src('runner_axis'), grf: src('runner_grf'),
                 hip_x: f.hip_x[i], hip_y: f.hip_y[i], foot_x: f.foot_x[i],
                 foot_y: f.foot_y[i]}}; }}""", i)


@pytest.mark.parametrize("bad", ["-1", "nan", "abc", "1e999"])
def test_a_bad_url_value_shows_an_error_and_the_server_keeps_serving(page, server, bad):
    open_page(page, server, f"?preset=table6.1&k={bad}")
    assert "k" in text(page, "error") and bad.replace("1e999", "inf") in text(page, "error")
    # the refused value kept the preset's, whose gait the page shows
    assert expected_largest(tslip.preset("table6.1")) in text(page, "multipliers")
    assert server.alive() and get(server.url + "/favicon.ico")[0] == 200


def test_a_bad_value_sent_by_a_control_shows_an_error_and_the_page_goes_on(page, server):
    open_page(page, server, "?preset=table6.1")
    set_value(page, "k", -5.0)  # a slider cannot go there; a crafted message can
    assert "(0, inf)" in wait_text(page, "error", "k [MgL^-1]")
    set_value(page, "k", 9.0)
    wait_text(page, "multipliers", expected_largest(
        dataclasses.replace(tslip.preset("table6.1"), k=9.0)))
    assert text(page, "error") == ""
    assert server.alive()


def test_a_map_cell_loads_its_gait(page, server):
    open_page(page, server, "?preset=table6.1")
    set_value(page, "map_points", 3)
    page.get_by_role("button", name="compute map").click()
    wait_text(page, "map_status", "click a cell")
    data = page.evaluate(f"() => {{ const d = ({_MODEL})('map_source').data;"
                         " return {x: Array.from(d.x), y: Array.from(d.y),"
                         " lam: Array.from(d.lam)}; }")
    assert len(data["x"]) == 9
    # a cell with a gait, other than the current one
    i = next(j for j in range(9) if data["lam"][j] == data["lam"][j]
             and (data["x"][j], data["y"][j]) != (0.3, 8.0))
    r, k = data["x"][i], data["y"][i]
    want = dataclasses.replace(tslip.preset("table6.1"), r=r, k=k)
    assert data["lam"][i] == pytest.approx(tslip.floquet(tslip.find_gait(want)).max_nontrivial,
                                           abs=1e-6)
    page.evaluate(f"(i) => {{ ({_MODEL})('map_source').selected.indices = [i]; }}", i)
    wait_text(page, "multipliers", expected_largest(want))
    assert page.evaluate(f"() => ({_MODEL})('k').value") == pytest.approx(k)
