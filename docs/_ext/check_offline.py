"""Check that a built HTML site works offline: no page loads anything from the network.

Run by ``make docs`` after Sphinx (``python docs/_ext/check_offline.py docs/_build/html``).  It fails
(exit status 1, one line per offending reference) when

* an HTML page loads a resource from a non-local URL: ``<script src>``, ``<link href>`` (stylesheets,
  fonts, icons, preloads, manifests), ``<img>``/``<source>``/``<iframe>``/``<embed>``/``<audio>``/``<video>``
  ``src``, ``<object data>``, or an ``@import``/``url(...)`` in a ``<style>`` block or ``style`` attribute;
* a stylesheet under the site's ``_static`` imports a stylesheet or a font from a non-local URL;
* a page that typesets mathematics does not load MathJax from the site's own ``_static`` folder.

A URL is non-local when it has a scheme other than ``data:``/``blob:``/``file:``, or starts with ``//``
(protocol-relative).  Hyperlinks (``<a href>``) are not resources and are not checked: following one is
the reader's choice.
"""

from __future__ import annotations

import re
import sys
from html.parser import HTMLParser
from pathlib import Path

#: (tag, attribute) pairs whose URL the browser fetches while showing the page.
RESOURCE_ATTRS = {
    ("script", "src"),
    ("link", "href"),
    ("img", "src"),
    ("img", "srcset"),
    ("source", "src"),
    ("source", "srcset"),
    ("iframe", "src"),
    ("embed", "src"),
    ("audio", "src"),
    ("video", "src"),
    ("video", "poster"),
    ("track", "src"),
    ("object", "data"),
    ("input", "src"),
}
_LOCAL_SCHEMES = ("data:", "blob:", "file:")
_SCHEME = re.compile(r"^[a-zA-Z][a-zA-Z0-9+.-]*:")
_CSS_URL = re.compile(r"""(?:url\(\s*['"]?|@import\s+['"])([^'")\s]+)""")


def is_remote(url: str) -> bool:
    """True when the browser would fetch ``url`` from the network."""
    url = url.strip()
    if url.startswith("//"):
        return True
    if _SCHEME.match(url):
        return not url.lower().startswith(_LOCAL_SCHEMES)
    return False


class _Resources(HTMLParser):
    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.urls: list[tuple[int, str, str]] = []  # (line, what, url)
        self.scripts: list[str] = []
        self._in_style = False

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        line = self.getpos()[0]
        for name, value in attrs:
            if value is None:
                continue
            if (tag, name) in RESOURCE_ATTRS:
                urls = [part.split()[0] for part in value.split(",") if part.split()] if name == "srcset" else [value]
                self.urls.extend((line, f"<{tag} {name}>", u) for u in urls)
                if tag == "script":
                    self.scripts.append(value)
            elif name == "style":
                self.urls.extend((line, f"<{tag} style>", u) for u in _CSS_URL.findall(value))
        self._in_style = tag == "style"

    def handle_endtag(self, tag: str) -> None:
        if tag == "style":
            self._in_style = False

    def handle_data(self, data: str) -> None:
        if self._in_style:
            line = self.getpos()[0]
            self.urls.extend((line, "<style>", u) for u in _CSS_URL.findall(data))


_MATH = re.compile(r'class="[^"]*\bmath\b')


def check_site(root: Path) -> list[str]:
    """Every problem found under the built site ``root`` (empty when it works offline)."""
    problems: list[str] = []
    pages = sorted(root.rglob("*.html"))
    if not pages:
        return [f"{root}: no HTML pages (build the site first)"]
    for page in pages:
        text = page.read_text(encoding="utf-8", errors="replace")
        parser = _Resources()
        parser.feed(text)
        rel = page.relative_to(root)
        for line, what, url in parser.urls:
            if is_remote(url):
                problems.append(f"{rel}:{line}: {what} loads {url}")
        if _MATH.search(text) and not any("mathjax" in s.lower() and not is_remote(s) for s in parser.scripts):
            problems.append(f"{rel}: typesets mathematics but loads no local MathJax")
    for css in sorted(root.rglob("*.css")):
        text = css.read_text(encoding="utf-8", errors="replace")
        for m in _CSS_URL.finditer(text):
            if is_remote(m[1]):
                line = text.count("\n", 0, m.start()) + 1
                problems.append(f"{css.relative_to(root)}:{line}: stylesheet loads {m[1]}")
    return problems


def main(argv: list[str] | None = None) -> int:
    """Check the site given as the only argument (default ``docs/_build/html``); print the problems."""
    args = sys.argv[1:] if argv is None else argv
    root = Path(args[0] if args else "docs/_build/html")
    problems = check_site(root)
    for p in problems:
        print(f"check_offline: {p}", file=sys.stderr)
    if problems:
        print(f"check_offline: {len(problems)} network reference(s): the site would not work offline", file=sys.stderr)
        return 1
    n_pages = sum(1 for _ in root.rglob("*.html"))
    print(f"check_offline: {n_pages} pages load nothing from the network")
    return 0


if __name__ == "__main__":
    sys.exit(main())
