"""numba kernel: DOP853 (SciPy's coefficients, error norm and step control) with variational equations.

The vector field is passed as first-class functions with fixed signatures
(:data:`F_SIGNATURE`, :data:`JAC_SIGNATURE`), so the kernel is compiled once
per machine (``cache=True``) for every system.  Output samples are hit
exactly by shortening steps (no dense output).
"""

from __future__ import annotations

import numpy as np
from numba import njit, types
from scipy.integrate._ivp import dop853_coefficients as _co

#: ``f(x, p, theta, out)`` and ``dfdp(x, p, theta, out)``: ``x``, ``theta`` (fixed model parameters) and
#: ``out`` C-contiguous float64 vectors, ``p`` the continuation parameter.
F_SIGNATURE = types.void(types.float64[::1], types.float64, types.float64[::1], types.float64[::1])
#: ``jac(x, p, theta, out)`` with ``out`` a C-contiguous float64 ``(n, n)`` matrix.
JAC_SIGNATURE = types.void(types.float64[::1], types.float64, types.float64[::1], types.float64[:, ::1])

_NS = _co.N_STAGES
_A = np.ascontiguousarray(_co.A[:_NS, :_NS])
_B = np.ascontiguousarray(_co.B)
_C = np.ascontiguousarray(_co.C[:_NS])
_E3 = np.ascontiguousarray(_co.E3)
_E5 = np.ascontiguousarray(_co.E5)

_FT = types.FunctionType(F_SIGNATURE)
_JT = types.FunctionType(JAC_SIGNATURE)


@njit(cache=True)
def _rhs(f, jac, dfdp, y, p, th, n, sens, xb, J, fp, out):  # pragma: no cover - compiled
    for i in range(n):
        xb[i] = y[i]
    f(xb, p, th, fp)
    for i in range(n):
        out[i] = fp[i]
    if sens:
        jac(xb, p, th, J)
        dfdp(xb, p, th, fp)
        n1 = n + 1
        for i in range(n):
            for j in range(n1):
                s = 0.0
                for k in range(n):
                    s += J[i, k] * y[n + k * n1 + j]
                out[n + i * n1 + j] = s
            out[n + i * n1 + n] += fp[i]


_SIG = types.Tuple((types.int64, types.int64, types.float64))(
    _FT, _JT, _FT, types.float64[::1], types.float64, types.float64[::1], types.float64, types.float64,
    types.float64[::1],
    types.boolean, types.float64[::1], types.float64[:, ::1], types.float64, types.int64,
)  # fmt: skip


@njit(_SIG, cache=True)
def dop853(f, jac, dfdp, y0, p, th, T, rtol, atol, sens, t_samples, samples, h0, max_steps):  # pragma: no cover
    """Integrate ``y' = F(y)`` (state, or state + ``[M | x_p]``) from 0 to ``T``; ``y0`` is overwritten.

    Returns ``(status, nfev, h_last)``; status 0 success, -1 step size too small, -2 too many steps,
    -3 non-finite state.
    """
    N = y0.size
    n = samples.shape[1]
    xb = np.empty(n)
    J = np.empty((n, n))
    fp = np.empty(n)
    K = np.empty((_NS + 1, N))
    yn = np.empty(N)
    tmp = np.empty(N)
    f0 = np.empty(N)
    _rhs(f, jac, dfdp, y0, p, th, n, sens, xb, J, fp, f0)
    nfev = 1
    ks = 0
    nsamp = t_samples.size
    # samples at t = 0
    while ks < nsamp and t_samples[ks] <= 0.0:
        for i in range(n):
            samples[ks, i] = y0[i]
        ks += 1
    # initial step (Hairer-Norsett-Wanner II.4, as SciPy)
    if h0 <= 0.0:
        d0 = 0.0
        d1 = 0.0
        for i in range(N):
            sc = atol[i] + abs(y0[i]) * rtol
            d0 += (y0[i] / sc) ** 2
            d1 += (f0[i] / sc) ** 2
        d0 = np.sqrt(d0 / N)
        d1 = np.sqrt(d1 / N)
        hh = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
        hh = min(hh, T)
        for i in range(N):
            tmp[i] = y0[i] + hh * f0[i]
        _rhs(f, jac, dfdp, tmp, p, th, n, sens, xb, J, fp, yn)
        nfev += 1
        d2 = 0.0
        for i in range(N):
            sc = atol[i] + abs(y0[i]) * rtol
            d2 += ((yn[i] - f0[i]) / sc) ** 2
        d2 = np.sqrt(d2 / N) / hh
        if d1 <= 1e-15 and d2 <= 1e-15:
            h1 = max(1e-6, hh * 1e-3)
        else:
            h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
        h = min(100 * hh, h1, T)
    else:
        h = min(h0, T)
    t = 0.0
    steps = 0
    while t < T:
        target = T if ks >= nsamp else min(T, t_samples[ks])
        rejected = False
        while True:
            min_step = 10 * abs(np.nextafter(t, np.inf) - t)
            if h < min_step:
                return -1, nfev, h
            clipped = t + h >= target
            hs = target - t if clipped else h
            # stages
            for i in range(N):
                K[0, i] = f0[i]
            for s in range(1, _NS):
                for i in range(N):
                    acc = 0.0
                    for j in range(s):
                        acc += K[j, i] * _A[s, j]
                    tmp[i] = y0[i] + acc * hs
                _rhs(f, jac, dfdp, tmp, p, th, n, sens, xb, J, fp, K[s])
            for i in range(N):
                acc = 0.0
                for j in range(_NS):
                    acc += K[j, i] * _B[j]
                yn[i] = y0[i] + hs * acc
            _rhs(f, jac, dfdp, yn, p, th, n, sens, xb, J, fp, K[_NS])
            nfev += _NS
            e5 = 0.0
            e3 = 0.0
            for i in range(N):
                sc = atol[i] + max(abs(y0[i]), abs(yn[i])) * rtol
                a5 = 0.0
                a3 = 0.0
                for j in range(_NS + 1):
                    a5 += K[j, i] * _E5[j]
                    a3 += K[j, i] * _E3[j]
                e5 += (a5 / sc) ** 2
                e3 += (a3 / sc) ** 2
            if e5 == 0.0 and e3 == 0.0:
                err = 0.0
            else:
                err = abs(hs) * e5 / np.sqrt((e5 + 0.01 * e3) * N)
            if not np.isfinite(err):
                if rejected and h < min_step * 10:
                    return -3, nfev, h
                h *= 0.2
                rejected = True
                continue
            if err < 1.0:
                fac = 10.0 if err == 0.0 else min(10.0, 0.9 * err ** (-1.0 / 8.0))
                if rejected:
                    fac = min(1.0, fac)
                hn = hs * fac
                # a step shortened to hit an output time does not shrink the next one
                h = max(hn, h) if clipped and fac >= 1.0 else hn
                break
            h = hs * max(0.2, 0.9 * err ** (-1.0 / 8.0))
            rejected = True
        t = target if clipped else t + hs
        for i in range(N):
            y0[i] = yn[i]
            f0[i] = K[_NS, i]
        if clipped and ks < nsamp and target == t_samples[ks]:
            for i in range(n):
                samples[ks, i] = y0[i]
            ks += 1
        steps += 1
        if steps > max_steps:
            return -2, nfev, h
    return 0, nfev, h


def _guard() -> None:
    from ..codegen.cache import guard_numba_caches

    guard_numba_caches(globals())  # a damaged or unwritable numba cache file is recompiled, never an error


_guard()
