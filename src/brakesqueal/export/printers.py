"""Source printers for C, GNU Octave / MATLAB, Julia and Python (via :mod:`sympy.printing`).

Each printer formats an :class:`~.model.ExportModel`: the header (argument
order, units), one function per :class:`~.model.ExportFunction` (common
subexpressions ``w0, w1, ...`` first, then the outputs), the small
hand-written helpers ``solve_pads`` / ``rhs`` of the nonlinear export and
``parameters()``.  Conventions per language:

* **C** (C99, ``#include <math.h>``, link with ``-lm``): functions
  ``brakesqueal_<name>(const double *in..., double *out...)``; matrices
  row-major; ``solve_pads`` and ``rhs`` return 0 on success.
* **Octave** (also MATLAB): one function file; its main function, named after
  the file, returns a struct of function handles (``m = name(); m.rhs(t, y, p)``);
  inputs and outputs are column vectors, matrices 2 × 2.
* **Julia**: ``module BrakesquealModel``; vectors are 1-based, matrices 2 × 2.
* **Python**: a dependency-free module (``math`` only); tuples out.
"""

from __future__ import annotations

import re
from typing import Any, Callable

from .model import ExportFunction, ExportModel

__all__ = ["print_c", "print_octave", "print_julia", "print_python", "PRINTERS"]

_NEWTON_RTOL = "1e-14"
_NEWTON_MAXIT = 50


def _float(v: float) -> str:
    return repr(float(v))


def _comment(lines: list[str], prefix: str) -> list[str]:
    return [(prefix + " " + ln).rstrip() for ln in lines]


def _used_inputs(fn: ExportFunction) -> list[tuple[str, int, str]]:
    """``(argument, index, entry)`` for the entries the function uses, in order."""
    used = fn.used_symbols()
    return [(arg, i, n) for arg, names in fn.inputs for i, n in enumerate(names) if n in used]


def _flat_outputs(fn: ExportFunction) -> list[tuple[str, int, Any]]:
    out, k = [], 0
    for name, labels, _ in fn.outputs:
        for i in range(len(labels)):
            out.append((name, i, fn.exprs[k]))
            k += 1
    return out


# --------------------------------------------------------------------------- C
def print_c(model: ExportModel, out_name: str = "brakesqueal_model") -> str:
    """C99 source of ``model`` (see the module docstring for the conventions).

    Parameters
    ----------
    model : ExportModel
        What to print.
    out_name : str
        Stem of the output file, used in the header only.

    Returns
    -------
    str
    """
    from sympy.printing.c import ccode

    def code(e: Any) -> str:
        return ccode(e, standard="c99")

    lines = ["/*"] + _comment(model.header_lines(), " *") + [" *", f" * Compile: gcc -O2 -c {out_name}.c -lm", " */"]
    lines += ["#include <math.h>", ""]
    for fn in model.functions:
        sig = ", ".join([f"const double *{a}" for a, _ in fn.inputs] + [f"double *{o}" for o, _, _ in fn.outputs])
        lines += [f"/* {fn.doc} */", f"void brakesqueal_{fn.name}({sig})", "{"]
        lines += [f"    const double {n} = {a}[{i}];" for a, i, n in _used_inputs(fn)]
        lines += [f"    const double {s} = {code(e)};" for s, e in fn.replacements]
        lines += [f"    {o}[{i}] = {code(e)};" for o, i, e in _flat_outputs(fn)]
        lines += ["}", ""]
    if model.what == "nonlinear":
        lines += [
            "/* Newton's method for g(y, l, ldot = 0) = 0 from l = 0; returns 0 on success, 1 otherwise. */",
            "int brakesqueal_solve_pads(const double *y, const double *p, double *l)",
            "{",
            "    double g[4];",
            "    l[0] = 0.0;",
            "    l[1] = 0.0;",
            f"    for (int it = 0; it < {_NEWTON_MAXIT}; ++it) {{",
            "        brakesqueal_pad_residuals(y, l, p, g);",
            "        const double s0 = g[0] / g[2], s1 = g[1] / g[3];",
            "        l[0] -= s0;",
            "        l[1] -= s1;",
            "        if (!isfinite(s0) || !isfinite(s1)) return 1;",
            f"        if (fabs(s0) <= {_NEWTON_RTOL} * fabs(l[0]) + 1e-300 && fabs(s1) <= {_NEWTON_RTOL} * fabs(l[1]) + 1e-300)",
            "            return 0;",
            "    }",
            "    return 1;",
            "}",
            "",
            "/* dy/dt with the pads solved first (t unused); returns 0 on success, 1 if the pads did not converge. */",
            "int brakesqueal_rhs(double t, const double *y, const double *p, double *dydt)",
            "{",
            "    double l[2];",
            "    (void)t;",
            "    const int status = brakesqueal_solve_pads(y, p, l);",
            "    brakesqueal_state_derivative(y, l, p, dydt);",
            "    return status;",
            "}",
            "",
        ]
    vals = ", ".join(_float(v) for v in model.parameter_values)
    lines += [
        f"/* The parameter set {model.parameter_source} (p order as in the header). */",
        "void brakesqueal_parameters(double *p)",
        "{",
        f"    static const double values[{len(model.parameter_values)}] = {{{vals}}};",
        f"    for (int i = 0; i < {len(model.parameter_values)}; ++i) p[i] = values[i];",
        "}",
    ]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------- Octave
