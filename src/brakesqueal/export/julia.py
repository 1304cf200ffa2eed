"""Julia printer of an :class:`~.model.ExportModel`: ``module BrakesquealModel``.

Vectors are 1-based, matrices ``Matrix{Float64}`` (``n × n``, ...); the
linear solves use ``\\``.
"""

from __future__ import annotations

from typing import Any

from ._common import (FLOOR, MAXIT, RTOL, comment, fmt_float, function_names, grouped, is_number, used_inputs,
                      with_temporaries)
from .model import ExportModel

__all__ = ["print_julia"]


def _doc(text: str) -> str:
    """A Julia docstring literal (no interpolation, no escapes)."""
    return '"""' + text.replace("\\", "\\\\").replace("$", "\\$").replace('"', "'") + '"""'


def _assemble(o: str, shape: tuple[int, ...], entries: list[str]) -> str:
    if len(shape) == 1:
        return f"    {o} = [" + ", ".join(entries) + "]"
    r, c = shape
    if r == 1 or c == 1:  # a literal with one row or column would be a vector
        return f"    {o} = reshape([" + ", ".join(entries) + f"], {r}, {c})"
    rows = [" ".join(entries[i * c : (i + 1) * c]) for i in range(r)]
    return f"    {o} = [" + "; ".join(rows) + "]"


def _helpers(model: ExportModel) -> list[str]:
    n, m, za = model.n, model.m, model.z_arg
    if m == 0:
        lines = [f'"""Pad unknowns {za} (none in this model)."""', "solve_pads(y, p) = Float64[]", ""]
    else:
        step = (f"permutedims(reshape(g[{m + 1}:end], {m}, {m})) \\ r" if model.pad_jacobian == "dense"
                else f"r ./ g[{m + 1}:{2 * m}]")
        lines = [
            f'"""Newton\'s method for G(y, {za}) = 0 from {za} = 0; returns the pad unknowns {za} (see the header)."""',
            "function solve_pads(y, p)",
            f"    {za} = zeros({m})",
            f"    for it in 1:{MAXIT}",
            f"        g = pad_residuals(y, {za}, p)",
            f"        scale = pad_residual_scale(y, {za}, p)",
            f"        r = g[1:{m}]",
            f"        if all(abs.(r) .<= {FLOOR} .* scale)",
            f"            return {za}  # G = 0 to rounding",
            "        end",
            f"        s = {step}",
            "        if !all(isfinite.(s))",
            "            break",
            "        end",
            f"        {za} = {za} .- s",
            f"        if all(abs.(s) .<= {RTOL} .* abs.({za}))",
            f"            return {za}",
            "        end",
            "    end",
            '    error("Newton iteration for the pad unknowns did not converge")',
            "end",
            "",
        ]
    kept = "".join(f", {za}[{j + 1}]" for j in model.kept_index)
    lines += [
        f'"""dy/dt = (Qdot, Qddot{", Ldot_kept" if model.kept else ""}) for given pad unknowns, M Qddot = -f."""',
        f"function state_derivative(y, {za}, p)",
        f"    M, f = mass_force(y, {za}, p)",
        f"    return vcat(y[{n + 1}:{2 * n}], -(M \\ f){kept})",
        "end",
        "",
        '"""dy/dt with the pads solved first (t unused)."""',
        "rhs(t, y, p) = state_derivative(y, solve_pads(y, p), p)",
        "",
    ]
    return lines


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

    def code(e: Any) -> str:
        return fmt_float(float(e)) if is_number(e) else julia_code(e)

    names = function_names(model)
    lines = comment(model.header_lines() + ["", f'Use: include("{out_name}.jl"); using .BrakesquealModel'], "#")
    lines += ["module BrakesquealModel", "", "export " + ", ".join(names), ""]
    for fn in model.functions:
        lines += [_doc(fn.doc + "."), f"function {fn.name}({', '.join(a for a, _ in fn.inputs)})"]
        lines += [f"    {n} = {a}[{i + 1}]" for a, i, n in used_inputs(fn)]
        lines += [f"    {s} = {julia_code(e)}" for s, e in fn.replacements]
        results = []
        for o, shape, exprs in grouped(fn):
            assigns, entries = with_temporaries(o, exprs, code, "    {} = {}")
            lines += assigns
            lines.append(_assemble(o, shape, entries))
            results.append(o)
        lines += [f"    return {', '.join(results)}", "end", ""]
    if model.what == "nonlinear":
        lines += _helpers(model)
    vals = ", ".join(fmt_float(v) for v in model.parameter_values)
    lines += [_doc(f"The parameter set {model.parameter_source}."), f"parameters() = [{vals}]", "", "end # module"]
    return "\n".join(lines) + "\n"
