"""GNU Octave / MATLAB printer of an :class:`~.model.ExportModel`.

One function file: its main function, named after the file, returns a struct
of function handles (``m = name(); m.rhs(t, y, p)``); inputs and outputs are
column vectors, matrices ``n × n`` (``k × n`` ...).  The linear solves use
``\\``.
"""

from __future__ import annotations

from typing import Any

from ._common import (FLOOR, MAXIT, RTOL, comment, fmt_float, function_names, grouped, is_number, used_inputs,
                      with_temporaries)
from .model import ExportModel

__all__ = ["print_octave"]


def _assemble(o: str, shape: tuple[int, ...], entries: list[str]) -> str:
    if len(shape) == 1:
        return f"  {o} = [" + "; ".join(entries) + "];"
    r, c = shape
    rows = [", ".join(entries[i * c : (i + 1) * c]) for i in range(r)]
    return f"  {o} = [" + "; ".join(rows) + "];"


def _helpers(model: ExportModel) -> list[str]:
    n, m, za = model.n, model.m, model.z_arg
    lines = [f"function {za} = solve_pads(y, p)",
             f"  % Newton's method for G(y, {za}) = 0 from {za} = 0 (the pad unknowns, see the header)."]
    if m == 0:
        lines += [f"  {za} = zeros(0, 1);", "end", ""]
    else:
        step = (f"reshape(g({m + 1}:end), {m}, {m}).' \\ r" if model.pad_jacobian == "dense"
                else f"r ./ g({m + 1}:{2 * m})")
        lines += [
            f"  {za} = zeros({m}, 1);",
            f"  for it = 1:{MAXIT}",
            f"    g = pad_residuals(y, {za}, p);",
            f"    scale = pad_residual_scale(y, {za}, p);",
            f"    r = g(1:{m});",
            f"    if all(abs(r) <= {FLOOR} * scale)",
            "      return;  % G = 0 to rounding",
            "    end",
            f"    s = {step};",
            "    if ~all(isfinite(s))",
            "      break;",
            "    end",
            f"    {za} = {za} - s;",
            f"    if all(abs(s) <= {RTOL} * abs({za}))",
            "      return;",
            "    end",
            "  end",
            "  error('brakesqueal:solve_pads', 'Newton iteration for the pad unknowns did not converge');",
            "end",
            "",
        ]
    kept = "".join(f"; {za}({j + 1})" for j in model.kept_index)
    lines += [
        f"function dydt = state_derivative(y, {za}, p)",
        f"  % dy/dt = (Qdot, Qddot{', Ldot_kept' if model.kept else ''}) for given pad unknowns, M Qddot = -f.",
        f"  [M, f] = mass_force(y, {za}, p);",
        f"  dydt = [y({n + 1}:{2 * n}); -(M \\ f){kept}];",
        "end",
        "",
        "function dydt = rhs(t, y, p)",
        "  % dy/dt with the pads solved first (t unused), e.g. ode45(@(t, y) m.rhs(t, y, p), ...).",
        "  dydt = state_derivative(y, solve_pads(y, p), p);",
        "end",
        "",
    ]
    return lines


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

    def code(e: Any) -> str:
        return fmt_float(float(e)) if is_number(e) and not e.is_Integer else octave_code(e)

    names = function_names(model)
    lines = [f"function m = {out_name}()"]
    lines += comment([f"{out_name}: brakesqueal exported model; m = {out_name}(); m.<function>(...)."], "%")
    lines += comment([""] + model.header_lines() + ["", "Vectors are columns, matrices rows x columns."], "%")
    lines += [f"  m.{n} = @{n};" for n in names]
    lines += ["end", ""]
    for fn in model.functions:
        outs = [o for o, *_ in fn.outputs]
        lhs = outs[0] if len(outs) == 1 else "[" + ", ".join(outs) + "]"
        lines += [f"function {lhs} = {fn.name}({', '.join(a for a, _ in fn.inputs)})", f"  % {fn.doc}."]
        lines += [f"  {n} = {a}({i + 1});" for a, i, n in used_inputs(fn)]
        lines += [f"  {s} = {code(e)};" for s, e in fn.replacements]
        for o, shape, exprs in grouped(fn):
            assigns, entries = with_temporaries(o, exprs, code, "  {} = {};")
            lines += assigns
            lines.append(_assemble(o, shape, entries))
        lines += ["end", ""]
    if model.what == "nonlinear":
        lines += _helpers(model)
    vals = "; ".join(fmt_float(v) for v in model.parameter_values)
    lines += [
        "function p = parameters()",
        f"  % The parameter set {model.parameter_source}.",
        f"  p = [{vals}];",
        "end",
    ]
    return "\n".join(lines) + "\n"
