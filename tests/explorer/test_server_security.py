"""A running explorer lets no web page in (issue 30), over HTTP and WebSocket.

``brakesqueal explore --port 0`` runs in a subprocess; the tests talk to it with ``http.client`` (any ``Host``
header), Tornado's WebSocket client and Bokeh's client (the page's document, as the browser gets it).
Each refusal has a positive control: the same request with the right Host, Origin and token is served.
"""

from __future__ import annotations

import asyncio
import html
import http.client
from html.parser import HTMLParser
import subprocess
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any, TypeVar, cast
from urllib.parse import urlencode, urlsplit

import pytest

from _served import Served

pytestmark = pytest.mark.slow  # a server subprocess

pytest.importorskip("panel")

_T = TypeVar("_T")


@pytest.fixture(scope="module")
def srv() -> Iterator[Served]:
    s = Served(["--port", "0"])
    try:
        yield s
    finally:
        s.stop()


def get(srv: Served, path: str, *, host: str | None = None, headers: dict[str, str] | None = None,
        port: int | None = None) -> tuple[int, dict[str, str], bytes]:
    """GET ``path`` from the server with the given ``Host`` header (default its own)."""
    conn = http.client.HTTPConnection("127.0.0.1", port or srv.port, timeout=120)
    try:
        conn.putrequest("GET", path, skip_host=True, skip_accept_encoding=True)
        conn.putheader("Host", host or f"127.0.0.1:{port or srv.port}")
        for k, v in (headers or {}).items():
            conn.putheader(k, v)
        conn.endheaders()
        r = conn.getresponse()
        return r.status, {k.lower(): v for k, v in r.getheaders()}, r.read()
    finally:
        conn.close()


def _in_thread(fn: Callable[[], _T]) -> _T:
    """``fn()`` in a thread of its own (with its own event loop: the browser tests' Playwright runs one here)."""
    out: list[Any] = []

    def run() -> None:
        try:
            out.append((True, fn()))
        except BaseException as exc:  # re-raised in the caller
            out.append((False, exc))

    t = threading.Thread(target=run)
    t.start()
    t.join()
    ok, value = out[0]
    if not ok:
        raise value
    return cast("_T", value)


def ws_status(port: int, *, host: str, origin: str | None, query: str = "", cookie: str | None = None) -> int:
    """Open the page's WebSocket (``/ws``) with these headers: 101 if it opens, else the HTTP status."""
    from bokeh.util.token import generate_jwt_token, generate_session_id
    from tornado.httpclient import HTTPClientError, HTTPRequest
    from tornado.websocket import websocket_connect

    async def go() -> int:
        headers = {"Host": host}
        if origin is not None:
            headers["Origin"] = origin
        if cookie is not None:
            headers["Cookie"] = cookie
        req = HTTPRequest(f"ws://127.0.0.1:{port}/ws{query}", headers=headers, request_timeout=120)
        token = generate_jwt_token(generate_session_id(), signed=False)
        try:
            conn = await websocket_connect(req, subprotocols=["bokeh", token])
        except HTTPClientError as exc:
            return exc.code
        try:
            first = await conn.read_message()  # Bokeh's ACK: the session is open
            assert first is not None
        finally:
            conn.close()
        return 101

    return _in_thread(lambda: asyncio.run(go()))


def alert_html(srv: Served, query: dict[str, str]) -> str:
    """The HTML of the message line of a session opened with ``query``, as the browser renders it."""
    import panel.models  # noqa: F401  (Panel's models, so Bokeh's client can read the document)
    from bokeh.client import pull_session

    def pull() -> list[str]:
        session = pull_session(url=srv.base, arguments={**query, "token": srv.token})
        try:
            return [m.text for m in session.document.models if "bs-alert" in (getattr(m, "css_classes", None) or [])
                    and isinstance(getattr(m, "text", None), str)]
        finally:
            session.close()

    texts = _in_thread(pull)
    assert len(texts) == 1
    return html.unescape(texts[0])  # Panel's HTML model carries the pane's HTML escaped once more


class _Page(HTMLParser):
    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tags: list[str] = []
        self.text = ""

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append(tag)

    def handle_data(self, data: str) -> None:
        self.text += data


