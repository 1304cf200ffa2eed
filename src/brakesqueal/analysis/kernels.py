r"""Certified stability criteria of 2-DOF models, generated from the closed forms and compiled.

The characteristic polynomial of eq. (47) for a 2-DOF model is the quartic

.. math:: \det(\lambda^2 \bar M + \lambda \bar D + \bar K)
          = a_4 \lambda^4 + a_3 \lambda^3 + a_2 \lambda^2 + a_1 \lambda + a_0 .

All roots have negative real parts iff (Liénard–Chipart / Hurwitz) every
``s a_i > 0`` and ``s H3 > 0`` with ``s = sign(a4)`` and
``H3 = a3 a2 a1 - a4 a1^2 - a3^2 a0`` (the third Hurwitz determinant).  The
test is invariant under multiplying all ``a_i`` by one non-zero number — so
a common denominator of any sign may be dropped *per point* — and under
``λ -> σλ`` (``a_i -> a_i σ^i``).  Stability can only change where ``a0 = 0``,
``H3 = 0`` or ``a4 = 0`` (Orlando's formula).

Every floating-point verdict made here is *certified*: values carry a
rigorous bound of their rounding error and a sign is only used when it
exceeds the bound; otherwise the point is reported *uncertain* and the caller
recomputes it by a robust route (:mod:`.robust`).

Generated / compiled pieces:

* :func:`model_form` — the closed form of any model with two coordinates and
  rate-free pads (:func:`~brakesqueal.symbolic.linearize.model_closed_form`,
  tangential stiffnesses as compliance symbols, packing order
  ``spec.parameters``); for the paper's model it equals
  ``closed_form("general")``.  Everything generated from it is keyed by the
  model's :func:`~brakesqueal.codegen.model_key` (and the parameter space's
  :meth:`~brakesqueal.model.parameters.ParameterSpace.key`).
* :func:`quartic_numerators` — the closed form (trivial silent motion)
  specialised to a parameter space with some axes symbolic, after checking
  that every zero-state residual of the model vanishes identically under the
  space's ties (the silent motion is trivial on the whole grid); entries are converted to elements of a
  rational function field
  (``sympy.polys.fields``, exact rational arithmetic with cancellation), so
  ``a_i = N_i / Den`` with small, exact numerator polynomials.  Constants such
  as π are extra generators.
* :func:`grid_kernel` / :func:`map_kernel` — numerators as polynomials in one
  *inner* axis whose coefficients depend on the other axes; the coefficient
  table is evaluated per row in exponent-scaled floating point with an error
  bound, the inner loop (unrolled Horner + Hurwitz inequalities + error
  bounds) is generated and compiled with numba and returns 0 (unstable),
  1 (stable) or 2 (uncertain).
* :func:`trivial_entries` — ``Mbar, Dbar, Kbar`` from a parameter vector with
  a rigorous rounding bound per entry (generated, compiled).
* :func:`omega_entries` — ``Mbar, Dbar, Kbar`` are Laurent polynomials in Ω,
  so ``Ω^6 H3`` is a polynomial in Ω; :func:`~.crossings.critical_speeds_batch`
  isolates its real roots with certified Descartes bisection in compiled code
  (:func:`~._compiled.critical_batch`) and recomputes exactly the sets that
  cannot be certified.
"""

from __future__ import annotations

import hashlib
import math
from fractions import Fraction
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

if TYPE_CHECKING:
    from ..model.parameters import ParameterSpace

__all__ = [
    "quartic_coefficients", "hurwitz_h3", "hurwitz_stable", "ModelForm", "model_form", "QuarticNumerators",
    "quartic_numerators", "GridKernel", "grid_kernel", "MapKernel", "map_kernel", "classify_numpy", "real_roots",
    "trivial_entries", "RateBlocks", "zero_rate_blocks", "omega_entries", "omega_coefficients",
    "omega_kernel_available", "omega_subranges", "inner_exponent", "kernel_segments", "run_classify", "kernel_scaling",
    "form_info", "has_model_form", "closed_route", "kernel_eigen", "CharpolyTable", "charpoly_table",
    "charpoly_verdicts", "charpoly_point_verdicts", "CHARPOLY_ACCURACY", "CHARPOLY_ROUTE",
]

_U = 2.0 ** -53
#: Inner-axis block size of the compiled map kernel (error bounds are computed per block).
BLOCK = 32


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
    """Liénard–Chipart verdict (bool array) in plain floating point, *not certified*.

    Kept for quick checks on well-scaled coefficients; the analysis routes use
    the certified tests of :mod:`.robust` (:func:`~.robust.routh_verdicts`).
    """
    s = np.sign(a4)
    a0, a1, a2, a3, a4 = (np.asarray(a) * s for a in (a0, a1, a2, a3, a4))
    return (a0 > 0) & (a1 > 0) & (a2 > 0) & (a3 > 0) & (a4 > 0) & (hurwitz_h3(a0, a1, a2, a3, a4) > 0)


# ---------------------------------------------------------------- model closed forms
@dataclass(frozen=True, eq=False)
class ModelForm:
    """Closed-form ``M, D, K`` of a 2-DOF model about its zero state, in packing symbols.

    Built by :func:`model_form` from :func:`~brakesqueal.symbolic.linearize.model_closed_form`.

    Attributes
    ----------
    key : str
        :func:`~brakesqueal.codegen.model_key` of the model.
    names : tuple of str
        Model parameters in packing order (``spec.parameters``).
    symbols : tuple
        SymPy symbol of every packing slot: the parameter itself, or its
        compliance ``c = 1/k`` for a tangential stiffness (named like the
        generated code's parameters, e.g. ``c_ip1``).
    compliance : tuple of bool
        Whether a slot holds a compliance.
    M, D, K : sympy.Matrix
        ``2 x 2`` matrices of eq. (47) in :attr:`symbols`.
    model_symbols : dict
        Model parameter name -> the SymPy symbol used in :attr:`residuals`
        (positive, ``h`` names real, as in ``model_closed_form``).
    residuals : tuple
        The residuals ``R, G`` at the zero state in :attr:`model_symbols`
        (non-zero ones only): the silent motion is the zero state exactly
        where they vanish.
    omega : str or None
        Name of the disk's spin parameter (``None`` when the spin is a number).
    omega_free : bool
        Whether :attr:`residuals` do not depend on the spin (then the silent
        motion is trivial for every spin when it is for one).
    """

    key: str
    names: tuple[str, ...]
    symbols: tuple[Any, ...]
    compliance: tuple[bool, ...]
    M: Any
    D: Any
    K: Any
    model_symbols: dict[str, Any]
    residuals: tuple[Any, ...]
    omega: str | None
    omega_free: bool

    @property
    def by_name(self) -> dict[str, Any]:
        """Packing symbol by model parameter name."""
        return dict(zip(self.names, self.symbols))


_MEMO: dict[Any, Any] = {}
_MEMO_MAX = 256


def _memo(key: Any, build: Callable[[], Any]) -> Any:
    """Process-wide memo of generated objects keyed by model key and space key (bounded, FIFO)."""
    if key in _MEMO:
        return _MEMO[key]
    value = build()
    if len(_MEMO) >= _MEMO_MAX:
        _MEMO.pop(next(iter(_MEMO)))
    _MEMO[key] = value
    return value


def _key(spec: Any) -> str:
    from ..codegen import model_key

    return model_key(spec)


def _disk_json(kind: str, ident: str, build: Callable[[], Any]) -> Any:
    """A JSON-able value built once and kept in the on-disk cache (so that warm starts need no SymPy).

    Keyed by ``kind`` and a hash of ``ident`` (model key, space key, axes); the
    cache's fingerprint covers this module, so editing a generator rebuilds it.
    """
    import json

    from ..numeric import cache

    name = f"{kind}-{hashlib.sha256(ident.encode()).hexdigest()[:24]}.json"
    return json.loads(cache.cached_text("stability-tables", name, lambda: json.dumps(build())))


def form_info(spec: Any) -> dict[str, Any]:
    """What the closed-form routes of a model need to know, without SymPy on a warm start.

    Parameters
    ----------
    spec : ModelSpec
        The model.

    Returns
    -------
    dict
        ``{"form": bool, "omega_kernel": bool}``: whether :func:`model_form`
        applies and whether :func:`omega_kernel_available`; built once per
        model (:func:`~brakesqueal.codegen.model_key`) and kept on disk.
    """
    def build() -> dict[str, Any]:
        form = model_form(spec)
        ok = False
        if form is not None and form.omega is not None and form.omega_free:
            try:
                ok = bool(_omega_source(spec))
            except NotImplementedError:
                ok = False
        return {"form": form is not None, "omega_kernel": ok}

    key = _key(spec)
    return _memo(("form-info", key), lambda: _disk_json("form", key, build))  # type: ignore[no-any-return]


def has_model_form(spec: Any) -> bool:
    """Whether :func:`model_form` applies to a model (cached on disk: no SymPy on a warm start)."""
    return bool(form_info(spec)["form"])


def model_form(spec: Any) -> ModelForm | None:
    """The closed form of a model for the generated kernels, or ``None`` where it does not apply.

    It applies to models with two coordinates whose pads are all rate-free at
    the zero state (:attr:`CompiledModel.rate_free_at_zero
    <brakesqueal.codegen.compiled.CompiledModel.rate_free_at_zero>`) and whose
    pads are, provably from the parameter roles, in sliding contact there
    (normal force and sliding speed positive); the others use the per-point
    routes of :mod:`.points`.

    Parameters
    ----------
    spec : ModelSpec
        The model.

    Returns
    -------
    ModelForm or None
        Memoized by :func:`~brakesqueal.codegen.model_key`.
    """
    return _memo(("form", _key(spec)), lambda: _build_form(spec))


