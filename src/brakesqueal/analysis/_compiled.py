"""Compiled (numba) polynomial root isolation and the batched critical-speed kernel.

Imported lazily (numba start-up costs about a second); every function is
cached on disk by numba.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["peval", "real_roots", "critical_batch"]

_JIT = dict(cache=True, error_model="numpy")


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
    """Real roots of ``Σ c[k] x^k`` in ``(lo, hi)``, ascending, written to ``out``; returns the count.

    Derivative cascade: the real roots of ``p^(m+1)`` split the interval into
    pieces where ``p^(m)`` is monotone, so each piece holds at most one root,
    found by bracketing.  Roots of even multiplicity at a critical point are
    reported once.
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


@numba.njit(**_JIT)
def _pmul(a, b):  # type: ignore[no-untyped-def]
    out = np.zeros(a.shape[0] + b.shape[0] - 1)
    for i in range(a.shape[0]):
        for j in range(b.shape[0]):
            out[i + j] += a[i] * b[j]
    return out


@numba.njit(**_JIT)
def _stable_at(A, P, w):  # type: ignore[no-untyped-def]
    for i in range(5):
        if not peval(A[i], A.shape[1] - 1, w) > 0.0:
            return False
    return peval(P, P.shape[0] - 1, w) > 0.0


@numba.njit(**_JIT)
def critical_batch(E_all, lo, hi, roots_out, dirs_out, counts, start_stable):  # type: ignore[no-untyped-def]
    """Stability changes along Ω in ``(lo, hi)`` for each row of Laurent entry tables.

    ``E_all[n, e, k]`` is the coefficient of ``Ω^(k-1)`` of entry ``e`` of
    ``(Mbar, Dbar, Kbar)`` (row-major).  With ``w = Ω/s``, ``s = sqrt(lo hi)``,
    ``A_i(w) = w² a_i`` and ``P(w) = w^6 H3`` are polynomials; candidates are
    the real roots of ``P`` and of the ``A_i``, stability is decided between
    consecutive candidates by Liénard–Chipart.
    """
    s = math.sqrt(lo * hi)
    wl, wh = lo / s, hi / s
    cand = np.empty(64)
    r = np.empty(32)
    for n in range(E_all.shape[0]):
        E = E_all[n].copy()
        for e in range(12):
            f = 1.0 / s
            for k in range(4):
                E[e, k] *= f
                f *= s
        m11, m12, m21, m22 = E[0], E[1], E[2], E[3]
        d11, d12, d21, d22 = E[4], E[5], E[6], E[7]
        k11, k12, k21, k22 = E[8], E[9], E[10], E[11]
        A = np.zeros((5, 7))
        A[4] = _pmul(m11, m22) - _pmul(m12, m21)
        A[3] = _pmul(m11, d22) + _pmul(d11, m22) - _pmul(m12, d21) - _pmul(d12, m21)
        A[2] = (_pmul(m11, k22) + _pmul(d11, d22) + _pmul(k11, m22) - _pmul(m12, k21)
                - _pmul(d12, d21) - _pmul(k12, m21))
        A[1] = _pmul(d11, k22) + _pmul(k11, d22) - _pmul(d12, k21) - _pmul(k12, d21)
        A[0] = _pmul(k11, k22) - _pmul(k12, k21)
        mx = np.max(np.abs(A))
        if mx > 0.0:
            A /= mx
        if peval(A[4], 6, 1.0) < 0.0:
            A *= -1.0
        P = _pmul(A[1], _pmul(A[3], A[2]) - _pmul(A[4], A[1])) - _pmul(_pmul(A[3], A[3]), A[0])
        mx = np.max(np.abs(P))
        if mx > 0.0:
            P /= mx
        nc = 0
        lz = 0
        while lz < P.shape[0] - 1 and P[lz] == 0.0:
            lz += 1
        k = real_roots(P[lz:].copy(), wl, wh, r)
        for q in range(k):
            cand[nc] = r[q]
            nc += 1
        for i in range(5):
            lz = 0
            while lz < 6 and A[i, lz] == 0.0:
                lz += 1
            k = real_roots(A[i, lz:].copy(), wl, wh, r)
            for q in range(k):
                if nc < cand.shape[0]:
                    cand[nc] = r[q]
                    nc += 1
        c = np.sort(cand[:nc])
        prev = _stable_at(A, P, wl)
        start_stable[n] = prev
        m = 0
        for q in range(nc):
            b = c[q + 1] if q + 1 < nc else wh
            if b <= c[q]:
                continue
            st = _stable_at(A, P, math.sqrt(c[q] * b))
            if st != prev:
                if m < roots_out.shape[1]:
                    roots_out[n, m] = c[q] * s
                    dirs_out[n, m] = 1 if st else -1
                m += 1
                prev = st
        counts[n] = m


def _guard() -> None:
    from ..numeric.cache import guard_numba_caches

    guard_numba_caches(globals())  # a damaged numba cache file is recompiled, never an error


_guard()
