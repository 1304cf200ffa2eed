"""Stability boundaries of maps, refined onto the boundary (analysis.boundary), and the map figure options.

Independent check: every refined vertex is compared with the exact crossing
(``analysis.crossings``, roots of the characteristic polynomial's Hurwitz
determinant, not the bisection of verdicts) on the grid line through it, and,
for a built model, with the sign change of the largest real part of the
eigenvalues of ``M, D, K`` (``scipy.linalg.eigvals`` of the state matrix)
just either side of it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from brakesqueal.analysis.boundary import stability_boundary
from brakesqueal import crossings, evaluate
from brakesqueal import linearize
from brakesqueal import Axis, stability_map, write_map
from brakesqueal.errors import ParameterError
from brakesqueal.model import ParameterSpace, get_model
from brakesqueal.results import open_map, plot_map_file


def _ev(space):
    """The maps' bisection evaluator: the dispatcher's certified verdicts."""
    return lambda values: evaluate(space, values, eigen=False)


def _boundary(space, x, y, **kw):
    m = stability_map(space, x, y, boundary=False)
    outer, inner = m.dims
    ax = {x.name: x, y.name: y}
    return m, stability_boundary(space, ax[outer], ax[inner], m.data.stable.values, m.data.status.values,
                                 evaluator=_ev(space), **kw)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_paper_boundary_vertices_are_exact_crossings(seed):
    rng = np.random.default_rng(seed)
    space = ParameterSpace.from_preset("paper-fig2")
    lo = 10 ** rng.uniform(4.8, 5.2)
    x = Axis("k_ip", lo, lo * 10 ** rng.uniform(4, 5), int(rng.integers(15, 30)), log=True)
    y = Axis("mu", rng.uniform(0.05, 0.2), rng.uniform(0.8, 1.0), int(rng.integers(12, 25)))
    m, b = _boundary(space, x, y, iterations=40, budget=60.0)
    assert b.vertices > 10 and b.refined.sum() > 0.9 * b.vertices
    o, i = b.coords  # (mu, k_ip)
    checked = 0
    for mu, kip in list(zip(o, i))[:: max(1, b.vertices // 12)]:
        if not np.isfinite(mu):
            continue
        on_k_line = np.isclose(np.log10(kip), np.log10(x.values()), rtol=0, atol=1e-12).any()
        if on_k_line:  # refined along mu at fixed k_ip
            r = crossings(space.with_values({"k_ip": kip}), Axis("mu", y.start, y.stop))
            ref = min((v for v, _ in r.crossings), key=lambda v: abs(v - mu))
            assert abs(mu - ref) <= 1e-8 * abs(ref), (mu, ref)
        else:  # refined along k_ip at fixed mu
            r = crossings(space.with_values({"mu": mu}), Axis("k_ip", x.start, x.stop, log=True))
            ref = min((v for v, _ in r.crossings), key=lambda v: abs(v - kip))
            assert abs(kip - ref) <= 1e-8 * abs(ref), (kip, ref)
        checked += 1
    assert checked >= 5


def _max_real(spec, values):
    lm = linearize(spec.get_preset().resolve(values))
    n = lm.M.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(lm.M, lm.K), -np.linalg.solve(lm.M, lm.D)]])
    return float(np.max(scipy.linalg.eigvals(A).real))


@pytest.mark.slow
def test_built_model_boundary_separates_eigenvalue_signs():
    spec = get_model("six-dof")
    space = ParameterSpace.from_preset("six-dof")
    x = Axis("Omega", 5.0, 200.0, 14, log=True)
    y = Axis("N0", 1000.0, 5000.0, 8)
    m, b = _boundary(space, x, y, iterations=40, budget=60.0)
    assert b.vertices >= 3
    o, i = b.coords
    outer = m.dims[0]
    ax = {"Omega": x, "N0": y}
    checked = 0
    for a, c, w in list(zip(o, i, b.width))[:: max(1, b.vertices // 6)]:
        if not np.isfinite(a):
            continue
        v = {outer: a, m.dims[1]: c}
        # the refined coordinate is the one not on a grid line; its final bracket is w grid steps wide
        key = "Omega" if not np.isclose(np.log10(v["Omega"]), np.log10(x.values()), rtol=0, atol=1e-12).any() \
            else "N0"
        axis = ax[key]
        t = np.log10(v[key]) if axis.log else v[key]
        step = (np.log10(axis.stop / axis.start) if axis.log else axis.stop - axis.start) / (axis.num - 1)
        assert w < 1e-3  # the bracket shrank from a whole grid step
        ends = [t - (0.5 * w + 1e-12) * step, t + (0.5 * w + 1e-12) * step]
        vals = [10 ** e if axis.log else e for e in ends]
        lo, hi = (_max_real(spec, {**v, key: val}) for val in vals)
        assert lo * hi < 0, (v, w, lo, hi)
        checked += 1
    assert checked >= 2


@pytest.mark.slow
def test_map_stores_boundary_and_plots_it(tmp_path):
    space = ParameterSpace.from_preset("paper-fig2")
    x, y = Axis("k_ip", 1e5, 1e10, 40, log=True), Axis("mu", 0.05, 1.0, 30)
    path = tmp_path / "m.nc"
    write_map(space, x, y, str(path))
    m = open_map(str(path))
    assert "boundary_k_ip" in m.data and "boundary_mu" in m.data
    mem = stability_map(space, x, y)
    np.testing.assert_array_equal(m.data["boundary_k_ip"].values, mem.data["boundary_k_ip"].values)
    # the figure draws exactly the stored curve
    fig = plot_map_file(str(path))
    lines = [ln for ln in fig.axes[0].lines if ln.get_color() == "k"]
    assert len(lines) == 1
    np.testing.assert_array_equal(lines[0].get_xdata(), m.data["boundary_k_ip"].values)
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert "stability boundary" in labels
    assert fig.axes[0].get_xlabel() == r"$k_{\mathrm{ip}}$ [N/m]" and fig.axes[0].get_ylabel() == r"$\mu$"
    # a colour field gets a colour bar labelled with its symbol and unit
    fig = plot_map_file(str(path), color="max_real")
    assert any("Re" in a.get_ylabel() and "[1/s]" in a.get_ylabel() for a in fig.axes[1:])
    with pytest.raises(ParameterError, match="color"):
        plot_map_file(str(path), color="nope")
    # the CSV has one row per grid point: the boundary (its own dimension) is not multiplied into it
    import pandas as pd

    m.to_csv(str(tmp_path / "m.csv"))
    df = pd.read_csv(tmp_path / "m.csv")
    assert len(df) == 40 * 30 and not any(c.startswith("boundary") for c in df.columns)
    assert df["stable"].sum() == int(mem.data["stable"].sum())


def test_failed_points_are_in_the_legend(tmp_path):
    space = ParameterSpace.from_preset("paper-fig2")
    m = stability_map(space, Axis("k_ip", 1e5, 1e10, 20, log=True), Axis("mu", -0.5, 1.0, 20))
    fig = m.plot()
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any("no verdict" in s for s in labels)


def test_boundary_bad_options():
    space = ParameterSpace.from_preset("paper-fig2")
    x, y = Axis("k_ip", 1e5, 1e10, 5, log=True), Axis("mu", 0.05, 1.0, 4)
    st = np.zeros((4, 5), bool)
    ss = np.zeros((4, 5), np.int8)
    with pytest.raises(ParameterError, match="iterations"):
        stability_boundary(space, y, x, st, ss, iterations=99, evaluator=_ev(space))
    with pytest.raises(ParameterError, match="shape"):
        stability_boundary(space, x, y, st, ss, evaluator=_ev(space))
    # a uniformly stable map has no boundary
    assert stability_boundary(space, y, x, st | True, ss, evaluator=_ev(space)).vertices == 0


@pytest.mark.slow
def test_fig3_tips_close_the_squeal_region():
    """At a located tip the onset and the re-stabilisation meet: just inside both exist and are close to the
    tip's speed, just outside the silent motion is stable on the whole range (exact critical speeds)."""
    from brakesqueal import critical_speeds_many
    from brakesqueal.reproduce import fig3_tips

    space = ParameterSpace.from_preset("paper-fig3", {"k_ip": math.inf})
    diff = np.linspace(-0.9, 0.9, 19)
    roots, dirs, counts, _ = critical_speeds_many(space, {"mu1": (1 + diff) / 2, "mu2": (1 - diff) / 2}, 1.0, 1e5)
    onset = np.array([r[d < 0][0] if np.any(d < 0) else np.nan for r, d in zip(roots, dirs)])
    tips = fig3_tips(space, diff, onset, np.ones(diff.size, bool), (1.0, 1e5))
    assert len(tips) == 2 and tips[0][0] == pytest.approx(-tips[1][0], rel=1e-9)  # symmetric in mu1 - mu2
    for d_tip, w_tip in tips:
        inward = -np.sign(d_tip)
        for d, has in ((d_tip + inward * 1e-6, True), (d_tip - inward * 1e-6, False)):
            r, dd, c, _ = critical_speeds_many(space, {"mu1": np.array([(1 + d) / 2]),
                                                       "mu2": np.array([(1 - d) / 2])}, 1.0, 1e5)
            down = r[0][dd[0] < 0]
            assert bool(down.size) is has
            if has:
                up = r[0][(dd[0] > 0) & (r[0] > down[0])]
                assert up.size and down[0] < w_tip < up[0]
                assert (up[0] - down[0]) / w_tip < 0.1  # the region closes at the tip


