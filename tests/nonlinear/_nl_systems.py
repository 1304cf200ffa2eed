"""Test systems for brakesqueal.nonlinear, built with SymPy so that every derivative is exact.

``sympy_system`` differentiates the vector field symbolically (Jacobian, f_p, A_p and the second and
third derivative tensors, contracted by einsum for ``B`` and ``C``); the closed forms used as
references in the tests are derived independently in the test files.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from brakesqueal.nonlinear import SmoothSystem


def _lam(args, expr):
    """Lambdified ``expr`` (matrix or array) for scalar-valued entries: returns a float ndarray."""
    fn = sp.lambdify(args, expr.tolist() if hasattr(expr, "tolist") else expr, "numpy", cse=True)

    def call(x, p):
        return np.array(fn(*(x, p)), dtype=float)

    return call


def sympy_system(exprs, xs, p, *, exact_multilinear=True, **kw) -> SmoothSystem:
    """A SmoothSystem with exact f, jac, dfdp, jac_p and (optionally) exact B, C from SymPy."""
    F = sp.Matrix(exprs)
    X = sp.Matrix(xs)
    n = len(xs)
    J = F.jacobian(X)
    args = (sp.Matrix(xs), p)
    f = _lam(args, F)
    jac = _lam(args, J)
    fp = _lam(args, F.diff(p))
    jp = _lam(args, J.diff(p))
    extra = {}
    if exact_multilinear:
        H = sp.Array([[[sp.diff(F[i], xs[j], xs[k]) for k in range(n)] for j in range(n)] for i in range(n)])
        T3 = sp.Array([[[[sp.diff(F[i], xs[j], xs[k], xs[l]) for l in range(n)] for k in range(n)] for j in range(n)]
                       for i in range(n)])
        Hn = _lam(args, H)
        Tn = _lam(args, T3)
        extra["B"] = lambda x, pp, u, v: np.einsum("ijk,j,k->i", Hn(x, pp), u, v)
        extra["C"] = lambda x, pp, u, v, w: np.einsum("ijkl,j,k,l->i", Tn(x, pp), u, v, w)
    return SmoothSystem(f=lambda x, pp: f(x, pp).ravel(), jac=jac, n=n, dfdp=lambda x, pp: fp(x, pp).ravel(),
                        jac_p=jp, **extra, **kw)


def hopf_normal_form(omega: float, c: complex, **kw) -> SmoothSystem:
    """z' = (mu + i omega) z + c z |z|^2 in Cartesian coordinates (x1, x2) = (Re z, Im z)."""
    x1, x2, mu = sp.symbols("x1 x2 mu", real=True)
    z = x1 + sp.I * x2
    dz = sp.expand((mu + sp.I * sp.nsimplify(omega)) * z + (sp.nsimplify(c.real) + sp.I * sp.nsimplify(c.imag)) * z**2 * sp.conjugate(z))
    return sympy_system([sp.re(dz), sp.im(dz)], [x1, x2], mu, parameter_name="mu", **kw)


def brusselator(A: float, **kw) -> SmoothSystem:
    """x' = A - (B + 1) x + x^2 y, y' = B x - x^2 y; parameter B (Hopf at B = 1 + A^2)."""
    x, y, B = sp.symbols("x y B", real=True)
    a = sp.nsimplify(A)
    return sympy_system([a - (B + 1) * x + x**2 * y, B * x - x**2 * y], [x, y], B, parameter_name="B",
                        state_names=("x", "y"), **kw)


def van_der_pol(**kw) -> SmoothSystem:
    """x'' - (mu - x^2) x' + x = 0 as x' = v, v' = -x + (mu - x^2) v."""
    x, v, mu = sp.symbols("x v mu", real=True)
    return sympy_system([v, -x + (mu - x**2) * v], [x, v], mu, parameter_name="mu", state_names=("x", "v"), **kw)


def bautin(beta: float = 1.0, **kw) -> SmoothSystem:
    """r' = r (mu + beta r^2 - r^4), theta' = 1 in Cartesian form."""
    x1, x2, mu = sp.symbols("x1 x2 mu", real=True)
    r2 = x1**2 + x2**2
    g = mu + sp.nsimplify(beta) * r2 - r2**2
    return sympy_system([g * x1 - x2, g * x2 + x1], [x1, x2], mu, parameter_name="mu", **kw)


def period_doubling(d: float = 2.0, **kw) -> SmoothSystem:
    """Cycle r = sqrt(p), T = 2 pi; transverse (u, v) turning by half a revolution per period.

    Multipliers: 1, exp(-4 pi p), -exp(2 pi (-1 + d sqrt(p))), -exp(2 pi (-1 - d sqrt(p))); PD at p = 1/d^2.
    """
    x, y, u, v, p = sp.symbols("x y u v p", real=True)
    dd = sp.nsimplify(d)
    g = p - x**2 - y**2
    return sympy_system([g * x - y, g * y + x, -v / 2 - u + dd * (x * u + y * v), u / 2 - v + dd * (y * u - x * v)],
                        [x, y, u, v], p, **kw)


def neimark_sacker(a: float = 0.3, k: float = 4.0, **kw) -> SmoothSystem:
    """Cycle r = sqrt(p), T = 2 pi; transverse focus w' = (-1 + k r^2) w + a J w.

    Multipliers: 1, exp(-4 pi p), exp(2 pi (-1 + k p)) exp(+-2 pi i a); NS at p = 1/k.
    """
    x, y, u, v, p = sp.symbols("x y u v p", real=True)
    r2 = x**2 + y**2
    g = p - r2
    s = -1 + sp.nsimplify(k) * r2
    aa = sp.nsimplify(a)
    return sympy_system([g * x - y, g * y + x, s * u - aa * v, aa * u + s * v], [x, y, u, v], p, **kw)


def friction_oscillator(exact: bool = True, **kw) -> SmoothSystem:
    """The 4-state 2-DOF friction-type (mode-coupling) oscillator of ``benchmarks/bench_nonlinear.py``.

    q'' + C q' + K(p) q + k_n q^3 + d_n q^2 q' = 0 (cubic terms componentwise), K(p) = [[k1, p], [-p, k2]],
    C = diag(c1, c2); state (q1, q2, dq1, dq2), parameter p; exact B, C unless ``exact=False``.
    """
    q1, q2, v1, v2, p = sp.symbols("q1 q2 dq1 dq2 p", real=True)
    k1, k2, c1, c2, kn, dn = 1, sp.Rational(3, 2), sp.Rational(1, 50), sp.Rational(1, 50), sp.Rational(1, 2), \
        sp.Rational(3, 10)  # fmt: skip
    exprs = [v1, v2, -(k1 * q1 + p * q2) - c1 * v1 - kn * q1**3 - dn * q1**2 * v1,
             -(-p * q1 + k2 * q2) - c2 * v2 - kn * q2**3 - dn * q2**2 * v2]
    return sympy_system(exprs, [q1, q2, v1, v2], p, exact_multilinear=exact, parameter_name="p",
                        state_names=("q1", "q2", "dq1", "dq2"), **kw)
