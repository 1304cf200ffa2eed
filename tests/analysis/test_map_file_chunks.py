"""The ``map`` command's NetCDF file written block by block (:class:`~brakesqueal.results.MapFile`).

* the file holds what scipy's NetCDF3 writer (``StabilityMap.to_netcdf``)
  writes for the same arrays: values, types, attributes, fill values, with and
  without a boundary, float32 and float64, sizes needing padding;
* a map written in many small blocks equals the same map written in one block;
* the verdicts and ``max_real``/``frequency`` of a map written in small blocks
  agree with LAPACK eigenvalues of the linear model, computed point by point;
* a map whose variables exceed the format's 4 GiB is refused before anything is computed.

Memory and time are measured in ``benchmarks/bench_map_memory.py``, not here.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from brakesqueal.analysis.boundary import Boundary
from brakesqueal import linearize
from brakesqueal import Axis, write_map
from brakesqueal.errors import ParameterError
from brakesqueal.model import get_preset
from brakesqueal.model.parameters import ParameterSpace
from brakesqueal.results import MapFile, StabilityMap
from brakesqueal.codegen import build


def _read(path, **kw):
    return xr.open_dataset(path, **kw).load()


def _same(a: xr.Dataset, b: xr.Dataset) -> None:
    """Equal values, dtypes, attributes and fill values (``identical`` ignores the stored encoding)."""
    assert a.identical(b)
    assert list(a.variables) == list(b.variables) or set(a.variables) == set(b.variables)
    for v in a.variables:
        assert a[v].dtype == b[v].dtype, v
        assert {k: str(w) for k, w in a[v].attrs.items()} == {k: str(w) for k, w in b[v].attrs.items()}, v
        fa, fb = a[v].encoding.get("_FillValue"), b[v].encoding.get("_FillValue")
        assert (fa is None) == (fb is None), v
        if fa is not None:
            assert np.isnan(fa) and np.isnan(fb) and np.asarray(fa).dtype == np.asarray(fb).dtype, v


@pytest.mark.parametrize("eigen", [True, False])
@pytest.mark.parametrize("ftype", [np.float64, np.float32])
@pytest.mark.parametrize("nb", [0, 7])  # no boundary (room kept for one), a boundary of 7 vertices
def test_map_file_holds_what_scipy_writes(tmp_path, eigen, ftype, nb):
    """Random arrays (NaN included, odd sizes: padded variables) written in blocks by MapFile read back exactly as
    StabilityMap.to_netcdf (xarray's scipy engine) writes them, by xarray's default engine and scipy with or
    without mmap."""
    space = ParameterSpace.from_preset("paper-fig2")
    outer, inner = Axis("mu", 0.05, 1.0, 13), Axis("k_ip", 1e5, 1e10, 7, log=True)
    rng = np.random.default_rng(3)
    shape = (outer.num, inner.num)
    stable = rng.random(shape) < 0.5
    status = rng.integers(0, 8, shape).astype(np.int8)
    mr = rng.normal(size=shape).astype(ftype) if eigen else None
    fr = rng.normal(size=shape).astype(ftype) if eigen else None
    if mr is not None and fr is not None:
        mr[status == 4] = np.nan
        fr[status == 4] = np.nan
    b = None
    if nb:
        co = rng.uniform(0.05, 1.0, nb), rng.uniform(1e5, 1e10, nb)
        co[0][3] = co[1][3] = np.nan  # curves are separated by NaN
        b = Boundary((outer.name, inner.name), co, np.ones(nb, bool), np.zeros(nb))
    method = "a route's name"
    ref = tmp_path / "ref.nc"
    StabilityMap.from_arrays(space, outer, inner, stable=stable, status=status, max_real=mr, frequency=fr,
                             method=method, boundary=b).to_netcdf(str(ref))
    out = tmp_path / "chunks.nc"
    f = MapFile(str(out), space, outer, inner, eigen=eigen, float_dtype=ftype, method=method, boundary=True)
    for r0, r1, c0, c1 in ((6, 13, 0, 7), (0, 5, 0, 7), (5, 6, 3, 7), (5, 6, 0, 3)):  # any order; pieces of a row
        blk = np.s_[r0:r1, c0:c1]
        f.write_rows(r0, r1, stable[blk], status[blk], None if mr is None else mr[blk],
                     None if fr is None else fr[blk], c0=c0)
    if b is not None:
        f.write_boundary(b)
    f.close()
    want = _read(ref, engine="scipy")
    assert ("boundary_mu" in want) == bool(nb)
    for kw in ({}, {"engine": "scipy"}, {"engine": "scipy", "backend_kwargs": {"mmap": False}}):
        _same(want, _read(out, **kw))
    # the grid variables come first in the header, as scipy orders them
    assert list(_read(out).data_vars)[:4 if eigen else 2] == list(want.data_vars)[:4 if eigen else 2]


def test_map_file_checks_its_input(tmp_path):
    space = ParameterSpace.from_preset("paper-fig2")
    outer, inner = Axis("mu", 0.05, 1.0, 3), Axis("k_ip", 1e5, 1e10, 4)
    f = MapFile(str(tmp_path / "m.nc"), space, outer, inner, eigen=True, method="m")
    z = np.zeros((1, 4))
    with pytest.raises(ValueError, match="max_real and frequency"):
        f.write_rows(0, 1, z, z)
    with pytest.raises(ValueError, match="expected shape"):
        f.write_rows(0, 1, z, z, z, np.zeros((1, 3)))
    with pytest.raises(ValueError, match="nor a piece"):
        f.write_rows(0, 2, np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3)), c0=1)
    with pytest.raises(ValueError, match="nor a piece"):
        f.write_rows(0, 1, np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((1, 3)), c0=2)
    f.abort()
    f = MapFile(str(tmp_path / "n.nc"), space, outer, inner, eigen=False, method="m", boundary=False)
    with pytest.raises(RuntimeError, match="no room"):
        f.write_boundary(Boundary(("mu", "k_ip"), (np.ones(3), np.ones(3)), np.ones(3, bool), np.zeros(3)))
    with pytest.raises(ValueError, match="longer than"):
        f.close("a longer route name")


def _tol_equal(a: xr.Dataset, b: xr.Dataset, eigen: bool, rtol: float = 1e-11) -> None:
    """``a`` and ``b`` identical, ``max_real``/``frequency`` to ``rtol`` (other blocks, other warm starts)."""
    if eigen:
        scale = max(np.nanmax(np.abs(a["max_real"].values)), 2 * np.pi * np.nanmax(a["frequency"].values))
        for v, f in (("max_real", 1.0), ("frequency", 2 * np.pi)):
            va, vb = a[v].values, b[v].values
            assert np.array_equal(np.isnan(va), np.isnan(vb))
            assert f * np.nanmax(np.abs(va.astype(float) - vb)) <= rtol * scale
            b[v].values[...] = va
    _same(a, b)


@pytest.mark.parametrize("eigen", [True, False])
@pytest.mark.parametrize("preset,x,y", [
    ("paper-fig2", Axis("k_ip", 1e5, 1e10, 41, log=True), Axis("mu", -0.1, 1.0, 37)),  # invalid points, a boundary
    ("paper-fig2", Axis("k_ip", 1e5, 1e6, 9, log=True), Axis("mu", 0.05, 0.06, 11)),  # no boundary on the map
    ("paper-fig3", Axis("mu1", 0.2, 0.8, 7), Axis("mu2", 0.2, 0.8, 5)),  # per-point route (non-trivial silent motion)
    ("eight-dof", Axis("k_c", 1e8, 1e10, 14, log=True), Axis("k_cn", 5e6, 5e8, 11, log=True)),  # charpoly route
])
def test_chunked_and_unchunked_writes_give_the_same_map(tmp_path, preset, x, y, eigen):
    from brakesqueal.model import resolve_space

    space = resolve_space(preset) if preset == "eight-dof" else ParameterSpace.from_preset(preset)
    one, many = tmp_path / "one.nc", tmp_path / "many.nc"
    s1 = write_map(space, x, y, str(one), eigen=eigen, chunk_points=10**7)
    s2 = write_map(space, x, y, str(many), eigen=eigen, chunk_points=1)  # one point per block
    a, b = _read(one), _read(many)
    # the characteristic-polynomial roots are accurate to 1e-9 (CHARPOLY_ACCURACY) whatever the warm start
    _tol_equal(a, b, eigen, 1e-8 if preset == "eight-dof" else 1e-11)
    assert s1.stable_fraction == s2.stable_fraction == pytest.approx(float(a["stable"].values.mean()))
    assert s1.method == s2.method == a.attrs["method"]
    np.testing.assert_array_equal(a["route"].values, b["route"].values)  # the same route decided every point
    if preset == "eight-dof":
        from brakesqueal.results import label_names

        assert np.mean(a["route"].values == label_names(a["route"].attrs).index("charpoly-grid")) > 0.9


@pytest.mark.parametrize("chunk", [15, 3 * 41 + 5])  # pieces of rows (15, 15, 11), three whole rows
def test_blocks_of_any_size_give_the_same_map(tmp_path, chunk):
    space = ParameterSpace.from_preset("paper-fig2")
    x, y = Axis("k_ip", 1e5, 1e10, 41, log=True), Axis("mu", -0.1, 1.0, 37)
    one, many = tmp_path / "one.nc", tmp_path / "many.nc"
    write_map(space, x, y, str(one), chunk_points=10**7)
    write_map(space, x, y, str(many), chunk_points=chunk)
    a, b = _read(one), _read(many)
    np.testing.assert_array_equal(a["stable"].values, b["stable"].values)  # verdicts identical per point
    np.testing.assert_array_equal(a["status"].values, b["status"].values)
    _tol_equal(a, b, True)  # and every variable, max_real/frequency to 1e-11


def test_blocks_cover_the_grid_once_in_file_order():
    from brakesqueal.analysis.maps import _blocks

    for n_o, n_i, points in ((7, 5, 1), (7, 5, 4), (7, 5, 5), (7, 5, 12), (7, 5, 100), (3, 10, 4), (1, 1, 0)):
        seen = np.zeros((n_o, n_i), int)
        last = -1
        for r0, r1, c0, c1 in _blocks(n_o, n_i, points):
            assert (r1 - r0) * (c1 - c0) <= max(points, 1)
            assert (c0, c1) == (0, n_i) or r1 == r0 + 1  # contiguous in the row-major file
            assert r0 * n_i + c0 == last + 1  # in file order, no gap
            last = (r1 - 1) * n_i + c1 - 1
            seen[r0:r1, c0:c1] += 1
        assert np.all(seen == 1)


def _eigen_reference(space, names, a, b):
    """max Re λ and the least-stable mode's frequency [Hz] from LAPACK eigenvalues of [[0, I], [-M⁻¹K, -M⁻¹D]]."""
    mr, fr, sep = [], [], []
    for u, v in zip(a, b):
        lm = linearize(space.resolve({names[0]: float(u), names[1]: float(v)}))
        assert not lm.pad_states
        n = lm.M.shape[0]
        S = np.zeros((2 * n, 2 * n))
        S[:n, n:] = np.eye(n)
        S[n:, :n] = -np.linalg.solve(lm.M, lm.K)
        S[n:, n:] = -np.linalg.solve(lm.M, lm.D)
        lam = np.linalg.eigvals(S)
        lam = lam[np.argsort(-lam.real)]
        scale = np.max(np.abs(lam))
        mr.append(lam[0].real)
        fr.append(abs(lam[0].imag) / (2 * np.pi))
        # how far the rightmost real part is from the next mode's (a conjugate pair counts once)
        k = 2 if abs(lam[0].imag) > 1e-9 * scale else 1
        sep.append((lam[0].real - lam[k].real) / scale if k < lam.size else np.inf)
    return np.array(mr), np.array(fr), np.array(sep)


def test_chunked_map_agrees_with_eigenvalues_point_by_point(tmp_path):
    """Verdicts and max_real/frequency of a map written in small blocks, at sampled points, against LAPACK."""
    space = ParameterSpace.from_preset("paper-fig2")
    x, y = Axis("k_ip", 1e5, 1e10, 60, log=True), Axis("mu", 0.05, 1.0, 50)
    path = tmp_path / "m.nc"
    write_map(space, x, y, str(path), chunk_points=7 * 60)  # blocks of 7 rows, the last one shorter
    ds = _read(path)
    assert ds["stable"].dims == ("mu", "k_ip")
    rng = np.random.default_rng(11)
    i, j = rng.integers(0, 50, 150), rng.integers(0, 60, 150)
    mu, k = ds["mu"].values[i], ds["k_ip"].values[j]
    mr, fr, sep = _eigen_reference(get_preset("paper-fig2"), ("mu", "k_ip"), mu, k)
    st, ss = ds["stable"].values[i, j], ds["status"].values[i, j]
    got_mr, got_fr = ds["max_real"].values[i, j], ds["frequency"].values[i, j]
    assert np.all(ss == 0)
    scale = np.maximum(np.abs(mr), 1.0)
    clear = np.abs(mr) > 1e-9 * scale
    assert clear.mean() > 0.9 and 0.1 < st.mean() < 0.9  # both verdicts are sampled
    assert np.array_equal(st[clear].astype(bool), mr[clear] < 0)
    assert np.all(np.abs(got_mr - mr) <= 1e-9 * np.maximum(np.abs(mr), 2 * np.pi * fr) + 1e-12)
    good = sep > 1e-6
    assert good.mean() > 0.5
    assert np.all(np.abs(got_fr[good] - fr[good]) <= 1e-9 * np.maximum(fr[good], np.abs(mr[good]) / (2 * np.pi)))


def test_a_map_beyond_the_file_format_is_refused_before_computing(tmp_path, monkeypatch):
    import brakesqueal.analysis.maps as maps

    monkeypatch.setattr(maps, "_rows", lambda *a, **k: pytest.fail("computed"))
    space = ParameterSpace.from_preset("paper-fig2")
    path = tmp_path / "m.nc"
    x, y = Axis("k_ip", 1e5, 1e10, 40000, log=True), Axis("mu", 0.05, 1.0, 40000)  # 1.6e9 points, float32: 6.4 GB
    with pytest.raises(ParameterError, match="at most 4 GiB per variable"):
        write_map(space, x, y, str(path), force=True)
    assert not path.exists()
    with pytest.raises(ParameterError, match="--force"):
        write_map(space, x, y, str(path))


@pytest.mark.parametrize("ax", [
    Axis("k_ip", 1e5, 1e10, 1001, log=True), Axis("mu", -0.2, 1.0, 17), Axis("h", 1e-310, 2e-310, 7),  # subnormal
    Axis("a", 3.0, 7.0, 2), Axis("b", 1e-300, 1e300, 9999, log=True), Axis("c", 0.1, 0.1 + 2e-15, 5),  # near the resolution limit
])
def test_axis_values_range_equals_a_slice_of_values(ax):
    rng = np.random.default_rng(ax.num)
    v = ax.values()
    assert np.array_equal(ax.values_range(0, ax.num), v)
    for _ in range(40):
        i0, i1 = sorted(rng.integers(0, ax.num + 1, 2).tolist())
        w = ax.values_range(i0, i1)
        assert w.dtype == v.dtype and np.array_equal(w, v[i0:i1]), (i0, i1)
    with pytest.raises(ValueError, match="outside"):
        ax.values_range(0, ax.num + 1)


def test_plot_indices():
    from brakesqueal.results import plot_indices

    assert np.array_equal(plot_indices(5, 7), np.arange(5))
    for n in range(8, 200):
        idx = plot_indices(n, 7)
        assert idx[0] == 0 and idx[-1] == n - 1 and idx.size <= 7 and np.all(np.diff(idx) > 0)


def test_plot_of_a_large_map_draws_every_kth_point(tmp_path, monkeypatch):
    """Above MAX_PLOT_POINTS per axis, plot_map_file draws exactly the map sampled at plot_indices (with the whole
    stored boundary): the same image as StabilityMap.plot of that sample."""
    import matplotlib.image as mimage

    import brakesqueal.results as results

    monkeypatch.setattr(results, "MAX_PLOT_POINTS", 9)
    space = ParameterSpace.from_preset("paper-fig2")
    path = str(tmp_path / "m.nc")
    write_map(space, Axis("k_ip", -1e6, 1e9, 40), Axis("mu", -0.1, 1.0, 30), path)  # invalid points: hatched
    ds = results.open_map(path).data
    sub = ds.isel(mu=results.plot_indices(30, 9), k_ip=results.plot_indices(40, 9))
    assert sub["stable"].shape == (9, 9) and "boundary_mu" in sub
    for color in ("verdict", "max_real"):
        results.plot_map_file(path, x="k_ip", color=color).savefig(tmp_path / "a.png", dpi=60)
        results.StabilityMap(sub).plot(x="k_ip", color=color).savefig(tmp_path / "b.png", dpi=60)
        a, b = mimage.imread(tmp_path / "a.png"), mimage.imread(tmp_path / "b.png")
        assert a.shape == b.shape and np.array_equal(a, b)
