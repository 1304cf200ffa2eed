"""Fixtures of the explorer's browser tests: a served explorer and a Playwright page that may load nothing remote.

The browser is Debian's ``chromium`` (``apt-get install chromium``) driven by
Playwright from PyPI through ``executable_path`` (no ``playwright install``).
Every request that does not go to the loopback server is aborted and
recorded; a test fails on any such request and on any "Failed to load
resource" console message.

The server serves only requests with its token: :func:`server` reads the URL
the command prints at start, and :meth:`Page.open` puts the token into every
link it opens (the page then holds it in a cookie).
"""

from __future__ import annotations

import json
import os
import shutil
import socket
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, urlsplit

from _served import TIMEOUT, Served

import pytest

CHROMIUM = os.environ.get("BRAKESQUEAL_CHROMIUM") or shutil.which("chromium") or "/usr/bin/chromium"
#: Directory for screenshots (docs/figures when making the docs' gallery), or unset.
SHOTS = os.environ.get("BRAKESQUEAL_EXPLORER_SCREENSHOTS")


def browser_missing() -> str | None:
    """Why the browser tests cannot run, or None."""
    try:
        import panel  # noqa: F401
        import playwright.sync_api  # noqa: F401
    except ImportError as exc:
        return f"the explorer's browser tests need panel and playwright (pip install -e '.[test]'): {exc}"
    if not (os.path.isfile(CHROMIUM) and os.access(CHROMIUM, os.X_OK)):
        return "chromium is not installed (apt-get install chromium); the explorer's browser tests need it"
    return None


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@pytest.fixture(scope="session")
def served() -> Iterator[Served]:
    """``brakesqueal explore`` (with the cancel tests' gates) in a subprocess on a free loopback port."""
    why = browser_missing()
    if why:
        pytest.skip(why)
    # _gated_server.py is `python -m brakesqueal` plus the cancel test's gate (see its docstring)
    s = Served(["--port", str(_free_port())], script=str(Path(__file__).with_name("_gated_server.py")))
    try:
        yield s
    finally:
        s.stop()


@pytest.fixture(scope="session")
def server(served: Served) -> str:
    """The served explorer's URL, with its token (``http://127.0.0.1:PORT/?token=...``)."""
    return served.url


@pytest.fixture(scope="session")
def browser() -> Iterator[Any]:
    """Debian's chromium, headless, driven by Playwright."""
    why = browser_missing()
    if why and os.environ.get("BRAKESQUEAL_REQUIRE_BROWSER") == "1":  # CI (.ci/run): the browser tests must run
        pytest.fail(f"BRAKESQUEAL_REQUIRE_BROWSER=1 but {why}")
    if why:
        pytest.skip(why)
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        yield b
        b.close()


class Page:
    """A browser page on the explorer with helpers that wait on the render counter."""

    def __init__(self, page: Any, url: str) -> None:
        self.page = page
        parts = urlsplit(url)
        self.base = f"{parts.scheme}://{parts.netloc}/"
        self.token = parse_qs(parts.query).get("token", [""])[0]
        self.remote: list[str] = []
        self.failed: list[str] = []

    def open(self, query: str = "") -> None:
        """Load the explorer (``query`` without ``?``; the token is added) and wait for the first eigenvalues."""
        self.page.goto(self.base + "?" + (f"{query}&" if query else "") + f"token={self.token}")
        self.page.locator("#bs-render").wait_for(state="attached", timeout=TIMEOUT * 1000)
        self.wait(lambda s: "locus" in s)

    def shown(self) -> tuple[int, dict[str, Any]]:
        """The render counter and the state the page shows."""
        el = self.page.locator("#bs-render")
        return int(el.get_attribute("data-count") or 0), json.loads(el.get_attribute("data-shown") or "{}")

    def wait(self, predicate: Callable[[dict[str, Any]], Any], timeout: float = TIMEOUT) -> dict[str, Any]:
        """Wait until the render counter moves to a state satisfying ``predicate``; return that state."""
        deadline = time.monotonic() + timeout
        last = -1
        while True:
            count, shown = self.shown()
            if count != last:
                last = count
                if predicate(shown):
                    return shown
            if time.monotonic() > deadline:
                raise AssertionError(f"the page did not reach the expected state within {timeout} s; shows {shown}")
            self.page.wait_for_timeout(10)  # yield to the browser between polls of the counter

    def screenshot(self, name: str) -> None:
        """Save ``explorer-<name>.png`` when screenshots are requested."""
        if SHOTS:
            Path(SHOTS).mkdir(parents=True, exist_ok=True)
            self.page.screenshot(path=str(Path(SHOTS) / f"explorer-{name}.png"), full_page=True)


@pytest.fixture
def page(browser: Any, server: str) -> Iterator[Page]:
    """A fresh page; fails the test on a remote request or a resource that did not load."""
    context = browser.new_context(viewport={"width": 1400, "height": 1000})
    pg = context.new_page()
    wrapper = Page(pg, server)

    def route(r: Any) -> None:
        url = r.request.url
        if url.startswith(("http://127.0.0.1:", "ws://127.0.0.1:", "data:", "blob:")):
            r.continue_()
        else:
            wrapper.remote.append(url)
            r.abort()

    pg.route("**/*", route)
    pg.on("console", lambda m: wrapper.failed.append(m.text) if "failed to load resource" in m.text.lower() else None)
    pg.on("requestfailed", lambda r: wrapper.failed.append(f"{r.url}: {r.failure}")
          if r.url.startswith("http://127.0.0.1:") else None)
    try:
        yield wrapper
    finally:
        context.close()
    assert wrapper.remote == [], f"the page requested remote resources: {wrapper.remote}"
    assert wrapper.failed == [], f"resources failed to load: {wrapper.failed}"
