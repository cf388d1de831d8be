"""The page's logic in this process: first-run message, newer moves win, errors shown."""

from __future__ import annotations

import dataclasses
import threading
import time

import pytest
from bokeh.document import Document

import tslip
from tslip.explore import app, compute, workers
from tslip.explore.state import parse_query


class Page:
    """An :class:`app.Explorer` on a document whose next-tick callbacks run when asked."""

    def __init__(self, query: dict[str, str]) -> None:
        self.doc = Document()
        self.calls: list = []
        self.shown: list[str] = []  # the multipliers' text after each callback
        self.doc.add_next_tick_callback = self.calls.append  # type: ignore[method-assign]
        state, errors = parse_query(query)
        self.ex = app.Explorer(self.doc, state, errors)

    def until(self, done, timeout: float = 60.0, newest_first: bool = False) -> None:
        t0 = time.monotonic()
        while not done():
            while self.calls:
                self.calls.pop(-1 if newest_first else 0)()
                self.shown.append(self.ex.mult_text.text)
            if time.monotonic() - t0 > timeout:
                raise AssertionError("timed out")
            time.sleep(0.01)


@pytest.fixture
def held(monkeypatch):
    """``compute.solve`` waits for ``release``; limits run here, not in a process."""
    release = threading.Event()
    solve = compute.solve

    def slow(params):
        release.wait(30)
        return solve(params)

    monkeypatch.setattr(compute, "solve", slow)
    monkeypatch.setattr(workers, "limit", compute.limit)
    return release


def test_a_cold_kernel_cache_shows_the_compile_message_until_the_first_gait(monkeypatch, held):
    monkeypatch.setattr(app, "kernels_cold", lambda: True)
    monkeypatch.setattr(app, "_WARM", threading.Event())
    page = Page({"preset": "table6.1"})
    page.until(lambda: page.ex.status.text == app.COMPILING)
    held.set()
    page.until(lambda: page.ex.status.text.startswith("gait found"))
    assert "largest non-trivial" in page.ex.mult_text.text
    page.ex.close()


def test_a_newer_move_replaces_an_older_one(held):
    page = Page({"preset": "table6.1"})
    page.ex.sliders["k"].value = 9.0  # while the first request is still held
    held.set()
    want = tslip.floquet(tslip.find_gait(
        dataclasses.replace(tslip.preset("table6.1"), k=9.0))).max_nontrivial
    page.until(lambda: f"{want:.4f}" in page.ex.mult_text.text)
    page.until(lambda: page.ex.limit_text.text.startswith("robustness limits (25"))
    page.until(lambda: len(page.ex.frames_src.data["t"]) > 10)  # the runner's animation
    assert min(page.ex.ground_src.data["y"]) == max(page.ex.ground_src.data["y"]) == 0.0  # push
    old = tslip.floquet(tslip.find_gait(tslip.preset("table6.1"))).max_nontrivial
    assert not any(f"{old:.4f}" in text for text in page.shown)  # the older gait never drawn
    page.ex.close()


def test_an_exception_in_the_work_is_shown_and_the_page_goes_on(monkeypatch):
    monkeypatch.setattr(workers, "limit", compute.limit)
    solve = compute.solve
    calls = []

    def failing_once(params):
        calls.append(params)
        if len(calls) == 1:
            raise RuntimeError("kernel exploded")
        return solve(params)

    monkeypatch.setattr(compute, "solve", failing_once)
    page = Page({"preset": "table6.1"})
    page.until(lambda: "kernel exploded" in page.ex.error.text)
    page.ex.sliders["k"].value = 9.0
    page.until(lambda: page.ex.status.text.startswith("gait found"))
    assert page.ex.error.text == ""
    page.ex.close()


def test_the_limits_are_drawn_whatever_order_the_posted_callbacks_run_in(monkeypatch):
    """Callbacks posted before a page's session exists run in any order (Bokeh keeps them in
    a set): here all the work posted while nothing is drawn runs newest first, and the
    limits still end up shown, not hidden by their gait's "updating"."""
    monkeypatch.setattr(workers, "limit", compute.limit)
    page = Page({"preset": "table6.1"})
    deadline = time.monotonic() + 60
    while not page.calls and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(3.0)  # the limits and the runner would be posted by now (0.1 s of work)
    page.until(lambda: page.ex.limit_text.text.startswith("robustness limits (25"),
               timeout=30, newest_first=True)
    page.until(lambda: len(page.ex.frames_src.data["t"]) > 10)
    page.ex.close()


def test_a_negative_fraction_sent_by_the_page_is_refused_and_the_runner_kept(monkeypatch):
    """A slider cannot go below 0; a crafted message can. Refused in plain words (no class
    name), the runner's disturbance is not turned around; 0 is accepted."""
    monkeypatch.setattr(workers, "limit", compute.limit)
    page = Page({"preset": "table6.1", "disturbance": "step_down"})
    page.until(lambda: "at the 2nd touch-down" in page.ex.strip_text.text)
    runner = page.ex.strip_text.text
    page.ex.fraction.value = -0.5
    page.until(lambda: page.ex.error.text != "")
    assert page.ex.error.text == "fraction [-] must be in [0, 2], got -0.5"
    time.sleep(0.5)
    page.until(lambda: not page.calls)
    assert page.ex.strip_text.text == runner  # no run with the step turned into a step up
    page.ex.fraction.value = 0.0
    page.until(lambda: page.ex.strip_text.text != runner)
    assert float(page.ex.strip_text.text.split()[2]) == 0.0  # "step_down of 0 at ..."
    assert page.ex.error.text == ""
    page.ex.close()


def test_a_binding_retraction_stop_is_a_plain_message_and_one_log_line(caplog):
    """alpha_stop = 1.0 rad binds at the Table 6.1 gait (Section 7.5): the search refuses
    it, and the page says why in the error line, without the exception's class name."""
    caplog.set_level("INFO", logger="tslip.explore")
    page = Page({"preset": "table6.1", "alpha_stop": "1.0"})
    page.until(lambda: page.ex.error.text != "")
    assert page.ex.error.text.startswith("no gait: alpha_stop binds at the periodic gait")
    assert "Error" not in page.ex.error.text
    assert page.ex.status.text == page.ex.error.text and page.ex.mult_text.text == "no gait"
    records = [r for r in caplog.records if "alpha_stop binds" in r.getMessage()]
    assert len(records) == 1 and records[0].exc_info is None
    page.ex.close()