def _build_form(spec: Any) -> ModelForm | None:
    import sympy as sp

    from ..codegen import compile_model
    from ..symbolic.assemble import build_equations
    from ..symbolic.linearize import model_closed_form

    cm = compile_model(spec)
    if cm.n != 2 or not all(cm.rate_free_at_zero):
        return None
    cf = model_closed_form(spec)
    if cf.rate_blocks:
        return None
    S = cf.symbols
    kip = set(spec.stiffness_names())
    names = tuple(spec.parameters)
    comp = tuple(n in kip for n in names)
    syms = tuple(sp.Symbol(pn, nonnegative=True) if c else S[n] for n, pn, c in zip(names, cm.param_names, comp))
    rep = {S[n]: 1 / s for n, s, c in zip(names, syms, comp) if c}

    def conv(m: Any) -> Any:
        return m.xreplace(rep).applyfunc(sp.cancel)

    # zero-state residuals and contact in the model's (positive) symbols: sqrt(Omega^2 r^2) -> Omega r
    eq = build_equations(spec, "symengine")
    back = {sp.Symbol(pn): (1 / S[n] if c else S[n]) for n, pn, c in zip(names, eq.param_names, comp)}
    zero = {s: 0 for s in eq.x}

    def at_zero(e: Any) -> Any:
        return sp.factor_terms(sp.cancel(sp.sympify(e.subs(zero)).xreplace(back)))

    rows = list(eq.R) + (list(eq.G) if eq.G is not None else [])
    residuals = tuple(r for r in (at_zero(e) for e in rows) if r != 0)
    for c in eq.pads:
        fn = at_zero(c.F_n)
        speed2 = at_zero(sum((v * v for v in c.v_r), 0))
        if not (fn.is_positive and speed2.is_positive):
            return None
    M, D, K = conv(cf.M), conv(cf.D), conv(cf.K)
    try:
        for X in (M, D, K):
            for e in X:
                _terms(e, list(syms))
    except NotImplementedError:  # not a Laurent polynomial in the parameters: no generated kernels
        return None
    omega = spec.disk.Omega if isinstance(spec.disk.Omega, str) else None
    omega_free = omega is None or all(S[omega] not in r.free_symbols for r in residuals)
    return ModelForm(key=_key(spec), names=names, symbols=syms, compliance=comp, M=M, D=D,
                     K=K, model_symbols=dict(S), residuals=residuals, omega=omega, omega_free=omega_free)


@dataclass(frozen=True, eq=False)
class RateBlocks:
    """The pads' rate blocks of a model at the zero state, simplified symbolically (no cancellation noise).

    At the zero state a massless pad's rate terms are differences of terms
    that cancel exactly for a constant friction coefficient (the derivative of
    the sliding direction along the sliding velocity vanishes); generated
    code evaluates such differences to rounding noise, which would give a
    spurious pad mode ``-G_L / G_dL`` of any sign.  Here they are simplified
    with the parameters' signs from their roles (``sqrt(Omega^2 r^2) = Omega
    r``), so only the genuine part remains (e.g. ``c_ip N0 mu'(v*)`` of a
    falling friction law) and an exact zero stays zero.

    Attributes
    ----------
    evaluate : callable
        ``evaluate(cols) -> (R_dL, G_dL, G_ddQ)`` for packing-order parameter
        arrays of length ``N``: arrays of shapes ``(N, n, m)``, ``(N, m, m)``,
        ``(N, m, n)``.
    """

    n: int
    m: int
    evaluate: Callable[[list[np.ndarray]], tuple[np.ndarray, np.ndarray, np.ndarray]]


def zero_rate_blocks(spec: Any) -> RateBlocks:
    """The zero-state rate blocks ``R_dL``, ``G_dL``, ``G_ddQ`` of a model, simplified (see :class:`RateBlocks`).

    Parameters
    ----------
    spec : ModelSpec
        The model.

    Returns
    -------
    RateBlocks
        Memoized by :func:`~brakesqueal.codegen.model_key`.
    """
    return _memo(("rates", _key(spec)), lambda: _build_rates(spec))


