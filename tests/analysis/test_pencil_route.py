"""Route ``pencil-refined`` and the disk-mode colouring of maps (a massless pad's own 0 Hz mode is not squeal).

References: the pencil route's verdicts and ``max_real`` are compared with the 40-digit ``extended`` route
(mpmath eigenvalues, an independent computation) point by point, and with closed forms of decoupled pencils;
the map's ``disk_stable`` with a second map judged with ``modes="disk"`` throughout.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import brakesqueal as bs
from brakesqueal.analysis.robust import STABLE, UNDECIDED, UNSTABLE, extended_analysis, state_analysis
from brakesqueal.analysis.verdict import DECIDED, ROUTES, Context, Points
from brakesqueal.analysis.verdict._linear import operating_points
from brakesqueal.analysis.verdict.pencil_refined import pencil_analysis
from brakesqueal.model import resolve_space


def _pencil(c: float, eps: float, coupling: float = 0.0):
    """A damped oscillator (mass 0.16, stiffness 1.9e7, damping c) and a pad-like state of rate -1/eps."""
    m, k = 0.16, 1.9e7
    E = np.diag([1.0, m, eps])
    A = np.array([[0.0, 1.0, 0.0], [-k, -c, -3600.0 * coupling], [7e-3 * coupling, 0.0, -1.0]])
    return E, A


@pytest.mark.parametrize("c", [-1e-3, 1e-3, -0.3, 0.3])
@pytest.mark.parametrize("eps", [1e-20, -1e-20, 6.3e-17])
def test_decoupled_pencil_matches_the_closed_form(c, eps):
    E, A = _pencil(c, eps)
    labels = np.array([0, 0, 1])
    # closed form: lambda = (-c +- sqrt(c^2 - 4 m k)) / (2 m) and -1/eps
    disk = -c / (2 * 0.16)
    code, mr, fr, bd, car = pencil_analysis(E, A, labels, np.array([1]))
    assert code == (UNSTABLE if disk > 0 else STABLE)
    assert abs(mr - disk) <= bd and bd < 1e-6 and car == 0
    assert fr == pytest.approx(math.sqrt(1.9e7 / 0.16 - disk ** 2) / (2 * math.pi), rel=1e-12)
    # every mode judged: the pad's own mode decides when it is unstable (eps < 0: rate +1e20)
    code_all, mr_all, _, _, car_all = pencil_analysis(E, A, labels)
    if eps < 0:
        assert code_all == UNSTABLE and car_all == 1 and mr_all == pytest.approx(-1 / eps, rel=1e-12)
    else:
        assert code_all == code and mr_all == pytest.approx(mr, abs=bd)


@pytest.mark.parametrize("eps", [1e-13, -1e-15, 1e-22])
def test_coupled_pencil_agrees_with_40_digits_where_the_norm_wise_bound_cannot_decide(eps):
    E, A = _pencil(-2e-3, eps, coupling=1.0)
    labels = np.array([0, 0, 1])
    code, mr, _, bd, car = pencil_analysis(E, A, labels, np.array([1]))
    ref = extended_analysis(E, A, 1, labels, np.array([1]))
    assert code == ref[0] != UNDECIDED and car == 0
    assert abs(mr - ref[1]) <= bd + ref[3]
    # the norm-wise route on E^-1 A leaves the disk mode undecided beside the pad's huge mode
    S = np.linalg.solve(E, A)[None]
    nw = state_analysis(S, labels, np.array([1]))
    assert nw[0][0] == UNDECIDED


@pytest.mark.parametrize("E,A,allowed", [
    (np.eye(2), np.array([[-1.0, 1.0], [0.0, -1.0]]), {STABLE, UNDECIDED}),  # defective double eigenvalue
    (np.eye(2), np.array([[0.0, 1.0], [-1.0, 0.0]]), {UNDECIDED}),  # +-i: on the boundary, no verdict
    (np.diag([1.0, 0.0]), np.array([[-1.0, 1.0], [1.0, -1.0]]), {UNDECIDED}),  # an algebraic row: not this route
])
def test_pencil_route_never_guesses(E, A, allowed):
    assert pencil_analysis(E, A, np.zeros(2, dtype=np.int64))[0] in allowed


def _contexts(modes: str):
    space = resolve_space(preset="paper-fig2", sets={"mu1": 0.5, "mu2": 0.5})
    g = np.linspace(0.05, 0.95, 9)
    m1, m2 = np.meshgrid(g, g + 0.013)  # off the diagonal mu1 = mu2: tilted silent motions, pads kept
    points = Points.of(space, {"mu1": m1.ravel(), "mu2": m2.ravel()})
    engine = bs.engine(space)
    ctx = Context(engine, space, points, points.size, eigen=True, modes=modes)
    operating_points(ctx)
    return ctx


@pytest.mark.parametrize("modes", ["disk", "all"])
def test_pencil_route_agrees_with_the_extended_route_on_tilted_points(modes):
    ctx = _contexts(modes)
    pending = np.flatnonzero(np.isin(ctx.status, DECIDED))
    route = {r.name: r for r in ROUTES}
    a = route["pencil-refined"].run(ctx, pending)
    b = route["extended"].run(ctx, pending)
    both = (a.code != UNDECIDED) & (b.code != UNDECIDED)
    assert np.count_nonzero(a.code != UNDECIDED) >= 0.9 * pending.size
    assert both.sum() >= 0.9 * pending.size
    assert np.array_equal(a.code[both], b.code[both])
    assert np.all(np.abs(a.max_real[both] - b.max_real[both]) <= a.bound[both] + b.bound[both])
    if modes == "disk":  # the pad's own modes left out: every verdict is carried by the disk
        assert np.all(a.carrier[a.code != UNDECIDED] == 0)


def test_map_colours_the_disk_modes_and_counts_pad_only_points(tmp_path):
    import xarray as xr

    space = resolve_space(preset="paper-fig2", sets={"mu1": 0.5, "mu2": 0.5})
    x, y = bs.Axis("mu1", 0.0, 1.0, 12), bs.Axis("mu2", 0.0, 1.0, 12)
    s = bs.write_map(space, x, y, tmp_path / "all.nc")
    bs.write_map(space, x, y, tmp_path / "disk.nc", modes="disk")
    with xr.open_dataset(tmp_path / "all.nc") as a, xr.open_dataset(tmp_path / "disk.nc") as d:
        dec = a.status.values <= 1
        disk = a.disk_stable.values
        # the disk verdict stored beside every map equals the verdict of a map that judges the disk alone
        assert np.array_equal(disk[dec], d.stable.values[dec].astype(np.int8))
        pad_only = dec & (a.stable.values == 0) & (disk == 1)
        assert s.pad_only == int(pad_only.sum()) > 0
        assert "only through a massless pad's own 0 Hz mode" in s.text()
        # pad-only points are carried by a pad's tangential rate in the all-modes verdict
        names = a.carrier.attrs["flag_meanings"].split()
        assert all(names[c].endswith("tangential_rate") for c in a.carrier.values[pad_only])
    fig = bs.open_map(tmp_path / "all.nc").plot()
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert "pad's own 0 Hz mode only" in labels and "disk modes' boundary (grid)" in labels


@pytest.mark.parametrize("model,x,y,stored", [
    ("paper", ("mu1", 0.1, 1.0), ("k_ip1", 1e5, 1e7), True),  # massless pads whose rates are states
    ("six-dof", ("mu1", 0.1, 1.0), ("k_c", 1e7, 1e10), False),  # pads with mass: every mode is a structure's
])
def test_disk_variable_only_where_pads_have_modes_of_their_own(tmp_path, model, x, y, stored):
    import xarray as xr

    space = resolve_space(model)
    s = bs.write_map(space, bs.Axis(*x, 5), bs.Axis(*y, 5, True), tmp_path / "m.nc")
    with xr.open_dataset(tmp_path / "m.nc") as ds:
        assert ("disk_stable" in ds) is stored
        if stored:  # the disk's verdict never contradicts a "stable" of every mode
            assert np.all(ds.disk_stable.values[ds.stable.values == 1] == 1)
    assert s.pad_only == 0 or stored