def print_octave(model: ExportModel, out_name: str = "brakesqueal_model") -> str:
    """GNU Octave / MATLAB function file of ``model``.

    Parameters
    ----------
    model : ExportModel
        What to print.
    out_name : str
        Name of the main function; must equal the file's stem.

    Returns
    -------
    str
    """
    from sympy.printing.octave import octave_code

    names = [fn.name for fn in model.functions] + (["solve_pads", "rhs"] if model.what == "nonlinear" else [])
    names.append("parameters")
    lines = [f"function m = {out_name}()"]
    lines += _comment([f"{out_name}: brakesqueal exported model; m = {out_name}(); m.<function>(...)."], "%")
    lines += _comment([""] + model.header_lines() + ["", "Vectors are columns, matrices 2 x 2."], "%")
    lines += [f"  m.{n} = @{n};" for n in names]
    lines += ["end", ""]
    for fn in model.functions:
        outs = [o for o, _, _ in fn.outputs]
        lhs = outs[0] if len(outs) == 1 else "[" + ", ".join(outs) + "]"
        lines += [f"function {lhs} = {fn.name}({', '.join(a for a, _ in fn.inputs)})", f"  % {fn.doc}"]
        lines += [f"  {n} = {a}({i + 1});" for a, i, n in _used_inputs(fn)]
        lines += [f"  {s} = {octave_code(e)};" for s, e in fn.replacements]
        k = 0
        for o, labels, _ in fn.outputs:
            # one temporary per entry: no expression inside [...], where spaces may separate elements
            tmp = [f"{o}_{i + 1}" for i in range(len(labels))]
            lines += [f"  {t} = {octave_code(fn.exprs[k + i])};" for i, t in enumerate(tmp)]
            k += len(labels)
            if model.what == "linear":
                lines.append(f"  {o} = [{tmp[0]}, {tmp[1]}; {tmp[2]}, {tmp[3]}];")
            else:
                lines.append(f"  {o} = [" + "; ".join(tmp) + "];")
        lines += ["end", ""]
    if model.what == "nonlinear":
        lines += [
            "function l = solve_pads(y, p)",
            "  % Newton's method for g(y, l, ldot = 0) = 0 from l = 0.",
            "  l = [0; 0];",
            f"  for it = 1:{_NEWTON_MAXIT}",
            "    g = pad_residuals(y, l, p);",
            "    s = g(1:2) ./ g(3:4);",
            "    l = l - s;",
            f"    if all(abs(s) <= {_NEWTON_RTOL} * abs(l) + 1e-300)",
            "      return;",
            "    end",
            "  end",
            "  error('brakesqueal:solve_pads', 'Newton iteration for the pad deformations did not converge');",
            "end",
            "",
            "function dydt = rhs(t, y, p)",
            "  % dy/dt with the pads solved first (t unused), e.g. ode45(@(t, y) m.rhs(t, y, p), ...).",
            "  dydt = state_derivative(y, solve_pads(y, p), p);",
            "end",
            "",
        ]
    vals = "; ".join(_float(v) for v in model.parameter_values)
    lines += [
        "function p = parameters()",
        f"  % The parameter set {model.parameter_source}.",
        f"  p = [{vals}];",
        "end",
    ]
    return "\n".join(lines) + "\n"


