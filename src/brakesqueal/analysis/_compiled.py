"""Compiled (numba) kernels: certified sign tests, root isolation and the batched critical-speed kernel.

Imported lazily (numba start-up costs about a second); every function is
cached on disk by numba.

Certified arithmetic
--------------------
Numbers are carried as *midpoint-radius intervals* ``(m, r)``: the exact value
lies in ``[m - r, m + r]``.  Every operation adds the rounding error of its
midpoint (``u |m|``, ``u = 2^-53``) and inflates the radius by ``1 + 16u`` to
cover the rounding of the radius computation itself (Rump's midpoint-radius
arithmetic with a safety factor; an absolute ``2^-1020`` covers underflow).
A sign is *certified* when the interval excludes zero.  These intervals are
used by the Routh test (:func:`routh_interval`), by interval Horner
(:func:`horner_interval`), by Descartes' rule of signs on an interval
(:func:`descartes`), and by the critical-speed kernel (:func:`critical_batch`).
"""

from __future__ import annotations

import math
import os
from typing import Any

import numba
import numpy as np

# the parallel drivers below run on numba's OpenMP layer on this platform: idle threads sleep instead of spinning
# (the default spin-wait burns a core on a shared machine); numba loads the layer at the first parallel call
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

__all__ = ["peval", "real_roots", "routh_interval", "routh_batch", "quartic_interval_batch", "horner_interval",
           "descartes", "isolate_roots", "critical_batch", "quartic_factor", "quartic_top_grid", "quartic_top_rows",
           "charpoly_grid", "critical_batch_chunks", "charpoly_grid_chunks",
           "quartic_top_grid_chunks", "balance_batch", "PARALLEL_MIN", "UNSTABLE", "STABLE", "UNDECIDED"]

_JIT: dict[str, Any] = dict(cache=True, error_model="numpy")

UNSTABLE, STABLE, UNDECIDED = 0, 1, 2
_U = 2.0 ** -53
_KR = 1.0 + 16.0 * _U
_ETA = 2.0 ** -1020  # smallest normal range: subnormal operands are very slow on x86


# ---------------------------------------------------------------- plain float helpers (kept for callers)
@numba.njit(**_JIT)
def peval(c, deg, x):  # type: ignore[no-untyped-def]
    """Horner evaluation of ``Σ_{k<=deg} c[k] x^k``."""
    v = c[deg]
    for k in range(deg - 1, -1, -1):
        v = v * x + c[k]
    return v


@numba.njit(**_JIT)
def _solve(c, dc, deg, lo, hi, flo):  # type: ignore[no-untyped-def]
    """Root of ``c`` in ``[lo, hi]`` (sign change, ``flo = c(lo)``) by safeguarded Newton."""
    a, b = lo, hi
    x = 0.5 * (a + b)
    for _ in range(300):
        fx = peval(c, deg, x)
        if fx == 0.0:
            return x
        if (fx > 0.0) == (flo > 0.0):
            a = x
        else:
            b = x
        if b - a <= 4e-16 * max(abs(a), abs(b)):
            return 0.5 * (a + b)
        d = peval(dc, deg - 1, x) if deg > 0 else 0.0
        xn = x - fx / d if d != 0.0 else 0.5 * (a + b)
        if not (a < xn < b) or abs(xn - x) > 0.5 * (b - a):
            xn = 0.5 * (a + b)
        if xn == x:
            return x
        x = xn
    return x


@numba.njit(**_JIT)
def real_roots(c, lo, hi, out):  # type: ignore[no-untyped-def]
    """Real roots of ``Σ c[k] x^k`` in ``(lo, hi)`` in floating point (not certified), ascending; returns the count.

    Derivative cascade: the real roots of ``p^(m+1)`` split the interval into
    pieces where ``p^(m)`` is monotone, so each piece holds at most one root,
    found by bracketing.  Kept as a fast helper; the certified isolation is
    :func:`isolate_roots`.
    """
    deg = c.shape[0] - 1
    while deg > 0 and c[deg] == 0.0:
        deg -= 1
    if deg <= 0:
        return 0
    n = deg + 1
    ders = np.zeros((n, n))
    for k in range(n):
        ders[0, k] = c[k]
    for m in range(1, deg):
        for k in range(deg - m + 1):
            ders[m, k] = ders[m - 1, k + 1] * (k + 1)
    pts = np.empty(n + 1)
    new = np.empty(n + 1)
    npts = 0
    r = -ders[deg - 1, 0] / ders[deg - 1, 1]
    if lo < r < hi:
        pts[0] = r
        npts = 1
    for m in range(deg - 2, -1, -1):
        dm = deg - m
        nn = 0
        a = lo
        fa = peval(ders[m], dm, a)
        for q in range(npts + 1):
            b = pts[q] if q < npts else hi
            fb = peval(ders[m], dm, b)
            if fa == 0.0 and q > 0:
                new[nn] = a
                nn += 1
            elif (fa > 0.0 and fb < 0.0) or (fa < 0.0 and fb > 0.0):
                new[nn] = _solve(ders[m], ders[m + 1], dm, a, b, fa)
                nn += 1
            a, fa = b, fb
        for q in range(nn):
            pts[q] = new[q]
        npts = nn
    for q in range(npts):
        out[q] = pts[q]
    return npts


# ---------------------------------------------------------------- midpoint-radius interval arithmetic
@numba.njit(inline="always", **_JIT)
def _imul(a, ra, b, rb):  # type: ignore[no-untyped-def]
    if (a == 0.0 and ra == 0.0) or (b == 0.0 and rb == 0.0):
        return 0.0, 0.0  # exact zeros stay exact (and no tiny radii that would become subnormal)
    m = a * b
    return m, ((abs(a) * rb + ra * abs(b)) + ra * rb + _U * abs(m)) * _KR + _ETA


@numba.njit(inline="always", **_JIT)
def _iadd(a, ra, b, rb):  # type: ignore[no-untyped-def]
    m = a + b
    return m, (ra + rb + _U * abs(m)) * _KR


@numba.njit(inline="always", **_JIT)
def _isub(a, ra, b, rb):  # type: ignore[no-untyped-def]
    m = a - b
    return m, (ra + rb + _U * abs(m)) * _KR


@numba.njit(inline="always", **_JIT)
def _idiv(a, ra, b, rb):  # type: ignore[no-untyped-def]
    """Interval quotient; the caller guarantees ``|b| > rb``."""
    m = a / b
    return m, ((ra + abs(m) * rb) / (abs(b) - rb) + _U * abs(m)) * _KR + _ETA


@numba.njit(inline="always", **_JIT)
def _sign(m, r):  # type: ignore[no-untyped-def]
    """+1 / -1 if the interval is certified positive / negative, 0 otherwise (NaN: 0)."""
    if m - r > 0.0:
        return 1
    if m + r < 0.0:
        return -1
    return 0


@numba.njit(**_JIT)
def horner_interval(c, rc, deg, x):  # type: ignore[no-untyped-def]
    """Enclosure ``(value, radius)`` of ``Σ_{k<=deg} c_k x^k`` for ``c_k ∈ [c[k] ± rc[k]]``, ``x`` exact."""
    v, rv = c[deg], rc[deg]
    ax = abs(x)
    for k in range(deg - 1, -1, -1):
        m = v * x
        rm = (ax * rv + _U * abs(m)) * _KR
        if rm != 0.0 or m != 0.0:
            rm += _ETA
        v, rv = _iadd(m, rm, c[k], rc[k])
    return v, rv


@numba.njit(**_JIT)
def _sgn_at(c, rc, d, x):  # type: ignore[no-untyped-def]
    v, r = horner_interval(c, rc, d, x)
    return _sign(v, r)


# ---------------------------------------------------------------- certified Routh test
@numba.njit(**_JIT)
def _normalise(row, rrow, n):  # type: ignore[no-untyped-def]
    big = 0.0
    for k in range(n):
        v = abs(row[k]) + rrow[k]
        if v > big:
            big = v
    if big > 0.0 and math.isfinite(big):
        e = math.frexp(big)[1]
        for k in range(n):
            row[k] = math.ldexp(row[k], -e)
            rrow[k] = math.ldexp(rrow[k], -e)


