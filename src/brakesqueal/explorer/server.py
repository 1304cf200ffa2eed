"""Serve the explorer: a Bokeh server (through Panel) on loopback, every asset from the installed packages.

The server serves its own page and nothing else, to its own page only:

* a per-server token (``secrets.token_urlsafe``, printed in the URL at start, as Jupyter does) is needed by
  every request, HTTP and WebSocket: in the query (``?token=...``) or in the cookie the first such request
  sets (``HttpOnly``, ``SameSite=Strict``, named with the port);
* the ``Host`` header must name the bound address (the loopback names ``127.0.0.1``, ``localhost`` and
  ``[::1]``, or the ``--host`` given) with the port, so a DNS-rebound name is refused; an ``Origin``
  header must equal ``http://`` and that ``Host``; requests a browser marks as coming from another site
  (``Sec-Fetch-Site``) are refused, but for a top-level navigation carrying the token;
* Panel's and Bokeh's routes the page does not use are removed (``/components/...``, which imports any
  installed module by name, ``/autoload.js``, ``/metadata``);
* a link whose query parameters are too long, too many or not plain text is answered by a redirect to the
  page without them, which says what was refused (Panel would otherwise fail on them, e.g. on 5000 digits);
* binding beyond loopback needs ``allow_remote`` (``--allow-remote``) and keeps all of the above.

Everything is decided in :class:`Guard`, which a rule placed before every route of the Tornado
application consults (:func:`make_server`).
"""

from __future__ import annotations

import hmac
import ipaddress
import secrets
import socket
import sys
from collections.abc import Iterable
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING, Any, cast
from urllib.parse import urlencode

from ..errors import ParameterError

if TYPE_CHECKING:
    from bokeh.server.server import Server
    from tornado.httputil import HTTPHeaders, HTTPServerRequest

    from ..model.parameters import ParameterSpace

__all__ = ["serve", "make_server", "is_loopback", "free_port", "explorer_url", "Guard", "DEFAULT_PORT",
           "UNUSED_ROUTES", "check_address"]

#: Default port (Bokeh's).
DEFAULT_PORT = 5006
#: Routes of Panel and Bokeh the explorer's page does not use; removed from the server (patterns as Tornado
#: lists them).  ``/components/`` imports any installed module named in the URL.
UNUSED_ROUTES = ("/components/(.*)$", "/autoload.js$", "/metadata$")
#: Names of the loopback interface a ``Host`` header may use.
_LOOPBACK_NAMES = ("127.0.0.1", "localhost", "[::1]")


