"""The explorer's web server: a Bokeh server on one host and port, and its export routes.

It binds 127.0.0.1 unless told otherwise. Any page the user opens can reach
localhost, so every request (the page, the exports, the static files, the
websocket) must name the server in its ``Host`` header: 127.0.0.1, localhost
or [::1] with the port on the loopback address, the ``--host`` address
otherwise, and any name given with ``allow_hosts`` (:func:`allowed_hosts`);
anything else gets 403. That stops DNS rebinding (a page at ``evil.example``
that resolves to 127.0.0.1 sends ``Host: evil.example``), which the websocket
origin allow-list alone does not: Tornado accepts a websocket whose Origin
equals its Host without asking it. The websocket also takes connections only
from those origins (a page from another origin). ``/export/params.toml`` and
``/export/trajectory.parquet`` take the same URL query as the page.
"""

from __future__ import annotations

import asyncio
import ipaddress
import logging
import signal
import sys
import threading
import webbrowser
from collections.abc import Callable, Iterable
from typing import Any

from tornado.httputil import HTTPServerRequest
from tornado.routing import Matcher, Rule
from tornado.web import RequestHandler

__all__ = ["serve", "make_server", "LOOPBACK", "allowed_hosts"]

log = logging.getLogger("tslip.explore")

#: The default address: this machine only.
LOOPBACK = "127.0.0.1"
#: The names of this machine's loopback address that a browser may put in ``Host``.
LOOPBACK_NAMES = ("127.0.0.1", "localhost", "[::1]")


def _is_loopback(host: str) -> bool:
    """The default address or another name of it (localhost, ::1)."""
    return host.lower().strip("[]") in ("127.0.0.1", "localhost", "::1")


def _is_wildcard(host: str) -> bool:
    """``0.0.0.0`` or ``::`` (every address of the machine, its loopback included)."""
    try:
        return ipaddress.ip_address(host.strip("[]")).is_unspecified
    except ValueError:
        return host == ""


def _host_port(name: str, port: int) -> str:
    """``name`` as a ``Host`` header has it, with ``port`` unless it carries one."""
    name = name.strip().lower()
    if name.startswith("["):
        return name if "]:" in name else f"{name}:{port}"
    if name.count(":") > 1:  # a bare IPv6 address
        return f"[{name}]:{port}"
    return name if ":" in name else f"{name}:{port}"


def allowed_hosts(host: str, port: int, allow_hosts: Iterable[str] = ()) -> list[str]:
    """The ``Host`` headers (``name:port``, lower case) the server answers, in order.

    On the loopback address (127.0.0.1, localhost, ::1) 127.0.0.1, localhost
    and [::1]; on another address that address (on 0.0.0.0 or ::, which
    include the loopback, its names instead); then every name of
    ``allow_hosts`` (``name`` or ``name:port``), all with ``port`` unless
    they carry one.

    Raises
    ------
    ValueError
        If an ``allow_hosts`` entry is empty or holds a scheme, a path or a space.
    """
    names = list(LOOPBACK_NAMES) if _is_loopback(host) or _is_wildcard(host) else [host]
    for name in allow_hosts:
        if not name.strip() or any(c in name for c in "/ \t@?#"):
            raise ValueError(f"--allow-host must be a host name or name:port, got {name!r}")
        names.append(name)
    return list(dict.fromkeys(_host_port(n, port) for n in names))


def _header_host(request: HTTPServerRequest) -> str:
    """The request's ``Host`` as ``name:port`` (port 80 when it has none), lower case."""
    return _host_port(request.headers.get("Host", ""), 80)


class _ForeignHost(Matcher):
    """Matches a request whose ``Host`` is not one of the server's names."""

    def __init__(self, allowed: Iterable[str]) -> None:
        self.allowed = frozenset(allowed)

    def match(self, request: HTTPServerRequest) -> dict[str, Any] | None:
        return None if _header_host(request) in self.allowed else {}


class _Forbidden(RequestHandler):
    """403 for every method: the request named another host (DNS rebinding)."""

    def prepare(self) -> None:
        log.warning("tslip explore: refused a request for Host %r (allowed: %s)",
                    self.request.headers.get("Host", ""), ", ".join(sorted(
                        self.application.settings["tslip_allowed_hosts"])))
        self.set_status(403)
        self.set_header("Content-Type", "text/plain; charset=utf-8")
        self.finish("error: this server does not answer for that host name\n")


