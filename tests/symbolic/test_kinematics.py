"""Kinematic identities of eqs. (2)-(11), (16), (37), checked numerically at random states.

Independent routes: SymPy's own time differentiation of q(t) functions, the
cross product written out, and a direct 3x3 linear solve of eq. (16).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from brakesqueal.symbolic.kinematics import cardan_kinematics, dmat_dvec, kron, rot, tilde, tilde_matrix

q = sp.symbols("q1:4")
KIN = cardan_kinematics(sp, q)


def _num(expr, subs):
    return np.array(sp.Matrix(expr).subs(subs).evalf(30), dtype=float)


@pytest.fixture(params=range(4))
def state(request, rng):
    return {
        "q": rng.uniform(-0.6, 0.6, 3),
        "dq": rng.normal(0, 2, 3),
        "ddq": rng.normal(0, 5, 3),
    }


def test_rotations_are_proper_orthogonal(state):
    A = _num(KIN.A, dict(zip(q, state["q"])))
    assert np.allclose(A @ A.T, np.eye(3), atol=1e-14)
    assert np.isclose(np.linalg.det(A), 1.0)
    # elementary rotations turn e_y into e_z about x by +90 degrees (right-handed)
    assert np.allclose(np.array(rot(sp, "x", sp.pi / 2) * sp.Matrix([0, 1, 0]), dtype=float).ravel(), [0, 0, 1])


def test_jacobians_give_the_angular_velocity_of_A(state):
    """omega0~ = Adot A^T (definition) equals tilde(J_R0 qdot) (eq. 6) and J_R3 = A^T J_R0 (eq. 9)."""
    t = sp.Symbol("t")
    qt = [sp.Function(f"f{i}")(t) for i in range(3)]
    A_t = KIN.A.subs(dict(zip(q, qt)))
    W = (A_t.diff(t) * A_t.T).subs({sp.Derivative(qt[i], t): state["dq"][i] for i in range(3)})
    W = _num(W.subs(dict(zip(qt, state["q"]))), {})
    omega_def = np.array([W[2, 1], W[0, 2], W[1, 0]])
    sub = dict(zip(q, state["q"]))
    J0, J3, A = _num(KIN.J_R0, sub), _num(KIN.J_R3, sub), _num(KIN.A, sub)
    assert np.allclose(W, -W.T, atol=1e-12)
    assert np.allclose(J0 @ state["dq"], omega_def, rtol=1e-12, atol=1e-12)
    assert np.allclose(J3, A.T @ J0, atol=1e-14)


def test_hessian_gives_angular_acceleration(state):
    """omegadot = J_R qddot + H_R (qdot ⊗ qdot) (eqs. 10-11), against SymPy's d/dt of omega(q(t))."""
    t = sp.Symbol("t")
    qt = [sp.Function(f"f{i}")(t) for i in range(3)]
    for J, H in ((KIN.J_R0, KIN.H_R0), (KIN.J_R3, KIN.H_R3)):
        omega_t = J.subs(dict(zip(q, qt))) * sp.Matrix([sp.diff(f, t) for f in qt])
        wdot = omega_t.diff(t)
        reps = {}
        for i, f in enumerate(qt):
            reps[sp.Derivative(f, (t, 2))] = state["ddq"][i]
        for i, f in enumerate(qt):
            reps[sp.Derivative(f, t)] = state["dq"][i]
        ref = _num(wdot.subs(reps).subs(dict(zip(qt, state["q"]))), {})
        sub = dict(zip(q, state["q"]))
        got = _num(J, sub) @ state["ddq"] + _num(H, sub) @ np.kron(state["dq"], state["dq"])
        assert np.allclose(got, ref.ravel(), rtol=1e-12, atol=1e-12)


