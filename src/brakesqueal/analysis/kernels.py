r"""Exact stability criteria of 2-DOF models, generated from the closed forms and compiled.

The characteristic polynomial of eq. (47) for a 2-DOF model is the quartic

.. math:: \det(\lambda^2 \bar M + \lambda \bar D + \bar K)
          = a_4 \lambda^4 + a_3 \lambda^3 + a_2 \lambda^2 + a_1 \lambda + a_0 .

With ``a4 > 0`` all roots have negative real parts iff (Liénard–Chipart)
``a0, a1, a2, a3 > 0`` and ``H3 = a3 a2 a1 - a4 a1^2 - a3^2 a0 > 0``; on the
boundary of the stable set either ``a0 = 0`` (a real root at 0) or ``H3 = 0``
(a pair ``±iω``).  The criterion is invariant under multiplying all ``ai``
by one positive number, and under ``λ -> σλ`` (``ai -> ai σ^i``), which the
kernels use to keep numbers of order one.

Three generated / compiled pieces live here:

* :func:`map_kernel` — for two axes of a :class:`~.space.ParameterSpace`,
  the closed form (``closed_form("general")``, trivial silent motion) is
  specialised symbolically, the quartic's coefficients (times their common
  positive denominator) become polynomials in the *inner* axis whose
  coefficients depend on the *outer* axis only; the outer part is evaluated
  once per row with NumPy, the inner loop is a few fused multiply-adds and
  the Hurwitz inequalities, compiled with numba.
* :func:`omega_coefficients` / :func:`critical_speeds_batch` — ``Mbar, Dbar,
  Kbar`` are Laurent polynomials in Ω (gyroscopic ``ΦΩ``, friction damping
  ``∝ 1/Ω``), so ``Ω^6 H3`` is a polynomial in Ω; its real roots are isolated
  exactly (derivative cascade + safeguarded Newton) in compiled code.
* :func:`path_polynomials` — the same for one arbitrary axis (``crossings``).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Callable

import numpy as np

from .space import VECTOR_NAMES, ParameterSpace

__all__ = [
    "quartic_coefficients", "hurwitz_h3", "hurwitz_stable", "MapKernel", "map_kernel",
    "real_roots", "omega_coefficients", "critical_speeds_batch", "path_polynomials",
]


# ---------------------------------------------------------------- generic formulas
def quartic_coefficients(M: Any, D: Any, K: Any) -> tuple[Any, Any, Any, Any, Any]:
    """``(a0, a1, a2, a3, a4)`` of ``det(λ²M + λD + K)`` for 2×2 matrices (last two axes).

    Works for NumPy arrays of shape ``(..., 2, 2)`` and SymPy matrices.
    """
    def e(X: Any, i: int, j: int) -> Any:
        return X[i, j] if hasattr(X, "shape") and len(getattr(X, "shape", ())) == 2 else X[..., i, j]

    m11, m12, m21, m22 = e(M, 0, 0), e(M, 0, 1), e(M, 1, 0), e(M, 1, 1)
    d11, d12, d21, d22 = e(D, 0, 0), e(D, 0, 1), e(D, 1, 0), e(D, 1, 1)
    k11, k12, k21, k22 = e(K, 0, 0), e(K, 0, 1), e(K, 1, 0), e(K, 1, 1)
    a4 = m11 * m22 - m12 * m21
    a3 = m11 * d22 + d11 * m22 - m12 * d21 - d12 * m21
    a2 = m11 * k22 + d11 * d22 + k11 * m22 - m12 * k21 - d12 * d21 - k12 * m21
    a1 = d11 * k22 + k11 * d22 - d12 * k21 - k12 * d21
    a0 = k11 * k22 - k12 * k21
    return a0, a1, a2, a3, a4


def hurwitz_h3(a0: Any, a1: Any, a2: Any, a3: Any, a4: Any) -> Any:
    """Third Hurwitz determinant ``a3 a2 a1 - a4 a1² - a3² a0`` of the quartic."""
    return a1 * (a3 * a2 - a4 * a1) - a3 * a3 * a0


def hurwitz_stable(a0: Any, a1: Any, a2: Any, a3: Any, a4: Any) -> Any:
    """Liénard–Chipart verdict (bool array): all roots of the quartic in the open left half-plane."""
    s = np.sign(a4)
    a0, a1, a2, a3, a4 = (np.asarray(a) * s for a in (a0, a1, a2, a3, a4))
    return (a0 > 0) & (a1 > 0) & (a2 > 0) & (a3 > 0) & (a4 > 0) & (hurwitz_h3(a0, a1, a2, a3, a4) > 0)


# ---------------------------------------------------------------- symbolic helpers
@lru_cache(maxsize=1)
def _closed_form_compliance() -> tuple[Any, Any, Any, dict[str, Any]]:
    """General closed form (trivial silent motion) with ``k_ip1, k_ip2`` replaced by compliances."""
    import sympy as sp

    from ..symbolic.linearize import closed_form

    cf = closed_form("general")
    S = cf.symbols
    c1, c2 = sp.Symbol("c_ip1", nonnegative=True), sp.Symbol("c_ip2", nonnegative=True)
    rep = {S["k_ip1"]: 1 / c1, S["k_ip2"]: 1 / c2}

    def conv(m: Any) -> Any:
        return m.xreplace(rep).applyfunc(sp.cancel)

    syms = {n: (c1 if n == "c_ip1" else c2 if n == "c_ip2" else S[n]) for n in VECTOR_NAMES}
    return conv(cf.M), conv(cf.D), conv(cf.K), syms


def _specialise(space: ParameterSpace, axes: dict[str, Any]) -> tuple[Any, Any, Any, Any]:
    """Closed-form matrices with the space's values (axes symbolic) and ``mu1 h10 - mu2 h20``."""
    M, D, K, syms = _closed_form_compliance()
    vals = space.symbolic(axes)
    sub = {syms[n]: vals[n] for n in VECTOR_NAMES}
    moment = vals["mu1"] * vals["h10"] - vals["mu2"] * vals["h20"]
    return M.xreplace(sub), D.xreplace(sub), K.xreplace(sub), moment