@numba.njit(**_JIT)
def _routh_core(a, r, m, row0, r0, row1, r1, new, rnew):  # type: ignore[no-untyped-def]
    for k in range(m + 1):
        if not (math.isfinite(a[k]) and math.isfinite(r[k])):
            return UNDECIDED
    if m == 0:
        return STABLE if abs(a[0]) > r[0] else UNDECIDED
    lead = a[m]
    if not abs(lead) > r[m]:
        return UNDECIDED
    s = 1.0 if lead > 0.0 else -1.0
    # λ -> 2^e λ: a_k -> a_k 2^(e k), exact; balances |a_0| and |a_m|
    e = 0
    if a[0] != 0.0:
        e = int(round((math.log2(abs(a[0])) - math.log2(abs(lead))) / m))
    n0 = m // 2 + 1
    for k in range(n0 + 1):
        row0[k] = 0.0
        r0[k] = 0.0
        row1[k] = 0.0
        r1[k] = 0.0
    for k in range(n0):
        i = m - 2 * k
        if i >= 0:
            row0[k] = s * math.ldexp(a[i], e * i)
            r0[k] = math.ldexp(r[i], e * i)
        i = m - 1 - 2 * k
        if i >= 0:
            row1[k] = s * math.ldexp(a[i], e * i)
            r1[k] = math.ldexp(r[i], e * i)
    _normalise(row0, r0, n0)
    _normalise(row1, r1, n0)
    if not row0[0] - r0[0] > 0.0:
        return UNDECIDED  # cannot happen after the sign fold unless overflow
    for j in range(2, m + 1):
        sg = _sign(row1[0], r1[0])
        if sg == -1 or (row1[0] + r1[0] <= 0.0):
            return UNSTABLE
        if sg == 0:
            return UNDECIDED
        q, rq = _idiv(row0[0], r0[0], row1[0], r1[0])
        for k in range(n0):
            pm, pr = _imul(q, rq, row1[k + 1], r1[k + 1])
            new[k], rnew[k] = _isub(row0[k + 1], r0[k + 1], pm, pr)
        new[n0] = 0.0
        rnew[n0] = 0.0
        for k in range(n0 + 1):
            row0[k] = row1[k]
            r0[k] = r1[k]
            row1[k] = new[k]
            r1[k] = rnew[k]
        _normalise(row1, r1, n0)
        if not (math.isfinite(row1[0]) and math.isfinite(r1[0])):
            return UNDECIDED
    sg = _sign(row1[0], r1[0])
    if sg == 1:
        return STABLE
    if sg == -1 or row1[0] + r1[0] <= 0.0:
        return UNSTABLE
    return UNDECIDED


@numba.njit(**_JIT)
def routh_interval(a, r):  # type: ignore[no-untyped-def]
    """Certified Routh–Hurwitz verdict of ``Σ a_k λ^k`` with ``|error of a_k| <= r[k]``.

    Returns ``STABLE`` (1) if every polynomial in the coefficient box has all
    roots in the open left half-plane, ``UNSTABLE`` (0) if none has, and
    ``UNDECIDED`` (2) otherwise (or when a value is not finite).
    """
    m = a.shape[0] - 1
    n0 = m // 2 + 2
    w = np.zeros((6, n0 + 1))
    return _routh_core(a, r, m, w[0], w[1], w[2], w[3], w[4], w[5])


@numba.njit(**_JIT)
def routh_batch(A, R, out):  # type: ignore[no-untyped-def]
    """:func:`routh_interval` for every row of ``A`` / ``R`` (ascending coefficients); verdicts to ``out``."""
    m = A.shape[1] - 1
    n0 = m // 2 + 2
    w = np.zeros((6, n0 + 1))
    for i in range(A.shape[0]):
        out[i] = _routh_core(A[i], R[i], m, w[0], w[1], w[2], w[3], w[4], w[5])


@numba.njit(**_JIT)
def quartic_interval_batch(E, RE, A, RA):  # type: ignore[no-untyped-def]
    """Interval coefficients ``a0..a4`` of ``det(λ²M + λD + K)`` for 2×2 matrices given entry-wise.

    ``E[n, 12]`` holds ``M, D, K`` row-major, ``RE`` their radii; writes ``A[n, 5]``, ``RA[n, 5]``.
    """
    for n in range(E.shape[0]):
        e = E[n]
        re = RE[n]
        # a4 = m11 m22 - m12 m21
        x, rx = _imul(e[0], re[0], e[3], re[3])
        y, ry = _imul(e[1], re[1], e[2], re[2])
        A[n, 4], RA[n, 4] = _isub(x, rx, y, ry)
        # a3 = m11 d22 + d11 m22 - m12 d21 - d12 m21
        s, rs = _imul(e[0], re[0], e[7], re[7])
        x, rx = _imul(e[4], re[4], e[3], re[3])
        s, rs = _iadd(s, rs, x, rx)
        x, rx = _imul(e[1], re[1], e[6], re[6])
        s, rs = _isub(s, rs, x, rx)
        x, rx = _imul(e[5], re[5], e[2], re[2])
        A[n, 3], RA[n, 3] = _isub(s, rs, x, rx)
        # a2 = m11 k22 + d11 d22 + k11 m22 - m12 k21 - d12 d21 - k12 m21
        s, rs = _imul(e[0], re[0], e[11], re[11])
        x, rx = _imul(e[4], re[4], e[7], re[7])
        s, rs = _iadd(s, rs, x, rx)
        x, rx = _imul(e[8], re[8], e[3], re[3])
        s, rs = _iadd(s, rs, x, rx)
        x, rx = _imul(e[1], re[1], e[10], re[10])
        s, rs = _isub(s, rs, x, rx)
        x, rx = _imul(e[5], re[5], e[6], re[6])
        s, rs = _isub(s, rs, x, rx)
        x, rx = _imul(e[9], re[9], e[2], re[2])
        A[n, 2], RA[n, 2] = _isub(s, rs, x, rx)
        # a1 = d11 k22 + k11 d22 - d12 k21 - k12 d21
        s, rs = _imul(e[4], re[4], e[11], re[11])
        x, rx = _imul(e[8], re[8], e[7], re[7])
        s, rs = _iadd(s, rs, x, rx)
        x, rx = _imul(e[5], re[5], e[10], re[10])
        s, rs = _isub(s, rs, x, rx)
        x, rx = _imul(e[9], re[9], e[6], re[6])
        A[n, 1], RA[n, 1] = _isub(s, rs, x, rx)
        # a0 = k11 k22 - k12 k21
        x, rx = _imul(e[8], re[8], e[11], re[11])
        y, ry = _imul(e[9], re[9], e[10], re[10])
        A[n, 0], RA[n, 0] = _isub(x, rx, y, ry)


