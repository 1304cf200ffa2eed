"""Properties of the derived nonlinear equations (eqs. 35-45, 49) and the generated code."""

from __future__ import annotations

import numpy as np
import pytest
import symengine as se
import sympy as sp

from brakesqueal.codegen import build


def compiled_model():
    """The paper's compiled equations (its engine's)."""
    return build("paper").compiled
from brakesqueal.symbolic.linearize import trivial_blocks
from brakesqueal.symbolic.model import PARAMETER_SYMBOLS, STATE_SYMBOLS, derive_equations


def _params(rng):
    return {
        "Theta": 0.16, "Phi": 0.33, "k_t": 1.9e7, "d_t": 0.2, "k1": 5e6, "k2": 7e6, "d1": 4.0, "d2": 6.0,
        "c_ip1": 1 / 3e8, "c_ip2": 1 / 8e7, "mu1": 0.45, "mu2": 0.3, "h10": 0.012, "h20": 0.009, "r": 0.13,
        "N0": 2500.0, "Omega": float(rng.uniform(10, 200)),
    }  # fmt: skip


def _state(rng):
    scales = [3e-3, 3e-3, 1, 1, 300, 300, 1e-5, 1e-5, 1e-2, 1e-2]
    return dict(zip(STATE_SYMBOLS, rng.normal(0, 1, 10) * scales))


def _eval(eq, expr_matrix, state, params, extra=None):
    sub = {eq.state[k]: v for k, v in state.items()}
    sub.update({eq.params[k]: v for k, v in params.items()})
    if extra:
        sub.update(extra)
    return np.array([float(se.sympify(e).subs(sub)) for e in expr_matrix])


def test_residual_at_rest_is_eq49():
    eq = derive_equations("sympy")
    p = {n: sp.Symbol(n, positive=True) for n in PARAMETER_SYMBOLS}
    psi0 = eq.psi.subs({s: 0 for s in eq.state_vector}).xreplace({eq.params[n]: p[n] for n in PARAMETER_SYMBOLS})
    expected = sp.Matrix([0, -p["N0"] * (p["mu1"] * p["h10"] - p["mu2"] * p["h20"])])
    assert sp.simplify(psi0 - expected) == sp.zeros(2, 1)


def test_equations_do_not_depend_on_the_spin_angle(rng):
    eq = derive_equations("symengine", keep_q3=True)
    q3 = se.Symbol("q3")
    params = _params(rng)
    for _ in range(3):
        x = _state(rng)
        a = _eval(eq, eq.psi, x, params, {q3: 0.0})
        b = _eval(eq, eq.psi, x, params, {q3: float(rng.uniform(-3, 3))})
        assert np.allclose(a, b, rtol=1e-11, atol=1e-9)


def test_kronecker_and_chain_rule_routes_agree(rng):
    """The paper's Kronecker form (eqs. 35-45) vs. differentiating the angular momentum directly."""
    kr = derive_equations("symengine", kronecker=True)
    cr = derive_equations("symengine", kronecker=False)
    params = _params(rng)
    for _ in range(4):
        x = _state(rng)
        a, b = _eval(kr, kr.psi, x, params), _eval(cr, cr.psi, x, params)
        assert np.allclose(a, b, rtol=1e-10, atol=1e-10 * np.abs(b).max())


def test_spin_term_missing_from_eq44_vanishes(rng):
    """h_m = G C*(s ⊗ s) (not printed in eq. 44) is zero for the axisymmetric disk, but not for Theta_x != Theta_y."""
    eq = derive_equations("symengine")
    params = _params(rng)
    for _ in range(3):
        x = _state(rng)
        hm = _eval(eq, eq.reduced.h_m, x, params)
        scale = params["Phi"] * params["Omega"] ** 2
        assert np.all(np.abs(hm) < 1e-12 * scale)
    # sanity: with a product of inertia (spin axis not principal) the same term is not zero
    from brakesqueal.symbolic.constraint import spin_constraint
    from brakesqueal.symbolic.euler import euler_matrices
    from brakesqueal.symbolic.kinematics import cardan_kinematics, kron

    q1, q2 = se.symbols("q1 q2")
    kin = cardan_kinematics(se, (q1, q2, se.Symbol("q3")))
    kin = type(kin)(**{**kin.__dict__, "A": kin.A.subs({se.Symbol("q3"): 0}), "J_R3": kin.J_R3.subs({se.Symbol("q3"): 0}),
                       "H_R3": kin.H_R3.subs({se.Symbol("q3"): 0})})  # fmt: skip
    _, C = euler_matrices(se, kin, se.Matrix([[0.1, 0, 0.05], [0, 0.2, 0], [0.05, 0, 0.3]]))
    con = spin_constraint(se, (q1, q2), 50.0)
    val = (se.Matrix([[1, 0, 0], [0, 1, 0]]) * C * kron(se, con.s, con.s)).subs({q1: 0.1, q2: 0.2})
    assert max(abs(float(v)) for v in val) > 1.0


def test_pad_rates_do_not_enter_at_first_order_at_the_trivial_solution():
    """d psi/d ldot = d g/d ldot = 0 at q_m0 = 0 for fully general parameters (why l̇ does not matter there)."""
    eq = derive_equations("symengine")
    b = trivial_blocks(eq)
    pos = {s: sp.Symbol(str(s), positive=True) for s in eq.param_vector}
    for key in ("psi_dl", "g_dl"):
        m = sp.Matrix(sp.sympify(b[key])).xreplace({sp.Symbol(str(k)): v for k, v in pos.items()})
        assert sp.simplify(m) == sp.zeros(2, 2), key
    # and they do not vanish away from it (so the quasi-static choice is a real modelling decision)
    away = {eq.state["q2"]: 1e-3, eq.state["q1"]: 0.0}
    full = eq.psi.jacobian(se.Matrix([eq.state["dl1"], eq.state["dl2"]])).subs({**{s: 0 for s in eq.state_vector}, **away})
    vals = {eq.params[k]: v for k, v in _params(np.random.default_rng(0)).items()}
    assert max(abs(float(e.subs(vals))) for e in full) > 0


@pytest.mark.parametrize("seed", range(3))
def test_generated_code_matches_symbolic_evaluation(seed):
    rng = np.random.default_rng(seed)
    eq = derive_equations("symengine")
    params, x = _params(rng), _state(rng)
    m = compiled_model()
    pv = [params[n] for n in PARAMETER_SYMBOLS]
    xv = [x[n] for n in STATE_SYMBOLS]
    got = np.array(m.residuals(xv, pv))
    want = np.concatenate([_eval(eq, eq.psi, x, params), _eval(eq, eq.g, x, params)])
    assert np.allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
    jac = np.array(m.jacobians(xv, pv)).reshape(2, 2, 10)
    J = eq.psi.jacobian(se.Matrix(eq.state_vector))
    want_j = _eval(eq, [J[i, j] for i in range(2) for j in range(10)], x, params).reshape(2, 10)
    assert np.allclose(jac[0], want_j, rtol=1e-11, atol=1e-11 * np.abs(want_j).max())
    # vectorized NumPy binding of the same source gives the same numbers
    vec = np.array(m.vectorized.residuals(xv, pv), dtype=float)
    assert np.allclose(vec, got, rtol=1e-14, atol=0)
