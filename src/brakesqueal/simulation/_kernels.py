r"""Compiled simulation kernels of any model: generated numba functions plus a static DOP853 template.

The equations of a model (:func:`~brakesqueal.symbolic.assemble.build_equations`,
``R(Q, Qdot, Qddot, L, Ldot) = 0`` and ``G(Q, Qdot, L, Ldot) = 0``) are turned
once into numba source by the package's one printer
(:func:`brakesqueal.codegen.printer.generate_module`, common subexpressions
eliminated):

* ``pad_balance_e(y, l, dl, p, e, out)`` — per pad unknown ``j``: ``G_j`` and its
  derivative with respect to the pad's unknown (``l_j`` of a quasi-static pad,
  ``ldot_j`` of a dynamic pad), with the pads' engagement ``e`` (1 pressed, 0
  lifted off: the balance without the friction force; the template's
  ``pad_balance(y, l, dl, p, out)`` is every pad pressed);
* ``mass_force(y, l, dl, p, out)`` — the mass matrix ``M(Q) = dR/dQddot``
  (``n x n``, row-major) and the forcing ``f = R(Qddot = 0)``, so that
  ``M Qddot + f = 0`` (``R`` is linear in ``Qddot``: checked when generating);
* ``contact(y, l, dl, p, out)`` — per pad the
  :data:`~brakesqueal.codegen.compiled.CONTACT_FIELDS` ``F_n, v_r (3), h, hdot, l``;
* ``pad_scale(y, l, dl, p, out)`` — per pad unknown the size of the terms of
  ``G_j`` (its rounding level divided by ``eps``: the Newton tolerance);
* ``energy(y, l, dl, p, out)`` — ``T2, T1, T0`` (kinetic energy by degree in the
  tilt rates, the spin constraint substituted) and the potentials
  ``V_support`` (disk and caliper springs) and ``V_pads`` (pad springs and preloads);

with ``y = (Q, Qdot)`` (the first ``2n`` entries of the integrator state), ``l``
and ``dl`` the pad deformations ``L`` and their rates, ``p``
(:meth:`Parameters.vector <brakesqueal.model.parameters.Parameters.vector>`).

**Pad treatment** (decided per pad from the model, :func:`pad_treatment`): a
massless pad with a finite tangential stiffness and rate-independent
(``coulomb``) friction is *quasi-static*: ``ldot := 0`` is substituted in all
its expressions and ``l`` solves ``G(Q, Qdot, l, 0) = 0``.  With rate-dependent
friction (``linear``, ``stribeck``, ``stick``) or a tangential damper ``d_ip`` it is *dynamic*: ``l`` is a state and
``ldot`` solves ``G(Q, Qdot, l, ldot) = 0``.  Each pad's ``G_j`` depends on its
own unknown only (checked), so both are scalar Newton iterations per pad,
warm-started from the previous value.

A static template (:data:`_TEMPLATE`) adds the pad solve, the right-hand side
(Gaussian elimination with partial pivoting for ``M Qddot = -f``), the event
functions (contact loss ``F_n <= 0`` and sliding reversal ``v_r . v_r0 <= 0`` for
every pad), post-processing and a Dormand–Prince 8(5,3) integrator (SciPy's
DOP853 coefficients, error norm, step-size control and 7th-order dense output,
ported to numba) that runs for a bounded number of steps per call and keeps its
whole state in arrays, so a run split into calls is bitwise the same as one call.
No compiled function returns an array: boxing an array calls back into the
interpreter (numba's ``_numba_unpickle``), where a pending ``KeyboardInterrupt``
would surface inside compiled code (issue 11).

The module is cached per model (:func:`brakesqueal.codegen.cache.load_module`,
entry ``model-<hash>/simulate.py``) and numba caches its machine code beside it.
"""

from __future__ import annotations

import math
import types
from typing import Any

from ..codegen import cache

__all__ = ["KERNEL_NAME", "PAD_KINDS", "pad_treatment", "kernel_source", "load_kernels"]

#: File name of the kernel module in the model's cache entry.
KERNEL_NAME = "simulate.py"
#: Treatments of a massless pad's tangential deformation (see the module docstring).
PAD_KINDS = ("quasi-static", "dynamic")


