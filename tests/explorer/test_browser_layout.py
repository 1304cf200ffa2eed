"""The explorer's page at an engineer's laptop width: 1280 px, no horizontal scroll (issue 29)."""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.slow

#: The viewport of a 1280 px wide laptop screen.
VIEWPORT = {"width": 1280, "height": 800}


def test_page_fits_1280_px(page):
    page.page.set_viewport_size(VIEWPORT)
    page.open()
    # the map and the simulation's views (built once the page has loaded) are the widest rows
    page.wait(lambda s: "map" in s)
    page.page.wait_for_selector(".bs-audio", state="attached", timeout=60_000)
    page.page.wait_for_timeout(500)  # the last layout pass
    width = page.page.evaluate("() => document.documentElement.scrollWidth")
    client = page.page.evaluate("() => document.documentElement.clientWidth")
    assert width <= VIEWPORT["width"], f"the page is {width} px wide"
    assert width <= client, f"horizontal scroll: {width} px of content in a {client} px window"
    page.screenshot("1280")