def rendered(markup: str) -> tuple[list[str], str]:
    """The elements and the text a browser makes of ``markup``."""
    p = _Page()
    p.feed(markup)
    p.close()
    return p.tags, p.text


def test_the_page_needs_the_token(srv):
    status, headers, _ = get(srv, f"/?token={srv.token}")
    assert status == 200
    assert headers["set-cookie"].startswith(f"brakesqueal-explorer-{srv.port}={srv.token};")
    cookie = f"brakesqueal-explorer-{srv.port}={srv.token}"
    assert get(srv, "/", headers={"Cookie": cookie})[0] == 200
    for path in ("/", "/?token=wrong", f"/?token={srv.token[:-1]}", "/static/js/bokeh.min.js", "/favicon.ico",
                 "/ws"):
        status, _, body = get(srv, path)
        assert status == 403, path
        assert b"token" in body and b"Traceback" not in body
    assert get(srv, "/static/js/bokeh.min.js", headers={"Cookie": cookie})[0] == 200
    assert get(srv, "/", headers={"Cookie": f"brakesqueal-explorer-{srv.port}=wrong"})[0] == 403


def test_the_printed_url_is_the_tokenized_one(srv):
    line = next(ln for ln in srv.output if "explorer at" in ln)
    assert f"http://127.0.0.1:{srv.port}/?token={srv.token}" in line
    assert len(srv.token) >= 32


def test_a_components_probe_imports_nothing_and_the_server_goes_on(srv):
    # GET /components/pygments.__main__/... made Panel import pygments' command line, which exited the server
    for path in ("/components/pygments.__main__/x/_css/y", "/components/panel/Column/_css/x",
                 "/autoload.js?bokeh-autoload-element=x", "/metadata"):
        assert get(srv, f"{path}{'&' if '?' in path else '?'}token={srv.token}")[0] == 404, path
        assert get(srv, path)[0] == 403, path  # and without the token, refused before any route
    assert srv.proc.poll() is None
    assert get(srv, f"/?token={srv.token}")[0] == 200


@pytest.mark.parametrize("name", ["evil.example", "127.0.0.1.nip.io", "localhost.evil.example", "attacker"])
def test_a_host_that_is_not_this_server_is_refused(srv, name):
    host = f"{name}:{srv.port}"
    status, _, body = get(srv, f"/?token={srv.token}", host=host)
    assert status == 403 and b"Host" in body
    assert get(srv, f"/?token={srv.token}", host=f"127.0.0.1:{srv.port + 1}")[0] == 403
    for ok in ("127.0.0.1", "localhost"):
        assert get(srv, f"/static/js/bokeh.min.js?token={srv.token}", host=f"{ok}:{srv.port}")[0] == 200


def test_the_websocket_refuses_a_rebound_host_another_origin_and_no_token(srv):
    port, own = srv.port, f"127.0.0.1:{srv.port}"
    token = f"?{urlencode({'token': srv.token})}"
    cookie = f"brakesqueal-explorer-{port}={srv.token}"
    # DNS rebinding: Host and Origin both name the attacker (Tornado skips its Origin check when they match)
    evil = f"evil.example:{port}"
    assert ws_status(port, host=evil, origin=f"http://{evil}", query=token) == 403
    assert ws_status(port, host=evil, origin=f"http://{evil}", cookie=cookie) == 403
    assert ws_status(port, host=own, origin=f"http://{evil}", cookie=cookie) == 403
    assert ws_status(port, host=own, origin=f"http://127.0.0.1:{port + 1}", cookie=cookie) == 403
    assert ws_status(port, host=own, origin=f"http://{own}") == 403  # no token
    assert ws_status(port, host=own, origin=f"http://{own}", query="?token=wrong") == 403
    assert ws_status(port, host=own, origin=f"http://{own}", cookie=cookie) == 101
    assert ws_status(port, host=f"localhost:{port}", origin=f"http://localhost:{port}", query=token) == 101