def pad_treatment(spec: Any) -> tuple[str, ...]:
    """Treatment of every pad deformation ``L`` of a model (``"quasi-static"`` or ``"dynamic"``).

    Parameters
    ----------
    spec : ModelSpec
        The model.

    Returns
    -------
    tuple of str
        One entry per massless pad with a finite tangential stiffness (the
        order of ``Equations.algebraic``): ``"quasi-static"`` for
        rate-independent (``coulomb``) friction without a tangential damper,
        ``"dynamic"`` for rate-dependent friction (``linear``, ``stribeck``,
        ``stick``) or a tangential damper ``d_ip`` (a parameter name or a
        nonzero number).  Decided from the model, never from parameter values.
    """
    return tuple(t for t in (pad.treatment for pad in spec.pads) if t is not None)


def _value(se: Any, eq: Any, v: Any) -> Any:
    """Symbolic value of a component field (parameter name, number; stiffnesses through their compliance)."""
    if v is None:
        return se.Integer(0)
    if isinstance(v, str):
        names = list(eq.spec.parameters)
        sym = eq.params[names.index(v)]
        return 1 / sym if v in eq.spec.stiffness_names() else sym
    return se.Integer(int(v)) if float(v).is_integer() else se.sympify(float(v))


def _state_name(prefix: str, component: str) -> str:
    return f"{prefix}{component}" if component.isdigit() else f"{prefix}_{component}"


def _check_free(what: str, expr: Any, forbidden: set[Any]) -> None:
    bad = set(expr.free_symbols) & forbidden
    if bad:
        raise ValueError(f"cannot generate simulation kernels: {what} depends on {sorted(map(str, bad))}")


def _expressions(spec: Any) -> dict[str, Any]:
    """Symbolic outputs of the generated functions and the metadata of the module."""
    import symengine as se

    from ..symbolic.assemble import build_equations

    eq = build_equations(spec)
    n, m = eq.n, eq.m
    kinds = pad_treatment(spec)
    if len(kinds) != m:
        raise AssertionError("pad treatment does not match the pad deformations of the equations")
    quasi = {eq.dL[j]: 0 for j in range(m) if kinds[j] == "quasi-static"}

    def qs(e: Any) -> Any:
        return se.sympify(e).subs(quasi) if quasi else se.sympify(e)

    ddQ = set(eq.ddQ)
    # mass matrix and forcing: R = M(Q) Qddot + f(Q, Qdot, L, Ldot), R linear in Qddot
    R = [qs(eq.R[i]) for i in range(n)]
    Mx, f = [], []
    zero_dd = {s: 0 for s in eq.ddQ}
    for i in range(n):
        for j in range(n):
            e = R[i].diff(eq.ddQ[j])
            _check_free(f"dR/dQddot[{i}, {j}]", e, ddQ)  # R is linear in Qddot
            Mx.append(e)
        f.append(R[i].subs(zero_dd))
    # unilateral contact: the engagement chi_j (1 pressed, 0 lifted) factors pad j's contact force f_p
    chi = [se.Symbol(f"chi__{j}") for j in range(len(spec.pads))]
    eq_u = build_equations(spec, engagement={pad.name: c for pad, c in zip(spec.pads, chi)})
    # pad balances with the engagement (a lifted pad's G_j has no friction term): each G_j depends on its own
    # unknown only
    bal, dbal = [], []
    for j in range(m):
        g = qs(eq_u.G[j])
        others = {eq.L[k] for k in range(m) if k != j} | {eq.dL[k] for k in range(m) if k != j}
        _check_free(f"G[{j}]", g, others | ddQ)
        bal.append(g)
        dbal.append(g.diff(eq.L[j] if kinds[j] == "quasi-static" else eq.dL[j]))
    scale = [qs(e) for e in _pad_scales(se, eq)]
    contact: list[Any] = []
    for c, l in zip(eq.pads, eq.tangential):
        contact += [qs(c.F_n), qs(c.v_r[0]), qs(c.v_r[1]), qs(c.v_r[2]), qs(c.h), qs(c.hdot), qs(l)]
    energy = _energy(se, eq)
    # unilateral contact: R = R(chi = 0) + sum_j chi_j D_j
    release = []
    for j in range(len(spec.pads)):
        for i in range(n):
            r = qs(eq_u.R[i])
            e = r.diff(chi[j]) if chi[j] in r.free_symbols else se.Integer(0)
            _check_free(f"dR[{i}]/dchi[{j}]", e, ddQ | set(chi))  # the contact force is linear in chi, free of Qddot
            release.append(e)
    return {"eq": eq, "chi": chi, "kinds": kinds, "mass_force": Mx + f, "pad_balance": bal + dbal, "contact": contact,
            "energy": [qs(e) for e in energy], "pad_scale": scale, "release": release}