def _identically_zero(expr: Any) -> bool:
    import sympy as sp

    return sp.simplify(sp.together(expr)) == 0


def _numerators(M: Any, D: Any, K: Any, var_signs: dict[Any, int]) -> list[Any] | None:
    """Numerators of ``a0..a4`` over a common denominator of known sign (sign folded in).

    Returns ``None`` when the dependence is not rational.
    """
    import sympy as sp

    lam = sp.Symbol("lam")
    det = sp.together((lam ** 2 * M + lam * D + K).det(method="berkowitz"))
    num, den = sp.fraction(det)
    gens = list(var_signs)
    try:
        poly = sp.Poly(sp.expand(num), lam, *gens)
        den_poly = sp.Poly(sp.expand(den), *gens)
    except sp.PolynomialError:
        return None
    if any(not c.is_number for c in poly.coeffs()) or any(not c.is_number for c in den_poly.coeffs()):
        return None
    # sign of the denominator for the axes' signs
    pos = {v: sp.Symbol(f"_p{i}", positive=True) * s for i, (v, s) in enumerate(var_signs.items())}
    dsub = sp.expand(den.xreplace(pos))
    sign = 1 if dsub.is_positive else -1 if dsub.is_negative else 0
    numer = sp.expand(num if sign != 0 else num * den) * (sign or 1)
    p = sp.Poly(numer, lam)
    coeffs = [p.coeff_monomial(lam ** i) for i in range(5)]
    return [sp.expand(c) for c in coeffs]


# ---------------------------------------------------------------- 2-D map kernel
@dataclass(frozen=True)
class MapKernel:
    """Compiled Hurwitz classifier for a map over two axes of a parameter space.

    Attributes
    ----------
    outer, inner : str
        Axis names; the inner axis is the contiguous (fast) one, chosen as the
        one in which the quartic's coefficients have the lowest degrees.
    degrees : tuple of int
        Degree of ``a0..a4`` in the inner axis.
    row_coefficients : callable
        ``f(outer_values, inner_ref) -> (C, sigma)``: per-row coefficient table
        (``n_outer × Σ(deg+1)``) for the scaled inner variable ``t = inner/inner_ref``,
        normalised per row, and the per-row time scale ``sigma`` (roots are ``σ μ``).
    classify : callable
        ``classify(C, t, out)`` writes the verdict (uint8, 1 = stable) to ``out[n_outer, n_inner]``.
    coefficients : callable
        ``coefficients(C, t, out)`` writes ``a0..a4`` (scaled) to ``out[5, n_outer, n_inner]``.
    source : str
        Generated kernel source.
    """

    outer: str
    inner: str
    degrees: tuple[int, ...]
    row_coefficients: Callable[[np.ndarray, float], tuple[np.ndarray, np.ndarray]]
    classify: Callable[..., None]
    coefficients: Callable[..., None]
    source: str


