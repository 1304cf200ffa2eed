"""brakesqueal.nonlinear.system: finite-difference multilinear forms against exact SymPy derivatives."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from _nl_systems import sympy_system

from brakesqueal.errors import ParameterError
from brakesqueal.nonlinear import PiecewiseSystem, SmoothSystem, Transition, fd_bilinear, fd_dp, fd_trilinear


@pytest.fixture(scope="module")
def analytic():
    """A 3-D analytic field with polynomial, trigonometric and exponential terms and a parameter."""
    x, y, z, p = sp.symbols("x y z p", real=True)
    exprs = [
        sp.sin(x) * y + p * z**2 - x**3 / 3,
        sp.exp(-y / 2) * z + x * y * z - p * sp.cos(z),
        x**2 * y - sp.sin(p * x) + z**3 * y / 5,
    ]
    return sympy_system(exprs, [x, y, z], p)


def _rand_c(rng, n):
    return rng.normal(size=n) + 1j * rng.normal(size=n)


def test_fd_bilinear_and_trilinear_match_exact_within_their_error_estimate(analytic, rng):
    """Random points and complex directions: the FD forms agree with the exact tensors, and the reported
    error estimate bounds the actual error (it is the quantity first_lyapunov uses for its tolerance)."""
    for _ in range(12):
        x = rng.normal(size=3) * 0.8
        p = float(rng.normal())
        u, v, w = _rand_c(rng, 3), _rand_c(rng, 3), _rand_c(rng, 3)
        Bx = analytic.B(x, p, u, v)
        Bf, eb = fd_bilinear(analytic.jac, x, p, u, v)
        scale = np.max(np.abs(Bx)) + 1
        assert np.max(np.abs(Bf - Bx)) <= max(eb, 1e-14 * scale)
        assert np.max(np.abs(Bf - Bx)) <= 1e-9 * scale
        assert eb <= 1e-7 * scale  # the estimate is useful, not vacuous
        Cx = analytic.C(x, p, u, v, w)
        Cf, ec = fd_trilinear(analytic.jac, x, p, u, v, w)
        scale = np.max(np.abs(Cx)) + 1
        assert np.max(np.abs(Cf - Cx)) <= max(ec, 1e-14 * scale)
        assert np.max(np.abs(Cf - Cx)) <= 1e-7 * scale
        assert ec <= 1e-5 * scale


def test_multilinear_forms_are_symmetric_and_real_for_real_vectors(analytic, rng):
    x = rng.normal(size=3)
    u, v, w = rng.normal(size=3), rng.normal(size=3), rng.normal(size=3)
    b1, _ = fd_bilinear(analytic.jac, x, 0.3, u, v)
    b2, _ = fd_bilinear(analytic.jac, x, 0.3, v, u)
    assert not np.iscomplexobj(b1)
    np.testing.assert_allclose(b1, b2, rtol=1e-9, atol=1e-10)
    c1, _ = fd_trilinear(analytic.jac, x, 0.3, u, v, w)
    c2, _ = fd_trilinear(analytic.jac, x, 0.3, w, u, v)
    np.testing.assert_allclose(c1, c2, rtol=1e-7, atol=1e-8)


def test_system_falls_back_to_finite_differences(analytic, rng):
    """A SmoothSystem without B, C, dfdp, jac_p computes them; the exact one returns error 0."""
    bare = SmoothSystem(f=analytic.f, jac=analytic.jac, n=3)
    assert not bare.exact_multilinear and analytic.exact_multilinear
    x, p = rng.normal(size=3), 0.7
    u, v = _rand_c(rng, 3), _rand_c(rng, 3)
    val, err = analytic.bilinear(x, p, u, v)
    assert err == 0.0
    np.testing.assert_allclose(bare.bilinear(x, p, u, v)[0], val, rtol=1e-9, atol=1e-10)
    np.testing.assert_allclose(bare.f_p(x, p), analytic.f_p(x, p), rtol=1e-9, atol=1e-10)
    np.testing.assert_allclose(bare.A_p(x, p), analytic.A_p(x, p), rtol=1e-9, atol=1e-10)
    np.testing.assert_allclose(fd_dp(analytic.f, x, p), analytic.dfdp(x, p), rtol=1e-9, atol=1e-10)


def test_transition_derivatives_by_differences():
    tr = Transition(guard=lambda x, p: x[0] ** 2 - p * x[1], target=0, direction=-1,
                    reset=lambda x, p: np.array([x[0], -p * x[1]]))  # fmt: skip
    x = np.array([0.7, -0.4])
    np.testing.assert_allclose(tr.grad(x, 2.0), [1.4, -2.0], rtol=1e-9)
    assert tr.h_p(x, 2.0) == pytest.approx(0.4, rel=1e-9)
    xp, G, Gp = tr.apply(x, 2.0)
    np.testing.assert_allclose(xp, [0.7, 0.8])
    np.testing.assert_allclose(G, [[1, 0], [0, -2.0]], atol=1e-9)
    np.testing.assert_allclose(Gp, [0, 0.4], atol=1e-9)


def test_bad_definitions_raise_one_line_errors():
    f = lambda x, p: x  # noqa: E731
    with pytest.raises(ParameterError, match="'n'"):
        SmoothSystem(f, f, 0)
    with pytest.raises(ParameterError, match="state_names"):
        SmoothSystem(f, f, 2, state_names=("a",))
    with pytest.raises(ParameterError, match="direction"):
        Transition(lambda x, p: 0.0, 0, direction=2)
    s1, s2 = SmoothSystem(f, f, 2), SmoothSystem(f, f, 3)
    with pytest.raises(ParameterError, match="same dimension"):
        PiecewiseSystem((s1, s2), ((), ()), lambda x, p: 0)
    with pytest.raises(ParameterError, match="targets mode"):
        PiecewiseSystem((s1,), ((Transition(lambda x, p: 0.0, 3),),), lambda x, p: 0)
