"""Serve the explorer: a Bokeh server (through Panel) on loopback, every asset from the installed packages."""

from __future__ import annotations

import ipaddress
import socket
import sys
from typing import TYPE_CHECKING, cast

from ..errors import ParameterError

if TYPE_CHECKING:
    from bokeh.server.server import Server

    from ..model.parameters import ParameterSpace

__all__ = ["serve", "make_server", "is_loopback", "free_port", "DEFAULT_PORT"]

#: Default port (Bokeh's).
DEFAULT_PORT = 5006


def is_loopback(host: str) -> bool:
    """Whether ``host`` names the loopback interface only (``127.0.0.1``, ``::1``, ``localhost``)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def free_port(host: str = "127.0.0.1") -> int:
    """A port that is free on ``host`` now."""
    with socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET) as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


def _configure_offline() -> None:
    """Serve Bokeh's and Panel's JavaScript and CSS from the installed packages; load nothing from a CDN."""
    import panel as pn
    from bokeh.settings import settings

    settings.resources = "server"
    pn.extension(inline=False)  # registers Panel's bundled models; resources are served by this server


def make_server(space: ParameterSpace, *, port: int = DEFAULT_PORT, host: str = "127.0.0.1",
                show: bool = False) -> Server:
    """A started-on-demand Bokeh server of the explorer (call ``.start()``, ``.io_loop.start()``).

    Parameters
    ----------
    space : ParameterSpace
        The command line's space (:func:`brakesqueal.model.options.resolve_space`).
    port : int
        TCP port (0: a free one).
    host : str
        Address to bind (default loopback).
    show : bool
        Open a browser tab once the server runs.

    Returns
    -------
    bokeh.server.server.Server
    """
    import panel as pn

    from .app import build_page, warm_up
    from .state import Origin

    if not 0 <= port <= 65535:
        raise ParameterError(f"--port must be in [0, 65535]; got {port}")
    origin = Origin(space)
    origin.space_of(origin.initial_state())
    if port == 0:
        port = free_port(host if host not in ("0.0.0.0", "::") else "127.0.0.1")
    _configure_offline()
    origins = [f"{host}:{port}", f"127.0.0.1:{port}", f"localhost:{port}"]
    if not is_loopback(host):
        origins = ["*"]
    warm_up(origin)
    server = pn.serve({"/": lambda: build_page(origin)}, port=port, address=host, show=show, start=False,
                      websocket_origin=origins, title="brakesqueal explorer", verbose=False)
    return cast("Server", server)  # not threaded: the Bokeh server itself


def serve(space: ParameterSpace, *, port: int = DEFAULT_PORT, host: str = "127.0.0.1",
          open_browser: bool = True) -> None:
    """Serve the explorer until interrupted.

    Parameters
    ----------
    space : ParameterSpace
        The command line's space.
    port : int
        TCP port (0: a free one).
    host : str
        Address to bind; anything but loopback prints a warning (the
        explorer has no authentication: anyone who can reach the port can
        use it and make this machine compute).
    open_browser : bool
        Open the page in the default browser.
    """
    if not is_loopback(host):
        print(f"brakesqueal: warning: serving on {host}, not loopback: anyone who can reach this address can use "
              "the explorer (no authentication)", file=sys.stderr)
    try:
        server = make_server(space, port=port, host=host, show=False)
    except OSError as exc:
        raise ParameterError(f"--port {port} on {host}: cannot listen ({exc.strerror or exc})") from None
    url = f"http://{host if ':' not in host else '[' + host + ']'}:{server.port}/"
    print(f"brakesqueal: explorer at {url} (Ctrl-C to stop)", file=sys.stderr, flush=True)
    server.start()
    if open_browser:
        server.io_loop.add_callback(server.show, "/")
    try:
        server.io_loop.start()
    finally:
        server.stop()
