"""The explorer measured in a real browser: start-up, slider → root locus, a 1e5-point map view.

Needs Panel, Playwright and Debian's ``chromium``; therefore it is not a
``bench_*.py`` script (``make bench`` does not run it): run it with
``make bench-explorer`` or ``.venv/bin/python benchmarks/browser_explorer.py``.

* **start**: from launching ``brakesqueal explore`` to the first leading
  eigenvalue rendered in the page (the second of two launches, so the code
  caches are warm; the first is reported too).
* **slider → root locus**: 50 moves of the ``mu`` slider (arrow keys on its
  handle, alternating directions) with the root locus along ``mu``, each
  timed from the key press to the render counter showing the eigenvalues
  and root locus of the new value, plus two animation frames (the canvas
  repainted); p50 and p95.  The path along ``mu`` does not depend on the
  current ``mu``, so it is reused and only the current eigenvalues move.
  Then 20 moves of ``mu`` with the root locus along ``k_ip``, which must be
  recomputed (60 linearizations and the mode tracking) on every move.
* **map view**: 5 changes of a fixed parameter (``d_t``), each timed from
  the typed value to the re-computed 400 x 250 = 1e5-point map rendered.

Baselines, from the same process: the library's own computation of the
same root locus (:func:`brakesqueal.explorer.state.locus_view`) and map
(:func:`brakesqueal.explorer.state.map_view`); the ratios are the cost of
serving, transferring and drawing.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, best_time, emit, user_env  # noqa: E402

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
FRAMES = "() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))"


def _port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _shown(page: Any) -> tuple[int, dict[str, Any]]:
    el = page.locator("#bs-render")
    return int(el.get_attribute("data-count") or 0), json.loads(el.get_attribute("data-shown") or "{}")


#: In-page helpers: the render element (inside Panel's shadow roots, found once per root) and its state.
HELPERS = """
window.__bsFind = () => { const stack = [document]; while (stack.length) { const r = stack.pop();
  if (r.querySelector('#bs-render')) return r;
  for (const e of r.querySelectorAll('*')) if (e.shadowRoot) stack.push(e.shadowRoot); } return null; };
window.__bsShown = () => { let r = window.__bsRoot; let el = r && r.querySelector('#bs-render');
  if (!el) { r = window.__bsRoot = window.__bsFind(); el = r && r.querySelector('#bs-render'); }
  return el ? JSON.parse(el.dataset.shown) : {}; };
