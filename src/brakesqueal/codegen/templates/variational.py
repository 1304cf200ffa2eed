"""Template: a model's vector field with its exact Jacobian and parameter derivative (numba), read as text.

:func:`brakesqueal.codegen.simulation.variational_source` appends the text
below the marker line to the simulation kernels (:mod:`.simulation_pads`) and
the generated ``rg_jacobian`` (``d(R, G)/dx``) and ``rg_param_jacobian``
(``d(R, G)/dp``), with ``_P`` the number of model parameters.  The body
defines ``nl_f``, ``nl_jac`` and ``nl_dfdp`` with the fixed signatures of
:mod:`.flow_dop853` (``F_SIGNATURE``, ``JAC_SIGNATURE``): the simulation's
``f(y)`` (bilateral contact), its exact Jacobian by implicit differentiation
of ``(R, G) = 0`` for ``z = (Qddot, L_quasi-static, Ldot_dynamic)``
(``f_y = [0 I 0; -Phi_z^-1 Phi_y]``, as :func:`brakesqueal.simulation.state_jacobian`)
and ``f_p dp/ds``; ``theta = (p, dp/ds, ztol, l, dl)``.

The stand-ins above the marker only make this file a valid, linted module.
"""
# ruff: noqa: E501
# mypy: ignore-errors

import math

import numpy as np
from numba import njit

_N = 2  # coordinates Q (generated)
_M = 2  # pad deformations L (generated)
_NY = 4  # integrator state (generated)
_NDYN = 0  # dynamic pad states (generated)
_P = 17  # model parameters (generated)
_KIND = np.zeros(2, dtype=np.int64)  # per L: 0 quasi-static, 1 dynamic (generated)
_DYN = np.zeros(0, dtype=np.int64)  # index into L of the dynamic pad states (generated)


def solve_pads(y, l, dl, p, ztol, g):  # template simulation_pads
    raise NotImplementedError


def mass_force(y, l, dl, p, out):  # generated per model
    raise NotImplementedError


def _accelerations(y, dl, ok, mw, out):  # template simulation_pads
    raise NotImplementedError


def rg_jacobian(y, l, dl, a, p, out):  # generated per model
    raise NotImplementedError


def rg_param_jacobian(y, l, dl, a, p, out):  # generated per model
    raise NotImplementedError


# ---- template body ----

from numba import types as _nbt  # noqa: E402

_FSIG = _nbt.void(_nbt.float64[::1], _nbt.float64, _nbt.float64[::1], _nbt.float64[::1])
_JSIG = _nbt.void(_nbt.float64[::1], _nbt.float64, _nbt.float64[::1], _nbt.float64[:, ::1])
_NTH = 2 * _P + 3 * _M  # theta = (p (P), dp/ds (P), ztol (M), l (M), dl (M)); l, dl: warm start, updated in place


@njit(cache=True)
def _theta_views(th):
    return th[:_P], th[_P:2 * _P], th[2 * _P:2 * _P + _M], th[2 * _P + _M:2 * _P + 2 * _M], th[2 * _P + 2 * _M:]


@njit(cache=True)
def _state(y, th, acc):
    """Solve the pads (warm start in theta) and the accelerations at y; returns (ok, p, l, dl)."""
    p, _v, ztol, l, dl = _theta_views(th)
    g = np.empty(2 * _M + 1)
    mw = np.empty(_N * _N + _N)
    out = np.empty(_NY)
    ok = solve_pads(y, l, dl, p, ztol, g)
    mass_force(y, l, dl, p, mw)
    _accelerations(y, dl, ok, mw, out)
    for i in range(_N):
        acc[i] = out[_N + i]
    return ok, out


@njit(_FSIG, cache=True)
def nl_f(y, s, th, out):
    """out = f(y): the integrator's right-hand side (bilateral contact); s unused (theta holds the parameters)."""
    acc = np.empty(_N)
    _ok, r = _state(y, th, acc)
    for i in range(_NY):
        out[i] = r[i]


