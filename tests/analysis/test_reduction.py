"""Parametric model reduction (:mod:`brakesqueal.analysis.reduction`, Gräbner et al., ZAMM 2016).

* POD basis and Galerkin projection on small synthetic data (quick);
* the 4669-DOF TU Berlin brake: a basis from box eigenvectors at Ω = 2π, 4π, 6π, 8π, dimension
  <= 200, keeps every box eigenvalue to 1e-4 relative at Ω = 3π, 5π, 7π (not sampled), checked
  against the full sparse box route's eigenvalues there, stored in tests/data/fe (slow).
"""

from __future__ import annotations

import json
import math
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
import scipy.io as sio
import scipy.linalg as sl
import scipy.sparse as sp

from brakesqueal.analysis.reduction import (ReducedBasis, dense_qep_eigenvalues, pod_basis, project,
                                            reduce_qep)
from brakesqueal.errors import BrakesquealError, ParameterError

FE = resources.files("brakesqueal").joinpath("data", "fe")
BOX4669 = {"re": (-50.0, 50.0), "freq": (0.0, 20000.0)}  # as in test_sparse_box.py
# full-model box eigenvalues at the check speeds (how made: the script beside it)
CHECK_SPEEDS = Path(__file__).resolve().parents[1] / "data" / "fe" / "disk_brake4669_check_speeds_box.json"
NAMES = (("M", "BMLL"), ("D1", "BDLL"), ("DG", "BYLL"), ("DR", "BDIWLL"), ("D4", "BHLL"),
         ("K1", "BKLL"), ("KR", "BKQLL"), ("KGeo", "BWLL"))


def brake100(omega: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """NLEVP disk_brake100: D = D1 + DR/Ω + Ω DG, K = K1 + KR."""
    with FE.joinpath("nlevp-disk-brake-100", "disk_brake100.mat").open("rb") as f:
        d = sio.loadmat(f)
    return d["M"], d["D1"] + d["DR"] / omega + omega * d["DG"], d["K1"] + d["KR"]


def brake4669_matrices() -> dict[str, sp.csc_matrix]:
    out = {}
    for name, key in NAMES:
        with FE.joinpath("tu-berlin-disk-brake-4669", f"{key}00.mat").open("rb") as f:
            out[name] = sp.csc_matrix(sio.loadmat(f)[key])
    return out


def assemble(P: dict, omega: float) -> tuple:
    """M, D(Ω), K(Ω) of the 4669 brake (NLEVP definition) from its coefficient matrices (full or reduced)."""
    D = P["D1"] + P["DR"] / omega + omega * P["DG"] + P["D4"] / 1600.0
    K = P["K1"] + P["KR"] + omega**2 * P["KGeo"]
    return P["M"], D, K


def in_box(lam: np.ndarray, re: tuple[float, float], freq: tuple[float, float]) -> np.ndarray:
    return ((lam.real >= re[0]) & (lam.real <= re[1]) & (lam.imag >= 2 * math.pi * freq[0])
            & (lam.imag <= 2 * math.pi * freq[1]))


def test_pod_basis_real_orthonormal_and_spans_snapshots(rng: np.random.Generator) -> None:
    n = 60
    base = rng.standard_normal((n, 4)) + 1j * rng.standard_normal((n, 4))  # 8 real directions
    snaps = [base @ (rng.standard_normal((4, 3)) + 1j * rng.standard_normal((4, 3))) for _ in range(3)]
    b = pod_basis(snaps, samples=[1.0, 2.0, 3.0])
    assert isinstance(b, ReducedBasis)
    assert b.r == 8 and b.V.dtype == float
    assert np.allclose(b.V.T @ b.V, np.eye(8), atol=1e-12)
    assert list(b.samples) == [1.0, 2.0, 3.0]
    assert b.singular_values[8] < 1e-10 * b.singular_values[0] < b.singular_values[7]
    S = np.concatenate(snaps, axis=1)
    assert np.linalg.norm(S - b.V @ (b.V.T @ S)) < 1e-10 * np.linalg.norm(S)
    assert pod_basis(snaps, r=3).r == 3
    with pytest.raises(ParameterError, match="r ="):
        pod_basis(snaps, r=100)
    with pytest.raises(ParameterError, match="row counts"):
        pod_basis([base, base[:10]])
    with pytest.raises(ParameterError, match="at least one"):
        pod_basis([])


def test_project_dense_and_sparse(rng: np.random.Generator) -> None:
    n, r = 40, 5
    V = np.linalg.qr(rng.standard_normal((n, r)))[0]
    A = rng.standard_normal((n, n))
    out = project(V, {"A": A, "S": sp.csc_matrix(A)})
    assert set(out) == {"A", "S"}
    for X in out.values():
        assert isinstance(X, np.ndarray) and X.shape == (r, r)
        assert np.allclose(X, V.T @ A @ V, atol=1e-12)
    with pytest.raises(ParameterError, match="rows"):
        project(V, {"B": np.eye(n + 1)})


def test_dense_qep_eigenvalues_is_the_companion_qz() -> None:
    M, D, K = brake100(2 * math.pi)
    lam = dense_qep_eigenvalues(M, D, K)
    n = M.shape[0]
    ref = sl.eigvals(np.block([[np.zeros((n, n)), np.eye(n)], [-K, -D]]),
                     np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), M]]))
    assert lam.size == 200
    assert all(np.min(np.abs(ref - v)) <= 1e-8 * abs(v) for v in lam)


