"""Template: the static part of a model's batched silent-motion kernel (numba), read as text.

:func:`brakesqueal.codegen.silent.kernel_source` appends the text below the
marker line to the generated part of the kernel: the model's ``residuals``,
``jacobians`` and ``contact`` decorated for numba, the wrappers
``static_residuals``, ``static_jacobian``, ``full_jacobian``,
``contact_table`` at zero rates and the constants ``_N``, ``_M``, ``_NPAD``,
``_NF``, ``_TILTING``.  The stand-ins above the marker only make this file a
valid, linted module; they are never part of a kernel.

The iteration is exactly the Newton stage of
:func:`brakesqueal.analysis.equilibrium.silent_motion_vector` (scaled
unknowns and rows, abandoned as soon as the steps stop contracting).
"""
# ruff: noqa: E501
# mypy: ignore-errors

import math

import numpy as np
from numba import njit

_N = 2  # coordinates Q (generated)
_M = 0  # pad deformations L (generated)
_NPAD = 2  # pads (generated)
_NF = 7  # contact fields per pad (generated)
_TILTING = True  # the disk tilts (generated)


def static_residuals(z, p, out):  # generated per model
    raise NotImplementedError


def static_jacobian(z, p, out):  # generated per model
    raise NotImplementedError


def full_jacobian(z, p, out):  # generated per model
    raise NotImplementedError


def contact_table(z, p, out):  # generated per model
    raise NotImplementedError


# ---- template body ----


@njit(cache=True, error_model="numpy")
def _lu_solve(A, b, x):
    """Solve A x = b by Gaussian elimination with partial pivoting (A, b overwritten); False if singular."""
    k = A.shape[0]
    for c in range(k):
        piv = c
        best = abs(A[c, c])
        for r in range(c + 1, k):
            if abs(A[r, c]) > best:
                best = abs(A[r, c])
                piv = r
        if not best > 0.0:
            return False
        if piv != c:
            for j in range(k):
                t = A[c, j]
                A[c, j] = A[piv, j]
                A[piv, j] = t
            t = b[c]
            b[c] = b[piv]
            b[piv] = t
        for r in range(c + 1, k):
            f = A[r, c] / A[c, c]
            if f != 0.0:
                for j in range(c + 1, k):
                    A[r, j] -= f * A[c, j]
                b[r] -= f * b[c]
    for c in range(k - 1, -1, -1):
        s = b[c]
        for j in range(c + 1, k):
            s -= A[c, j] * x[j]
        x[c] = s / A[c, c]
    return True