@pytest.mark.parametrize("query,shown", [
    ({"along": "[click](http://evil.example/)"}, "[click](http://evil.example/)"),
    ({"set": "mu=![x](http://evil.example/i.png)"}, "![x](http://evil.example/i.png)"),
    ({"x": "<img src=http://evil.example/i.png>"}, "<img src=http://evil.example/i.png>"),
    ({"model": "<a href='//evil.example'>m</a>"}, "<a href='//evil.example'>m</a>"),
])
def test_a_hostile_link_value_is_shown_as_text(srv, query, shown):
    tags, text = rendered(alert_html(srv, query))
    assert tags == []  # no element made of the value: no link, no image ...
    assert text.startswith("link:") and shown in text  # ... the value is shown literally, as text


def test_a_5000_digit_number_in_a_link_is_a_message_not_a_traceback(srv):
    status, headers, _ = get(srv, f"/?token={srv.token}&nx={'5' * 5000}")
    assert status == 302  # to the page without the link, which says what was refused
    target = headers["location"]
    assert "5555" not in target
    status, _, body = get(srv, target)
    assert status == 200 and b"Traceback" not in body
    query = dict(p.split("=", 1) for p in urlsplit(target).query.split("&"))
    query.pop("token", None)
    tags, text = rendered(alert_html(srv, query))
    assert tags == [] and "'nx' in the link is too long" in text and "64" in text and "5555" not in text
    assert get(srv, f"/ws?token={srv.token}&nx={'5' * 5000}")[0] == 400  # a session opened without the page
    assert not any("Traceback" in line for line in srv.output), "".join(srv.output)


def test_binding_beyond_loopback_without_allow_remote_is_one_line():
    r = subprocess.run([sys.executable, "-m", "brakesqueal", "explore", "--no-browser", "--host", "0.0.0.0",
                        "--port", "0"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "--host 0.0.0.0" in lines[0] and "--allow-remote" in lines[0], r.stderr
    assert "Traceback" not in r.stderr + r.stdout


def test_with_allow_remote_the_token_host_and_origin_checks_stay():
    s = Served(["--host", "0.0.0.0", "--allow-remote", "--port", "0"])
    try:
        assert any("not loopback" in line for line in s.output)
        port = s.port

        def status(host: str, path: str = "/", **headers: Any) -> int:
            return get(s, path, host=host, headers=headers, port=port)[0]

        with_token = f"/?token={s.token}"
        assert status(f"127.0.0.1:{port}", with_token) == 200
        assert status(f"192.0.2.7:{port}", with_token) == 200  # an address of this machine, as a client uses it
        assert status(f"127.0.0.1:{port}") == 403  # the token is still needed
        assert status(f"evil.example:{port}", with_token) == 403  # a DNS name that is not this machine's
        assert status(f"192.0.2.7:{port}", with_token, Origin=f"http://evil.example:{port}") == 403
        assert status(f"192.0.2.7:{port}", with_token, Origin=f"http://192.0.2.7:{port}") == 200
        evil = f"evil.example:{port}"
        assert ws_status(port, host=evil, origin=f"http://{evil}", query=f"?token={s.token}") == 403
        assert ws_status(port, host=f"127.0.0.1:{port}", origin=f"http://{evil}", query=f"?token={s.token}") == 403
    finally:
        s.stop()


def test_explore_opens_the_browser_at_the_printed_tokenized_url(monkeypatch, capsys):
    import bokeh.util.browser

    from brakesqueal import resolve_space
    from brakesqueal.explorer import server

    opened: list[str] = []

    def view(url: str, *args: Any, **kwargs: Any) -> None:  # the browser: note the URL, stop the server
        opened.append(url)
        from tornado.ioloop import IOLoop

        IOLoop.current().add_callback(IOLoop.current().stop)

    monkeypatch.setattr(bokeh.util.browser, "view", view)

    def run() -> None:
        loop = asyncio.new_event_loop()
        asyncio.set_event_loop(loop)
        try:
            server.serve(resolve_space(None, "paper-fig2", None, []), port=0, open_browser=True)
        finally:
            loop.close()

    _in_thread(run)
    printed = capsys.readouterr().err
    assert len(opened) == 1 and f"explorer at {opened[0]} " in printed
    assert opened[0].startswith("http://127.0.0.1:") and "/?token=" in opened[0]
