"""Exact real-root isolation of rational polynomials in plain Python (integers and Fractions).

The exact crossing routes (:mod:`.crossings`) need the real roots of a few
univariate polynomials with rational coefficients, separated from each other
and refined to a relative width; computer algebra is not loaded at run time
for that (the engine hands plain rational coefficients over), so this module
does it with Python integers:

* square-free parts ``f / gcd(f, f')`` (primitive polynomial remainder
  sequence over the integers);
* a gcd-free basis of all square-free parts — pairwise coprime polynomials
  whose products, with multiplicities, give back every input polynomial
  (so a root shared by two inputs is one root of one basis polynomial);
* Descartes' rule of signs with bisection (Collins–Akritas / Vincent's
  theorem: the number of sign variations of ``(1+y)^d p((a + b y)/(1+y))``
  bounds the number of roots in ``(a, b)`` and equals it when it is 0 or 1)
  on the positive and the negative axis separately, after shrinking each to
  Cauchy's root bounds; bisection is geometric on wide ranges so that roots
  hundreds of decades apart are separated in a few hundred steps;
* refinement by bisection on the sign change of the simple root.

Checked against SymPy's continued-fraction isolation in
``tests/analysis/test_exact_roots.py``.
"""
from __future__ import annotations

import math
from fractions import Fraction
from typing import Any, Sequence

__all__ = ["isolate_real_roots"]

Poly = list[int]  # ascending integer coefficients, no trailing zeros


def _trim(p: list[Any]) -> list[Any]:
    while p and p[-1] == 0:
        p = p[:-1]
    return p