def test_matrix_tilde_convention_makes_eq37_the_gyroscopic_term(state):
    """A tilde(J_R3) (I J_R3 ⊗ E3)(qdot ⊗ qdot) == A (omega3 × I omega3) with the row-block tilde only."""
    Th, Ph = 0.16, 0.32
    I3 = sp.diag(Th, Th, Ph)
    sub = dict(zip(q, state["q"]))
    J3 = KIN.J_R3
    qq = np.kron(state["dq"], state["dq"])
    A = _num(KIN.A, sub)
    w3 = _num(J3, sub) @ state["dq"]
    ref = A @ np.cross(w3, np.diag([Th, Th, Ph]) @ w3)
    got = A @ _num(tilde_matrix(sp, J3) * kron(sp, I3 * J3, sp.eye(3)), sub) @ qq
    assert np.allclose(got, ref, rtol=1e-12, atol=1e-12)
    column_block = tilde(sp, J3[:, 0]).row_join(tilde(sp, J3[:, 1])).row_join(tilde(sp, J3[:, 2]))
    other = A @ _num(column_block * kron(sp, I3 * J3, sp.eye(3)), sub) @ qq
    assert not np.allclose(other, ref, rtol=1e-6), "the column-block tilde must not satisfy eq. (37)"
    fixed = A @ _num(column_block * kron(sp, sp.eye(3), I3 * J3), sub) @ qq
    assert np.allclose(fixed, ref, rtol=1e-12, atol=1e-12)


def test_tilde_identities(rng):
    a, b = rng.normal(size=3), rng.normal(size=3)
    J = rng.normal(size=(3, 4))
    v = rng.normal(size=4)
    assert np.allclose(np.array(tilde(sp, sp.Matrix(a)), dtype=float) @ b, np.cross(a, b))
    T = np.array(tilde_matrix(sp, sp.Matrix(J)), dtype=float)
    assert np.allclose(T @ np.kron(a, v), np.cross(J @ v, a))
    assert np.allclose(np.array(tilde_matrix(sp, sp.Matrix(a)), dtype=float), np.array(tilde(sp, sp.Matrix(a)), dtype=float))
    assert np.allclose(np.array(kron(sp, sp.Matrix(J), sp.Matrix(a)), dtype=float), np.kron(J, a[:, None]))


def test_matrix_derivative_wrt_vector_chain_rule(rng):
    """d/dt (A(q) x) = A xdot + (dA/dq)(qdot ⊗ x) for the horizontal-concatenation definition."""
    x = sp.symbols("x1:4")
    Amat = sp.Matrix([[sp.sin(q[0]) * q[1], q[2] ** 2, 1], [sp.cos(q[1] * q[2]), q[0], q[1] * q[0]]])
    dA = dmat_dvec(sp, Amat, q)
    qv, qd, xv = rng.normal(size=3), rng.normal(size=3), rng.normal(size=3)
    sub = dict(zip(q, qv))
    lhs = sum(np.array(Amat.diff(q[k]).subs(sub), dtype=float) * qd[k] for k in range(3)) @ xv
    rhs = np.array(dA.subs(sub), dtype=float) @ np.kron(qd, xv)
    assert np.allclose(lhs, rhs)
    assert dA.shape == (2, 9) and x


def test_contact_height_is_eq16_third_row(rng):
    """h from Cramer's rule equals the third unknown of the full 3x3 system of eq. (16)."""
    import symengine as se

    from brakesqueal.symbolic.contact import pad_contact

    qs = se.symbols("q1 q2 q3")
    kin = cardan_kinematics(se, qs)
    h10, l1, r = se.symbols("h10 l1 r")
    c = pad_contact(se, side=1, h0=h10, base=se.Matrix([0, -r, 0]), e_t=se.Matrix([1, 0, 0]), l=l1,
                    z3=kin.A[:, 2], omega0=se.zeros(3, 1), rate=lambda e: se.Integer(0),
                    friction=lambda v: se.Integer(0), N0=se.Integer(1), nominal_speed=r, k=se.Integer(1),
                    d=se.Integer(0), w_m=se.Integer(0))
    for _ in range(3):
        qv = rng.uniform(-0.3, 0.3, 2)
        vals = {qs[0]: qv[0], qs[1]: qv[1], qs[2]: 0.4, h10: 0.011, l1: rng.normal(0, 1e-3), r: 0.13}
        A = np.array(kin.A.subs(vals).tolist(), dtype=float)
        p_l = np.array([vals[l1], -0.13, -0.011])
        p_K = np.array([0, 0, -0.011])
        u, v, h = np.linalg.solve(np.column_stack([A[:, 0], A[:, 1], [0, 0, -1]]), p_l - A @ p_K)
        assert np.isclose(float(c.h.subs(vals)), h, rtol=1e-12, atol=1e-15)
        assert (u, v) != (None, None)
