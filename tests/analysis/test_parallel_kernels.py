"""The parallel drivers of the compiled kernels give the serial kernels' results (and those are exact).

* :func:`~brakesqueal.analysis.crossings.critical_speeds_batch` on many sets runs
  :func:`~brakesqueal.analysis._compiled.critical_batch` on chunks in parallel: identical arrays, and a sample
  of sets agrees with the exact rational route (:func:`~brakesqueal.analysis.crossings.exact_omega_crossings`)
  to 1e-10 relative.
* :func:`~brakesqueal.analysis.kernels.charpoly_verdicts` on large grids runs blocks of rows in parallel (each
  block warm-starts itself): the same certified verdicts as one serial sweep, ``max_real`` within the route's
  accuracy, and the same results for any number of threads.
"""

from __future__ import annotations

import pytest

import numba
import numpy as np

from brakesqueal.analysis import _compiled
from brakesqueal.analysis.crossings import critical_speeds_batch, exact_omega_crossings
from brakesqueal.analysis.kernels import CHARPOLY_ACCURACY, charpoly_verdicts, omega_entries, omega_subranges
from brakesqueal import Axis
from brakesqueal.analysis.robust import UNDECIDED
from brakesqueal.model import ParameterSpace, resolve_space
from brakesqueal.codegen import build


@pytest.mark.slow
def test_critical_speeds_parallel_equals_serial_and_exact():
    n = _compiled.PARALLEL_MIN + 123
    rng = np.random.default_rng(5)
    mu1 = rng.uniform(0.05, 0.95, n)
    kip = 10 ** rng.uniform(6.5, 10, n)
    space = ParameterSpace.from_preset("paper-fig3")
    arr = space.arrays({"mu1": mu1, "mu2": 1 - mu1, "k_ip": kip})
    P = np.ascontiguousarray(np.stack([np.broadcast_to(v, (n,)) for v in space.vectors(arr)], axis=1))
    roots, dirs, counts, start = critical_speeds_batch(build(space.model), P, 1.0, 1e5)
    E, R = omega_entries(build(space.model), P)
    r2 = np.full((n, 8), np.nan)
    d2 = np.zeros((n, 8), dtype=np.int8)
    c2 = np.zeros(n, dtype=np.int64)
    s2 = np.zeros(n, dtype=np.bool_)
    f2 = np.zeros(n, dtype=np.uint8)
    _compiled.critical_batch(E, R, omega_subranges(1.0, 1e5), r2, d2, c2, s2, f2)
    assert not f2.any()
    np.testing.assert_array_equal(roots, r2)
    np.testing.assert_array_equal(dirs, d2)
    np.testing.assert_array_equal(counts, c2)
    np.testing.assert_array_equal(start, s2)
    assert (counts == 2).sum() > n // 2
    for i in rng.choice(n, 4, replace=False):
        st, found, undecided = exact_omega_crossings(build(space.model), P[i], 1.0, 1e5)
        assert not undecided and bool(st) == bool(start[i]) and len(found) == counts[i]
        for k, (v, d) in enumerate(found):
            assert abs(roots[i, k] / v - 1) <= 1e-10
            assert dirs[i, k] == (1 if d == "stabilizing" else -1)


@pytest.mark.slow
def test_charpoly_blocks_equal_serial_sweep_for_any_thread_count():
    space = resolve_space("eight-dof")
    tab = build(space.model).charpoly_table(space, "k_cn", "k_c")
    assert tab is not None
    ov = Axis("k_cn", 5e6, 5e8, 150, log=True).values()
    iv = Axis("k_c", 1e8, 1e10, 40, log=True).values()
    shape = (ov.size, iv.size)
    codes, mr, fr = charpoly_verdicts(tab, ov, iv)  # > PARALLEL_MIN points: blocks of rows
    assert ov.size * iv.size >= _compiled.PARALLEL_MIN
    c1 = np.empty(shape, dtype=np.uint8)
    m1 = np.empty(shape)
    f1 = np.empty(shape)
    _compiled.charpoly_grid(tab.Q, tab.RQ, ov, iv, np.ones(shape, dtype=np.bool_), True, CHARPOLY_ACCURACY,
                            c1, m1, f1)
    both = (codes != UNDECIDED) & (c1 != UNDECIDED)
    assert both.mean() > 0.99
    np.testing.assert_array_equal(codes[both], c1[both])
    scale = np.abs(mr) + 2 * np.pi * fr
    np.testing.assert_array_less(np.abs(mr - m1)[both], 2 * CHARPOLY_ACCURACY * scale[both])
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        again = charpoly_verdicts(tab, ov, iv)
    finally:
        numba.set_num_threads(before)
    for a, b in zip(again, (codes, mr, fr)):
        np.testing.assert_array_equal(a, b)


def test_quartic_roots_blocks_equal_serial_for_any_thread_count():
    from brakesqueal.analysis.kernels import kernel_eigen, kernel_scaling

    space = ParameterSpace.from_preset("paper-fig2")
    x, y = Axis("k_ip", 1e5, 1e10, 90, True), Axis("mu", 0.05, 1.0, 300)
    kern = build(space.model).map_kernel(space, x.name, y.name)
    assert kern is not None
    ax = {x.name: x, y.name: y}
    ov, iv = ax[kern.outer].values(), ax[kern.inner].values()
    e, t = kernel_scaling(kern, iv)
    C, _, lam_e = kern.row_tables(ov, e)
    assert C.shape[0] > 64 and C.shape[0] * t.size >= _compiled.PARALLEL_MIN
    mr, fr, ok = kernel_eigen(kern, C, t, lam_e)  # blocks of rows in parallel
    A = np.empty((5, C.shape[0], t.size))
    kern.coefficients(C, t, A)
    m1, f1, o1 = np.empty_like(mr), np.empty_like(fr), np.empty_like(ok)
    _compiled.quartic_top_grid(A, np.ascontiguousarray(lam_e, dtype=np.int64), m1, f1, o1)
    both = (ok == 1) & (o1 == 1)
    assert both.mean() > 0.999
    scale = np.abs(mr) + 2 * np.pi * fr
    np.testing.assert_array_less(np.abs(mr - m1)[both], 1e-11 * scale[both])
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        again = kernel_eigen(kern, C, t, lam_e)
    finally:
        numba.set_num_threads(before)
    for a, b in zip(again, (mr, fr, ok)):
        np.testing.assert_array_equal(a, b)
