"""Models given by coefficient matrices (imported finite-element models) through every linear analysis.

References are independent computations made in the tests: a dense QZ of the
companion pencil ``A - λB`` (``scipy.linalg.eig(A, B)``, LAPACK ``ggev``) of the
NLEVP problem ``disk_brake100`` assembled here by hand from its ``.mat`` file
(``scipy.io.loadmat``), never through brakesqueal's reader or coefficient
grammar.
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
import scipy.io
import scipy.linalg

from brakesqueal.errors import ParameterError

DATA = os.path.join(os.path.dirname(__file__), "..", "..", "src", "brakesqueal", "data", "fe")
DB100 = os.path.join(DATA, "nlevp-disk-brake-100", "disk_brake100.mat")


def _raw() -> dict[str, np.ndarray]:
    d = scipy.io.loadmat(DB100)
    return {k: np.asarray(d[k], dtype=float) for k in ("M", "D1", "DR", "DG", "K1", "KR")}


def _qz(w: float, s: float = 1.0) -> np.ndarray:
    """Every eigenvalue of disk_brake100 at Omega = w with the friction scale s: dense QZ of the companion pencil."""
    r = _raw()
    n = r["M"].shape[0]
    D = r["D1"] + s * r["DR"] / w + w * r["DG"]
    K = r["K1"] + s * r["KR"]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-K, -D]])
    B = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), r["M"]]])
    return scipy.linalg.eig(A, B, right=False)


def _match(a: np.ndarray, b: np.ndarray) -> float:
    """Largest relative distance of each eigenvalue of ``a`` to its partner in ``b`` (optimal assignment)."""
    from scipy.optimize import linear_sum_assignment

    C = np.abs(a[:, None] - b[None, :])
    i, j = linear_sum_assignment(C)
    scale = np.maximum(np.abs(b[j]), 1e-300)
    return float(np.max(C[i, j] / np.maximum(scale, np.abs(b).max() * 1e-14)))


@pytest.fixture(scope="module")
def db100():
    from brakesqueal.codegen import build
    from brakesqueal.model import resolve_space

    space = resolve_space(model="disk_brake100")
    return build(space.model), space


@pytest.mark.parametrize("w", [2 * math.pi, 4 * math.pi, 8 * math.pi])
def test_eigenvalues_equal_a_dense_qz(db100, w):
    from brakesqueal.analysis.eigen import eigen_analysis
    from brakesqueal.analysis.linear import linearize

    engine, space = db100
    lm = linearize(engine, space.resolve({"Omega": w}))
    ref = _qz(w)
    assert lm.eigenvalues.size == ref.size == 200
    # the plain companion QZ is itself accurate only to about kappa u ||(A, B)|| / |lambda| (~3e-8 relative for the
    # eigenvalues of magnitude 1e-3 beside 1.4e4; it is 4e-9 off at 4 pi, see the 40-digit test below)
    assert _match(lm.eigenvalues, ref) < 1e-8
    v = eigen_analysis(lm, engine).verdict()
    n_unstable = int(np.sum(ref.real > 0))
    assert n_unstable == int(np.sum(lm.eigenvalues.real > 0)) == 2
    assert v.status == "unstable" and v.carrier == "structure"
    assert v.error_bound < abs(v.max_real)
    assert v.listed == pytest.approx(ref.real.max(), rel=1e-8)  # the listed eigenvalue (QZ's accuracy, above)
    assert abs(v.max_real - ref.real.max()) < v.error_bound  # the verdict's, within its bound


@pytest.mark.parametrize("case", [0, 1, 2])
def test_smallest_eigenvalues_equal_40_digit_references(db100, case):
    """The eigenvalues hardest in relative terms (smallest magnitude) against mpmath references to 1e-12
    (``tests/data/fe/make_disk_brake100_reference.py``: Newton on the Rayleigh functional at 40 digits)."""
    import json

    from brakesqueal.analysis.linear import linearize

    ref = json.load(open(os.path.join(os.path.dirname(__file__), "..", "data", "fe", "disk_brake100_reference.json")))
    c = ref["cases"][case]
    w = {"2pi": 2, "4pi": 4, "8pi": 8}[c["Omega"]] * math.pi
    engine, space = db100
    lam = linearize(engine, space.resolve({"Omega": w})).eigenvalues
    for re_, im_ in c["eigenvalues"]:
        z = complex(float(re_), float(im_))
        assert np.min(np.abs(lam - z)) < 1e-12 * abs(z)


def test_friction_scale_enters_as_declared(db100):
    """s = 0 removes the friction matrices: the verdict is that of D1 + Omega DG, K1 alone (dense QZ)."""
    from brakesqueal.analysis.linear import linearize

    engine, space = db100
    lm = linearize(engine, space.resolve({"Omega": 3.0, "s": 0.0}))
    ref = _qz(3.0, 0.0)
    assert _match(lm.eigenvalues, ref) < 1e-9
    assert ref.real.max() < 0  # without friction the brake is stable


def test_map_verdicts_agree_with_qz(db100):
    from brakesqueal.analysis.maps import Axis, stability_map

    engine, space = db100
    m = stability_map(engine, space, Axis("Omega", 2 * math.pi, 8 * math.pi, 3, False), Axis("s", 0.0, 1.0, 4, False),
                      boundary=False)
    ds = m.data
    for i, s in enumerate(ds["s"].values):
        for j, w in enumerate(ds["Omega"].values):
            ref = _qz(float(w), float(s)).real.max()
            assert bool(ds["stable"].values[i, j]) == (ref < 0)
            # the map's max_real: eigenvalues of the balanced state matrix (about 1e-7 relative here)
            assert float(ds["max_real"].values[i, j]) == pytest.approx(ref, rel=1e-6, abs=1e-12)


@pytest.mark.slow
def test_crossings_along_the_friction_scale_bracket_the_dense_scan(db100):
    """The crossing in s found by the dispatcher lies where a dense QZ scan changes sign."""
    from brakesqueal.analysis.crossings import crossings
    from brakesqueal.analysis.maps import Axis

    engine, space = db100
    w = 2 * math.pi
    r = crossings(engine, space.with_values({"Omega": w}), Axis("s", 0.0, 0.3, 2, False))
    assert r.stable_at_start
    assert len(r.crossings) == 1 and r.crossings[0][1] == "destabilizing"
    c = r.crossings[0][0]
    assert _qz(w, c * (1 - 1e-3)).real.max() < 0 < _qz(w, c * (1 + 1e-3)).real.max()


@pytest.mark.slow
def test_critical_speed_consistent_with_a_dense_scan(db100):
    """At the friction scale 0.2 the brake squeals from low speeds on; critical-speed says so, like a dense scan."""
    from brakesqueal.analysis.crossings import critical_speeds

    engine, space = db100
    r = critical_speeds(engine, space.with_values({"s": 0.1}), 1.0, 100.0)
    scan = [(_qz(w, 0.1).real.max() < 0) for w in np.geomspace(1.0, 100.0, 7)]
    assert r.stable_at_start == scan[0]
    flips = sum(a != b for a, b in zip(scan, scan[1:]))
    assert len(r.crossings) >= flips


def test_sensitivities_match_finite_differences(db100):
    from brakesqueal.analysis.eigen import eigen_analysis
    from brakesqueal.analysis.linear import linearize

    engine, space = db100
    p = space.resolve({"Omega": 5.0})
    ea = eigen_analysis(linearize(engine, p), engine)
    lam0 = ea.eigenvalues[0]
    sens = ea.parameter_sensitivities()
    for name, h in (("Omega", 5e-3), ("s", 1e-3)):  # steps above QZ's noise (~4e-12 in these eigenvalues)
        up = _qz(5.0 + (h if name == "Omega" else 0.0), 1.0 + (h if name == "s" else 0.0))
        dn = _qz(5.0 - (h if name == "Omega" else 0.0), 1.0 - (h if name == "s" else 0.0))
        fd = (up[np.argmin(abs(up - lam0))] - dn[np.argmin(abs(dn - lam0))]) / (2 * h)
        assert sens[name][0] == pytest.approx(fd * p[name], rel=1e-4)  # sensitivities are d lambda / d ln p


@pytest.mark.parametrize("expr, words", [
    ("M*K1", "product of two matrices"),
    ("K1 + 2", "multiplies no matrix"),
    ("K1 + X9", "unknown name 'X9'"),
    ("sqrt(K1)", "function of a matrix"),
    ("1/K1", "division by a matrix"),
])
def test_coefficient_grammar_refuses_nonlinear_combinations(expr, words):
    from brakesqueal.model.matrices import MatrixSpec

    r = _raw()
    with pytest.raises(ParameterError, match="coefficient K") as e:
        MatrixSpec(name="m", matrices=r, coefficients={"M": "M", "D": "D1", "K": expr}, parameters={"Omega": 1.0})
    assert words in str(e.value) and "\n" not in str(e.value)


def test_coefficients_are_linear_combinations_with_parameter_factors():
    """A parsed law evaluates to the same matrices as the law written out in NumPy."""
    from brakesqueal.model.matrices import MatrixSpec

    r = _raw()
    spec = MatrixSpec(name="m", matrices=r, coefficients={
        "M": "M", "D": "2*(D1 - DR/Omega) + Omega*DG/3 - (-DG)", "K": "s**2*(K1 + KR)/2 + K1"},
        parameters={"Omega": 2.0, "s": 3.0})
    M, D, K = spec.at({"Omega": 2.0, "s": 3.0})
    for got, want in ((D, 2 * (r["D1"] - r["DR"] / 2.0) + 2.0 * r["DG"] / 3 + r["DG"]),
                      (K, 9 * (r["K1"] + r["KR"]) / 2 + r["K1"])):
        assert np.abs(got - want).max() <= 1e-15 * np.abs(want).max()  # equal to rounding (summation order)
    Mb, Db, Kb = spec.dense_batch({"Omega": np.array([2.0, 4.0]), "s": np.array([3.0, 1.0])})
    assert np.array_equal(Db[0], D) and np.array_equal(Kb[0], K) and np.array_equal(Mb[1], r["M"])


def test_bad_matrices_are_refused_in_one_line():
    from brakesqueal.model.matrices import MatrixSpec

    r = _raw()
    bad = dict(r, KR=r["KR"][:50, :50])
    with pytest.raises(ParameterError, match="'KR' is 50x50, the others 100x100"):
        MatrixSpec(name="m", matrices=bad, coefficients={"M": "M", "D": "D1", "K": "K1"})
    nan = dict(r, KR=r["KR"].copy())
    nan["KR"][3, 4] = np.nan
    with pytest.raises(ParameterError, match="'KR' has NaN"):
        MatrixSpec(name="m", matrices=nan, coefficients={"M": "M", "D": "D1", "K": "K1"})
    with pytest.raises(ParameterError, match="must be square"):
        MatrixSpec(name="m", matrices=dict(r, KR=r["KR"][:, :99]), coefficients={"M": "M", "D": "D1", "K": "K1"})
    with pytest.raises(ParameterError, match="coefficients must be exactly M, D, K; missing K"):
        MatrixSpec(name="m", matrices=r, coefficients={"M": "M", "D": "D1"})


def test_nonlinear_analyses_refuse_a_matrix_model(db100):
    from brakesqueal.api_nonlinear import simulation_model

    engine, space = db100
    with pytest.raises(ParameterError, match="coefficient matrices, a linear model"):
        simulation_model(space)
    with pytest.raises(ParameterError, match="coefficient matrices"):
        engine.silent_kernel()


def test_a_mass_matrix_whose_determinant_underflows_is_not_singular():
    """A 172-DOF reduced model's M (entries ~1e-3) has det 1e-516 = 0.0 in double precision: singularity is a
    zero pivot, not a vanishing determinant (every point of such a model was undecided before)."""
    from brakesqueal.analysis.robust import descriptor_states, state_matrices

    rng = np.random.default_rng(1)
    n = 172
    A = rng.standard_normal((n, n))
    M = 1e-3 * (A @ A.T / n + np.eye(n))
    assert np.linalg.det(M) == 0.0  # the premise
    S, good = state_matrices(M[None], np.eye(n)[None], np.eye(n)[None])
    assert good[0] and np.all(np.isfinite(S))
    E = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), M]])
    assert descriptor_states(E[None], np.eye(2 * n)[None])[1][0]
    Z = M.copy()
    Z[:, 0] = 0.0  # truly singular
    assert not state_matrices(Z[None], np.eye(n)[None], np.eye(n)[None])[1][0]
