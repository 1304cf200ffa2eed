"""critical-speed at the magnitude bound (1e±100): every certain verdict agrees with exact arithmetic (issue 11).

The characteristic polynomial ``det(M s^2 + D s + K)`` of the paper's closed
form (eqs. 51-54, derived with SymPy here, independently of the compiled
kernels) is evaluated in exact rationals at points between and beyond the
reported crossings; Routh-Hurwitz for the quartic gives the verdict.  A
route that claimed certainty it does not have (overflow in products of
1e100-sized terms) would disagree here.
"""

from __future__ import annotations

import math

import pytest
import sympy as sp

from brakesqueal import critical_speeds
from brakesqueal.model.parameters import ParameterSpace

BASE = {"mu1": "0.6", "mu2": "0.4", "k_ip": "1e8", "h": "0.02", "r": "0.13", "k_t": "1.88e7", "d_t": "0.1",
        "k1": "6e6", "k2": "6e6", "d1": "5", "d2": "5", "Phi": "0.32", "N0": "3000", "R_disk": "0.15"}


@pytest.fixture(scope="module")
def charpoly():
    """The quartic's coefficients as functions of the paper-fig3 parameters (exact, SymPy)."""
    names = ("Theta Phi k_t d_t k1 k2 d1 d2 k_ip1 k_ip2 mu1 mu2 h10 h20 r N0 Omega s").split()
    S = dict(zip(names, sp.symbols(names)))
    Theta, Phi, k_t, d_t, k1, k2, d1, d2, kp1, kp2, mu1, mu2, h10, h20, r, N0, Om, s = (S[n] for n in names)
    # the paper's eqs. (51)-(54) for q_m0 = 0 (eq. 49 holds in paper-fig3), as printed by `brakesqueal derive`
    M = sp.Matrix([[Theta, 0], [0, Theta]])
    D = sp.Matrix([
        [(N0*Om*d1*h10*kp2*mu1**2*r + N0*Om*d2*h20*kp1*mu2**2*r + N0*h10**2*kp1*kp2*mu1 + N0*h20**2*kp1*kp2*mu2
          + Om*d1*kp1*kp2*r**3 + Om*d2*kp1*kp2*r**3 + Om*d_t*kp1*kp2*r)/(Om*kp1*kp2*r), Om*Phi],
        [(N0*d1*kp2*mu1*r + N0*d2*kp1*mu2*r - Om*Phi*kp1*kp2 - d1*h10*kp1*kp2*mu1*r - d2*h20*kp1*kp2*mu2*r)
         / (kp1*kp2), d_t]])
    K = sp.Matrix([
        [(N0*h10*k1*kp2*mu1**2 + N0*h10*kp1*kp2 + N0*h20*k2*kp1*mu2**2 + N0*h20*kp1*kp2 + k1*kp1*kp2*r**2
          + k2*kp1*kp2*r**2 + kp1*kp2*k_t)/(kp1*kp2),
         N0*(-N0*h10*kp2*mu1**3 - N0*h10*kp2*mu1 - N0*h20*kp1*mu2**3 - N0*h20*kp1*mu2 + h10**2*kp1*kp2*mu1
             + h20**2*kp1*kp2*mu2)/(kp1*kp2*r)],
        [r*(N0*k1*kp2*mu1 + N0*k2*kp1*mu2 - N0*kp1*kp2*mu1 - N0*kp1*kp2*mu2 - h10*k1*kp1*kp2*mu1
            - h20*k2*kp1*kp2*mu2)/(kp1*kp2),
         (-N0**2*kp1*mu2**2 - N0**2*kp1 - N0**2*kp2*mu1**2 - N0**2*kp2 + N0*h10*kp1*kp2*mu1**2 + N0*h10*kp1*kp2
          + N0*h20*kp1*kp2*mu2**2 + N0*h20*kp1*kp2 + kp1*kp2*k_t)/(kp1*kp2)]])
    return S, (M, D, K)


