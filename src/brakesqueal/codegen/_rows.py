"""Compiled evaluation of kernel coefficient tables per row, in exponent-scaled floating point with error bounds.

A table term ``t`` contributes ``mant[t] · 2^e2[t] · Π_j x_j^exps[t, j]`` to
column ``slot[t]``.  Every outer value is split as ``x = m 2^q`` (``frexp``),
so that ``Π x^e = Π m^e · 2^(Σ q e)``: the power of two is accumulated as an
integer, the row is scaled by one common power of two (its largest term is
of order one), and nothing overflows whatever the axis values and the
magnitudes of the exact coefficients are.  Row scaling by a positive number
does not change any stability verdict.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["rows_eval", "normalise_rows"]

_U = 2.0 ** -53
#: 2^-k for k = 0..1074 (exact), avoids a libm ldexp call per term
_POW2 = np.ldexp(1.0, -np.arange(1075))


@numba.njit(cache=True, error_model="numpy")
def rows_eval(exps, slot, mant, e2, Um, Qe, nops, C, EC):  # type: ignore[no-untyped-def]
    """Fill ``C[r, s]`` (values) and ``EC[r, s]`` (absolute error bounds) for every row ``r``.

    ``nops[s]`` bounds the number of rounded operations per term plus the
    number of terms of column ``s``; the bound is ``(nops + 2) u Σ|terms|``
    (standard summation / product error analysis) plus the magnitude of any
    term that underflows.
    """
    pow2 = _POW2  # a global array (frozen into the compiled code; a default argument defeated numba's cache)
    nt = exps.shape[0]
    nx = exps.shape[1]
    ncol = C.shape[1]
    ex = np.empty(nt, dtype=np.int64)
    A = np.empty(ncol)
    for r in range(C.shape[0]):
        mx = -(1 << 62)
        for t in range(nt):
            e = e2[t]
            for j in range(nx):
                e += Qe[r, j] * exps[t, j]
            ex[t] = e
            if mant[t] != 0.0 and e > mx:
                mx = e
        for s in range(ncol):
            C[r, s] = 0.0
            A[s] = 0.0
            EC[r, s] = 0.0
        for t in range(nt):
            v = mant[t]
            for j in range(nx):
                u = Um[r, j]
                for _ in range(exps[t, j]):
                    v *= u
            sh = ex[t] - mx
            s = slot[t]
            if sh < -1000:
                EC[r, s] += pow2[min(-sh, 1074)]
                continue
            v *= pow2[-sh]
            C[r, s] += v
            A[s] += abs(v)
        for s in range(ncol):
            EC[r, s] += (nops[s] + 2.0) * _U * 1.001 * A[s] + 1e-300


@numba.njit(cache=True, error_model="numpy")
def normalise_rows(C, EC, degrees, lam_e):  # type: ignore[no-untyped-def]
    """Balance ``λ -> 2^e λ`` per row (``|N_0| ~ |N_4|``) and scale the row by a power of two (exact).

    ``lam_e[r]`` receives the row's ``e`` (the roots of the scaled quartic times ``2^e`` are the ``λ``).
    """
    offs = np.zeros(6, dtype=np.int64)
    for i in range(5):
        offs[i + 1] = offs[i] + degrees[i] + 1
    for r in range(C.shape[0]):
        m0 = 0.0
        m4 = 0.0
        for k in range(offs[0], offs[1]):
            m0 = max(m0, abs(C[r, k]))
        for k in range(offs[4], offs[5]):
            m4 = max(m4, abs(C[r, k]))
        e = 0
        if m0 > 0.0 and m4 > 0.0 and math.isfinite(m0) and math.isfinite(m4):
            e = int(round((math.log2(m0) - math.log2(m4)) / 4.0))
        lam_e[r] = e
        if e != 0:
            for i in range(5):
                for k in range(offs[i], offs[i + 1]):
                    C[r, k] = math.ldexp(C[r, k], i * e)
                    EC[r, k] = math.ldexp(EC[r, k], i * e)
        big = 0.0
        for k in range(C.shape[1]):
            big = max(big, abs(C[r, k]) + EC[r, k])
        if big > 0.0 and math.isfinite(big):
            sh = -math.frexp(big)[1]
            for k in range(C.shape[1]):
                C[r, k] = math.ldexp(C[r, k], sh)
                EC[r, k] = math.ldexp(EC[r, k], sh)


def _guard() -> None:
    from .cache import guard_numba_caches

    guard_numba_caches(globals())  # a damaged or unwritable numba cache file is recompiled, never an error


_guard()