@pytest.mark.parametrize("kip", [3e5, 1e6, 1e8])
def test_points_on_the_boundary_get_one_verdict_everywhere(kip):
    """At the float nearest an exact crossing (and its neighbours) linearize, eigen-analysis, the per-point
    evaluator and a map report the same verdict."""
    from brakesqueal import eigen_analysis
    from brakesqueal import evaluate_point

    space = ParameterSpace.from_preset("paper-fig2", {"k_ip": kip})
    r = crossings(space, Axis("mu", 0.05, 1.0))
    assert r.crossings
    for v, _ in r.crossings:
        for mu in (np.nextafter(v, 0), v, np.nextafter(v, 2)):
            lin = eigen_analysis(linearize(space.resolve({"mu": float(mu)}))).verdict().status
            pv = evaluate_point(space, {"mu": float(mu)})
            pt = "stable" if pv.stable else ("unstable" if pv.decided else "undecided")
            d_t = space.value("d_t")
            m = stability_map(space, Axis("mu", float(mu), 1.5, 2), Axis("d_t", d_t, 2 * d_t + 1, 2), boundary=False)
            row = m.data.sel(mu=float(mu), d_t=d_t)
            mp = "stable" if bool(row.stable.values) else ("unstable" if int(row.status.values) == 0
                                                             else "undecided")
            assert lin == pt == mp, (kip, mu, lin, pt, mp)