def _exact_verdict(charpoly, values: dict[str, str], omega: float) -> str:
    S, (M, D, K) = charpoly
    v = {k: sp.Rational(x) for k, x in values.items()}
    kip = v.pop("k_ip")
    h, Rd = v.pop("h"), v.pop("R_disk")
    v.update(k_ip1=kip, k_ip2=kip, h10=h*v["mu2"]/(v["mu1"] + v["mu2"]), h20=h*v["mu1"]/(v["mu1"] + v["mu2"]))
    v["Theta"] = v["Phi"]/2 + v["Phi"]/(2*Rd**2)*(v["h10"] - v["h20"])**2
    v["Omega"] = sp.Rational(repr(omega))
    sub = {S[k]: x for k, x in v.items()}
    s = S["s"]
    c = sp.Poly(sp.expand((M.subs(sub)*s**2 + D.subs(sub)*s + K.subs(sub)).det()), s).all_coeffs()  # exact
    if c[0] < 0:
        c = [-x for x in c]
    a4, a3, a2, a1, a0 = c
    h3 = a3*a2*a1 - a4*a1**2 - a3**2*a0
    return "stable" if all(x > 0 for x in c) and h3 > 0 else "unstable"


@pytest.mark.parametrize("name,value", [("k_ip", "1e100"), ("k_t", "1e100"), ("N0", "1e100"), ("Phi", "1e100"),
                                        ("d1", "1e100"), ("Phi", "2e-100"), ("N0", "1e-100"), ("k_ip", "1e-100")])
@pytest.mark.slow
def test_critical_speeds_at_the_magnitude_bound_agree_with_exact_hurwitz(charpoly, name, value):
    values = {**BASE, name: value}
    space = ParameterSpace.from_preset("paper-fig3", {name: float(value)})
    r = critical_speeds(space, 1.0, 1e5)
    d = r.to_dict()
    assert set(d) >= {"stable_at_start", "crossings"}, d
    roots = [c["value"] if isinstance(c, dict) else c[0] for c in d.get("crossings", [])]
    certain = d.get("exhaustive", True) and not d.get("undecided_ranges")
    edges = [1.0, *roots, 1e5]
    probes = [math.sqrt(a * b) for a, b in zip(edges[:-1], edges[1:])]  # one point inside every interval
    expected = "stable" if d["stable_at_start"] else "unstable"
    for k, omega in enumerate(probes):
        if certain:
            assert _exact_verdict(charpoly, values, omega) == expected, (name, value, omega, d)
        if k < len(roots):
            expected = "unstable" if expected == "stable" else "stable"


@pytest.mark.slow
@pytest.mark.parametrize("preset,hi", [("paper-fig3", 1e300), ("paper-fig2", 1e150)])
def test_a_range_past_omegas_bound_is_undecided_there_and_agrees_with_crossings(preset, hi):
    # |Omega| <= 1e100 (the parameter table): a verdict beyond it would be on invalid parameter sets.  Both
    # critical-speed routes and `crossings` must list that piece as undecided and agree on everything else.
    import numpy as np

    from brakesqueal import critical_speeds_many, crossings
    from brakesqueal import Axis
    from brakesqueal.status import PointStatus

    space = ParameterSpace.from_preset(preset)
    r = critical_speeds(space, 1.0, hi)
    c = crossings(space, Axis("Omega", 1.0, hi, 2, True))
    assert not r.complete and r.undecided_ranges, r.to_dict()
    assert any(a <= 1e100 and b >= hi for a, b in r.undecided_ranges), r.undecided_ranges
    assert r.undecided_ranges == c.undecided_ranges and r.crossings == c.crossings
    assert r.stable_at_start == c.stable_at_start
    # the onset below the bound is still established
    within = critical_speeds(space, 1.0, 1e100)
    assert within.complete and r.Omega_crit == pytest.approx(within.Omega_crit, rel=1e-10)  # kernel: 1e-10
    assert r.Omega_crit_certain
    _, _, counts, _, status = critical_speeds_many(space, {"mu": np.array([0.3])} if preset == "paper-fig2"
                                                   else {"mu1": np.array([0.3])}, 1.0, hi, return_status=True)
    assert (status == int(PointStatus.UNDECIDED)).all(), status
    _, _, _, _, status_in = critical_speeds_many(space, {}, 1.0, 1e100, return_status=True)
    assert (status_in == int(PointStatus.OK)).all()