def normalise_rows(C: np.ndarray, degrees: tuple[int, ...], inner_ref: float) -> tuple[np.ndarray, np.ndarray]:
    """Scale per-row quartic coefficient tables for the compiled Hurwitz classifier.

    ``C`` holds, per row, the inner-axis polynomial coefficients of ``a0..a4``
    (``degrees[i] + 1`` columns each).  The inner variable is divided by
    ``inner_ref``, time is rescaled per row by ``sigma = (|a0| / |a4|)^(1/4)``
    (``λ → σ λ``, which keeps the roots' magnitudes near one and does not change
    the Hurwitz signs), and each row is divided by its largest entry.

    Parameters
    ----------
    C : ndarray, shape (rows, sum(degrees) + 5)
        Coefficient table (modified copy returned).
    degrees : tuple of int
        Inner-axis degree of each of ``a0..a4``.
    inner_ref : float
        Scale of the inner axis.

    Returns
    -------
    C : ndarray
        The normalised, C-contiguous table.
    sigma : ndarray, shape (rows,)
        The per-row time scales.
    """
    C = C * np.concatenate([inner_ref ** np.arange(d + 1) for d in degrees])
    offs = np.concatenate([[0], np.cumsum([d + 1 for d in degrees])])
    mag = [np.max(np.abs(C[:, offs[i]:offs[i + 1]]), axis=1) for i in range(5)]
    with np.errstate(divide="ignore", invalid="ignore"):
        sigma = np.where((mag[0] > 0) & (mag[4] > 0), (mag[0] / mag[4]) ** 0.25, 1.0)
    for i in range(5):
        C[:, offs[i]:offs[i + 1]] *= (sigma ** i)[:, None]
    scale = np.max(np.abs(C), axis=1)
    scale[~(scale > 0)] = 1.0
    C /= scale[:, None]
    return np.ascontiguousarray(C), sigma


def _kernel_source(degrees: tuple[int, ...]) -> str:
    offs = np.concatenate([[0], np.cumsum([d + 1 for d in degrees])]).tolist()
    load = "; ".join(f"c{i}_{k} = C[i, {offs[i] + k}]" for i in range(5) for k in range(degrees[i] + 1))

    def horner(i: int) -> str:
        d = degrees[i]
        expr = f"c{i}_{d}"
        for k in range(d - 1, -1, -1):
            expr = f"(c{i}_{k} + x * {expr})"
        return expr

    body = "\n".join(f"            a{i} = {horner(i)}" for i in range(5))
    h3 = "a1 * (a3 * a2 - a4 * a1) - a3 * a3 * a0"
    return f'''"""Generated by brakesqueal.analysis.kernels (degrees {degrees}). Do not edit."""
import numba


@numba.njit(cache=True, fastmath={{"contract"}}, error_model="numpy", boundscheck=False)
def classify(C, t, out):
    """Hurwitz verdict of the quartic: out[i, j] = 1 iff stable at (outer i, inner t[j])."""
    for i in range(C.shape[0]):
        {load}
        o = out[i]
        for j in range(t.shape[0]):
            x = t[j]
{body}
            h3 = {h3}
            o[j] = (a0 > 0.0) & (a1 > 0.0) & (a2 > 0.0) & (a3 > 0.0) & (a4 > 0.0) & (h3 > 0.0)


@numba.njit(cache=True, fastmath={{"contract"}}, error_model="numpy", boundscheck=False)
def coefficients(C, t, out):
    """Scaled quartic coefficients: out[k, i, j] = a_k at (outer i, inner t[j])."""
    for i in range(C.shape[0]):
        {load}
        for j in range(t.shape[0]):
            x = t[j]
{body}
            out[0, i, j] = a0
            out[1, i, j] = a1
            out[2, i, j] = a2
            out[3, i, j] = a3
            out[4, i, j] = a4
'''


def _load_generated(source: str, tag: str) -> Any:
    """Import generated kernel source from the on-disk cache (numba caches beside it)."""
    from ..numeric import cache

    digest = hashlib.sha256(source.encode()).hexdigest()[:16]
    return cache.load_module("stability-kernels", f"brakesqueal_kernel_{tag}_{digest}.py", lambda: source)


