"""Template: the static part of a model's simulation kernels (numba), read as text.

:func:`brakesqueal.codegen.simulation.kernel_source` appends the text below the
marker line to the generated part of the kernel module: the model's
``pad_balance_e``, ``mass_force``, ``contact``, ``energy``, ``release`` and
``pad_scale`` (``docs/simulation.md``) and the constants ``_N``, ``_M``,
``_NPAD``, ``_NDYN``, ``_NY``, ``_NEV``, ``_KIND``, ``_DYN``, ``_PRESSED``.
The body adds the pads' tangential balances solved per pad (Newton's method,
warm-started, with a bracketing fallback), the right-hand side ``y' = f(y)``
of eq. (44) generalized (``M(Q) Qddot = -f`` by Gaussian elimination with
partial pivoting), its unilateral-contact variant, the event functions and
the post-processing of samples.  No compiled function returns an array:
boxing an array calls back into the interpreter, where a pending
``KeyboardInterrupt`` would surface inside compiled code (issue 11).

The stand-ins above the marker only make this file a valid, linted module;
they are never part of a kernel.
"""
# ruff: noqa: E501
# mypy: ignore-errors

import math

import numpy as np
from numba import njit

_N = 2  # coordinates Q (generated)
_M = 2  # pad deformations L (generated)
_NPAD = 2  # pads (generated)
_NDYN = 0  # pad deformations that are states (generated)
_NY = 4  # integrator state (generated)
_NEV = 4  # event functions (generated)
_KIND = np.zeros(2, dtype=np.int64)  # per L: 0 quasi-static, 1 dynamic (generated)
_DYN = np.zeros(0, dtype=np.int64)  # index into L of the dynamic pad states (generated)
_PRESSED = np.ones(2, dtype=np.int64)  # every pad pressed (generated)


def pad_balance_e(y, l, dl, p, e, out):  # generated per model
    raise NotImplementedError


def mass_force(y, l, dl, p, out):  # generated per model
    raise NotImplementedError


def contact(y, l, dl, p, out):  # generated per model
    raise NotImplementedError


def energy(y, l, dl, p, out):  # generated per model
    raise NotImplementedError


def release(y, l, dl, p, out):  # generated per model
    raise NotImplementedError


# ---- template body ----


@njit(cache=True, error_model="numpy")
def pad_balance(y, l, dl, p, out):
    """G_j and dG_j/dz_j of every pad unknown with every pad pressed (bilateral contact)."""
    pad_balance_e(y, l, dl, p, _PRESSED, out)


@njit(cache=True, error_model="numpy")
def solve_pads(y, l, dl, p, ztol, g):
    """solve_pads_e with every pad pressed (bilateral contact)."""
    return solve_pads_e(y, l, dl, p, ztol, g, _PRESSED)


@njit(cache=True, error_model="numpy")
def solve_pads_e(y, l, dl, p, ztol, g, eng):
    """Newton iterations for G = 0 per pad, in place from the current l, dl (warm start).

    Quasi-static pads: unknown l_j (ldot_j = 0); dynamic pads: l_j = y[2N + i] and unknown ldot_j.
    eng: per pad 1 pressed, 0 lifted off (its balance without the friction force: a lifted pad relaxes).
    Converged when every step is below 1e-13 |z_j| + ztol_j (ztol: the rounding level of G_j / dG_j).
    """
    for i in range(_NDYN):
        l[_DYN[i]] = y[2 * _N + i]
    if _M == 0:
        return True
    for _ in range(40):
        pad_balance_e(y, l, dl, p, eng, g)
        done = True
        for j in range(_M):
            den = g[_M + j]
            if den == 0.0 or not abs(g[j]) < 1e300 * abs(den):  # (python's error model: no division by 0)
                return _solve_pads_bracketed(y, l, dl, p, ztol, g, eng)
            d = g[j] / den
            if _KIND[j] == 0:
                l[j] -= d
                z = l[j]
            else:
                dl[j] -= d
                z = dl[j]
            if abs(d) > 1e-13 * abs(z) + ztol[j]:
                done = False
        if done:
            return True
    return _solve_pads_bracketed(y, l, dl, p, ztol, g, eng)


