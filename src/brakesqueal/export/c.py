"""C99 printer of an :class:`~.model.ExportModel` (``#include <math.h>``, link with ``-lm``).

Functions are ``brakesqueal_<name>(const double *in..., double *out...)``;
matrices are row-major.  ``solve_pads``, ``state_derivative`` and ``rhs``
return 0 on success, 1 if Newton's method for the pads did not converge and
2 if the mass matrix is singular.  The linear solve is a small Gaussian
elimination with partial pivoting (``static``, no library needed).
"""

from __future__ import annotations

from typing import Any

from ._common import FLOOR, MAXIT, RTOL, comment, flat_outputs, fmt_float, unused_arguments, used_inputs
from .model import ExportModel

__all__ = ["print_c"]

_SOLVE = """\
/* Solves A s = b in place by Gaussian elimination with partial pivoting: A (row-major k x k) is
 * overwritten, b becomes s.  Returns 0, or 1 if A is singular. */
static int brakesqueal_solve_linear(int k, double *A, double *b)
{
    for (int c = 0; c < k; ++c) {
        int piv = c;
        double amax = fabs(A[c * k + c]);
        for (int i = c + 1; i < k; ++i) {
            if (fabs(A[i * k + c]) > amax) {
                amax = fabs(A[i * k + c]);
                piv = i;
            }
        }
        if (!(amax > 0.0) || !isfinite(amax)) return 1;
        if (piv != c) {
            for (int j = 0; j < k; ++j) {
                const double tmp = A[c * k + j];
                A[c * k + j] = A[piv * k + j];
                A[piv * k + j] = tmp;
            }
            const double tmp = b[c];
            b[c] = b[piv];
            b[piv] = tmp;
        }
        for (int i = c + 1; i < k; ++i) {
            const double fac = A[i * k + c] / A[c * k + c];
            for (int j = c + 1; j < k; ++j) A[i * k + j] -= fac * A[c * k + j];
            b[i] -= fac * b[c];
        }
    }
    for (int i = k - 1; i >= 0; --i) {
        double s = b[i];
        for (int j = i + 1; j < k; ++j) s -= A[i * k + j] * b[j];
        b[i] = s / A[i * k + i];
    }
    return 0;
}
"""


def _helpers(model: ExportModel) -> list[str]:
    n, m, za = model.n, model.m, model.z_arg
    lines = [_SOLVE]
    lines += [f"/* Newton's method for G(y, {za}) = 0 from {za} = 0 (the pad unknowns, see the header); returns 0 on "
              "success, 1 otherwise. */",
              f"int brakesqueal_solve_pads(const double *y, const double *p, double *{za})", "{"]
    if m == 0:
        lines += ["    (void)y;", "    (void)p;", f"    (void){za};", "    return 0;", "}", ""]
    else:
        dense = model.pad_jacobian == "dense"
        glen = m + (m * m if dense else m)
        lines += [f"    double g[{glen}], scale[{m}];", f"    for (int j = 0; j < {m}; ++j) {za}[j] = 0.0;",
                  f"    for (int it = 0; it < {MAXIT}; ++it) {{",
                  f"        brakesqueal_pad_residuals(y, {za}, p, g);",
                  f"        brakesqueal_pad_residual_scale(y, {za}, p, scale);",
                  "        int done = 1;",
                  f"        for (int j = 0; j < {m}; ++j)",
                  f"            if (!(fabs(g[j]) <= {FLOOR} * scale[j])) done = 0;",
                  "        if (done) return 0; /* G = 0 to rounding */"]
        if dense:
            lines += [f"        double J[{m * m}], s[{m}];", f"        for (int j = 0; j < {m}; ++j) s[j] = g[j];",
                      f"        for (int j = 0; j < {m * m}; ++j) J[j] = g[{m} + j];",
                      f"        if (brakesqueal_solve_linear({m}, J, s)) return 1;",
                      f"        for (int j = 0; j < {m}; ++j) {{", "            const double step = s[j];"]
        else:
            lines += [
                f"        for (int j = 0; j < {m}; ++j) {{",
                f"            const double step = g[j] / g[{m} + j];",
            ]
        lines += ["            if (!isfinite(step)) return 1;", f"            {za}[j] -= step;",
                  f"            if (!(fabs(step) <= {RTOL} * fabs({za}[j]))) done = 0;", "        }",
                  "        if (done) return 0; /* converged steps */", "    }", "    return 1;", "}", ""]
    kept = [f"    dydt[{2 * n + k}] = {za}[{j}];" for k, j in enumerate(model.kept_index)]
    lines += [
        f"/* dy/dt = (Qdot, Qddot{', Ldot_kept' if model.kept else ''}) for given pad unknowns, M Qddot = -f; "
        "returns 0, or 2 if M is singular. */",
        f"int brakesqueal_state_derivative(const double *y, const double *{za}, const double *p, double *dydt)",
        "{",
        f"    double M[{n * n}], f[{n}];",
        f"    brakesqueal_mass_force(y, {za}, p, M, f);",
        f"    for (int i = 0; i < {n}; ++i) {{",
        f"        dydt[i] = y[{n} + i];",
        "        f[i] = -f[i];",
        "    }",
        f"    const int singular = brakesqueal_solve_linear({n}, M, f);",
        f"    for (int i = 0; i < {n}; ++i) dydt[{n} + i] = f[i];",
        *kept,
        "    return singular ? 2 : 0;",
        "}",
        "",
        "/* dy/dt with the pads solved first (t unused); returns 0 on success, 1 if the pads did not converge, "
        "2 if M is singular. */",
        "int brakesqueal_rhs(double t, const double *y, const double *p, double *dydt)",
        "{",
        f"    double {za}[{max(m, 1)}] = {{0.0}};",
        "    (void)t;",
        f"    const int pads = brakesqueal_solve_pads(y, p, {za});",
        f"    const int acc = brakesqueal_state_derivative(y, {za}, p, dydt);",
        "    return pads ? pads : acc;",
        "}",
        "",
    ]
    return lines


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

    head = [ln.replace("*/", "* /") for ln in model.header_lines()]
    lines = (
        ["/*"] + comment(head, " *") + [" *", f" * Compile: gcc -std=c99 -O2 -c {out_name}.c (link with -lm)", " */"]
    )
    lines += ["#include <math.h>", ""]
    for fn in model.functions:
        sig = ", ".join([f"const double *{a}" for a, _ in fn.inputs] + [f"double *{o}" for o, *_ in fn.outputs])
        lines += [f"/* {fn.doc}. */", f"void brakesqueal_{fn.name}({sig})", "{"]
        lines += [f"    (void){a};" for a in unused_arguments(fn)]
        lines += [f"    const double {n} = {a}[{i}];" for a, i, n in used_inputs(fn)]
        lines += [f"    const double {s} = {code(e)};" for s, e in fn.replacements]
        lines += [f"    {o}[{i}] = {code(e)};" for o, i, e in flat_outputs(fn)]
        lines += ["}", ""]
    if model.what == "nonlinear":
        lines += _helpers(model)
    vals = ", ".join(fmt_float(v) for v in model.parameter_values)
    k = len(model.parameter_values)
    lines += [
        f"/* The parameter set {model.parameter_source.replace('*/', '* /')} (p order as in the header). */",
        "void brakesqueal_parameters(double *p)",
        "{",
        f"    static const double values[{k}] = {{{vals}}};",
        f"    for (int i = 0; i < {k}; ++i) p[i] = values[i];",
        "}",
    ]
    return "\n".join(lines) + "\n"