# ----------------------------------------------------------------------- Julia
def print_julia(model: ExportModel, out_name: str = "brakesqueal_model") -> str:
    """Julia module ``BrakesquealModel`` of ``model``.

    Parameters
    ----------
    model : ExportModel
        What to print.
    out_name : str
        Stem of the output file, used in the header only.

    Returns
    -------
    str
    """
    from sympy.printing.julia import julia_code

    names = [fn.name for fn in model.functions] + (["solve_pads", "rhs"] if model.what == "nonlinear" else [])
    names.append("parameters")
    lines = _comment(model.header_lines() + ["", f'Use: include("{out_name}.jl"); using .BrakesquealModel'], "#")
    lines += ["module BrakesquealModel", "", "export " + ", ".join(names), ""]
    for fn in model.functions:
        lines += [f'"""{fn.doc}"""', f"function {fn.name}({', '.join(a for a, _ in fn.inputs)})"]
        lines += [f"    {n} = {a}[{i + 1}]" for a, i, n in _used_inputs(fn)]
        lines += [f"    {s} = {julia_code(e)}" for s, e in fn.replacements]
        k, results = 0, []
        for o, labels, _ in fn.outputs:
            # one temporary per entry: no expression inside [...], where spaces separate elements
            tmp = [f"{o}_{i + 1}" for i in range(len(labels))]
            lines += [f"    {t} = {julia_code(fn.exprs[k + i])}" for i, t in enumerate(tmp)]
            k += len(labels)
            if model.what == "linear":
                lines.append(f"    {o} = [{tmp[0]} {tmp[1]}; {tmp[2]} {tmp[3]}]")
            else:
                lines.append(f"    {o} = [" + ", ".join(tmp) + "]")
            results.append(o)
        lines += [f"    return {', '.join(results)}", "end", ""]
    if model.what == "nonlinear":
        lines += [
            '"""Newton\'s method for g(y, l, ldot = 0) = 0 from l = 0; returns l = [l1, l2]."""',
            "function solve_pads(y, p)",
            "    l = [0.0, 0.0]",
            f"    for it in 1:{_NEWTON_MAXIT}",
            "        g = pad_residuals(y, l, p)",
            "        s = g[1:2] ./ g[3:4]",
            "        l = l .- s",
            f"        if all(abs.(s) .<= {_NEWTON_RTOL} .* abs.(l) .+ 1e-300)",
            "            return l",
            "        end",
            "    end",
            '    error("Newton iteration for the pad deformations did not converge")',
            "end",
            "",
            '"""dy/dt with the pads solved first (t unused)."""',
            "rhs(t, y, p) = state_derivative(y, solve_pads(y, p), p)",
            "",
        ]
    vals = ", ".join(_float(v) for v in model.parameter_values)
    lines += [f'"""The parameter set {model.parameter_source}."""', f"parameters() = [{vals}]", "", "end # module"]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------- Python
def print_python(model: ExportModel, out_name: str = "brakesqueal_model") -> str:
    """Dependency-free Python module of ``model`` (``math`` only).

    Parameters
    ----------
    model : ExportModel
        What to print.
    out_name : str
        Stem of the output file, used in the header only.

    Returns
    -------
    str
    """
    from sympy.printing.pycode import pycode

    def code(e: Any) -> str:
        return pycode(e, fully_qualified_modules=True)

    lines = ['"""' + "\n".join(model.header_lines()).replace("\\", "\\\\") + '\n"""', "", "import math", ""]
    for fn in model.functions:
        lines += ["", f"def {fn.name}({', '.join(a for a, _ in fn.inputs)}):", f'    """{fn.doc}."""']
        lines += [f"    {n} = {a}[{i}]" for a, i, n in _used_inputs(fn)]
        lines += [f"    {s} = {code(e)}" for s, e in fn.replacements]
        k, results = 0, []
        for o, labels, _ in fn.outputs:
            vals = [code(fn.exprs[k + i]) for i in range(len(labels))]
            k += len(labels)
            if model.what == "linear":
                results.append(f"(({vals[0]}, {vals[1]}), ({vals[2]}, {vals[3]}))")
            else:
                results.append("(" + ", ".join(vals) + ")")
        lines.append(f"    return {', '.join(results)}" if len(results) > 1 else f"    return {results[0]}")
        lines.append("")
    if model.what == "nonlinear":
        lines += [
            "",
            "def solve_pads(y, p):",
            '    """Newton\'s method for g(y, l, ldot = 0) = 0 from l = 0; returns (l1, l2) [m]."""',
            "    l1 = l2 = 0.0",
            f"    for _ in range({_NEWTON_MAXIT}):",
            "        g1, g2, g1l, g2l = pad_residuals(y, (l1, l2), p)",
            "        s1, s2 = g1 / g1l, g2 / g2l",
            "        l1, l2 = l1 - s1, l2 - s2",
            f"        if abs(s1) <= {_NEWTON_RTOL} * abs(l1) + 1e-300 and abs(s2) <= {_NEWTON_RTOL} * abs(l2) + 1e-300:",
            "            return (l1, l2)",
            '    raise ArithmeticError("Newton iteration for the pad deformations did not converge")',
            "",
            "",
            "def rhs(t, y, p):",
            '    """dy/dt with the pads solved first (t unused), e.g. scipy.integrate.solve_ivp(rhs, ..., args=(p,))."""',
            "    return state_derivative(y, solve_pads(y, p), p)",
            "",
        ]
    vals = ", ".join(_float(v) for v in model.parameter_values)
    lines += [
        "",
        "def parameters():",
        f'    """The parameter set {model.parameter_source}."""',
        f"    return ({vals},)",
    ]
    return "\n".join(lines) + "\n"


#: Printer of each code target.
PRINTERS: dict[str, Callable[[ExportModel, str], str]] = {
    "c": print_c,
    "octave": print_octave,
    "julia": print_julia,
    "python": print_python,
}

_IDENT = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


def is_identifier(name: str) -> bool:
    """Whether ``name`` is a valid function/file name in every target language."""
    return bool(_IDENT.match(name))