def _pad_scales(se: Any, eq: Any) -> list[Any]:
    """Per pad unknown, the size of the terms of ``G_j = (l - u_m) + c (f_t + mu* N0)`` (its rounding level / eps)."""
    from ..symbolic.contact import angle_cos_sin

    spec = eq.spec
    Q = dict(zip(eq.coords, eq.Q))
    cal = {c.name: c for c in spec.calipers}
    out = []
    for pad, c, l in zip(spec.pads, eq.pads, eq.tangential):
        rigid = not isinstance(pad.k_ip, str) and math.isinf(pad.k_ip)
        if "tangential" in pad.dofs or rigid:
            continue
        comp = 1 / _value(se, eq, pad.k_ip)  # the compliance (symbol, or 1/number)
        mount = cal.get(pad.mount) if pad.mount else None
        ca = angle_cos_sin(se, pad.angle_deg)[0]
        u_m = Q[_state_name("uc", mount.name)] * ca if mount and "tangential" in mount.dofs else se.Integer(0)
        out.append(abs(l) + abs(u_m) + abs(comp * c.f_t) + abs(comp * c.mu_star * _value(se, eq, pad.preload)))
    return out


def _energy(se: Any, eq: Any) -> list[Any]:
    """``T2, T1, T0, V_support, V_pads``: the sum of the components' ``energy`` hooks (``docs/simulation.md``, energy).

    ``se`` is the backend of ``eq`` (kept for the callers' symmetry with the other builders).
    """
    from ..symbolic.assemble import ENERGY_TERMS, energy_terms

    terms = energy_terms(eq)
    return [terms[k] for k in ENERGY_TERMS]


_PREAMBLE = '''import math
from math import sin, cos, tan, sqrt, exp, log, pi

import numpy as np
from numba import njit

_N = {n}  # coordinates Q
_M = {m}  # pad deformations L
_NPAD = {npad}  # pads
_NDYN = {ndyn}  # pad deformations that are states (rate-dependent friction or a tangential damper)
_NY = {ny}  # integrator state (Q, Qdot, L_dynamic)
_NEV = {nev}  # event functions: contact loss and sliding reversal of every pad
_KIND = np.array({kind}, dtype=np.int64)  # per L: 0 quasi-static (unknown l, ldot = 0), 1 dynamic (unknown ldot)
_DYN = np.array({dyn}, dtype=np.int64)  # index into L of the i-th state y[2 N + i]
_PRESSED = np.ones(max(_NPAD, 1), dtype=np.int64)  # engagement of every pad in bilateral contact
'''

_DECORATOR = '@njit(cache=True, error_model="numpy")'

