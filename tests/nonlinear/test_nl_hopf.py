"""First Lyapunov coefficient: closed forms on textbook systems, derived independently in the tests."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from _nl_systems import bautin, brusselator, hopf_normal_form, sympy_system, van_der_pol

from brakesqueal.errors import BrakesquealError, ParameterError
from brakesqueal.nonlinear import SmoothSystem, first_lyapunov


def _check_normalisation(h):
    A = h.eigenvalue.imag
    assert abs(np.vdot(h.q, h.q) - 1) < 1e-13
    assert abs(np.vdot(h.p, h.q) - 1) < 1e-13
    assert A == pytest.approx(h.omega0)


@pytest.mark.parametrize("seed", range(4))
def test_hopf_normal_form_c1_is_exact(seed):
    """z' = (mu + i w) z + c z|z|^2: with <q, q> = 1 the Cartesian embedding gives |x|^2 = 2|z|^2, so the
    normal-form coefficient is exactly c1 = 2 c (also its imaginary part), l1 = 2 Re(c) / w."""
    rng = np.random.default_rng(seed)
    w = float(rng.uniform(0.3, 5))
    c = complex(round(rng.normal(), 3), round(rng.normal(), 3))
    for exact in (True, False):
        s = hopf_normal_form(w, c, exact_multilinear=exact)
        h = first_lyapunov(s, [0.0, 0.0], 0.01)
        _check_normalisation(h)
        assert h.p0 == pytest.approx(0.0, abs=1e-14)
        tol = 1e-12 if exact else 1e-8
        assert abs(h.c1 - 2 * c) <= tol * max(1, abs(c))
        assert h.l1 == pytest.approx(2 * c.real / w, rel=tol, abs=tol)
        assert abs(h.l1 - 2 * c.real / w) <= max(h.l1_error, 1e-15)  # the estimate covers the actual error
        assert h.multilinear == ("exact" if exact else "finite-difference")
        assert h.criticality == ("supercritical" if c.real < 0 else "subcritical")
        assert h.dlambda_dp == pytest.approx(1.0)
        # cycle |z|^2 = -mu/Re c: first harmonic of x1 is |z|, i.e. a_j = 1/sqrt|Re c|, omega' = -Im c / Re c
        np.testing.assert_allclose(h.amplitude_coefficients, 1 / math.sqrt(abs(c.real)), rtol=1e-7)
        assert h.frequency_slope == pytest.approx(-c.imag / c.real, rel=1e-7, abs=1e-9)
        assert h.side == (1 if c.real < 0 else -1)


def _brusselator_l1_guckenheimer_holmes(A_val: float) -> float:
    """Independent route: Jordan coordinates + the planar formula of Guckenheimer & Holmes (eq. 3.4.11),
    then the MatCont normalisation: x - x0 = Re(w v), v = T0 - i T1, so c1 = 4 a / |v|^2."""
    A = sp.nsimplify(A_val)
    x, y, u1, u2 = sp.symbols("x y u1 u2")
    B0 = 1 + A**2
    f = sp.Matrix([A - (B0 + 1) * x + x**2 * y, B0 * x - x**2 * y])
    xe = sp.Matrix([A, B0 / A])
    J = f.jacobian([x, y]).subs({x: xe[0], y: xe[1]})
    w = A  # eigenvalues +-iA (trace 0, det A^2)
    q0 = sp.Matrix([J[0, 1], sp.I * w - J[0, 0]])
    T = sp.Matrix.hstack(q0.applyfunc(sp.re), -q0.applyfunc(sp.im))
    xs = xe + T * sp.Matrix([u1, u2])
    rhs = sp.expand(T.inv() * f.subs({x: xs[0], y: xs[1]}))
    lin = rhs.jacobian([u1, u2]).subs({u1: 0, u2: 0})
    assert sp.simplify(lin - sp.Matrix([[0, -w], [w, 0]])) == sp.zeros(2)
    F = sp.expand(rhs[0] - lin[0, 0] * u1 - lin[0, 1] * u2)
    G = sp.expand(rhs[1] - lin[1, 0] * u1 - lin[1, 1] * u2)

    def d(e, *v):
        return sp.diff(e, *v).subs({u1: 0, u2: 0})

    a = (d(F, u1, u1, u1) + d(F, u1, u2, u2) + d(G, u1, u1, u2) + d(G, u2, u2, u2)) / 16 + (
        d(F, u1, u2) * (d(F, u1, u1) + d(F, u2, u2)) - d(G, u1, u2) * (d(G, u1, u1) + d(G, u2, u2))
        - d(F, u1, u1) * d(G, u1, u1) + d(F, u2, u2) * d(G, u2, u2)
    ) / (16 * w)  # fmt: skip
    return float(4 * a / (w * sum(sp.Abs(c) ** 2 for c in q0)))


@pytest.mark.parametrize("A", [0.5, 1.0, 2.0])
def test_brusselator_l1_matches_the_guckenheimer_holmes_route(A):
    ref = _brusselator_l1_guckenheimer_holmes(A)
    assert ref == pytest.approx(-(A**2 + 2) / (2 * A * (2 * A**2 + 1)), rel=1e-14)  # the closed form it simplifies to
    s = brusselator(A)
    h = first_lyapunov(s, [A, (1 + A**2) / A], 1 + A**2 + 0.05)  # refined from an off-Hopf parameter
    _check_normalisation(h)
    assert h.p0 == pytest.approx(1 + A**2, rel=1e-14)
    assert h.omega0 == pytest.approx(A, rel=1e-14)
    assert h.l1 == pytest.approx(ref, rel=1e-12)
    assert h.criticality == "supercritical"
    # transversality: trace = B - 1 - A^2, so Re(lambda) = (B - 1 - A^2)/2 along the equilibrium branch
    assert h.dRe_lambda_dp == pytest.approx(0.5, rel=1e-12)
    np.testing.assert_allclose(h.dx0_dp, [0.0, 1 / A], atol=1e-13)
    hf = first_lyapunov(brusselator(A, exact_multilinear=False), [A, (1 + A**2) / A], 1 + A**2)
    assert abs(hf.l1 - ref) <= hf.l1_error and hf.l1_error < 1e-6 * abs(ref)


def test_van_der_pol_averaging_closed_form():
    """x'' - (mu - x^2) x' + x = 0: averaging gives r' = r (mu - r^2/4) / 2, amplitude 2 sqrt(mu) in x and
    in x', frequency 1 + O(mu^2); in the MatCont normalisation (|q_x| = |q_v| = 1/sqrt 2) l1 = -1/4."""
    for exact in (True, False):
        h = first_lyapunov(van_der_pol(exact_multilinear=exact), [0.0, 0.0], 0.0, refine=False)
        assert h.l1 == pytest.approx(-0.25, rel=1e-12 if exact else 1e-8)
        np.testing.assert_allclose(h.amplitude_coefficients, [2.0, 2.0], rtol=1e-8)
        assert h.frequency_slope == pytest.approx(0.0, abs=1e-8)
        assert h.dRe_lambda_dp == pytest.approx(0.5)
        assert h.side == 1 and h.criticality == "supercritical"
        g = h.cycle_guess(0.01)
        assert g.period == pytest.approx(2 * math.pi, rel=1e-8)
        np.testing.assert_allclose(g.amplitude, [0.2, 0.2], rtol=1e-8)