def is_loopback(host: str) -> bool:
    """Whether ``host`` names the loopback interface only (``127.0.0.1``, ``::1``, ``localhost``)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def free_port(host: str = "127.0.0.1") -> int:
    """A port that is free on ``host`` now."""
    with socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET) as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


def _url_host(host: str) -> str:
    """``host`` as written in a URL (an IPv6 address in brackets)."""
    return f"[{host}]" if ":" in host and not host.startswith("[") else host


def explorer_url(host: str, port: int, token: str) -> str:
    """The URL that opens the explorer: ``http://HOST:PORT/?token=TOKEN`` (a wildcard address as ``127.0.0.1``).

    Parameters
    ----------
    host : str
        The bound address.
    port : int
        The bound port.
    token : str
        The server's token.

    Returns
    -------
    str
    """
    shown = "127.0.0.1" if host in ("0.0.0.0", "::", "") else host
    return f"http://{_url_host(shown)}:{port}/?{urlencode({'token': token})}"


def _is_ip(name: str) -> bool:
    try:
        ipaddress.ip_address(name.strip("[]"))
    except ValueError:
        return False
    return True


@dataclass(frozen=True)
class Guard:
    """What a request must carry to reach the explorer; :meth:`refusal` decides.

    Attributes
    ----------
    token : str
        The server's token (query parameter ``token`` or the cookie :attr:`cookie`).
    port : int
        The bound port (every accepted ``Host`` names it).
    names : frozenset of str
        Host names (lower case, IPv6 addresses in brackets) a ``Host`` header may use.
    any_ip : bool
        Whether any IP address is accepted as a host name too (binding beyond loopback: the machine's
        addresses are not known in advance; a DNS name that is not in ``names`` is still refused).
    """

    token: str
    port: int
    names: frozenset[str]
    any_ip: bool = False

    @classmethod
    def for_address(cls, host: str, port: int, token: str, *, remote: bool = False) -> Guard:
        """The guard of a server bound to ``host:port``: the loopback names and ``host``; with ``remote``
        also any IP address and this machine's names (``socket.gethostname``, ``getfqdn``)."""
        names = {*_LOOPBACK_NAMES, _url_host(host).lower()}
        if remote:
            names.update(n.lower() for n in (socket.gethostname(), socket.getfqdn()) if n)
            names.discard("0.0.0.0")
            names.discard("[::]")
        return cls(token=token, port=port, names=frozenset(names), any_ip=remote)

    @property
    def cookie(self) -> str:
        """Name of the cookie holding the token (with the port: browsers share cookies across ports)."""
        return f"brakesqueal-explorer-{self.port}"

    def host_allowed(self, host: str) -> bool:
        """Whether a ``Host`` header value names this server (its address and port)."""
        host = host.strip().lower()
        if host.startswith("["):
            name, _, rest = host.partition("]")
            name += "]"
            port = rest[1:] if rest.startswith(":") else ("" if not rest else "x")
        else:
            name, _, port = host.partition(":")
        if port != str(self.port) and not (port == "" and self.port == 80):
            return False
        return name in self.names or (self.any_ip and _is_ip(name) and name not in ("0.0.0.0", "[::]"))

    def token_in_query(self, request: HTTPServerRequest) -> bool:
        """Whether the request's query carries the token."""
        given = request.query_arguments.get("token", [])
        return any(hmac.compare_digest(g, self.token.encode()) for g in given)

    def _token_in_cookie(self, headers: HTTPHeaders) -> bool:
        from http.cookies import CookieError, SimpleCookie

        jar: SimpleCookie = SimpleCookie()
        for line in headers.get_list("Cookie"):
            try:
                jar.load(line)
            except CookieError:
                continue
        morsel = jar.get(self.cookie)
        return morsel is not None and hmac.compare_digest(morsel.value.encode(), self.token.encode())

    def refusal(self, request: HTTPServerRequest) -> str | None:
        """Why ``request`` is refused (403), or None.

        Refused: a ``Host`` that does not name this server; an ``Origin`` other than ``http://`` and the
        ``Host``; a request a browser marks as from another site (``Sec-Fetch-Site``), unless it is a
        top-level navigation with the token in its query; a request without the token (query or cookie).
        """
        headers = request.headers
        host = headers.get("Host", "")
        if not self.host_allowed(host):
            return "the Host header does not name this server (use the URL printed at start)"
        origin = headers.get("Origin")
        if origin is not None and origin.lower() != f"http://{host.strip().lower()}":
            return "requests from another origin are refused"
        site = headers.get("Sec-Fetch-Site", "").lower()
        if site in ("cross-site", "same-site"):
            navigation = (headers.get("Sec-Fetch-Mode", "").lower() == "navigate"
                          and headers.get("Sec-Fetch-Dest", "").lower() == "document")
            if not (navigation and self.token_in_query(request)):
                return "requests from another site are refused"
        if not (self.token_in_query(request) or self._token_in_cookie(headers)):
            return ("this server needs its token: open the URL printed by 'brakesqueal explore' "
                    "(http://.../?token=...)")
        return None

    def set_cookie_header(self) -> str:
        """The ``Set-Cookie`` value that stores the token in the browser (this port's pages only)."""
        return f"{self.cookie}={self.token}; Path=/; HttpOnly; SameSite=Strict"


def _link_refusal(request: HTTPServerRequest, guard: Guard) -> tuple[int, str] | None:
    """How a request of the page (or of a session, ``/ws``) whose query breaks the link limits is answered:
    the page by a redirect to itself without the query, saying what was refused (302 and the target); a
    session by 400; None when the query is within the limits (:func:`~.state.link_problem`)."""
    from .state import REFUSED_KEY, link_limit_message, link_problem

    if request.path not in ("/", "", "/ws"):
        return None
    query = {k: [v.decode("utf-8", "replace") for v in vs] for k, vs in request.query_arguments.items()
             if k != "token"}
    problem = link_problem(query)
    if problem is None:
        return None
    if request.path == "/ws" or request.method != "GET":
        return 400, link_limit_message(problem)
    target: dict[str, str] = {REFUSED_KEY: problem}
    if guard.token_in_query(request):
        target["token"] = guard.token
    return 302, "/?" + urlencode(target)


