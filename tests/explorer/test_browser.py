"""The explorer in a real browser: sliders, links, map clicks, the boundary overlay, audio, bad input, offline.

Every expectation is computed independently with the library (``linearize``
of the same parameters) and compared with what the page renders.
"""

from __future__ import annotations

import math
import time
from urllib.parse import parse_qs, urlparse

import numpy as np
import pytest

from brakesqueal import linearize, resolve_parameters
from brakesqueal.explorer.state import AUDIO_RATE, format_eigenvalue

pytestmark = pytest.mark.slow


def library_leading(sets: list[str]) -> str:
    """The leading eigenvalue of the paper-fig2 point ``sets``, computed directly and formatted as the page does."""
    lam = np.asarray(linearize(resolve_parameters(None, "paper-fig2", None, sets)).eigenvalues)
    top = lam[lam.real == lam.real.max()]
    return format_eigenvalue(complex(top[np.argmax(top.imag)]))


def sets_of(state: dict) -> list[str]:
    return [s for s in state["set"].split(",") if s]


def test_slider_moves_the_leading_eigenvalue(page):
    page.open()
    first = page.wait(lambda s: s["locus"]["state"]["set"] == "")
    assert first["locus"]["leading"] == library_leading([])
    assert page.page.locator("#bs-leading").text_content() == library_leading([])
    handle = page.page.locator(".bs-slider-mu .noUi-handle")
    handle.focus()
    typed = page.page.locator(".bs-input-mu input")
    for _ in range(5):  # each press seen in the typed value before the next (else the state read below can be one
        before = typed.input_value()  # the slider passes on its way, and the link then holds a later one)
        page.page.keyboard.press("ArrowLeft")
        deadline = time.monotonic() + 30  # (the input sits in a shadow root: polled from here)
        while typed.input_value() == before and time.monotonic() < deadline:
            page.page.wait_for_timeout(50)
        assert typed.input_value() != before
    page.wait(lambda s: s["locus"]["state"]["set"] == f"mu={typed.input_value()}")
    value = typed.input_value()
    assert float(value) < 0.5
    shown = page.page.locator("#bs-leading").text_content()
    assert shown == library_leading([f"mu={value}"])
    assert shown != library_leading([])
    # the link holds the state (written once the state rests)
    page.page.wait_for_function("v => new URLSearchParams(location.search).get('set') === v", arg=f"mu={value}",
                                timeout=30_000)
    query = parse_qs(urlparse(page.page.url).query)
    assert query["set"] == [f"mu={value}"] and query["preset"] == ["paper-fig2"]
    page.screenshot("slider")


def test_link_reproduces_the_view(page):
    page.open("preset=paper-fig2&set=mu%3D0.3,k_ip%3D1e7&along=k_ip")
    s = page.wait(lambda s: s["locus"]["state"]["set"] == "mu=0.3,k_ip=1e7")
    assert s["locus"]["state"]["along"] == "k_ip"
    assert page.page.locator(".bs-input-mu input").input_value() == "0.3"
    assert float(page.page.locator(".bs-input-k_ip input").input_value()) == 1e7
    assert page.page.locator("#bs-leading").text_content() == library_leading(["mu=0.3", "k_ip=1e7"])


def test_a_link_made_in_a_session_reproduces_its_map_and_hopf_line(page):
    # found in review: slider ranges (so the map's extent and the Hopf search path) came from the link's values,
    # not from the session's, so the same link showed another map (41.7 % against 25.8 % stable)
    page.open()
    page.wait(lambda s: "map" in s and s["locus"]["state"]["set"] == "")
    box = page.page.locator(".bs-input-mu input")
    box.fill("0.8")
    box.press("Enter")
    # the map does not depend on mu (an axis): it is not recomputed; the Hopf line and critical speed are
    session = page.wait(lambda s: "map" in s and s.get("info_state", {}).get("set") == "mu=0.8" and "hopf" in s)
    page.page.wait_for_function("() => new URLSearchParams(location.search).get('set') === 'mu=0.8'",
                                timeout=30_000)
    link = urlparse(page.page.url).query
    page.open(link)
    linked = page.wait(lambda s: "map" in s and s.get("info_state", {}).get("set") == "mu=0.8" and "hopf" in s)
    assert linked["map"]["stable_fraction"] == session["map"]["stable_fraction"]
    assert linked["map"]["points"] == session["map"]["points"]
    assert linked["hopf"] == session["hopf"] and linked["cs"] == session["cs"]


