r"""The closed forms behind the generated stability kernels: all computer algebra of the stability routes.

The stability routes (:mod:`brakesqueal.analysis`) never run SymPy; what they
need of a model's closed form is computed here once, turned into tables or
source text by :mod:`brakesqueal.codegen.stability` and kept in the on-disk
cache, so that a warm start imports no computer algebra.

* :func:`build_model_form` — ``Mbar, Dbar, Kbar`` of a model with two
  coordinates and rate-free pads about its zero state, in packing symbols
  (tangential stiffnesses as compliances ``c = 1/k_ip``), with the zero-state
  residuals (eq. 49 for the paper's model) that say where the silent motion
  is trivial.
* :func:`quartic_numerators` — that closed form specialised to a parameter
  space with some axes symbolic: ``a_i = N_i / Den`` of
  ``det(λ²M + λD + K)`` with exact numerator polynomials (rational function
  field over QQ; constants such as π are extra generators).
* :func:`grid_table`, :func:`univariate_table` — those numerators as data:
  the coefficient table of the compiled grid kernel, and exact univariate
  coefficients for the exact crossings of :mod:`brakesqueal.analysis.crossings`.
* :func:`entry_slots`, :func:`omega_slots`, :func:`exact_entries_source`,
  :func:`exact_omega_source` — the closed-form entries term by term (bounded
  floating-point kernels, exact rational evaluation).
* :func:`rate_block_exprs` — the pads' zero-state rate blocks, simplified
  (no cancellation noise).
* :func:`nd_form`, :func:`charpoly_data` — the exact characteristic
  polynomial of a zero state of any size on two axes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ..model.components import ModelSpec
    from ..model.parameters import ParameterSpace

__all__ = [
    "ModelForm", "build_model_form", "QuarticNumerators", "quartic_numerators", "grid_table", "univariate_table",
    "entry_slots", "omega_slots", "exact_entries_source", "exact_omega_source", "rate_block_exprs", "nd_form",
    "charpoly_data", "MAX_INNER_DEGREE", "MAX_OUTER_DEGREE", "UNIVARIATE_DIGITS",
]

#: Grid kernels are refused (callers use the per-point routes) above these inner / outer degrees.
MAX_INNER_DEGREE = 12
MAX_OUTER_DEGREE = 40
#: Significant digits of constants (π, √3, ...) in the exact univariate tables (then marked inexact).
UNIVARIATE_DIGITS = 80


# ---------------------------------------------------------------- model closed forms
@dataclass(frozen=True, eq=False)
class ModelForm:
    """Closed-form ``M, D, K`` of a 2-DOF model about its zero state, in packing symbols.

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


def _zero_state(spec: ModelSpec, names: tuple[str, ...], comp: tuple[bool, ...], S: dict[str, Any]
                ) -> tuple[tuple[Any, ...], bool]:
    """Non-zero zero-state residuals in the model's symbols, and whether every pad provably touches and slides."""
    import sympy as sp

    from .assemble import build_equations

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
            return residuals, False
    return residuals, True


def build_model_form(spec: ModelSpec, key: str, param_names: tuple[str, ...], n: int, rate_free: tuple[bool, ...]
                     ) -> ModelForm | None:
    """The closed form of a model for the generated kernels, or ``None`` where it does not apply.

    It applies to models with two coordinates whose pads are all rate-free at
    the zero state and provably (from the parameter roles) in sliding contact
    there, with Laurent-polynomial entries in the packing symbols.

    Parameters
    ----------
    spec : ModelSpec
        The model.
    key : str
        Its :func:`~brakesqueal.codegen.model_key`.
    param_names : tuple of str
        The generated code's parameter names (compliance names for tangential stiffnesses).
    n : int
        Number of coordinates.
    rate_free : tuple of bool
        Per pad deformation: its rate blocks vanish at the zero state
        (:attr:`~brakesqueal.codegen.compiled.CompiledModel.rate_free_at_zero`).

    Returns
    -------
    ModelForm or None
    """
    import sympy as sp

    from .linearize import model_closed_form

    if n != 2 or not all(rate_free):
        return None
    cf = model_closed_form(spec)
    if cf.rate_blocks:
        return None
    S = cf.symbols
    kip = set(spec.stiffness_names())
    names = tuple(spec.parameters)
    comp = tuple(n in kip for n in names)
    syms = tuple(sp.Symbol(pn, nonnegative=True) if c else S[n] for n, pn, c in zip(names, param_names, comp))
    rep = {S[n]: 1 / s for n, s, c in zip(names, syms, comp) if c}

    def conv(m: Any) -> Any:
        return m.xreplace(rep).applyfunc(sp.cancel)

    # zero-state residuals and contact in the model's (positive) symbols: sqrt(Omega^2 r^2) -> Omega r
    residuals, sliding = _zero_state(spec, names, comp, S)
    if not sliding:
        return None
    M, D, K = conv(cf.M), conv(cf.D), conv(cf.K)
    try:
        for X in (M, D, K):
            for e in X:
                terms(e, list(syms))
    except NotImplementedError:  # not a Laurent polynomial in the parameters: no generated kernels
        return None
    omega = spec.disk.Omega if isinstance(spec.disk.Omega, str) else None
    omega_free = omega is None or all(S[omega] not in r.free_symbols for r in residuals)
    return ModelForm(key=key, names=names, symbols=syms, compliance=comp, M=M, D=D,
                     K=K, model_symbols=dict(S), residuals=residuals, omega=omega, omega_free=omega_free)