@lru_cache(maxsize=32)
def _map_kernel_cached(space: ParameterSpace, x: str, y: str, sx: int, sy: int) -> MapKernel | None:
    import sympy as sp

    X, Y = sp.Symbol("X", real=True), sp.Symbol("Y", real=True)
    M, D, K, moment = _specialise(space, {x: X, y: Y})
    if not _identically_zero(moment):
        return None
    nums = _numerators(M, D, K, {X: sx, Y: sy})
    if nums is None:
        return None
    deg_x = tuple(sp.Poly(a, X, Y).degree(X) if a != 0 else 0 for a in nums)
    deg_y = tuple(sp.Poly(a, X, Y).degree(Y) if a != 0 else 0 for a in nums)
    if sum(deg_x) <= sum(deg_y):
        inner, outer, I, O, degrees = x, y, X, Y, deg_x
    else:
        inner, outer, I, O, degrees = y, x, Y, X, deg_y
    exprs = []
    for a, d in zip(nums, degrees):
        p = sp.Poly(a, I)
        exprs.extend(p.coeff_monomial(I ** k) if k else p.coeff_monomial(1) for k in range(d + 1))
    fn = sp.lambdify([O], exprs, modules="numpy")
    degs = degrees

    def row_coefficients(outer_values: np.ndarray, inner_ref: float) -> tuple[np.ndarray, np.ndarray]:
        ov = np.asarray(outer_values, dtype=float)
        cols = [np.broadcast_to(np.asarray(c, dtype=float), ov.shape) for c in fn(ov)]
        C = np.stack(cols, axis=1) if cols else np.zeros((ov.size, 0))
        return normalise_rows(C, degs, inner_ref)

    source = _kernel_source(degrees)
    mod = _load_generated(source, "map")
    return MapKernel(outer=outer, inner=inner, degrees=degrees, row_coefficients=row_coefficients,
                     classify=mod.classify, coefficients=mod.coefficients, source=source)


def classify_numpy(kernel: MapKernel, C: np.ndarray, t: np.ndarray) -> np.ndarray:
    """NumPy (no compiler) version of ``kernel.classify`` on the same row coefficients."""
    offs = np.concatenate([[0], np.cumsum([d + 1 for d in kernel.degrees])])
    a = []
    for i, d in enumerate(kernel.degrees):
        v = np.broadcast_to(C[:, offs[i] + d, None], (C.shape[0], t.size)).copy()
        for k in range(d - 1, -1, -1):
            v *= t
            v += C[:, offs[i] + k, None]
        a.append(v)
    a0, a1, a2, a3, a4 = a
    h3 = a3 * a2
    h3 -= a4 * a1
    h3 *= a1
    h3 -= a3 * a3 * a0
    return (a0 > 0) & (a1 > 0) & (a2 > 0) & (a3 > 0) & (a4 > 0) & (h3 > 0)


def map_kernel(space: ParameterSpace, x: str, y: str, x_positive: bool = True, y_positive: bool = True
               ) -> MapKernel | None:
    """Build (or fetch) the compiled Hurwitz map kernel over axes ``x`` and ``y``.

    Returns ``None`` when the silent motion is not identically trivial on the
    map (``mu1 h10 ≠ mu2 h20`` somewhere) or the dependence is not rational;
    callers then fall back to numeric linearization / batched eigenvalues.
    ``x_positive`` / ``y_positive`` state the signs of the axis ranges (used to
    prove the sign of the common denominator).
    """
    return _map_kernel_cached(space, x, y, 1 if x_positive else -1, 1 if y_positive else -1)


