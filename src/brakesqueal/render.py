"""Rendering of closed forms and linear models as text, LaTeX and JSON."""

from __future__ import annotations

import json
from typing import Any

import numpy as np

__all__ = ["render_closed_form", "render_linear_model", "render_model_closed_form", "render_built_linear", "FORMATS"]

FORMATS = ("text", "latex", "json")


def render_closed_form(case: str, fmt: str) -> str:
    """Render ``Mbar, Dbar, Kbar`` of a case (see :func:`~brakesqueal.symbolic.linearize.closed_form`)."""
    import sympy as sp

    from .symbolic.linearize import closed_form

    cf = closed_form(case)  # type: ignore[arg-type]
    mats = {"M": cf.M, "D": cf.D, "K": cf.K}
    if fmt == "json":
        data = {
            "case": case,
            "assumptions": cf.assumptions,
            "operating_point": "q_m0 = 0 (trivial silent motion)",
            **{k: [[str(e) for e in m.row(i)] for i in range(m.rows)] for k, m in mats.items()},
        }
        return json.dumps(data, indent=2)
    if fmt == "latex":
        body = [f"% brakesqueal closed form, case {case}: {cf.assumptions}"]
        for k, m in mats.items():
            body.append(rf"\bar{{\mathbf{{{k}}}}}_m = {sp.latex(m, mat_delim='[')}")
        return "\n\n".join(body)
    lines = [f"Case '{case}': {cf.assumptions}", "Linearized about q_m0 = 0 (eq. 47):", ""]
    for k, m in mats.items():
        for i in range(m.rows):
            for j in range(m.cols):
                lines.append(f"{k}bar[{i + 1},{j + 1}] = {sp.sstr(m[i, j])}")
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def _fmt_matrix(name: str, m: np.ndarray) -> list[str]:
    rows = [f"  [{', '.join(f'{v: .10e}' for v in row)}]" for row in m]
    return [f"{name} ="] + rows


def render_linear_model(lm: Any, fmt: str) -> str:
    """Render a :class:`~brakesqueal.analysis.linear.LinearModel` as text or JSON."""
    if fmt == "json":
        return json.dumps(lm.to_dict(), indent=2)
    lines = ["Parameters:"]
    for k, v in lm.params.to_json_dict().items():
        lines.append(f"  {k:6s} = {v}")
    kind = "trivial (eq. 49 holds)" if lm.silent.trivial else f"non-trivial, {lm.silent.iterations} Newton steps"
    lines.append(f"Silent motion: q_m0 = [{lm.q_m0[0]:.6e}, {lm.q_m0[1]:.6e}] rad ({kind})")
    lines.append(f"  normal forces F_n1, F_n2 = {lm.silent.normal_forces[0]:.6g}, {lm.silent.normal_forces[1]:.6g} N")
    lines += _fmt_matrix("M", lm.M) + _fmt_matrix("D", lm.D) + _fmt_matrix("K", lm.K)
    lines.append("Eigenvalues [1/s]          frequency [Hz]   damping ratio")
    for z in lm.eigenvalues:
        f = abs(z.imag) / (2 * np.pi)
        zeta = -z.real / abs(z) if abs(z) > 0 else 0.0
        lines.append(f"  {z.real: .6e} {z.imag:+.6e}j  {f:12.4f}  {zeta: .3e}")
    verdict = "UNSTABLE (squeal)" if lm.max_real > 0 else "stable"
    lines.append(f"Silent motion is {verdict}: max Re(lambda) = {lm.max_real:.6e} 1/s")
    return "\n".join(lines) + "\n"


def render_model_closed_form(spec: Any, fmt: str) -> str:
    """Render the symbolic ``M, D, K`` of a built model about the zero state."""
    import sympy as sp

    from .builder import model_closed_form

    M, D, K, coords = model_closed_form(spec)
    mats = {"M": M, "D": D, "K": K}
    note = "about the zero state (the silent motion when it is trivial)"
    if fmt == "json":
        data = {"model": spec.name, "coordinates": list(coords), "operating_point": note,
                **{k: [[str(e) for e in m.row(i)] for i in range(m.rows)] for k, m in mats.items()}}  # fmt: skip
        return json.dumps(data, indent=2)
    if fmt == "latex":
        body = [f"% brakesqueal model {spec.name}, coordinates {', '.join(coords)}, {note}"]
        body += [rf"\mathbf{{{k}}} = {sp.latex(m, mat_delim='[')}" for k, m in mats.items()]
        return "\n\n".join(body)
    lines = [f"Model '{spec.name}': {spec.description}", f"Coordinates: {', '.join(coords)}; linearized {note}", ""]
    for k, m in mats.items():
        for i in range(m.rows):
            for j in range(m.cols):
                if m[i, j] != 0:
                    lines.append(f"{k}[{coords[i]},{coords[j]}] = {sp.sstr(m[i, j])}")
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def render_built_linear(lm: Any, fmt: str) -> str:
    """Render a :class:`~brakesqueal.builder.BuiltLinearModel` as text or JSON."""
    params = {k: ("inf" if v == float("inf") else v) for k, v in lm.values.items()}
    if fmt == "json":
        return json.dumps({
            "model": lm.spec.name, "parameters": params, "coordinates": list(lm.coords),
            "Q0": [float(v) for v in lm.Q0], "M": lm.M.tolist(), "D": lm.D.tolist(), "K": lm.K.tolist(),
            "eigenvalues": [[float(z.real), float(z.imag)] for z in lm.eigenvalues],
        }, indent=2)  # fmt: skip
    lines = [f"Model '{lm.spec.name}' ({len(lm.coords)} DOF: {', '.join(lm.coords)})", "Parameters:"]
    lines += [f"  {k:8s} = {v}" for k, v in params.items()]
    lines.append("Silent motion: " + ", ".join(f"{c} = {v:.6e}" for c, v in zip(lm.coords, lm.Q0)))
    lines += _fmt_matrix("M", lm.M) + _fmt_matrix("D", lm.D) + _fmt_matrix("K", lm.K)
    lines.append("Eigenvalues [1/s]          frequency [Hz]   damping ratio")
    for z in lm.eigenvalues:
        zeta = -z.real / abs(z) if abs(z) > 0 else 0.0
        lines.append(f"  {z.real: .6e} {z.imag:+.6e}j  {abs(z.imag) / (2 * np.pi):12.4f}  {zeta: .3e}")
    verdict = "UNSTABLE (squeal)" if lm.max_real > 0 else "stable"
    lines.append(f"Silent motion is {verdict}: max Re(lambda) = {lm.max_real:.6e} 1/s")
    return "\n".join(lines) + "\n"