# ---------------------------------------------------------------- rate blocks
def rate_block_exprs(spec: ModelSpec) -> tuple[int, int, list[Any], list[Any]]:
    """The zero-state rate blocks ``R_dL``, ``G_dL``, ``G_ddQ`` of a model, simplified (SymPy).

    At the zero state a massless pad's rate terms are differences of terms
    that cancel exactly for a constant friction coefficient; simplified with
    the parameters' signs from their roles (``sqrt(Omega^2 r^2) = Omega r``)
    only the genuine part remains (e.g. ``c_ip N0 mu'(v*)`` of a falling
    friction law) and an exact zero stays zero.

    Returns
    -------
    n, m : int
        Coordinates and pad deformations.
    args : list
        SymPy symbols of the packing slots (compliances for tangential stiffnesses).
    exprs : list
        ``R_dL`` (n × m), ``G_dL`` (m × m), ``G_ddQ`` (m × n), row-major, concatenated.
    """
    import sympy as sp
    import symengine as se

    from .assemble import build_equations
    from .linearize import model_closed_form, simplify_entry

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
    return n, m, args, exprs


# ---------------------------------------------------------------- specialisation to a parameter space
def _specialise(form: ModelForm, space: ParameterSpace, axes: dict[str, Any]
                ) -> tuple[Any, Any, Any, list[Any]]:
    """Closed-form matrices with the space's values (axes symbolic) and the zero-state residuals."""
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

    def hurwitz(self) -> Any:
        """``H3`` of the numerators, ``N1 (N3 N2 - N4 N1) - N3² N0`` (exact)."""
        n0, n1, n2, n3, n4 = self.N
        return n1 * (n3 * n2 - n4 * n1) - n3 ** 2 * n0


def quartic_field(entries: list[Any], symbols: list[Any]) -> tuple[tuple[Any, ...], Any, tuple[Any, ...]] | None:
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


def _negligible(r: Any, msub: dict[Any, Any], syms: list[Any]) -> bool:
    """Whether a zero-state residual vanishes *to rounding* for every value of the axes ``syms``.

    The symbolic analogue of :func:`brakesqueal.analysis.equilibrium.is_trivial` (the one rule,
    :data:`brakesqueal.status.TRIVIAL_NOISE_FLOOR`): the residual's numerator, a polynomial in the model's
    symbols, is written term by term with the space's values (ties as functions of the axes, numbers as the
    exact rationals of their doubles) over a common denominator; for every monomial of the axes the exact sum
    of its coefficients must be at most ``TRIVIAL_NOISE_FLOOR eps`` times the sum of their magnitudes, each
    weighted by its term's degree in the parameters (the ``sum_k |p_k dF/dp_k|`` of the pointwise rule).  An
    identically vanishing residual passes; so do the float-equal sets of ``mu1 h10 = mu2 h20`` (eq. 49) that
    :func:`~brakesqueal.analysis.equilibrium.silent_motion` calls trivial.  Where the terms are not polynomial in
    the axes, the exact identity test decides.
    """
    import sympy as sp

    from ..status import TRIVIAL_NOISE_FLOOR

    if r == 0:
        return True
    try:
        num = sp.numer(sp.together(r))
        tms = sp.Add.make_args(sp.expand(num))
        parts = []
        for t in tms:
            w = sum(int(e) for b, e in t.as_powers_dict().items() if b.is_Symbol and e.is_Integer and e > 0) or 1
            v = sp.together(_exact_floats(sp.sympify(t).xreplace(msub)))
            n_, d_ = sp.fraction(v)
            parts.append((w, n_, d_))
        den = sp.Integer(1)
        for _, _, d_ in parts:
            den = sp.lcm(den, d_)
        signed: dict[Any, Any] = {}
        mags: dict[Any, float] = {}
        gens = list(syms)
        for w, n_, d_ in parts:
            poly = sp.Poly(sp.expand(n_ * sp.cancel(den / d_)), *gens) if gens else None
            items = poly.terms() if poly is not None else [((), sp.expand(n_ * sp.cancel(den / d_)))]
            for mon, c in items:
                if not c.is_number:
                    raise ValueError("not polynomial in the axes")
                signed[mon] = signed.get(mon, 0) + c
                mags[mon] = mags.get(mon, 0.0) + w * abs(float(c))
        eps = 2.0 ** -52
        return all(abs(float(signed[m])) <= TRIVIAL_NOISE_FLOOR * eps * mags[m] for m in signed)
    except (ValueError, TypeError, sp.PolynomialError, sp.GeneratorsNeeded):
        return _vanishes(r.xreplace(msub), syms)