# The static part of the kernel module: pad solve, RHS, events, post-processing, DOP853 with dense output.
_TEMPLATE = r'''

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
def dense_eval(F, y_old, x, out):
    """SciPy's Dop853DenseOutput at normalized time x in [0, 1]."""
    n = y_old.shape[0]
    nf = F.shape[0]
    for j in range(n):
        acc = 0.0
        for k in range(nf):
            acc += F[nf - 1 - k, j]
            if k % 2 == 0:
                acc *= x
            else:
                acc *= 1.0 - x
        out[j] = acc + y_old[j]


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


@njit(cache=True, error_model="numpy")
def _error_norm(K, E5, E3, h, scale):
    n = scale.shape[0]
    e5 = 0.0
    e3 = 0.0
    for j in range(n):
        a = 0.0
        b = 0.0
        for s in range(K.shape[0]):
            a += K[s, j] * E5[s]
            b += K[s, j] * E3[s]
        e5 += (a / scale[j]) ** 2
        e3 += (b / scale[j]) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * n)


@njit(cache=True, error_model="numpy")
def _event_at(k, x, F, y, l, dl, p, ztol, vr0, g, cb, ev, yint, eng):
    """Event function k at normalized time x of the step (pad unknowns solved from l, dl, updated)."""
    dense_eval(F, y, x, yint)
    solve_pads_e(yint, l, dl, p, ztol, g, eng)
    event_values_u(yint, l, dl, p, vr0, cb, eng, ev)
    return ev[k]


@njit(cache=True, error_model="numpy")
def _bisect(k, a, b, F, y, l0, dl0, p, ztol, vr0, g, cb, ev, yint, lb, dlb, eng):
    """First x in [a, b] with event k <= 0, given event k > 0 at a and <= 0 at b (60 halvings; returns the <= 0 end)."""
    lb[:] = l0
    dlb[:] = dl0
    for _ in range(60):
        c = 0.5 * (a + b)
        if _event_at(k, c, F, y, lb, dlb, p, ztol, vr0, g, cb, ev, yint, eng) > 0.0:
            a = c
        else:
            b = c
    return b


@njit(cache=True, error_model="numpy")
def _golden(k, a, b, F, y, l0, dl0, p, ztol, vr0, g, cb, ev, yint, lb, dlb, eng):
    """Minimum of event k on [a, b] (48 golden-section steps): returns (x, value); stops early at a value <= 0."""
    lb[:] = l0
    dlb[:] = dl0
    r = 0.6180339887498949
    c = b - r * (b - a)
    d = a + r * (b - a)
    fc = _event_at(k, c, F, y, lb, dlb, p, ztol, vr0, g, cb, ev, yint, eng)
    fd = _event_at(k, d, F, y, lb, dlb, p, ztol, vr0, g, cb, ev, yint, eng)
    for _ in range(48):
        if fc <= 0.0:
            return c, fc
        if fd <= 0.0:
            return d, fd
        if fc < fd:
            b = d
            d = c
            fd = fc
            c = b - r * (b - a)
            fc = _event_at(k, c, F, y, lb, dlb, p, ztol, vr0, g, cb, ev, yint, eng)
        else:
            a = c
            c = d
            fc = fd
            d = a + r * (b - a)
            fd = _event_at(k, d, F, y, lb, dlb, p, ztol, vr0, g, cb, ev, yint, eng)
    if fc < fd:
        return c, fc
    return d, fd


@njit(cache=True, error_model="numpy")
def dop853(y, f, l, dl, ev_old, ev_prev, p, ztol, vr0, t, t1, h_abs, rtol, atol, max_step, t_out, i_out, Y, te0, dte,
           i_est, Yest, event_mode, ev_t, ev_k, n_ev, budget, stats, y_event, eng, A, B, C, E3, E5, D):
    """Adaptive DOP853 from t towards t1 (SciPy's algorithm), at most ``budget`` accepted steps per call.

    Integrator state, updated in place: y (state), f (its derivative), l, dl (pad unknowns, solved at y),
    ev_old (event values at y), ev_prev (at the previous step's last inner point; inf at the start); stats
    (int64) accumulates nfev, accepted steps, rejected steps.  Events: sign changes between NSUB + 1 points
    per step are bisected; a sampled minimum within twice the second difference of zero (a grazing dip) is
    located by golden-section search and, if it is <= 0, the crossing before it is bisected.
    Dense output at t_out[i_out:] goes into Y; at te0 + i dte (i = i_est, ...) into the ring buffer Yest
    (row i % Yest.shape[0]).  event_mode: 0 = none, 1 = stop at the first event, 2 = record and continue,
    3 = unilateral contact (eng[j] = 1 pressed, 0 lifted; a contact event ends the step there and switches the
    pad: recorded as k = j for a lift-off, 2 NPAD + j for a re-contact), sliding reversals recorded, 4 = the same
    but stop at a sliding reversal, 5 = stop at the first contact loss, record sliding reversals (pads with
    regularised stick-slip, for which a reversal is ordinary motion).
    Returns (status, t, h_abs, i_out, i_est, n_ev, k_event, t_event): status 0 = reached t1,
    1 = stopped at an event (state in y_event), 2 = budget used or event buffer full (call again to continue),
    -1 = step size too small, -2 = non-finite state or pad equations unsolvable, -4 = a pad switched twice
    within 10 minimal steps (chattering contact).
    """
    n = y.shape[0]
    SAFETY = 0.9
    MIN_FACTOR = 0.2
    MAX_FACTOR = 10.0
    expo = -1.0 / 8.0
    NSUB = 4
    K = np.zeros((16, n))
    F = np.zeros((7, n))
    ynew = np.empty(n)
    fnew = np.empty(n)
    ystage = np.empty(n)
    scale = np.empty(n)
    yint = np.empty(n)
    g = np.empty(2 * _M + 1)
    mw = np.empty(_N * _N + _N)
    cb = np.empty(7 * _NPAD)
    ev_new = np.empty(_NEV)
    ev_mid = np.empty(_NEV)
    evs = np.empty((NSUB + 1, _NEV))
    Ls = np.empty((NSUB + 1, _M))
    dLs = np.empty((NSUB + 1, _M))
    lnew = l.copy()
    dlnew = dl.copy()
    lsave = l.copy()
    dlsave = dl.copy()
    lint = l.copy()
    dlint = dl.copy()
    lb = l.copy()
    dlb = dl.copy()
    Dw = np.empty(_NPAD * _N + 1)
    t_switch = np.full(_NPAD, -math.inf)
    slide_t = np.empty(_NPAD)
    k_event = -1
    t_event = math.nan
    steps = 0
    while t < t1:
        if steps >= budget or ((event_mode == 3 or event_mode == 4) and n_ev + 2 * _NPAD + 2 > ev_t.shape[0]):
            return (2, t, h_abs, i_out, i_est, n_ev, k_event, t_event)
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        if h_abs > max_step:
            h_abs = max_step
        if h_abs < min_step:
            h_abs = min_step
        rejected = False
        while True:
            if h_abs < min_step:
                return (-1, t, h_abs, i_out, i_est, n_ev, k_event, t_event)
            t_new = t + h_abs
            if t_new > t1:
                t_new = t1
            h = t_new - t
            h_abs = abs(h)
            lnew[:] = l
            dlnew[:] = dl
            for j in range(n):
                K[0, j] = f[j]
            for s in range(1, 12):
                for j in range(n):
                    acc = 0.0
                    for q in range(s):
                        acc += K[q, j] * A[s, q]
                    ystage[j] = y[j] + h * acc
                rhs_u(ystage, lnew, dlnew, p, ztol, g, mw, eng, Dw, K[s])
            for j in range(n):
                acc = 0.0
                for q in range(12):
                    acc += K[q, j] * B[q]
                ynew[j] = y[j] + h * acc
            rhs_u(ynew, lnew, dlnew, p, ztol, g, mw, eng, Dw, fnew)
            stats[0] += 12
            for j in range(n):
                K[12, j] = fnew[j]
            finite = True
            for j in range(n):
                if not (abs(ynew[j]) < 1e300 and abs(fnew[j]) < 1e300):
                    finite = False
            if finite:
                for j in range(n):
                    scale[j] = atol[j] + max(abs(y[j]), abs(ynew[j])) * rtol
                err = _error_norm(K[:13], E5, E3, h, scale)
            else:
                err = 1e10
            if err < 1.0:
                if err == 0.0:
                    factor = MAX_FACTOR
                else:
                    factor = min(MAX_FACTOR, SAFETY * err ** expo)
                if rejected:
                    factor = min(1.0, factor)
                h_abs *= factor
                break
            if not finite and h_abs <= 1e3 * min_step:
                return (-2, t, h_abs, i_out, i_est, n_ev, k_event, t_event)
            h_abs *= max(MIN_FACTOR, SAFETY * err ** expo)
            rejected = True
            stats[2] += 1
        steps += 1
        stats[1] += 1
        lsave[:] = lnew  # pad unknowns solved at ynew
        dlsave[:] = dlnew
        # dense output of this step (3 extra stages)
        need_dense = (i_out < t_out.shape[0] and t_out[i_out] <= t_new) or event_mode > 0 \
            or te0 + i_est * dte <= t_new
        if need_dense:
            for s in range(13, 16):
                for j in range(n):
                    acc = 0.0
                    for q in range(s):
                        acc += K[q, j] * A[s, q]
                    ystage[j] = y[j] + h * acc
                rhs_u(ystage, lnew, dlnew, p, ztol, g, mw, eng, Dw, K[s])
            stats[0] += 3
            for j in range(n):
                dy = ynew[j] - y[j]
                F[0, j] = dy
                F[1, j] = h * f[j] - dy
                F[2, j] = 2.0 * dy - h * (fnew[j] + f[j])
                for r in range(4):
                    acc = 0.0
                    for q in range(16):
                        acc += D[r, q] * K[q, j]
                    F[3 + r, j] = h * acc
        t_stop = t_new
        stop = False
        switch = -1
        if event_mode > 0:
            # event values at NSUB + 1 points of the step (dense output; the end with the saved pad unknowns)
            for k in range(_NEV):
                evs[0, k] = ev_old[k]
            Ls[0, :] = l
            dLs[0, :] = dl
            lint[:] = l
            dlint[:] = dl
            for sub in range(1, NSUB + 1):
                if sub == NSUB:
                    event_values_u(ynew, lsave, dlsave, p, vr0, cb, eng, ev_new)
                    Ls[sub, :] = lsave
                    dLs[sub, :] = dlsave
                else:
                    dense_eval(F, y, sub / NSUB, yint)
                    solve_pads_e(yint, lint, dlint, p, ztol, g, eng)
                    event_values_u(yint, lint, dlint, p, vr0, cb, eng, ev_new)
                    Ls[sub, :] = lint
                    dLs[sub, :] = dlint
                for k in range(_NEV):
                    evs[sub, k] = ev_new[k]
            first = -1
            tf = t_new
            for k in range(_NPAD):
                slide_t[k] = math.nan
            for k in range(_NEV):
                # in time order: a sign change between two points (bisected), or a sampled minimum close to zero
                # (a grazing dip: the minimum is located by golden-section search, and a crossing before it bisected)
                i = 0
                while i <= NSUB:
                    xc = -1.0
                    nxt = i + 1
                    if i >= 1 and evs[i - 1, k] > 0.0 and evs[i, k] <= 0.0:
                        xc = _bisect(k, (i - 1) / NSUB, i / NSUB, F, y, Ls[i - 1], dLs[i - 1], p, ztol, vr0, g, cb,
                                     ev_mid, yint, lb, dlb, eng)
                    elif evs[i, k] > 0.0:
                        left = evs[i - 1, k] if i >= 1 else ev_prev[k]
                        right = evs[i + 1, k] if i < NSUB else math.inf
                        if left > evs[i, k] and right >= evs[i, k]:
                            c = min(max(i, 1), NSUB - 1)
                            trig = 2.0 * abs(evs[c - 1, k] - 2.0 * evs[c, k] + evs[c + 1, k])
                            if evs[i, k] <= trig:
                                lo = max(i - 1, 0)
                                hi = min(i + 1, NSUB)
                                xm, vm = _golden(k, lo / NSUB, hi / NSUB, F, y, Ls[i], dLs[i], p, ztol, vr0, g, cb,
                                                 ev_mid, yint, lb, dlb, eng)
                                if vm <= 0.0:
                                    xc = _bisect(k, lo / NSUB, xm, F, y, Ls[lo], dLs[lo], p, ztol, vr0, g, cb,
                                                 ev_mid, yint, lb, dlb, eng)
                                    nxt = hi + 1
                    if xc >= 0.0:
                        tk = t + xc * h
                        if event_mode == 3 and k >= _NPAD:
                            slide_t[k - _NPAD] = tk  # recorded below if before a contact switch
                            break
                        if event_mode == 2 or (event_mode == 5 and k >= _NPAD):
                            if n_ev < ev_t.shape[0]:
                                ev_t[n_ev] = tk
                                ev_k[n_ev] = k
                            n_ev += 1
                        else:
                            if first < 0 or tk < tf:
                                first = k
                                tf = tk
                                dense_eval(F, y, xc, y_event)
                            break
                    i = nxt
            if (event_mode == 1 or event_mode == 5) and first >= 0:
                stop = True
                t_stop = tf
                k_event = first
                t_event = tf
            if event_mode == 3 or event_mode == 4:
                for k in range(_NPAD):
                    if slide_t[k] == slide_t[k] and slide_t[k] <= tf:
                        ev_t[n_ev] = slide_t[k]
                        ev_k[n_ev] = _NPAD + k
                        n_ev += 1
                if first >= _NPAD:  # a sliding reversal (event_mode 4): stop
                    stop = True
                    t_stop = tf
                    k_event = first
                    t_event = tf
                elif first >= 0:  # lift-off or re-contact of pad `first`: end the step there and switch
                    if tf - t_switch[first] <= 10.0 * min_step:
                        return (-4, tf, h_abs, i_out, i_est, n_ev, first, tf)
                    t_switch[first] = tf
                    switch = first
                    t_stop = tf
                    ev_t[n_ev] = tf
                    ev_k[n_ev] = first if eng[first] == 1 else 2 * _NPAD + first
                    n_ev += 1
            for k in range(_NEV):
                ev_prev[k] = evs[NSUB - 1, k]
                ev_old[k] = evs[NSUB, k]
        while i_out < t_out.shape[0] and t_out[i_out] <= t_stop:
            x = (t_out[i_out] - t) / h
            dense_eval(F, y, x, yint)
            for j in range(n):
                Y[i_out, j] = yint[j]
            i_out += 1
        nbuf = Yest.shape[0]
        while te0 + i_est * dte <= t_stop:
            x = (te0 + i_est * dte - t) / h
            dense_eval(F, y, x, yint)
            r = i_est % nbuf
            for j in range(n):
                Yest[r, j] = yint[j]
            i_est += 1
        if switch >= 0:
            # continue from the switching point in the other contact state (the step beyond it is discarded)
            t = t_stop
            eng[switch] = 1 - eng[switch]
            for j in range(n):
                y[j] = y_event[j]
            rhs_u(y, l, dl, p, ztol, g, mw, eng, Dw, f)
            stats[0] += 1
            event_values_u(y, l, dl, p, vr0, cb, eng, ev_old)
            for k in range(_NEV):
                ev_prev[k] = ev_old[k]  # no grazing test at the switching point itself
            continue
        t = t_new
        for j in range(n):
            y[j] = ynew[j]
            f[j] = fnew[j]
        l[:] = lsave
        dl[:] = dlsave
        if stop:
            return (1, t, h_abs, i_out, i_est, n_ev, k_event, t_event)
    return (0, t, h_abs, i_out, i_est, n_ev, k_event, t_event)
'''


