"""The characteristic-polynomial route of n-DOF maps against LAPACK eigenvalues of the state matrix.

The route (:func:`brakesqueal.analysis.kernels.charpoly_verdicts`) certifies
verdicts from the roots of the exact ``det(λ²M + λD + K)`` with Gerschgorin
inclusion disks; here every decided point is compared with
``numpy.linalg.eigvals`` of the state matrix built from the generated zero-state
``M, D, K`` (an independent computation: no polynomial, no inclusion theory).
"""

from __future__ import annotations

import numpy as np
import pytest

from brakesqueal.analysis.kernels import charpoly_verdicts
from brakesqueal import Axis, stability_map
from brakesqueal.analysis.points import evaluate_arrays
from brakesqueal.analysis.robust import STABLE, UNDECIDED
from brakesqueal.codegen import compile_model
from brakesqueal.model import resolve_space
from brakesqueal.codegen import build



def _lapack(space, outer, inner, ov, iv):
    """Eigenvalues of the state matrices at the grid points (rows: outer values)."""
    cm = compile_model(space.model)
    arr = space.arrays({outer: ov[:, None], inner: iv[None, :]})
    shape = (ov.size, iv.size)
    cols = [np.ascontiguousarray(np.broadcast_to(v, shape).ravel()) for v in space.vectors(arr)]
    M, D, K = cm.zero_linear(cols)
    n, N = cm.n, M.shape[0]
    A = np.zeros((N, 2 * n, 2 * n))
    A[:, :n, n:] = np.eye(n)
    A[:, n:, :n] = -np.linalg.solve(M, K)
    A[:, n:, n:] = -np.linalg.solve(M, D)
    return np.linalg.eigvals(A).reshape(shape + (2 * n,))


# (model, outer, inner, outer range, inner range, least fraction decided by the route): at small d_ip the
# six-dof's two pad modes form a near-double pair (1e-7 apart, Re ~ -0.1) that the polynomial's disks cannot
# separate, so those points go to the eigenvalue route
CASES = [
    ("eight-dof", "k_cn", "k_c", (5e6, 5e8), (1e8, 1e10), 0.95),
    ("eight-dof", "Omega", "N0", (1.0, 300.0), (500.0, 2e4), 0.95),
    ("eight-dof", "d_c", "k_ct", (0.5, 200.0), (1e6, 1e9), 0.95),
    ("six-dof", "k_c", "d_ip", (1e7, 1e10), (0.1, 100.0), 0.5),
]


@pytest.mark.slow
@pytest.mark.parametrize("model,outer,inner,ro,ri,least", CASES)
def test_charpoly_verdicts_agree_with_lapack(model, outer, inner, ro, ri, least):
    space = resolve_space(model)
    tab = build(space.model).charpoly_table(space, outer, inner)
    assert tab is not None and tab.degree == 2 * compile_model(space.model).n
    rng = np.random.default_rng(7)
    ov = np.sort(np.exp(rng.uniform(np.log(ro[0]), np.log(ro[1]), 9)))
    iv = np.sort(np.exp(rng.uniform(np.log(ri[0]), np.log(ri[1]), 40)))
    ev = _lapack(space, outer, inner, ov, iv)
    order = np.argsort(-ev.real, axis=-1)
    top = np.take_along_axis(ev, order[..., :1], -1)[..., 0]
    second = np.take_along_axis(ev, order[..., 1:2], -1)[..., 0]
    scale = np.abs(top)
    for eigen in (False, True):
        codes, mr, fr = charpoly_verdicts(tab, ov, iv, eigen=eigen)
        done = codes != UNDECIDED
        assert done.mean() > least
        clear = done & (np.abs(top.real) > 1e-7 * scale)
        assert clear.sum() > 0.5 * least * codes.size
        np.testing.assert_array_equal(codes[clear] == STABLE, top.real[clear] < 0)
        if eigen:
            # max Re λ to 1e-9 relative (of |λ|); LAPACK's own error is far below that here
            np.testing.assert_array_less(np.abs(mr[done] - top.real[done]), 1e-9 * scale[done])
            # the leading mode is unambiguous: the next root is its conjugate or clearly further left
            conj = np.abs(top.imag + second.imag) < 1e-8 * scale
            sep = done & ((top.real - second.real > 1e-8 * scale) | conj)
            f_ref = np.abs(top.imag) / (2 * np.pi)
            np.testing.assert_array_less(np.abs(fr[sep] - f_ref[sep]), 1e-9 * scale[sep] / (2 * np.pi) + 1e-300)
        else:
            assert np.all(np.isnan(mr[~done]))


