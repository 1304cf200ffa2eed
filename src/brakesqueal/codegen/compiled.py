r"""Numeric callables of any model, generated once from its symbolic equations and cached.

:func:`compile_model` assembles the equations of a
:class:`~brakesqueal.model.components.ModelSpec`
(:func:`~brakesqueal.symbolic.assemble.build_equations`), differentiates them
and generates Python source with common subexpressions eliminated
(:mod:`.printer`).  The source is cached on disk keyed on the model's
equations (not its default values) and the generator's own source, so a warm
start imports neither SymPy nor symengine.  The same source is bound to
``math`` (fast scalar calls) and to ``numpy`` (broadcast over parameter
arrays, for maps and sweeps).

Argument conventions (every function documents them in its docstring):

* ``x = (Q, Qdot, Qddot, L, Ldot)`` — coordinates, rates, accelerations,
  pad deformations and their rates (SI units);
* ``p`` — parameters in the model's canonical order with tangential
  stiffnesses replaced by compliances (:meth:`Parameters.vector
  <brakesqueal.model.parameters.Parameters.vector>`).
"""

from __future__ import annotations

import hashlib
import json
import math
import types
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

__all__ = ["CompiledModel", "compile_model", "model_key", "CONTACT_FIELDS"]

#: Per-pad outputs of ``contact(x, p)``, in this order.
CONTACT_FIELDS = ("F_n", "v_rx", "v_ry", "v_rz", "h", "hdot", "l")


def model_key(spec: Any) -> str:
    """Cache key of a model's equations: a hash of its components (not defaults, presets or texts).

    Parameters
    ----------
    spec : ModelSpec
        The model.

    Returns
    -------
    str
        ``"model-<20 hex digits>"``.
    """
    from ..model.io import spec_to_dict

    d = spec_to_dict(spec, presets=False)
    # every component table (a new kind of component is hashed without a change here); not the texts or values
    d = {k: v for k, v in d.items() if k not in ("name", "description", "reference", "parameters", "presets")}
    d["parameters"] = list(spec.parameters)  # the packing order, not the values
    text = json.dumps(d, sort_keys=True)
    return "model-" + hashlib.sha256(text.encode()).hexdigest()[:20]