def kernel_source(spec: Any) -> str:
    """Complete source of a model's kernel module (generated functions + template).

    Parameters
    ----------
    spec : ModelSpec
        The model.

    Returns
    -------
    str
        Python source (numba).

    Raises
    ------
    ValueError
        If the equations do not have the structure the integrator relies on
        (``R`` linear in ``Qddot``, each pad balance depending on its own
        unknown only).
    """
    from ..codegen.printer import FunctionSpec, generate_module

    ex = _expressions(spec)
    eq = ex["eq"]
    n, m, npad = eq.n, eq.m, len(spec.pads)
    kinds = ex["kinds"]
    dyn = [j for j in range(m) if kinds[j] == "dynamic"]
    meta = {"model": spec.name, "coords": list(eq.coords), "algebraic": list(eq.algebraic), "kinds": list(kinds),
            "pads": [p.name for p in spec.pads], "params": list(eq.param_names), "tilting": bool(spec.disk.tilting)}
    preamble = _PREAMBLE.format(n=n, m=m, npad=npad, ndyn=len(dyn), ny=2 * n + len(dyn), nev=2 * npad,
                                kind=[0 if k == "quasi-static" else 1 for k in kinds], dyn=dyn)
    y = ("y_", [*eq.Q, *eq.dQ])
    ll, dl, pp = ("l_", eq.L), ("dl_", eq.dL), ("p_", eq.params)
    args = (y, ll, dl, pp)
    specs = [
        FunctionSpec("pad_balance_e", (y, ll, dl, pp, ("e_", ex["chi"])), ex["pad_balance"],
                     "G_j, then dG_j/dz_j (z_j = l_j quasi-static, ldot_j dynamic), eqs. (33)-(34) generalized; "
                     "e: per pad 1 pressed, 0 lifted off (no friction on the pad)."),
        FunctionSpec("mass_force", args, ex["mass_force"],
                     "M = dR/dQddot (n x n, row-major), then f = R(Qddot = 0): M Qddot + f = 0 (eq. 44 generalized)."),
        FunctionSpec("contact", args, ex["contact"],
                     "Per pad: F_n [N], v_r (3) [m/s], h [m], hdot [m/s], l [m] (eqs. 12-34)."),
        FunctionSpec("energy", args, ex["energy"], "T2, T1, T0, V_support, V_pads [J]."),
        FunctionSpec("release", args, ex["release"],
                     "Per pad j, the part D_j of the forcing f due to its contact force f_p (n entries): f = f0 + "
                     "sum_j chi_j D_j; a lifted pad (chi_j = 0) is removed by f - D_j."),
        FunctionSpec("pad_scale", args, ex["pad_scale"],
                     "Per pad unknown: |l| + |u_m| + |c f_t| + |c mu* N0|, the size of the terms of G_j [m]."),
    ]
    header = (f"Generated by brakesqueal.simulation for the equations of model {spec.name!r}. Do not edit.\n\n"
              f"y = ({', '.join(str(s) for s in y[1])}, <dynamic pad deformations>)\n"
              f"l = ({', '.join(map(str, eq.L))}); dl = their rates; pad treatment {list(kinds)}\n"
              f"p = ({', '.join(eq.param_names)})")
    src = generate_module(specs, header, decorator=_DECORATOR, unpack="index", out="out_", preamble=preamble)
    return src + _TEMPLATE + f"\nMETA = {meta!r}\n"