@njit(cache=True, error_model="numpy")
def newton_batch(P, S, floor, max_tilt, max_iter, Z, code, iters, FN, SPEED):
    """Newton from the trivial state for every row of P (scaled as equilibrium._System).

    S[i]: per residual row the magnitude of its terms at z = 0 (a residual is zero to rounding when
    |F_k| <= floor eps S_k).

    Z[i] = (Q0, L0); code[i] = 0 accepted, 1 not converged / inadmissible, 2 contact or sliding near its limit,
    3 non-finite residual or Jacobian; FN, SPEED: per pad at the solution (accepted points).
    """
    K = _N + _M
    eps = 2.220446049250313e-16
    z = np.zeros(K)
    y = np.zeros(K)
    r = np.zeros(K)
    step = np.zeros(K)
    J = np.zeros((K, K))
    J0 = np.zeros((K, K))
    row = np.zeros(K)
    col = np.zeros(K)
    c0 = np.zeros((_NPAD, _NF))
    c1 = np.zeros((_NPAD, _NF))
    for i in range(P.shape[0]):
        p = P[i]
        iters[i] = 0
        for k in range(K):
            z[k] = 0.0
            y[k] = 0.0
        # equilibration at z = 0: rows by their largest entry, then columns
        static_jacobian(z, p, J0)
        bad = False
        for a in range(K):
            mx = 0.0
            for b in range(K):
                v = abs(J0[a, b])
                if not v < math.inf:
                    bad = True
                if v > mx:
                    mx = v
            row[a] = mx if mx > 0.0 else 1.0
        for b in range(K):
            mx = 0.0
            for a in range(K):
                v = abs(J0[a, b]) / row[a]
                if v > mx:
                    mx = v
            col[b] = mx if mx > 0.0 else 1.0
        if bad:
            code[i] = 3
            continue
        ok = False
        last = math.inf
        rlast = math.inf
        it = 0
        while it < max_iter:
            it += 1
            for k in range(K):
                z[k] = y[k] / col[k]
            static_residuals(z, p, r)
            finite = True
            resid = True
            for k in range(K):
                if not abs(r[k]) <= floor * eps * S[i, k]:
                    resid = False
                r[k] = -r[k] / row[k]
                if not abs(r[k]) < math.inf:
                    finite = False
            if not finite:
                break
            rsize = 0.0
            for k in range(K):
                if abs(r[k]) > rsize:
                    rsize = abs(r[k])
            stalled = rsize >= 0.5 * rlast
            rlast = rsize
            if it == 1:  # z = 0: the Jacobian of the equilibration
                for a in range(K):
                    for b in range(K):
                        J[a, b] = J0[a, b]
            else:
                static_jacobian(z, p, J)
            for a in range(K):
                for b in range(K):
                    J[a, b] = J[a, b] / row[a] / col[b]
            if not _lu_solve(J, r, step):
                break
            size = 0.0
            small = True
            ymax = 0.0
            for k in range(K):
                if not abs(step[k]) < math.inf:
                    finite = False
                y[k] += step[k]
            if not finite:
                break
            for k in range(K):
                s = abs(step[k])
                if s > size:
                    size = s
                if s > 8.0 * eps * abs(y[k]):
                    small = False
                if abs(y[k]) > ymax:
                    ymax = abs(y[k])
            if small or size == 0.0:
                ok = True
                break
            at_floor = size <= 1e-9 * ymax or resid or (stalled and size <= 1e-6 * ymax)
            if size > 0.9 * last and at_floor:
                ok = True
                break
            if it > 1 and size > 0.5 * last:
                ok = at_floor  # no longer contracting: converged only at the noise floor
                break
            last = size
            if it == max_iter:
                ok = at_floor
        iters[i] = it
        for k in range(K):
            z[k] = y[k] / col[k]
            Z[i, k] = z[k]
        if not ok:
            code[i] = 1
            continue
        admissible = True
        for k in range(K):
            if not abs(z[k]) < math.inf:
                admissible = False
        if _TILTING and (abs(z[0]) >= max_tilt or abs(z[1]) >= max_tilt):
            admissible = False
        if not admissible:
            code[i] = 1
            continue
        # contact and sliding at the solution, against their values at the trivial state
        contact_table(z, p, c1)
        for k in range(K):
            y[k] = 0.0
        contact_table(y, p, c0)
        near = False
        for j in range(_NPAD):
            fn = c1[j, 0]
            v = math.sqrt(c1[j, 1] ** 2 + c1[j, 2] ** 2 + c1[j, 3] ** 2)
            v0 = math.sqrt(c0[j, 1] ** 2 + c0[j, 2] ** 2 + c0[j, 3] ** 2)
            FN[i, j] = fn
            SPEED[i, j] = v
            if not (fn > 1e-7 * max(abs(c0[j, 0]), abs(fn)) and fn < math.inf):
                near = True
            if not (v > 1e-7 * max(v0, v) and v < math.inf):
                near = True
        code[i] = 2 if near else 0
    return None


@njit(cache=True, error_model="numpy")
def jacobian_batch(P, Z, out):
    """out[i] = d(R, G)/dx at x = (Q, 0, 0, L, 0) with z = Z[i], p = P[i] (row-major, flat)."""
    for i in range(P.shape[0]):
        full_jacobian(Z[i], P[i], out[i])
    return None
