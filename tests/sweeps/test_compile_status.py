"""While the first run compiles, a terminal shows one updating line with the seconds spent,
renewed at least every 10 s; a pipe or a file gets nothing beyond the announcement and the
families' lines (issue 40: 74 s passed in silence)."""

import io
import re
import threading
import time
from types import SimpleNamespace

import pytest
from rich.console import Console

from tslip import _kernel_cache
from tslip.sweeps import _warmup

FAMILY = "a kernel family"


@pytest.fixture
def compiling(monkeypatch):
    """One family missing until ``done`` is set; a clock that advances 3 s a look."""
    done = threading.Event()
    clock = {"t": 0.0}

    def perf_counter():
        clock["t"] += 3.0
        return clock["t"]

    monkeypatch.setitem(_kernel_cache.FAMILIES, FAMILY, ("simulation", ()))
    monkeypatch.setattr(_warmup, "_missing", lambda packages: ({}, "", [FAMILY]))
    monkeypatch.setattr(_kernel_cache, "missing_families",
                        lambda dirs, digest, families=None: [] if done.is_set() else [FAMILY])
    monkeypatch.setattr(_warmup, "time", SimpleNamespace(perf_counter=perf_counter))
    monkeypatch.setattr(_warmup, "POLL_SECONDS", 0.01)
    return done


def _wait_for(predicate, limit=30.0):
    end = time.monotonic() + limit
    while not predicate():
        assert time.monotonic() < end, "the compile watcher never got there"
        time.sleep(0.01)


def test_a_terminal_shows_the_seconds_spent_compiling_on_one_line(compiling):
    buf = io.StringIO()
    console = Console(file=buf, force_terminal=True, width=120)
    updates = []  # the line's renewals (the terminal draws them at its own rate)
    real = console.status

    def status(text):
        st = real(text)
        update = st.update
        st.update = lambda t: (updates.append(t), update(t))
        return st

    console.status = status
    said = []
    with _warmup.announce(said.append, terminal=console):
        _wait_for(lambda: len(set(re.findall(r"family left, (\d+) s", buf.getvalue()))) >= 3)
        compiling.set()
        _wait_for(lambda: any("compiled" in s for s in said))
    seconds = [int(re.search(r"1 of 1 family left, (\d+) s", u)[1]) for u in updates]
    assert len(seconds) >= 3 and seconds == sorted(seconds)
    assert max(b - a for a, b in zip(seconds, seconds[1:])) <= 10  # at least every 10 s
    drawn = [int(s) for s in re.findall(r"1 of 1 family left, (\d+) s", buf.getvalue())]
    assert len(set(drawn)) >= 3 and set(drawn) <= set(seconds) | {0}
    assert len(said) == 2 and said[0].startswith("first run: compiling 1 kernel family not")
    # one line, redrawn in place: never a newline between two of its drawings
    text = buf.getvalue()
    first, last = text.index("family left"), text.rindex("family left")
    assert "\n" not in text[first:last]


def test_a_pipe_gets_nothing_extra(compiling):
    buf = io.StringIO()
    console = Console(file=buf, force_terminal=False, width=120)
    said = []
    with _warmup.announce(said.append, terminal=console):
        time.sleep(0.2)  # many looks at the (fake) cache and the clock
        compiling.set()
        _wait_for(lambda: any("compiled" in s for s in said))
    assert buf.getvalue() == ""
    assert len(said) == 2 and "compiled a kernel family (1/1" in said[1]
