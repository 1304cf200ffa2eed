"""Plain-Python exact root isolation (``analysis._roots``) against SymPy's continued-fraction isolation.

SymPy (``sympy.intervals`` over QQ, an independent algorithm: continued
fractions instead of Descartes bisection, its own square-free decomposition)
is the reference; it is used here only, never at run time.
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
import sympy as sp

from brakesqueal.analysis._roots import isolate_real_roots


def _poly(roots: list[Fraction], quad: list[tuple[int, int]], lead: Fraction) -> list[Fraction]:
    """Ascending coefficients of ``lead * prod (x - r) * prod (x^2 + b x + c)``."""
    c = [lead]
    for r in roots:
        c = [Fraction(0)] + c
        for i in range(len(c) - 1):
            c[i] -= r * c[i + 1]
    for b, q in quad:
        out = [Fraction(0)] * (len(c) + 2)
        for i, v in enumerate(c):
            out[i] += q * v
            out[i + 1] += b * v
            out[i + 2] += v
        c = out
    return c


def _sympy(polys, lo, hi):
    X = sp.Symbol("X")
    P, idx = [], []
    for i, c in enumerate(polys):
        if any(v != 0 for v in c):
            idx.append(i)
            P.append(sp.Poly([sp.Rational(v.numerator, v.denominator) for v in reversed(c)], X, domain=sp.QQ))
    res = sp.intervals(P, inf=sp.Rational(lo.numerator, lo.denominator), sup=sp.Rational(hi.numerator, hi.denominator))
    return [(Fraction(int(a.p), int(a.q)), Fraction(int(b.p), int(b.q)), {idx[k]: int(m) for k, m in o.items()})
            for (a, b), o in res]


def _same_roots(mine, ref):
    """Same number of roots, pairwise overlapping intervals, same owners and multiplicities."""
    assert len(mine) == len(ref), (mine, ref)
    for (a, b, o), (c, d, p) in zip(mine, ref):
        assert a <= b and max(a, c) <= min(b, d), ((a, b), (c, d))
        assert o == p
    for (a, b, _), (c, d, _) in zip(mine, mine[1:]):
        assert b < c  # disjoint, ascending


@pytest.mark.parametrize("seed", range(40))
def test_agrees_with_sympy_on_random_polynomial_families(seed):
    rng = np.random.default_rng(seed)
    pool = [Fraction(int(rng.integers(-40, 40)), int(rng.integers(1, 9))) for _ in range(6)]
    polys = []
    for _ in range(int(rng.integers(1, 4))):
        k = int(rng.integers(0, 5))
        roots = [pool[int(j)] for j in rng.integers(0, len(pool), k)]  # repeats give multiple and shared roots
        quad = [(int(rng.integers(-6, 6)), int(rng.integers(10, 40))) for _ in range(int(rng.integers(0, 2)))]
        polys.append(_poly(roots, quad, Fraction(int(rng.integers(1, 50)) * int(rng.choice([-1, 1])),
                                                  int(rng.integers(1, 7)))))
    if rng.random() < 0.2:
        polys.append([0, 0])  # a zero polynomial is ignored
    lo, hi = sorted(rng.choice(pool + [Fraction(-50), Fraction(50)], 2, replace=False))
    mine = isolate_real_roots(polys, lo, hi)
    _same_roots(mine, _sympy(polys, lo, hi))
    for a, b, owners in mine:
        for i, m in owners.items():  # each interval holds a root of each owner, of that multiplicity
            assert a == b or _sign_change_or_even(polys[i], a, b, m)


def _sign_change_or_even(p, a, b, m):
    def val(x):
        return sum(c * x ** k for k, c in enumerate(p))
    va, vb = val(a), val(b)
    return (va * vb < 0) == (m % 2 == 1) or va == 0 or vb == 0


def test_roots_hundreds_of_decades_apart_and_refinement():
    roots = [Fraction(1, 10 ** 80), Fraction(3, 10 ** 5), Fraction(5, 2), Fraction(7 * 10 ** 90)]
    c = _poly(roots, [(1, 1)], Fraction(3))
    iv = isolate_real_roots([c], Fraction(1, 10 ** 100), Fraction(10 ** 100))
    assert len(iv) == 4
    for (a, b, owners), r in zip(iv, roots):
        assert a <= r <= b and owners == {0: 1} and b - a <= Fraction(1, 10 ** 14) * r
    iv = isolate_real_roots([c], Fraction(1), Fraction(10), eps_rel=1e-40)
    assert len(iv) == 1 and iv[0][1] - iv[0][0] <= Fraction(1, 10 ** 40) * Fraction(5, 2)


def test_shared_roots_and_roots_at_the_ends():
    p = _poly([Fraction(1), Fraction(2), Fraction(2), Fraction(0)], [], Fraction(1))
    q = _poly([Fraction(2), Fraction(-3)], [], Fraction(-7, 3))
    iv = isolate_real_roots([p, q], Fraction(-3), Fraction(1))
    # -3 (end, q), 0 (p), 1 (end, p); 2 outside
    assert [(a, b) for a, b, _ in iv] == [(-3, -3), (0, 0), (1, 1)]
    assert [o for *_, o in iv] == [{1: 1}, {0: 1}, {0: 1}]
    iv = isolate_real_roots([p, q], Fraction(3, 2), Fraction(5, 2))
    assert len(iv) == 1 and iv[0][2] == {0: 2, 1: 1} and iv[0][0] <= 2 <= iv[0][1]
    assert isolate_real_roots([[1, 0, 1]], -10, 10) == []
    assert isolate_real_roots([[0]], -1, 1) == []


def test_floats_and_sympy_rationals_are_taken_exactly():
    iv = isolate_real_roots([[-0.1, 1.0]], 0, 1)  # root at the double nearest 0.1, not 1/10
    assert iv[0][0] <= Fraction(0.1) <= iv[0][1]
    iv = isolate_real_roots([[sp.Rational(-1, 10), 1]], 0, 1)
    assert iv[0][0] <= Fraction(1, 10) <= iv[0][1]
    with pytest.raises(ValueError, match="lo="):
        isolate_real_roots([[1, 1]], 1, 0)


@pytest.mark.parametrize("seed", [0, *(pytest.param(k, marks=pytest.mark.slow) for k in (1, 2))])  # mpmath: ~15 s each
def test_balanced_roots_agree_with_mpmath_on_polynomials_spanning_hundreds_of_decades(seed):
    """The exact-route profile's roots (Newton polygon groups, double-precision starts, 50-digit polish) against
    mpmath's polyroots at 80 digits with a large extra precision: the least-stable root's real part to 1e-40 of
    its modulus; where the fast route gives up (NaN) the caller falls back to mpmath itself."""
    import mpmath

    from brakesqueal.analysis.robust import balanced_roots_summary

    rng = np.random.default_rng(seed)
    given_up = 0
    for _ in range(60):
        e = rng.integers(-300, 300, 5)
        c = [Fraction(float(rng.uniform(0.5, 2) * rng.choice([-1, 1]))) * Fraction(2) ** int(x) for x in e]
        mr, fr = balanced_roots_summary(c)
        with mpmath.workdps(80):
            roots = mpmath.polyroots([mpmath.mpf(x.numerator) / x.denominator for x in reversed(c)], maxsteps=5000,
                                     extraprec=5000)
            order = sorted(roots, key=lambda z: -mpmath.re(z))
            top = order[0]
            ref_mr, ref_fr, mod = float(mpmath.re(top)), float(abs(mpmath.im(top)) / (2 * mpmath.pi)), abs(top)
            # the frequency is that of one root only where no other (but its conjugate) has the same real part
            unique = all(mpmath.re(top) - mpmath.re(z) > mpmath.mpf(10) ** -30 * mod
                         for z in order[1:] if abs(z - mpmath.conj(top)) > mpmath.mpf(10) ** -30 * mod)
        if not np.isfinite(mr):
            given_up += 1
            continue
        assert abs(mr - ref_mr) <= 1e-40 * float(mod)
        if unique:
            assert abs(fr - ref_fr) <= 1e-40 * float(mod)
    assert given_up <= 6


def test_exact_route_profile_at_the_magnitude_bound_has_its_roots():
    """At N0 = 1e100 the quartic's coefficients span 1e-2 .. 1e290 and its roots 1e1 .. 1e97: the profile of the
    exact route carries every point's max Re (mpmath's polyroots gave NaN there, after 0.3 s a point)."""
    from brakesqueal import critical_speeds
    from brakesqueal.model.parameters import ParameterSpace

    r = critical_speeds(ParameterSpace.from_preset("paper-fig3", {"N0": 1e100}), 1.0, 1e5)
    prof = np.asarray(r.profile[1])  # (values, max_real)
    assert prof.size and np.all(np.isfinite(prof))
    assert np.all((prof >= 0) == (not r.stable_at_start))  # no crossing in the range: one sign throughout
