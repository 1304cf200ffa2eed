"""Two-parameter squeal regions (issue 28): Hopf curves on the stability boundary, l1 along them, codim-2
points, the ``region`` command and its bad input."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import brakesqueal as bs
from brakesqueal.analysis.maps import Axis
from brakesqueal.cli import main
from brakesqueal.errors import ParameterError
from brakesqueal.region import hopf_curves

FIG2 = {"k_ip": math.inf}
X2, Y2 = Axis("mu", 0.05, 1.0), Axis("Omega", 10.0, 200.0)
# Fig. 3's set with mu2 = 0.5: one Hopf curve in (mu1, Omega), supercritical below, subcritical above (the upper
# re-stabilisation), with a generalised-Hopf point between
FIG3 = {"k_ip": math.inf, "mu2": 0.5}
X3, Y3 = Axis("mu1", 0.0, 1.0), Axis("Omega", 10.0, 20000.0, log=True)


def _space(preset: str, sets: dict[str, float]):
    return bs.resolve_space(preset=preset, sets=sets)


@pytest.fixture(scope="module")
def fig2_curve():
    space = _space("paper-fig2", FIG2)
    curves = hopf_curves(bs.engine(space), space, X2, Y2)
    assert len(curves) == 1
    return curves[0]


@pytest.fixture(scope="module")
def fig3_curve():
    space = _space("paper-fig3", FIG3)
    curves = hopf_curves(bs.engine(space), space, X3, Y3)
    assert len(curves) == 1
    return curves[0]


def _on_boundary(space, x: Axis, y: Axis, p) -> None:
    """Independent check through ``crossings``: a path in y at the point's x (and one in x at its y) has exactly
    one stability change in a narrow window around the point, at the point's value."""
    for fixed, path, value, other in ((x.name, y.name, p.y, p.x), (y.name, x.name, p.x, p.y)):
        width = 1e-3 * abs(value)
        r = bs.crossings(space.with_values({fixed: other}), Axis(path, value - width, value + width))
        assert len(r.crossings) == 1, (fixed, other, path, value, r.crossings)
        assert abs(r.crossings[0][0] - value) <= 1e-9 * abs(value), (path, value, r.crossings[0][0])


def test_curve_points_lie_on_the_stability_boundary(fig2_curve):
    """Random points of the (mu, Omega) Hopf curve of Fig. 2's set are exact crossings along both axes."""
    space = _space("paper-fig2", FIG2)
    rng = np.random.default_rng(28)
    pts = fig2_curve.points
    assert len(pts) >= 20 and all(p.residual <= 1e-12 for p in pts)
    for k in rng.choice(len(pts), size=6, replace=False):
        _on_boundary(space, X2, Y2, pts[int(k)])
    # the curve runs from edge to edge of the box: mu = 1 (bottom right) to Omega = 200 (top)
    assert fig2_curve.ends == ("edge of the box", "edge of the box")
    ends = {(round(p.x, 12), round(p.y, 9)) for p in (pts[0], pts[-1])}
    at_mu1 = bs.crossings(space.with_values({"mu": 1.0}), Y2).crossings[0][0]
    at_top = bs.crossings(space.with_values({"Omega": 200.0}), X2).crossings[0][0]
    got = sorted(ends)
    assert got[0][0] == pytest.approx(at_top, rel=1e-9) and got[0][1] == pytest.approx(200.0, rel=1e-12)
    assert got[1][0] == pytest.approx(1.0, rel=1e-12) and got[1][1] == pytest.approx(at_mu1, rel=1e-9)


def test_l1_along_the_curve_agrees_with_hopf_points(fig3_curve):
    """At points on both sides of the generalised-Hopf point the sign of l1 is that of the pointwise ``hopf``
    (a path in Omega through the point), and the points are on the boundary."""
    space = _space("paper-fig3", FIG3)
    pts = fig3_curve.points
    kinds = {p.criticality for p in pts}
    assert {"supercritical", "subcritical"} <= kinds
    rng = np.random.default_rng(3)
    sub = [i for i, p in enumerate(pts) if p.criticality == "subcritical"]
    sup = [i for i, p in enumerate(pts) if p.criticality == "supercritical"]
    for k in [*rng.choice(sub, 2, replace=False), *rng.choice(sup, 2, replace=False)]:
        p = pts[int(k)]
        _on_boundary(space, X3, Y3, p)
        hp = bs.hopf_points(space.with_values({"mu1": p.x}), Axis("Omega", p.y * 0.999, p.y * 1.001))
        assert len(hp) == 1 and hp[0].hopf is not None
        assert np.sign(hp[0].hopf.l1) == np.sign(p.l1), (p, hp[0].hopf.l1)
        assert hp[0].hopf.l1 == pytest.approx(p.l1, rel=1e-6)


def test_generalised_hopf_point_is_where_l1_vanishes(fig3_curve):
    """The GH point lies on the boundary, between the super- and subcritical parts, with l1 ~ 0 there."""
    from brakesqueal.nonlinear.implicit import exact_lyapunov

    space = _space("paper-fig3", FIG3)
    gh = [s for s in fig3_curve.special_points if s.type == "GH"]
    assert len(gh) == 1
    g = gh[0]
    _on_boundary(space, X3, Y3, g)
    scale = max(abs(p.l1) for p in fig3_curve.points if p.l1 is not None)
    eng = bs.engine(space)
    l1 = exact_lyapunov(eng, space.with_values({"mu1": g.x}), "Omega", g.y).hopf.l1
    assert abs(l1) <= 1e-6 * scale
    # slightly along the curve on either side: opposite signs
    signs = set()
    for f in (0.98, 1.02):
        y = g.y * f
        x = bs.crossings(space.with_values({"Omega": y}), Axis("mu1", g.x * 0.9, g.x * 1.1)).crossings[0][0]
        signs.add(np.sign(exact_lyapunov(eng, space.with_values({"mu1": x}), "Omega", y).hopf.l1))
    assert signs == {-1.0, 1.0}