def quartic_numerators(form: ModelForm | None, space: ParameterSpace, names: tuple[str, ...]
                       ) -> QuarticNumerators | None:
    """Exact numerators of ``a0..a4`` with the axes ``names`` symbolic (trivial silent motion).

    Parameters
    ----------
    form : ModelForm or None
        The model's closed form (``None``: no closed form, the result is ``None``).
    space : ParameterSpace
        The parameter space (any model).
    names : tuple of str
        Settable names of ``space`` kept symbolic.

    Returns
    -------
    QuarticNumerators or None
        ``None`` when the model has no closed form, the silent motion is not
        identically trivial on the axes (a zero-state residual of the model
        does not vanish identically under the space's ties, e.g.
        ``mu1 h10 != mu2 h20`` somewhere for the paper's model, eq. 49) or the
        dependence on an axis is not rational.
    """
    import sympy as sp

    if form is None:
        return None
    names = tuple(names)
    syms = [sp.Symbol(f"X{i}", real=True) for i in range(len(names))]
    M, D, K, residuals = _specialise(form, space, dict(zip(names, syms)))
    vals = space.symbolic(dict(zip(names, syms)))
    msub = {form.model_symbols[n]: vals[n] for n in form.names}
    if not all(_negligible(r, msub, syms) for r in form.residuals):
        return None
    res = quartic_field(list(M) + list(D) + list(K), syms)
    if res is None:
        return None
    N, den, consts = res
    return QuarticNumerators(names, consts, N, den)


def _const_values(consts: tuple[Any, ...], dps: int = 60) -> list[Any]:
    import mpmath
    import sympy as sp

    with mpmath.workdps(dps):
        return [mpmath.mpf(sp.N(c, dps + 10)) for c in consts]


def _numeric_terms(poly: Any, n_axes: int, consts: tuple[Any, ...]) -> dict[tuple[int, ...], Any]:
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


def grid_table(qn: QuarticNumerators | None, names: tuple[str, ...]) -> dict[str, Any] | None:
    """The coefficient table of a grid kernel as JSON-able data (exact mantissas as hex), or ``None``.

    The numerators are polynomials in one *inner* axis (the one of lowest
    total degree; ties: the trailing axis) whose coefficients are monomials
    in the other axes; every term is ``mant 2^e2 Π outer^exps`` in column
    ``slot`` (``(i, k)``: coefficient of ``inner^k`` in ``N_i``).  ``None``
    above :data:`MAX_INNER_DEGREE` / :data:`MAX_OUTER_DEGREE`.
    """
    if qn is None or not names:
        return None
    nax = len(names)
    tms = [_numeric_terms(p, nax, qn.constants) for p in qn.N]
    degs = [tuple(max((m[j] for m in t), default=0) for t in tms) for j in range(nax)]
    totals = [sum(d) for d in degs]
    inner = max(i for i in range(nax) if totals[i] == min(totals))  # ties: the trailing axis
    degrees = degs[inner]
    if max(degrees) > MAX_INNER_DEGREE:
        return None
    offs = [0]
    for d in degrees:
        offs.append(offs[-1] + d + 1)
    rows_e, rows_k, rows_s, rows_m, rows_x = [], [], [], [], []
    for i, t in enumerate(tms):
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
    ncol = offs[-1]
    nterms = [0] * ncol
    tdeg = [0] * ncol
    for s, ex in zip(rows_s, rows_e):
        nterms[s] += 1
        tdeg[s] = max(tdeg[s], sum(ex))
    nops = [float(a + b + 4) for a, b in zip(nterms, tdeg)]
    return {"inner": int(inner), "degrees": [int(d) for d in degrees], "exps": rows_e, "ipow": rows_k,
            "slot": rows_s, "mant": [float(m).hex() for m in rows_m], "e2": rows_x, "nops": nops}