@dataclass(frozen=True, eq=False)
class CompiledModel:
    """Compiled callables of one model.

    Attributes
    ----------
    spec : ModelSpec
        The model.
    coords : tuple of str
        Coordinates ``Q``.
    algebraic : tuple of str
        Pad deformations ``L``.
    param_names : tuple of str
        Names of the entries of ``p`` (compliance names for tangential stiffnesses).
    residuals : callable
        ``residuals(x, p) -> (n + m,)``: ``R`` then ``G``.
    jacobians : callable
        ``jacobians(x, p) -> ((n + m) * (3n + 2m),)``: ``d(R, G)/dx``, row-major.
    contact : callable
        ``contact(x, p)``: per pad the :data:`CONTACT_FIELDS`.
    zero_residuals, zero_jacobians : callable
        The same at ``x = 0`` as functions of ``p`` only (NumPy-bound: ``p``
        may hold broadcastable arrays).
    zero_residual_scale : callable
        ``f(p)``: per row of ``(R, G)`` at ``x = 0``, the sum over parameters
        of ``|p_k dF/dp_k|`` — the magnitude of the terms whose cancellation
        gives the residual, used to recognise a trivial silent motion to
        rounding (:func:`brakesqueal.analysis.equilibrium.silent_motion`).
    vectorized : module
        Every function bound to NumPy.
    source : str
        The generated source.
    rate_free_at_zero : tuple of bool
        Per pad deformation ``L``: whether its rate blocks ``R_Ldot``,
        ``G_Ldot`` vanish identically at the zero state (rate-independent
        friction), so that the quasi-static elimination is exact there.
    """

    spec: Any
    coords: tuple[str, ...]
    algebraic: tuple[str, ...]
    param_names: tuple[str, ...]
    residuals: Callable[..., tuple[float, ...]]
    jacobians: Callable[..., tuple[float, ...]]
    contact: Callable[..., tuple[float, ...]]
    vectorized: types.ModuleType
    source: str = field(repr=False)
    rate_free_at_zero: tuple[bool, ...] = ()

    @property
    def n(self) -> int:
        """Number of coordinates."""
        return len(self.coords)

    @property
    def m(self) -> int:
        """Number of pad deformations ``L``."""
        return len(self.algebraic)

    @property
    def nx(self) -> int:
        """Length of the state ``x``."""
        return 3 * self.n + 2 * self.m

    @property
    def zero_residuals(self) -> Callable[..., tuple[Any, ...]]:
        """``f(p)``: residuals at ``x = 0`` (NumPy-bound)."""
        return self.vectorized.zero_residuals

    @property
    def zero_jacobians(self) -> Callable[..., tuple[Any, ...]]:
        """``f(p)``: Jacobians at ``x = 0`` (NumPy-bound), row-major like :attr:`jacobians`."""
        return self.vectorized.zero_jacobians

    @property
    def zero_residual_scale(self) -> Callable[..., tuple[Any, ...]]:
        """``f(p)``: term magnitude of every residual row at ``x = 0`` (NumPy-bound)."""
        return self.vectorized.zero_residual_scale

    def jacobian_matrix(self, x: Any, p: Any) -> np.ndarray:
        """``d(R, G)/dx`` as an ``(n + m, 3n + 2m)`` array."""
        return np.asarray(self.jacobians(x, p), dtype=float).reshape(self.n + self.m, self.nx)

    def zero_jacobian_matrix(self, p: Any) -> np.ndarray:
        """``d(R, G)/dx`` at ``x = 0`` with structural zeros exact, as an ``(n + m, 3n + 2m)`` array."""
        vals = self.zero_jacobians(list(map(float, p)))
        return np.array([float(v) for v in vals], dtype=float).reshape(self.n + self.m, self.nx)

    def zero_linear(self, p: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Batched ``M, D, K`` about the zero state with the pad deformations eliminated (NumPy).

        Parameters
        ----------
        p : sequence of array_like
            Packing-order parameter arrays (broadcastable; see
            :meth:`ParameterSpace.vectors <brakesqueal.model.parameters.ParameterSpace.vectors>`).

        Returns
        -------
        M, D, K : ndarray, shape (..., n, n)
            Exact linearization at a trivial silent motion when every pad is
            rate-free there (:attr:`rate_free_at_zero`); otherwise the
            quasi-static part of the descriptor system.
        """
        n, m, nx = self.n, self.m, self.nx
        vals = self.zero_jacobians(list(p))
        shape = np.broadcast_shapes(*(np.shape(v) for v in vals))
        J = np.stack([np.broadcast_to(np.asarray(v, dtype=float), shape) for v in vals], axis=-1)
        J = J.reshape(*shape, n + m, nx)
        M, D, K = J[..., :n, 2 * n:3 * n], J[..., :n, n:2 * n], J[..., :n, :n]
        if m:
            with np.errstate(all="ignore"):
                GL = J[..., n:, 3 * n:3 * n + m]
                RL = J[..., :n, 3 * n:3 * n + m]
                P = np.swapaxes(np.linalg.solve(np.swapaxes(GL, -1, -2), np.swapaxes(RL, -1, -2)), -1, -2)
                M = M - P @ J[..., n:, 2 * n:3 * n]
                D = D - P @ J[..., n:, n:2 * n]
                K = K - P @ J[..., n:, :n]
        return M, D, K

    def contact_table(self, x: Any, p: Any) -> np.ndarray:
        """``contact(x, p)`` as an array ``(n_pads, len(CONTACT_FIELDS))``."""
        return np.asarray(self.contact(x, p), dtype=float).reshape(len(self.spec.pads), len(CONTACT_FIELDS))


def _generate(spec: Any) -> str:
    import symengine as se

    from ..symbolic.assemble import build_equations
    from .printer import FunctionSpec, generate_module

    eq = build_equations(spec)
    res = list(eq.R) + (list(eq.G) if eq.G is not None else [])
    X = se.Matrix(eq.x)
    jac: list[Any] = []
    for e in res:
        jac.extend(se.Matrix([e]).jacobian(X))
    zero = {s: 0 for s in eq.x}
    res0 = _structural_zeros([se.sympify(e).subs(zero) for e in res], eq.params)
    jac0 = _structural_zeros([se.sympify(e).subs(zero) for e in jac], eq.params)
    jac0 = _simplified_rate_columns(jac0, eq)
    scale0 = []
    for e in res0:
        terms = [se.Abs(pk * e.diff(pk)) for pk in eq.params]
        scale0.append(sum(terms, se.Integer(0)))
    contact: list[Any] = []
    for c, l in zip(eq.pads, eq.tangential):
        contact += [c.F_n, c.v_r[0], c.v_r[1], c.v_r[2], c.h, c.hdot, l]
    n, m = len(eq.coords), len(eq.algebraic)
    nx = 3 * n + 2 * m
    rate_free = [all(jac0[i * nx + 3 * n + m + j] == 0 for i in range(n + m))
                 and all(jac0[(n + j) * nx + 3 * n + m + k] == 0 for k in range(m)) for j in range(m)]
    meta: dict[str, Any] = {"coords": list(eq.coords), "algebraic": list(eq.algebraic), "params": list(eq.param_names),
            "x": [str(s) for s in eq.x], "rate_free_at_zero": rate_free}
    header = (f"Generated by brakesqueal for the equations of model {spec.name!r}. Do not edit.\n\n"
              f"x = ({', '.join(meta['x'])})\np = ({', '.join(meta['params'])})")
    xa, pa = ("x", eq.x), ("p", eq.params)
    specs = [
        FunctionSpec("residuals", (xa, pa), res, "(R, G) at the state x: eqs. (44), (33)-(34) generalized."),
        FunctionSpec("jacobians", (xa, pa), jac, "d(R, G)/dx, row-major (n + m) x (3n + 2m)."),
        FunctionSpec("rate_jacobians", (xa, pa), [jac[r * nx + 3 * n + m + j] for r in range(n + m) for j in range(m)],
                     "d(R, G)/dLdot, row-major (n + m) x m: the pads' rate coefficients alone (checked in extended "
                     "precision at tilted silent motions)."),
        FunctionSpec("contact", (xa, pa), contact,
                     "Per pad: F_n [N], v_r (3) [m/s], h [m], hdot [m/s], l [m] (eqs. 12-34)."),
        FunctionSpec("zero_residuals", (pa,), res0, "(R, G) at x = 0."),
        FunctionSpec("zero_jacobians", (pa,), jac0, "d(R, G)/dx at x = 0, row-major."),
        FunctionSpec("zero_residual_scale", (pa,), scale0, "Sum_k |p_k d(R, G)/dp_k| at x = 0, per row."),
    ]
    return generate_module(specs, header) + f"META = {meta!r}\n"


def _simplified_rate_columns(jac0: list[Any], eq: Any) -> list[Any]:
    """Zero-state Jacobian entries of the pads' rates (``Ldot`` columns, ``Qddot`` columns of ``G``), simplified.

    These entries decide whether a pad keeps its tangential rate
    (:func:`brakesqueal.analysis.linear.linearize`).  As generated they are
    differences of terms that cancel analytically (e.g. ``1/|Omega r| -
    Omega^2 r^2/|Omega r|^3``), whose rounding noise would otherwise pose as a
    tiny non-zero rate coefficient and a spurious pad mode of order
    ``1/noise``; simplified with SymPy (parameters positive, except the disk
    faces' distances) the cancellation is done exactly, and exponentials stay
    in the numerators (:func:`~brakesqueal.symbolic.linearize.simplify_entry`:
    a Stribeck decay ``exp(-v/v_s)`` is never evaluated as ``1/exp(v/v_s)``).
    """
    n, m = len(eq.coords), len(eq.algebraic)
    nx = 3 * n + 2 * m
    cols = set(range(3 * n + m, nx))
    todo = [k for k, e in enumerate(jac0) if not e.is_Number
            and (k % nx in cols or (k // nx >= n and 2 * n <= k % nx < 3 * n))]
    if not todo:
        return jac0
    import sympy as sp
    import symengine as se

    from ..symbolic.linearize import simplify_entry

    spec = eq.spec
    real = {v for v in (spec.disk.h_upper, spec.disk.h_lower) if isinstance(v, str)}
    pos = {sp.Symbol(str(p)): (sp.Symbol(str(p), real=True) if name in real else sp.Symbol(str(p), positive=True))
           for p, name in zip(eq.params, spec.parameters)}
    back = {v: k for k, v in pos.items()}
    out = list(jac0)
    for k in todo:
        v = simplify_entry(sp.sympify(str(jac0[k])).xreplace(pos)).xreplace(back)
        out[k] = se.sympify(v)
    return out


def _structural_zeros(exprs: list[Any], params: list[Any], points: int = 2) -> list[Any]:
    """Replace expressions that vanish identically by the exact 0.

    At ``x = 0`` several residuals and Jacobian entries are identically zero
    but are generated as cancelling terms (e.g.
    ``N0 mu/sqrt(Omega^2 r^2) - N0 mu r^2 Omega^2/(Omega^2 r^2)^(3/2)``), which
    floating point turns into rounding noise.  Each entry is evaluated
    *exactly* (symengine rational arithmetic) at ``points`` random points
    where every parameter is the square of a positive rational (so the square
    roots of the contact kinematics stay rational); an entry that is exactly
    0 at every point is an identity 0 on the domain (a polynomial-identity
    test; an entry that does not reduce to a rational is left alone).
    """
    import symengine as se

    rng = np.random.default_rng(20261123)
    zero = [not (e.is_Number and float(e) == 0.0) for e in exprs]
    for _ in range(points):
        vals = {}
        for p in params:
            a, b = (int(v) for v in rng.integers(2, 97, size=2))
            vals[p] = se.Rational(a * a, b * b)
        for i, e in enumerate(exprs):
            if zero[i]:
                v = se.sympify(e).xreplace(vals)
                zero[i] = bool(v.is_Number and v == 0)
    return [se.Integer(0) if z else e for z, e in zip(zero, exprs)]


def _namespace(lib: str) -> dict[str, Any]:
    ns: Any = math if lib == "math" else np
    return dict(sin=ns.sin, cos=ns.cos, tan=ns.tan, sqrt=ns.sqrt, exp=ns.exp, log=ns.log,
                abs=abs if lib == "math" else np.abs, pi=math.pi)


_COMPILED: dict[tuple[str, bool], CompiledModel] = {}


def _compiled(key: str, spec: Any, use_cache: bool) -> CompiledModel:
    from . import cache

    if (key, use_cache) in _COMPILED:
        return _COMPILED[(key, use_cache)]
    scalar = cache.load_module(key, "model.py", lambda: _generate(spec), use_cache=use_cache,
                               namespace=_namespace("math"), variant="math")
    source: str = scalar.__source__
    vec = cache.load_module(key, "model.py", lambda: source, use_cache=use_cache, namespace=_namespace("numpy"),
                            variant="numpy")
    meta = scalar.META
    cm = CompiledModel(spec=spec, coords=tuple(meta["coords"]), algebraic=tuple(meta["algebraic"]),
                       param_names=tuple(meta["params"]), residuals=scalar.residuals,
                       jacobians=scalar.jacobians, contact=scalar.contact, vectorized=vec, source=source,
                       rate_free_at_zero=tuple(meta.get("rate_free_at_zero", ())))
    _COMPILED[(key, use_cache)] = cm
    return cm


def compile_model(spec: Any, *, use_cache: bool = True) -> CompiledModel:
    """Generate (or load from the cache) the numeric code of a model.

    Parameters
    ----------
    spec : ModelSpec or str
        The model, or a built-in model name / model file.
    use_cache : bool, optional
        Read and write the on-disk cache (default ``True``); ``False``
        generates in-process and leaves the cache untouched.

    Returns
    -------
    CompiledModel
        Memoized per process by the model's equations.
    """
    from ..model.parameters import as_model_spec

    spec = as_model_spec(spec)
    cm = _compiled(model_key(spec), spec, use_cache)
    if cm.spec is not spec:
        cm = CompiledModel(spec=spec, coords=cm.coords, algebraic=cm.algebraic, param_names=cm.param_names,
                           residuals=cm.residuals, jacobians=cm.jacobians, contact=cm.contact,
                           vectorized=cm.vectorized, source=cm.source, rate_free_at_zero=cm.rate_free_at_zero)
    return cm
