"""``tslip explore``: the interactive explorer in the browser (the ``explore`` extra)."""

from __future__ import annotations

import gc
from typing import Annotated

import typer

from ._common import errors, interruptible

__all__ = ["commands", "explore_cmd"]

#: ``explore``, added to the app by :mod:`tslip.cli.main`.
commands = typer.Typer()


@commands.command("explore")
def explore_cmd(
    port: Annotated[int, typer.Option("--port", min=1, max=65535,
                                      help="Port to serve on.")] = 5006,
    host: Annotated[str, typer.Option("--host", help="Address to bind (default 127.0.0.1, "
                                      "this machine only).")] = "127.0.0.1",
    allow_host: Annotated[list[str] | None, typer.Option(
        "--allow-host", metavar="NAME", help="A further name (or name:port) the server "
        "answers for, e.g. this machine's name with --host 0.0.0.0; repeatable. Requests "
        "naming any other host get 403.")] = None,
    no_open: Annotated[bool, typer.Option("--no-open", help="Do not open a browser.")] = False,
) -> None:
    """Explore gaits in the browser: sliders, gait, multipliers, robustness, stability map.

    Serves a local web page (Bokeh server) until Ctrl-C or SIGTERM. It binds
    127.0.0.1 unless --host says otherwise and answers only requests that
    name it: 127.0.0.1, localhost or [::1] with the port (another --host: that
    address), and the --allow-host names; websocket connections only from
    those origins. Needs the explore extra: pip install "tslip\\[explore]".
    """
    with errors(), interruptible():
        try:
            import bokeh  # noqa: F401
        except ImportError:
            raise ValueError('tslip explore needs Bokeh: pip install "tslip[explore]"') from None
        from ..explore.server import allowed_hosts, serve

        allowed_hosts(host, port, allow_host or ())  # a bad --allow-host: one line, exit 2
        if host != "127.0.0.1":
            typer.echo(f"warning: serving on {host}: other machines that reach this address "
                       "can use the explorer (and the CPU); use --host 127.0.0.1 to keep it "
                       "local", err=True)
        serve(port, host, open_browser=not no_open, allow_hosts=allow_host or ())
    # the process ends now: without this the collector's last pass over numba's and Bokeh's
    # objects at exit took 2-3 s (measured under load), and the server (with the resource
    # tracker it started) outlived its "stopped" by that much
    gc.freeze()