def test_amplitude_prediction_is_independent_of_units():
    """Rescaling a coordinate (x -> 1000 x, as SI units would) changes q's normalisation and l1, but
    the predicted first-harmonic amplitudes scale with the coordinate, and the frequency is unchanged."""
    x, v, mu = sp.symbols("x v mu", real=True)
    k = 1000
    X = x / k  # X is the original coordinate, x = k X
    scaled = sympy_system([k * v, -X + (mu - X**2) * v], [x, v], mu)
    h0 = first_lyapunov(van_der_pol(), [0, 0], 0.0)
    h1 = first_lyapunov(scaled, [0, 0], 0.0)
    assert abs(h1.l1 / h0.l1) < 1e-3  # l1 depends on the normalisation
    np.testing.assert_allclose(h1.amplitude_coefficients, [k * 2.0, 2.0], rtol=1e-10)
    assert h1.frequency_slope == pytest.approx(h0.frequency_slope, abs=1e-10)


def test_degenerate_hopf_point_is_reported_as_such():
    """r' = r (mu + beta r^2 - r^4) with beta = 0 has l1 = 0 exactly (a Bautin point)."""
    for exact in (True, False):
        h = first_lyapunov(bautin(beta=0.0, exact_multilinear=exact), [0, 0], 0.0)
        assert h.criticality == "degenerate"
        assert abs(h.l1) <= 10 * h.l1_error
        assert h.side == 0
        with pytest.raises(BrakesquealError, match="degenerate"):
            h.cycle_guess(0.1)
    h = first_lyapunov(bautin(beta=1e-3), [0, 0], 0.0)
    assert h.criticality == "subcritical" and h.l1 == pytest.approx(2e-3, rel=1e-9)


