"""A standalone, compilable LaTeX document (``amsmath``) of an exported model.

The document lists the argument order and units, the common subexpressions
and then the outputs, one ``align*`` line each (long lines are left to
overflow rather than broken by hand; ``pdflatex`` reports them as overfull
boxes, not errors).
"""

from __future__ import annotations

from typing import Any

from .model import ExportModel

__all__ = ["print_latex", "SYMBOL_NAMES"]

#: LaTeX name of the paper model's state and parameter symbols (other names: :func:`.names.latex_symbol`).
SYMBOL_NAMES: dict[str, str] = {
    "q1": "q_1", "q2": "q_2", "dq1": r"\dot q_1", "dq2": r"\dot q_2", "ddq1": r"\ddot q_1", "ddq2": r"\ddot q_2",
    "l1": "l_1", "l2": "l_2", "dl1": r"\dot l_1", "dl2": r"\dot l_2",
    "Theta": r"\Theta", "Phi": r"\Phi", "k_t": r"k_{t}", "d_t": r"d_{t}", "k1": "k_1", "k2": "k_2",
    "d1": "d_1", "d2": "d_2", "c_ip1": r"c_{ip,1}", "c_ip2": r"c_{ip,2}", "mu1": r"\mu_1", "mu2": r"\mu_2",
    "h10": "h_{10}", "h20": "h_{20}", "r": "r", "N0": "N_0", "Omega": r"\Omega",
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
    out = []
    for ch in text:
        out.append({"\\": r"\textbackslash{}", "_": r"\_", "%": r"\%", "&": r"\&", "#": r"\#", "^": r"\^{}",
                    "$": r"\$", "{": r"\{", "}": r"\}", "~": r"\~{}"}.get(ch, ch))
    return "".join(out)


def _symbol(name: str, model: ExportModel) -> str:
    from .names import is_identifier, latex_symbol

    if name in SYMBOL_NAMES:
        return SYMBOL_NAMES[name]
    if name in model.latex:
        return model.latex[name]
    return latex_symbol(name) if is_identifier(name) else r"\mathrm{" + _tex_escape(name) + "}"


def _output_name(label: str, model: ExportModel) -> str:
    """LaTeX of an output label: ``psi1`` → ``\\psi_{1}``, ``R_w1`` → ``R_{w1}``, ``M12`` → ``\\bar{M}_{12}``."""
    from .names import latex_symbol

    if "/" in label:  # a derivative dg1/dl1
        num, den = label.split("/", 1)
        return rf"\partial {_output_name(num[1:], model)}/\partial {_symbol(den[1:], model)}"
    if label.startswith("scale_"):
        return r"s\left(" + _output_name(label[len("scale_"):], model) + r"\right)"
    if label.startswith("f_"):
        return r"f\left(" + _output_name(label[2:], model) + r"\right)"
    for block in ("R_dL", "R_L", "G_dQ", "G_Q", "G_dL", "G_L", "M", "D", "K"):
        if label.startswith(block) and label[len(block):].replace("_", "").isdigit():
            idx = label[len(block):]
            idx = idx if "_" not in idx else idx.replace("_", ",")
            head = block if "_" not in block else block.split("_")[0] + "_{" + block.split("_")[1] + "}"
            bar = r"\bar{" + head + "}" if model.what == "linear" and "_" not in block else head
            return rf"{bar}_{{{idx}}}" if "_" not in block else rf"\left({bar}\right)_{{{idx}}}"
    if label.startswith("psi") and label[3:].isdigit():
        return rf"\psi_{{{label[3:]}}}"
    if label.startswith(("R_", "g")):
        return latex_symbol(label)
    return r"\mathrm{" + _tex_escape(label) + "}"


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

    inputs = {n for fn in model.functions for _, names in fn.inputs for n in names}
    names: dict[Any, str] = {sp.Symbol(k): _symbol(k, model) for k in inputs}

    def tex(e: Any) -> str:
        local = dict(names)
        for s in e.free_symbols:
            n = str(s)
            if s not in local:
                head = n.rstrip("0123456789")
                local[s] = f"{head}_{{{n[len(head):]}}}" if head != n else n
        return sp.latex(e, symbol_names=local, mul_symbol=None)

    head = model.header_lines()
    title = head[0].split(": ", 1)[1].rstrip(".")
    lines = ["% " + ln if ln else "%" for ln in head]
    lines += [f"% Compile: pdflatex {out_name}.tex", r"\documentclass[a4paper,10pt]{article}",
              r"\usepackage{amsmath}", r"\allowdisplaybreaks",
              r"\begin{document}", r"\section*{brakesqueal: " + _tex_escape(title) + "}", ""]  # fmt: skip
    if model.description:
        lines += [_tex_escape(f"Model '{model.model_name}': {model.description}"), ""]
    lines += [r"\subsection*{Arguments}", r"\begin{tabular}{lll}", r"symbol & meaning & unit \\ \hline"]
    if model.what == "nonlinear":
        for n, u in zip(model.x_names, model.units(model.x_names)):
            lines.append(rf"${_symbol(n, model)}$ & state & ${_unit(u)}$ \\")
    comp = {c: k for c, k in model.compliances}
    for n, u in zip(model.parameter_names, model.parameter_units):
        meaning = rf"compliance $1/{_symbol(comp[n], model)}$ (0: rigid support)" if n in comp else "parameter"
        lines.append(rf"${_symbol(n, model)}$ & {meaning} & ${_unit(u)}$ \\")
    lines += [r"\end{tabular}", ""]
    lines += [_tex_escape(" ".join(note.strip() for note in model.notes)), ""]
    for fn in model.functions:
        lines += [r"\subsection*{" + _tex_escape(fn.name) + "}", _tex_escape(fn.doc) + ".", ""]
        if fn.replacements:
            lines += [r"\paragraph{Common subexpressions}", r"\begin{align*}"]
            lines += [rf"{tex(s)} &= {tex(e)} \\" for s, e in fn.replacements]
            lines[-1] = lines[-1].removesuffix(r" \\")
            lines += [r"\end{align*}"]
        lines += [r"\paragraph{Outputs}", r"\begin{align*}"]
        k = 0
        for _, labels, _, _ in fn.outputs:
            for lab in labels:
                lines.append(rf"{_output_name(lab, model)} &= {tex(fn.exprs[k])} \\")
                k += 1
        lines[-1] = lines[-1].removesuffix(r" \\")
        lines += [r"\end{align*}", ""]
    vals = [rf"{_symbol(n, model)} = {v!r}" for n, v in zip(model.parameter_names, model.parameter_values)]
    rows = [r",\quad ".join(vals[i : i + 5]) for i in range(0, len(vals), 5)]
    lines += [r"\subsection*{Parameter set}", _tex_escape(model.parameter_source) + ":", r"\begin{gather*}"]
    lines += [" \\\\\n".join(rows), r"\end{gather*}"]
    lines += [r"\end{document}"]
    return "\n".join(lines) + "\n"
