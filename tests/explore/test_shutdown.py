"""No process of the explorer outlives its server, whatever signal ends the server."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import psutil
import pytest

from .conftest import START_TIMEOUT, free_port

#: The issue's bound: seconds after the signal by which every process of the server is gone.
GONE_WITHIN = 3.0


def _sigint_default() -> None:
    """SIGINT as a terminal has it, for a child: a shell starts background jobs with SIGINT
    ignored, and a child inherits that (Python then installs no handler)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _alive(procs: list[psutil.Process]) -> list[psutil.Process]:
    out = []
    for p in procs:
        try:
            if p.status() != psutil.STATUS_ZOMBIE:  # a zombie has ended (its parent reaps it)
                out.append(p)
        except psutil.NoSuchProcess:
            pass
    return out


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT, signal.SIGKILL],
                         ids=["SIGTERM", "SIGINT", "SIGKILL"])
def test_the_worker_and_every_other_process_end_with_the_server(tmp_path, sig):
    """The server alone gets the signal (as from kill or a service manager, not a terminal's
    Ctrl-C, which reaches the whole group); its processes (the robustness worker, the
    resource tracker) are gone 3 s later."""
    log = tmp_path / "server.log"
    procs: list[psutil.Process] = []
    with log.open("w") as out:
        proc = subprocess.Popen(
            [sys.executable, "-m", "tslip", "explore", "--port", str(free_port()), "--no-open"],
            stdout=out, stderr=subprocess.STDOUT, env=os.environ.copy(),
            preexec_fn=_sigint_default)
    try:
        deadline = time.monotonic() + START_TIMEOUT
        while "worker process" not in log.read_text():  # started: it watches its server
            assert proc.poll() is None and time.monotonic() < deadline, log.read_text()
            time.sleep(0.2)
        worker = int(log.read_text().split("worker process ")[1].split()[0])
        procs += psutil.Process(proc.pid).children(recursive=True)
        assert worker in [p.pid for p in procs]
        procs.append(psutil.Process(proc.pid))
        os.kill(proc.pid, sig)
        deadline = time.monotonic() + GONE_WITHIN
        while _alive(procs) and time.monotonic() < deadline:
            proc.poll()  # reaps the server
            time.sleep(0.05)
        left = [(p.pid, p.name()) for p in _alive(procs)]
    finally:
        for p in _alive(procs):
            p.kill()
        if proc.poll() is None:
            proc.kill()
        proc.wait()
    assert left == [], log.read_text()
    if sig != signal.SIGKILL:
        assert "tslip explore: stopped" in log.read_text()
        assert "Traceback" not in log.read_text()
