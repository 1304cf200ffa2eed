"""Box eigenvalues of finite-element QEPs (:mod:`brakesqueal.analysis.sparse_box`) against dense QZ.

* NLEVP ``disk_brake100`` (dense, 100 DOF) at Ω = 2π, 4π, 8π: every eigenvalue of the box, against
  the QZ of the companion pencil computed here;
* the TU Berlin brake (4669 DOF, sparse) at Ω = 2π against a stored dense QZ reference
  (``tests/data/fe/``, how it was made is in the README there) — slow;
* an undecided verdict when the shifts are capped below what the box needs; bad input.
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

from brakesqueal.analysis.sparse_box import BoxResult, box_eigenvalues, qep_residuals
from brakesqueal.errors import ParameterError

FE = resources.files("brakesqueal").joinpath("data", "fe")
REF = Path(__file__).resolve().parents[1] / "data" / "fe" / "disk_brake4669_omega2pi_box.json"

# the disk_brake100 box: the unstable mode and 84-85 of the 100 upper-half-plane eigenvalues;
# the nearest eigenvalue is >= 4.7e-3 from its edges at the three speeds (checked below)
BOX100 = {"re": (-1.0, 1.0), "freq": (0.0, 0.7)}
# the 4669 brake: audible band, growth rates above -50 1/s (the least-damped modes)
BOX4669 = {"re": (-50.0, 50.0), "freq": (0.0, 20000.0)}


def brake100(omega: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """NLEVP disk_brake100: D = D1 + DR/Ω + Ω DG, K = K1 + KR."""
    with FE.joinpath("nlevp-disk-brake-100", "disk_brake100.mat").open("rb") as f:
        d = sio.loadmat(f)
    return d["M"], d["D1"] + d["DR"] / omega + omega * d["DG"], d["K1"] + d["KR"]


def brake4669(omega: float) -> tuple[sp.csc_matrix, sp.csc_matrix, sp.csc_matrix]:
    """TU Berlin disk_brake4669 (NLEVP definition, Ω_ref = 1, F_ref = 1600)."""
    m = {}
    for name in ("BMLL", "BDLL", "BYLL", "BDIWLL", "BHLL", "BKLL", "BKQLL", "BWLL"):
        with FE.joinpath("tu-berlin-disk-brake-4669", f"{name}00.mat").open("rb") as f:
            m[name] = sp.csc_matrix(sio.loadmat(f)[name])
    D = m["BDLL"] + m["BDIWLL"] / omega + omega * m["BYLL"] + m["BHLL"] / 1600.0
    K = m["BKLL"] + m["BKQLL"] + omega**2 * m["BWLL"]
    return m["BMLL"], D.tocsc(), K.tocsc()


def dense_qz(M: np.ndarray, D: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """QZ of the companion pencil: eigenvalues and the QEP's right / left vectors."""
    n = M.shape[0]
    Z, I_ = np.zeros((n, n)), np.eye(n)
    A = np.block([[Z, I_], [-K, -D]])
    B = np.block([[I_, Z], [Z, M]])
    lam, vl, vr = sl.eig(A, B, left=True, right=True)
    return lam, vr[:n], vl[n:]  # right: first block of [x; λx]; left: y is the second block of w


def in_box(lam: np.ndarray, re: tuple[float, float], freq: tuple[float, float]) -> np.ndarray:
    return ((lam.real >= re[0]) & (lam.real <= re[1]) & (lam.imag >= 2 * math.pi * freq[0])
            & (lam.imag <= 2 * math.pi * freq[1]))


@pytest.mark.parametrize("omega", [2 * math.pi, 4 * math.pi, 8 * math.pi])
def test_brake100_box_matches_dense_qz(omega: float) -> None:
    M, D, K = brake100(omega)
    lam, X, Y = dense_qz(M, D, K)
    sel = in_box(lam, **BOX100)
    ref, ref_bound = lam[sel], qep_residuals(M, D, K, lam[sel], X[:, sel], Y[:, sel])[1]
    # the box's edges are clear of eigenvalues (else a count could differ by rounding)
    near_edge = np.min(np.abs(np.concatenate([lam.real - BOX100["re"][0], lam.real - BOX100["re"][1],
                                              lam.imag - 2 * math.pi * BOX100["freq"][1]])))
    assert near_edge > 1e-3

    res = box_eigenvalues(M, D, K, **BOX100, k=20)
    assert isinstance(res, BoxResult)
    assert res.complete and res.notes == ()
    assert res.eigenvalues.size == ref.size >= 80
    # one-to-one matching; agreement to 1e-9 relative, or, for the eigenvalues |λ| ~ 1e-3 far below
    # ‖K‖/‖D‖ ~ 1, within the joint first-order error bounds (QZ's own bound there is ~1e-11 absolute,
    # i.e. ~1e-8 relative: the dense reference is the less accurate of the two)
    used = np.zeros(ref.size, bool)
    for lb, bb in zip(res.eigenvalues, res.bounds):
        j = int(np.argmin(np.where(used, np.inf, np.abs(ref - lb))))
        used[j] = True
        err = abs(ref[j] - lb)
        assert err <= 1e-9 * abs(lb) or err <= bb + ref_bound[j], (lb, ref[j], err, bb, ref_bound[j])
        assert bb <= 1e-8 * abs(lb)
    assert used.all()
    # sorted by decreasing real part; counts and the verdict
    assert np.all(np.diff(res.eigenvalues.real) <= 0)
    n_unstable = int(np.count_nonzero(ref.real > 0))
    assert n_unstable == 1
    assert res.unstable == n_unstable and res.undecided == 0
    f = ref[ref.real > 0][0].imag / (2 * math.pi)
    assert res.verdict == f"1 unstable mode in [{f:.6g}, {f:.6g}] Hz"
    assert res.vectors is not None and res.vectors.shape == (100, ref.size)


