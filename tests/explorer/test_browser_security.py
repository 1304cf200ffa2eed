"""In chromium: a web page on another origin cannot read or drive a running explorer (issue 30).

The victim's browser holds the explorer's cookie (it opened the printed URL); then it visits an attacker's page
that tries to read the explorer (``fetch``) and to drive it (its WebSocket):

* from another port of this machine (``http://127.0.0.1:OTHER``: same site, so the cookie goes along) and from
  another site (``http://localhost:OTHER``);
* from a DNS-rebound name (``evil.example``, resolved to 127.0.0.1 by the browser: its page is same-origin with
  the explorer's port, so the browser would let it read the answers; the server refuses the Host).  Chromium's
  own Local Network Access checks would block that page before it reaches the server, so that browser runs
  without them (as Firefox and older browsers do): the test is of the server's check;

and a ``/components/`` probe and a hostile link.  Each attack has its control: the same script on the
explorer's own page reads it.
"""

from __future__ import annotations

import http.server
import threading
from collections.abc import Iterator
from typing import Any
from urllib.parse import urlsplit

import pytest

from _served import REBOUND, TIMEOUT
from conftest import CHROMIUM

pytestmark = pytest.mark.slow

#: The attacker's script: read the explorer (CORS and no-CORS fetch) and open its WebSocket.
ATTACK = """
async function attack(target, ws_target) {
  const out = {};
  try {
    const r = await fetch(target, {credentials: "include"});
    out.cors = {status: r.status, body: (await r.text()).slice(0, 200)};
  } catch (e) { out.cors = "error: " + e; }
  try {
    const r = await fetch(target, {mode: "no-cors", credentials: "include"});
    out.nocors = {type: r.type, status: r.status, body: await r.text()};
  } catch (e) { out.nocors = "error: " + e; }
  out.ws = await new Promise(resolve => {
    const ws = new WebSocket(ws_target, ["bokeh", "x"]);
    ws.onopen = () => { resolve("open"); ws.close(); };
    ws.onerror = () => resolve("error");
    ws.onclose = e => resolve("closed " + e.code);
    setTimeout(() => resolve("timeout"), 20000);
  });
  return out;
}
"""
PAGE = f"<!doctype html><html><head><title>attacker</title><script>{ATTACK}</script></head><body>hi</body></html>"


@pytest.fixture(scope="module")
def attacker() -> Iterator[int]:
    """An attacker's web server on another port of this machine; yields the port."""

    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self) -> None:  # noqa: N802  (http.server's name)
            body = PAGE.encode()
            self.send_response(200)
            self.send_header("Content-Type", "text/html; charset=utf-8")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args: Any) -> None:
            pass

    srv = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    try:
        yield int(srv.server_address[1])
    finally:
        srv.shutdown()
        srv.server_close()


@pytest.fixture(scope="module")
def rebinding_browser(browser: Any) -> Iterator[Any]:
    """Chromium resolving ``evil.example`` to 127.0.0.1, without its Local Network Access checks."""
    b = browser.browser_type.launch(executable_path=CHROMIUM, args=[  # the same Playwright as ``browser``
        "--no-sandbox", f"--host-resolver-rules=MAP {REBOUND} 127.0.0.1",
        "--disable-features=LocalNetworkAccessChecks,BlockInsecurePrivateNetworkRequests,"
        "PrivateNetworkAccessSendPreflights"])
    yield b
    b.close()


def _victim(browser: Any, served: Any) -> Iterator[tuple[Any, list[tuple[str, int]]]]:
    """A page that opened the explorer's printed URL (its context holds the cookie), and the statuses of the
    explorer's answers to the requests of every other page it visits."""
    context = browser.new_context()
    answers: list[tuple[str, int]] = []
    own = {f"127.0.0.1:{served.port}", f"{REBOUND}:{served.port}"}

    def seen(r: Any) -> None:
        frame = r.frame.url if r.frame is not None else ""
        if urlsplit(r.url).netloc in own and urlsplit(frame).netloc != f"127.0.0.1:{served.port}":
            answers.append((r.url, r.status))  # an answer of the explorer to another page than its own

    context.on("response", seen)
    pg = context.new_page()
    assert pg.goto(served.url).status == 200
    assert any(c["name"] == f"brakesqueal-explorer-{served.port}" for c in context.cookies())
    answers.clear()  # the answer to that navigation
    try:
        yield pg, answers
    finally:
        context.close()