@njit(cache=True, error_model="numpy")
def _pad_value(y, l, dl, p, g, j, z, eng):
    """G_j and dG_j/dz_j with pad j's unknown set to z (the other pads' entries are not used)."""
    if _KIND[j] == 0:
        l[j] = z
    else:
        dl[j] = z
    pad_balance_e(y, l, dl, p, eng, g)
    return g[j], g[_M + j]


@njit(cache=True, error_model="numpy")
def _solve_pads_bracketed(y, l, dl, p, ztol, g, eng):
    """The fallback of solve_pads when Newton from the warm start fails: per pad, a sign change of G_j is
    bracketed by steps doubling away from 0 (the silent motion's value) in the descent direction, then the
    root is found by Newton steps kept inside the bracket (bisection otherwise).  Needed where G_j is nearly
    a step (a pad near stick with regularised stick-slip, ``docs/simulation.md``): Newton overshoots there.
    The converged solutions of solve_pads are unchanged; only its failures are retried.
    """
    for j in range(_M):
        a = 0.0
        ga, da = _pad_value(y, l, dl, p, g, j, a, eng)
        if not abs(ga) < 1e300:
            return False
        if ga == 0.0:
            continue
        h = 1e-6 + ztol[j]
        sgn = -1.0 if ga * da > 0.0 else 1.0  # towards the root of a monotone G_j
        found = False
        b, gb = a, ga
        for _ in range(400):
            b = a + sgn * h
            gb, db = _pad_value(y, l, dl, p, g, j, b, eng)
            if not abs(gb) < 1e300:
                return False
            if (gb > 0.0) != (ga > 0.0) or gb == 0.0:
                found = True
                break
            a, ga = b, gb
            h *= 2.0
            if h > 1e30:
                break
        if not found:
            return False
        # now G_j(a) and G_j(b) differ in sign: Newton inside [lo, hi], bisection when it leaves
        lo, hi, glo = (a, b, ga) if a < b else (b, a, gb)
        z = b
        gz, dz = gb, db
        ok = False
        for _ in range(400):
            step_ok = abs(dz) > 0.0 and abs(gz / dz) < 1e300
            zn = z - gz / dz if step_ok else 0.5 * (lo + hi)
            if not (lo < zn < hi):
                zn = 0.5 * (lo + hi)
            if abs(zn - z) <= 1e-13 * abs(zn) + ztol[j] or hi - lo <= 2e-13 * abs(zn) + 2.0 * ztol[j]:
                z = zn
                ok = True
                break
            z = zn
            gz, dz = _pad_value(y, l, dl, p, g, j, z, eng)
            if not abs(gz) < 1e300:
                return False
            if gz == 0.0:
                ok = True
                break
            if (gz > 0.0) == (glo > 0.0):
                lo, glo = z, gz
            else:
                hi = z
        if not ok:
            return False
        if _KIND[j] == 0:
            l[j] = z
        else:
            dl[j] = z
    pad_balance_e(y, l, dl, p, eng, g)
    return True


@njit(cache=True, error_model="numpy")
def rhs(y, l, dl, p, ztol, g, mw, out):
    """out = dy/dt for y = (Q, Qdot, L_dyn); the pad unknowns l, dl are solved (and updated) on the way.

    Qddot solves M(Q) Qddot = -f (Gaussian elimination with partial pivoting); a failed pad solve or a
    singular mass matrix gives NaN (the step is rejected).
    """
    ok = solve_pads(y, l, dl, p, ztol, g)
    mass_force(y, l, dl, p, mw)
    _accelerations(y, dl, ok, mw, out)


@njit(cache=True, error_model="numpy")
def rhs_u(y, l, dl, p, ztol, g, mw, eng, D, out):
    """rhs with unilateral contact: the contact force of every pad with eng[j] == 0 (lifted off) removed.

    f = f0 + sum_j chi_j D_j (the generated ``release``); D: scratch of NPAD * N entries.
    """
    ok = solve_pads_e(y, l, dl, p, ztol, g, eng)
    mass_force(y, l, dl, p, mw)
    off = False
    for j in range(_NPAD):
        if eng[j] == 0:
            off = True
    if off:
        release(y, l, dl, p, D)
        for j in range(_NPAD):
            if eng[j] == 0:
                for i in range(_N):
                    mw[_N * _N + i] -= D[j * _N + i]
    _accelerations(y, dl, ok, mw, out)