class _Export(RequestHandler):
    """GET ``/export/<file>?<query>``: the current gait's parameters or trajectory."""

    def initialize(self, kind: str) -> None:
        self.kind = kind

    async def get(self) -> None:
        from . import compute
        from .state import parse_query

        args = {k: v[-1].decode("utf-8", "replace") for k, v in self.request.arguments.items()}
        state, errors = parse_query(args)
        if errors:
            self._fail(400, "; ".join(errors))
            return
        try:
            solved = await asyncio.wrap_future(_exports().submit(compute.solve, state.params))
        except Exception as exc:  # noqa: BLE001 - reported, logged, the server goes on
            log.exception("tslip explore: export failed")
            self._fail(500, f"{type(exc).__name__}: {exc}")
            return
        if not solved.ok or solved.gait is None or solved.trajectory is None:
            self._fail(422, solved.message)
            return
        if self.kind == "toml":
            self.set_header("Content-Type", "application/toml; charset=utf-8")
            self.set_header("Content-Disposition", 'attachment; filename="params.toml"')
            self.finish(compute.params_toml(solved.gait.params))
        else:
            self.set_header("Content-Type", "application/vnd.apache.parquet")
            self.set_header("Content-Disposition", 'attachment; filename="trajectory.parquet"')
            self.finish(compute.trajectory_parquet(solved.trajectory))

    def _fail(self, code: int, message: str) -> None:
        log.warning("tslip explore: export refused: %s", message)
        self.set_status(code)
        self.set_header("Content-Type", "text/plain; charset=utf-8")
        self.finish(f"error: {message}\n")


#: The export routes' gait searches (a daemon thread: a stopping server does not wait).
_EXPORTS: list[Any] = []


def _exports() -> Any:
    if not _EXPORTS:
        from .workers import Lane

        _EXPORTS.append(Lane("tslip-exports"))
    return _EXPORTS[0]


def make_server(port: int, host: str = LOOPBACK, allow_hosts: Iterable[str] = ()) -> object:
    """A started-but-not-running Bokeh server of the explorer at ``host:port``.

    It answers only requests whose ``Host`` is one of :func:`allowed_hosts`
    (403 otherwise) and websockets from those origins.
    """
    from bokeh.application import Application
    from bokeh.application.handlers.function import FunctionHandler
    from bokeh.server.server import Server

    from .app import make_document

    hosts = allowed_hosts(host, port, allow_hosts)
    server = Server(
        {"/": Application(FunctionHandler(make_document))},
        # Bokeh's origin list cannot parse an IPv6 [address]:port; such a page's websocket
        # has an Origin equal to its (checked) Host, which Tornado accepts without the list
        port=port, address=host,
        allow_websocket_origin=[h for h in hosts if not h.startswith("[")],
        extra_patterns=[(r"/export/params\.toml", _Export, {"kind": "toml"}),
                        (r"/export/trajectory\.parquet", _Export, {"kind": "parquet"})],
        num_procs=1,
    )
    # Bokeh builds its Tornado application itself (no hook for a Host check): the rule goes
    # first in the application's router, before every route of Bokeh's and the exports'
    tornado_app = server._tornado  # noqa: SLF001 - the application Bokeh serves
    tornado_app.settings["tslip_allowed_hosts"] = hosts
    tornado_app.default_router.rules.insert(0, Rule(_ForeignHost(hosts), _Forbidden))
    return server


def serve(port: int = 5006, host: str = LOOPBACK, open_browser: bool = True,
          echo: Callable[[str], None] = print, allow_hosts: Iterable[str] = ()) -> None:
    """Serve the explorer at ``http://host:port/`` until interrupted (Ctrl-C or SIGTERM).

    ``allow_hosts``: further names (``name`` or ``name:port``) the server
    answers for besides its address (:func:`allowed_hosts`). Stopping ends
    every page's work and the worker process of the robustness searches.

    Raises
    ------
    ValueError
        If ``port`` is not in [1, 65535] or an ``allow_hosts`` entry is not a host name.
    """
    if not 1 <= port <= 65535:
        raise ValueError(f"port must be in [1, 65535], got {port}")
    allowed_hosts(host, port, allow_hosts)  # refused before anything starts
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    server: Any = make_server(port, host, allow_hosts)
    server.start()
    from .workers import prestart

    prestart()
    url = f"http://{host}:{port}/"
    echo(f"tslip explore: serving at {url} (Ctrl-C stops)")
    if open_browser:
        server.io_loop.add_callback(webbrowser.open, url)
    if sys.platform != "win32" and threading.current_thread() is threading.main_thread():
        # SIGTERM (kill, a service manager) stops as Ctrl-C does
        server.io_loop.asyncio_loop.add_signal_handler(signal.SIGTERM, server.io_loop.stop)
    try:
        server.io_loop.start()
    except KeyboardInterrupt:
        pass
    finally:
        _shut_down(server)
    echo("tslip explore: stopped")


def _shut_down(server: Any) -> None:
    """Stop serving, stop every page's work and end the worker process."""
    from .app import close_pages
    from .workers import stop_worker

    server.stop(wait=False)
    close_pages()
    stop_worker()