@pytest.fixture
def victim(browser: Any, served: Any) -> Iterator[tuple[Any, list[tuple[str, int]]]]:
    yield from _victim(browser, served)


@pytest.fixture
def rebound_victim(rebinding_browser: Any, served: Any) -> Iterator[tuple[Any, list[tuple[str, int]]]]:
    yield from _victim(rebinding_browser, served)


def _explorer_reads_itself(pg: Any, served: Any) -> None:
    """The control: the attacker's script, run by the explorer's own page, reads the explorer."""
    pg.evaluate(ATTACK.replace("async function attack", "window.attack = async function"))
    # (its own URL: an answer in the browser's cache would be an answer the attack never asked the server for)
    own = pg.evaluate("([t, w]) => attack(t, w)", [served.base + "static/js/bokeh.min.js?control",
                                                    f"ws://127.0.0.1:{served.port}/ws"])
    assert own["cors"]["status"] == 200 and "Bokeh" in own["cors"]["body"], own


@pytest.mark.parametrize("site", ["127.0.0.1", "localhost"])
def test_a_page_on_another_origin_cannot_read_or_drive_the_explorer(victim, served, attacker, site):
    pg, answers = victim
    _explorer_reads_itself(pg, served)
    answers.clear()
    pg.goto(f"http://{site}:{attacker}/attack.html")
    for target in (served.base, served.base + "static/js/bokeh.min.js", served.base + "?nx=3&ny=3"):
        out = pg.evaluate("([t, w]) => attack(t, w)", [target, f"ws://127.0.0.1:{served.port}/ws"])
        assert isinstance(out["cors"], str) and out["cors"].startswith("error"), out  # nothing read
        assert out["nocors"] == {"type": "opaque", "status": 0, "body": ""}, out  # nothing read either
        assert out["ws"] != "open", out  # not driven
    # the server itself refused them (not only the browser's CORS rule): every answer it gave was 403
    assert answers and all(status == 403 for _, status in answers), answers


def test_a_dns_rebound_page_cannot_read_or_drive_the_explorer(rebound_victim, served):
    pg, answers = rebound_victim
    # the attacker's page at evil.example:PORT (the explorer's port); its name then resolves to 127.0.0.1, so
    # its requests to its own origin reach the explorer, and the browser lets the page read the answers
    origin = f"http://{REBOUND}:{served.port}"
    pg.route(f"{origin}/attack.html", lambda r: r.fulfill(status=200, content_type="text/html", body=PAGE))
    pg.goto(f"{origin}/attack.html")
    for target in ("/", f"/?token={served.token[:4]}", "/static/js/bokeh.min.js"):
        out = pg.evaluate("([t, w]) => attack(t, w)", [origin + target, f"ws://{REBOUND}:{served.port}/ws"])
        assert out["cors"]["status"] == 403 and "Host" in out["cors"]["body"], out  # it reached the server: refused
        assert out["ws"] != "open", out
    assert answers and all(status == 403 for _, status in answers), answers


def test_a_components_probe_from_the_browser_imports_nothing(victim, served):
    pg, _ = victim
    probe = pg.goto(served.base + f"components/pygments.__main__/x/_css/y?token={served.token}")
    assert probe.status == 404
    assert served.proc.poll() is None  # the server did not import pygments' command line (which exits)
    assert pg.goto(served.url).status == 200
    pg.locator("#bs-render").wait_for(state="attached", timeout=TIMEOUT * 1000)


def test_a_hostile_link_shows_its_value_as_text(page):
    value = "![x](//evil.example/i.png)<img src=//evil.example/j.png>"  # within the link limits
    page.open("set=mu%3D" + value.replace("<", "%3C").replace(">", "%3E").replace("=", "%3D").replace(" ", "%20"))
    alert = page.page.locator(".bs-alert")
    message = alert.get_by_text("link:")
    message.wait_for(timeout=30_000)
    assert value in (message.text_content() or "")
    assert alert.locator("a, img").count() == 0
    # and the page requested nothing from the outside (the page fixture fails on any remote request)