def test_map_click_moves_every_view(page):
    page.open()
    before = page.wait(lambda s: "map" in s and "cs" in s and "hopf" in s)
    canvas = page.page.locator(".bs-map .bk-Canvas")
    box = canvas.bounding_box()
    page.page.mouse.click(box["x"] + 0.3 * box["width"], box["y"] + 0.75 * box["height"])
    after = page.wait(lambda s: set(dict(v.split("=") for v in sets_of(s["locus"]["state"]))) == {"k_ip", "mu"}
                      and s.get("info_state", {}).get("set") == s["locus"]["state"]["set"])
    values = dict(v.split("=") for v in sets_of(after["locus"]["state"]))
    assert page.page.locator(".bs-input-mu input").input_value() == values["mu"]
    assert page.page.locator(".bs-input-k_ip input").input_value() == values["k_ip"]
    sets = [f"k_ip={values['k_ip']}", f"mu={values['mu']}"]
    assert page.page.locator("#bs-leading").text_content() == library_leading(sets)
    # the marker sits where the click was (map coordinates: log10 k_ip, mu)
    px, py = after["locus"]["point"]
    assert px == pytest.approx(math.log10(float(values["k_ip"])), abs=1e-5)
    assert py == pytest.approx(float(values["mu"]), abs=1e-5)
    # the Hopf line is the one of the new point (its distance to the crossing changed with mu)
    assert after["hopf"] != before["hopf"] or float(values["mu"]) < 0.405
    page.screenshot("map-click")