def _mpf_fraction(v: Any) -> Fraction:
    import mpmath

    sign, man, exp, _ = mpmath.mpf(v)._mpf_
    man = -int(man) if sign else int(man)
    return Fraction(man * 2 ** exp) if exp >= 0 else Fraction(man, 2 ** (-exp))


def _univariate(poly: Any, consts: tuple[Any, ...]) -> tuple[list[Fraction], bool]:
    """Ascending Fraction coefficients in the first generator; ``exact`` False when constants were rounded."""
    import mpmath
    import sympy as sp

    if not consts:
        deg = max((m[0] for m in poly.monoms()), default=0)
        out = [Fraction(0)] * (deg + 1)
        for mon, c in poly.terms():
            out[mon[0]] += Fraction(int(c.numerator), int(c.denominator))
        return out, True
    digits = UNIVARIATE_DIGITS
    with mpmath.workdps(digits + 20):
        cv = [mpmath.mpf(sp.N(c, digits + 30)) for c in consts]
        acc: dict[int, Any] = {}
        for mon, c in poly.terms():
            v = mpmath.mpf(int(c.numerator)) / int(c.denominator)
            for g, k in zip(cv, mon[1:]):
                v *= g ** k
            acc[mon[0]] = acc.get(mon[0], 0) + v
        deg = max(acc, default=0)
        out = [Fraction(0)] * (deg + 1)
        for k, v in acc.items():
            with mpmath.workdps(digits):
                out[k] = _mpf_fraction(+v)
    return out, False


def univariate_table(qn: QuarticNumerators | None) -> dict[str, Any] | None:
    """Exact univariate coefficients of ``N_0..N_4``, ``H3(N)`` and ``Den`` in one axis, as JSON-able data.

    Returns
    -------
    dict or None
        ``{"N": [5 lists], "H": list, "den": list, "exact": bool}``, ascending
        coefficients as ``"p/q"`` strings; ``exact`` is false when constants
        (π, ...) were rounded to :data:`UNIVARIATE_DIGITS` significant digits.
        ``None`` for ``qn is None``.
    """
    if qn is None:
        return None
    exact = True
    polys = []
    for p in (*qn.N, qn.hurwitz(), qn.den):
        c, ex = _univariate(p, qn.constants)
        exact &= ex
        polys.append([f"{v.numerator}/{v.denominator}" for v in c])
    return {"N": polys[:5], "H": polys[5], "den": polys[6], "exact": exact}


# ---------------------------------------------------------------- entries term by term
def terms(expr: Any, syms: list[Any]) -> list[tuple[Any, dict[int, int]]]:
    """Expanded terms ``c Π syms^k`` of a Laurent polynomial in ``syms``.

    Raises
    ------
    NotImplementedError
        A term that is not a Laurent monomial in ``syms``.
    """
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


def _float_slots(slots: list[list[tuple[Any, dict[int, int]]]]) -> list[list[tuple[float, dict[int, int]]]]:
    import sympy as sp

    return [[(float(sp.Float(c, 30)), p) for c, p in s] for s in slots]


def entry_slots(form: ModelForm) -> list[list[tuple[float, dict[int, int]]]]:
    """The 12 entries of ``M, D, K`` (row-major) term by term: ``(coefficient, {slot: power})`` per term."""
    args = list(form.symbols)
    return _float_slots([terms(X[i, j], args) for X in (form.M, form.D, form.K) for i in range(2) for j in range(2)])


def _omega_terms(form: ModelForm) -> list[list[tuple[Any, dict[int, int]]]]:
    if form.omega is None:
        raise NotImplementedError(f"model {form.key}: the disk's spin is a number, not a parameter")
    args = list(form.symbols)
    iw = form.names.index(form.omega)
    W = args[iw]
    slots = []
    for m in (form.M, form.D, form.K):
        for i in range(2):
            for j in range(2):
                groups: list[list[tuple[Any, dict[int, int]]]] = [[], [], [], []]
                for c, powers in terms(m[i, j] * W, args):
                    k = powers.pop(iw, 0)
                    if not 0 <= k <= 3:
                        raise NotImplementedError("closed form is not a Laurent polynomial in Omega of "
                                                  "degree <= 2")
                    groups[k].append((c, powers))
                slots.extend(groups)
    return slots


