"""Numeric linearization (eqs. 46-48) against central finite differences of the nonlinear residuals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from brakesqueal import silent_motion
from brakesqueal.analysis.equilibrium import silent_motion_vector
from brakesqueal.analysis.equilibrium import parameter_vector
from brakesqueal.codegen import CONTACT_FIELDS, compile_model
from brakesqueal.errors import ContactLossError, NoSilentMotionError
from brakesqueal import linearize, pad_rate_eigenvalues
from brakesqueal.analysis.linear import state_matrix
from brakesqueal.errors import SilentMotionError
from brakesqueal.codegen import build


def compiled_model():
    """The paper's compiled equations (its engine's)."""
    return build("paper").compiled
from brakesqueal.model import get_preset


def _reduced_psi(model, p, q, dq, ddq, l_guess):
    """psi with l eliminated quasi-statically: solve g(q, dq, l, ldot=0) = 0 by Newton, then evaluate psi."""
    l = np.array(l_guess, dtype=float)
    for _ in range(30):
        x = [q[0], q[1], dq[0], dq[1], ddq[0], ddq[1], l[0], l[1], 0.0, 0.0]
        res = np.array(model.residuals(x, p))
        jl = np.array(model.jacobians(x, p)).reshape(2, 2, 10)[1][:, 6:8]
        step = np.linalg.solve(jl, -res[2:])
        l = l + step
        if np.all(np.abs(step) < 1e-22):
            break
    x = [q[0], q[1], dq[0], dq[1], ddq[0], ddq[1], l[0], l[1], 0.0, 0.0]
    return np.array(model.residuals(x, p))[:2]


def _fd_matrices(params, lm):
    model = compiled_model()
    p = parameter_vector(params)
    q0, l0 = lm.q_m0, lm.silent.l0
    steps = {"K": 1e-8, "D": 1e-6, "M": 1e-4}
    out = {}
    for name, idx in (("K", 0), ("D", 1), ("M", 2)):
        cols = []
        for j in range(2):
            e = np.zeros(2)
            e[j] = steps[name]
            args_p = [q0.copy(), np.zeros(2), np.zeros(2)]
            args_m = [q0.copy(), np.zeros(2), np.zeros(2)]
            args_p[idx] = args_p[idx] + e
            args_m[idx] = args_m[idx] - e
            fp = _reduced_psi(model, p, *args_p, l0)
            fm = _reduced_psi(model, p, *args_m, l0)
            cols.append((fp - fm) / (2 * steps[name]))
        out[name] = np.column_stack(cols)
    return out


@pytest.mark.parametrize(
    "overrides",
    [{}, {"mu1": 0.7, "mu2": 0.2}, {"mu1": 0.5, "mu2": 0.5, "k_ip": "inf"}],
    ids=["fig3-default", "fig3-asymmetric", "fig3-rigid"],
)
def test_linearization_matches_central_differences_at_nontrivial_silent_motion(overrides):
    base = get_preset("paper-fig3").resolve(overrides)
    params = base.replace(h10=base.h10 * 1.3)  # break eq. (49): non-trivial silent motion
    lm = linearize(params)
    assert not lm.silent.trivial and np.abs(lm.q_m0).max() > 1e-8
    fd = _fd_matrices(params, lm)
    for name in "MDK":
        got, want = getattr(lm, name), fd[name]
        # central differences are accurate to ~1e-7 relative to the largest entry of each row
        tol = 2e-6 * np.abs(want).max(axis=1, keepdims=True) + 1e-6
        assert np.all(np.abs(got - want) <= tol), f"{name}\n{got}\n{want}"


def test_closed_form_kernel_equals_numeric_linearization_at_trivial_point(rng):
    m = compiled_model()
    for mu in rng.uniform(0.1, 1.0, 3):
        params = get_preset("paper-fig2").resolve({"mu": float(mu), "k_ip": float(rng.uniform(1e7, 1e9))})
        lm = linearize(params)
        mats = np.array(np.stack(m.zero_linear(np.array(parameter_vector(params)))), dtype=float).reshape(3, 2, 2)
        for got, want in zip(mats, (lm.M, lm.D, lm.K)):
            assert np.allclose(got, want, rtol=1e-13, atol=1e-13 * np.abs(want).max())


def test_state_matrix_eigenvalues_solve_the_quadratic_eigenproblem(rng):
    lm = linearize(get_preset("paper-fig2").resolve())
    for lam in lm.eigenvalues:
        Q = lam**2 * lm.M + lam * lm.D + lm.K
        assert abs(np.linalg.det(Q)) <= 1e-9 * np.linalg.norm(lm.K) ** 2
    A = state_matrix(lm.M, lm.D, lm.K)
    assert A.shape == (4, 4) and np.allclose(A[:2, 2:], np.eye(2))
    assert lm.eigenvalues.real[0] >= lm.eigenvalues.real[-1]


def test_keeping_pad_rates_adds_stiff_pad_modes_away_from_trivial_point():
    base = get_preset("paper-fig3").resolve()
    params = base.replace(h10=base.h10 * 1.3)
    quasi = linearize(params, pad_rates="quasi-static").eigenvalues
    kept = pad_rate_eigenvalues(params)
    assert len(kept) == 6  # two extra first-order pad modes
    fast = kept[np.argsort(-np.abs(kept))][:2]
    assert np.all(np.abs(fast) > 1e6 * np.abs(quasi).max())  # stiff pad modes of the massless pads
    slow = kept[np.argsort(np.abs(kept))][:4]
    nearest = np.array([slow[np.argmin(np.abs(slow - lam))] for lam in quasi])
    assert np.all(np.abs(nearest - quasi) <= 1e-6 * np.abs(quasi))  # physical modes barely move
    assert np.all(np.abs(nearest.real - quasi.real) <= 1e-5 * np.abs(quasi.real))
    # at the trivial point both treatments coincide exactly (no extra finite eigenvalues)
    triv = get_preset("paper-fig3").resolve()
    assert len(pad_rate_eigenvalues(triv)) == 4


def test_missing_silent_motion_is_established_by_a_fold():
    # a very soft rotational support against a large friction moment (eq. 49): the branch of silent motions
    # connected to the trivial one folds back before the parameters are reached (found by a random search)
    from brakesqueal.model import get_preset as preset_of_any_model

    params = preset_of_any_model("general").resolve().replace(
        k_t=2.491695571611462, mu1=1.6826345592247665, mu2=0.1333800175342028, h10=0.027874097668453765,
        h20=0.0435995744628355, N0=79101.77744387428, k1=4860663.169200994, k2=597852.128134904,
        k_ip1=926195.9047145735)
    with pytest.raises(NoSilentMotionError, match=r"turns back at 72\.\d+ % of the asymmetry \(a fold\)"):
        silent_motion(params)
    # the same moment on stiffer supports: the branch reaches the parameters
    assert np.all(np.isfinite(silent_motion(params.replace(k_t=1e6)).q0))


def test_contact_loss_is_reported_with_parameter_names():
    import dataclasses

    real = compile_model("paper")

    def lifted(x, p):  # pad 2 pulled off the disk: negative normal force
        c = list(real.contact(x, p))
        c[len(CONTACT_FIELDS)] = -5.0
        return tuple(c)

    model = dataclasses.replace(real, contact=lifted)
    params = get_preset("paper-fig2").resolve()
    with pytest.raises(ContactLossError, match=r"pad '2' .*loses contact.*normal force -5 N.*N0=3600.*k2=6e\+06"):
        silent_motion_vector(model, [float(v) for v in params.vector()])


def test_trivial_silent_motion_has_preload_forces():
    params = get_preset("paper-fig3").resolve({"mu1": 0.8, "mu2": 0.2})
    sm = silent_motion(params)
    assert sm.trivial and np.all(sm.q_m0 == 0)
    assert np.allclose(sm.normal_forces, params.N0, rtol=1e-12)
    assert np.allclose(sm.sliding_speeds, params.Omega * params.r, rtol=1e-12)
    assert math.isfinite(linearize(params).max_real)


def test_descriptor_eigenvalues_match_60_digit_arithmetic():
    """The kept pad rates give a badly scaled pencil (G_dl ~ 1e-13 G_l): equilibrated QZ keeps every digit that matters."""
    import mpmath

    base = get_preset("paper-fig3").resolve()
    lm = linearize(base.replace(h10=base.h10 * 1.3))
    assert lm.pad_states
    E, A = lm.descriptor
    with mpmath.workdps(60):
        S = mpmath.inverse(mpmath.matrix(E.tolist())) * mpmath.matrix(A.tolist())
        ref = np.array([complex(z) for z in mpmath.eig(S, left=False, right=False)])
    got = lm.eigenvalues
    slow = np.abs(ref) < 1e8
    for z, is_slow in zip(ref, slow):
        nearest = got[np.argmin(np.abs(got - z))]
        if is_slow:  # the structural modes: to rounding of the pencil
            assert abs(nearest - z) <= 1e-9 * abs(z)
            assert abs(nearest.real - z.real) <= 1e-6 * abs(z.real)
        else:  # the stiff pad modes (~1e14 1/s): sign and magnitude, to 1e-5
            assert abs(nearest - z) <= 1e-5 * abs(z) and np.sign(nearest.real) == np.sign(z.real)


@pytest.mark.slow
def test_descriptor_eigenvalue_table_agrees_with_the_verdict_at_random_tilted_silent_motions():
    """The eigenvalue table and the certified verdict of one linear model never contradict each other.

    At tilted silent motions (mu1 h10 != mu2 h20, massless pads of finite k_ip) the pads' own modes reach
    1e13-1e16 1/s beside structural modes of 1e4.  Reviewed case: the table said 1.991e15 while the verdict
    (and 80-digit arithmetic) said 1.908e15.  Checked here at random points, independently of any eigenvalue
    algorithm: each listed eigenvalue makes ``lambda E - A`` singular to rounding (its smallest singular value
    over ``|lambda| |E| + |A|``), and the table's largest real part lies within the verdict's error bound of
    the verdict's ``max_real``.
    """
    rng = np.random.default_rng(20261127)
    base = get_preset("paper-fig3").resolve()
    checked = 0
    for _ in range(12):
        p = base.replace(h10=base.h10 * rng.uniform(0.6, 1.4), mu1=rng.uniform(0.15, 0.8), mu2=rng.uniform(0.15, 0.8))
        try:
            lm = linearize(p)
        except SilentMotionError:
            continue
        if not lm.pad_states:
            continue
        E, A = lm.descriptor
        lam = lm.eigenvalues
        assert lam.size == E.shape[0]
        nE, nA = np.linalg.norm(E, 2), np.linalg.norm(A, 2)
        for z in lam:
            smin = np.linalg.svd(z * E - A, compute_uv=False)[-1]
            assert smin <= 1e-12 * (abs(z) * nE + nA), (z, smin)
        from brakesqueal import eigen_analysis

        ea = eigen_analysis(lm)
        np.testing.assert_array_equal(ea.eigenvalues, lam)  # `eigen` lists what `linearize` lists
        v = ea.verdict()
        assert abs(lam.real.max() - v.max_real) <= max(v.error_bound, 1e-12 * abs(v.max_real)), (lam[:2], v)
        checked += 1
    assert checked >= 6
