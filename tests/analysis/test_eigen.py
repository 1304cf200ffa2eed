"""Eigen-analysis: splits, sensitivities (vs finite differences of eigenvalues), verdicts."""

from __future__ import annotations

import numpy as np
import pytest

from brakesqueal import eigen_analysis
from brakesqueal import linearize
from brakesqueal.analysis.linear import LinearModel, state_matrix
from brakesqueal.model import get_preset


@pytest.fixture(scope="module")
def ea():
    return eigen_analysis(get_preset("paper-fig2").resolve({"mu": 0.5, "k_ip": 1e6}))


def _eig_sorted(M, D, K):
    lam = np.linalg.eigvals(state_matrix(M, D, K))
    return lam[np.lexsort((-lam.imag, -lam.real))]


def test_eigenvalues_modes_and_split(ea):
    lm = ea.model
    np.testing.assert_allclose(ea.eigenvalues, _eig_sorted(lm.M, lm.D, lm.K), rtol=1e-10)
    for i, lam in enumerate(ea.eigenvalues):
        Q = lam ** 2 * lm.M + lam * lm.D + lm.K
        assert np.linalg.norm(Q @ ea.modes[:, i]) < 1e-9 * np.linalg.norm(Q)
        assert np.linalg.norm(np.conj(ea.left[:, i]) @ Q) < 1e-9 * np.linalg.norm(Q)
    s = ea.split()
    np.testing.assert_allclose(s["D_s"] + s["G"], lm.D)
    np.testing.assert_allclose(s["K_s"] + s["N"], lm.K)
    np.testing.assert_allclose(s["G"], -s["G"].T)
    np.testing.assert_allclose(s["N"], -s["N"].T)
    np.testing.assert_allclose(ea.frequencies, np.abs(ea.eigenvalues.imag) / (2 * np.pi))
    assert np.all(np.sign(ea.damping_ratios) == -np.sign(ea.eigenvalues.real))


@pytest.mark.parametrize("which", ["M", "D", "K"])
def test_entry_sensitivities_vs_finite_differences(ea, which):
    lm = ea.model
    sens = ea.entry_sensitivities()[which]
    for j in range(2):
        for k in range(2):
            mats = {"M": lm.M.copy(), "D": lm.D.copy(), "K": lm.K.copy()}
            h = 1e-6 * max(abs(mats[which][j, k]), 1e-3 * np.abs(mats[which]).max())
            mp = {n: m.copy() for n, m in mats.items()}
            mm = {n: m.copy() for n, m in mats.items()}
            mp[which][j, k] += h
            mm[which][j, k] -= h
            fd = (_eig_sorted(mp["M"], mp["D"], mp["K"]) - _eig_sorted(mm["M"], mm["D"], mm["K"])) / (2 * h)
            np.testing.assert_allclose(sens[:, j, k], fd, rtol=1e-4, atol=1e-6 * np.abs(fd).max() + 1e-12)


def test_parameter_sensitivity_vs_finite_difference(ea):
    ps = ea.parameter_sensitivities()
    p = ea.model.params
    for name in ("k_t", "mu1", "Omega"):
        v = getattr(p, name)
        lp = _eig_sorted(*(getattr(linearize(p.replace(**{name: v * np.exp(1e-5)})), k) for k in "MDK"))
        lm_ = _eig_sorted(*(getattr(linearize(p.replace(**{name: v * np.exp(-1e-5)})), k) for k in "MDK"))
        fd = (lp - lm_) / 2e-5
        np.testing.assert_allclose(ps[name].real, fd.real, rtol=1e-3, atol=1e-6)


def test_verdict_and_tolerance():
    p = get_preset("paper-fig2").resolve({"mu": 0.5, "k_ip": 1e6})
    ea = eigen_analysis(p)
    v = ea.verdict()
    assert v.status in ("stable", "unstable") and v.error_bound > 0
    assert v.stable == (ea.max_real < 0)
    lm = ea.model
    shift = ea.max_real  # shift the spectrum so the top eigenvalue sits on the imaginary axis
    M, D, K = lm.M, lm.D + 2 * shift * lm.M, lm.K + shift * lm.D + shift ** 2 * lm.M
    on_axis = eigen_analysis(LinearModel(p, lm.silent, M, D, K))
    assert abs(on_axis.max_real) < 1e-6
    assert on_axis.verdict().status == "undecided"
    ds = ea.to_xarray()
    assert ds.sizes["mode"] == 4 and ds.attrs["verdict"] == v.status
    fig = ea.plot()
    assert fig.axes