def _primitive(p: Sequence[Any]) -> Poly:
    """Ascending primitive integer polynomial with a positive leading coefficient (same roots)."""
    q = _trim([Fraction(c) for c in p])
    if not q:
        return []
    den = 1
    for c in q:
        den = den * c.denominator // math.gcd(den, c.denominator)
    ints = [int(c * den) for c in q]
    g = 0
    for c in ints:
        g = math.gcd(g, c)
    sign = 1 if ints[-1] > 0 else -1
    return [sign * c // g for c in ints]


def _deg(p: Sequence[Any]) -> int:
    return len(p) - 1


def _prem(a: Poly, b: Poly) -> Poly:
    """Pseudo-remainder ``lc(b)^(deg a - deg b + 1) a mod b`` (exact in integers)."""
    r = list(a)
    db, lb = _deg(b), b[-1]
    while r and _deg(r) >= db:
        c, shift = r[-1], _deg(r) - db
        r = [lb * x for x in r]
        for i, y in enumerate(b):
            r[i + shift] -= c * y
        r = _trim(r)
    return r


def _gcd(a: Sequence[Any], b: Sequence[Any]) -> Poly:
    """Primitive greatest common divisor (primitive polynomial remainder sequence)."""
    a, b = _primitive(a), _primitive(b)
    while b:
        a, b = b, _primitive(_prem(a, b))
    return a


def _divide(a: Sequence[Any], b: Sequence[Any]) -> tuple[list[Fraction], list[Fraction]]:
    """Quotient and remainder of ``a / b`` over the rationals (not normalized)."""
    r = [Fraction(x) for x in a]
    q = [Fraction(0)] * max(len(a) - len(b) + 1, 1)
    while r and _deg(r) >= _deg(b):
        c, shift = r[-1] / b[-1], _deg(r) - _deg(b)
        q[shift] = c
        for i, y in enumerate(b):
            r[i + shift] -= c * y
        r = _trim(r)
    return _trim(q), r


def _exact(a: Sequence[Any], b: Sequence[Any]) -> Poly:
    """Primitive ``a / b`` where ``b`` divides ``a``."""
    return _primitive(_divide(a, b)[0])


def _derivative(p: Sequence[Any]) -> list[Any]:
    return [i * c for i, c in enumerate(p)][1:]


def _sub(a: Sequence[Any], b: Sequence[Any]) -> list[Any]:
    n = max(len(a), len(b))
    return _trim([(a[i] if i < len(a) else 0) - (b[i] if i < len(b) else 0) for i in range(n)])


def _squarefree(p: Poly) -> list[tuple[Poly, int]]:
    """Yun's square-free decomposition ``p = c prod f_k^k`` (the ``f_k`` of degree >= 1, with ``k``)."""
    dp = _derivative(p)
    a = _gcd(p, dp)
    b = _divide(p, a)[0]
    c = _divide(dp, a)[0]
    d = _sub(c, [Fraction(x) for x in _derivative(b)])
    out, k = [], 1
    while _deg(b) >= 1:
        f = _gcd(b, d)
        if _deg(f) >= 1:
            out.append((f, k))
        b = _divide(b, f)[0]
        c = _divide(d, f)[0]
        d = _sub(c, _derivative(b))
        k += 1
    return out


def _basis(parts: list[Poly]) -> list[Poly]:
    """Pairwise coprime polynomials whose products give every (square-free) part."""
    basis: list[Poly] = []
    for g in parts:
        new: list[Poly] = []
        for b in basis:
            h = _gcd(g, b) if _deg(g) >= 1 else [1]
            if _deg(h) < 1:
                new.append(b)
                continue
            new.append(h)
            q = _exact(b, h)
            if _deg(q) >= 1:
                new.append(q)
            g = _exact(g, h)
        if _deg(g) >= 1:
            new.append(g)
        basis = new
    return basis


def _sign_at(p: Poly, x: Fraction) -> int:
    """Exact sign of ``p(x)``."""
    n, d = x.numerator, x.denominator
    s, dp = 0, 1
    for c in reversed(p):  # Horner on n/d, scaled by d^deg
        s = s * n + c * dp
        dp *= d
    return (s > 0) - (s < 0)


def _taylor(p: list[int], c: int) -> list[int]:
    """Coefficients of ``p(x + c)`` (ascending, integers)."""
    q = list(p)
    n = len(q)
    for i in range(n - 1):
        for k in range(n - 2, i - 1, -1):
            q[k] += c * q[k + 1]
    return q


def _variations(p: Poly, a: Fraction, b: Fraction) -> int:
    """Sign variations of ``(1+y)^d p((a + b y)/(1+y))``: 0 or 1 is the number of roots in ``(a, b)``."""
    den = a.denominator * b.denominator // math.gcd(a.denominator, b.denominator)
    an, wn = int(a * den), int((b - a) * den)
    d = _deg(p)
    q = [c * den ** (d - i) for i, c in enumerate(p)]  # den^d p(x / den)
    q = _taylor(q, an)  # x -> an + x
    q = [c * wn ** i for i, c in enumerate(q)]  # x -> wn y
    q = _taylor(q[::-1], 1)  # reversed, y -> y + 1
    count, last = 0, 0
    for c in q:
        if c:
            s = 1 if c > 0 else -1
            if last and s != last:
                count += 1
            last = s
    return count


def _log2(x: Fraction) -> int:
    return x.numerator.bit_length() - x.denominator.bit_length()


def _split(a: Fraction, b: Fraction) -> Fraction:
    """A point inside ``(a, b)``, ``0 < a < b``: geometric on wide ranges, else the midpoint."""
    if b > 4 * a:
        m = Fraction(2) ** ((_log2(a) + _log2(b)) // 2)
        if a < m < b:
            return m
    return (a + b) / 2


def _cauchy(p: Poly) -> Fraction:
    """A power of two above every |root| of ``p`` (Cauchy's bound)."""
    lead = abs(p[-1])
    bound = 1 + Fraction(max(abs(c) for c in p[:-1]) if len(p) > 1 else 0, lead)
    return Fraction(2) ** (_log2(bound) + 2)


def _positive(p: Poly, lo: Fraction, hi: Fraction) -> list[tuple[Fraction, Fraction]]:
    """Isolating intervals of the roots of square-free ``p`` in the open ``(lo, hi)``, ``0 <= lo``."""
    k = 0
    while k < len(p) and p[k] == 0:
        k += 1
    core = p[k:]
    if _deg(core) < 1:
        return []
    upper = _cauchy(core)
    lower = 1 / _cauchy(core[::-1])
    a, b = max(lo, lower / 2), min(hi, 2 * upper)
    out: list[tuple[Fraction, Fraction]] = []
    stack = [(a, b)] if a < b else []
    while stack:
        a, b = stack.pop()
        v = _variations(core, a, b)
        if v == 0:
            continue
        if v == 1 and _sign_at(core, a) and _sign_at(core, b):
            out.append((a, b))  # one simple root inside, a sign change at the ends
            continue
        m = _split(a, b)
        if _sign_at(core, m) == 0:
            out.append((m, m))
        stack += [(m, b), (a, m)]
    return out


def _refine(p: Poly, a: Fraction, b: Fraction, tol_abs: Fraction | None, eps_rel: Fraction
            ) -> tuple[Fraction, Fraction]:
    """Bisect the sign change of a simple root of ``p`` in ``[a, b]`` (same sign side)."""
    if a == b:
        return a, b
    neg = b <= 0
    if neg:
        p = [c if i % 2 == 0 else -c for i, c in enumerate(p)]
        a, b = -b, -a
    sa = _sign_at(p, a)
    for _ in range(4000):
        tol = eps_rel * b if tol_abs is None else tol_abs
        if b - a <= tol:
            break
        m = _split(a, b) if a > 0 else (a + b) / 2
        sm = _sign_at(p, m)
        if sm == 0:
            a = b = m
            break
        if sm == sa:
            a = m
        else:
            b = m
    return (-b, -a) if neg else (a, b)


def _isolate(p: Poly, lo: Fraction, hi: Fraction) -> list[tuple[Fraction, Fraction]]:
    """Isolating intervals (ascending) of the roots of square-free ``p`` in the closed ``[lo, hi]``."""
    out = [(x, x) for x in sorted({lo, hi}) if _sign_at(p, x) == 0]
    if lo < 0 < hi and _sign_at(p, Fraction(0)) == 0:
        out.append((Fraction(0), Fraction(0)))
    if hi > 0:
        out += _positive(p, max(lo, Fraction(0)), hi)
    if lo < 0:
        mirror = [c if i % 2 == 0 else -c for i, c in enumerate(p)]
        out += [(-b, -a) for a, b in _positive(mirror, max(-hi, Fraction(0)), -lo)]
    return sorted(set(out))


def _fraction(x: Any) -> Fraction:
    if isinstance(x, Fraction):
        return x
    if hasattr(x, "p") and hasattr(x, "q"):  # a SymPy Rational, without importing SymPy
        return Fraction(int(x.p), int(x.q))
    return Fraction(x)


def isolate_real_roots(polys: Sequence[Sequence[Any]], lo: Any, hi: Any, *, eps_rel: float = 1e-15
                       ) -> list[tuple[Fraction, Fraction, dict[int, int]]]:
    """Exact isolation of the real roots of several rational polynomials in ``[lo, hi]``.

    Parameters
    ----------
    polys : sequence of sequences
        Ascending exact coefficients (int, Fraction, SymPy Rational or float
        taken exactly).  Zero polynomials are ignored.
    lo, hi : number
        The closed interval (any magnitudes, e.g. ``1e-100`` and ``1e100``;
        taken exactly).
    eps_rel : float
        Each isolating interval is refined to a width ``<= eps_rel |root|``
        (for roots away from zero; ``eps_rel * max(|lo|, |hi|)`` for an
        interval touching zero).

    Returns
    -------
    list of (a, b, owners)
        Disjoint isolating intervals ``[a, b]`` (exact Fractions, ascending;
        ``a == b`` for a root hit exactly); ``owners`` maps the index of every
        polynomial vanishing inside to the root's multiplicity.  Guarantee:
        exact (integer arithmetic throughout).
    """
    lo_q, hi_q = _fraction(lo), _fraction(hi)
    if lo_q > hi_q:
        raise ValueError(f"isolate_real_roots: lo={lo} must not exceed hi={hi}")
    originals: dict[int, Poly] = {}
    for i, c in enumerate(polys):
        p = _primitive([_fraction(v) for v in c])
        if p:
            originals[i] = p
    factors = {i: _squarefree(p) for i, p in originals.items() if _deg(p) >= 1}
    basis = _basis([f for fs in factors.values() for f, _ in fs])
    eps = Fraction(eps_rel)
    scale = max(abs(lo_q), abs(hi_q))
    items: list[list[Any]] = []
    for j, b in enumerate(basis):
        for a_, b_ in _isolate(b, lo_q, hi_q):
            tol = None if (a_ > 0 or b_ < 0) else eps * scale
            a_, b_ = _refine(b, a_, b_, tol, eps)
            items.append([a_, b_, j])
    # intervals of different basis polynomials hold different roots: shrink the overlapping ones apart
    items.sort(key=lambda t: (t[0], t[1]))
    for _ in range(10000):
        clash = [k for k in range(len(items) - 1) if items[k + 1][0] <= items[k][1]]
        if not clash:
            break
        for k in {x for c in clash for x in (c, c + 1)}:
            a_, b_, j = items[k]
            if a_ < b_:
                half = (b_ - a_) / 2
                items[k][0], items[k][1] = _refine(basis[j], a_, b_, half, eps)
        items.sort(key=lambda t: (t[0], t[1]))
    out = []
    for a_, b_, j in items:
        owners = {i: k for i, fs in factors.items() for f, k in fs if not _divide(f, basis[j])[1]}
        out.append((a_, b_, owners))
    return out
