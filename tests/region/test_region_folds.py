"""Fold-of-cycles curves from the generalised-Hopf points of a region (issue 28 items 2 and 3).

On Fig. 3's set with rigid pads (``k_ip = inf``, ``mu2 = 0.5``) the Hopf curve in (mu1, Omega) has one GH point
(mu1 ~ 0.2387, Omega ~ 3098 rad/s), subcritical above it (the upper re-stabilisation).  Along every slice the
unstable cycles born there lose contact before the branch folds, so the fold-of-cycles curve is cut by the
contact loss at once: the slices give ``contact_loss`` points and the "contact lost" region.  The checks are
independent of the slicing: the crossings and branches are recomputed with other ranges, the certified linear
verdict is evaluated at a point inside the region.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import brakesqueal as bs
from brakesqueal.analysis.maps import Axis
from brakesqueal.cli import main
from brakesqueal.nonlinear.models import limit_cycles
from brakesqueal.region import FoldCurve, FoldPoint, region_diagram

FIG3 = {"k_ip": math.inf, "mu2": 0.5}
X3, Y3 = Axis("mu1", 0.0, 1.0), Axis("Omega", 10.0, 20000.0, log=True)


@pytest.fixture(scope="module")
def fig3_region():
    space = bs.resolve_space(preset="paper-fig3", sets=FIG3)
    r = region_diagram(bs.engine(space), space, X3, Y3, grid=None, fold_points=3)
    return space, r


def _inside(poly, pt) -> bool:
    from matplotlib.path import Path

    return bool(Path(np.array(poly)).contains_point(pt))


@pytest.mark.slow
def test_fold_curve_starts_at_gh_and_slices_the_subcritical_side(fig3_region):
    space, r = fig3_region
    (gh,) = [s for c in r.curves for s in c.special_points if s.type == "GH"]
    (f,) = r.folds
    assert f.points[0].kind == "GH" and (f.points[0].x, f.points[0].y) == (gh.x, gh.y) == f.gh
    assert f.along == "mu1" and len(f.points) == 4  # GH + 3 slices, each with a point
    for p in f.points[1:]:
        # the slice's Hopf point is a stability crossing of the slice (recomputed over another range) ...
        (h, _d), = bs.crossings(space.with_values({"Omega": p.y}), Axis("mu1", 0.5 * p.hopf, 1.0)).crossings
        assert p.hopf == pytest.approx(h, rel=1e-9)
        # ... above the GH point, where the curve is subcritical
        hp = bs.hopf_points(space.with_values({"Omega": p.y}), Axis("mu1", 0.5 * p.hopf, 1.0))
        assert p.y > gh.y and hp[0].hopf.criticality == "subcritical"
        # this model: the cycles lose contact before they fold; the point is on the stable side of the Hopf point
        assert p.kind == "contact_loss" and p.contact_lost and p.x < p.hopf
        assert p.period == pytest.approx(2 * math.pi / hp[0].hopf.omega0, rel=0.02)
    # the curve leaves the GH point along the Hopf curve: its distance from the Hopf curve grows from 0 at GH
    gaps = [abs(p.hopf - p.x) for p in f.points]
    dist = [abs(p.x - gh.x) for p in f.points]
    assert gaps[0] == 0 and all(a < b for a, b in zip(gaps, gaps[1:]))
    assert all(g < 1e-3 * d for g, d in zip(gaps[1:], dist[1:]))  # a thin band along the subcritical Hopf curve


@pytest.mark.slow
def test_contact_loss_points_match_independent_branches_without_fold(fig3_region):
    """Each slice's point is the contact loss of an independently computed branch (another range), whose
    parameter is monotonic up to there: no turning point (fold) comes first, so ``contact_lost`` is right."""
    space, r = fig3_region
    (f,) = r.folds
    p = f.points[1]
    sp = space.with_values({"Omega": p.y})
    b = limit_cycles(bs.engine(sp), sp, Axis("mu1", 0.5 * p.hopf, 0.5 * (1 + p.hopf)), pads="exact")
    assert b.contact_loss == pytest.approx(p.x, rel=1e-7)
    ps = np.array([b.hopf.hopf.p0] + [q.p for q in b.points])
    steps = np.diff(ps)
    assert np.all(steps < 0) and b.folds == []  # cycles for mu1 < Hopf, no turn before the contact loss


@pytest.mark.slow
def test_point_in_contact_lost_region_has_stable_silent_motion_and_a_cycle(fig3_region):
    space, r = fig3_region
    (f,) = r.folds
    (poly,) = f.regions("contact_loss")
    assert f.regions("LPC") == []
    p = f.points[2]
    sp = space.with_values({"Omega": p.y})
    b = limit_cycles(bs.engine(sp), sp, Axis("mu1", 0.5 * p.hopf, 0.5 * (1 + p.hopf)), pads="exact")
    # a cycle of the library's branch strictly between the Hopf point and the contact loss
    mids = [q for q in b.points if p.x < q.p < p.hopf and min(q.F_n_min) > 0]
    assert mids
    q = mids[len(mids) // 2]
    assert max(q.amplitude.values()) > 1e-4 and q.residual < 1e-6
    v = bs.evaluate_point(space, {"mu1": q.p, "Omega": p.y})
    assert v.stable  # certified: the silent motion is linearly stable there
    assert _inside(poly, (q.p, p.y))
    # and the JSON names the region
    d = r.to_dict()
    assert d["regions"]["contact_lost"] and d["regions"]["squeal_possible_although_linearly_stable"] == []
    assert d["fold_curves"][0]["points"][0]["kind"] == "GH"
    assert {"mu1", "Omega", "amplitude", "period", "route", "contact_lost"} <= set(d["fold_curves"][0]["points"][1])


def test_regions_follow_the_hopf_curve_seeded():
    """The polygons: near side on the Hopf curve's path, far side shifted by the slices' distances; the LPC
    region starts at the GH point, a contact-loss run starts at the point before it (seeded random slices)."""
    rng = np.random.default_rng(28)
    for _ in range(20):
        n = int(rng.integers(2, 6))
        ys = np.sort(rng.uniform(1.0, 2.0, n))
        hop = 0.3 + 0.1 * ys  # the Hopf curve x = 0.3 + 0.1 y
        gaps = rng.uniform(0.001, 0.01, n)
        split = int(rng.integers(0, n + 1))  # folds first, then contact loss
        pts = [FoldPoint(0.4, 1.0, "GH", 0.4, {}, 1.0, "normal form", False)]
        for k in range(n):
            kind = "LPC" if k < split else "contact_loss"
            pts.append(FoldPoint(hop[k] + gaps[k], ys[k], kind, hop[k], {"q": 1.0}, 1.0, "shooting",
                                 kind == "contact_loss"))
        path = tuple((0.3 + 0.1 * y, y) for y in np.linspace(1.0, 2.0, 11))
        f = FoldCurve(0, (0.4, 1.0), "x", "x", tuple(pts), (), path)
        lpc, cl = f.regions("LPC"), f.regions("contact_loss")
        assert len(lpc) == (1 if split else 0) and len(cl) == (1 if split < n else 0)
        if split:
            assert lpc[0][0] == (0.4, 1.0)  # from GH
        for poly in lpc + cl:
            a = np.array(poly)
            # every vertex lies between the Hopf curve and at most the largest gap beyond it
            off = a[:, 0] - (0.3 + 0.1 * a[:, 1])
            assert np.all(off > -1e-12) and np.all(off <= gaps.max() + 1e-12)
        if split < n:
            # a point halfway out, halfway between the run's first slice and the point before it, is inside
            y0, g0 = (1.0, 0.0) if split == 0 else (ys[split - 1], gaps[split - 1])
            y = 0.5 * (y0 + ys[split])
            g = 0.5 * (g0 + gaps[split])
            assert _inside(cl[0], (0.3 + 0.1 * y + 0.5 * g, y))
            assert not _inside(cl[0], (0.3 + 0.1 * y - 0.5 * g, y))  # the linearly unstable side is not


def test_no_folds_option_and_bad_fold_points(capsys):
    rc = main(["region", "--preset", "paper-fig2", "--set", "k_ip=inf", "--x", "mu=0.5:1", "--y", "Omega=10:200",
               "--grid", "3", "--seeds", "1", "--max-points", "5", "--no-folds", "--format", "json"])
    out = capsys.readouterr()
    assert rc == 0, out.err
    d = json.loads(out.out)
    assert d["fold_of_cycles"] == "not computed" and d["fold_curves"] == [] and "--folds" in d["shaded"]
    rc = main(["region", "--preset", "paper-fig2", "--x", "mu=0.5:1", "--y", "Omega=10:200", "--fold-points", "0"])
    err = capsys.readouterr().err
    assert rc == 2 and "--fold-points" in err and "Traceback" not in err


def test_branch_fold_before_contact_loss_is_a_turning_point(monkeypatch):
    """The slice rule on a branch with a known fold (r' = r (mu + r^2 - r^4): fold at mu = -1/4, r^2 = 1/2):
    the fold is taken when every pad is in contact up to it, the contact loss when contact is lost first; the
    fold taken is a turning point of the branch (the parameter's steps change sign there)."""
    from pathlib import Path
    from types import SimpleNamespace

    monkeypatch.syspath_prepend(str(Path(__file__).resolve().parents[1] / "nonlinear"))
    from _nl_systems import bautin

    from brakesqueal.nonlinear import continue_cycles, first_lyapunov
    from brakesqueal.region.folds import _branch_point

    s = bautin()
    h = first_lyapunov(s, [0.0, 0.0], 0.0)
    br = continue_cycles(s, h, (-0.5, 0.5), ds_max=0.1)
    ds = br.data
    p = ds["p"].values
    i = int(ds["special_index"].values[list(ds["special_kind"].values).index("LPC")])
    assert (p[i] - p[i - 1]) * (p[i + 1] - p[i]) < 0  # a turning point of the branch
    ok = np.ones(p.size, dtype=bool)
    kind, pv, amp, period = _branch_point(SimpleNamespace(data=ds.assign(in_contact=("point", ok)),
                                                          contact_loss=None))
    assert kind == "LPC" and pv == pytest.approx(-0.25, abs=1e-9)
    assert amp["x1"] ** 2 == pytest.approx(0.5, abs=1e-6) and period == pytest.approx(2 * math.pi, rel=1e-6)
    ok[i - 1:] = False  # contact lost before the fold
    kind, pv, _amp, _period = _branch_point(SimpleNamespace(data=ds.assign(in_contact=("point", ok)),
                                                            contact_loss=float(p[i - 1])))
    assert kind == "contact_loss" and pv == float(p[i - 1])


@pytest.mark.slow
def test_auto_cycle_branch_folds_only_beyond_our_contact_loss(fig3_region):
    """AUTO-07p continues the cycles of a slice (the bilateral equations, which know nothing of contact loss) from
    its Hopf point: its first fold of cycles (LP) lies far beyond our contact loss, so "contact lost before the
    fold" is right; and AUTO's tilt amplitude at our contact loss agrees with ours."""
    from brakesqueal.region.auto import auto_available, auto_cycle_branch

    why = auto_available()
    if why:
        if __import__("os").environ.get("BRAKESQUEAL_REQUIRE_AUTO") == "1":
            pytest.fail(f"BRAKESQUEAL_REQUIRE_AUTO=1 but {why}")
        pytest.skip(why)
    space, r = fig3_region
    (f,) = r.folds
    p = f.points[2]
    ac = auto_cycle_branch(bs.engine(space), space, Axis("Omega", 0.9 * p.y, 1.1 * p.y), Axis("mu1", 0.1, 1.0),
                           p.y, 0.9 * p.hopf, direction=-1)
    assert ac.hopf == pytest.approx(p.hopf, rel=1e-8)
    assert ac.fold is not None and ac.fold < p.x < p.hopf  # cycles for mu1 < Hopf; AUTO folds past the loss
    assert (p.hopf - ac.fold) > 100 * (p.hopf - p.x)
    # AUTO's largest tilt over the orbit at our contact loss (interpolated on its monotonic start) ~ our
    # first-harmonic amplitude there (nearly sinusoidal at that small amplitude)
    k = int(np.argmax(ac.p < p.x)) + 1
    q1 = float(np.interp(p.x, ac.p[:k][::-1], ac.max_state[:k, 0][::-1]))
    assert q1 == pytest.approx(p.amplitude["q1"], rel=0.03)
    assert ac.period[1] == pytest.approx(p.period, rel=1e-3)


@pytest.mark.parametrize("beta", [0.5, 1.0, 2.0])
def test_fold_of_cycles_of_the_generalised_hopf_normal_form(monkeypatch, beta):
    """r' = r (beta1 + beta2 r^2 - r^4): the fold of cycles lies on beta1 = -beta2^2/4 with amplitude
    sqrt(beta2/2) (closed form); the slice rule locates it on the branch to 1e-8 for several beta2 (a curve)."""
    from pathlib import Path
    from types import SimpleNamespace

    monkeypatch.syspath_prepend(str(Path(__file__).resolve().parents[1] / "nonlinear"))
    from _nl_systems import bautin

    from brakesqueal.nonlinear import continue_cycles, first_lyapunov
    from brakesqueal.region.folds import _branch_point

    s = bautin(beta)
    h = first_lyapunov(s, [0.0, 0.0], 0.0)
    assert h.l1 > 0  # subcritical at beta1 = 0: the cycles exist for beta1 < 0 and fold back
    ds = continue_cycles(s, h, (-beta ** 2, 0.5), ds_max=0.1).data
    kind, b1, amp, period = _branch_point(SimpleNamespace(data=ds.assign(in_contact=("point", np.ones(ds["p"].size,
                                                                                                       dtype=bool))),
                                                          contact_loss=None))
    assert kind == "LPC"
    assert b1 == pytest.approx(-beta ** 2 / 4, abs=1e-8)
    assert amp["x1"] == pytest.approx(math.sqrt(beta / 2), abs=1e-8)
    assert period == pytest.approx(2 * math.pi, rel=1e-8)


def test_bad_fold_contact_is_one_line(capsys):
    rc = main(["region", "--preset", "paper-fig2", "--set", "k_ip=inf", "--x", "mu=0.5:1", "--y", "Omega=10:200",
               "--fold-contact", "sticky"])
    err = capsys.readouterr().err
    assert rc == 2 and "--fold-contact" in err and "stop or bilateral" in err and "Traceback" not in err


@pytest.mark.slow
def test_region_command_follows_bilateral_folds_past_the_contact_loss(tmp_path, capsys, fig3_region):
    """``--fold-contact bilateral``: each slice that loses contact (as the default run finds) is followed on to
    the fold of the bilateral equations, farther from its Hopf point than the contact loss, which the JSON and the
    NetCDF keep; the default run's contact-loss points are those of this one's slices."""
    import xarray as xr

    _, r_stop = fig3_region
    out = tmp_path / "r.nc"
    rc = main(["region", "--preset", "paper-fig3", "--set", "k_ip=inf", "--set", "mu2=0.5", "--x", "mu1=0:1",
               "--y", "Omega=10:20000:log", "--grid", "3", "--fold-points", "3", "--fold-contact", "bilateral",
               "--no-progress", "--format", "json", "--out", str(out)])
    res = capsys.readouterr()
    assert rc == 0, res.err
    d = json.loads(res.out)
    (fc,) = d["fold_curves"]
    (f_stop,) = r_stop.folds
    pts = fc["points"][1:]
    assert [p["kind"] for p in pts] == ["LPC_bilateral"] * 3
    for p, q in zip(pts, f_stop.points[1:]):
        assert p["contact_lost"] and p["Omega"] == pytest.approx(q.y, rel=1e-12)
        assert p["contact_loss"] == pytest.approx(q.x, rel=1e-6)  # where the default run stops
        # the fold lies beyond the contact loss, on the linearly stable side of the slice's Hopf point
        assert p["mu1"] < p["contact_loss"] < p["hopf_mu1"]
    assert d["regions"]["bilateral_equations_fold_band"]
    with xr.open_dataset(out, engine="scipy") as ds:
        kinds = [k.decode() if isinstance(k, bytes) else str(k) for k in ds["fold_kind"].values]
        assert kinds.count("LPC_bilateral") == 3
        np.testing.assert_allclose(ds["fold_contact_loss"].values[1:], [p["contact_loss"] for p in pts], rtol=1e-12)