def _build_rates(spec: Any) -> RateBlocks:
    import sympy as sp
    import symengine as se

    from ..symbolic.assemble import build_equations
    from ..symbolic.linearize import model_closed_form, simplify_entry

    eq = build_equations(spec, "symengine")
    n, m = len(eq.coords), len(eq.algebraic)
    S = model_closed_form(spec).symbols
    names = tuple(spec.parameters)
    kip = set(spec.stiffness_names())
    csyms = {pn: sp.Symbol(pn, nonnegative=True) for n_, pn in zip(names, eq.param_names) if n_ in kip}
    back = {sp.Symbol(pn): (1 / S[n_] if n_ in kip else S[n_]) for n_, pn in zip(names, eq.param_names)}
    fwd = {S[n_]: 1 / csyms[pn] for n_, pn in zip(names, eq.param_names) if n_ in kip}
    zero = {s: 0 for s in eq.x}
    G = eq.G if eq.G is not None else se.zeros(0, 1)

    def clean(e: Any) -> Any:
        v = simplify_entry(sp.sympify(e.subs(zero)).xreplace(back))
        return simplify_entry(v.xreplace(fwd)) if fwd else v

    exprs = []
    for res, var, rows, cols in ((eq.R, eq.dL, n, m), (G, eq.dL, m, m), (G, eq.ddQ, m, n)):
        for i in range(rows):
            for j in range(cols):
                exprs.append(clean(se.diff(res[i], var[j])) if m else sp.Integer(0))
    args = [csyms[pn] if pn in csyms else S[n_] for n_, pn in zip(names, eq.param_names)]
    fn = sp.lambdify(args, exprs, modules="numpy")

    def evaluate(cols: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        N = int(np.size(cols[0])) if cols else 1
        with np.errstate(all="ignore"):
            vals = [np.broadcast_to(np.asarray(v, dtype=float), (N,)) for v in fn(*cols)] if exprs else []
        a = np.stack(vals, axis=-1) if vals else np.zeros((N, 0))
        k1, k2 = n * m, n * m + m * m
        return a[:, :k1].reshape(N, n, m), a[:, k1:k2].reshape(N, m, m), a[:, k2:].reshape(N, m, n)

    return RateBlocks(n=n, m=m, evaluate=evaluate)


def _specialise(space: ParameterSpace, axes: dict[str, Any]) -> tuple[Any, Any, Any, list[Any]] | None:
    """Closed-form matrices with the space's values (axes symbolic) and the zero-state residuals."""
    form = model_form(space.model)
    if form is None:
        return None
    vals = space.symbolic(axes)
    sub = {s: (1 / vals[n] if c else vals[n]) for n, s, c in zip(form.names, form.symbols, form.compliance)}
    msub = {form.model_symbols[n]: vals[n] for n in form.names}
    res = [r.xreplace(msub) for r in form.residuals]
    return form.M.xreplace(sub), form.D.xreplace(sub), form.K.xreplace(sub), res


def _exact_floats(e: Any) -> Any:
    """Replace SymPy Floats by the exact rationals of their double values (what the float routes use)."""
    import sympy as sp

    fl = e.atoms(sp.Float)
    return e.xreplace({f: sp.Rational(float(f)) for f in fl}) if fl else e


def _constants(exprs: list[Any]) -> list[Any]:
    """Irrational numeric atoms (π, √2, exp(1), ...) of the expressions, used as extra field generators."""
    import sympy as sp

    out: set[Any] = set()
    for e in exprs:
        out |= e.atoms(sp.NumberSymbol)
        out |= {a for a in e.atoms(sp.Pow) if a.is_number and not a.exp.is_Integer}
        out |= {a for a in e.atoms(sp.Function) if a.is_number}
    return sorted(out, key=sp.default_sort_key)


@dataclass(frozen=True)
class QuarticNumerators:
    """Exact numerators of the quartic's coefficients, ``a_i = N_i / Den``.

    Attributes
    ----------
    names : tuple of str
        The symbolic axes (settable names of the space), in generator order.
    constants : tuple
        SymPy constants (π, ...) that are further generators of the ring.
    N : tuple
        ``N_0 .. N_4`` as ``sympy.polys.rings.PolyElement`` over QQ with
        generators ``names + constants``.
    den : PolyElement
        The common denominator (its sign is never assumed).
    """

    names: tuple[str, ...]
    constants: tuple[Any, ...]
    N: tuple[Any, ...]
    den: Any

    @property
    def ring(self) -> Any:
        """The polynomial ring of ``N`` and ``den``."""
        return self.den.ring

    def hurwitz(self) -> Any:
        """``H3`` of the numerators, ``N1 (N3 N2 - N4 N1) - N3² N0`` (exact)."""
        n0, n1, n2, n3, n4 = self.N
        return n1 * (n3 * n2 - n4 * n1) - n3 ** 2 * n0


def _quartic_field(entries: list[Any], symbols: list[Any]) -> tuple[tuple[Any, ...], Any, tuple[Any, ...]] | None:
    """``(N, den, constants)`` of ``det(λ²M + λD + K)`` for 12 SymPy entries rational in ``symbols``."""
    import sympy as sp
    from sympy.polys.fields import field

    entries = [_exact_floats(sp.sympify(e)) for e in entries]
    consts = _constants(entries)
    F, *_ = field(list(symbols) + consts, sp.QQ)
    try:
        conv = [F.from_expr(e) if e != 0 else F(0) for e in entries]
    except Exception:  # non-rational dependence (Abs, sqrt of an axis, ...)
        return None
    m11, m12, m21, m22, d11, d12, d21, d22, k11, k12, k21, k22 = conv
    A = [k11 * k22 - k12 * k21,
         d11 * k22 + k11 * d22 - d12 * k21 - k12 * d21,
         m11 * k22 + d11 * d22 + k11 * m22 - m12 * k21 - d12 * d21 - k12 * m21,
         m11 * d22 + d11 * m22 - m12 * d21 - d12 * m21,
         m11 * m22 - m12 * m21]
    den = A[0].denom
    for a in A[1:]:
        den = den.lcm(a.denom)
    N = tuple(a.numer * den.exquo(a.denom) for a in A)
    return N, den, tuple(consts)


def quartic_numerators(space: ParameterSpace, names: tuple[str, ...]) -> QuarticNumerators | None:
    """Exact numerators of ``a0..a4`` with the axes ``names`` symbolic (trivial silent motion).

    Parameters
    ----------
    space : ParameterSpace
        The parameter space (any model).
    names : tuple of str
        Settable names of ``space`` kept symbolic.

    Returns
    -------
    QuarticNumerators or None
        ``None`` when the model has no closed form (:func:`model_form`), the
        silent motion is not identically trivial on the axes (a zero-state
        residual of the model does not vanish identically under the space's
        ties, e.g. ``mu1 h10 != mu2 h20`` somewhere for the paper's model, eq.
        49) or the dependence on an axis is not rational.  Memoized by model
        key, space key and ``names``.
    """
    names = tuple(names)
    return _memo(("qn", _key(space.model), space.key(), names), lambda: _quartic_numerators(space, names))


def _vanishes(expr: Any, syms: list[Any]) -> bool:
    """Whether an expression is identically zero (exact rational-function test, else ``simplify``)."""
    import sympy as sp
    from sympy.polys.fields import field

    e = _exact_floats(expr)
    try:
        Fm, *_ = field(list(syms) + _constants([e]), sp.QQ)
        return bool(Fm.from_expr(e) == 0)
    except Exception:  # non-rational dependence
        return bool(sp.simplify(e) == 0)


def _quartic_numerators(space: ParameterSpace, names: tuple[str, ...]) -> QuarticNumerators | None:
    import sympy as sp

    syms = [sp.Symbol(f"X{i}", real=True) for i in range(len(names))]
    spec_ = _specialise(space, dict(zip(names, syms)))
    if spec_ is None:
        return None
    M, D, K, residuals = spec_
    if not all(_vanishes(r, syms) for r in residuals):
        return None
    res = _quartic_field(list(M) + list(D) + list(K), syms)
    if res is None:
        return None
    N, den, consts = res
    return QuarticNumerators(tuple(names), consts, N, den)


def _const_values(consts: tuple[Any, ...], dps: int = 60) -> list[Any]:
    import mpmath
    import sympy as sp

    with mpmath.workdps(dps):
        return [mpmath.mpf(sp.N(c, dps + 10)) for c in consts]


def numeric_terms(poly: Any, n_axes: int, consts: tuple[Any, ...]) -> dict[tuple[int, ...], Any]:
    """Collect a ring element by axis exponents; constants evaluated with mpmath (60 digits)."""
    import mpmath

    cv = _const_values(consts)
    out: dict[tuple[int, ...], Any] = {}
    with mpmath.workdps(60):
        for mon, c in poly.terms():
            v = mpmath.mpf(c.numerator) / c.denominator
            for g, k in zip(cv, mon[n_axes:]):
                v *= g ** k
            key = tuple(mon[:n_axes])
            out[key] = out.get(key, 0) + v
    return out


def _frexp_mp(v: Any) -> tuple[float, int]:
    import mpmath

    if v == 0:
        return 0.0, 0
    m, e = mpmath.frexp(v)
    return float(m), int(e)


# ---------------------------------------------------------------- N-D grid kernel
@dataclass(frozen=True)
class GridKernel:
    """Compiled, certified Hurwitz classifier over the axes of a grid.

    Attributes
    ----------
    names : tuple of str
        All axes; ``inner`` is the index of the contiguous (fast) one, chosen
        as the axis in which the numerators have the lowest degrees.
    degrees : tuple of int
        Degree of ``N_0..N_4`` in the inner axis.
    exps, slot, mant, e2 : ndarray
        Coefficient table: term ``t`` contributes
        ``mant[t] 2^e2[t] Π_j outer_j^exps[t, j]`` to column ``slot[t]``
        (``slot`` enumerates ``(i, k)``: coefficient of ``inner^k`` in ``N_i``),
        with the inner power ``ipow[t]``.
    ipow : ndarray
        Inner exponent of every term.
    nops : ndarray
        Per column, a bound on the floating-point operations of its evaluation.
    classify : callable
        ``classify(C, EC, t, seg, Tseg, out)``: 0 unstable, 1 stable, 2
        uncertain at ``(row i, inner t[j])`` (see :func:`_kernel_source`,
        :func:`kernel_segments`; :func:`run_classify` wraps it).
    coefficients : callable
        ``coefficients(C, t, out)`` writes ``a0..a4`` (scaled) to ``out[5, rows, n_inner]``.
    source : str
        Generated kernel source.
    """

    names: tuple[str, ...]
    inner: int
    degrees: tuple[int, ...]
    exps: np.ndarray
    ipow: np.ndarray
    slot: np.ndarray
    mant: np.ndarray
    e2: np.ndarray
    nops: np.ndarray
    classify: Callable[..., None]
    coefficients: Callable[..., None]
    source: str

    def row_coefficients(self, outer: list[np.ndarray], inner_exp: int) -> tuple[np.ndarray, np.ndarray]:
        """Per-row coefficient table ``C`` and its absolute error bound ``EC``.

        Parameters
        ----------
        outer : list of ndarray
            Values of the outer axes (``names`` without ``inner``), each of
            length ``rows``.
        inner_exp : int
            The inner variable is ``t = inner / 2^inner_exp``.

        Returns
        -------
        C, EC : ndarray, shape (rows, Σ(degrees + 1))
            Coefficients of ``t^k`` in ``N_i`` (column blocks ``i = 0..4``),
            each row multiplied by one positive power of two (balanced with
            ``λ -> 2^e λ`` and normalised); ``EC`` bounds their errors.
        """
        C, EC, _ = self.row_tables(outer, inner_exp)
        return C, EC

    def row_tables(self, outer: list[np.ndarray], inner_exp: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`row_coefficients` and, per row, the exponent ``e`` of its balancing ``λ = 2^e ν``.

        Returns
        -------
        C, EC : ndarray
            As :meth:`row_coefficients`.
        lam_e : ndarray of int64, shape (rows,)
            The roots ``ν`` of a row's scaled quartic times ``2^lam_e`` are the eigenvalues ``λ`` [1/s].
        """
        from ._rows import normalise_rows, rows_eval

        n_rows = int(np.size(outer[0])) if outer else 1
        ncol = int(sum(d + 1 for d in self.degrees))
        nout = len(outer)
        Um = np.empty((n_rows, max(nout, 1)))
        Qe = np.zeros((n_rows, max(nout, 1)), dtype=np.int64)
        for j, v in enumerate(outer):
            m, e = np.frexp(np.asarray(v, dtype=float))
            Um[:, j], Qe[:, j] = m, e
        e2 = self.e2 + inner_exp * self.ipow
        C = np.zeros((n_rows, ncol))
        EC = np.zeros((n_rows, ncol))
        lam_e = np.zeros(n_rows, dtype=np.int64)
        rows_eval(self.exps, self.slot, self.mant, e2, Um, Qe, self.nops, C, EC)
        normalise_rows(C, EC, np.array(self.degrees, dtype=np.int64), lam_e)
        bad = ~(np.all(np.isfinite(C), axis=1) & np.all(np.isfinite(EC), axis=1))
        if bad.any():  # such rows are classified uncertain (a4 = 0 with an infinite bound)
            C[bad] = 0.0
            EC[bad] = np.inf
        return C, EC, lam_e


def _kernel_source(degrees: tuple[int, ...]) -> str:
    """Numba source of the certified classifier for inner-axis degrees ``degrees`` of ``N_0..N_4``.

    Two passes per row: a vectorizable pass with one error bound per row
    (valid for every ``|t| <= max|t|``), then, only for the rare points it
    leaves uncertain, a scalar pass with the point's own (tighter) bounds.
    """
    offs = np.concatenate([[0], np.cumsum([d + 1 for d in degrees])]).tolist()
    load = "; ".join(f"c{i}_{k} = C[i, {offs[i] + k}]" for i in range(5) for k in range(degrees[i] + 1))
    gam = [(2 * d + 4) * _U * 1.0001 for d in degrees]
    loadb = "\n".join(f"        b{i}_{k} = EC[i, {offs[i] + k}] + {gam[i]!r} * abs(c{i}_{k})"
                      for i in range(5) for k in range(degrees[i] + 1))

    def horner(i: int, pre: str, var: str, wrap: str = "") -> str:
        d = degrees[i]
        expr = f"{wrap}({pre}{i}_{d})" if wrap else f"{pre}{i}_{d}"
        for k in range(d - 1, -1, -1):
            term = f"{wrap}({pre}{i}_{k})" if wrap else f"{pre}{i}_{k}"
            expr = f"({term} + {var} * {expr})"
        return expr

    def indent(text: str, n: int) -> str:
        return "\n".join(" " * n + ln for ln in text.splitlines())

    poly = "\n".join(f"a{i} = {horner(i, 'c', 'x')}" for i in range(5))
    rowb = "\n".join(f"E{i} = ({horner(i, 'b', 'T')}) * 1.0000000001 + 1e-300" for i in range(5))
    rowB = "\n".join(f"B{i} = {horner(i, 'c', 'T', 'abs')} * 1.0000000001 + E{i}" for i in range(5))
    ehrow = ("ehb = (E1 * B3 * B2 + B1 * E3 * B2 + B1 * B3 * E2 + E4 * B1 * B1 + 2.0 * B4 * E1 * B1\n"
             "       + 2.0 * E3 * B3 * B0 + B3 * B3 * E0 + 1.2e-15 * (B1 * B3 * B2 + B4 * B1 * B1 + B3 * B3 * B0))"
             " * 1.0000001 + 1e-300")
    test = ("s = math.copysign(1.0, a4)\n"
            "d0 = s * a0\nd1 = s * a1\nd2 = s * a2\nd3 = s * a3\n"
            "h = d1 * (d3 * d2 - abs(a4) * d1) - d3 * d3 * d0\n"
            "sg = abs(a4) > E4\n"
            "st = sg & (d0 > E0) & (d1 > E1) & (d2 > E2) & (d3 > E3) & (h > ehb)\n"
            "ng = sg & ((d0 < -E0) | (d1 < -E1) | (d2 < -E2) | (d3 < -E3) | (h < -ehb))")
    # pass 1: d_k / E_k > 1 for all k <=> certified stable, < -1 for one k <=> certified unstable; the
    # reciprocals are rounded down by 4.5e-16 so that fl(d_k r_k) > 1 implies d_k > E_k (no NaN can occur:
    # finite tables, |t|^deg < 2^300, see kernel_scaling and GridKernel.row_coefficients)
    fast = ("s = math.copysign(1.0, a4)\n"
            "d0 = s * a0\nd1 = s * a1\nd2 = s * a2\nd3 = s * a3\n"
            "h = d1 * (d3 * d2 - abs(a4) * d1) - d3 * d3 * d0\n"
            "sg = abs(a4) > E4\n"
            "m = min(min(min(d0 * r0, d1 * r1), min(d2 * r2, d3 * r3)), h * rh)")
    ehpt = ("A0 = abs(a0) + E0\nA1 = abs(a1) + E1\nA2 = abs(a2) + E2\nA3 = abs(a3) + E3\nA4 = abs(a4) + E4\n"
            "ehb = (E1 * A3 * A2 + abs(a1) * E3 * A2 + abs(a1 * a3) * E2 + E4 * A1 * A1"
            " + abs(a4) * E1 * (A1 + abs(a1))\n"
            "       + E3 * (A3 + abs(a3)) * A0 + a3 * a3 * E0 + 1.2e-15 * (A1 * A3 * A2 + A4 * A1 * A1 + A3 * A3 * A0))"
            " * 1.0000001 + 1e-300")
    lines = [
        f'"""Generated by brakesqueal.analysis.kernels (degrees {degrees}). Do not edit."""',
        "import math", "", "import numba", "import numpy as np", "", "",
        '@numba.njit(cache=True, fastmath={"contract"}, error_model="numpy", boundscheck=False)',
        "def classify(C, EC, t, seg, Tseg, out):",
        '    """Certified Hurwitz verdict: out[i, j] = 1 stable, 0 unstable, 2 uncertain at (row i, inner t[j]).',
        "",
        "    a_k = Horner(C row, t) with |error| <= E_k (coefficient bounds EC plus Horner rounding);",
        "    s = sign(a4) per point (a common denominator of any sign drops out), d_k = s a_k and",
        "    s H3 = d1 (d3 d2 - |a4| d1) - d3^2 d0; H3's error bound",
        "    follows from the E_k by interval reasoning.  Pass 1 uses one bound per segment",
        "    t[seg[q]:seg[q+1]] (valid for |t| <= Tseg[q]), pass 2 re-tests its uncertain points",
        "    with their own bounds.",
        '    """',
        "    n = t.shape[0]",
        "    for i in range(C.shape[0]):",
        f"        {load}",
        loadb,
        "        orow = out[i]",
        "        for q in range(seg.shape[0] - 1):",
        "            T = Tseg[q]",
        indent(rowb, 12), indent(rowB, 12), indent(ehrow, 12),
        "            r0 = (1.0 / E0) * (1.0 - 4.5e-16)",
        "            r1 = (1.0 / E1) * (1.0 - 4.5e-16)",
        "            r2 = (1.0 / E2) * (1.0 - 4.5e-16)",
        "            r3 = (1.0 / E3) * (1.0 - 4.5e-16)",
        "            rh = (1.0 / ehb) * (1.0 - 4.5e-16)",
        "            ts = t[seg[q]:seg[q + 1]]",
        "            o = orow[seg[q]:seg[q + 1]]",
        "            for j in range(ts.shape[0]):",
        "                x = ts[j]",
        indent(poly, 16), indent(fast, 16),
        "                o[j] = 2 - (sg & (m > 1.0)) - 2 * (sg & (m < -1.0))",
        "        o = orow",
        "        nu = np.uint8(0)",
        "        for j in range(n):",
        "            nu = max(nu, o[j])",
        "        if nu < 2:",
        "            continue",
        "        for j in range(n):",
        "            if o[j] != 2:",
        "                continue",
        "            x = t[j]",
        "            T = abs(x)",
        indent(rowb, 12), indent(poly, 12), indent(ehpt, 12), indent(test, 12),
        "            o[j] = 1 if st else (0 if ng else 2)",
        "", "",
        '@numba.njit(cache=True, fastmath={"contract"}, error_model="numpy", boundscheck=False)',
        "def coefficients(C, t, out):",
        '    """Scaled quartic numerators: out[k, i, j] = N_k at (row i, inner t[j]) (no error bound)."""',
        "    for i in range(C.shape[0]):",
        f"        {load}",
        "        for j in range(t.shape[0]):",
        "            x = t[j]",
        indent(poly, 12),
    ]
    lines += [f"            out[{i}, i, j] = a{i}" for i in range(5)]
    return "\n".join(lines) + "\n"


def _load_generated(source: str, tag: str) -> Any:
    """Import generated kernel source from the on-disk cache (numba caches beside it)."""
    from ..numeric import cache

    digest = hashlib.sha256(source.encode()).hexdigest()[:16]
    return cache.load_module("stability-kernels", f"brakesqueal_kernel_{tag}_{digest}.py", lambda: source)


def _load_keyed(tag: str, spec: Any, generate: Callable[[], str]) -> Any:
    """Import a generated module named by the model's key; ``generate`` (SymPy) only runs on a cache miss."""
    from ..numeric import cache

    return cache.load_module("stability-kernels", f"brakesqueal_kernel_{tag}_{_key(spec)}.py", generate)


#: Kernels are refused (callers use the per-point route) above these inner / outer degrees.
MAX_INNER_DEGREE = 12
MAX_OUTER_DEGREE = 40


def grid_kernel(space: ParameterSpace, names: tuple[str, ...]) -> GridKernel | None:
    """Build (or fetch) the certified classifier for a grid over ``names``.

    Parameters
    ----------
    space : ParameterSpace
        The parameter space (any model).
    names : tuple of str
        The grid's axes (settable names of ``space``).

    Returns
    -------
    GridKernel or None
        ``None`` when no closed-form kernel applies: no closed form for the
        model (:func:`model_form`), a non-trivial silent motion somewhere on
        the grid, non-rational dependence, or degrees above
        :data:`MAX_INNER_DEGREE` / :data:`MAX_OUTER_DEGREE` (callers then use
        the per-point routes of :mod:`.points`, which are always correct but
        slower).  Nothing is assumed about the signs of the axes.  Memoized
        by model key, space key and ``names``.
    """
    names = tuple(names)
    return _memo(("grid", _key(space.model), space.key(), names), lambda: _grid_kernel(space, names))


def _space_ident(space: ParameterSpace, names: tuple[str, ...]) -> str:
    return f"{_key(space.model)}|{space.key()}|{tuple(names)!r}"


def closed_route(space: ParameterSpace, names: tuple[str, ...]) -> bool:
    """Whether :func:`quartic_numerators` applies (the closed form, trivial on the whole grid), cached on disk.

    Parameters
    ----------
    space : ParameterSpace
        The parameter space (any model).
    names : tuple of str
        The axes.

    Returns
    -------
    bool
        ``quartic_numerators(space, names) is not None``, decided once per
        model, space and axes with SymPy and then read from the on-disk cache.
    """
    names = tuple(names)
    if not has_model_form(space.model):
        return False
    ident = _space_ident(space, names)
    return bool(_memo(("closed", ident),
                      lambda: _disk_json("closed", ident, lambda: quartic_numerators(space, names) is not None)))


def _grid_kernel(space: ParameterSpace, names: tuple[str, ...]) -> GridKernel | None:
    if not closed_route(space, names):
        return None
    tab = _disk_json("grid", _space_ident(space, names), lambda: _grid_table(space, names))
    if tab is None:
        return None
    degrees = tuple(int(d) for d in tab["degrees"])
    source = _kernel_source(degrees)
    mod = _load_generated(source, "map")
    nt = len(tab["slot"])
    return GridKernel(names=tuple(names), inner=int(tab["inner"]), degrees=degrees,
                      exps=np.array(tab["exps"], dtype=np.int64).reshape(nt, len(names) - 1),
                      ipow=np.array(tab["ipow"], dtype=np.int64), slot=np.array(tab["slot"], dtype=np.int64),
                      mant=np.array([float.fromhex(v) for v in tab["mant"]]), e2=np.array(tab["e2"], dtype=np.int64),
                      nops=np.array(tab["nops"], dtype=float), classify=mod.classify, coefficients=mod.coefficients,
                      source=source)


def _grid_table(space: ParameterSpace, names: tuple[str, ...]) -> dict[str, Any] | None:
    """The coefficient table of a grid kernel as JSON-able data (exact mantissas as hex), or ``None``."""
    qn = quartic_numerators(space, tuple(names))
    if qn is None or not names:
        return None
    nax = len(names)
    terms = [numeric_terms(p, nax, qn.constants) for p in qn.N]
    degs = [tuple(max((m[j] for m in t), default=0) for t in terms) for j in range(nax)]
    totals = [sum(d) for d in degs]
    inner = max(i for i in range(nax) if totals[i] == min(totals))  # ties: the trailing axis
    degrees = degs[inner]
    if max(degrees) > MAX_INNER_DEGREE:
        return None
    offs = np.concatenate([[0], np.cumsum([d + 1 for d in degrees])])
    rows_e, rows_k, rows_s, rows_m, rows_x = [], [], [], [], []
    for i, t in enumerate(terms):
        for mon, v in t.items():
            if v == 0:
                continue
            m, e = _frexp_mp(v)
            outer_exp = [int(mon[j]) for j in range(nax) if j != inner]
            if sum(outer_exp) > MAX_OUTER_DEGREE:
                return None
            rows_e.append(outer_exp)
            rows_k.append(int(mon[inner]))
            rows_s.append(int(offs[i] + mon[inner]))
            rows_m.append(m)
            rows_x.append(int(e))
    ncol = int(offs[-1])
    nterms = np.bincount(np.array(rows_s, dtype=np.int64), minlength=ncol)
    tdeg = np.zeros(ncol, dtype=np.int64)
    for s, ex in zip(rows_s, rows_e):
        tdeg[s] = max(tdeg[s], sum(ex))
    nops = (nterms + tdeg + 4).astype(float)
    return {"inner": int(inner), "degrees": [int(d) for d in degrees], "exps": rows_e, "ipow": rows_k,
            "slot": rows_s, "mant": [float(m).hex() for m in rows_m], "e2": rows_x,
            "nops": [float(v) for v in nops]}


def kernel_scaling(kern: GridKernel | MapKernel | None, inner_values: np.ndarray) -> tuple[int, np.ndarray] | None:
    """Inner-axis scaling ``(e, t)`` if the kernel's Horner evaluation stays in range for these values.

    Parameters
    ----------
    kern : GridKernel or MapKernel or None
        The kernel (``None`` gives ``None``).
    inner_values : ndarray
        Values of the kernel's inner axis.

    Returns
    -------
    tuple or None
        ``(e, t)`` with ``t = inner_values / 2^e`` (see :func:`inner_exponent`),
        or ``None`` when ``|t|^degree`` could reach ``2^300`` (the kernel then
        does not apply; no overflow, no NaN in the compiled loop).
    """
    if kern is None:
        return None
    e = inner_exponent(inner_values)
    t = np.ldexp(np.asarray(inner_values, dtype=float), -e)
    deg = max(kern.degrees)
    tmax = float(np.max(np.abs(t))) if t.size else 0.0
    if not (np.all(np.isfinite(t)) and (tmax <= 1 or deg * math.log2(tmax) < 300)):
        return None
    return e, t


def inner_exponent(values: np.ndarray) -> int:
    """Power-of-two scale of an inner axis: ``t = value / 2^e`` has magnitudes near one."""
    a = np.abs(np.asarray(values, dtype=float))
    a = a[np.isfinite(a) & (a > 0)]
    if a.size == 0:
        return 0
    return int(round(0.5 * (math.log2(a.min()) + math.log2(a.max()))))


def kernel_segments(t: np.ndarray, min_len: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """Segments of the inner values for the kernel's first pass: ``|t|`` within a factor 8, at least ``min_len`` long.

    Returns ``(seg, Tseg)``: boundaries ``seg[0] = 0 < ... < seg[-1] = len(t)``
    and the largest ``|t|`` of every segment (the error bounds hold for every
    point of a segment; longer segments only make them looser).
    """
    a = np.abs(np.asarray(t, dtype=float))
    n = a.size
    if n == 0:
        return np.array([0], dtype=np.int64), np.zeros(0)
    with np.errstate(divide="ignore", invalid="ignore"):
        cls = np.where(a > 0, np.floor(np.log2(np.where(a > 0, a, 1.0)) / 3.0), -1e6)
    cls[~np.isfinite(a)] = 1e6
    cuts = np.flatnonzero(np.diff(cls)) + 1
    seg = [0]
    for c in cuts:
        if c - seg[-1] >= min_len:
            seg.append(int(c))
    if n - seg[-1] < min_len and len(seg) > 1:
        seg.pop()
    seg.append(n)
    segs = np.array(seg, dtype=np.int64)
    with np.errstate(invalid="ignore"):
        T = np.maximum.reduceat(a, segs[:-1])
    return segs, T


def run_classify(kern: GridKernel | MapKernel, C: np.ndarray, EC: np.ndarray, t: np.ndarray,
                 out: np.ndarray | None = None) -> np.ndarray:
    """Call the compiled classifier on row tables ``C, EC`` and inner values ``t`` (codes 0/1/2)."""
    t = np.ascontiguousarray(t, dtype=float)
    if out is None:
        out = np.empty((C.shape[0], t.size), dtype=np.uint8)
    seg, T = kernel_segments(t)
    kern.classify(C, EC, t, seg, T, out)
    return out


def classify_grid_values(kern: GridKernel, outer: list[np.ndarray], inner_values: np.ndarray) -> np.ndarray:
    """Verdict codes ``(rows, n_inner)`` (0 unstable, 1 stable, 2 uncertain) of a grid kernel."""
    e = inner_exponent(inner_values)
    C, EC = kern.row_coefficients(outer, e)
    t = np.ldexp(np.asarray(inner_values, dtype=float), -e)
    return run_classify(kern, C, EC, t)


# ---------------------------------------------------------------- 2-D map kernel
@dataclass(frozen=True)
class MapKernel:
    """The grid kernel of a 2-D map, with the axis roles named.

    Attributes
    ----------
    outer, inner : str
        Axis names; the inner axis is the contiguous (fast) one.
    degrees : tuple of int
        Degree of ``N_0..N_4`` in the inner axis.
    grid : GridKernel
        The underlying kernel.
    """

    outer: str
    inner: str
    degrees: tuple[int, ...]
    grid: GridKernel

    @property
    def classify(self) -> Callable[..., None]:
        """``classify(C, EC, t, seg, Tseg, out)`` (see :class:`GridKernel`, :func:`run_classify`)."""
        return self.grid.classify

    @property
    def coefficients(self) -> Callable[..., None]:
        """``coefficients(C, t, out)`` (see :class:`GridKernel`)."""
        return self.grid.coefficients

    @property
    def source(self) -> str:
        """Generated kernel source."""
        return self.grid.source

    def row_coefficients(self, outer_values: np.ndarray, inner_exp: int) -> tuple[np.ndarray, np.ndarray]:
        """``(C, EC)`` per outer value for ``t = inner / 2^inner_exp`` (see :meth:`GridKernel.row_coefficients`)."""
        return self.grid.row_coefficients([np.asarray(outer_values, dtype=float)], inner_exp)

    def row_tables(self, outer_values: np.ndarray, inner_exp: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(C, EC, lam_e)`` per outer value (see :meth:`GridKernel.row_tables`)."""
        return self.grid.row_tables([np.asarray(outer_values, dtype=float)], inner_exp)

    def verdicts(self, outer_values: np.ndarray, inner_values: np.ndarray) -> np.ndarray:
        """Verdict codes ``(n_outer, n_inner)``: 0 unstable, 1 stable, 2 uncertain."""
        return classify_grid_values(self.grid, [np.asarray(outer_values, dtype=float)], inner_values)


def kernel_eigen(kern: GridKernel | MapKernel, C: np.ndarray, t: np.ndarray, lam_e: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Max Re λ and its frequency at every point of a kernel's rows (compiled roots of the quartic).

    The quartic's coefficients come from the same row tables as the verdict
    (:meth:`GridKernel.row_tables`); its roots from Newton's method on the
    factorization into two real quadratics, warm-started from the neighbouring
    points (:func:`~._compiled.quartic_top_grid`).

    Parameters
    ----------
    kern : GridKernel or MapKernel
        The kernel.
    C : ndarray, shape (rows, ncol)
        Row tables.
    t : ndarray
        Scaled inner values.
    lam_e : ndarray of int64
        Per row, the exponent of its balancing (``λ = 2^lam_e ν``).

    Returns
    -------
    max_real, frequency : ndarray, shape (rows, t.size)
        ``max Re λ`` [1/s] and ``|Im λ| / 2π`` [Hz] of that root.
    ok : ndarray of uint8
        0 where the roots were not found cleanly (NaN there; the caller recomputes those points).
    """
    from ._compiled import PARALLEL_MIN, quartic_top_grid, quartic_top_grid_chunks

    t = np.ascontiguousarray(t, dtype=float)
    rows = C.shape[0]
    A = np.empty((5, rows, t.size))
    kern.coefficients(C, t, A)
    mr = np.empty((rows, t.size))
    fr = np.empty((rows, t.size))
    ok = np.empty((rows, t.size), dtype=np.uint8)
    le = np.ascontiguousarray(lam_e, dtype=np.int64)
    with np.errstate(all="ignore"):
        try:
            if rows * t.size >= PARALLEL_MIN and rows > CHARPOLY_BLOCK:
                # blocks of rows in parallel, each warm-starting itself (results independent of the thread count)
                quartic_top_grid_chunks(A, le, mr, fr, ok, CHARPOLY_BLOCK)
            else:
                quartic_top_grid(A, le, mr, fr, ok)
        except ZeroDivisionError:
            # numba's complex division raises on a zero divisor (coefficients at the magnitude limits, e.g.
            # Omega = 1e-99): no root is taken from this block, the caller recomputes every point
            mr[:], fr[:], ok[:] = np.nan, np.nan, 0
    return mr, fr, ok


def map_kernel(space: ParameterSpace, x: str, y: str) -> MapKernel | None:
    """Build (or fetch) the certified map kernel over axes ``x`` and ``y``.

    Returns ``None`` when the silent motion is not identically trivial on the
    map (``mu1 h10 ≠ mu2 h20`` somewhere), the dependence is not rational, or
    the degrees are too high; callers then use the per-point route.  The
    result does not depend on the axes' ranges or signs.
    """
    g = grid_kernel(space, (x, y))
    if g is None:
        return None
    names = (x, y)
    return MapKernel(outer=names[1 - g.inner], inner=names[g.inner], degrees=g.degrees, grid=g)


def _np_bounds(C: np.ndarray, EC: np.ndarray, degrees: tuple[int, ...], T: np.ndarray | float
               ) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Error bounds ``E_k`` and magnitude bounds ``B_k`` of the ``a_k`` for ``|t| <= T`` (broadcast to rows × T)."""
    offs = np.concatenate([[0], np.cumsum([d + 1 for d in degrees])])
    E, B = [], []
    for i, d in enumerate(degrees):
        g = (2 * d + 4) * _U * 1.0001
        c = C[:, offs[i]:offs[i + 1], None]
        b = EC[:, offs[i]:offs[i + 1], None] + g * np.abs(c)
        e = b[:, d]
        m = np.abs(c[:, d])
        for k in range(d - 1, -1, -1):
            e = e * T + b[:, k]
            m = m * T + np.abs(c[:, k])
        E.append(e * 1.0000000001 + 1e-300)
        B.append(m * 1.0000000001 + E[-1])
    return E, B


def _np_values(C: np.ndarray, degrees: tuple[int, ...], t: np.ndarray) -> list[np.ndarray]:
    offs = np.concatenate([[0], np.cumsum([d + 1 for d in degrees])])
    a = []
    for i, d in enumerate(degrees):
        v = np.broadcast_to(C[:, offs[i] + d, None], (C.shape[0], t.size)).copy()
        for k in range(d - 1, -1, -1):
            v *= t
            v += C[:, offs[i] + k, None]
        a.append(v)
    return a


def _np_test(a: list[np.ndarray], E: list[np.ndarray], eh: np.ndarray) -> np.ndarray:
    a0, a1, a2, a3, a4 = a
    E0, E1, E2, E3, E4 = E
    s = np.where(a4 > 0, 1.0, -1.0)
    d0, d1, d2, d3 = s * a0, s * a1, s * a2, s * a3
    h = d1 * (d3 * d2 - np.abs(a4) * d1) - d3 * d3 * d0
    sg = np.abs(a4) > E4
    st = sg & (d0 > E0) & (d1 > E1) & (d2 > E2) & (d3 > E3) & (h > eh)
    ng = sg & ((d0 < -E0) | (d1 < -E1) | (d2 < -E2) | (d3 < -E3) | (h < -eh))
    return np.where(st, 1, np.where(ng, 0, 2)).astype(np.uint8)


def _eh(A: list[np.ndarray], E: list[np.ndarray], a: list[np.ndarray] | None = None) -> np.ndarray:
    """Error bound of ``s H3`` from bounds ``E_k`` and magnitudes ``A_k`` (``|a_k| <= A_k - E_k``)."""
    A0, A1, A2, A3, A4 = A
    E0, E1, E2, E3, E4 = E
    v1, v3, v4 = (A1 - E1, A3 - E3, A4 - E4) if a is None else (np.abs(a[1]), np.abs(a[3]), np.abs(a[4]))
    return (E1 * A3 * A2 + v1 * E3 * A2 + v1 * v3 * E2 + E4 * A1 * A1 + v4 * E1 * (A1 + v1)
            + E3 * (A3 + v3) * A0 + v3 * v3 * E0 + 1.2e-15 * (A1 * A3 * A2 + A4 * A1 * A1 + A3 * A3 * A0)) * 1.0000001 \
        + 1e-300


def classify_numpy(kernel: MapKernel | GridKernel, C: np.ndarray, EC: np.ndarray, t: np.ndarray) -> np.ndarray:
    """NumPy (no compiler) version of the compiled classifier on the same row tables (codes 0/1/2).

    Same two passes: bounds per segment of :func:`kernel_segments`, then the
    points left uncertain with their own bounds.
    """
    degrees = kernel.degrees
    t = np.asarray(t, dtype=float)
    out = np.empty((C.shape[0], t.size), dtype=np.uint8)
    seg, Tseg = kernel_segments(t)
    with np.errstate(all="ignore"):
        for q in range(seg.size - 1):
            ts = t[seg[q]:seg[q + 1]]
            E, B = _np_bounds(C, EC, degrees, float(Tseg[q]))
            eh = _eh(B, E)
            a0, a1, a2, a3, a4 = _np_values(C, degrees, ts)
            s = np.copysign(1.0, a4)
            for x in (a0, a1, a2, a3):
                x *= s
            np.abs(a4, out=a4)
            h = a3 * a2
            h -= a4 * a1
            h *= a1
            h -= a3 * a3 * a0
            f = 1.0 - 4.5e-16  # fl(d r) > 1 implies d > E (see the compiled kernel)
            m = h * (f / eh)
            for x, e in zip((a0, a1, a2, a3), E[:4]):
                np.minimum(m, x * (f / e), out=m)
            sg = a4 > E[4]
            out[:, seg[q]:seg[q + 1]] = 2 - (sg & (m > 1.0)) - 2 * (sg & (m < -1.0))
        rr, cc = np.nonzero(out == 2)
        if rr.size:
            tt = t[cc]
            Cp, ECp = C[rr], EC[rr]
            offs = np.concatenate([[0], np.cumsum([d + 1 for d in degrees])])
            a, E = [], []
            for i, d in enumerate(degrees):
                g = (2 * d + 4) * _U * 1.0001
                v = Cp[:, offs[i] + d].copy()
                e = ECp[:, offs[i] + d] + g * np.abs(Cp[:, offs[i] + d])
                for k in range(d - 1, -1, -1):
                    v = v * tt + Cp[:, offs[i] + k]
                    e = e * np.abs(tt) + ECp[:, offs[i] + k] + g * np.abs(Cp[:, offs[i] + k])
                a.append(v)
                E.append(e * 1.0000000001 + 1e-300)
            A = [np.abs(x) + e for x, e in zip(a, E)]
            out[rr, cc] = _np_test(a, E, _eh(A, E, a))
    return out


# ---------------------------------------------------------------- real roots (compiled, floating point)
def real_roots(coeffs: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Real roots of the polynomial ``Σ coeffs[k] x^k`` in the open interval ``(lo, hi)`` (floating point).

    Derivative cascade (the roots of ``p'`` split the interval into monotone
    pieces), each root polished by safeguarded Newton.  Not certified; the
    analysis routes use :func:`~.robust.isolate_real_roots` (exact) or the
    certified compiled isolation.
    """
    from ._compiled import real_roots as _rr

    c = np.ascontiguousarray(coeffs, dtype=float)
    out = np.empty(max(c.size, 1))
    n = _rr(c, float(lo), float(hi), out)
    return out[:n].copy()


# ---------------------------------------------------------------- bounded closed-form entries (generated)
def _bounded_source(fname: str, slots: list[list[tuple[Any, dict[int, int]]]], doc: str, nparams: int) -> str:
    """Numba source ``fname(P, V, R)``: ``V[n, s]`` = Σ terms of slot ``s``, ``R[n, s]`` its rounding bound."""
    import sympy as sp

    lines = [f'"""Generated by brakesqueal.analysis.kernels: {doc}. Do not edit."""', "import numba", "", "",
             '@numba.njit(cache=True, error_model="numpy")', f"def {fname}(P, V, R):",
             f'    """{doc}; R bounds the rounding error of V."""',
             "    for n in range(P.shape[0]):", "        p = P[n]"]
    lines.append("        " + ", ".join(f"x{i}" for i in range(nparams)) + " = "
                 + ", ".join(f"p[{i}]" for i in range(nparams)))
    for s, terms in enumerate(slots):
        if not terms:
            lines.append(f"        V[n, {s}] = 0.0")
            lines.append(f"        R[n, {s}] = 0.0")
            continue
        lines.append("        v = 0.0")
        lines.append("        a = 0.0")
        kmax = 0
        for c, powers in terms:
            fac = [repr(float(sp.Float(c, 30)))]
            ops = 1
            for i, k in sorted(powers.items()):
                if k > 0:
                    fac.extend([f"x{i}"] * k)
                ops += abs(k)
            den = [f"x{i}" for i, k in sorted(powers.items()) for _ in range(-k)]
            expr = " * ".join(fac)
            if den:
                expr = f"({expr}) / ({' * '.join(den)})"
            kmax = max(kmax, ops)
            lines.append(f"        t = {expr}")
            lines.append("        v += t")
            lines.append("        a += abs(t)")
        g = (kmax + len(terms) + 4) * _U * 1.001
        lines.append(f"        V[n, {s}] = v")
        lines.append(f"        R[n, {s}] = {g!r} * a + 1e-300")
    return "\n".join(lines) + "\n"


def _terms(expr: Any, syms: list[Any]) -> list[tuple[Any, dict[int, int]]]:
    """Expanded terms ``c Π syms^k`` of a Laurent polynomial in ``syms``."""
    import sympy as sp

    out = []
    index = {s: i for i, s in enumerate(syms)}
    for term in sp.Add.make_args(sp.expand(expr)):
        if term == 0:
            continue
        c, rest = term.as_coeff_Mul()
        powers: dict[int, int] = {}
        for base, k in rest.as_powers_dict().items():
            if base == 1:
                continue
            if base not in index or not sp.Integer(k).is_integer:
                c = c * base ** k
                continue
            powers[index[base]] = powers.get(index[base], 0) + int(k)
        if not c.is_number:
            raise NotImplementedError(f"closed-form term {term} is not a Laurent monomial")
        out.append((c, powers))
    return out


def _form(spec: Any) -> ModelForm:
    form = model_form(spec)
    if form is None:
        from ..errors import ParameterError

        raise ParameterError(f"model '{spec.name}' has no closed-form kernel (two coordinates and rate-free pads "
                             "at the zero state are needed); use the per-point routes")
    return form


def _paper() -> Any:
    from ..model.library import get_model

    return get_model("paper")


def _entries_generated(spec: Any) -> Any:
    if not has_model_form(spec):
        _form(spec)  # raises the error naming the model

    def source() -> str:
        form = _form(spec)
        args = list(form.symbols)
        slots = [_terms(X[i, j], args) for X in (form.M, form.D, form.K) for i in range(2) for j in range(2)]
        return _bounded_source("entries_batch", slots, "Mbar, Dbar, Kbar entries (row-major)", len(args))

    return _memo(("entries", _key(spec)), lambda: _load_keyed("entries", spec, source))


def trivial_entries(P: np.ndarray, spec: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """``Mbar, Dbar, Kbar`` (trivial silent motion, closed form) with rigorous rounding bounds.

    Parameters
    ----------
    P : ndarray, shape (n, n_parameters)
        Parameter vectors in the model's packing order (``spec.parameters``,
        compliances ``c = 1/k_ip`` for tangential stiffnesses, as
        :meth:`Parameters.vector <brakesqueal.model.parameters.Parameters.vector>`).
    spec : ModelSpec, optional
        The model (default: the paper's); it needs a closed form (:func:`model_form`).

    Returns
    -------
    E, R : ndarray, shape (n, 12)
        Entries of ``M, D, K`` (row-major) and bounds on their rounding errors
        (exact for the given parameter vector).
    """
    spec = spec if spec is not None else _paper()
    P = np.ascontiguousarray(np.atleast_2d(P), dtype=float)
    E = np.empty((P.shape[0], 12))
    R = np.empty((P.shape[0], 12))
    with np.errstate(all="ignore"):
        _entries_generated(spec).entries_batch(P, E, R)
    return E, R


# ---------------------------------------------------------------- Omega: Laurent coefficients
def omega_kernel_available(spec: Any) -> bool:
    """Whether the critical-speed kernel applies to a model (closed form, spin a named parameter, Laurent form)."""
    return bool(form_info(spec)["omega_kernel"])


def _omega_source(spec: Any) -> str:
    """Source of ``entries_batch(P, V, R)``: coefficients of ``Ω·entry`` in powers Ω^0..Ω^3 with bounds (SymPy)."""
    form = _form(spec)
    if form.omega is None:
        raise NotImplementedError(f"model '{spec.name}': the disk's spin is a number, not a parameter")
    args = list(form.symbols)
    iw = form.names.index(form.omega)
    W = args[iw]
    slots = []
    for m in (form.M, form.D, form.K):
        for i in range(2):
            for j in range(2):
                groups: list[list[tuple[Any, dict[int, int]]]] = [[], [], [], []]
                for c, powers in _terms(m[i, j] * W, args):
                    k = powers.pop(iw, 0)
                    if not 0 <= k <= 3:
                        raise NotImplementedError("closed form is not a Laurent polynomial in Omega of "
                                                  "degree <= 2")
                    groups[k].append((c, powers))
                slots.extend(groups)
    return _bounded_source("entries_batch", slots, "Laurent coefficients in Omega", len(args))


def _omega_module(spec: Any) -> Any:
    """The compiled Ω kernel of a model whose :func:`form_info` says it applies (no SymPy on a warm start)."""
    key = ("omega", _key(spec))
    if key not in _MEMO:
        if not form_info(spec)["omega_kernel"]:
            return None
        _memo(key, lambda: _load_keyed("omega", spec, lambda: _omega_source(spec)))
    return _MEMO[key]


def omega_entries(P: np.ndarray, spec: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """Laurent coefficients in Ω of the 12 entries of ``Mbar, Dbar, Kbar``, with rounding bounds.

    Parameters
    ----------
    P : ndarray, shape (n, n_parameters)
        Parameter vectors in the model's packing order (Ω ignored).
    spec : ModelSpec, optional
        The model (default: the paper's).

    Returns
    -------
    E, R : ndarray, shape (n, 12, 4)
        ``entry = Σ_k E[.., e, k] Ω^(k-1)`` and the rounding bounds.
    """
    spec = spec if spec is not None else _paper()
    mod = _omega_module(spec)
    if mod is None:
        raise NotImplementedError(f"model '{spec.name}' has no Laurent form in its spin")
    P = np.ascontiguousarray(np.atleast_2d(P), dtype=float)
    V = np.empty((P.shape[0], 48))
    R = np.empty((P.shape[0], 48))
    with np.errstate(all="ignore"):
        mod.entries_batch(P, V, R)
    return V.reshape(-1, 12, 4), R.reshape(-1, 12, 4)


def omega_coefficients(p: np.ndarray, spec: Any = None) -> np.ndarray:
    """Laurent coefficients in Ω of the 12 entries of ``Mbar, Dbar, Kbar`` at parameter vector ``p``.

    Parameters
    ----------
    p : ndarray
        Parameter vector in the model's packing order (compliances).
    spec : ModelSpec, optional
        The model (default: the paper's).

    Returns
    -------
    ndarray, shape (12, 4)
        ``entry = Σ_k out[e, k] Ω^(k-1)``.
    """
    return omega_entries(np.atleast_2d(p), spec)[0][0]


def omega_subranges(lo: float, hi: float, decades: float = 6.0) -> np.ndarray:
    """Sub-range limits ``lo = b_0 < b_1 < … < b_J = hi`` with internal limits powers of two, ratio ≲ ``10^decades``."""
    if not (0 < lo < hi and math.isfinite(hi)):
        from ..errors import ParameterError

        raise ParameterError(f"the Omega range needs 0 < START < STOP (finite); got {lo!r}:{hi!r}")
    step = max(1, int(decades * math.log2(10)))
    e0, e1 = math.floor(math.log2(lo)) + 1, math.ceil(math.log2(hi)) - 1
    inner = [2.0 ** e for e in range(e0 + step // 2, e1, step)] if e1 - e0 > step else []
    pts = [lo] + [b for b in inner if lo < b < hi] + [hi]
    return np.array(pts, dtype=float)


# ---------------------------------------------------------------- n-DOF: the exact characteristic polynomial on a grid
#: Relative accuracy of every root (Gerschgorin disk radius / |root|) that the characteristic-polynomial route
#: requires before it reports ``max_real`` and the frequency (otherwise the point goes to the eigenvalue route).
CHARPOLY_ACCURACY = 1e-9
#: Rows per block of the characteristic-polynomial kernel (blocks run in parallel; each warm-starts itself).
CHARPOLY_BLOCK = 64
#: The route's name in results' ``method`` (ASCII: NetCDF3 attributes).
CHARPOLY_ROUTE = ("per point, compiled: certified roots of the exact characteristic polynomial "
                  "det(lam^2 M + lam D + K) (Weierstrass/Gerschgorin inclusion disks, warm-started along rows); "
                  "certified eigenvalue verdicts where the disks do not decide")


@dataclass(frozen=True, eq=False)
class CharpolyTable:
    """``det(λ²M + λD + K)`` of a model's zero state as a polynomial in ``λ`` and two axes (exact, then rounded).

    Attributes
    ----------
    outer, inner : str
        The axes (settable names): ``x`` and ``y`` of the table.
    Q : ndarray, shape (2n + 1, da + 1, db + 1)
        ``Q[k, a, b]``: coefficient of ``λ^k x^a y^b`` rounded to the nearest
        double (the exact polynomial has rational coefficients; each row of the
        pencil was multiplied by the least common multiple of its entries'
        denominators, a polynomial in ``x, y`` that does not change the roots
        where it does not vanish — and where it vanishes every coefficient does).
    RQ : ndarray
        Rounding radii of ``Q``.
    """

    outer: str
    inner: str
    Q: np.ndarray
    RQ: np.ndarray

    @property
    def degree(self) -> int:
        """Degree ``2n`` in ``λ``."""
        return int(self.Q.shape[0] - 1)


def _nd_form(spec: Any) -> tuple[Any, ...] | None:
    """Symbolic zero-state ``M, D, K`` and residuals of a rate-free model whose pads provably touch and slide."""
    import sympy as sp

    from ..codegen import compile_model
    from ..symbolic.assemble import build_equations
    from ..symbolic.linearize import model_closed_form

    cm = compile_model(spec)
    if not all(cm.rate_free_at_zero):
        return None
    cf = model_closed_form(spec)
    if cf.rate_blocks:
        return None
    S = cf.symbols
    names = tuple(spec.parameters)
    kip = set(spec.stiffness_names())
    eq = build_equations(spec, "symengine")
    back = {sp.Symbol(pn): (1 / S[n] if n in kip else S[n]) for n, pn in zip(names, eq.param_names)}
    zero = {s: 0 for s in eq.x}

    def at_zero(e: Any) -> Any:
        return sp.factor_terms(sp.cancel(sp.sympify(e.subs(zero)).xreplace(back)))

    rows = list(eq.R) + (list(eq.G) if eq.G is not None else [])
    residuals = tuple(r for r in (at_zero(e) for e in rows) if r != 0)
    for c in eq.pads:
        fn = at_zero(c.F_n)
        speed2 = at_zero(sum((v * v for v in c.v_r), 0))
        if not (fn.is_positive and speed2.is_positive):
            return None
    return S, cf.M, cf.D, cf.K, residuals


def _charpoly_data(space: ParameterSpace, names: tuple[str, str]) -> dict[str, Any] | None:
    """The exact characteristic polynomial on the axes ``names`` as JSON-able data (hex floats), or ``None``.

    ``None`` also where SymPy cannot carry out a step (an expression it cannot
    convert): the route is an optimisation, and the eigenvalue route decides
    those maps.
    """
    import sympy as sp

    try:
        return _charpoly_exact(space, names)
    except (NotImplementedError, ValueError, TypeError, ArithmeticError, sp.PolynomialError, sp.SympifyError):
        return None


def _charpoly_exact(space: ParameterSpace, names: tuple[str, str]) -> dict[str, Any] | None:
    import sympy as sp
    from sympy.polys.matrices import DomainMatrix

    form = _memo(("nd-form", _key(space.model)), lambda: _nd_form(space.model))
    if form is None:
        return None
    S, M, D, K, residuals = form
    X = [sp.Symbol(f"X{i}", real=True) for i in range(2)]
    vals = space.symbolic(dict(zip(names, X)))
    if any(v in (sp.oo, -sp.oo, sp.zoo) for v in vals.values()):
        return None
    sub = {S[n]: vals[n] for n in space.model.parameters}
    if not all(_vanishes(r.xreplace(sub), X) for r in residuals):
        return None  # the silent motion is not identically trivial on the axes

    def exact(e: Any) -> Any:
        e = _exact_floats(sp.sympify(e).xreplace(sub))
        cs = _constants([e])
        if cs:  # π etc.: the exact rational of the double the float routes use
            e = e.xreplace({c: sp.Rational(float(c)) for c in cs})
        return sp.cancel(e)

    lam = sp.Symbol("lam")
    n = M.shape[0]
    rows = []
    for i in range(n):
        ent = [(exact(M[i, j]), exact(D[i, j]), exact(K[i, j])) for j in range(n)]
        # only entries rational in the axes (e.g. not exp(-Omega r / v_s) of a Stribeck law): the lcm and the
        # expansion of transcendental entries grow without bound (memory), and the route would not apply anyway
        if not all(e.is_rational_function(*X) for t in ent for e in t):
            return None
        dens = [sp.fraction(e)[1] for t in ent for e in t]
        lcm = sp.lcm(dens) if dens else sp.Integer(1)
        rows.append([sp.expand(lcm * (lam ** 2 * a + lam * b_ + c)) for a, b_, c in ent])
    try:
        dm = DomainMatrix.from_Matrix(sp.Matrix(rows))
    except Exception:
        return None
    dom = dm.domain
    if not (getattr(dom, "is_PolynomialRing", False) and dom.domain in (sp.QQ, sp.ZZ)):
        return None
    gens = [str(g) for g in dom.symbols]
    if not set(gens) <= {"X0", "X1", "lam"}:
        return None
    P = sp.Poly(dom.to_sympy(dm.det()), lam, *X)
    m = 2 * n
    if P.is_zero or P.degree(lam) != m:
        return None
    da, db = max(P.degree(X[0]), 0), max(P.degree(X[1]), 0)
    q = [["0x0p+0"] * ((da + 1) * (db + 1)) for _ in range(m + 1)]
    for (k, a, b_), cval in P.terms():
        cq = sp.Rational(cval)
        v = float(Fraction(int(cq.p), int(cq.q)))  # correctly rounded
        if not math.isfinite(v):
            return None
        q[k][a * (db + 1) + b_] = v.hex()
    return {"shape": [m + 1, da + 1, db + 1], "q": q}


def charpoly_table(space: ParameterSpace, outer: str, inner: str) -> CharpolyTable | None:
    """The exact characteristic polynomial of a map's zero state in its two axes, or ``None`` where it does not apply.

    It applies to models of any size whose pads are rate-free at the zero
    state and provably touch and slide there, when every zero-state residual
    vanishes identically on the axes under the space's ties (the silent
    motion is trivial on the whole map), no parameter is infinite and the
    pencil's entries are rational in the axes.  Built once per model, space
    and axes with SymPy (``DomainMatrix`` determinant over ``QQ[λ, x, y]``)
    and kept in the on-disk cache.

    Parameters
    ----------
    space : ParameterSpace
        The parameter space.
    outer, inner : str
        The axes (``x`` and ``y`` of :class:`CharpolyTable`).

    Returns
    -------
    CharpolyTable or None
    """
    names = (outer, inner)

    def build() -> CharpolyTable | None:
        data = _disk_json("charpoly", _space_ident(space, names), lambda: _charpoly_data(space, names))
        if data is None:
            return None
        shape = tuple(int(v) for v in data["shape"])
        Q = np.array([[float.fromhex(v) for v in row] for row in data["q"]]).reshape(shape)
        big = float(np.max(np.abs(Q)))
        if big > 0:  # an exact power-of-two scaling (the row multipliers make the integers huge): no overflow later
            Q = np.ldexp(Q, -math.frexp(big)[1])
        RQ = np.abs(Q) * _U + np.where(Q != 0, 2.0 ** -1074, 0.0)
        return CharpolyTable(outer, inner, np.ascontiguousarray(Q), np.ascontiguousarray(RQ))

    return _memo(("charpoly", _key(space.model), space.key(), names), build)  # type: ignore[no-any-return]


def charpoly_verdicts(table: CharpolyTable, outer_values: np.ndarray, inner_values: np.ndarray,
                      valid: np.ndarray | None = None, *, eigen: bool = True
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Certified verdicts, ``max Re λ`` and frequency on a grid from the exact characteristic polynomial.

    Parameters
    ----------
    table : CharpolyTable
        From :func:`charpoly_table`.
    outer_values, inner_values : ndarray
        Grid values of ``table.outer`` and ``table.inner``.
    valid : ndarray of bool, shape (outer, inner), optional
        Points to compute (default all).
    eigen : bool
        Require every root to be accurate to :data:`CHARPOLY_ACCURACY`
        (relative) before a point is reported (for ``max_real`` and the
        frequency); otherwise the verdict alone is certified.

    Returns
    -------
    codes, max_real, frequency : ndarray, shape (outer, inner)
        :data:`~.robust.STABLE`, :data:`~.robust.UNSTABLE` or
        :data:`~.robust.UNDECIDED` (recompute those by another route; their
        ``max_real`` and frequency are NaN); ``max_real`` [1/s] and the
        frequency [Hz] of the root with the largest real part.

    Notes
    -----
    Every coefficient carries a rigorous bound of its rounding error; the
    roots are found by compiled Weierstrass (Durand-Kerner) sweeps and the
    verdict is read from the Gerschgorin disks of the generalized companion
    matrix ``diag(z) - 1 Wᵀ``, which contain every root of every polynomial
    within the coefficient bounds (:func:`~._compiled.charpoly_grid`).
    """
    from ._compiled import PARALLEL_MIN, charpoly_grid, charpoly_grid_chunks

    xo = np.ascontiguousarray(outer_values, dtype=float)
    yi = np.ascontiguousarray(inner_values, dtype=float)
    shape = (xo.size, yi.size)
    ok = np.ones(shape, dtype=np.bool_) if valid is None else np.ascontiguousarray(np.broadcast_to(valid, shape))
    codes = np.empty(shape, dtype=np.uint8)
    mr = np.empty(shape)
    fr = np.empty(shape)
    if xo.size * yi.size >= PARALLEL_MIN and xo.size > CHARPOLY_BLOCK:
        # blocks of rows in parallel; each block warm-starts itself (results independent of the thread count)
        charpoly_grid_chunks(table.Q, table.RQ, xo, yi, ok, bool(eigen), CHARPOLY_ACCURACY, codes, mr, fr,
                             CHARPOLY_BLOCK)
    else:
        charpoly_grid(table.Q, table.RQ, xo, yi, ok, bool(eigen), CHARPOLY_ACCURACY, codes, mr, fr)
    return codes, mr, fr


def charpoly_point_verdicts(table: CharpolyTable, outer_values: np.ndarray, inner_values: np.ndarray, *,
                            eigen: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`charpoly_verdicts` at scattered points ``(outer_values[k], inner_values[k])`` (1-D arrays).

    Each point warm-starts from the previous one (e.g. the vertices of a
    boundary curve); the verdicts are certified the same way.
    """
    from ._compiled import charpoly_points

    xs, ys = np.broadcast_arrays(np.asarray(outer_values, dtype=float), np.asarray(inner_values, dtype=float))
    xs, ys = np.ascontiguousarray(xs.ravel()), np.ascontiguousarray(ys.ravel())
    codes = np.empty(xs.size, dtype=np.uint8)
    mr = np.empty(xs.size)
    fr = np.empty(xs.size)
    charpoly_points(table.Q, table.RQ, xs, ys, bool(eigen), CHARPOLY_ACCURACY, codes, mr, fr)
    return codes, mr, fr