def _redacted(uri: str, limit: int = 160) -> str:
    """A request's URI for the log: the token hidden, at most ``limit`` characters."""
    from urllib.parse import parse_qsl, urlsplit

    parts = urlsplit(uri)
    if parts.query:
        query = [(k, "..." if k == "token" else v) for k, v in parse_qsl(parts.query, keep_blank_values=True)]
        uri = parts.path + "?" + urlencode(query)
    return uri if len(uri) <= limit else uri[:limit] + f"... ({len(uri)} characters)"


def _log_request(handler: Any) -> None:
    """Tornado's access log line, with the URI of :func:`_redacted` (no token, no megabyte of a link)."""
    from tornado.log import access_log

    status = handler.get_status()
    log = access_log.info if status < 400 else access_log.warning if status < 500 else access_log.error
    request = handler.request
    log("%d %s %s (%s) %.2fms", status, request.method, _redacted(request.uri or ""), request.remote_ip,
        1000.0 * request.request_time())


def _install_guard(app: Any, guard: Guard) -> None:
    """Consult ``guard`` before every route of the Tornado application ``app``; remove :data:`UNUSED_ROUTES`."""
    from tornado.routing import Matcher, Rule
    from tornado.web import OutputTransform, RequestHandler

    class Refused(RequestHandler):
        """Answers a refused request: 403 (or 400) with one line, or a redirect (a link beyond the limits)."""

        def initialize(self, status: int, message: str) -> None:
            self._refused = (status, message)

        def prepare(self) -> None:
            status, message = self._refused
            if status == 302:
                self.redirect(message)
                return
            self.set_status(status)
            self.set_header("Content-Type", "text/plain; charset=utf-8")
            self.finish(f"brakesqueal explorer: {message}\n")

    class Checked(Matcher):
        """Matches (so :class:`Refused` answers) every request the guard refuses."""

        def match(self, request: HTTPServerRequest) -> dict[str, Any] | None:
            why = guard.refusal(request)
            if why is not None:
                return {"target_kwargs": {"status": 403, "message": why}}
            answer = _link_refusal(request, guard)
            if answer is not None:
                return {"target_kwargs": {"status": answer[0], "message": answer[1]}}
            return None

    class TokenCookie(OutputTransform):
        """Sets the token's cookie on the answer to a request that carried the token in its query."""

        def __init__(self, request: HTTPServerRequest) -> None:
            super().__init__(request)
            self._set = guard.token_in_query(request)

        def transform_first_chunk(self, status_code: int, headers: HTTPHeaders, chunk: bytes,
                                  finishing: bool) -> tuple[int, HTTPHeaders, bytes]:
            if self._set:
                headers.add("Set-Cookie", guard.set_cookie_header())
            return status_code, headers, chunk

    app.wildcard_router.rules[:] = [r for r in app.wildcard_router.rules
                                    if getattr(getattr(r.matcher, "regex", None), "pattern", "") not in UNUSED_ROUTES]
    app.default_router.rules.insert(0, Rule(Checked(), Refused))
    app.add_transform(TokenCookie)
    app.settings["log_function"] = _log_request


def _configure_offline() -> None:
    """Serve Bokeh's and Panel's JavaScript and CSS from the installed packages; load nothing from a CDN."""
    import panel as pn
    from bokeh.settings import settings

    settings.resources = "server"
    pn.extension(inline=False)  # registers Panel's bundled models; resources are served by this server


def check_address(host: str, port: int, allow_remote: bool) -> None:
    """Raise ParameterError (one line naming ``--host`` or ``--port``) unless the explorer may listen there.

    Parameters
    ----------
    host : str
        The address to bind: loopback unless ``allow_remote``.
    port : int
        The port, in [0, 65535].
    allow_remote : bool
        Whether ``--allow-remote`` was given.
    """
    if not 0 <= port <= 65535:
        raise ParameterError(f"--port must be in [0, 65535]; got {port}", parameter="port")
    if not host or len(host) > 255 or any(c.isspace() for c in host):
        raise ParameterError(f"--host must be an address or host name; got {host[:64]!r}", parameter="host")
    if not is_loopback(host) and not allow_remote:
        raise ParameterError(f"--host {host[:64]} is not loopback: serving the explorer beyond this machine needs "
                             "--allow-remote (anyone who can reach the address and has the URL's token can use it)",
                             parameter="host")


