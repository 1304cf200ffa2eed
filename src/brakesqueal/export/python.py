"""Python printer of an :class:`~.model.ExportModel`: a dependency-free module (``math`` only).

Outputs are tuples (matrices as tuples of rows); the linear solves are a
small hand-written Gaussian elimination with partial pivoting.
"""

from __future__ import annotations

from typing import Any

from ._common import FLOOR, MAXIT, RTOL, fmt_float, grouped, used_inputs
from .model import ExportModel

__all__ = ["print_python"]

_SOLVE = '''

def _solve_linear(A, b):
    """s with A s = b by Gaussian elimination with partial pivoting (A: rows); ZeroDivisionError if singular."""
    k = len(b)
    A = [list(row) for row in A]
    b = list(b)
    for c in range(k):
        piv = max(range(c, k), key=lambda i: abs(A[i][c]))
        if not (abs(A[piv][c]) > 0.0 and math.isfinite(A[piv][c])):
            raise ZeroDivisionError("singular matrix in the exported model")
        A[c], A[piv] = A[piv], A[c]
        b[c], b[piv] = b[piv], b[c]
        for i in range(c + 1, k):
            fac = A[i][c] / A[c][c]
            for j in range(c + 1, k):
                A[i][j] -= fac * A[c][j]
            b[i] -= fac * b[c]
    s = [0.0] * k
    for i in range(k - 1, -1, -1):
        s[i] = (b[i] - sum(A[i][j] * s[j] for j in range(i + 1, k))) / A[i][i]
    return s
'''


def _tuple(items: list[str]) -> str:
    return "(" + ", ".join(items) + ("," if len(items) == 1 else "") + ")"


def _helpers(model: ExportModel) -> list[str]:
    n, m, za = model.n, model.m, model.z_arg
    lines = [_SOLVE, ""]
    lines += [
        "def solve_pads(y, p):",
        f'    """Newton\'s method for G(y, {za}) = 0 from {za} = 0; returns the pad unknowns {za} (see the header)."""',
    ]
    if m == 0:
        lines += ["    return ()", "", ""]
    else:
        if model.pad_jacobian == "dense":
            step = f"_solve_linear([g[{m} + {m} * i:{2 * m} + {m} * i] for i in range({m})], g[:{m}])"
        else:
            step = f"[g[j] / g[{m} + j] for j in range({m})]"
        lines += [
            f"    {za} = [0.0] * {m}",
            f"    for _ in range({MAXIT}):",
            f"        g = pad_residuals(y, {za}, p)",
            f"        scale = pad_residual_scale(y, {za}, p)",
            f"        if all(abs(g[j]) <= {FLOOR} * scale[j] for j in range({m})):",
            f"            return tuple({za})  # G = 0 to rounding",
            f"        s = {step}",
            "        if not all(math.isfinite(v) for v in s):",
            "            break",
            f"        {za} = [a - b for a, b in zip({za}, s)]",
            f"        if all(abs(s[j]) <= {RTOL} * abs({za}[j]) for j in range({m})):",
            f"            return tuple({za})",
            '    raise ArithmeticError("Newton iteration for the pad unknowns did not converge")',
            "",
            "",
        ]
    kept = "".join(f", {za}[{j}]" for j in model.kept_index)
    lines += [
        f"def state_derivative(y, {za}, p):",
        f'    """dy/dt = (Qdot, Qddot{", Ldot_kept" if model.kept else ""}) for given pad unknowns, M Qddot = -f."""',
        f"    M, f = mass_force(y, {za}, p)",
        "    acc = _solve_linear(M, [-v for v in f])",
        f"    return (*y[{n}:{2 * n}], *acc{kept})",
        "",
        "",
        "def rhs(t, y, p):",
        '    """dy/dt with the pads solved first (t unused), e.g. scipy.integrate.solve_ivp(rhs, ..., args=(p,))."""',
        "    return state_derivative(y, solve_pads(y, p), p)",
        "",
    ]
    return lines


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

    head = "\n".join(model.header_lines()).replace("\\", "\\\\").replace('"""', "'''")
    lines = ['"""' + head + '\n"""', "", "import math", ""]
    for fn in model.functions:
        lines += ["", f"def {fn.name}({', '.join(a for a, _ in fn.inputs)}):", f'    """{fn.doc}."""']
        lines += [f"    {n} = {a}[{i}]" for a, i, n in used_inputs(fn)]
        lines += [f"    {s} = {code(e)}" for s, e in fn.replacements]
        results = []
        for _, shape, exprs in grouped(fn):
            vals = [code(e) for e in exprs]
            if len(shape) == 2:
                r, c = shape
                results.append(_tuple([_tuple(vals[i * c : (i + 1) * c]) for i in range(r)]))
            else:
                results.append(_tuple(vals))
        lines.append(f"    return {', '.join(results)}")
        lines.append("")
    if model.what == "nonlinear":
        lines += _helpers(model)
    defaults = ", ".join(fmt_float(v) for v in model.parameter_values)
    source = model.parameter_source.replace("\\", "\\\\").replace('"""', "'''")
    lines += [
        "",
        "def parameters():",
        f'    """The parameter set {source}."""',
        f"    return ({defaults},)",
    ]
    return "\n".join(lines) + "\n"
