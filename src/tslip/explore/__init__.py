"""``tslip explore``: an interactive explorer of the TSLIP in the browser (``tslip[explore]``).

Move a slider, see the periodic gait, its Floquet multipliers, its robustness
limits and the runner after a disturbance; map the largest multiplier over
two parameters. A Bokeh server (:mod:`.server`) serves one document per tab
(:mod:`.app`); what it computes are plain functions (:mod:`.compute`) and its
state and URL query are data parsed with the validators of
:class:`tslip.Params` (:mod:`.state`). Needs the ``explore`` extra (Bokeh);
``import tslip.explore`` loads neither Bokeh nor the kernels.
"""

from collections.abc import Iterable

from .state import CONTROLS, GAINS, ExploreState, parse_query

__all__ = ["CONTROLS", "GAINS", "ExploreState", "parse_query", "serve"]


def serve(port: int = 5006, host: str = "127.0.0.1", open_browser: bool = True,
          allow_hosts: Iterable[str] = ()) -> None:
    """Serve the explorer at ``http://host:port/`` until Ctrl-C or SIGTERM (:func:`.server.serve`).

    ``allow_hosts``: further names (``name`` or ``name:port``) it answers for; a
    request naming any other host gets 403 (:func:`.server.allowed_hosts`).
    """
    from .server import serve as _serve

    _serve(port, host, open_browser, allow_hosts=allow_hosts)
