"""Template: the flow integrator (numba): the shared DOP853 step with variational equations, read as text.

:func:`brakesqueal.codegen.simulation.flow_kernel` appends the text below the
marker line to :mod:`.dop853` and loads the module once per machine (the code
cache).  The vector field is passed as first-class functions with fixed
signatures (:data:`F_SIGNATURE`, :data:`JAC_SIGNATURE`), so ``dop853`` is
compiled once for every system (:class:`brakesqueal.nonlinear.CompiledFlow`).
With ``sens`` the state is ``(x, [M | x_p])`` and the stages integrate the
variational equations ``M' = f_x M``, ``x_p' = f_x x_p + f_p``.  Output
samples are hit exactly by shortening steps (no dense output).

The stand-ins above the marker only make this file a valid, linted module.
"""
# ruff: noqa: E501
# mypy: ignore-errors

import math

import numpy as np
from numba import njit


def dop853_step(ctx, y, h, rtol, atol, K, ynew, ystage):  # template dop853
    raise NotImplementedError


def dop853_factor(err, rejected):  # template dop853
    raise NotImplementedError


_NS = 12  # template dop853


# ---- template body ----

from numba import types as _nbt  # noqa: E402

#: ``f(x, p, theta, out)`` and ``dfdp(x, p, theta, out)``: ``x``, ``theta`` (fixed model parameters) and
#: ``out`` C-contiguous float64 vectors, ``p`` the continuation parameter.
F_SIGNATURE = _nbt.void(_nbt.float64[::1], _nbt.float64, _nbt.float64[::1], _nbt.float64[::1])
#: ``jac(x, p, theta, out)`` with ``out`` a C-contiguous float64 ``(n, n)`` matrix.
JAC_SIGNATURE = _nbt.void(_nbt.float64[::1], _nbt.float64, _nbt.float64[::1], _nbt.float64[:, ::1])
_FT = _nbt.FunctionType(F_SIGNATURE)
_JT = _nbt.FunctionType(JAC_SIGNATURE)


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


@njit(cache=True, inline="always")
def _stage_rhs(ctx, y, out):
    """The right-hand side of the DOP853 stages: ctx = (f, jac, dfdp, p, theta, n, sens, xb, J, fp)."""
    _rhs(ctx[0], ctx[1], ctx[2], y, ctx[3], ctx[4], ctx[5], ctx[6], ctx[7], ctx[8], ctx[9], out)


_SIG = _nbt.Tuple((_nbt.int64, _nbt.int64, _nbt.float64))(
    _FT, _JT, _FT, _nbt.float64[::1], _nbt.float64, _nbt.float64[::1], _nbt.float64, _nbt.float64,
    _nbt.float64[::1], _nbt.boolean, _nbt.float64[::1], _nbt.float64[:, ::1], _nbt.float64, _nbt.int64,
)


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
    ctx = (f, jac, dfdp, p, th, n, sens, xb, J, fp)
    K = np.empty((16, N))
    yn = np.empty(N)
    tmp = np.empty(N)
    _stage_rhs(ctx, y0, K[0])
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
            d1 += (K[0, i] / sc) ** 2
        d0 = np.sqrt(d0 / N)
        d1 = np.sqrt(d1 / N)
        hh = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
        hh = min(hh, T)
        for i in range(N):
            tmp[i] = y0[i] + hh * K[0, i]
        _stage_rhs(ctx, tmp, yn)
        nfev += 1
        d2 = 0.0
        for i in range(N):
            sc = atol[i] + abs(y0[i]) * rtol
            d2 += ((yn[i] - K[0, i]) / sc) ** 2
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
            err = dop853_step(ctx, y0, hs, rtol, atol, K, yn, tmp)
            nfev += _NS
            if not err < math.inf:
                if rejected and h < min_step * 10:
                    return -3, nfev, h
                h *= 0.2
                rejected = True
                continue
            fac = dop853_factor(err, rejected)
            if err < 1.0:
                # a step shortened to hit an output time does not shrink the next one
                h = max(hs * fac, h) if clipped and fac >= 1.0 else hs * fac
                break
            h = hs * fac
            rejected = True
        t = target if clipped else t + hs
        for i in range(N):
            y0[i] = yn[i]
            K[0, i] = K[_NS, i]
        if clipped and ks < nsamp and target == t_samples[ks]:
            for i in range(n):
                samples[ks, i] = y0[i]
            ks += 1
        steps += 1
        if steps > max_steps:
            return -2, nfev, h
    return 0, nfev, h