# ---------------------------------------------------------------- real roots (compiled)
def real_roots(coeffs: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Real roots of the polynomial ``Σ coeffs[k] x^k`` in the open interval ``(lo, hi)``.

    Exact isolation by the derivative cascade (the roots of ``p'`` split the
    interval into monotone pieces), each root polished by safeguarded Newton
    to about one ulp of the polynomial's evaluation.
    """
    from ._compiled import real_roots as _rr

    c = np.ascontiguousarray(coeffs, dtype=float)
    out = np.empty(max(c.size, 1))
    n = _rr(c, float(lo), float(hi), out)
    return out[:n].copy()


# ---------------------------------------------------------------- Omega: Laurent coefficients
@lru_cache(maxsize=1)
def _omega_generated() -> Any:
    """Generate and compile ``entries(p) -> (12, 4)``: coefficients of ``Ω·entry`` in powers Ω^0..Ω^3."""
    import sympy as sp

    M, D, K, syms = _closed_form_compliance()
    W = syms["Omega"]
    rows = []
    for m in (M, D, K):
        for i in range(2):
            for j in range(2):
                e = sp.cancel(m[i, j] * W)
                num, den = sp.fraction(e)
                if W in den.free_symbols:
                    raise NotImplementedError("closed form is not a Laurent polynomial in Omega")
                p = sp.Poly(sp.expand(num), W)
                if p.degree() > 3:
                    raise NotImplementedError("closed form has powers of Omega above 2")
                rows.append([sp.cancel(p.coeff_monomial(W ** k) / den) for k in range(4)])
    flat = [e for row in rows for e in row]
    args = [syms[n] for n in VECTOR_NAMES]
    reps, reduced = sp.cse(flat)
    lines = ['"""Generated by brakesqueal.analysis.kernels: Laurent coefficients in Omega. Do not edit."""',
             "import numba", "import numpy as np", "", "",
             '@numba.njit(cache=True, error_model="numpy")', "def entries_batch(P, OUT):",
             '    """OUT[n, e, k]: coefficient of Omega^(k-1) in entry e of (Mbar, Dbar, Kbar) row-major."""',
             "    for n in range(P.shape[0]):", "        p = P[n]", "        out = OUT[n]"]
    lines.append("        " + ", ".join(str(a) for a in args) + (" = " + ", ".join(f"p[{i}]" for i in range(len(args)))))
    pr = sp.printing.pycode
    for s, v in reps:
        lines.append(f"        {s} = {pr(v, fully_qualified_modules=False)}")
    for idx, e in enumerate(reduced):
        lines.append(f"        out[{idx // 4}, {idx % 4}] = {pr(e, fully_qualified_modules=False)}")
    lines.append("")
    source = "\n".join(lines).replace("math.", "np.") + "\n"
    return _load_generated(source, "omega")


def omega_coefficients(p: np.ndarray) -> np.ndarray:
    """Laurent coefficients in Ω of the 12 entries of ``Mbar, Dbar, Kbar`` at parameter vector ``p``.

    ``p`` is in :data:`~.space.VECTOR_NAMES` order (compliances); returns
    ``(12, 4)``: ``entry = Σ_k out[e, k] Ω^(k-1)``.
    """
    out = np.zeros((1, 12, 4))
    _omega_generated().entries_batch(np.ascontiguousarray(np.atleast_2d(p), dtype=float), out)
    return out[0]


def critical_speeds_batch(params: np.ndarray, lo: float, hi: float, max_crossings: int = 8
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """All stability changes along Ω in ``(lo, hi)`` for many parameter vectors (trivial silent motion).

    Parameters
    ----------
    params : ndarray, shape (n, 17)
        Parameter vectors in :data:`~.space.VECTOR_NAMES` order (Ω ignored);
        every row must satisfy ``mu1 h10 = mu2 h20``.
    lo, hi : float
        The Ω range [rad/s], ``0 < lo < hi``.

    Returns
    -------
    crossings : ndarray (n, max_crossings)
        Ω values [rad/s] where stability changes, ascending, NaN-padded.
    directions : ndarray (n, max_crossings) int8
        ``-1`` destabilizing (stable below, unstable above), ``+1`` stabilizing.
    counts : ndarray (n,)
        Number of crossings found (may exceed ``max_crossings``).
    stable_at_start : ndarray (n,) bool
        Verdict just above ``lo``.
    """
    P = np.ascontiguousarray(np.atleast_2d(params), dtype=float)
    n = P.shape[0]
    roots = np.full((n, max_crossings), np.nan)
    dirs = np.zeros((n, max_crossings), dtype=np.int8)
    counts = np.zeros(n, dtype=np.int64)
    start = np.zeros(n, dtype=np.bool_)
    from ._compiled import critical_batch

    E = np.zeros((n, 12, 4))
    _omega_generated().entries_batch(P, E)
    critical_batch(E, float(lo), float(hi), roots, dirs, counts, start)
    return roots, dirs, counts, start


# ---------------------------------------------------------------- one arbitrary axis
def path_polynomials(space: ParameterSpace, name: str, positive: bool = True
                     ) -> tuple[list[np.ndarray], bool] | None:
    """Numerator polynomials of ``a0..a4`` in one axis (ascending float coefficients).

    Returns ``(polys, trivial)`` or ``None`` when the dependence is not rational
    or the silent motion is not identically trivial along the axis.
    """
    import sympy as sp

    X = sp.Symbol("X", real=True)
    M, D, K, moment = _specialise(space, {name: X})
    if not _identically_zero(moment):
        return None
    nums = _numerators(M, D, K, {X: 1 if positive else -1})
    if nums is None:
        return None
    polys = []
    for a in nums:
        p = sp.Poly(a, X)
        polys.append(np.array([float(p.coeff_monomial(X ** k)) for k in range(p.degree() + 1)]))
    return polys, True