def load_kernels(spec: Any, use_cache: bool = True) -> types.ModuleType:
    """Import a model's kernel module, generating and caching it on first use.

    Parameters
    ----------
    spec : ModelSpec
        The model.
    use_cache : bool, optional
        Keep the source in the package cache (entry ``model-<hash>``, file
        :data:`KERNEL_NAME`), where numba also caches its machine code
        (default ``True``); ``False`` generates and compiles in memory and
        writes no file.

    Returns
    -------
    module
        The numba functions ``rhs``, ``solve_pads``, ``event_values``,
        ``contact``, ``energy``, ``post_process``, ``dop853`` and ``META``.
    """
    from ..codegen.compiled import model_key

    return cache.load_module(model_key(spec), KERNEL_NAME, lambda: kernel_source(spec), use_cache=use_cache)


#: File name of the variational (exact Jacobian) kernel module in the model's cache entry.
VARIATIONAL_NAME = "variational.py"

# The static part of the variational module: the vector field, its exact Jacobian and its parameter derivative
# as numba functions with the fixed signatures of brakesqueal.nonlinear.compiled (compiled when imported).
_VARIATIONAL_TEMPLATE = r'''

from numba import types as _nbt

_FSIG = _nbt.void(_nbt.float64[::1], _nbt.float64, _nbt.float64[::1], _nbt.float64[::1])
_JSIG = _nbt.void(_nbt.float64[::1], _nbt.float64, _nbt.float64[::1], _nbt.float64[:, ::1])
_P = {P}  # model parameters
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
'''


