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
from brakesqueal.analysis.linear import linearize
from brakesqueal.analysis.maps import Axis, write_map
from brakesqueal.errors import ParameterError
from brakesqueal.model import get_preset
from brakesqueal.model.parameters import ParameterSpace
from brakesqueal.results import MapFile, StabilityMap


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
    for r0, r1 in ((0, 5), (5, 6), (6, 13)):  # blocks of unequal size
        f.write_rows(r0, r1, stable[r0:r1], status[r0:r1], None if mr is None else mr[r0:r1],
                     None if fr is None else fr[r0:r1])
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
    f.abort()
    f = MapFile(str(tmp_path / "n.nc"), space, outer, inner, eigen=False, method="m", boundary=False)
    with pytest.raises(RuntimeError, match="no room"):
        f.write_boundary(Boundary(("mu", "k_ip"), (np.ones(3), np.ones(3)), np.ones(3, bool), np.zeros(3)))
    with pytest.raises(ValueError, match="longer than"):
        f.close("a longer route name")


def _tol_equal(a: xr.Dataset, b: xr.Dataset, eigen: bool) -> None:
    """``a`` and ``b`` identical, ``max_real``/``frequency`` to rounding (other blocks, other warm starts)."""
    if eigen:
        scale = max(np.nanmax(np.abs(a["max_real"].values)), 2 * np.pi * np.nanmax(a["frequency"].values))
        for v, f in (("max_real", 1.0), ("frequency", 2 * np.pi)):
            va, vb = a[v].values, b[v].values
            assert np.array_equal(np.isnan(va), np.isnan(vb))
            assert f * np.nanmax(np.abs(va.astype(float) - vb)) <= 1e-11 * scale
            b[v].values[...] = va
    _same(a, b)


@pytest.mark.parametrize("eigen", [True, False])
@pytest.mark.parametrize("preset,x,y", [
    ("paper-fig2", Axis("k_ip", 1e5, 1e10, 41, log=True), Axis("mu", -0.1, 1.0, 37)),  # invalid points, a boundary
    ("paper-fig2", Axis("k_ip", 1e5, 1e6, 9, log=True), Axis("mu", 0.05, 0.06, 11)),  # no boundary on the map
    ("paper-fig3", Axis("mu1", 0.2, 0.8, 7), Axis("mu2", 0.2, 0.8, 5)),  # per-point route (non-trivial silent motion)
])
def test_chunked_and_unchunked_writes_give_the_same_map(tmp_path, preset, x, y, eigen):
    space = ParameterSpace.from_preset(preset)
    one, many = tmp_path / "one.nc", tmp_path / "many.nc"
    s1 = write_map(space, x, y, str(one), eigen=eigen, chunk_points=10**7)
    s2 = write_map(space, x, y, str(many), eigen=eigen, chunk_points=1)  # one outer row per block
    a, b = _read(one), _read(many)
    _tol_equal(a, b, eigen)
    assert s1.stable_fraction == s2.stable_fraction == pytest.approx(float(a["stable"].values.mean()))
    assert s1.method == s2.method == a.attrs["method"]


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