def test_wrong_side_and_bad_inputs():
    h = first_lyapunov(van_der_pol(), [0, 0], 0.0)
    with pytest.raises(ParameterError, match="side without cycles"):
        h.amplitude(-0.1)
    with pytest.raises(ParameterError, match="x0"):
        first_lyapunov(van_der_pol(), [0, 0, 0], 0.0)
    with pytest.raises(ParameterError, match="not a Hopf point"):
        first_lyapunov(van_der_pol(), [0, 0], 0.1, refine=False)
    real = SmoothSystem(lambda x, p: np.array([-x[0], p * x[1]]), lambda x, p: np.diag([-1.0, p]), 2)
    with pytest.raises(ParameterError, match="no complex eigenvalue pair"):
        first_lyapunov(real, [0, 0], 1.0)
    none = SmoothSystem(lambda x, p: np.array([1 + x[0] ** 2, -x[0] + p * x[1]]),
                        lambda x, p: np.array([[2 * x[0], 0.0], [-1.0, p]]), 2)  # no equilibrium at all
    with pytest.raises(BrakesquealError, match="equilibrium"):
        first_lyapunov(none, [0.5, 0.0], 0.1)
    assert h.as_dict()["criticality"] == "supercritical"


def test_mode_coupling_hopf_tracks_the_critical_pair():
    """2-DOF friction-type oscillator with equal damping: at the Hopf point both pairs have the same
    frequency (mode coupling).  Refinement from either side must follow the pair that crosses, and
    dRe_lambda_dp must match a finite difference of that eigenvalue (tracked by its eigenvector)."""
    from _nl_systems import friction_oscillator

    s, sfd = friction_oscillator(), friction_oscillator(exact=False)
    _jac = s.jac
    ref = first_lyapunov(s, np.zeros(4), 0.2509980079602)
    assert abs(ref.eigenvalue.real) < 1e-12
    for p0 in (0.2509, 0.2511):
        h = first_lyapunov(s, np.zeros(4), p0)
        assert h.p0 == pytest.approx(ref.p0, abs=1e-12)
        assert h.l1 == pytest.approx(ref.l1, rel=1e-9)
    hf = first_lyapunov(sfd, np.zeros(4), ref.p0)
    assert abs(hf.l1 - ref.l1) <= hf.l1_error
    assert ref.criticality == "supercritical"

    def crit(p):
        lam, V = np.linalg.eig(_jac(np.zeros(4), p))
        k = np.argmax([abs(np.vdot(ref.q, V[:, j])) for j in range(4)])
        return lam[k]

    d = 1e-7
    assert ref.dRe_lambda_dp == pytest.approx(((crit(ref.p0 + d) - crit(ref.p0 - d)) / (2 * d)).real, rel=1e-5)


def _si_scaled(base, W=1.0e4, L=1e-5, exact=True):
    """The benchmark oscillator in brake-like SI units: t_SI = t / W, angles x L, rates x L W."""
    S = np.diag([L, L, L * W, L * W])
    Si = np.linalg.inv(S)
    kw = {}
    if exact:
        kw = {"B": lambda x, p, u, v: W * S @ base.B(Si @ x, p, Si @ u, Si @ v),
              "C": lambda x, p, u, v, w: W * S @ base.C(Si @ x, p, Si @ u, Si @ v, Si @ w)}  # fmt: skip
    return S, SmoothSystem(lambda x, p: W * S @ base.f(Si @ x, p), lambda x, p: W * S @ base.jac(Si @ x, p) @ Si, 4,
                           dfdp=lambda x, p: W * S @ base.dfdp(Si @ x, p), **kw)  # fmt: skip


def test_badly_scaled_si_states_keep_a_sharp_error_estimate():
    """Stiffness entries ~1e8 next to ones (SI states) must not inflate the error estimate into a false
    'degenerate' verdict: l1 from exact and from finite-difference forms agree to 1e-10 and the
    estimate stays small; a_j carry the units (angles x L, rates x L W), omega0 x W."""
    from _nl_systems import friction_oscillator

    base = friction_oscillator()
    h0 = first_lyapunov(base, np.zeros(4), 0.2509980079602)
    for exact in (True, False):
        S, s = _si_scaled(base, exact=exact)
        h = first_lyapunov(s, np.zeros(4), 0.2509980079602)
        assert h.criticality == "supercritical"
        assert h.l1_error < 1e-8 * abs(h.l1)
        assert h.omega0 == pytest.approx(1e4 * h0.omega0, rel=1e-12)
        np.testing.assert_allclose(h.amplitude_coefficients, np.diag(S) * h0.amplitude_coefficients, rtol=1e-8)
        assert h.frequency_slope == pytest.approx(1e4 * h0.frequency_slope, rel=1e-7)