def variational_source(spec: Any) -> str:
    """Source of a model's variational module: :func:`kernel_source` plus the exact Jacobian, compiled.

    Adds the generated ``rg_jacobian(y, l, dl, a, p, out)`` (``d(R, G)/d(Q, Qdot, Qddot, L, Ldot)`` at
    ``Qddot = a``, ``(n + m) x (3n + 2m)`` row-major, quasi-static pads' ``Ldot = 0`` substituted after
    differentiating) and ``rg_param_jacobian`` (``d(R, G)/dp``, ``(n + m) x P``) and the numba functions
    ``nl_f``, ``nl_jac``, ``nl_dfdp`` with the signatures of :mod:`brakesqueal.nonlinear.compiled`:
    the vector field ``y' = f(y)`` of the simulation, its exact Jacobian by implicit differentiation of
    ``(R, G) = 0`` for ``z = (Qddot, L_quasi-static, Ldot_dynamic)`` (``f_y`` = ``[0 I 0; -Phi_z^-1 Phi_y]``,
    the same as :func:`~brakesqueal.simulation.state_jacobian`) and ``f_p dp/ds``.  ``theta`` is
    ``(p, dp/ds, ztol, l, dl)`` (:func:`variational_theta`).

    Parameters
    ----------
    spec : ModelSpec
        The model.

    Returns
    -------
    str
        Python source (numba).
    """
    import symengine as se

    from ..codegen.printer import FunctionSpec, generate_module

    ex = _expressions(spec)
    eq = ex["eq"]
    n, m = eq.n, eq.m
    kinds = ex["kinds"]
    quasi = {eq.dL[j]: 0 for j in range(m) if kinds[j] == "quasi-static"}
    phi = [se.sympify(e) for e in (*eq.R[:n], *(eq.G[:m] if m else []))]
    xs = [*eq.Q, *eq.dQ, *eq.ddQ, *eq.L, *eq.dL]

    def sub(e: Any) -> Any:
        return e.subs(quasi) if quasi else e

    jx = [sub(r.diff(x)) for r in phi for x in xs]
    jp = [sub(r.diff(q)) for r in phi for q in eq.params]
    args = (("y_", [*eq.Q, *eq.dQ]), ("l_", eq.L), ("dl_", eq.dL), ("a_", eq.ddQ), ("p_", eq.params))
    specs = [
        FunctionSpec("rg_jacobian", args, jx, "d(R, G)/d(Q, Qdot, Qddot, L, Ldot), (n + m) x (3n + 2m) row-major."),
        FunctionSpec("rg_param_jacobian", args, jp, "d(R, G)/dp, (n + m) x P row-major."),
    ]
    extra = generate_module(specs, f"Exact Jacobians of the equations of model {spec.name!r}.",
                            decorator=_DECORATOR, unpack="index", out="out_")
    return kernel_source(spec) + "\n\n" + extra + _VARIATIONAL_TEMPLATE.replace("{P}", str(len(eq.params)))


def load_variational(spec: Any, use_cache: bool = True) -> types.ModuleType:
    """Import a model's variational module (:func:`variational_source`), generating and caching it on first use.

    Parameters
    ----------
    spec : ModelSpec
        The model.
    use_cache : bool, optional
        As in :func:`load_kernels` (entry file :data:`VARIATIONAL_NAME`).

    Returns
    -------
    module
        With ``nl_f``, ``nl_jac``, ``nl_dfdp`` (and everything of :func:`load_kernels`).
    """
    from ..codegen.compiled import model_key

    return cache.load_module(model_key(spec), VARIATIONAL_NAME, lambda: variational_source(spec),
                             use_cache=use_cache)
