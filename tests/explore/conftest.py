"""One ``tslip explore`` server for the module's tests, in a subprocess on a free port."""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest

#: Seconds the server may take to answer (imports on a loaded machine); the issue's
#: 10 s is measured by benchmarks/bench_explore.py, not asserted here.
START_TIMEOUT = 60.0


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class Server:
    """A running explorer: its base URL, its port and its log so far."""

    def __init__(self, proc: subprocess.Popen[str], port: int, log: Path) -> None:
        self.proc, self.port, self.log = proc, port, log
        self.url = f"http://127.0.0.1:{port}"

    def alive(self) -> bool:
        return self.proc.poll() is None

    def text(self) -> str:
        return self.log.read_text()


def get(url: str, timeout: float = 30.0) -> tuple[int, bytes]:
    try:
        with urllib.request.urlopen(url, timeout=timeout) as r:  # noqa: S310 - localhost
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


@pytest.fixture(scope="session")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    port = free_port()
    log = tmp_path_factory.mktemp("explore") / "server.log"
    with log.open("w") as out:
        proc = subprocess.Popen(
            [sys.executable, "-m", "tslip", "explore", "--port", str(port), "--no-open"],
            stdout=out, stderr=subprocess.STDOUT, text=True, env=os.environ.copy())
    srv = Server(proc, port, log)
    try:
        deadline = time.monotonic() + START_TIMEOUT
        while True:
            try:
                # not "/": each GET of the page builds a document (seconds under load)
                if get(srv.url + "/favicon.ico", timeout=5)[0] == 200:
                    break
            except OSError:
                pass
            if not srv.alive() or time.monotonic() > deadline:
                pytest.fail(f"tslip explore did not serve on {srv.url}:\n{srv.text()}")
            time.sleep(0.2)
        yield srv
    finally:
        stop(proc)


def stop(proc: subprocess.Popen) -> None:
    """End a served explorer: terminate, then kill if it has not gone within 10 s."""
    proc.terminate()
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


def chromium() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if path := shutil.which(name):
            return path
    return None


@pytest.fixture(scope="session")
def browser() -> Iterator[object]:
    """Playwright's Chromium, the system's browser (no download)."""
    required = os.environ.get("TSLIP_REQUIRE_BROWSER") == "1"
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        if required:
            pytest.fail("playwright is not installed (the test extra installs it)")
        pytest.skip("playwright is not installed")
    exe = chromium()
    if exe is None:
        if required:
            pytest.fail("no Chromium for the browser tests (apt-get install chromium)")
        pytest.skip("no Chromium (apt-get install chromium)")
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=exe, args=["--no-sandbox"])
        try:
            yield b
        finally:
            b.close()