"""


def _wait_js(page: Any, predicate: str, arg: Any, timeout: float = 300.0) -> None:
    """Wait in the page (polling every 2 ms, no round trips) until ``predicate(shown, arg)`` holds."""
    page.wait_for_function(f"a => {{ const s = window.__bsShown(); try {{ return ({predicate})(s, a); }} "
                           "catch (e) { return false; } }", arg=arg, polling=2, timeout=timeout * 1000)


def _wait(page: Any, pred: Any, timeout: float = 300.0) -> dict[str, Any]:
    deadline = time.monotonic() + timeout
    while True:
        try:
            _, s = _shown(page)
            if pred(s):
                return s
        except Exception:  # the element is not there yet
            pass
        if time.monotonic() > deadline:
            raise TimeoutError("the page did not reach the expected state")
        time.sleep(0.001)


def _launch(browser: Any) -> tuple[Any, Any, float, float]:
    """Start the server, open a page; return (process, page, seconds to listen, seconds to first view)."""
    port = _port()
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "brakesqueal", "explore", "--no-browser", "--port", str(port)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=user_env())
    while True:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
            break
        except OSError:
            time.sleep(0.01)
    t_listen = time.perf_counter() - t0
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    page.add_init_script(HELPERS)
    page.route("**/*", lambda r: r.continue_() if r.request.url.startswith(("http://127.0.0.1", "ws://127.0.0.1",
                                                                             "data:", "blob:")) else r.abort())
    page.goto(f"http://127.0.0.1:{port}/")
    _wait(page, lambda s: "locus" in s)
    page.evaluate(FRAMES)
    return proc, page, t_listen, time.perf_counter() - t0


def main() -> int:
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        print("skipped: playwright is not installed (pip install -e '.[test]')")
        return 0
    if not Path(CHROMIUM).exists():
        print("skipped: chromium is not installed (apt-get install chromium)")
        return 0
    from brakesqueal import resolve_space
    from brakesqueal.explorer.state import locus_view, map_view, slider_range

    load_start = [round(x, 2) for x in os.getloadavg()]

    space = resolve_space(None, "paper-fig2", None, [])
    r_mu, r_k = slider_range(space, "mu"), slider_range(space, "k_ip")
    locus_view(space, "mu", r_mu)
    base_locus = best_time(lambda: locus_view(space, "mu", r_mu), repeat=5)
    map_view(space, "k_ip", "mu", r_k, r_mu, 400, 250)
    base_map = best_time(lambda: map_view(space, "k_ip", "mu", r_k, r_mu, 400, 250), repeat=3)
    results: list[BenchResult] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        starts = []
        for _ in range(2):
            proc, page, t_listen, t_view = _launch(browser)
            starts.append((t_listen, t_view))
            if len(starts) < 2:
                page.close()
                proc.terminate()
                proc.wait()
        try:
            _wait(page, lambda s: "map" in s and "info_state" in s)
            handle = page.locator(".bs-slider-mu .noUi-handle")
            handle.focus()
            lat = []
            for i in range(50):
                before = _shown(page)[1]["locus"]["state"]["set"]
                t0 = time.perf_counter()
                page.keyboard.press("ArrowRight" if (i // 25) % 2 == 0 else "ArrowLeft")
                _wait_js(page, "(s, b) => s.locus.state.set !== b", before)
                page.evaluate(FRAMES)
                lat.append(time.perf_counter() - t0)
            # a slider whose change moves the whole root locus (the path along k_ip depends on mu)
            page.goto(page.url.split("?")[0] + "?along=k_ip")
            _wait(page, lambda s: s.get("locus", {}).get("tracks_state", {}).get("along") == "k_ip")
            page.locator(".bs-slider-mu .noUi-handle").focus()
            lat2 = []
            for i in range(20):
                before = _shown(page)[1]["locus"]["state"]["set"]
                t0 = time.perf_counter()
                page.keyboard.press("ArrowRight" if (i // 10) % 2 == 0 else "ArrowLeft")
                _wait_js(page, "(s, b) => s.locus.state.set !== b && s.locus.tracks_state.set === s.locus.state.set",
                         before)
                page.evaluate(FRAMES)
                lat2.append(time.perf_counter() - t0)
            page.get_by_text("fixed parameters").click()  # open the card of the fixed parameters
            box = page.locator(".bs-input-d_t input")
            maps = []
            for i in range(5):
                value = f"{0.1 + 0.01 * (i + 1):.2f}"
                box.fill(value)
                t0 = time.perf_counter()
                box.press("Enter")
                _wait_js(page, "(s, v) => s.map.state.set.includes(v)", f"d_t={value}")
                page.evaluate(FRAMES)
                maps.append(time.perf_counter() - t0)
            points = _shown(page)[1]["map"]["points"]
        finally:
            proc.terminate()
            proc.wait()
            browser.close()
    lat_ms = np.array(lat) * 1e3
    p95 = float(np.percentile(lat_ms, 95))
    results.append(BenchResult("explorer start to first view (warm caches)", starts[1][1], "s",
                               details={"listening after [s]": round(starts[1][0], 3),
                                        "first launch [s]": round(starts[0][1], 3), "target [s]": 3}))
    results.append(BenchResult("slider -> root locus, p95 of 50 moves", p95, "ms", base_locus * 1e3,
                               p95 / (base_locus * 1e3),
                               details={"p50 [ms]": round(float(np.median(lat_ms)), 1),
                                        "max [ms]": round(float(lat_ms.max()), 1), "target [ms]": 100,
                                        "baseline": "locus_view in-process (60 linearizations + tracking)"}))
    lat2_ms = np.array(lat2) * 1e3
    p95b = float(np.percentile(lat2_ms, 95))
    results.append(BenchResult("slider -> recomputed root locus (path along k_ip, mu moved), p95 of 20 moves", p95b,
                               "ms", base_locus * 1e3, p95b / (base_locus * 1e3),
                               details={"p50 [ms]": round(float(np.median(lat2_ms)), 1),
                                        "baseline": "locus_view in-process"}))
    best_map = min(maps)
    results.append(BenchResult(f"map view, {points:,} points", float(np.median(maps)), "s", base_map,
                               float(np.median(maps)) / base_map,
                               details={"best [s]": round(best_map, 3), "target [s]": 1,
                                        "baseline": "map_view in-process (stability_map + refined boundary)"}))
    load = [round(x, 2) for x in os.getloadavg()]  # the machine may be shared: compare runs at similar loads
    for r in results:
        r.details["load average (1, 5, 15 min) at start / end"] = f"{load_start} / {load}"
        if not math.isfinite(r.value):
            return 1
    emit(results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