# ---------------------------------------------------------------- certified real-root isolation (Descartes)
@numba.njit(**_JIT)
def _transform(w, d, a, h):  # type: ignore[no-untyped-def]
    """In place: ``w <- (1+t)^d p(a + h/(1+t))`` coefficients (Taylor shift by a, scale by h, reverse, shift by 1)."""
    for i in range(d):
        for j in range(d - 1, i - 1, -1):
            w[j] += a * w[j + 1]
    hk = 1.0
    for k in range(1, d + 1):
        hk *= h
        w[k] *= hk
    for k in range((d + 1) // 2):
        t = w[k]
        w[k] = w[d - k]
        w[d - k] = t
    for i in range(d):
        for j in range(d - 1, i - 1, -1):
            w[j] += w[j + 1]


@numba.njit(**_JIT)
def descartes(c, rc, d, a, b, w, rw):  # type: ignore[no-untyped-def]
    """Certified Descartes bound for the roots of ``Σ c_k x^k`` (interval coefficients) in ``(a, b)``.

    The polynomial is transformed to ``q(t) = (1+t)^d p((a + b t)/(1+t))``
    (Taylor shift by ``a``, scaling by ``h = fl(b - a)``, reversal, shift by
    1) in plain floating point; the same linear map with all entries made
    non-negative, applied to ``rc + γ|c|`` (``γ = (6d + 4) u``, covering the
    rounding of every operation and of ``h``), bounds the error of every
    coefficient of ``q``.  ``w``, ``rw`` are workspaces of length ``d + 1``.
    Returns 0 (no root for any member of the coefficient box), 1 (exactly one
    simple root for every member) or 2 (undetermined: two or more sign
    variations, or an uncertain sign).
    """
    g = (6.0 * d + 4.0) * _U
    for k in range(d + 1):
        w[k] = c[k]
        rw[k] = rc[k] + g * abs(c[k])
    h = b - a
    _transform(w, d, a, h)
    _transform(rw, d, abs(a), abs(h))
    last = 0
    var = 0
    for k in range(d + 1):
        r = rw[k] * (1.0 + g) + (_ETA if rw[k] != 0.0 else 0.0)
        if w[k] == 0.0 and r == 0.0:
            continue
        sg = _sign(w[k], r)
        if sg == 0:
            return 2
        if last != 0 and sg != last:
            var += 1
            if var >= 2:
                return 2
        last = sg
    return var


@numba.njit(**_JIT)
def _horner_d(c, d, x):  # type: ignore[no-untyped-def]
    """Plain floating-point ``p(x)`` and ``p'(x)``."""
    p = c[d]
    dp = 0.0
    for k in range(d - 1, -1, -1):
        dp = dp * x + p
        p = p * x + c[k]
    return p, dp


@numba.njit(**_JIT)
def _illinois(c, rc, d, a, b, fa, fb, certified):  # type: ignore[no-untyped-def]
    """Illinois regula falsi on ``(a, b)`` (``fa``, ``fb`` of opposite signs); returns the final ``(a, b)``.

    ``certified``: use a sign only when certified by interval Horner (stop at
    the rounding band); otherwise plain floating-point signs.
    """
    sa = 1.0 if fa > 0.0 else -1.0
    side = 0
    for _ in range(100):
        if b - a <= 2.0 ** -46 * max(abs(a), abs(b)):  # the caller certifies x (1 ± 2^-44)
            break
        if a > 0.0 and b > 2.0 * a:
            x = math.sqrt(a) * math.sqrt(b)  # wide positive bracket: bisect in log scale first
        elif b < 0.0 and a < 2.0 * b:
            x = -math.sqrt(-a) * math.sqrt(-b)
        else:
            x = 0.5 * (a + b)
            if fa != fb:
                xs = a - fa * (b - a) / (fb - fa)
                if a < xs < b:
                    x = xs
        if not (a < x < b):
            break
        if certified:
            v, rv = horner_interval(c, rc, d, x)
            sg = _sign(v, rv)
            if sg == 0:
                break
        else:
            v = _horner_d(c, d, x)[0]
            if v == 0.0:
                return x, x
            sg = 1 if v > 0.0 else -1
        if sg == sa:
            a, fa = x, v
            if side == -1:
                fb *= 0.5
            side = -1
        else:
            b, fb = x, v
            if side == 1:
                fa *= 0.5
            side = 1
    return a, b


@numba.njit(**_JIT)
def _refine(c, rc, d, a, b, sa):  # type: ignore[no-untyped-def]
    """Shrink a bracket ``(a, b)`` holding one simple root (``sign p(a) = sa``, certified at both ends).

    The root is located in plain floating point (log-bisection while the
    bracket is wide, Illinois regula falsi, Newton); then the smallest
    bracket ``x (1 ± δ)``, ``δ = 2^-44, 2^-36, ...``, whose end signs are
    certified opposite is returned with the estimate: ``(a, b, x)``.  If no
    such bracket is found the original ``(a, b)`` is kept (still certified).
    """
    fa = _horner_d(c, d, a)[0]
    fb = _horner_d(c, d, b)[0]
    x = 0.5 * (a + b)
    if fa != 0.0 and fb != 0.0 and (fa > 0.0) != (fb > 0.0):
        lo, hi = _illinois(c, rc, d, a, b, fa, fb, False)
        x = 0.5 * (lo + hi)
        for _ in range(1):  # one Newton step polishes the estimate
            p, dp = _horner_d(c, d, x)
            if p == 0.0 or dp == 0.0:
                break
            xn = x - p / dp
            if not (lo <= xn <= hi) or xn == x:
                break
            x = xn
    if not (a < x < b):
        x = 0.5 * (a + b)
    delta = 2.0 ** -44
    scale = max(abs(x), 1e-300)
    for _ in range(6):
        xl = x - delta * scale
        xh = x + delta * scale
        if xl <= a or xh >= b:
            break
        if _sgn_at(c, rc, d, xl) == sa and _sgn_at(c, rc, d, xh) == -sa:
            return xl, xh, x
        delta *= 256.0
    return a, b, x


@numba.njit(**_JIT)
def isolate_roots(c, rc, d, lo, hi, out, w, rw, stack):  # type: ignore[no-untyped-def]
    """Certified isolation of the real roots of an interval polynomial in ``(lo, hi)``.

    Vincent–Collins–Akritas bisection with :func:`descartes`; every root is
    returned as a bracket ``out[k, :2] = (a, b)`` with certified opposite signs
    of ``p`` at ``a`` and ``b`` (exactly one simple root inside), ascending, and
    a floating-point estimate ``out[k, 2]`` inside the bracket.
    Returns the number of roots, or ``-1`` if the roots could not be isolated
    (a cluster narrower than ``2^-40`` relative, a root at ``lo`` or ``hi``,
    or more than ``out.shape[0]`` roots).
    """
    while d > 0 and c[d] == 0.0 and rc[d] == 0.0:
        d -= 1  # exact zero leading coefficients: lower degree
    if d == 0:
        return 0
    if lo >= 0.0:
        # Descartes on (0, inf) with the raw coefficients: V = 0 -> no positive root; V = 1 -> exactly one
        var = 0
        last = 0
        for k in range(d + 1):
            if c[k] == 0.0 and rc[k] == 0.0:
                continue
            sg = _sign(c[k], rc[k])
            if sg == 0:
                var = 99
                break
            if last != 0 and sg != last:
                var += 1
            last = sg
        if var == 0:
            return 0
        if var == 1:
            sa = _sgn_at(c, rc, d, lo)
            sb = _sgn_at(c, rc, d, hi)
            if sa != 0 and sb != 0:
                if sa == sb:
                    return 0
                if out.shape[0] < 1:
                    return -1
                ra, rb, rx = _refine(c, rc, d, lo, hi, sa)
                out[0, 0] = ra
                out[0, 1] = rb
                out[0, 2] = rx
                return 1
    top = 0
    stack[0, 0] = lo
    stack[0, 1] = hi
    top = 1
    nout = 0
    while top > 0:
        top -= 1
        a = stack[top, 0]
        b = stack[top, 1]
        v = descartes(c, rc, d, a, b, w, rw)
        if v == 0:
            continue
        if v == 1:
            sa = _sgn_at(c, rc, d, a)
            sb = _sgn_at(c, rc, d, b)
            if sa == 0 or sb == 0 or sa == sb:
                return -1
            if nout >= out.shape[0]:
                return -1
            ra, rb, rx = _refine(c, rc, d, a, b, sa)
            out[nout, 0] = ra
            out[nout, 1] = rb
            out[nout, 2] = rx
            nout += 1
            continue
        if b - a <= 2.0 ** -40 * max(abs(a), abs(b)):
            return -1
        if top + 2 > stack.shape[0]:
            return -1
        if a > 0.0 and b > 4.0 * a:
            mid = math.sqrt(a) * math.sqrt(b)
        else:
            mid = 0.5 * (a + b)
        ok = False
        for t in range(8):
            frac = (0.5, 0.4375, 0.5625, 0.375, 0.625, 0.3125, 0.6875, 0.25)[t]
            m = mid if t == 0 else a + frac * (b - a)
            if a < m < b and _sgn_at(c, rc, d, m) != 0:
                ok = True
                mid = m
                break
        if not ok:
            return -1
        stack[top, 0] = mid
        stack[top, 1] = b
        stack[top + 1, 0] = a
        stack[top + 1, 1] = mid
        top += 2
    return nout


# ---------------------------------------------------------------- critical speeds (certified)
@numba.njit(**_JIT)
def _ipoly_mul_acc(a, ra, b, rb, na, nb, sgn, out, rout):  # type: ignore[no-untyped-def]
    """``out += sgn * a * b`` for interval polynomials (lengths ``na``, ``nb``)."""
    for i in range(na):
        if a[i] == 0.0 and ra[i] == 0.0:
            continue
        for j in range(nb):
            if b[j] == 0.0 and rb[j] == 0.0:
                continue
            m, r = _imul(a[i], ra[i], b[j], rb[j])
            out[i + j], rout[i + j] = _iadd(out[i + j], rout[i + j], sgn * m, r)


@numba.njit(**_JIT)
def _verdict_at(A, RA, P, RP, w, dA, dP):  # type: ignore[no-untyped-def]
    """Certified quartic verdict at ``w`` from ``A_i(w) = w² a_i`` and ``P(w) = w^6 H3`` (w > 0).

    ``dA[i]``, ``dP`` are the effective degrees (higher coefficients exactly zero).
    """
    v4, r4 = horner_interval(A[4], RA[4], dA[4], w)
    s4 = _sign(v4, r4)
    if s4 == 0:
        return UNDECIDED
    allpos = True
    for i in range(4):
        v, r = horner_interval(A[i], RA[i], dA[i], w)
        sg = _sign(v, r) * s4
        if sg < 0:
            return UNSTABLE
        if sg == 0:
            allpos = False
    vp, rp = horner_interval(P, RP, dP, w)
    sp = _sign(vp, rp) * s4
    if sp < 0:
        return UNSTABLE
    if sp > 0 and allpos:
        return STABLE
    return UNDECIDED


@numba.njit(**_JIT)
def _piece_verdict(A, RA, P, RP, x0, x1, dA, dP):  # type: ignore[no-untyped-def]
    """Verdict somewhere inside ``(x0, x1)`` (a few trial points)."""
    for t in range(7):
        frac = (0.5, 0.25, 0.75, 0.125, 0.875, 0.375, 0.625)[t]
        if x0 > 0.0 and x1 > 4.0 * x0:
            x = math.exp(math.log(x0) + frac * (math.log(x1) - math.log(x0)))
        else:
            x = x0 + frac * (x1 - x0)
        if not (x0 < x < x1):
            continue
        v = _verdict_at(A, RA, P, RP, x, dA, dP)
        if v != UNDECIDED:
            return v
    return UNDECIDED


@numba.njit(**_JIT)
def critical_batch(E_all, R_all, bounds, roots_out, dirs_out, counts, start_stable, flags):  # type: ignore[no-untyped-def]
    """Certified stability changes along Ω for each row of Laurent entry tables.

    ``E_all[n, e, k]`` is the coefficient of ``Ω^(k-1)`` of entry ``e`` of
    ``(Mbar, Dbar, Kbar)`` (row-major), ``R_all`` its error radius.
    ``bounds`` are the sub-range limits ``lo = b_0 < b_1 < ... < b_J = hi``
    (internal ones powers of two).  On each sub-range, with ``Ω = s w``
    (``s`` a power of two near the geometric mean), ``A_i(w) = w² a_i`` and
    ``P(w) = w^6 H3`` are interval polynomials; the roots of ``A_0``, ``A_4``
    and ``P`` (the only places where the Liénard–Chipart verdict can change,
    by Orlando's formula) are isolated with :func:`isolate_roots` and the
    verdict is certified on every piece in between.  ``flags[n] = 1`` marks a
    row where something could not be certified (the caller recomputes it
    exactly); otherwise the results are complete for ``(lo, hi)``.
    """
    cand = np.empty((64, 3))
    brk = np.empty((32, 3))
    w = np.empty(19)
    rw = np.empty(19)
    stack = np.empty((256, 2))
    A = np.zeros((5, 7))
    RA = np.zeros((5, 7))
    P = np.zeros(19)
    RP = np.zeros(19)
    T1 = np.zeros(13)
    R1 = np.zeros(13)
    T2 = np.zeros(13)
    R2 = np.zeros(13)
    Es = np.zeros((12, 4))
    Rs = np.zeros((12, 4))
    dA = np.zeros(5, dtype=np.int64)
    maxc = roots_out.shape[1]
    nsub = bounds.shape[0] - 1
    for n in range(E_all.shape[0]):
        flag = 0
        m = 0
        prev = -1
        for j in range(nsub):
            lo = bounds[j]
            hi = bounds[j + 1]
            ks = int(round(0.5 * (math.log2(lo) + math.log2(hi))))
            wl = math.ldexp(lo, -ks)
            wh = math.ldexp(hi, -ks)
            for e in range(12):
                for k in range(4):
                    Es[e, k] = math.ldexp(E_all[n, e, k], ks * (k - 1))
                    Rs[e, k] = math.ldexp(R_all[n, e, k], ks * (k - 1))
            A[:, :] = 0.0
            RA[:, :] = 0.0
            # a4 = m11 m22 - m12 m21
            _ipoly_mul_acc(Es[0], Rs[0], Es[3], Rs[3], 4, 4, 1.0, A[4], RA[4])
            _ipoly_mul_acc(Es[1], Rs[1], Es[2], Rs[2], 4, 4, -1.0, A[4], RA[4])
            # a3 = m11 d22 + d11 m22 - m12 d21 - d12 m21
            _ipoly_mul_acc(Es[0], Rs[0], Es[7], Rs[7], 4, 4, 1.0, A[3], RA[3])
            _ipoly_mul_acc(Es[4], Rs[4], Es[3], Rs[3], 4, 4, 1.0, A[3], RA[3])
            _ipoly_mul_acc(Es[1], Rs[1], Es[6], Rs[6], 4, 4, -1.0, A[3], RA[3])
            _ipoly_mul_acc(Es[5], Rs[5], Es[2], Rs[2], 4, 4, -1.0, A[3], RA[3])
            # a2 = m11 k22 + d11 d22 + k11 m22 - m12 k21 - d12 d21 - k12 m21
            _ipoly_mul_acc(Es[0], Rs[0], Es[11], Rs[11], 4, 4, 1.0, A[2], RA[2])
            _ipoly_mul_acc(Es[4], Rs[4], Es[7], Rs[7], 4, 4, 1.0, A[2], RA[2])
            _ipoly_mul_acc(Es[8], Rs[8], Es[3], Rs[3], 4, 4, 1.0, A[2], RA[2])
            _ipoly_mul_acc(Es[1], Rs[1], Es[10], Rs[10], 4, 4, -1.0, A[2], RA[2])
            _ipoly_mul_acc(Es[5], Rs[5], Es[6], Rs[6], 4, 4, -1.0, A[2], RA[2])
            _ipoly_mul_acc(Es[9], Rs[9], Es[2], Rs[2], 4, 4, -1.0, A[2], RA[2])
            # a1 = d11 k22 + k11 d22 - d12 k21 - k12 d21
            _ipoly_mul_acc(Es[4], Rs[4], Es[11], Rs[11], 4, 4, 1.0, A[1], RA[1])
            _ipoly_mul_acc(Es[8], Rs[8], Es[7], Rs[7], 4, 4, 1.0, A[1], RA[1])
            _ipoly_mul_acc(Es[5], Rs[5], Es[10], Rs[10], 4, 4, -1.0, A[1], RA[1])
            _ipoly_mul_acc(Es[9], Rs[9], Es[6], Rs[6], 4, 4, -1.0, A[1], RA[1])
            # a0 = k11 k22 - k12 k21
            _ipoly_mul_acc(Es[8], Rs[8], Es[11], Rs[11], 4, 4, 1.0, A[0], RA[0])
            _ipoly_mul_acc(Es[9], Rs[9], Es[10], Rs[10], 4, 4, -1.0, A[0], RA[0])
            _normalise(A.reshape(-1), RA.reshape(-1), 35)
            # P = A1 (A3 A2 - A4 A1) - A3^2 A0
            T1[:] = 0.0
            R1[:] = 0.0
            _ipoly_mul_acc(A[3], RA[3], A[2], RA[2], 7, 7, 1.0, T1, R1)
            _ipoly_mul_acc(A[4], RA[4], A[1], RA[1], 7, 7, -1.0, T1, R1)
            T2[:] = 0.0
            R2[:] = 0.0
            _ipoly_mul_acc(A[3], RA[3], A[3], RA[3], 7, 7, 1.0, T2, R2)
            P[:] = 0.0
            RP[:] = 0.0
            _ipoly_mul_acc(A[1], RA[1], T1, R1, 7, 13, 1.0, P, RP)
            _ipoly_mul_acc(T2, R2, A[0], RA[0], 13, 7, -1.0, P, RP)
            _normalise(P, RP, 19)
            ok = True
            for k in range(19):
                if not (math.isfinite(P[k]) and math.isfinite(RP[k])):
                    ok = False
            for i in range(5):
                for k in range(7):
                    if not (math.isfinite(A[i, k]) and math.isfinite(RA[i, k])):
                        ok = False
            if not ok:
                flag = 1
                break
            for i in range(5):
                dA[i] = 6
                while dA[i] > 0 and A[i, dA[i]] == 0.0 and RA[i, dA[i]] == 0.0:
                    dA[i] -= 1
            dP = 18
            while dP > 0 and P[dP] == 0.0 and RP[dP] == 0.0:
                dP -= 1
            # isolate the roots of A0, A4, P
            nc = 0
            for which in range(3):
                if which == 0:
                    cnt = isolate_roots(P, RP, 18, wl, wh, brk, w, rw, stack)
                elif which == 1:
                    cnt = isolate_roots(A[0], RA[0], 6, wl, wh, brk, w, rw, stack)
                else:
                    cnt = isolate_roots(A[4], RA[4], 6, wl, wh, brk, w, rw, stack)
                if cnt < 0 or nc + cnt > cand.shape[0]:
                    flag = 1
                    break
                for q in range(cnt):
                    cand[nc, 0] = brk[q, 0]
                    cand[nc, 1] = brk[q, 1]
                    cand[nc, 2] = brk[q, 2]
                    nc += 1
            if flag:
                break
            # sort brackets, require them disjoint
            for q in range(1, nc):
                x0 = cand[q, 0]
                x1 = cand[q, 1]
                x2 = cand[q, 2]
                p = q - 1
                while p >= 0 and cand[p, 0] > x0:
                    cand[p + 1, 0] = cand[p, 0]
                    cand[p + 1, 1] = cand[p, 1]
                    cand[p + 1, 2] = cand[p, 2]
                    p -= 1
                cand[p + 1, 0] = x0
                cand[p + 1, 1] = x1
                cand[p + 1, 2] = x2
            for q in range(1, nc):
                if cand[q, 0] <= cand[q - 1, 1]:
                    flag = 1
            if flag:
                break
            x0 = wl
            for q in range(nc + 1):
                x1 = cand[q, 0] if q < nc else wh
                v = _piece_verdict(A, RA, P, RP, x0, x1, dA, dP)
                if v == UNDECIDED:
                    flag = 1
                    break
                if prev == -1:
                    start_stable[n] = v == STABLE
                elif v != prev:
                    if q == 0:
                        val = lo  # change exactly at the sub-range boundary
                    else:
                        val = math.ldexp(cand[q - 1, 2], ks)
                    if m < maxc:
                        roots_out[n, m] = val
                        dirs_out[n, m] = 1 if v == STABLE else -1
                    m += 1
                prev = v
                if q < nc:
                    x0 = cand[q, 1]
            if flag:
                break
        counts[n] = m
        flags[n] = flag


# ---------------------------------------------------------------- quartic roots (max Re λ and its frequency)
#: Newton on the factorization stops when every relative step is below this (the error is then ~ its square).
_QTOL = 1e-10


@numba.njit(**_JIT)
def _factor_newton(b0, b1, b2, b3, g):  # type: ignore[no-untyped-def]
    """Newton's method for ``μ⁴ + b3 μ³ + b2 μ² + b1 μ + b0 = (μ² + u1 μ + v1)(μ² + u2 μ + v2)``.

    ``g = (u1, v1, u2, v2)`` is the start and receives the result.  The
    Jacobian's determinant is the resultant of the two factors, so the
    iteration is regular unless they share a root.  Returns True when every
    relative step fell below ``_QTOL`` within 12 iterations (each factor on its
    own scale ``max(|u|, sqrt|v|)``, so a small root keeps its relative
    accuracy next to a large one).
    """
    u1, v1, u2, v2 = g[0], g[1], g[2], g[3]
    for _ in range(12):
        r0 = u1 + u2 - b3
        r1 = v1 + u1 * u2 + v2 - b2
        r2 = u1 * v2 + u2 * v1 - b1
        r3 = v1 * v2 - b0
        a11 = u2 - u1
        a21 = v2 - v1
        s1 = r1 - u1 * r0
        s2 = r2 - v1 * r0
        m1 = u2 * v1 - u1 * v2
        det = a11 * m1 + a21 * a21
        if not (det != 0.0 and math.isfinite(det)):
            return False
        inv = 1.0 / det
        du1 = (s1 * m1 - (s2 * v1 - u1 * r3) + (s2 * v2 - u2 * r3)) * inv
        dv1 = (a11 * (s2 * v1 - u1 * r3) - s1 * a21 * v1 + a21 * r3) * inv
        dv2 = (a11 * (u2 * r3 - s2 * v2) - a21 * r3 + s1 * a21 * v2) * inv
        du2 = r0 - du1
        u1 -= du1
        v1 -= dv1
        u2 -= du2
        v2 -= dv2
        if not (math.isfinite(u1) and math.isfinite(v1) and math.isfinite(u2) and math.isfinite(v2)):
            return False
        sc1 = max(abs(u1), math.sqrt(abs(v1)))
        sc2 = max(abs(u2), math.sqrt(abs(v2)))
        if (abs(du1) <= _QTOL * sc1 and abs(dv1) <= _QTOL * sc1 * sc1
                and abs(du2) <= _QTOL * sc2 and abs(dv2) <= _QTOL * sc2 * sc2):
            g[0], g[1], g[2], g[3] = u1, v1, u2, v2
            return True
    return False


@numba.njit(**_JIT)
def _aberth_start(b0, b1, b2, b3, g):  # type: ignore[no-untyped-def]
    """Cold start: the four roots by the Ehrlich–Aberth iteration, paired into real quadratic factors ``g``."""
    R = abs(b0) ** 0.25
    for c in (abs(b1) ** (1.0 / 3.0), math.sqrt(abs(b2)), abs(b3)):
        if not R > 0.0:
            R = c
    if not (R > 0.0 and math.isfinite(R)):
        R = 1.0
    z = np.empty(4, dtype=np.complex128)
    for k in range(4):
        ang = 0.4 + 0.5 * math.pi * k
        z[k] = R * complex(math.cos(ang), math.sin(ang))
    for _ in range(200):
        big = 0.0
        for i in range(4):
            x = z[i]
            p = (((x + b3) * x + b2) * x + b1) * x + b0
            dp = ((4.0 * x + 3.0 * b3) * x + 2.0 * b2) * x + b1
            if p == 0:
                continue
            nt = p / dp
            sm = 0j
            for j in range(4):
                if j != i:
                    sm += 1.0 / (x - z[j])
            w = nt / (1.0 - nt * sm)
            z[i] = x - w
            big = max(big, abs(w) / max(abs(z[i]), 1e-300))
        if not big < 1e300:
            return False
        if big < 1e-13:
            break
    # pair by imaginary part: (lowest, highest) and the middle two are both real-coefficient pairs
    order = np.argsort(z.imag)
    za, zb, zc, zd = z[order[0]], z[order[1]], z[order[2]], z[order[3]]
    g[0] = -(za + zd).real
    g[1] = (za * zd).real
    g[2] = -(zb + zc).real
    g[3] = (zb * zc).real
    return True


@numba.njit(**_JIT)
def _factor_top(u, v):  # type: ignore[no-untyped-def]
    """Largest real part of the roots of ``μ² + u μ + v`` and ``|Im|`` of that root (stable formulas)."""
    disc = u * u - 4.0 * v
    if disc < 0.0:
        return -0.5 * u, 0.5 * math.sqrt(-disc)
    q = -0.5 * (u + math.copysign(math.sqrt(disc), u))
    r2 = v / q if q != 0.0 else 0.0
    return max(q, r2), 0.0


@numba.njit(**_JIT)
def quartic_factor(b0, b1, b2, b3, g, warm):  # type: ignore[no-untyped-def]
    """Factor the monic quartic into ``g`` (warm start from ``g`` if ``warm``, else or on failure Aberth).

    Returns True when the factorization converged.
    """
    if warm and _factor_newton(b0, b1, b2, b3, g):
        return True
    if not _aberth_start(b0, b1, b2, b3, g):
        return False
    return _factor_newton(b0, b1, b2, b3, g)


@numba.njit(**_JIT)
def _top(a0, a1, a2, a3, a4, sc, g, warm, out):  # type: ignore[no-untyped-def]
    """Rightmost root of ``Σ a_k μ^k`` times ``sc``: ``out = (Re, |Im|/2π)``; False if not found cleanly."""
    if not (a4 != 0.0 and math.isfinite(a4) and math.isfinite(a0) and math.isfinite(a1) and math.isfinite(a2)
            and math.isfinite(a3)):
        return False
    inv = 1.0 / a4
    if not quartic_factor(a0 * inv, a1 * inv, a2 * inv, a3 * inv, g, warm):
        return False
    r1, i1 = _factor_top(g[0], g[1])
    r2, i2 = _factor_top(g[2], g[3])
    if r2 > r1:
        r1, i1 = r2, i2
    out[0] = r1 * sc
    out[1] = i1 * sc / (2.0 * math.pi)
    return math.isfinite(out[0]) and math.isfinite(out[1])


@numba.njit(**_JIT)
def quartic_top_grid(A, lam_e, mr, fr, ok):  # type: ignore[no-untyped-def]
    """Max Re λ and its frequency on a grid of quartics ``A[k, row, j]`` (ascending ``k``).

    The roots of row ``row`` are scaled by ``2^lam_e[row]``.

    Neighbouring points warm-start each other: along a row from the factors
    of the two previous points (extrapolated), a row's first point from the
    previous row's first point; a start that does not converge falls back to
    the Aberth cold start.  ``ok[row, j] = 0`` where no clean factorization
    was found (the caller recomputes those points by a robust route).
    """
    rows, n = A.shape[1], A.shape[2]
    g = np.empty(4)
    p1 = np.empty(4)
    p2 = np.empty(4)
    first = np.empty(4)
    out = np.empty(2)
    have_first = False
    for r in range(rows):
        sc = math.ldexp(1.0, lam_e[r])
        hv = 0
        for j in range(n):
            warm = True
            if hv >= 2:
                for k in range(4):
                    g[k] = 2.0 * p1[k] - p2[k]
            elif hv == 1:
                g[:] = p1
            elif have_first:
                g[:] = first
            else:
                warm = False
            good = _top(A[0, r, j], A[1, r, j], A[2, r, j], A[3, r, j], A[4, r, j], sc, g, warm, out)
            if good:
                mr[r, j] = out[0]
                fr[r, j] = out[1]
                ok[r, j] = 1
                if hv == 0:
                    first[:] = g
                    have_first = True
                p2[:] = p1
                p1[:] = g
                hv += 1
            else:
                mr[r, j] = np.nan
                fr[r, j] = np.nan
                ok[r, j] = 0
                hv = 0


@numba.njit(**_JIT)
def quartic_top_rows(A, mr, fr, ok):  # type: ignore[no-untyped-def]
    """Max Re λ and its frequency for quartics ``A[i, k]`` (ascending ``k``); each row warm-starts the next."""
    g = np.empty(4)
    out = np.empty(2)
    warm = False
    for i in range(A.shape[0]):
        good = _top(A[i, 0], A[i, 1], A[i, 2], A[i, 3], A[i, 4], 1.0, g, warm, out)
        if good:
            mr[i] = out[0]
            fr[i] = out[1]
            ok[i] = 1
        else:
            mr[i] = np.nan
            fr[i] = np.nan
            ok[i] = 0
        warm = good


# ---------------------------------------------------------------- n-DOF characteristic polynomial on a grid
@numba.njit(**_JIT)
def _cp_horner_rows(Q, RQ, x, T, RT):  # type: ignore[no-untyped-def]
    """Row table ``T[k, b] = Σ_a Q[k, a, b] x^a`` with rigorous radii ``RT`` (``Q`` known to within ``RQ``)."""
    m1, da1, db1 = Q.shape
    ax = abs(x)
    g = 2.0 * (2 * da1 + 2) * _U
    for k in range(m1):
        for b in range(db1):
            v = Q[k, da1 - 1, b]
            a = abs(v)
            r = RQ[k, da1 - 1, b]
            for i in range(da1 - 2, -1, -1):
                v = v * x + Q[k, i, b]
                a = a * ax + abs(Q[k, i, b])
                r = r * ax + RQ[k, i, b]
            T[k, b] = v
            RT[k, b] = (r + g * a) * (1.0 + 4.0 * (da1 + 2) * _U) + _ETA


@numba.njit(**_JIT)
def _cp_coefficients(T, RT, y, c, rc):  # type: ignore[no-untyped-def]
    """``c_k = Σ_b T[k, b] y^b`` with rigorous radii (Horner, running error bound)."""
    m1, db1 = T.shape
    ay = abs(y)
    g = 2.0 * (2 * db1 + 2) * _U
    for k in range(m1):
        v = T[k, db1 - 1]
        a = abs(v)
        r = RT[k, db1 - 1]
        for i in range(db1 - 2, -1, -1):
            v = v * y + T[k, i]
            a = a * ay + abs(T[k, i])
            r = r * ay + RT[k, i]
        c[k] = v
        rc[k] = (r + g * a) * (1.0 + 4.0 * (db1 + 2) * _U) + _ETA


@numba.njit(**_JIT)
def _cp_scale(c, rc, m, b, rb):  # type: ignore[no-untyped-def]
    """``b_k = c_k 2^(e k + f)`` (exact): ``λ = 2^e μ`` balances ``|c_0|`` and ``|c_m|``; returns ``e`` or -9999."""
    if c[m] == 0.0 or not math.isfinite(c[m]):
        return -9999
    e = 0
    if c[0] != 0.0 and math.isfinite(c[0]):
        e = int(round((math.frexp(c[0])[1] - math.frexp(c[m])[1]) / m))
    f = -(math.frexp(c[m])[1] + e * m)
    for k in range(m + 1):
        b[k] = math.ldexp(c[k], e * k + f)
        rb[k] = math.ldexp(rc[k], e * k + f) * (1.0 + 4.0 * _U) + _ETA
        if not (math.isfinite(b[k]) and math.isfinite(rb[k])):
            return -9999
        if b[k] != 0.0 and abs(b[k]) < 1e-280:  # subnormal range: the scaling would not be exact
            return -9999
    return e


@numba.njit(inline="always", **_JIT)
def _cabs(v):  # type: ignore[no-untyped-def]
    """``|v|`` to within a relative ``2u`` (no ``hypot``: the operands here never overflow, else inf/NaN results)."""
    return math.sqrt(v.real * v.real + v.imag * v.imag)


@numba.njit(**_JIT)
def _cp_cold(b, m, z, part):  # type: ignore[no-untyped-def]
    """Starting roots: eigenvalues of the companion matrix of ``b`` (LAPACK), made exactly conjugate-symmetric.

    ``part[i]`` is the index of the conjugate partner of ``z[i]`` (``i`` for a
    real root).  Returns ``False`` when the roots cannot be paired.
    """
    C = np.zeros((m, m), dtype=np.complex128)
    for k in range(m):
        C[0, k] = -b[m - 1 - k] / b[m]
        if not math.isfinite(C[0, k].real):
            return False
    for k in range(1, m):
        C[k, k - 1] = 1.0
    w = np.linalg.eigvals(C)
    scale = 0.0
    for i in range(m):
        if not (math.isfinite(w[i].real) and math.isfinite(w[i].imag)):
            return False
        scale = max(scale, _cabs(w[i]))
    tol = 1e-9 * scale
    used = np.zeros(m, dtype=np.bool_)
    n = 0
    for i in range(m):  # pairs: a root above the axis with the nearest unused conjugate below it
        if used[i] or not w[i].imag > tol:
            continue
        best = -1
        dist = np.inf
        for j in range(m):
            if not used[j] and w[j].imag < -tol:
                d = _cabs(w[j] - w[i].conjugate())
                if d < dist:
                    dist = d
                    best = j
        if best < 0:
            return False
        used[i] = True
        used[best] = True
        zi = 0.5 * (w[i] + w[best].conjugate())
        z[n] = zi
        z[n + 1] = zi.conjugate()
        part[n] = n + 1
        part[n + 1] = n
        n += 2
    for i in range(m):  # real roots
        if not used[i]:
            if abs(w[i].imag) > tol:
                return False
            z[n] = complex(w[i].real, 0.0)
            part[n] = n
            n += 1
    return n == m


@numba.njit(**_JIT)
def _cp_sweep(b, rb, m, z, part, w, rad):  # type: ignore[no-untyped-def]
    """One Weierstrass (Durand-Kerner) sweep at the current ``z`` (nothing updated).

    ``w[i] = p(z_i) / (b_m Π_{j≠i} (z_i - z_j))`` and rigorous radii
    ``rad[i] >= m |W_i|`` of the Gerschgorin disks of the generalized companion
    matrix ``diag(z) - 1 Wᵀ`` (its eigenvalues are the roots of every
    polynomial within the coefficient radii ``rb``): every root lies in the
    union of the disks ``|λ - z_i| <= rad[i]``, and a connected component of
    ``k`` disks holds exactly ``k`` roots.  ``z`` is conjugate-symmetric
    (``part``), so only one root of each pair is computed (``W`` of the partner
    is the conjugate, its disk the mirror image).  Returns the largest
    ``|w_i| / |z_i|`` (inf if a product vanishes).
    """
    lead = abs(b[m]) - rb[m]
    worst = 0.0
    g = 2.0 * (4 * m + 8) * _U
    for i in range(m):
        if part[i] < i:
            continue
        zi = z[i]
        az = _cabs(zi) * (1.0 + 2.0 * _U)
        h = abs(b[m])
        r = rb[m]
        if part[i] == i:  # real root: real Horner
            x = zi.real
            vr = b[m]
            for k in range(m - 1, -1, -1):
                vr = vr * x + b[k]
                h = h * az + abs(b[k])
                r = r * az + rb[k]
            v = complex(vr, 0.0)
            av = abs(vr)
        else:
            v = complex(b[m], 0.0)
            for k in range(m - 1, -1, -1):
                v = v * zi + b[k]
                h = h * az + abs(b[k])
                r = r * az + rb[k]
            av = _cabs(v)
        pr = complex(b[m], 0.0)
        for j in range(m):
            if j != i:
                pr = pr * (zi - z[j])
        apr = _cabs(pr)
        if not (apr > 0.0 and math.isfinite(apr) and lead > 0.0 and math.isfinite(av)):
            w[i] = 0.0
            rad[i] = np.inf
            worst = np.inf
            continue
        wi = v / pr
        if part[i] == i:
            wi = complex(wi.real, 0.0)
        w[i] = wi
        num = (av + g * h + r) * (1.0 + 8.0 * (m + 2) * _U)
        den = apr * (lead / abs(b[m])) * (1.0 - g * m)
        rad[i] = m * (num / den) * (1.0 + 16.0 * _U) + _ETA
        if part[i] != i:
            w[part[i]] = wi.conjugate()
            rad[part[i]] = rad[i]
        rel = _cabs(wi) / az if az > 0.0 else np.inf
        if rel > worst:
            worst = rel
    return worst


@numba.njit(**_JIT)
def _cp_verdict(z, rad, m):  # type: ignore[no-untyped-def]
    """STABLE if every disk lies in the open left half-plane; UNSTABLE if an isolated disk lies in the open right
    half-plane (it holds exactly one root); UNDECIDED otherwise."""
    stable = True
    for i in range(m):
        if not (z[i].real + rad[i] * (1.0 + 4.0 * _U) < 0.0):
            stable = False
            break
    if stable:
        return STABLE
    for i in range(m):
        if not (z[i].real - rad[i] * (1.0 + 4.0 * _U) > 0.0):
            continue
        if _cp_isolated(z, rad, m, i):
            return UNSTABLE
    return UNDECIDED


@numba.njit(**_JIT)
def _cp_isolated(z, rad, m, i):  # type: ignore[no-untyped-def]
    """Whether disk ``i`` is disjoint from every other disk (then it holds exactly one root)."""
    for j in range(m):
        if j != i and _cabs(z[i] - z[j]) * (1.0 - 4.0 * _U) <= (rad[i] + rad[j]) * (1.0 + 4.0 * _U):
            return False
    return True


@numba.njit(**_JIT)
def _cp_accurate(z, w, rad, part, m, acc):  # type: ignore[no-untyped-def]
    """Whether ``max Re λ`` and its root are known to ``acc |z_top|``.

    Gerschgorin row disks of ``T^-1 (diag(z) - 1 Wᵀ) T`` with ``T`` scaling
    the top root and its conjugate partner by ``t = 2^10, 2^20`` or ``2^30`` (``|W_j| <= rad_j / m``):
    the top root's disk has radius ``|W_top| + |W_partner| + Σ_other |W_k| / t``,
    every other disk ``Σ_k |W_k| + t (|W_top| + |W_partner|)``.  Accepted when
    the top disk is that small, disjoint from every other disk (so it holds
    exactly one root) and no other disk reaches further right; the root then
    lies within ``acc |z_top|`` of ``z_top - w_top``.
    """
    top = 0
    for i in range(m):
        if z[i].real > z[top].real:
            top = i
    p = part[top]
    wt = rad[top] / m + (rad[p] / m if p != top else 0.0)
    so = 0.0
    for k in range(m):
        if k != top and k != p:
            so += rad[k] / m
    f = 1.0 + 8.0 * (m + 2) * _U
    for q in range(1, 4):
        if _cp_scaled_ok(z, w, part, m, acc, top, wt, so, f, 2.0 ** (10 * q)):
            return True
    return False


@numba.njit(**_JIT)
def _cp_scaled_ok(z, w, part, m, acc, top, wt, so, f, t):  # type: ignore[no-untyped-def]
    """The test of :func:`_cp_accurate` for one scaling ``t``."""
    p = part[top]
    rt = (wt + so / t) * f
    if not rt + _cabs(w[top]) <= acc * _cabs(z[top]):  # the caller reports z_top - w_top
        return False
    ro = (wt + so + t * wt) * f
    edge = z[top].real + rt
    for j in range(m):
        if j == top or j == p:
            continue
        if z[j].real + ro > edge:
            return False
        if _cabs(z[top] - z[j]) * (1.0 - 4.0 * _U) <= (rt + ro) * (1.0 + 4.0 * _U):
            return False
    if p != top and _cabs(z[top] - z[p]) * (1.0 - 4.0 * _U) <= 2.0 * rt * (1.0 + 4.0 * _U):
        return False
    return True


@numba.njit(**_JIT)
def _cp_point(b, rb, m, z, part, w, rad, eigen, acc, maxit):  # type: ignore[no-untyped-def]
    """Iterate Weierstrass sweeps from ``z`` until the disks decide (and, with ``eigen``, ``max Re λ`` is accurate).

    Returns the verdict (UNDECIDED if not reached within ``maxit`` sweeps);
    ``z`` and ``rad`` hold the centres and radii that decided it.
    """
    for it in range(maxit):
        worst = _cp_sweep(b, rb, m, z, part, w, rad)
        if not math.isfinite(worst):
            return UNDECIDED
        if worst < 1e-4:
            code = _cp_verdict(z, rad, m)
            if code != UNDECIDED and (not eigen or _cp_accurate(z, w, rad, part, m, acc)):
                return code
        for i in range(m):
            z[i] = z[i] - w[i]
    return UNDECIDED


@numba.njit(**_JIT)
def _cp_workspace(m, db1):  # type: ignore[no-untyped-def]
    """Work arrays of the characteristic-polynomial sweeps (degree ``m``, ``db1`` coefficient columns):
    ``T, RT`` (coefficient tables), ``c, rc, b, rb`` (polynomial and rounding bounds), ``z, w`` (roots and
    updates), ``rad`` (inclusion radii), ``part`` (cluster labels)."""
    return (np.empty((m + 1, db1)), np.empty((m + 1, db1)), np.empty(m + 1), np.empty(m + 1), np.empty(m + 1),
            np.empty(m + 1), np.empty(m, dtype=np.complex128), np.empty(m, dtype=np.complex128), np.empty(m),
            np.empty(m, dtype=np.int64))


@numba.njit(**_JIT)
def charpoly_grid(Q, RQ, xo, yi, valid, eigen, acc, codes, mr, fr):  # type: ignore[no-untyped-def]
    """Certified verdicts (and ``max Re λ``, frequency) from the exact characteristic polynomial on a grid.

    ``Q[k, a, b]`` (radii ``RQ``) is the coefficient of ``λ^k x^a y^b`` of
    ``det(λ²M + λD + K)`` (up to a factor that does not vanish where the
    leading coefficient does not); ``x = xo[r]`` (outer), ``y = yi[j]``
    (inner).  Per point: coefficients with rigorous radii (Horner with
    running error bounds), ``λ = 2^e μ`` balancing, roots by Weierstrass
    (Durand-Kerner) sweeps warm-started from the previous points of the row
    (quadratic extrapolation; the first point of a row from the first point of
    the previous row; cold start from companion eigenvalues), and the verdict
    from Gerschgorin inclusion disks (:func:`_cp_sweep`, :func:`_cp_verdict`).
    With ``eigen`` the root with the largest real part must also be known to
    ``acc`` relative (:func:`_cp_accurate`), so that ``max_real`` and the
    frequency are accurate to that.  Points not decided so get code
    UNDECIDED (the caller recomputes them) and NaN.
    """
    m = Q.shape[0] - 1
    T, RT, c, rc, b, rb, z, w, rad, part = _cp_workspace(m, Q.shape[2])
    hist = np.empty((3, m), dtype=np.complex128)  # roots (λ units) at the last decided points of the row
    row0 = np.empty(m, dtype=np.complex128)  # roots at the first decided point of the previous row
    part0 = np.empty(m, dtype=np.int64)
    have0 = False
    two_pi = 2.0 * math.pi
    for r in range(xo.size):
        _cp_horner_rows(Q, RQ, xo[r], T, RT)
        have = 0
        first = True
        for j in range(yi.size):
            codes[r, j] = UNDECIDED
            mr[r, j] = np.nan
            fr[r, j] = np.nan
            if not valid[r, j]:
                continue
            _cp_coefficients(T, RT, yi[j], c, rc)
            e = _cp_scale(c, rc, m, b, rb)
            if e == -9999:
                have = 0
                continue
            s = math.ldexp(1.0, -e)
            code = UNDECIDED
            if have > 0 or (first and have0):
                for i in range(m):
                    if have >= 3:
                        z[i] = (3.0 * hist[0, i] - 3.0 * hist[1, i] + hist[2, i]) * s
                    elif have == 2:
                        z[i] = (2.0 * hist[0, i] - hist[1, i]) * s
                    elif have == 1:
                        z[i] = hist[0, i] * s
                    else:
                        z[i] = row0[i] * s
                        part[i] = part0[i]
                code = _cp_point(b, rb, m, z, part, w, rad, eigen, acc, 8)
            if code == UNDECIDED:
                have = 0
                if _cp_cold(b, m, z, part):
                    code = _cp_point(b, rb, m, z, part, w, rad, eigen, acc, 40)
            if code == UNDECIDED:
                have = 0
                continue
            codes[r, j] = code
            si = math.ldexp(1.0, e)
            top = 0
            for i in range(m):
                if z[i].real > z[top].real:
                    top = i
            zt = z[top] - w[top]  # the Weierstrass update: the centre of the top root's Gerschgorin disk
            mr[r, j] = zt.real * si
            fr[r, j] = abs(zt.imag) * si / two_pi
            for i in range(m):
                hist[2, i] = hist[1, i]
                hist[1, i] = hist[0, i]
                hist[0, i] = z[i] * si
            if first:
                for i in range(m):
                    row0[i] = hist[0, i]
                    part0[i] = part[i]
                have0 = True
                first = False
            have = min(have + 1, 3)


# ---------------------------------------------------------------- parallel drivers (independent chunks)
#: Smallest batch split over threads (below it the thread start-up costs more than it saves).
PARALLEL_MIN = 4096


@numba.njit(parallel=True, **_JIT)
def critical_batch_chunks(E_all, R_all, bounds, roots_out, dirs_out, counts, start_stable, flags, nchunk):  # type: ignore[no-untyped-def]  # noqa: E501
    """:func:`critical_batch` on ``nchunk`` contiguous chunks of rows in parallel (identical results)."""
    n = E_all.shape[0]
    for q in numba.prange(nchunk):
        a = q * n // nchunk
        b = (q + 1) * n // nchunk
        critical_batch(E_all[a:b], R_all[a:b], bounds, roots_out[a:b], dirs_out[a:b], counts[a:b],
                       start_stable[a:b], flags[a:b])


@numba.njit(parallel=True, **_JIT)
def charpoly_grid_chunks(Q, RQ, xo, yi, valid, eigen, acc, codes, mr, fr, block):  # type: ignore[no-untyped-def]
    """:func:`charpoly_grid` on blocks of ``block`` rows in parallel (each block warm-starts itself, so the
    results do not depend on the number of threads)."""
    n = xo.shape[0]
    nchunk = (n + block - 1) // block
    for q in numba.prange(nchunk):
        a = q * block
        b = min(n, a + block)
        charpoly_grid(Q, RQ, xo[a:b], yi, valid[a:b], eigen, acc, codes[a:b], mr[a:b], fr[a:b])


@numba.njit(parallel=True, **_JIT)
def quartic_top_grid_chunks(A, lam_e, mr, fr, ok, block):  # type: ignore[no-untyped-def]
    """:func:`quartic_top_grid` on blocks of ``block`` rows in parallel (each block warm-starts itself, so the
    results do not depend on the number of threads)."""
    n = A.shape[1]
    nchunk = (n + block - 1) // block
    for q in numba.prange(nchunk):
        a = q * block
        b = min(n, a + block)
        quartic_top_grid(A[:, a:b], lam_e[a:b], mr[a:b], fr[a:b], ok[a:b])


@numba.njit(**_JIT)
def balance_batch(B, t, iterations):  # type: ignore[no-untyped-def]
    """In place: a power-of-two diagonal similarity ``T^-1 B T`` of every ``B[i]`` (``t[i]`` its diagonal).

    The sweeps of :func:`~.robust.balance_scaling`: every row and column's off-diagonal sums are equilibrated
    simultaneously by ``2^round(log2(r/c)/2)``, until no scale changes (exact: powers of two).
    """
    N, m = B.shape[0], B.shape[1]
    e = np.zeros(m)
    for i in range(N):
        for j in range(m):
            t[i, j] = 1.0
        for _ in range(iterations):
            changed = False
            for j in range(m):
                c = 0.0
                r = 0.0
                for k in range(m):
                    if k != j:
                        c += abs(B[i, k, j])
                        r += abs(B[i, j, k])
                e[j] = 0.0
                if c > 0.0 and r > 0.0 and c < math.inf and r < math.inf:
                    v = np.rint(0.5 * math.log2(r / c))
                    if v == v and abs(v) < 1e300:
                        e[j] = v
                        if v != 0.0:
                            changed = True
            if not changed:
                break
            for a in range(m):
                for b in range(m):
                    if e[a] != e[b]:
                        B[i, a, b] = B[i, a, b] * math.ldexp(1.0, int(e[b]) - int(e[a]))
            for j in range(m):
                t[i, j] = t[i, j] * math.ldexp(1.0, int(e[j]))


def _guard() -> None:
    from ..codegen.cache import guard_numba_caches

    guard_numba_caches(globals())  # a damaged numba cache file is recompiled, never an error


_guard()
