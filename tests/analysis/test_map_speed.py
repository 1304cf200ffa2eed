"""The fast map route: compiled max Re λ / frequency, the in-place NetCDF writer, lazy imports.

References are independent of the compiled quartic route: LAPACK eigenvalues
(:func:`numpy.linalg.eigvals`) of the 4×4 state matrix built from the model's
closed-form ``M, D, K`` entries (:func:`~brakesqueal.analysis.kernels.trivial_entries`),
roots known by construction, and maps written through xarray.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from brakesqueal import Axis, stability_map, write_map
from brakesqueal.model.parameters import ParameterSpace
from brakesqueal.status import PointStatus
from brakesqueal.codegen import build

SRC = os.path.join(os.path.dirname(__file__), os.pardir, os.pardir, "src")


def _state_eigenvalues(space, names, a, b):
    """LAPACK eigenvalues of ``[[0, I], [-M⁻¹K, -M⁻¹D]]`` at points ``(names[0]=a, names[1]=b)`` (1-D arrays)."""
    from brakesqueal.analysis.kernels import trivial_entries

    arr = space.arrays({names[0]: a, names[1]: b})
    P = np.stack([np.broadcast_to(v, a.shape) for v in space.vectors(arr)], axis=1)
    E, _ = trivial_entries(build(space.model), P)
    M, D, K = E[:, 0:4].reshape(-1, 2, 2), E[:, 4:8].reshape(-1, 2, 2), E[:, 8:12].reshape(-1, 2, 2)
    S = np.zeros((a.size, 4, 4))
    S[:, 0:2, 2:4] = np.eye(2)
    S[:, 2:4, 0:2] = -np.linalg.solve(M, K)
    S[:, 2:4, 2:4] = -np.linalg.solve(M, D)
    return np.linalg.eigvals(S)


def _compare(lam, mr, fr, what):
    """``mr``/``fr`` against eigenvalues ``lam`` (n, 4) where the rightmost root is well conditioned."""
    scale = np.max(np.abs(lam), axis=1)
    order = np.argsort(-lam.real, axis=1)
    top = lam[np.arange(lam.shape[0]), order[:, 0]]
    # distance of the rightmost root to the nearest other root (excluding its conjugate)
    others = np.abs(lam - top[:, None])
    others[others == 0] = np.inf
    conj = np.abs(lam - np.conj(top)[:, None]) < 1e-12 * scale[:, None]
    others[conj & (np.abs(top.imag) > 1e-9 * scale)[:, None]] = np.inf
    sep = np.min(others, axis=1) / scale
    well = sep > 1e-3
    assert well.mean() > 0.9, what  # the test compares most points
    err = np.abs(mr - top.real) / scale
    assert np.all(err[well] <= 1e-9), (what, float(np.max(err[well])))
    # frequency: where the rightmost real part is not shared by another pair
    second = lam[np.arange(lam.shape[0]), order[:, 2]].real
    gap = (top.real - second) / scale
    fgood = well & ((np.abs(top.imag) < 1e-9 * scale) | (gap > 1e-6))
    ferr = np.abs(fr - np.abs(top.imag) / (2 * np.pi)) * 2 * np.pi / scale
    assert np.all(ferr[fgood] <= 1e-9), (what, float(np.max(ferr[fgood])))


def _random_axes(rng):
    lo = 10 ** rng.uniform(3, 7)
    hi = lo * 10 ** rng.uniform(1, 6)
    m0 = rng.uniform(0.0, 0.6)
    return Axis("k_ip", lo, hi, int(rng.integers(20, 60)), True), Axis("mu", m0, m0 + rng.uniform(0.1, 1.5),
                                                                        int(rng.integers(10, 40)))


@pytest.mark.parametrize("seed", range(6))
def test_map_max_real_and_frequency_against_lapack(seed):
    """Random paper-fig2 maps: every OK point's max_real/frequency vs LAPACK eigenvalues, consistent verdicts."""
    rng = np.random.default_rng(9100 + seed)
    space = ParameterSpace.from_preset("paper-fig2")
    x, y = _random_axes(rng)
    ds = stability_map(space, x, y).data
    K, MU = np.meshgrid(ds["k_ip"].values, ds["mu"].values)
    ok = ds["status"].values == int(PointStatus.OK)
    assert ok.mean() > 0.9
    lam = _state_eigenvalues(space, ("k_ip", "mu"), K[ok], MU[ok])
    mr, fr = ds["max_real"].values[ok], ds["frequency"].values[ok]
    _compare(lam, mr, fr, f"seed {seed} {x} {y}")
    st = ds["stable"].values[ok]
    assert np.array_equal(st, mr < 0)  # never contradicts the certified verdict


