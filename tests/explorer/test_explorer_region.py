"""The explorer's squeal-region view (issue 28, item 3): the Hopf curves over the map, coloured by criticality,
with the codimension-2 points, checked against independent computations rather than against the diagram itself:
every drawn point of a Hopf curve is a point where the exact linearization has a pair of eigenvalues on the
imaginary axis, and the colour of a piece is the criticality ``brakesqueal hopf`` finds on a path through it."""

from __future__ import annotations

import time

import numpy as np
import pytest

from brakesqueal import resolve_space
from brakesqueal.explorer.state import Origin

pytestmark = pytest.mark.slow  # continues the Hopf curves of paper-fig3 over the whole map (~10 s), twice


def _wait(predicate, timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.05)
    return False


@pytest.fixture(scope="module")
def explorer():
    from brakesqueal.explorer import app

    ex = app.Explorer(Origin(resolve_space(None, "paper-fig3", None, [])), {"nx": "6", "ny": "5"})
    assert _wait(lambda: "map" in ex.shown, 180), ex.shown
    assert (ex.state.x, ex.state.y) == ("Omega", "mu1") and ex._map_logs == (True, False)
    ex._on_region(None)
    assert _wait(lambda: "region" in ex.shown, 300), ex.shown
    yield ex
    ex.stop()


def test_the_hopf_curves_lie_where_the_linearization_has_imaginary_eigenvalues(explorer):
    from brakesqueal.api import linearize

    ex = explorer
    assert "error" not in ex.shown["region"], ex.shown["region"]
    xs, ys = ex.src_hopf.data["xs"], ex.src_hopf.data["ys"]
    assert xs and all(len(a) == len(b) >= 2 for a, b in zip(xs, ys))
    space = ex.origin.space_of(ex.state)
    rng = np.random.default_rng(3)
    checked = 0
    for a, b in zip(xs, ys):
        for k in rng.choice(len(a), size=min(3, len(a)), replace=False):
            omega, mu1 = 10.0 ** float(a[k]), float(b[k])  # the map's x axis (Omega) is logarithmic
            lam = linearize(space.resolve({"Omega": omega, "mu1": mu1})).eigenvalues
            top = lam[np.argmax(lam.real)]
            assert abs(top.real) < 1e-6 * abs(top), (omega, mu1, top)
            checked += 1
    assert checked >= 3


def test_the_colours_are_the_criticality_found_on_a_path_through_the_curve(explorer):
    from brakesqueal.analysis.maps import Axis
    from brakesqueal.api_nonlinear import hopf_points

    ex = explorer
    shown = ex.shown["region"]
    assert "GH" in shown["special_points"]  # the generalised-Hopf point splits the curve into two criticalities
    colours = set(ex.src_hopf.data["color"])
    assert {"#1f77b4", "#d62728"} <= colours, colours
    space = ex.origin.space_of(ex.state)
    checked = set()
    for a, b, colour in zip(ex.src_hopf.data["xs"], ex.src_hopf.data["ys"], ex.src_hopf.data["color"]):
        if len(a) < 3 or colour not in ("#1f77b4", "#d62728"):
            continue
        k = len(a) // 2
        omega, mu1 = 10.0 ** float(a[k]), float(b[k])
        pts = hopf_points(space.with_values({"Omega": omega}), Axis("mu1", mu1 - 0.02, mu1 + 0.02, 2))
        near = [p for p in pts if p.hopf is not None]
        assert near, (omega, mu1)
        crit = min(near, key=lambda p: abs(p.value - mu1)).hopf.criticality
        assert crit == ("supercritical" if colour == "#1f77b4" else "subcritical"), (omega, mu1, crit, colour)
        checked.add(crit)
    assert checked == {"supercritical", "subcritical"}, checked


def test_contact_loss_points_of_the_fold_slices_are_drawn_where_the_diagram_puts_them(explorer):
    ex = explorer
    pts = [p for c in ex._region_data["fold_curves"] for p in c["points"] if p["kind"] == "contact_loss"]
    assert pts and ex.shown["region"]["contact_loss_points"] == len(pts)
    np.testing.assert_allclose(10.0 ** np.asarray(ex.src_contact.data["x"]), [p["Omega"] for p in pts], rtol=1e-12)
    np.testing.assert_allclose(ex.src_contact.data["y"], [p["mu1"] for p in pts], rtol=1e-12)


def test_other_axes_clear_the_region(explorer):
    ex = explorer
    assert ex.src_hopf.data["xs"]
    assert "mu2" in ex.y_select.options, ex.y_select.options
    ex.y_select.value = "mu2"
    assert _wait(lambda: ex.shown.get("map", {}).get("state", {}).get("y") == "mu2", 180), ex.shown.get("map")
    assert ex.src_hopf.data["xs"] == [] and ex.src_special.data["x"] == []
