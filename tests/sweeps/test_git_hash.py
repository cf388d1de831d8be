"""The commit recorded with each study is asked of git at most once a minute."""

import subprocess

from tslip import _io


def test_git_is_asked_once_a_minute(monkeypatch):
    calls = []
    real = subprocess.run

    def counted(*args, **kwargs):
        calls.append(args[0])
        return real(*args, **kwargs)

    clock = [1000.0]
    monkeypatch.setattr(subprocess, "run", counted)
    monkeypatch.setattr(_io, "_git_cache", [])
    monkeypatch.setattr("time.monotonic", lambda: clock[0])
    first = _io.git_hash()
    assert [_io.git_hash() for _ in range(17)] == [first] * 17
    assert len(calls) == 1 and calls[0][:2] == ["git", "rev-parse"]
    clock[0] += _io.GIT_HASH_SECONDS + 1  # a minute later: asked again
    assert _io.git_hash() == first
    assert len(calls) == 2
    # the answer is the checkout's commit (tests run from a checkout)
    head = real(["git", "rev-parse", "HEAD"], cwd=_io.Path(_io.__file__).parent,
                capture_output=True, text=True).stdout.strip()
    assert first == (head or None)