@pytest.mark.parametrize("seed", range(4))
def test_kernel_eigen_fast_route_against_lapack(seed):
    """The compiled route itself (before any fallback) finds almost every point and agrees with LAPACK."""
    from brakesqueal.analysis.kernels import kernel_eigen, kernel_scaling

    rng = np.random.default_rng(9200 + seed)
    space = ParameterSpace.from_preset("paper-fig2")
    x, y = _random_axes(rng)
    kern = build(space.model).map_kernel(space, x.name, y.name)
    assert kern is not None
    ax = {x.name: x, y.name: y}
    ov, iv = ax[kern.outer].values(), ax[kern.inner].values()
    e, t = kernel_scaling(kern, iv)
    C, _, lam_e = kern.row_tables(ov, e)
    mr, fr, found = kernel_eigen(kern, C, t, lam_e)
    found = found.astype(bool)
    assert found.mean() > 0.99
    O, I = np.meshgrid(ov, iv, indexing="ij")
    lam = _state_eigenvalues(space, (kern.outer, kern.inner), O[found], I[found])
    _compare(lam, mr[found], fr[found], f"seed {seed}")


def test_quartic_top_rows_known_roots():
    """Monic quartics built from known roots (complex pairs and reals, scales 1e-3..1e5): rightmost root."""
    from brakesqueal.analysis._compiled import quartic_top_rows

    rng = np.random.default_rng(77)
    n = 4000
    roots = np.empty((n, 4), dtype=complex)
    for i in range(n):
        s = 10 ** rng.uniform(-3, 5, size=2)
        kind = rng.integers(3)
        if kind == 0:  # two complex pairs
            a = complex(rng.normal() * s[0], abs(rng.normal()) * s[0])
            b = complex(rng.normal() * s[1], abs(rng.normal()) * s[1])
            roots[i] = [a, a.conjugate(), b, b.conjugate()]
        elif kind == 1:  # one pair, two reals
            a = complex(rng.normal() * s[0], abs(rng.normal()) * s[0])
            roots[i] = [a, a.conjugate(), rng.normal() * s[1], rng.normal() * s[0]]
        else:  # four reals
            roots[i] = rng.normal(size=4) * np.repeat(s, 2)
    A = np.stack([np.real(np.poly(r))[::-1] for r in roots])  # ascending coefficients
    mr, fr, ok = np.empty(n), np.empty(n), np.empty(n, dtype=np.uint8)
    quartic_top_rows(A, mr, fr, ok)
    assert ok.mean() > 0.99
    lam = np.linalg.eigvals(np.stack([np.diag(r) for r in roots]))  # the roots themselves, as (n, 4)
    sel = ok.astype(bool)
    _compare(lam[sel], mr[sel], fr[sel], "known roots")


def _read(path):
    import xarray as xr

    return xr.open_dataset(path, engine="scipy").load()


@pytest.mark.parametrize("eigen", [True, False])
@pytest.mark.parametrize("preset,x,y", [
    ("paper-fig2", Axis("k_ip", -1e6, 1e8, 23), Axis("mu", -0.2, 1.0, 17)),  # invalid points included
    ("paper-fig3", Axis("mu1", 0.2, 0.8, 9), Axis("mu2", 0.2, 0.8, 7)),  # non-trivial silent motions
])
def test_write_map_same_file_as_xarray(tmp_path, preset, x, y, eigen):
    """write_map's file reads back identical to stability_map(...).to_netcdf (values, dtypes, attributes)."""
    space = ParameterSpace.from_preset(preset)
    a, b = tmp_path / "a.nc", tmp_path / "b.nc"
    m = stability_map(space, x, y, eigen=eigen)
    m.to_netcdf(str(a))
    s = write_map(space, x, y, str(b), eigen=eigen, chunk_points=50)  # several chunks
    da, db = _read(a), _read(b)
    if eigen:  # other chunks give other warm starts for the compiled roots: equal to rounding
        scale = max(np.nanmax(np.abs(da["max_real"].values)), 2 * np.pi * np.nanmax(da["frequency"].values))
        for v, f in (("max_real", 1.0), ("frequency", 2 * np.pi)):
            va, vb = da[v].values, db[v].values
            assert np.array_equal(np.isnan(va), np.isnan(vb))
            assert f * np.nanmax(np.abs(va - vb)) <= 1e-11 * scale
            db[v].values[...] = va
    assert da.identical(db)
    for v in da.variables:
        assert da[v].dtype == db[v].dtype
        assert {k: str(w) for k, w in da[v].attrs.items()} == {k: str(w) for k, w in db[v].attrs.items()}
        assert da[v].encoding.get("_FillValue") is None or np.isnan(db[v].encoding.get("_FillValue"))
    assert s.points == x.num * y.num
    assert s.stable_fraction == pytest.approx(float(da["stable"].values.mean()))
    assert s.method == da.attrs["method"]


