"""The explorer's server over HTTP: the page, the websocket allow-list, the exports."""

import base64
import http.client
import io
import os
import subprocess
import sys
import time
import tomllib

import pandas as pd
import pytest

import tslip
from tslip.simulation.result import TRAJECTORY_COLUMNS

from .conftest import START_TIMEOUT, free_port, get, stop


def test_the_page_is_served_on_the_loopback_address(server):
    status, body = get(server.url + "/")
    assert status == 200
    assert b"<title>tslip explore</title>" in body


def _open_ws(port: int, origin: str, host: str = "127.0.0.1") -> int:
    """The HTTP status of a websocket handshake (RFC 6455) from ``origin``: 101 opens it.

    Plain HTTP, as a browser sends it (no event loop: Playwright's runs in this thread).
    """
    conn = http.client.HTTPConnection(host, port, timeout=30)
    try:
        conn.request("GET", "/ws", headers={
            "Upgrade": "websocket", "Connection": "Upgrade", "Origin": origin,
            "Sec-WebSocket-Key": base64.b64encode(os.urandom(16)).decode(),
            "Sec-WebSocket-Version": "13", "Sec-WebSocket-Protocol": "bokeh, no-token"})
        return conn.getresponse().status
    finally:
        conn.close()


@pytest.mark.parametrize("origin", ["http://evil.example", "http://127.0.0.1:1",
                                    "null", "http://127.0.0.1.evil.example"])
def test_a_websocket_from_another_origin_is_refused(server, origin):
    assert _open_ws(server.port, origin) == 403


def test_a_websocket_from_its_own_origin_gets_past_the_allow_list(server):
    """The control for the test above: the same handshake from the page's own origin."""
    assert _open_ws(server.port, server.url) == 101


def test_the_toml_export_holds_the_solved_gait_parameters(server):
    status, body = get(server.url + "/export/params.toml?preset=table6.1&k=9")
    assert status == 200, body
    params = tslip.Params.from_dict(tomllib.loads(body.decode())["params"])
    q = tslip.Params.from_dict({"preset": "table6.1", "k": 9.0})
    assert params == tslip.find_gait(q).params  # alpha_r and alphad_ref solved


def test_the_parquet_export_holds_the_gaits_trajectory(server):
    status, body = get(server.url + "/export/trajectory.parquet?preset=table2.1")
    assert status == 200
    df = pd.read_parquet(io.BytesIO(body))
    assert list(df.columns) == list(TRAJECTORY_COLUMNS)
    g = tslip.find_gait(tslip.preset("table2.1"))
    assert df["t"].iloc[-1] == pytest.approx(2 * (g.stance_time + g.flight_time), rel=1e-6)


@pytest.mark.parametrize(("query", "word"), [("k=-3", "k [MgL^-1]"), ("k=nan", "nan"),
                                             ("v0=fast", "'fast'"), ("preset=x", "preset")])
def test_a_bad_export_query_is_refused_with_the_reason_and_the_server_goes_on(server, query,
                                                                            word):
    status, body = get(server.url + "/export/params.toml?" + query)
    assert status == 400
    assert word in body.decode()
    assert get(server.url + "/favicon.ico")[0] == 200  # still serving
    assert server.alive()


def test_another_host_warns_and_takes_websockets_only_from_that_host_and_port(tmp_path):
    """``--host`` other than 127.0.0.1 warns on stderr, and the allow-list is that host:port
    (127.0.0.2: another address of this machine's loopback, so nothing is exposed)."""
    host, port = "127.0.0.2", free_port()
    err = tmp_path / "stderr.txt"
    with err.open("w") as out:
        proc = subprocess.Popen([sys.executable, "-m", "tslip", "explore", "--host", host,
                                 "--port", str(port), "--no-open"], stdout=subprocess.DEVNULL,
                                stderr=out, env=os.environ.copy())
    try:
        deadline = time.monotonic() + START_TIMEOUT
        while True:
            try:
                if get(f"http://{host}:{port}/favicon.ico", timeout=5)[0] == 200:
                    break
            except OSError:
                pass
            assert proc.poll() is None and time.monotonic() < deadline, err.read_text()
            time.sleep(0.2)
        text = err.read_text()
        assert f"warning: serving on {host}" in text and "--host 127.0.0.1" in text
        assert _open_ws(port, f"http://{host}:{port}", host) == 101
        for origin in (f"http://127.0.0.1:{port}", f"http://localhost:{port}",
                       f"http://{host}:{port + 1}", "http://evil.example"):
            assert _open_ws(port, origin, host) == 403, origin
    finally:
        stop(proc)


def test_the_default_host_does_not_warn(server):
    assert "warning" not in server.text()