@pytest.mark.slow
def test_verdict_line_and_listed_eigenvalues_agree_at_extreme_values():
    """``linearize`` printed "UNSTABLE: max Re = 0.0" beside a listed 1.29e30 (mu = 1e90, k_ip = inf), and a
    verdict max Re of 1.55e11 beside a listed 0.0 (mu = 1e30): double-precision eigenvalues of matrices whose
    entries span 1e100.  Reference: the roots of det(lambda^2 M + lambda D + K) from the float matrices taken as
    exact rationals (SymPy), found by mpmath.polyroots at 120 digits."""
    import mpmath
    import numpy as np

    from brakesqueal import linearize, resolve_space
    from brakesqueal import eigen_analysis

    def charpoly_exact(M, D, K):
        """Exact ascending coefficients of det(lam^2 M + lam D + K), the floats taken as exact rationals (SymPy)."""
        import sympy as sp
        from fractions import Fraction

        lam = sp.Symbol("lam")
        n = np.shape(M)[0]
        Q = sp.Matrix(n, n, lambda i, j: lam ** 2 * sp.Rational(float(M[i][j])) + lam * sp.Rational(float(D[i][j]))
                      + sp.Rational(float(K[i][j])))
        p = sp.Poly(Q.det(method="berkowitz"), lam)
        return [Fraction(int(c.p), int(c.q)) for c in (sp.Rational(p.coeff_monomial(lam ** k)) for k in range(2 * n + 1))]


    rng = np.random.default_rng(27)
    cases = [("mu=1e90", "k_ip=inf"), ("k_ip=1e-100",), ("mu=1e30",), ("mu=1e50",), ("mu=0.4",)]
    cases += [(f"mu={10 ** rng.uniform(-6, 90)!r}", f"k_ip={10 ** rng.uniform(-100, 100)!r}") for _ in range(6)]
    for sets in cases:
        lm = linearize(resolve_space(None, None, None, list(sets)).resolve({}))
        coeffs = charpoly_exact(lm.M, lm.D, lm.K)
        with mpmath.workdps(120):
            c = [mpmath.mpf(f.numerator) / f.denominator for f in reversed(coeffs)]
            ref = np.array([complex(z) for z in mpmath.polyroots(c, maxsteps=400, extraprec=2000)])
        lam = lm.eigenvalues
        assert lam.size == ref.size
        for z in ref:
            assert np.min(np.abs(lam - z)) <= 1e-9 * abs(z), sets
        v = eigen_analysis(lm).verdict()
        if (ref.real.max() < 0) == (v.max_real < 0) or v.status == "undecided":
            assert v.max_real == pytest.approx(ref.real.max(), rel=1e-9)
        else:
            # the float matrices' eigenvalues are not resolved here (entries spanning 1e50: rounding the entries
            # to double moves the roots across the axis); the verdict is that of the exact linearization, the
            # closed form at the exact parameter values: its quartic's roots at 120 digits are the reference
            from brakesqueal.analysis.robust import _quartic_exact, exact_trivial_entries
            from brakesqueal.codegen import build

            q = _quartic_exact(exact_trivial_entries(build(lm.model), [float(x) for x in lm.params.vector()]))
            with mpmath.workdps(120):
                qq = [mpmath.mpf(f.numerator) / f.denominator for f in reversed(q)]
                exact = max(float(mpmath.re(z)) for z in mpmath.polyroots(qq, maxsteps=400, extraprec=2000))
            assert v.method.startswith("closed"), sets
            assert v.max_real == pytest.approx(exact, rel=1e-9), sets
        if v.status == "stable":
            assert v.max_real < 0, sets
        elif v.status == "unstable":
            assert v.max_real > 0, sets
        # a bound is reported only where it is smaller than the margin; otherwise the route certified the verdict
        assert math.isnan(v.error_bound) or v.error_bound < abs(v.max_real) or v.status == "undecided", sets
        assert v.status == "undecided" or v.method != "none", sets
