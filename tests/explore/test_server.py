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
from typer.testing import CliRunner

import tslip
from tslip.cli.main import app
from tslip.simulation.result import TRAJECTORY_COLUMNS

from .conftest import START_TIMEOUT, free_port, get, stop


def test_the_page_is_served_on_the_loopback_address(server):
    status, body = get(server.url + "/")
    assert status == 200
    assert b"<title>tslip explore</title>" in body


def _open_ws(port: int, origin: str, host: str = "127.0.0.1", header: str | None = None) -> int:
    """The HTTP status of a websocket handshake (RFC 6455) from ``origin``: 101 opens it.

    Plain HTTP, as a browser sends it (no event loop: Playwright's runs in this thread),
    to ``host`` with the ``Host`` header ``header`` (default ``host:port``).
    """
    return _raw(port, "/ws", host, header, {
        "Upgrade": "websocket", "Connection": "Upgrade", "Origin": origin,
        "Sec-WebSocket-Key": base64.b64encode(os.urandom(16)).decode(),
        "Sec-WebSocket-Version": "13", "Sec-WebSocket-Protocol": "bokeh, no-token"})


def _raw(port: int, path: str, host: str = "127.0.0.1", header: str | None = None,
         headers: dict[str, str] | None = None) -> int:
    """The HTTP status of a GET of ``path`` from ``host:port`` with ``Host: header``."""
    conn = http.client.HTTPConnection(host, port, timeout=60)
    try:
        conn.putrequest("GET", path, skip_host=True)
        conn.putheader("Host", f"{host}:{port}" if header is None else header)
        for k, v in (headers or {}).items():
            conn.putheader(k, v)
        conn.endheaders()
        response = conn.getresponse()
        response.read()
        return response.status
    finally:
        conn.close()


@pytest.mark.parametrize("origin", ["http://evil.example", "http://127.0.0.1:1",
                                    "null", "http://127.0.0.1.evil.example"])
def test_a_websocket_from_another_origin_is_refused(server, origin):
    assert _open_ws(server.port, origin) == 403


def test_a_websocket_from_its_own_origin_gets_past_the_allow_list(server):
    """The control for the test above: the same handshake from the page's own origin."""
    assert _open_ws(server.port, server.url) == 101


#: A page at one of these names that resolves to 127.0.0.1 (DNS rebinding) sends it as Host.
FOREIGN = ["evil.example:{port}", "evil.example", "127.0.0.1:{other}",
           "localhost.evil.example:{port}", ""]


@pytest.mark.parametrize("host", FOREIGN)
def test_a_request_naming_another_host_gets_403_on_every_route(server, host):
    """DNS rebinding: the connection reaches 127.0.0.1, the Host header names the attacker's
    page. The websocket's Origin equals that Host, as a rebound page's does (Tornado then
    does not ask the origin allow-list)."""
    host = host.format(port=server.port, other=server.port + 1)
    assert _raw(server.port, "/", header=host) == 403
    assert _raw(server.port, "/export/params.toml?preset=table6.1", header=host) == 403
    assert _raw(server.port, "/static/js/bokeh.min.js", header=host) == 403
    assert _open_ws(server.port, f"http://{host}", header=host) == 403


@pytest.mark.parametrize("host", ["127.0.0.1:{port}", "localhost:{port}", "[::1]:{port}",
                                  "LOCALHOST:{port}"])
def test_a_request_naming_the_server_gets_through(server, host):
    """The control for the test above: the same requests naming the server."""
    host = host.format(port=server.port)
    assert _raw(server.port, "/", header=host) == 200
    assert _raw(server.port, "/export/params.toml?preset=table6.1", header=host) == 200
    assert _open_ws(server.port, f"http://{host}", header=host) == 101


def test_a_binding_retraction_stop_is_refused_with_422_and_one_log_line(server):
    """alpha_stop = 1.0 rad holds the Table 6.1 leg at touch-down (alpha_TD is about 1.22):
    the gait search refuses it (Section 7.5); that is the input's fault, not the server's."""
    g = tslip.find_gait(tslip.preset("table6.1"))
    assert g.state.beta + g.state.phi > 1.0 + 0.1
    before = len(server.text())
    status, body = get(server.url + "/export/params.toml?preset=table6.1&alpha_stop=1.0")
    assert status == 422
    assert body.decode().startswith("error: no gait: alpha_stop binds at the periodic gait")
    assert "ValueError" not in body.decode()
    log = server.text()[before:]
    assert len([line for line in log.splitlines() if "alpha_stop binds" in line]) == 1, log
    assert "Traceback" not in log


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
    """``--host`` other than 127.0.0.1 warns on stderr, and the allow-lists are that host:port
    and the ``--allow-host`` names (127.0.0.2: another address of this machine's loopback,
    so nothing is exposed)."""
    host, port = "127.0.0.2", free_port()
    err = tmp_path / "stderr.txt"
    with err.open("w") as out:
        proc = subprocess.Popen([sys.executable, "-m", "tslip", "explore", "--host", host,
                                 "--port", str(port), "--no-open", "--allow-host", "box.lan",
                                 "--allow-host", "proxy.lan:8443"],
                                stdout=subprocess.DEVNULL, stderr=out, env=os.environ.copy())
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
        for name in (f"box.lan:{port}", "proxy.lan:8443"):
            assert _raw(port, "/", host, name) == 200, name
            assert _open_ws(port, f"http://{name}", host, name) == 101, name
        for name in (f"127.0.0.1:{port}", f"localhost:{port}", f"proxy.lan:{port}",
                     "box.lan:8443"):
            assert _raw(port, "/", host, name) == 403, name
    finally:
        stop(proc)


def test_the_default_host_does_not_warn(server):
    assert "warning" not in server.text()


def test_the_help_names_the_extra_to_install():
    """rich reads ``[explore]`` as markup unless it is escaped, and printed ``tslip``."""
    result = CliRunner().invoke(app, ["explore", "--help"], env={"COLUMNS": "120"})
    assert result.exit_code == 0
    assert 'pip install "tslip[explore]"' in result.output


@pytest.mark.parametrize("name", ["http://box.lan", "box.lan/", "", "a b"])
def test_a_bad_allow_host_is_one_line_and_exit_2(name):
    result = CliRunner().invoke(app, ["explore", "--no-open", "--allow-host", name])
    assert result.exit_code == 2
    want = f"error: --allow-host must be a host name or name:port, got {name!r}"
    assert result.output.strip() == want
