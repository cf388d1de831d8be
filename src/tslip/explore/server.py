"""The explorer's web server: a Bokeh server on one host and port, and its export routes.

It binds 127.0.0.1 unless told otherwise and accepts websocket connections
only from pages it served itself (``allow_websocket_origin`` = its own
host:port, and ``localhost:port`` on the loopback address): any page the user
opens can reach localhost, and without the allow-list it could drive the
explorer. ``/export/params.toml`` and ``/export/trajectory.parquet`` take the
same URL query as the page.
"""

from __future__ import annotations

import logging
import webbrowser
from collections.abc import Callable

from tornado.web import RequestHandler

__all__ = ["serve", "make_server", "LOOPBACK"]

log = logging.getLogger("tslip.explore")

#: The default address: this machine only.
LOOPBACK = "127.0.0.1"


def allowed_origins(host: str, port: int) -> list[str]:
    """The websocket origins the server accepts: its own ``host:port`` (and localhost's)."""
    out = [f"{host}:{port}"]
    if host == LOOPBACK:
        out.append(f"localhost:{port}")
    return out


class _Export(RequestHandler):
    """GET ``/export/<file>?<query>``: the current gait's parameters or trajectory."""

    def initialize(self, kind: str) -> None:
        self.kind = kind

    async def get(self) -> None:
        from tornado.ioloop import IOLoop

        from . import compute
        from .state import parse_query

        args = {k: v[-1].decode("utf-8", "replace") for k, v in self.request.arguments.items()}
        state, errors = parse_query(args)
        if errors:
            self._fail(400, "; ".join(errors))
            return
        try:
            solved = await IOLoop.current().run_in_executor(None, compute.solve, state.params)
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


def make_server(port: int, host: str = LOOPBACK) -> object:
    """A started-but-not-running Bokeh server of the explorer at ``host:port``."""
    from bokeh.application import Application
    from bokeh.application.handlers.function import FunctionHandler
    from bokeh.server.server import Server

    from .app import make_document

    return Server(
        {"/": Application(FunctionHandler(make_document))},
        port=port, address=host, allow_websocket_origin=allowed_origins(host, port),
        extra_patterns=[(r"/export/params\.toml", _Export, {"kind": "toml"}),
                        (r"/export/trajectory\.parquet", _Export, {"kind": "parquet"})],
        num_procs=1,
    )


def serve(port: int = 5006, host: str = LOOPBACK, open_browser: bool = True,
          echo: Callable[[str], None] = print) -> None:
    """Serve the explorer at ``http://host:port/`` until interrupted (Ctrl-C).

    Raises
    ------
    ValueError
        If ``port`` is not in [1, 65535].
    """
    if not 1 <= port <= 65535:
        raise ValueError(f"port must be in [1, 65535], got {port}")
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    server = make_server(port, host)
    server.start()  # type: ignore[attr-defined]
    url = f"http://{host}:{port}/"
    echo(f"tslip explore: serving at {url} (Ctrl-C stops)")
    if open_browser:
        server.io_loop.add_callback(webbrowser.open, url)  # type: ignore[attr-defined]
    try:
        server.io_loop.start()  # type: ignore[attr-defined]
    except KeyboardInterrupt:
        echo("tslip explore: stopped")
