"""Check that a built HTML site reads well at 1280 px and on a phone, in a real browser.

Run by ``make docs`` after Sphinx (``python docs/_ext/check_layout.py docs/_build/html``).  Every page is
loaded in headless chromium (Debian's ``chromium``, driven by Playwright as in the explorer's browser tests)
at 1280 x 900 px and at 390 x 844 px (a phone), and the check fails (exit status 1, one line per problem)
when

* the top bar is more than one row high (taller than :data:`MAX_NAVBAR_PX`);
* the left sidebar is shown without a link in it, or a page inside a section (its breadcrumbs name a
  parent page) has no sidebar listing the section's pages (at 1280 px);
* content is cut off: a code block, table, display equation, image, heading, paragraph or notebook output
  is wider than its box and hides the rest (``overflow-x`` ``hidden`` or ``clip``); any element of the
  text column, or its overflowing content, reaches past the column without a box around it that scrolls;
  or the page itself scrolls sideways;
* a command of the gallery (a ``console`` code block of ``gallery.html``, :data:`COMMANDS`) does not fit its
  box: the gallery's commands wrap (``div.bs-command``, ``_static/brakesqueal.css``), so that each is read
  whole without scrolling.

Without Playwright or chromium the check says why and passes, unless ``BRAKESQUEAL_REQUIRE_BROWSER=1``
(set by CI's ``.ci/run``), when that is a failure.
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path
from typing import Any

#: (name, width, height) of the viewports every page is checked at.
VIEWPORTS = [("1280 px", 1280, 900), ("phone", 390, 844)]
#: Height of a one-row top bar (pydata-sphinx-theme's is 64 px; two rows are more than 100).
MAX_NAVBAR_PX = 80
#: Slack for sub-pixel rounding.
EPS = 1

CHROMIUM = os.environ.get("BRAKESQUEAL_CHROMIUM") or shutil.which("chromium") or "/usr/bin/chromium"

#: Runs in the page; returns the measurements the checks need.
MEASURE = r"""
async ([sel, commands]) => {
  // measure the page as read: after MathJax has typeset it (inline formulas do not wrap)
  if (window.MathJax && MathJax.startup && MathJax.startup.promise) await MathJax.startup.promise;
  const visible = (el) => {
    if (!el) return false;
    const st = getComputedStyle(el);
    if (st.display === 'none' || st.visibility === 'hidden') return false;
    const r = el.getBoundingClientRect();
    return r.width > 0 && r.height > 0;
  };
  const describe = (el) => {
    const text = (el.textContent || el.getAttribute('src') || '').trim().replace(/\s+/g, ' ');
    return el.tagName.toLowerCase() + (el.className && typeof el.className === 'string' ? '.' +
      el.className.trim().split(/\s+/).join('.') : '') + ' "' + text.slice(0, 50) + '"';
  };
  const out = {};
  const header = document.querySelector('.bd-header');
  out.navbar = visible(header) ? header.getBoundingClientRect().height : null;
  const side = document.querySelector('#pst-primary-sidebar');
  out.sidebar = visible(side) ? side.querySelectorAll('.bd-docs-nav a[href]').length : null;
  out.parents = document.querySelectorAll(
    '.bd-breadcrumbs li.breadcrumb-item:not(.breadcrumb-home):not(.active)').length;
  out.pageWidth = document.documentElement.scrollWidth;
  out.viewport = window.innerWidth;
  const column = document.querySelector('article.bd-article');
  const right = column ? column.getBoundingClientRect().right : window.innerWidth;
  out.cut = [];
  out.outside = [];
  // does the element, or a box around it inside the column, scroll sideways? (cached per element)
  const scrolls = new Map();
  const inScroller = (el) => {
    if (!el || el === column) return false;
    if (!scrolls.has(el))
      scrolls.set(el, ['auto', 'scroll'].includes(getComputedStyle(el).overflowX) || inScroller(el.parentElement));
    return scrolls.get(el);
  };
  const candidates = [];
  for (const el of column ? column.querySelectorAll('*') : []) {
    if (!visible(el) || el.closest('mjx-container')) continue;  // MathJax's own boxes: div.math scrolls
    const st = getComputedStyle(el);
    if (el.clientWidth > 0 && el.scrollWidth > el.clientWidth + 1 && ['hidden', 'clip'].includes(st.overflowX)
        && el.matches(sel))
      out.cut.push(describe(el) + ' (' + el.scrollWidth + ' px in ' + el.clientWidth + ' px, overflow-x ' +
                   st.overflowX + ')');
    if (!inScroller(el.parentElement)) candidates.push([el, st]);  // else the reader scrolls to it
  }
  // an element whose box reaches past the column (the outermost one of a nest), then text that does
  const boxes = [];
  for (const [el, st] of candidates) {
    const r = el.getBoundingClientRect();
    if (r.right > right + 1 && !boxes.some((b) => b.contains(el))) {
      boxes.push(el);
      out.outside.push(describe(el) + ' (right edge ' + Math.round(r.right) + ' px, column ends at ' +
                       Math.round(right) + ' px)');
    }
  }
  const texts = [];
  for (const [el, st] of candidates) {
    if (st.overflowX !== 'visible' || el.clientWidth === 0) continue;
    const reach = el.getBoundingClientRect().left + el.scrollWidth;
    if (reach > right + 1 && !boxes.some((b) => el.contains(b) || b.contains(el))
        && !texts.some((t) => t.contains(el) || el.contains(t))) {
      // report the innermost block whose own text runs past: drop an ancestor reported before it
      for (let i = texts.length - 1; i >= 0; i--) if (texts[i].contains(el)) texts.splice(i, 1);
      texts.push(el);
    }
  }
  for (const el of texts)
    out.outside.push(describe(el) + ' (its text reaches ' + Math.round(el.getBoundingClientRect().left +
                     el.scrollWidth) + ' px, column ends at ' + Math.round(right) + ' px)');
  out.commands = [];
  for (const el of commands ? document.querySelectorAll(commands) : []) {
    if (visible(el) && el.scrollWidth > el.clientWidth + 1)
      out.commands.push(describe(el) + ' (' + el.scrollWidth + ' px in ' + el.clientWidth + ' px)');
  }
  return out;
}
"""

#: Pages whose command blocks (CSS selector) must fit their box, not scroll.
COMMANDS = {"gallery.html": "div.highlight-console pre"}
#: Elements whose content must not be cut off (hidden overflow) when it is wider than their box; any element of
#: the text column must stay inside it unless a box around it scrolls.
CONTENT = "pre, table, div.math, img, svg, div.cell_output, h1, h2, h3, h4, p, li, dt, dd, td, th, code"


def browser_missing() -> str | None:
    """Why the check cannot run here, or None."""
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError as exc:
        return f"the layout check needs playwright (pip install -e '.[test]'): {exc}"
    if not (os.path.isfile(CHROMIUM) and os.access(CHROMIUM, os.X_OK)):
        return "chromium is not installed (apt-get install chromium); the layout check needs it"
    return None


def problems_of(m: dict[str, Any], viewport: str) -> list[str]:
    """The problems of one page at one viewport, from the measurements of :data:`MEASURE`."""
    out: list[str] = []
    if m["navbar"] is not None and m["navbar"] > MAX_NAVBAR_PX:
        out.append(f"the top bar is {m['navbar']:.0f} px high: more than one row (at most {MAX_NAVBAR_PX} px)")
    if viewport == VIEWPORTS[0][0]:
        if m["sidebar"] == 0:
            out.append("the left sidebar is shown but has no link in it")
        elif m["sidebar"] is None and m["parents"] >= 1:
            out.append("the page is inside a section but has no sidebar listing the section's pages")
    if m["pageWidth"] > m["viewport"] + EPS:
        out.append(f"the page scrolls sideways: {m['pageWidth']} px wide in a {m['viewport']} px window")
    out += [f"content cut off without a scroll bar: {c}" for c in m["cut"]]
    out += [f"sticks out of the text column: {c}" for c in m["outside"]]
    out += [f"gallery command does not fit its box: {c}" for c in m["commands"]]
    return out


def check_site(site: Path, pages: list[Path] | None = None) -> list[str]:
    """One line per problem of the pages (default: every ``*.html`` of ``site``) at every viewport."""
    from playwright.sync_api import sync_playwright

    pages = sorted(site.rglob("*.html")) if pages is None else pages
    lines: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        try:
            tab = browser.new_page(viewport={"width": VIEWPORTS[0][1], "height": VIEWPORTS[0][2]})
            # the site must not fetch anything (check_offline.py checks the HTML); do not wait on the network
            tab.route("http*://**", lambda route: route.abort())
            for page in pages:
                tab.set_viewport_size({"width": VIEWPORTS[0][1], "height": VIEWPORTS[0][2]})
                tab.goto(page.resolve().as_uri(), wait_until="load")
                commands = COMMANDS.get(page.relative_to(site).as_posix(), "")
                for name, width, height in VIEWPORTS:  # one load, laid out again at each size
                    tab.set_viewport_size({"width": width, "height": height})
                    m = tab.evaluate(MEASURE, [CONTENT, commands])
                    lines += [f"{page.relative_to(site)} ({name}): {msg}" for msg in problems_of(m, name)]
        finally:
            browser.close()
    return lines


def main(argv: list[str]) -> int:
    """``check_layout.py SITE``: exit status 0 when every page reads well, 1 otherwise (or on bad use)."""
    if len(argv) != 2 or not Path(argv[1]).is_dir():
        print("usage: check_layout.py BUILT_HTML_DIR (a folder)", file=sys.stderr)
        return 2
    why = browser_missing()
    if why:
        if os.environ.get("BRAKESQUEAL_REQUIRE_BROWSER") == "1":
            print(f"check_layout: BRAKESQUEAL_REQUIRE_BROWSER=1 but {why}", file=sys.stderr)
            return 1
        print(f"check_layout: skipped: {why}")
        return 0
    site = Path(argv[1])
    pages = sorted(site.rglob("*.html"))
    lines = check_site(site, pages)
    for line in lines:
        print(f"check_layout: {line}", file=sys.stderr)
    if lines:
        return 1
    print(f"check_layout: {len(pages)} pages read well at {' and '.join(v[0] for v in VIEWPORTS)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