def omega_slots(form: ModelForm) -> list[list[tuple[float, dict[int, int]]]]:
    """Coefficients of ``Ω · entry`` in ``Ω^0``–``Ω^3`` for the 12 entries (48 slots), term by term.

    Raises
    ------
    NotImplementedError
        The spin is a number, or an entry is not a Laurent polynomial in Ω of degree at most 2.
    """
    return _float_slots(_omega_terms(form))


def _fraction_source(fname: str, slots: list[list[tuple[Any, dict[int, int]]]], doc: str) -> str:
    """Python source ``fname(x) -> list of Fraction``: every slot's terms in exact rational arithmetic.

    Irrational coefficients are written as their :data:`UNIVARIATE_DIGITS`-digit rational
    approximations and the module's ``EXACT`` is then ``False``.
    """
    import sympy as sp

    lines = [f'"""Generated by brakesqueal.symbolic.stability_forms: {doc} (Fraction arithmetic). Do not edit."""',
             "from fractions import Fraction", "", "", f"def {fname}(x):", f'    """{doc}."""',
             "    F = Fraction", "    out = []"]
    exact = True
    for s in slots:
        tms = []
        for c, powers in s:
            c = sp.sympify(c)
            if c.is_Rational:
                cq = Fraction(int(c.p), int(c.q))
            elif c.is_Float:  # a number of the model file: the double it is
                cq = Fraction(float(c))
            else:
                exact = False
                cq = Fraction(str(sp.N(c, UNIVARIATE_DIGITS)))
            fac = [f"F({cq.numerator}, {cq.denominator})"]
            fac += [f"x[{k}] ** {p}" if p != 1 else f"x[{k}]" for k, p in sorted(powers.items())]
            tms.append(" * ".join(fac))
        lines.append(f"    out.append({' + '.join(tms) if tms else 'F(0)'})")
    lines += ["    return out", "", "", f"EXACT = {exact!r}", ""]
    return "\n".join(lines)


def exact_entries_source(form: ModelForm) -> str:
    """Source of ``entries(x)``: the 12 entries of ``M, D, K`` at an exact rational parameter vector ``x``."""
    args = list(form.symbols)
    slots = [terms(X[i, j], args) for X in (form.M, form.D, form.K) for i in range(2) for j in range(2)]
    return _fraction_source("entries", slots, "Mbar, Dbar, Kbar entries (row-major)")


def exact_omega_source(form: ModelForm) -> str:
    """Source of ``omega_entries(x)``: coefficients of ``Ω·entry`` in ``Ω^0..Ω^3`` (48 values, exact)."""
    return _fraction_source("omega_entries", _omega_terms(form), "Laurent coefficients of Omega * entry in Omega")


# ---------------------------------------------------------------- n-DOF: the exact characteristic polynomial
def nd_form(spec: ModelSpec, rate_free: tuple[bool, ...]) -> tuple[Any, ...] | None:
    """Symbolic zero-state ``M, D, K`` and residuals of a rate-free model whose pads provably touch and slide."""
    from .linearize import model_closed_form

    if not all(rate_free):
        return None
    cf = model_closed_form(spec)
    if cf.rate_blocks:
        return None
    S = cf.symbols
    names = tuple(spec.parameters)
    kip = set(spec.stiffness_names())
    residuals, sliding = _zero_state(spec, names, tuple(n in kip for n in names), S)
    if not sliding:
        return None
    return S, cf.M, cf.D, cf.K, residuals


def charpoly_data(form: tuple[Any, ...] | None, space: ParameterSpace, names: tuple[str, str]
                  ) -> dict[str, Any] | None:
    """The exact characteristic polynomial on the axes ``names`` as JSON-able data (hex floats), or ``None``.

    ``None`` also where SymPy cannot carry out a step (an expression it cannot
    convert): the route is an optimisation, and the eigenvalue route decides
    those maps.
    """
    import sympy as sp

    if form is None:
        return None
    try:
        return _charpoly_exact(form, space, names)
    except (NotImplementedError, ValueError, TypeError, ArithmeticError, sp.PolynomialError, sp.SympifyError):
        return None


def _charpoly_exact(form: tuple[Any, ...], space: ParameterSpace, names: tuple[str, str]) -> dict[str, Any] | None:
    import sympy as sp
    from sympy.polys.matrices import DomainMatrix

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