def test_reduce_qep_refuses_an_incomplete_sample() -> None:
    with pytest.raises(BrakesquealError, match="incomplete"):
        reduce_qep(brake100, [2 * math.pi], re=(-1.0, 1.0), freq=(0.0, 0.7), k=10, max_shifts=1)
    with pytest.raises(ParameterError, match="omegas"):
        reduce_qep(brake100, [], re=(-1.0, 1.0), freq=(0.0, 0.7))


@pytest.mark.slow
def test_brake4669_reduced_model_keeps_box_eigenvalues() -> None:
    mats = brake4669_matrices()

    def qep(omega: float) -> tuple:
        M, D, K = assemble(mats, omega)
        return M, D.tocsc(), K.tocsc()

    # snapshots from a box a little wider than the one checked (modes near its edges move with Ω)
    samples = [2 * math.pi, 4 * math.pi, 6 * math.pi, 8 * math.pi]
    # the basis of the right and left eigenvectors (the default): its first 200 directions for the issue's
    # dimension bound, all 320 for real parts resolved far below the smallest growth rate
    basis = reduce_qep(qep, samples, re=(-100.0, 50.0), freq=(0.0, 21000.0), r=320)
    assert basis.r == 320 and np.allclose(basis.samples, samples)
    assert basis.singular_values[320] < 1e-6 * basis.singular_values[0]
    P = project(basis.V[:, :200], mats)
    P320 = project(basis.V, mats)
    # The full model's box eigenvalues at the unsampled speeds do not depend on the reduction: computed once by
    # the full sparse box route (tests/data/fe/make_disk_brake4669_check_speeds.py; that route is checked against a
    # dense LAPACK solve of the whole model in test_sparse_box.py) and stored, instead of 3 full solves per run.
    ref = json.loads(CHECK_SPEEDS.read_text())
    assert [c["label"] for c in ref["cases"]] == ["3pi", "5pi", "7pi"]
    for case, omega in zip(ref["cases"], (3 * math.pi, 5 * math.pi, 7 * math.pi)):
        assert case["omega"] == omega and case["complete"]
        stored = np.array([complex(*v) for v in case["eigenvalues"]])
        full = stored[in_box(stored, **BOX4669)]
        assert full.size >= 15
        red = dense_qep_eigenvalues(*assemble(P, omega))
        for lam in full:
            assert np.min(np.abs(red - lam)) <= 1e-4 * abs(lam), (omega, lam)
        # r = 320: growth rates of 1e-4 1/s beside 1e5 rad/s resolved, so every verdict is the full model's
        # (measured: relative 4.6e-11, real parts within 5.9e-8 1/s of the full model's, the smallest |Re| 8.6e-5)
        red320 = dense_qep_eigenvalues(*assemble(P320, omega))
        min_re = float(np.min(np.abs(full.real)))
        for lam in full:
            near = red320[np.argmin(np.abs(red320 - lam))]
            assert abs(near - lam) <= 1e-9 * abs(lam), (omega, lam, near)
            assert abs(near.real - lam.real) <= 0.01 * min_re, (omega, lam, near)
        # and no spurious reduced eigenvalue well inside the box, nor an unstable one anywhere that the full box
        # does not hold (the full model's largest Re in the box is its largest growth rate)
        for ev in (red, red320):
            for lam in ev[in_box(ev, re=(-45.0, 45.0), freq=(0.0, 19900.0))]:
                assert np.min(np.abs(full - lam)) <= 1e-4 * abs(lam), (omega, lam)
        assert np.max(red320[np.isfinite(red320)].real) <= np.max(full.real) + 0.01 * min_re