def _modules_after(args, env):
    code = ("import json, runpy, sys\n"
            f"sys.argv = ['brakesqueal'] + {args!r}\n"
            "try:\n    runpy.run_module('brakesqueal', run_name='__main__')\nexcept SystemExit:\n    pass\n"
            "heavy = ('numba', 'xarray', 'dask', 'matplotlib')\n"
            "sys.stderr.write(json.dumps(sorted(m for m in heavy if m in sys.modules)) + '\\n')\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=600)
    return json.loads(r.stderr.strip().splitlines()[-1])


@pytest.mark.slow
def test_lazy_imports(tmp_path):
    """``--help`` and warm ``linearize`` import none of numba/xarray/dask/matplotlib; ``map`` (no plot) only numba."""
    env = dict(os.environ, PYTHONPATH=os.path.abspath(SRC))
    assert _modules_after(["--help"], env) == []
    assert _modules_after(["map", "--help"], env) == []
    _modules_after(["linearize"], env)  # warms the cache
    assert _modules_after(["linearize"], env) == []
    args = ["map", "--x", "k_ip=1e5:1e10:30:log", "--y", "mu=0.05:1:20", "--out", str(tmp_path / "m.nc")]
    assert _modules_after(args, env) == ["numba"]
    assert (tmp_path / "m.nc").exists()


@pytest.mark.parametrize("x", ["k_ip", "mu"])
def test_plot_map_file_same_image_as_dataset_plot(tmp_path, x):
    """The CLI's plot from the file (no xarray) is pixel for pixel the StabilityMap.plot figure."""
    import matplotlib.image as mimage

    from brakesqueal.results import open_map, plot_map_file

    space = ParameterSpace.from_preset("paper-fig2")
    path = str(tmp_path / "m.nc")
    write_map(space, Axis("k_ip", -1e6, 1e9, 40), Axis("mu", -0.1, 1.0, 30), path)  # invalid points: hatched
    plot_map_file(path, x=x).savefig(tmp_path / "a.png", dpi=80)
    open_map(path).plot(x=x).savefig(tmp_path / "b.png", dpi=80)
    a, b = mimage.imread(tmp_path / "a.png"), mimage.imread(tmp_path / "b.png")
    assert a.shape == b.shape and np.array_equal(a, b)
    assert np.unique(a.reshape(-1, a.shape[-1]), axis=0).shape[0] > 10  # something was drawn


def _random_quartics(rng, n):
    """Interval quartics of every kind: random scales over the whole range, zeros, tiny/huge radii, inf/nan."""
    A = rng.normal(size=(n, 5)) * 10.0 ** rng.integers(-150, 150, size=(n, 1)) * 10.0 ** rng.uniform(-3, 3, (n, 5))
    A[rng.random((n, 5)) < 0.05] = 0.0
    pos = rng.random(n) < 0.5  # many all-positive rows (where the Routh test has work to do)
    A[pos] = np.abs(A[pos])
    R = np.abs(A) * 10.0 ** rng.uniform(-17, -2, (n, 5))
    A[rng.random((n, 5)) < 0.01] = np.inf
    A[rng.random((n, 5)) < 0.01] = np.nan
    return A, R


@pytest.mark.slow
def test_pure_python_twin_bit_for_bit():
    """The plain-Python twin of the interval kernels gives exactly the compiled results (random, extreme input)."""
    from brakesqueal.analysis import _compiled
    from brakesqueal.analysis._pure import call, twin

    rng = np.random.default_rng(5)
    n = 3000
    A, R = _random_quartics(rng, n)
    E = rng.normal(size=(n, 12)) * 10.0 ** rng.integers(-100, 100, size=(n, 1)) * 10.0 ** rng.uniform(-4, 4, (n, 12))
    RE = np.abs(E) * 10.0 ** rng.uniform(-17, -3, (n, 12))
    E[rng.random((n, 12)) < 0.005] = np.inf
    py = twin()
    for i in range(n):
        a, r = A[i:i + 1], R[i:i + 1]
        o1, o2 = np.empty(1, np.uint8), np.empty(1, np.uint8)
        _compiled.routh_batch(a, r, o1)
        call("routh_batch", 1, a, r, o2)  # twin, or the compiled kernel where Python raised
        assert o1[0] == o2[0], (a, r)
        q1, rq1, q2, rq2 = (np.empty((1, 5)) for _ in range(4))
        _compiled.quartic_interval_batch(E[i:i + 1], RE[i:i + 1], q1, rq1)
        call("quartic_interval_batch", 1, E[i:i + 1], RE[i:i + 1], q2, rq2)
        assert np.array_equal(q1, q2, equal_nan=True) and np.array_equal(rq1, rq2, equal_nan=True)
    # most rows really ran as Python (not the fallback), and the verdicts are not all the same
    ran, codes = 0, []
    for i in range(200):
        o = np.empty(1, np.uint8)
        try:
            with np.errstate(all="ignore"):
                py.routh_batch(A[i:i + 1], R[i:i + 1], o)
            ran += 1
            codes.append(int(o[0]))
        except (ArithmeticError, ValueError):
            pass
    assert ran > 150 and len(set(codes)) == 3