def test_brake100_undecided_when_shifts_capped() -> None:
    M, D, K = brake100(2 * math.pi)
    res = box_eigenvalues(M, D, K, **BOX100, k=10, max_shifts=2)
    assert len(res.shifts) == 2
    assert not res.complete
    assert res.verdict.startswith("undecided: ")
    assert "not covered" in res.verdict and "Hz" in res.verdict
    # fewer eigenvalues than the 85 of the box were found, and none is invented
    lam = dense_qz(M, D, K)[0]
    ref = lam[in_box(lam, **BOX100)]
    assert 0 < res.eigenvalues.size < ref.size
    assert all(np.min(np.abs(ref - v)) <= 1e-9 * abs(v) + b for v, b in zip(res.eigenvalues, res.bounds))
    # raising the cap resolves it
    assert box_eigenvalues(M, D, K, **BOX100, k=20, max_shifts=40).complete


def test_progress_and_stable_box() -> None:
    M, D, K = brake100(2 * math.pi)
    calls: list[tuple[int, int]] = []
    res = box_eigenvalues(M, D, K, re=(-1.0, -0.01), freq=(0.0, 0.7), k=20,
                          progress=lambda d, t: calls.append((d, t)))
    assert res.complete and res.unstable == 0 and res.verdict == "stable in box"
    assert calls and calls[-1] == (len(res.shifts), len(res.shifts))
    assert all(d <= t for d, t in calls)


@pytest.mark.parametrize("bad, match", [
    ({"M": np.ones((3, 4))}, "square"),
    ({"D": np.eye(4)}, "sizes must match"),
    ({"K": np.diag([1.0, np.nan, 1.0])}, "NaN"),
    ({"re": (1.0, 1.0)}, "re_lo < re_hi"),
    ({"freq": (5.0, 5.0)}, "empty box"),
    ({"freq": (-1.0, 5.0)}, "f_lo must be >= 0"),
    ({"k": 0}, "k ="),
    ({"max_shifts": 0}, "max_shifts"),
])
def test_bad_input(bad: dict, match: str) -> None:
    args = {"M": np.eye(3), "D": np.eye(3), "K": np.eye(3), "re": (-1.0, 1.0), "freq": (0.0, 1.0)}
    args.update(bad)
    with pytest.raises(ParameterError, match=match):
        box_eigenvalues(args.pop("M"), args.pop("D"), args.pop("K"), **args)


@pytest.mark.slow
def test_brake4669_box_matches_dense_reference() -> None:
    """4669 DOF at Ω = 2π against the stored dense QZ (9338-wide pencil) eigenvalues."""
    data = json.loads(REF.read_text())
    ref = np.array([complex(a, b) for a, b in data["eigenvalues"]])
    sup = data["box"]  # the stored superset of the test box
    assert sup["re"][0] <= BOX4669["re"][0] and sup["re"][1] >= BOX4669["re"][1]
    assert sup["freq"][1] >= BOX4669["freq"][1]
    ref = ref[in_box(ref, **BOX4669)]

    res = box_eigenvalues(*brake4669(2 * math.pi), **BOX4669)
    assert res.complete, res.notes
    assert res.eigenvalues.size == ref.size == 20
    used = np.zeros(ref.size, bool)
    for lb in res.eigenvalues:
        j = int(np.argmin(np.where(used, np.inf, np.abs(ref - lb))))
        used[j] = True
        assert abs(ref[j] - lb) <= 1e-8 * abs(lb), (lb, ref[j])
    # the error bounds decide every sign; the unstable count equals the dense one
    assert res.undecided == 0 and np.all(res.bounds < 0.1 * np.abs(res.eigenvalues.real))
    n_unstable = int(np.count_nonzero(ref.real > 0))
    assert n_unstable == 3
    assert res.unstable == n_unstable
    f = np.sort(ref[ref.real > 0].imag / (2 * math.pi))
    assert res.verdict == f"3 unstable modes in [{f[0]:.6g}, {f[-1]:.6g}] Hz"