def _route_share(ds, name):
    """Fraction of a map's points that the route ``name`` decided (its ``route`` variable)."""
    from brakesqueal.results import label_names

    names = label_names(ds["route"].attrs)
    return float(np.mean(np.asarray(ds["route"].values) == names.index(name)))


def test_map_uses_charpoly_route_and_agrees_with_eigenvalue_route():
    space = resolve_space("eight-dof")
    x, y = Axis("k_c", 1e8, 1e10, 14, log=True), Axis("k_cn", 5e6, 5e8, 11, log=True)
    m = stability_map(space, x, y, boundary=False)
    assert _route_share(m.data, "charpoly-grid") > 0.9
    d = m.data
    arr = space.arrays({"k_cn": y.values()[:, None], "k_c": x.values()[None, :]})
    ref = evaluate_arrays(build(space.model), space, arr)  # batched certified eigenvalue verdicts
    np.testing.assert_array_equal(d["status"].values, ref.status)
    ok = ref.status == 0
    np.testing.assert_array_equal(d["stable"].values[ok], ref.stable[ok])
    mr = d["max_real"].values
    scale = np.maximum(np.abs(mr), 2 * np.pi * np.abs(d["frequency"].values))
    np.testing.assert_array_less(np.abs(mr - ref.max_real)[ok], 1e-8 * scale[ok])
    v = stability_map(space, x, y, eigen=False, boundary=False).data
    np.testing.assert_array_equal(v["stable"].values, d["stable"].values)


def test_charpoly_route_refused_for_nontrivial_silent_motion():
    space = resolve_space("eight-dof")
    # mu1 alone breaks mu1 h10 = mu2 h20: the silent motion is not the zero state on the whole map
    assert build(space.model).charpoly_table(space, "mu1", "k_c") is None


def test_write_map_file_of_an_ndof_model(tmp_path):
    """The route's map is written by the NetCDF3 writer (ASCII attributes) and reads back with the same verdicts."""
    from brakesqueal import write_map
    from brakesqueal.results import open_map

    space = resolve_space("eight-dof")
    x, y = Axis("k_c", 1e8, 1e10, 9, log=True), Axis("k_cn", 5e6, 5e8, 7, log=True)
    path = tmp_path / "m8.nc"
    s = write_map(space, x, y, str(path), boundary=False)
    d = stability_map(space, x, y, boundary=False).data
    data = open_map(str(path)).data
    assert data.attrs["method"] == s.method and _route_share(data, "charpoly-grid") > 0.9
    np.testing.assert_array_equal(np.asarray(data["stable"].values, dtype=bool), d["stable"].values)


def test_charpoly_route_refused_quickly_for_transcendental_entries(tmp_path):
    """A Stribeck law puts exp(-Omega r / v_s) into the pencil: not rational in an Omega axis.

    Before, the exact determinant's lcm and expansion of those entries grew without bound (a 400-point map of the
    docs' caliper-stribeck example ran out of memory; the explorer's stribeck-drop preset took gigabytes).  The
    route must decline at once, and the map take the certified per-point route.
    """
    import re
    import time
    from pathlib import Path

    from brakesqueal.model import load_model

    text = Path(__file__).resolve().parents[2].joinpath("docs", "model-format.md").read_text()
    toml = re.search(r"```toml\n(.*?caliper-stribeck.*?)```", text, re.S).group(1)
    f = tmp_path / "caliper.toml"
    f.write_text(toml)
    spec = load_model(f)
    space = resolve_space(spec, "stribeck-drop")
    t0 = time.perf_counter()
    assert build(space.model).charpoly_table(space, "Omega", "mu") is None
    assert time.perf_counter() - t0 < 60  # declined before any expansion (minutes and gigabytes before)
    x, y = Axis("mu", 0.05, 1.0, 5), Axis("Omega", 1.0, 1000.0, 5, True)
    m = stability_map(space, x, y, boundary=False)
    assert _route_share(m.data, "charpoly-grid") == 0
    arr = space.arrays({"Omega": y.values()[:, None], "mu": x.values()[None, :]})
    ref = evaluate_arrays(build(space.model), space, arr)  # the per-point certified route, point by point
    np.testing.assert_array_equal(m.data["status"].values, ref.status)
    ok = ref.status == 0
    assert ok.any()
    np.testing.assert_array_equal(m.data["stable"].values[ok], ref.stable[ok])
