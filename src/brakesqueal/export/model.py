r"""The language-neutral description of what :mod:`brakesqueal.export` writes, for any model.

:func:`export_model` turns the symbolic equations of a
:class:`~brakesqueal.model.components.ModelSpec`
(:func:`~brakesqueal.symbolic.assemble.build_equations`, closed forms from
:func:`~brakesqueal.symbolic.linearize.model_closed_form`) into a list of
:class:`ExportFunction` (SymPy expressions, common subexpressions eliminated
with :func:`sympy.cse`) plus the argument and unit conventions every printer
writes into its header.  The printers (:mod:`.printers`, :mod:`.latex`) only
format what is described here and add small hand-written helpers (the pad
solver, the right-hand side, a linear solve).

Nonlinear export (``what="nonlinear"``), with ``n`` coordinates ``Q`` and
``m`` pad deformations ``L``:

* ``residuals(x, p)``: ``R`` (eq. 44 generalized) then ``G`` (eqs. 33-34) at
  the full state ``x = (Q, Qdot, Qddot, L, Ldot)``, exact.
* ``pad_residuals(y, z, p)`` and ``pad_residual_scale(y, z, p)`` (``m > 0``):
  ``G`` and its Jacobian with respect to the pad unknowns ``z``, and the sum
  of the magnitudes of ``G``'s terms (the rounding floor of the Newton solve).
* ``mass_force(y, z, p)``: ``M`` (``n × n``, row-major) and ``f`` with
  ``R = M Qddot + f``.

The ODE state is ``y = (Q, Qdot, L_kept)``.  A pad whose rate blocks vanish
at the zero state (rate-independent friction) is quasi-static, as in the
simulator and the linearization: ``ldot = 0`` and its ``l`` is a pad
unknown in ``z``.  A pad with a rate-dependent friction law keeps its
first-order dynamics (:mod:`brakesqueal.analysis.linear`): its ``l`` is part
of ``y`` and its rate ``ldot`` is the pad unknown in ``z``.

Linear export (``what="linear"``): ``linear_matrices(p)``, the closed-form
``M, D, K`` about the zero state (eq. 47; the pads' deformations eliminated
where that is exact) plus, for pads that keep their dynamics, the blocks
``R_L, R_dL, G_Q, G_dQ, G_L, G_dL`` of the descriptor system.  Valid only
where the zero state is the silent motion (checked).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

from ..errors import BrakesquealError, ParameterError
from .names import (
    coordinate_unit,
    latex_symbol,
    local_names,
    rate_unit,
    residual_label,
    residual_unit,
)

if TYPE_CHECKING:
    from ..model.components import ModelSpec
    from ..model.parameters import Parameters
    from ..symbolic.assemble import Equations

__all__ = [
    "WHATS", "ExportFunction", "ExportModel", "export_model", "PARAMETER_UNITS", "STATE_UNITS",
    "NEWTON_RTOL", "NEWTON_MAXIT", "RESIDUAL_FLOOR", "temporary_name", "term_scale",
]  # fmt: skip

What = Literal["nonlinear", "linear"]
#: The two kinds of export, the nonlinear equations or the closed-form linear matrices.
WHATS: tuple[str, ...] = ("nonlinear", "linear")

#: Newton's method of ``solve_pads`` stops when every step is below this fraction of its unknown ...
NEWTON_RTOL = 1e-14
#: ... or every residual is below ``RESIDUAL_FLOOR`` times its term scale (rounding level), within this many steps.
NEWTON_MAXIT = 50
#: Rounding floor of the pad residuals relative to the sum of their terms' magnitudes (64 machine epsilons).
RESIDUAL_FLOOR = 64 * 2.0**-52

#: SI unit of every entry of the paper model's state vector ``x``.
STATE_UNITS: dict[str, str] = {
    "q1": "rad", "q2": "rad", "dq1": "rad/s", "dq2": "rad/s", "ddq1": "rad/s^2", "ddq2": "rad/s^2",
    "l1": "m", "l2": "m", "dl1": "m/s", "dl2": "m/s",
}  # fmt: skip


def _paper_parameter_units() -> dict[str, str]:
    from ..symbolic.model import PARAMETER_SYMBOLS

    units = {"Theta": "kg m^2", "Phi": "kg m^2", "k_t": "N m/rad", "d_t": "N m s/rad", "k1": "N/m", "k2": "N/m",
             "d1": "N s/m", "d2": "N s/m", "c_ip1": "m/N", "c_ip2": "m/N", "mu1": "1", "mu2": "1", "h10": "m",
             "h20": "m", "r": "m", "N0": "N", "Omega": "rad/s"}  # fmt: skip
    return {n: units[n] for n in PARAMETER_SYMBOLS}


#: SI unit of every entry of the paper model's parameter vector ``p`` (compliances ``c_ip = 1/k_ip``).
PARAMETER_UNITS: dict[str, str] = _paper_parameter_units()


def temporary_name(output: str, index: int) -> str:
    """Name of the temporary holding entry ``index`` (0-based) of an output in Octave and Julia."""
    return f"{output}_{index + 1}"


@dataclass(frozen=True)
class ExportFunction:
    """One exported function: inputs, outputs and CSE-reduced expressions.

    Attributes
    ----------
    name : str
        Function name (printers may prefix it, e.g. ``brakesqueal_`` in C).
    doc : str
        One-line description, with equation numbers.
    inputs : tuple of (str, tuple of str)
        Argument names and the local variable each entry unpacks into, in order.
    outputs : tuple of (str, tuple of str, str, tuple of int)
        Output groups ``(name, entry labels, unit, shape)``; ``shape`` is
        ``(k,)`` for a vector and ``(rows, cols)`` for a matrix (row-major).
    replacements : tuple of (sympy.Symbol, sympy.Expr)
        Common subexpressions in evaluation order.
    exprs : tuple of sympy.Expr
        Flat outputs (all groups, in order) in terms of the inputs and the
        common subexpressions.
    """

    name: str
    doc: str
    inputs: tuple[tuple[str, tuple[str, ...]], ...]
    outputs: tuple[tuple[str, tuple[str, ...], str, tuple[int, ...]], ...]
    replacements: tuple[tuple[Any, Any], ...]
    exprs: tuple[Any, ...]

    def used_symbols(self) -> set[str]:
        """Names of the input entries the expressions actually use."""
        names: set[str] = set()
        for _, e in self.replacements:
            names |= {str(s) for s in e.free_symbols}
        for e in self.exprs:
            names |= {str(s) for s in e.free_symbols}
        return names


@dataclass(frozen=True)
class ExportModel:
    """Everything a printer needs: functions, conventions and a parameter set.

    Attributes
    ----------
    what : {"nonlinear", "linear"}
        What the functions describe.
    functions : tuple of ExportFunction
        The symbolic functions, in printing order.
    parameter_values : tuple of float
        The chosen parameter set in packing order (:meth:`Parameters.vector
        <brakesqueal.model.parameters.Parameters.vector>`), printed as the
        function ``parameters()``.
    parameter_source : str
        Where the values come from (model, preset, file, overrides).
    notes : tuple of str
        Conventions written into every header.
    model_name : str
        Name of the model.
    description : str
        The model's description (one paragraph).
    coords : tuple of str
        Coordinates ``Q``.
    algebraic : tuple of str
        Pad deformations ``L`` (one per massless pad with a finite tangential stiffness).
    kept : tuple of str
        The entries of ``algebraic`` that keep first-order dynamics (a
        rate-dependent friction law); the others are quasi-static.
    parameter_names : tuple of str
        Names of the entries of ``p`` (compliance names for tangential stiffnesses).
    parameter_units : tuple of str
        Their SI units (``"1"``: dimensionless).
    compliances : tuple of (str, str)
        ``(compliance, stiffness)`` name pairs: ``c = 1/k``, 0 for a rigid support.
    pad_jacobian : {"diagonal", "dense"}
        Whether ``pad_residuals`` returns the diagonal of ``dG/dz`` (each
        pad's balance depends on its own unknown only) or the whole matrix.
    latex : dict
        LaTeX of every local input name and output label.
    """

    what: str
    functions: tuple[ExportFunction, ...]
    parameter_values: tuple[float, ...]
    parameter_source: str
    notes: tuple[str, ...] = field(default=())
    model_name: str = "paper"
    description: str = ""
    coords: tuple[str, ...] = ("q1", "q2")
    algebraic: tuple[str, ...] = ("l1", "l2")
    kept: tuple[str, ...] = ()
    parameter_names: tuple[str, ...] = ()
    parameter_units: tuple[str, ...] = ()
    compliances: tuple[tuple[str, str], ...] = ()
    pad_jacobian: str = "diagonal"
    latex: dict[str, str] = field(default_factory=dict, compare=False)

    # ---------------------------------------------------------------- layout
    @property
    def n(self) -> int:
        """Number of coordinates."""
        return len(self.coords)

    @property
    def m(self) -> int:
        """Number of pad deformations (pad unknowns of ``solve_pads``)."""
        return len(self.algebraic)

    @property
    def x_names(self) -> tuple[str, ...]:
        """The full state ``x = (Q, Qdot, Qddot, L, Ldot)`` of ``residuals``."""
        c, a = self.coords, self.algebraic
        return (*c, *(f"d{n}" for n in c), *(f"dd{n}" for n in c), *a, *(f"d{n}" for n in a))

    @property
    def y_names(self) -> tuple[str, ...]:
        """The ODE state ``y = (Q, Qdot, L_kept)``."""
        return (*self.coords, *(f"d{n}" for n in self.coords), *self.kept)

    @property
    def z_names(self) -> tuple[str, ...]:
        """The pad unknowns: ``l`` of a quasi-static pad, ``ldot`` of a pad that keeps its dynamics."""
        return tuple(f"d{n}" if n in self.kept else n for n in self.algebraic)

    @property
    def z_arg(self) -> str:
        """Name of the pad-unknown argument: ``l`` when every pad is quasi-static, else ``z``."""
        return "z" if self.kept else "l"

    @property
    def kept_index(self) -> tuple[int, ...]:
        """Positions in ``z`` of the rates of the kept pads (the tail of ``dy/dt``)."""
        return tuple(i for i, n in enumerate(self.algebraic) if n in self.kept)

    def units(self, names: tuple[str, ...]) -> list[str]:
        """Units of state entries (``q1``, ``dq1``, ``ddq1``, ``l1``, ``dl1``, ...)."""
        out = []
        base = set(self.coords) | set(self.algebraic)
        for n in names:
            order = 0
            while n not in base and n.startswith("d"):
                n, order = n[1:], order + 1
            out.append(rate_unit(n, order))
        return out

    # ---------------------------------------------------------------- header
    def header_lines(self) -> list[str]:
        """Plain-text header: argument order, units and conventions (no comment markers)."""
        from .. import __version__

        title = {
            "nonlinear": "nonlinear equations of motion (paper eq. 44, generalized) and pad residuals (eqs. 33-34)",
            "linear": "closed-form linear matrices M, D, K about the zero state (paper eqs. 47-48, generalized)",
        }[self.what]
        lines = [f"Generated by brakesqueal {__version__} (brakesqueal export) for model '{self.model_name}': "
                 f"{title}.", "Do not edit.", ""]
        if self.description:
            lines += _wrap(f"Model '{self.model_name}': {self.description}") + [""]
        lines.append(f"n = {self.n} coordinates Q = ({', '.join(self.coords)}); m = {self.m} pad deformations "
                     f"L = ({', '.join(self.algebraic)}).")
        lines += ["", "Argument order and units:"]
        if self.what == "nonlinear":
            xs = self.x_names
            lines.append("  x = (" + ", ".join(xs) + ")")
            lines.append("      [" + ", ".join(self.units(xs)) + "]")
            ys, zs = self.y_names, self.z_names
            lines.append(f"  y = ({', '.join(ys)}) [{', '.join(self.units(ys))}];  "
                         f"{self.z_arg} = ({', '.join(zs)}) [{', '.join(self.units(zs))}];  t [s]")
        lines.append("  p = (" + ", ".join(self.parameter_names) + ")")
        lines.append("      [" + ", ".join(self.parameter_units) + "]")
        for c, k in self.compliances:
            lines.append(f"  {c} = 1/{k}, 0 for a rigid support")
        lines += ["", "Functions:"]
        for fn in self.functions:
            ins = ", ".join(a for a, _ in fn.inputs)
            outs = "; ".join(f"{o} = ({', '.join(lab)}) [{u}]" for o, lab, u, _ in fn.outputs)
            lines.append(f"  {fn.name}({ins}): {fn.doc}")
            lines.append(f"      -> {outs}")
        if self.what == "nonlinear":
            lines.extend(self._helper_lines())
        lines.append(f"  parameters(): the parameter set {self.parameter_source}")
        if self.notes:
            lines.append("")
            for note in self.notes:
                lines.extend(_wrap(note))
        return lines

    def _helper_lines(self) -> list[str]:
        za, dense = self.z_arg, self.pad_jacobian == "dense"
        return [
            f"  solve_pads(y, p): Newton's method for G(y, {za}) = 0 from {za} = 0 with the exact "
            + ("Jacobian dG/dz" if dense else "diagonal Jacobian") + f" -> {za} (empty without pad deformations)",
            f"  state_derivative(y, {za}, p): dy/dt = (Qdot, Qddot" + (", Ldot_kept" if self.kept else "")
            + "), Qddot from M Qddot = -f (a linear solve)",
            "  rhs(t, y, p): dy/dt with the pads solved first (for ODE solvers; t is unused)",
        ]


def _wrap(text: str, width: int = 100) -> list[str]:
    import textwrap

    return textwrap.wrap(text, width) or [""]


# ------------------------------------------------------------------ symbolic parts
def _cse(exprs: list[Any], avoid: set[str]) -> tuple[tuple[tuple[Any, Any], ...], tuple[Any, ...]]:
    import sympy as sp

    prefix = next(p for p in ("w", "t", "s", "v", "cse") if not any(
        a.startswith(p) and a[len(p):].isdigit() for a in avoid))
    reps, reduced = sp.cse(exprs, symbols=sp.numbered_symbols(prefix), order="none")
    return tuple(reps), tuple(reduced)


def _function(name: str, doc: str, inputs: Any, outputs: Any, exprs: list[Any], avoid: set[str]) -> ExportFunction:
    reps, reduced = _cse(exprs, avoid)
    sizes = sum(len(lab) for _, lab, _, _ in outputs)
    if sizes != len(exprs):  # pragma: no cover - a programming error
        raise BrakesquealError(f"export: {name} has {len(exprs)} expressions for {sizes} output entries")
    return ExportFunction(name=name, doc=doc, inputs=inputs, outputs=outputs, replacements=reps, exprs=reduced)


def term_scale(expr: Any, depth: int = 3) -> Any:
    """Sum of the magnitudes of the terms of ``expr`` (through ``depth`` levels of sums and products).

    The rounding error of evaluating ``expr`` is a small multiple of the
    machine epsilon times this scale, so ``|expr| <= RESIDUAL_FLOOR * scale``
    means "zero to rounding" even where the terms cancel (a pad residual at
    the silent motion, ``l + c_ip (f_t + mu N0)`` with ``f_t = -mu N0``).

    Parameters
    ----------
    expr : sympy.Expr
        The expression.
    depth : int
        Levels of ``Add``/``Mul`` to descend into before taking ``Abs``.

    Returns
    -------
    sympy.Expr
    """
    import sympy as sp

    if expr.is_Number:
        return abs(expr)
    if depth > 0 and expr.is_Add:
        return sp.Add(*[term_scale(a, depth - 1) for a in expr.args])
    if depth > 0 and expr.is_Mul:
        return sp.Mul(*[term_scale(a, depth - 1) for a in expr.args])
    return sp.Abs(expr)


def _matrix_unit(rows: list[str], cols: list[str]) -> str:
    """Unit of a matrix with entry ``(i, j)`` in ``rows[i] / cols[j]``."""
    named = {("N m", "rad/s^2"): "kg m^2", ("N m", "rad/s"): "N m s/rad", ("N m", "rad"): "N m/rad",
             ("N", "m/s^2"): "kg", ("N", "m/s"): "N s/m", ("N", "m"): "N/m", ("m", "m"): "1", ("m", "m/s"): "s"}

    def div(a: str, b: str) -> str:
        return named.get((a, b), f"{a}/({b})")

    if len(set(rows)) <= 1 and len(set(cols)) <= 1 and rows and cols:
        return div(rows[0], cols[0])
    return "entry (i, j) in [row i]/[column j], rows (" + ", ".join(rows) + "), columns (" + ", ".join(cols) + ")"


def _matrix_labels(name: str, rows: int, cols: int) -> tuple[str, ...]:
    sep = "" if rows < 10 and cols < 10 else "_"
    return tuple(f"{name}{i + 1}{sep}{j + 1}" for i in range(rows) for j in range(cols))


class _Symbols:
    """SymPy symbols of a model's entries under their local (printable) names."""

    def __init__(self, eq: Equations, reserved: set[str]) -> None:
        import sympy as sp

        self.x = [str(s) for s in eq.x]
        self.p = list(eq.param_names)
        self.local = local_names([*self.x, *self.p], reserved)
        self.sym = {n: sp.Symbol(self.local[n]) for n in (*self.x, *self.p)}
        self.plain = {sp.Symbol(n): self.sym[n] for n in (*self.x, *self.p)}

    def names(self, names: Iterable[str]) -> tuple[str, ...]:
        return tuple(self.local[n] for n in names)


def _reserved(n: int, m: int) -> set[str]:
    """Names the local variables must not take: arguments, outputs, helpers and temporaries."""
    outs = {"res": n + m, "g": m + m * m, "scale": m, "M": n * n, "f": n, "D": n * n, "K": n * n, "R_L": n * m,
            "R_dL": n * m, "G_Q": m * n, "G_dQ": m * n, "G_L": m * m, "G_dL": m * m, "dydt": 2 * n + m}
    names = {"x", "y", "z", "l", "p", "t", "residuals", "pad_residuals", "pad_residual_scale", "mass_force",
             "linear_matrices", "solve_pads", "state_derivative", "rhs", "parameters", "BrakesquealModel"}
    for o, k in outs.items():
        names.add(o)
        names |= {temporary_name(o, i) for i in range(k)}
    return names


def _pads_coupled(G: list[Any], z: list[Any]) -> bool:
    """Whether some ``G_i`` depends on another pad's unknown ``z_j`` (then ``dG/dz`` is exported dense).

    In the models of :func:`~brakesqueal.symbolic.assemble.build_equations` each pad's balance involves
    only its own deformation, so the Jacobian is diagonal; the dense path is kept for models that couple
    pads (tests force it through this function).
    """
    return any(z[j] in G[i].free_symbols for i in range(len(G)) for j in range(len(z)) if i != j)


def _nonlinear_functions(spec: ModelSpec) -> tuple[tuple[ExportFunction, ...], dict[str, Any]]:
    import sympy as sp

    from ..symbolic.assemble import build_equations
    from ..symbolic.linearize import model_closed_form

    eq = build_equations(spec, "symengine")
    n, m = len(eq.coords), len(eq.algebraic)
    kept = tuple(model_closed_form(spec).rate_blocks.get("pads", ()))
    S = _Symbols(eq, _reserved(n, m))
    sym, avoid = S.sym, set(S.local.values())
    R = [sp.sympify(e).xreplace(S.plain) for e in eq.R]
    G = [sp.sympify(e).xreplace(S.plain) for e in (eq.G if eq.G is not None else [])]
    # the ODE's view: quasi-static pads have ldot = 0, kept pads' ldot is the pad unknown
    quasi = {sym[f"d{a}"]: 0 for a in eq.algebraic if a not in kept}
    z = [sym[f"d{a}"] if a in kept else sym[a] for a in eq.algebraic]
    y = [*(sym[c] for c in eq.coords), *(sym[f"d{c}"] for c in eq.coords), *(sym[a] for a in kept)]
    ydd = [sym[f"dd{c}"] for c in eq.coords]
    x_in = ("x", S.names(S.x))
    p_in = ("p", S.names(S.p))
    y_in = ("y", tuple(str(s) for s in y))
    z_in = ("l" if not kept else "z", tuple(str(s) for s in z))
    row_labels = tuple(residual_label(c) for c in eq.coords) + tuple(residual_label(a) for a in eq.algebraic)
    row_units = [residual_unit(c) for c in eq.coords] + [residual_unit(a) for a in eq.algebraic]
    fns = [_function(
        "residuals", "residuals R of the equations of motion (eq. 44, generalized) and G of the pads' tangential "
        "balances (eqs. 33-34) at the full state x", (x_in, p_in),
        (("res", row_labels, ", ".join(row_units), (n + m,)),), R + G, avoid)]
    dense = False
    meta: dict[str, Any] = {"kept": kept}
    if m:
        Gz = [e.xreplace(quasi) for e in G]
        dense = _pads_coupled(Gz, z)
        pairs = [(i, j) for i in range(m) for j in (range(m) if dense else [i])]
        zn = [f"d{a}" if a in kept else a for a in eq.algebraic]
        jac = [Gz[i].diff(z[j]) for i, j in pairs]
        jl = tuple(f"d{row_labels[n + i]}/d{zn[j]}" for i, j in pairs)
        ju = ["s" if eq.algebraic[j] in kept else "1" for _, j in pairs]
        doc = ("pad residuals G at the pad unknowns (l of a quasi-static pad, with ldot = 0; ldot of a kept pad) "
               + ("and their Jacobian dG/d(unknowns) (row-major)" if dense
                  else "and the diagonal of that Jacobian (G_i depends on the i-th unknown only)"))
        fns.append(_function("pad_residuals", doc, (y_in, z_in, p_in),
                             (("g", row_labels[n:] + jl, ", ".join(["m"] * m + ju), (m + len(jac),)),),
                             Gz + jac, avoid))  # fmt: skip
        fns.append(_function(
            "pad_residual_scale", "sum of the magnitudes of the terms of each pad residual (G = 0 to rounding "
            f"when |G_i| <= {RESIDUAL_FLOOR!r} * scale_i)", (y_in, z_in, p_in),
            (("scale", tuple(f"scale_{lab}" for lab in row_labels[n:]), "m", (m,)),),
            [term_scale(e) for e in Gz], avoid))  # fmt: skip
    Rz = [e.xreplace(quasi) for e in R]
    Mm = [Rz[i].diff(ydd[j]) for i in range(n) for j in range(n)]
    if any(s in e.free_symbols for e in Mm for s in ydd):  # pragma: no cover - R is linear in Qddot
        raise BrakesquealError(f"export: the residuals of model '{spec.name}' are not linear in the accelerations")
    f = [e.xreplace({s: 0 for s in ydd}) for e in Rz]
    acc = [rate_unit(c, 2) for c in eq.coords]
    fns.append(_function(
        "mass_force", "M and f of R = M(Q) Qddot + f(Q, Qdot, L, Ldot) at the pad unknowns "
        "(M row-major n x n); Qddot = -M^-1 f", (y_in, z_in, p_in),
        (("M", _matrix_labels("M", n, n), _matrix_unit(row_units[:n], acc), (n, n)),
         ("f", tuple(f"f_{lab}" for lab in row_labels[:n]), ", ".join(row_units[:n]), (n,))),
        Mm + f, avoid))  # fmt: skip
    meta.update(pad_jacobian="dense" if dense else "diagonal", symbols=S, coords=eq.coords, algebraic=eq.algebraic)
    return tuple(fns), meta


def _linear_functions(spec: ModelSpec) -> tuple[tuple[ExportFunction, ...], dict[str, Any]]:
    import sympy as sp

    from ..symbolic.assemble import build_equations
    from ..symbolic.linearize import model_closed_form, simplify_entry

    eq = build_equations(spec, "symengine")
    cf = model_closed_form(spec)
    n = len(eq.coords)
    kept = tuple(cf.rate_blocks.get("pads", ()))
    k = len(kept)
    S = _Symbols(eq, _reserved(n, k))
    avoid = set(S.local.values())
    # closed-form symbols (positive / real, stiffnesses as k_ip) -> compliances, simplified, then printable names
    back: dict[Any, Any] = {}
    final: dict[Any, Any] = {}
    for name, pname in zip(spec.parameters, eq.param_names):
        s = cf.symbols[name]
        if pname != name:
            c = sp.Symbol(pname, positive=True)
            back[s] = 1 / c
            final[c] = S.sym[pname]
        else:
            final[s] = S.sym[pname]

    def entries(mat: Any) -> list[Any]:
        out = []
        for e in list(mat):
            e = simplify_entry(sp.sympify(e).xreplace(back)).xreplace(final)
            stray = {str(s) for s in e.free_symbols} - avoid
            if stray:  # pragma: no cover - a programming error
                raise BrakesquealError(f"export: closed form of model '{spec.name}' has unknown symbols {stray}")
            out.append(e)
        return out

    rows = [residual_unit(c) for c in eq.coords]
    cols = [coordinate_unit(c) for c in eq.coords]
    rates = [rate_unit(c, 1) for c in eq.coords]
    accs = [rate_unit(c, 2) for c in eq.coords]
    groups = [("M", cf.M, rows, accs), ("D", cf.D, rows, rates), ("K", cf.K, rows, cols)]
    if k:
        rb = cf.rate_blocks
        groups += [("R_L", rb["R_L"], rows, ["m"] * k), ("R_dL", rb["R_dL"], rows, ["m/s"] * k),
                   ("G_Q", rb["G_Q"], ["m"] * k, cols), ("G_dQ", rb["G_dQ"], ["m"] * k, rates),
                   ("G_L", rb["G_L"], ["m"] * k, ["m"] * k), ("G_dL", rb["G_dL"], ["m"] * k, ["m/s"] * k)]
    outputs, exprs = [], []
    for name, mat, ru, cu in groups:
        r, c = len(ru), len(cu)
        if (mat.rows, mat.cols) != (r, c):  # pragma: no cover - a programming error
            raise BrakesquealError(f"export: block {name} of model '{spec.name}' is {mat.shape}, expected {(r, c)}")
        outputs.append((name, _matrix_labels(name, r, c), _matrix_unit(ru, cu), (r, c)))
        exprs += entries(mat)
    doc = ("closed-form M, D, K (row-major n x n) about the zero state Q = 0, L = 0 (eqs. 47-48 with the "
           "quasi-static pads eliminated; valid where the zero state is the silent motion, e.g. eq. 49)")
    if k:
        doc += (f"; the pads {', '.join(kept)} keep first-order dynamics (rate-dependent friction or a tangential "
                "damper) and their blocks R_L, R_dL, G_Q, G_dQ, G_L, G_dL follow")
    fn = _function("linear_matrices", doc, (("p", S.names(S.p)),), tuple(outputs), exprs, avoid)
    return (fn,), {"kept": kept, "pad_jacobian": "diagonal", "symbols": S, "coords": eq.coords,
                   "algebraic": eq.algebraic}


_FUNCTIONS: dict[tuple[str, str], tuple[tuple[ExportFunction, ...], dict[str, Any]]] = {}


def _functions(spec: ModelSpec, what: str) -> tuple[tuple[ExportFunction, ...], dict[str, Any]]:
    """The symbolic functions of a model, cached in-process by the model's equations."""
    from ..codegen import model_key

    key = (model_key(spec), what)
    if key not in _FUNCTIONS:
        _FUNCTIONS[key] = (_nonlinear_functions if what == "nonlinear" else _linear_functions)(spec)
    return _FUNCTIONS[key]


def _nonlinear_notes(kept: tuple[str, ...], algebraic: tuple[str, ...]) -> tuple[str, ...]:
    quasi = [a for a in algebraic if a not in kept]
    notes = []
    if quasi:
        notes.append(f"Quasi-static pads ({', '.join(quasi)}): ldot = 0 in the sliding velocities, l follows "
                     "(Q, Qdot) through G = 0 (rate-independent friction; docs/theory.md).")
    if kept:
        notes.append(f"Pads with first-order dynamics ({', '.join(kept)}, rate-dependent friction or a tangential "
                     "damper): l is part of the state y, its rate ldot is the pad unknown solved from G = 0 (needs "
                     "dG/dldot != 0: a finite tangential stiffness and a friction law whose slope is not 0, or a "
                     "damper d_ip > 0).")
    return tuple(notes)


def _linear_notes(kept: tuple[str, ...]) -> tuple[str, ...]:
    if not kept:
        return ("The linear model is M dQddot + D dQdot + K dQ = 0 (eq. 47) for the deviation dQ from the zero "
                "state.",)
    return ("The pads " + ", ".join(kept) + " keep first-order dynamics: the linear model is the descriptor "
            "system E xi' = A xi in xi = (dQ, dQdot, dL) with E = [I 0 0; 0 M R_dL; 0 0 G_dL] and "
            "A = [0 I 0; -K -D -R_L; -G_Q -G_dQ -G_L] (brakesqueal.analysis.linear); M, D, K alone are not the "
            "linearization.",)


def _check_trivial(params: Parameters) -> None:
    """Refuse the closed form unless the zero state is the silent motion of ``params``."""
    from ..analysis.equilibrium import silent_motion
    from ..errors import SilentMotionError

    what = ("--what linear exports the closed form about the zero state Q = 0, L = 0, valid only where that is the "
            "silent motion")
    hint = ("(use 'brakesqueal linearize " + ("" if params.model.name == "paper" else f"--model {params.model.name} ")
            + "--format json' for the numeric matrices at this silent motion)")
    from ..codegen import build

    try:
        sm = silent_motion(build(params.model), params)  # export is an entry point: the model is built here
    except SilentMotionError as exc:
        raise ParameterError(f"{what}; these parameters have none: {exc}") from None
    if sm.trivial:
        return
    d = params.as_dict()
    if {"mu1", "mu2", "h10", "h20"} <= set(d):
        detail = (f"which needs mu1*h10 = mu2*h20 (eq. 49); got mu1*h10 = {d['mu1'] * d['h10']:.6g} m, "
                  f"mu2*h20 = {d['mu2'] * d['h20']:.6g} m ")
    else:
        q0 = ", ".join(f"{c} = {v:.3g}" for c, v in zip(sm.coords, sm.q0))
        detail = f"but the silent motion of these parameters is at {q0} "
    raise ParameterError(f"{what}, {detail}{hint}")


def export_model(
    what: What = "nonlinear",
    params: Parameters | None = None,
    *,
    source: str | None = None,
    model: ModelSpec | str | None = None,
) -> ExportModel:
    """Build the language-neutral export description of any model.

    Parameters
    ----------
    what : {"nonlinear", "linear"}
        ``"nonlinear"``: ``residuals``, ``pad_residuals``,
        ``pad_residual_scale`` (when the model has pad deformations),
        ``mass_force`` (plus the printers' ``solve_pads``,
        ``state_derivative``, ``rhs``); ``"linear"``: ``linear_matrices``
        (closed form about the zero state).
    params : Parameters, optional
        The parameter set printed as ``parameters()``; it also names the
        model.  Default: the model's default preset, or preset
        ``paper-fig2`` without a model.
    source : str, optional
        Description of where ``params`` came from, for the header.
    model : ModelSpec or str, optional
        The model (a built-in name or a TOML path), when ``params`` is not given.

    Returns
    -------
    ExportModel

    Raises
    ------
    ParameterError
        If ``what`` is unknown, ``params`` belongs to another model than
        ``model``, or ``what == "linear"`` and the zero state is not the
        silent motion of ``params`` (for the paper's model:
        ``mu1*h10 != mu2*h20``, eq. 49).
    """
    from ..analysis.equilibrium import as_parameters
    from ..model.components import ModelSpec
    from ..model.library import get_preset, resolve_model

    if what not in WHATS:
        raise ParameterError(f"The option '--what' must be one of {', '.join(WHATS)}; got {what!r}")
    chosen = None if model is None else (model if isinstance(model, ModelSpec) else resolve_model(model))
    if params is None:  # the defaults of brakesqueal.model.options.resolve_space
        preset = get_preset("paper-fig2") if chosen is None else chosen.get_preset(None)
        params = preset.resolve({})
        source = source or f"model {params.model.name}, preset {preset.name}"
    params = as_parameters(params)
    spec = params.model
    if chosen is not None and chosen.name != spec.name:
        raise ParameterError(f"the parameters belong to model '{spec.name}', not to model '{chosen.name}'")
    if what == "linear":
        _check_trivial(params)
    values = tuple(float(v) for v in params.vector())
    if not all(math.isfinite(v) for v in values):  # pragma: no cover - Parameters validates
        raise ParameterError("the parameter vector has non-finite entries")
    fns, meta = _functions(spec, what)
    S = meta["symbols"]
    kept = meta["kept"]
    stiff = spec.stiffness_names()
    units = tuple("m/N" if n in stiff else (spec.unit(n) or "1") for n in spec.parameters)
    comp = tuple((pn, n) for n, pn in zip(spec.parameters, S.p) if n in stiff)
    coords, algebraic = meta["coords"], meta["algebraic"]
    latex: dict[str, str] = {}
    for c in (*coords, *algebraic):
        core = latex_symbol(c)
        latex[c] = latex[S.local[c]] = core
        latex[f"d{c}"] = latex[S.local[f"d{c}"]] = r"\dot{" + core + "}"
        if c in coords:
            latex[f"dd{c}"] = latex[S.local[f"dd{c}"]] = r"\ddot{" + core + "}"
    for n in S.p:
        latex[n] = latex[S.local[n]] = latex_symbol(n)
    notes = _nonlinear_notes(kept, algebraic) if what == "nonlinear" else _linear_notes(kept)
    return ExportModel(
        what=what, functions=fns, parameter_values=values, parameter_source=source or "given", notes=notes,
        model_name=spec.name, description=spec.description, coords=coords, algebraic=algebraic, kept=kept,
        parameter_names=tuple(S.p), parameter_units=units, compliances=comp, pad_jacobian=meta["pad_jacobian"],
        latex=latex,
    )  # fmt: skip
