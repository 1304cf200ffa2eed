"""A standalone, compilable LaTeX document (``amsmath``) of an exported model.

The document lists the argument order and units, the common subexpressions
``w_k`` and then the outputs, one ``align*`` line each (long lines are left to
overflow rather than broken by hand; ``pdflatex`` reports them as overfull
boxes, not errors).
"""

from __future__ import annotations

from typing import Any

from .model import PARAMETER_UNITS, STATE_UNITS, ExportModel

__all__ = ["print_latex", "SYMBOL_NAMES"]

#: LaTeX name of every state and parameter symbol.
SYMBOL_NAMES: dict[str, str] = {
    "q1": "q_1", "q2": "q_2", "dq1": r"\dot q_1", "dq2": r"\dot q_2", "ddq1": r"\ddot q_1", "ddq2": r"\ddot q_2",
    "l1": "l_1", "l2": "l_2", "dl1": r"\dot l_1", "dl2": r"\dot l_2",
    "Theta": r"\Theta", "Phi": r"\Phi", "k_t": r"k_{t}", "d_t": r"d_{t}", "k1": "k_1", "k2": "k_2",
    "d1": "d_1", "d2": "d_2", "c_ip1": r"c_{ip,1}", "c_ip2": r"c_{ip,2}", "mu1": r"\mu_1", "mu2": r"\mu_2",
    "h10": "h_{10}", "h20": "h_{20}", "r": "r", "N0": "N_0", "Omega": r"\Omega",
}  # fmt: skip

_OUTPUT_NAMES = {
    "psi1": r"\psi_1", "psi2": r"\psi_2", "g1": "g_1", "g2": "g_2", "dg1/dl1": r"\partial g_1/\partial l_1",
    "dg2/dl2": r"\partial g_2/\partial l_2", "dq1": r"\dot q_1", "dq2": r"\dot q_2", "ddq1": r"\ddot q_1",
    "ddq2": r"\ddot q_2",
}  # fmt: skip


def _unit(u: str) -> str:
    """Math-mode unit: ``"kg m^2"`` -> ``\\mathrm{kg}\\,\\mathrm{m}^{2}``."""
    if u == "1":
        return "1"
    parts = []
    for tok in u.split(" "):
        base, _, exp = tok.partition("^")
        parts.append(r"\mathrm{" + base + "}" + (f"^{{{exp}}}" if exp else ""))
    return r"\,".join(parts)


def _tex_escape(text: str) -> str:
    for a, b in (("\\", r"\textbackslash{}"), ("_", r"\_"), ("%", r"\%"), ("&", r"\&"), ("#", r"\#"), ("^", r"\^{}")):
        text = text.replace(a, b)
    return text


def _output_name(label: str) -> str:
    if label in _OUTPUT_NAMES:
        return _OUTPUT_NAMES[label]
    # matrix entries "D21" -> \bar{D}_{21}
    return rf"\bar{{{label[0]}}}_{{{label[1:]}}}"


def print_latex(model: ExportModel, out_name: str = "brakesqueal_model") -> str:
    """Standalone LaTeX document of ``model``.

    Parameters
    ----------
    model : ExportModel
        What to print.
    out_name : str
        Stem of the output file, used in a comment only.

    Returns
    -------
    str
    """
    import sympy as sp

    names: dict[Any, str] = {sp.Symbol(k): v for k, v in SYMBOL_NAMES.items()}

    def tex(e: Any) -> str:
        local = dict(names)
        for s in e.free_symbols:
            n = str(s)
            if n.startswith("w") and n[1:].isdigit():
                local[s] = f"w_{{{n[1:]}}}"
        return sp.latex(e, symbol_names=local, mul_symbol=None)

    head = model.header_lines()
    lines = ["% " + ln if ln else "%" for ln in head]
    lines += [f"% Compile: pdflatex {out_name}.tex", r"\documentclass[a4paper,10pt]{article}",
              r"\usepackage{amsmath}", r"\allowdisplaybreaks",
              r"\begin{document}", r"\section*{brakesqueal: " + _tex_escape(head[0].split(": ", 1)[1].rstrip(".")) + "}",
              "", r"\subsection*{Arguments}", r"\begin{tabular}{lll}", r"symbol & meaning & unit \\ \hline"]  # fmt: skip
    if model.what == "nonlinear":
        for n, u in STATE_UNITS.items():
            lines.append(rf"${SYMBOL_NAMES[n]}$ & state & ${_unit(u)}$ \\")
    for n, u in PARAMETER_UNITS.items():
        meaning = r"compliance $1/k_{ip}$ (0: rigid support)" if n.startswith("c_ip") else "parameter"
        lines.append(rf"${SYMBOL_NAMES[n]}$ & {meaning} & ${_unit(u)}$ \\")
    lines += [r"\end{tabular}", ""]
    if model.what == "nonlinear":
        lines += [
            r"The pads are quasi-static: $\dot l = 0$ in the sliding velocities; $l$ follows $(q,\dot q)$ "
            r"through $g = 0$. The equations of motion are $\psi = 0$ (eq.~44), the pads' tangential "
            r"equilibria $g = 0$ (eqs.~33--34).",
            "",
        ]
    else:
        lines += [
            r"Linearization about the trivial silent motion $q_{m0} = 0$ (eqs.~47--48, valid when "
            r"$\mu_1 h_{10} = \mu_2 h_{20}$, eq.~49): "
            r"$\bar M \ddot q + \bar D \dot q + \bar K q = 0$.",
            "",
        ]
    for fn in model.functions:
        lines += [r"\subsection*{" + _tex_escape(fn.name) + "}", _tex_escape(fn.doc) + ".", ""]
        if fn.replacements:
            lines += [r"\paragraph{Common subexpressions}", r"\begin{align*}"]
            lines += [rf"{tex(s)} &= {tex(e)} \\" for s, e in fn.replacements]
            lines[-1] = lines[-1].removesuffix(r" \\")
            lines += [r"\end{align*}"]
        lines += [r"\paragraph{Outputs}", r"\begin{align*}"]
        k = 0
        for _, labels, _ in fn.outputs:
            for lab in labels:
                lines.append(rf"{_output_name(lab)} &= {tex(fn.exprs[k])} \\")
                k += 1
        lines[-1] = lines[-1].removesuffix(r" \\")
        lines += [r"\end{align*}", ""]
    vals = [rf"{SYMBOL_NAMES[n]} = {v!r}" for n, v in zip(PARAMETER_UNITS, model.parameter_values)]
    rows = [r",\quad ".join(vals[i : i + 6]) for i in range(0, len(vals), 6)]
    lines += [r"\subsection*{Parameter set}", _tex_escape(model.parameter_source) + ":", r"\begin{gather*}"]
    lines += [" \\\\\n".join(rows), r"\end{gather*}"]
    lines += [r"\end{document}"]
    return "\n".join(lines) + "\n"