@njit(cache=True, error_model="numpy")
def _accelerations(y, dl, ok, mw, out):
    """out = (Qdot, Qddot, Ldot_dyn) from M, f in mw (M Qddot = -f, partial pivoting); NaN if singular or not ok."""
    n = _N
    f0 = n * n
    for i in range(n):
        out[i] = y[n + i]
        mw[f0 + i] = -mw[f0 + i]
    for k in range(n):
        piv = k
        big = abs(mw[k * n + k])
        for i in range(k + 1, n):
            v = abs(mw[i * n + k])
            if v > big:
                big = v
                piv = i
        if not big > 0.0:
            ok = False
            break
        if piv != k:
            for j in range(k, n):
                tmp = mw[k * n + j]
                mw[k * n + j] = mw[piv * n + j]
                mw[piv * n + j] = tmp
            tmp = mw[f0 + k]
            mw[f0 + k] = mw[f0 + piv]
            mw[f0 + piv] = tmp
        inv = 1.0 / mw[k * n + k]
        for i in range(k + 1, n):
            fac = mw[i * n + k] * inv
            if fac != 0.0:
                for j in range(k + 1, n):
                    mw[i * n + j] -= fac * mw[k * n + j]
                mw[f0 + i] -= fac * mw[f0 + k]
    if ok:
        for i in range(n - 1, -1, -1):
            acc = mw[f0 + i]
            for j in range(i + 1, n):
                acc -= mw[i * n + j] * out[n + j]
            out[n + i] = acc / mw[i * n + i]
    for i in range(_NDYN):
        out[2 * n + i] = dl[_DYN[i]]
    if not ok:
        out[n] = math.nan


@njit(cache=True, error_model="numpy")
def event_values(y, l, dl, p, vr0, cb, out):
    """Per pad F_n (contact loss at <= 0), then per pad v_r . v_r0 (sliding reversal at <= 0); l, dl solved."""
    contact(y, l, dl, p, cb)
    for j in range(_NPAD):
        b = 7 * j
        out[j] = cb[b]
        out[_NPAD + j] = cb[b + 1] * vr0[3 * j] + cb[b + 2] * vr0[3 * j + 1] + cb[b + 3] * vr0[3 * j + 2]


@njit(cache=True, error_model="numpy")
def event_values_u(y, l, dl, p, vr0, cb, eng, out):
    """event_values with unilateral contact: a lifted pad's contact function is -F_n (re-contact at <= 0) and its
    sliding-reversal function is 1 (no friction)."""
    event_values(y, l, dl, p, vr0, cb, out)
    for j in range(_NPAD):
        if eng[j] == 0:
            out[j] = -out[j]
            out[_NPAD + j] = 1.0




@njit(cache=True, error_model="numpy")
def post_process(Y, count, l, dl, p, ztol, ENG, L_out, dL_out, C_out, E_out):
    """Pad unknowns, contact quantities and energy terms at the first ``count`` rows of Y (in place).

    l, dl: start values (the silent motion's), updated as warm starts from sample to sample; ENG[i]: the
    pads' engagement at row i (1 pressed, 0 lifted off).
    """
    g = np.empty(2 * _M + 1)
    cb = np.empty(7 * _NPAD)
    eb = np.empty(5)
    for i in range(count):
        y = Y[i]
        finite = True
        for j in range(_NY):
            if not abs(y[j]) < 1e300:
                finite = False
        if finite:
            finite = solve_pads_e(y, l, dl, p, ztol, g, ENG[i])
        if not finite:
            L_out[i, :] = math.nan
            dL_out[i, :] = math.nan
            C_out[i, :] = math.nan
            E_out[i, :] = math.nan
            continue
        for j in range(_M):
            L_out[i, j] = l[j]
            dL_out[i, j] = dl[j]
        contact(y, l, dl, p, cb)
        for k in range(7 * _NPAD):
            C_out[i, k] = cb[k]
        energy(y, l, dl, p, eb)
        for k in range(5):
            E_out[i, k] = eb[k]