def _run(capsys, *args):
    rc = main(list(args))
    out = capsys.readouterr()
    return rc, out.out, out.err


def test_region_command_exact_form(capsys, tmp_path):
    """The issue's exact form: JSON with hopf_curves (points by axis name with l1) and special_points; the
    NetCDF and figure are written."""
    import xarray as xr

    nc, png = tmp_path / "r.nc", tmp_path / "r.png"
    rc, out, err = _run(capsys, "region", "--preset", "paper-fig2", "--set", "k_ip=inf", "--x", "mu=0.05:1", "--y",
                        "Omega=10:200", "--format", "json", "--out", str(nc), "--plot", str(png))
    assert rc == 0, err
    d = json.loads(out)
    assert isinstance(d["special_points"], list) and d["special_points"] == []  # none in this box
    # no GH point in this box: the fold-of-cycles stage ran and found no curve, nothing is shaded
    assert d["fold_of_cycles"] == "computed" and d["fold_curves"] == []
    assert d["regions"] == {"squeal_possible_although_linearly_stable": [], "contact_lost": [],
                            "bilateral_equations_fold_band": []}
    assert "no generalised-Hopf point" in d["shaded"]
    (curve,) = d["hopf_curves"]
    pts = curve["points"]
    assert len(pts) >= 20
    assert all({"mu", "Omega", "l1", "omega_hz"} <= set(p) for p in pts)
    assert all(p["l1"] < 0 and p["criticality"] == "supercritical" for p in pts)  # Fig. 2's onset: supercritical
    space = _space("paper-fig2", FIG2)
    first, last = sorted((pts[0], pts[-1]), key=lambda p: p["mu"])
    assert first["Omega"] == pytest.approx(200.0, rel=1e-12)
    assert first["mu"] == pytest.approx(bs.crossings(space.with_values({"Omega": 200.0}), X2).crossings[0][0],
                                        rel=1e-9)
    assert last["mu"] == pytest.approx(1.0, rel=1e-12)
    assert last["Omega"] == pytest.approx(bs.crossings(space.with_values({"mu": 1.0}), Y2).crossings[0][0],
                                          rel=1e-9)
    hp = bs.hopf_points(space.with_values({"mu": last["mu"]}), Axis("Omega", 10.0, 200.0))
    assert last["l1"] == pytest.approx(hp[0].hopf.l1, rel=1e-6)
    assert last["omega_hz"] == pytest.approx(hp[0].hopf.frequency0_hz, rel=1e-9)
    ds = xr.open_dataset(nc, engine="scipy")
    assert ds.sizes["point"] == len(pts) and np.allclose(ds["mu"].values, [p["mu"] for p in pts])
    assert ds.attrs["fold_of_cycles"] == "computed" and ds.sizes.get("fold_point", 0) == 0
    assert png.stat().st_size > 10_000


def test_region_command_text(capsys):
    rc, out, err = _run(capsys, "region", "--preset", "paper-fig2", "--set", "k_ip=inf", "--x", "mu=0.5:1", "--y",
                        "Omega=10:200", "--grid", "5", "--seeds", "2", "--no-folds")
    assert rc == 0, err
    assert "1 curve(s)" in out and "supercritical" in out and "fold-of-cycles curves: not computed" in out
    assert "--folds computes them" in out


@pytest.mark.parametrize("args, option", [
    (["--x", "mu=0.05:1", "--y", "mu=0.1:0.5"], "--y"),                 # equal axes
    (["--x", "nonsense=0.05:1", "--y", "Omega=10:200"], "nonsense"),    # unknown axis
    (["--x", "mu=1:0.05", "--y", "Omega=10:200"], "--x"),               # empty (reversed) range
    (["--x", "mu=0.05:1", "--y", "Omega=10:10"], "--y"),                # empty range
    (["--x", "mu=0.05:1", "--y", "Omega=10:200", "--model", "disk_brake100"], "--model"),
])
def test_region_bad_input_one_line(capsys, args, option):
    rc, out, err = _run(capsys, "region", "--preset", "paper-fig2", *args) if "--model" not in args else \
        _run(capsys, "region", "--x", "Omega=1:100", "--y", "s=0.1:1", "--model", "disk_brake100")
    assert rc == 2
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in err, err
    assert option in lines[0]


def test_library_bad_input():
    space = _space("paper-fig2", FIG2)
    eng = bs.engine(space)
    with pytest.raises(ParameterError, match="--y"):
        hopf_curves(eng, space, X2, Axis("mu", 0.1, 0.5))
    with pytest.raises(ParameterError, match="--x"):
        hopf_curves(eng, space, Axis("mu1", 0.1, 0.5), Y2)  # tied to mu in paper-fig2
    with pytest.raises(ParameterError, match="--x.*bogus|bogus"):
        hopf_curves(eng, space, Axis("bogus", 0.1, 0.5), Y2)
    with pytest.raises(ParameterError, match="empty or reversed"):
        Axis("mu", 0.5, 0.5)
    mat = bs.resolve_space(model="disk_brake100")
    with pytest.raises(ParameterError, match="--model.*coefficient matrices"):
        hopf_curves(bs.engine(mat), mat, Axis("Omega", 1.0, 100.0), Axis("s", 0.1, 1.0))