def make_server(space: ParameterSpace, *, port: int = DEFAULT_PORT, host: str = "127.0.0.1",
                show: bool = False, token: str | None = None, allow_remote: bool = False) -> Server:
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
        Open a browser tab at the tokenized URL once the server runs.
    token : str, optional
        The token every request must carry: 16 to 256 letters, digits, ``-`` or ``_`` (default: a fresh
        ``secrets.token_urlsafe(32)``; pass one to know the URL, :func:`explorer_url`).
    allow_remote : bool
        Allow an address other than loopback (the token and the Host and Origin checks stay).

    Returns
    -------
    bokeh.server.server.Server

    Raises
    ------
    ParameterError
        A port outside [0, 65535], an address beyond loopback without ``allow_remote``, or a malformed token.
    """
    check_address(host, port, allow_remote)
    token = token or secrets.token_urlsafe(32)
    if not (16 <= len(token) <= 256 and all(c.isascii() and (c.isalnum() or c in "-_") for c in token)):
        raise ParameterError("the explorer's token must be 16 to 256 letters, digits, '-' or '_' "
                             f"(as secrets.token_urlsafe makes); got {len(token)} characters", parameter="token")
    import panel as pn

    from .app import build_page, warm_up
    from .state import Origin

    origin = Origin(space)
    origin.space_of(origin.initial_state())
    if port == 0:
        port = free_port(host if host not in ("0.0.0.0", "::") else "127.0.0.1")
    _configure_offline()
    guard = Guard.for_address(host, port, token, remote=not is_loopback(host))
    # Bokeh's own check of the WebSocket's Origin (the guard's is stricter; Bokeh cannot parse IPv6 names)
    origins = ["*"] if guard.any_ip or ":" in host else sorted(f"{n}:{port}" for n in guard.names if "[" not in n)
    warm_up(origin)
    server = pn.serve({"/": lambda: build_page(origin)}, port=port, address=host, show=False, start=False,
                      websocket_origin=origins, title="brakesqueal explorer", verbose=False)
    server = cast("Server", server)  # not threaded: the Bokeh server itself
    _install_guard(server._tornado, guard)  # the Tornado application (Panel reaches it the same way)
    if show:
        _open_browser(server, explorer_url(host, port, token))
    return server


def _open_browser(server: Server, url: str) -> None:
    """Open ``url`` (the tokenized one) in a new tab of the default browser once the server's loop runs."""
    from bokeh.util.browser import view

    server.io_loop.add_callback(partial(view, url, new="tab"))


def _shown_urls(host: str, port: int, token: str) -> Iterable[str]:
    yield explorer_url(host, port, token)
    if host in ("0.0.0.0", "::"):
        yield explorer_url(socket.gethostname(), port, token)


def serve(space: ParameterSpace, *, port: int = DEFAULT_PORT, host: str = "127.0.0.1",
          open_browser: bool = True, allow_remote: bool = False) -> None:
    """Serve the explorer until interrupted; print its URL (with the token) and open it in a browser.

    Parameters
    ----------
    space : ParameterSpace
        The command line's space.
    port : int
        TCP port (0: a free one).
    host : str
        Address to bind: loopback unless ``allow_remote``.
    open_browser : bool
        Open the page in the default browser.
    allow_remote : bool
        Allow an address beyond loopback (prints a warning: anyone who can reach the address and has the
        URL's token can use the explorer and make this machine compute).

    Raises
    ------
    ParameterError
        A bad or busy port, or an address beyond loopback without ``allow_remote``.
    """
    check_address(host, port, allow_remote)
    if not is_loopback(host):
        print(f"brakesqueal: warning: serving on {host}, not loopback: anyone who can reach this address and has "
              "the URL's token can use the explorer", file=sys.stderr)
    token = secrets.token_urlsafe(32)
    try:
        server = make_server(space, port=port, host=host, show=False, token=token, allow_remote=allow_remote)
    except OSError as exc:
        raise ParameterError(f"--port {port} on {host}: cannot listen ({exc.strerror or exc})",
                             parameter="port") from None
    urls = list(_shown_urls(host, server.port if server.port is not None else port, token))
    print(f"brakesqueal: explorer at {urls[0]} (Ctrl-C to stop)", file=sys.stderr, flush=True)
    for other in urls[1:]:
        print(f"brakesqueal: also at {other}", file=sys.stderr, flush=True)
    server.start()
    if open_browser:
        _open_browser(server, urls[0])
    try:
        server.io_loop.start()
    finally:
        server.stop()