def test_boundary_overlay_lies_on_the_stability_boundary(page):
    page.open()
    page.wait(lambda s: "map" in s)
    data = page.page.evaluate(
        "() => { const d = Bokeh.documents[0].get_model_by_name('bs-boundary').data;"
        " return {x: Array.from(d.x), y: Array.from(d.y)} }")
    bx, by = np.array(data["x"], dtype=float), np.array(data["y"], dtype=float)
    ok = np.isfinite(bx) & np.isfinite(by)
    assert ok.sum() > 50
    # grid steps of the 400 x 250 map over log10 k_ip in [6, 10] and mu in [0.01, 1]
    hx, hy = 4 / 399 / 2, 0.99 / 249 / 2
    for i in np.flatnonzero(ok)[:: max(1, ok.sum() // 8)]:
        signs = set()
        for dx in (-hx, hx):
            for dy in (-hy, hy):
                sets = [f"k_ip={float(10 ** (bx[i] + dx))!r}", f"mu={float(by[i] + dy)!r}"]
                lam = linearize(resolve_parameters(None, "paper-fig2", None, sets)).eigenvalues
                signs.add(bool(np.max(np.real(lam)) > 0))
        assert signs == {True, False}, f"vertex ({10 ** bx[i]:.6g}, {by[i]:.6g}) is not on the boundary"


def test_audio_has_the_simulated_duration(page):
    page.open("t_end=0.2")
    page.page.get_by_role("button", name="Simulate").click()
    s = page.wait(lambda s: "sim" in s, timeout=600)
    assert "error" not in s["sim"], s["sim"]
    samples = int(math.floor(0.2 * AUDIO_RATE + 1e-9)) + 1
    assert s["sim"]["samples"] == samples
    audio = page.page.locator(".bs-audio audio")
    duration = audio.evaluate("a => new Promise(r => { if (a.readyState >= 1) r(a.duration); "
                              "else a.addEventListener('loadedmetadata', () => r(a.duration)); })")
    assert duration == pytest.approx(samples / AUDIO_RATE, abs=1e-3)
    page.screenshot("simulation")


def test_bad_input_shows_the_message_and_keeps_the_view(page):
    page.open()
    page.wait(lambda s: s["locus"]["state"]["set"] == "")
    box = page.page.locator(".bs-input-mu input")
    box.fill("-1")
    box.press("Enter")
    alert = page.page.locator(".bs-alert")
    message = alert.get_by_text("must be in")
    message.wait_for(timeout=30_000)
    text = message.text_content()
    assert "'mu1'" in text and "[0, inf)" in text
    assert page.page.locator("#bs-leading").text_content() == library_leading([])


@pytest.mark.parametrize("query,expect", [("along=zzz", "zzz"), ("x=N0", "N0"), ("t_end=-1", "t_end"),
                                          ("t_end=nan", "t_end")])
def test_a_bad_link_shows_its_message_and_the_command_lines_view(page, query, expect):
    # found in review: unknown or tied axis names were silently replaced by the defaults, and a bad t_end was
    # only refused at Simulate
    page.open(query)
    s = page.wait(lambda s: "locus" in s)
    assert s["locus"]["state"]["along"] == "mu" and s["locus"]["state"]["t_end"] == "0.5"
    message = page.page.locator(".bs-alert").get_by_text("link:")
    message.wait_for(timeout=30_000)
    assert expect in message.text_content()


def test_caps_are_explained_in_the_page(page):
    page.open("nx=2000&ny=1000")
    s = page.wait(lambda s: "map" in s)
    assert "at most 1,000,000 points" in s["map"]["error"]
    page.page.get_by_text("the explorer computes at most 1,000,000 points").wait_for(timeout=30_000)


def test_cancel_stops_a_simulation(page):
    from _gated_server import GATED_T_END

    # the served explorer holds a run of GATED_T_END seconds at its first progress report until it is
    # cancelled (a real 5 s run can finish before a click under load: CI failed once on that race)
    page.open(f"t_end={GATED_T_END:g}")
    page.page.get_by_role("button", name="Simulate").click()
    page.page.get_by_role("button", name="Cancel").click()
    s = page.wait(lambda s: "sim" in s, timeout=600)
    assert s["sim"].get("error") == "cancelled", s["sim"]
    page.page.get_by_text("simulation: cancelled").wait_for(timeout=30_000)


def test_cancel_stops_the_limit_cycles(page):
    from _gated_server import GATED_OMEGA

    # the served explorer holds the cycles of a state at Omega = GATED_OMEGA at the progress callback the lane
    # passes to the branch, until Cancel makes it raise (the continuation no longer ends with a dropped result)
    page.open(f"preset=paper-fig3&set=mu1%3D0.5,mu2%3D0.5,Omega%3D{GATED_OMEGA:g}&along=Omega")
    page.wait(lambda s: s["locus"]["state"]["along"] == "Omega")
    page.page.get_by_role("button", name="Cycles").click()
    page.page.get_by_text("Cancel stops it").wait_for(timeout=30_000)
    bar = page.page.locator("progress.bs-cycles-progress")
    bar.wait_for(state="visible", timeout=30_000)  # the branch's progress bar, shown while it runs
    page.page.get_by_role("button", name="Cancel").click()
    s = page.wait(lambda s: "cycles" in s, timeout=600)
    assert s["cycles"].get("error") == "cancelled", s["cycles"]
    assert f"Omega={GATED_OMEGA:g}" in s["cycles"]["state"]["set"]
    page.page.get_by_text("limit cycles: cancelled").wait_for(timeout=30_000)
    bar.wait_for(state="hidden", timeout=30_000)


def test_limit_cycles_end_at_the_contact_loss(page):
    # paper-fig3 at mu1 = mu2 = 0.5 along Omega in [30, 40]: supercritical onset at 35.74 rad/s (hopf, cycles)
    page.open("preset=paper-fig3&set=mu1%3D0.5,mu2%3D0.5,Omega%3D36&along=Omega")
    page.wait(lambda s: s["locus"]["state"]["along"] == "Omega")
    page.page.get_by_role("button", name="Cycles").click()
    s = page.wait(lambda s: "cycles" in s, timeout=900)
    assert "error" not in s["cycles"], s["cycles"]
    from brakesqueal import resolve_space
    from brakesqueal import Axis
    from brakesqueal.explorer.state import slider_range
    from brakesqueal import hopf_points

    space = resolve_space(None, "paper-fig3", None, ["mu1=0.5", "mu2=0.5", "Omega=36"])
    rng = slider_range(space, "Omega")
    onset = next(h for h in hopf_points(space, Axis("Omega", rng.low, rng.high, 2, rng.log)) if h.hopf is not None)
    assert f"{onset.hopf.p0:.6g}" in s["cycles"]["summary"]
    # k_ip = 1e8 is finite: the pads would be quasi-static in the simulated equations, so the view continues the
    # cycles with their rates kept (harmonic balance, as `brakesqueal cycles`) and says so
    assert onset.simulated is not None and "exact pads" in s["cycles"]["summary"]
    assert s["cycles"]["points"] >= 3
    from brakesqueal import harmonic_branch

    hb = harmonic_branch(space, Axis("Omega", rng.low, rng.high, 2, rng.log), max_points=25, max_harmonics=40)
    assert hb.contact_loss is not None and s["cycles"]["contact_loss"] == pytest.approx(hb.contact_loss, rel=1e-9)
    assert s["cycles"]["contact_loss"] > onset.hopf.p0
    page.screenshot("cycles")


def test_region_draws_the_hopf_curves_over_the_map(page):
    # paper-fig3's map (Omega, mu1): one Hopf curve, supercritical at low speed, subcritical beyond its
    # generalised-Hopf point; the page draws what `brakesqueal region` computes over the same box
    page.open("preset=paper-fig3&nx=6&ny=5")
    page.wait(lambda s: "map" in s and s["map"].get("points") == 30, timeout=600)
    page.page.get_by_role("button", name="Region").click()
    s = page.wait(lambda s: "region" in s, timeout=900)
    assert "error" not in s["region"], s["region"]
    assert s["region"]["curves"] >= 1 and "GH" in s["region"]["special_points"]
    page.page.get_by_text("squeal region:").wait_for(timeout=30_000)
    from brakesqueal import Axis, region_diagram, resolve_space
    from brakesqueal.explorer.state import slider_range

    space = resolve_space(None, "paper-fig3", None, [])
    rx, ry = slider_range(space, "Omega"), slider_range(space, "mu1")
    r = region_diagram(space, Axis("Omega", rx.low, rx.high, 2, rx.log),
                       Axis("mu1", ry.low, ry.high, 2, ry.log), grid=None)
    assert s["region"]["curves"] == len(r.curves)
    assert sorted(s["region"]["special_points"]) == sorted(sp.type for c in r.curves for sp in c.special_points)
    page.screenshot("region")