@njit(cache=True)
def _eliminate(J, X, nrhs):
    """Phi_z X = -X in place (Phi = (R, G), z = (Qddot, L_quasi-static, Ldot_dynamic); J = rg_jacobian), rows
    equilibrated, partial pivoting; NaN if singular."""
    nz = _N + _M
    nc = 3 * _N + 2 * _M
    A = np.empty((nz, nz))
    for i in range(nz):
        for j in range(_N):
            A[i, j] = J[i * nc + 2 * _N + j]
        for j in range(_M):
            c = 3 * _N + j if _KIND[j] == 0 else 3 * _N + _M + j
            A[i, _N + j] = J[i * nc + c]
    for i in range(nz):
        big = 0.0
        for j in range(nz):
            big = max(big, abs(A[i, j]))
        if not big > 0.0:
            big = 1.0
        for j in range(nz):
            A[i, j] /= big
        for k in range(nrhs):
            X[i, k] = -X[i, k] / big
    for k in range(nz):
        piv = k
        big = abs(A[k, k])
        for i in range(k + 1, nz):
            if abs(A[i, k]) > big:
                big = abs(A[i, k])
                piv = i
        if not big > 0.0:
            X[:, :] = math.nan
            return
        if piv != k:
            for j in range(nz):
                A[k, j], A[piv, j] = A[piv, j], A[k, j]
            for j in range(nrhs):
                X[k, j], X[piv, j] = X[piv, j], X[k, j]
        for i in range(k + 1, nz):
            fct = A[i, k] / A[k, k]
            if fct != 0.0:
                for j in range(k, nz):
                    A[i, j] -= fct * A[k, j]
                for j in range(nrhs):
                    X[i, j] -= fct * X[k, j]
    for k in range(nz - 1, -1, -1):
        for j in range(nrhs):
            acc_ = X[k, j]
            for i in range(k + 1, nz):
                acc_ -= A[k, i] * X[i, j]
            X[k, j] = acc_ / A[k, k]


@njit(_JSIG, cache=True)
def nl_jac(y, s, th, out):
    """out = f_y(y), exact: implicit differentiation of (R, G) = 0 for z = (Qddot, L_qs, Ldot_dyn)."""
    acc = np.empty(_N)
    ok, _r = _state(y, th, acc)
    p, _v, _z, l, dl = _theta_views(th)
    J = np.empty((_N + _M) * (3 * _N + 2 * _M))
    rg_jacobian(y, l, dl, acc, p, J)
    nc = 3 * _N + 2 * _M
    X = np.empty((_N + _M, _NY))
    for i in range(_N + _M):
        for j in range(2 * _N):
            X[i, j] = J[i * nc + j]
        for d in range(_NDYN):
            X[i, 2 * _N + d] = J[i * nc + 3 * _N + _DYN[d]]
    _eliminate(J, X, _NY)
    for i in range(_NY):
        for j in range(_NY):
            out[i, j] = 0.0
    for i in range(_N):
        out[i, _N + i] = 1.0
        for j in range(_NY):
            out[_N + i, j] = X[i, j] if ok else math.nan
    for d in range(_NDYN):
        for j in range(_NY):
            out[2 * _N + d, j] = X[_N + _DYN[d], j] if ok else math.nan


@njit(_FSIG, cache=True)
def nl_dfdp(y, s, th, out):
    """out = df/ds = f_p(y) dp/ds (dp/ds in theta), exact: implicit differentiation of (R, G) = 0."""
    acc = np.empty(_N)
    ok, _r = _state(y, th, acc)
    p, v, _z, l, dl = _theta_views(th)
    Jp = np.empty((_N + _M) * _P)
    rg_param_jacobian(y, l, dl, acc, p, Jp)
    J = np.empty((_N + _M) * (3 * _N + 2 * _M))
    rg_jacobian(y, l, dl, acc, p, J)
    X = np.empty((_N + _M, 1))
    for i in range(_N + _M):
        a = 0.0
        for k in range(_P):
            if v[k] != 0.0:
                a += Jp[i * _P + k] * v[k]
        X[i, 0] = a
    _eliminate(J, X, 1)
    for i in range(_N):
        out[i] = 0.0
        out[_N + i] = X[i, 0] if ok else math.nan
    for d in range(_NDYN):
        out[2 * _N + d] = X[_N + _DYN[d], 0] if ok else math.nan
