"""The package against an independent second formalism (``tests/reference/newton_euler.py``).

The reference derives the same model with ``sympy.physics.mechanics`` vectors
and dyadics (Euler's law about O, ``v2pt_theory`` sliding velocities) and
evaluates it with mpmath at 30 digits; it shares no code with the package.
Here the package's compiled nonlinear residuals, its silent motion and its
linear matrices must agree with it to 1e-9 relative.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from brakesqueal import silent_motion
from brakesqueal.analysis.equilibrium import parameter_vector
from brakesqueal import linearize
from brakesqueal.codegen import build


def compiled_model():
    """The paper's compiled equations (its engine's)."""
    return build("paper").compiled
from brakesqueal.model import Parameters, get_model
from brakesqueal.symbolic.model import PARAMETER_SYMBOLS, STATE_SYMBOLS

ref = pytest.importorskip("tests.reference.newton_euler")


def _random_params(rng: np.random.Generator, *, trivial: bool, finite_kip: bool = True) -> Parameters:
    mu1, mu2 = rng.uniform(0.1, 0.8, 2)
    h20 = rng.uniform(0.005, 0.015)
    h10 = mu2 * h20 / mu1 if trivial else rng.uniform(0.005, 0.015)
    kip = rng.uniform(2e7, 5e8, 2) if finite_kip else (math.inf, math.inf)
    return Parameters(get_model("paper"), dict(
        Theta=rng.uniform(0.1, 0.3), Phi=rng.uniform(0.2, 0.5), k_t=rng.uniform(5e6, 3e7), d_t=rng.uniform(0, 1),
        k1=rng.uniform(2e6, 9e6), k2=rng.uniform(2e6, 9e6), d1=rng.uniform(1, 10), d2=rng.uniform(1, 10),
        k_ip1=kip[0], k_ip2=kip[1], mu1=mu1, mu2=mu2, h10=h10, h20=h20, r=rng.uniform(0.08, 0.16),
        N0=rng.uniform(1000, 5000), Omega=rng.uniform(5, 300),
    ))  # fmt: skip


def _ref_params(p: Parameters) -> dict[str, float]:
    return dict(zip(PARAMETER_SYMBOLS, parameter_vector(p)))


def assert_close(a, b, rtol=1e-9, label=""):
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = np.maximum(np.abs(b), 1e-12 * np.max(np.abs(b)))
    err = np.max(np.abs(a - b) / scale)
    assert err <= rtol, f"{label}: max relative deviation {err:.3e}\npackage={a}\nreference={b}"


@pytest.mark.parametrize("seed", range(6))
def test_nonlinear_residuals_agree_at_random_states(seed):
    rng = np.random.default_rng(seed)
    p = _random_params(rng, trivial=bool(seed % 2))
    x = {
        "q1": rng.normal(0, 2e-3), "q2": rng.normal(0, 2e-3), "dq1": rng.normal(0, 0.5), "dq2": rng.normal(0, 0.5),
        "ddq1": rng.normal(0, 500), "ddq2": rng.normal(0, 500), "l1": rng.normal(0, 1e-5), "l2": rng.normal(0, 1e-5),
        "dl1": rng.normal(0, 1e-2), "dl2": rng.normal(0, 1e-2),
    }  # fmt: skip
    psi_ref, g_ref = ref.residuals(x, _ref_params(p))
    out = compiled_model().residuals([x[n] for n in STATE_SYMBOLS], parameter_vector(p))
    assert_close(out[:2], psi_ref, label="psi")
    assert_close(out[2:], g_ref, label="g")


@pytest.mark.parametrize("seed", range(4))
def test_linear_matrices_agree_at_random_general_parameters(seed):
    rng = np.random.default_rng(100 + seed)
    trivial = seed < 2
    p = _random_params(rng, trivial=trivial, finite_kip=seed != 1)
    pr = _ref_params(p)
    lm = linearize(p, pad_rates="quasi-static")  # the reference eliminates the pads with dl := 0
    if trivial:
        state0 = {n: 0.0 for n in ref.STATE}
        assert lm.silent.trivial
    else:
        state0 = ref.silent_motion(pr)
        # vector norms: q1 is ~1e-13 rad here, below double resolution next to q2 ~ 1e-7 rad
        assert np.linalg.norm(lm.q0 - [state0["q1"], state0["q2"]]) <= 1e-9 * np.hypot(state0["q1"], state0["q2"])
        # g = l + c (f_x + mu N0) cancels the preload friction mu N0 in double precision, so l is resolved to
        # rounding of the preload deformation c mu N0 (~1e-5 m), i.e. ~1e-20 m absolute: allow that floor
        floor = 1e-14 * max(c * mu * p.N0 for c, mu in ((1 / p.k_ip1, p.mu1), (1 / p.k_ip2, p.mu2)))
        want_l = np.array([state0["l1"], state0["l2"]])
        assert np.linalg.norm(lm.silent.l0 - want_l) <= 1e-9 * np.linalg.norm(want_l) + floor
    M, D, K = ref.linearize(state0, pr)
    assert_close(lm.M, M, label="M")
    assert_close(lm.D, D, label="D")
    assert_close(lm.K, K, label="K")


def test_silent_motion_satisfies_the_reference_equations():
    rng = np.random.default_rng(7)
    p = _random_params(rng, trivial=False)
    sm = silent_motion(p)
    x = dict(zip(STATE_SYMBOLS, sm.state()))
    psi, g = ref.residuals(x, _ref_params(p))
    assert np.max(np.abs(psi)) < 1e-9 * p.k_t * max(abs(sm.q_m0).max(), 1e-9)
    assert np.max(np.abs(g)) < 1e-12
