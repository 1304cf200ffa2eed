"""Rendering of closed forms and linear models as text, LaTeX and JSON."""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING, Any, cast

import numpy as np

if TYPE_CHECKING:
    from .analysis.eigen import EigenAnalysis, Verdict
    from .analysis.linear import LinearModel
    from .model.components import ModelSpec
    from .symbolic.linearize import Case

__all__ = ["render_closed_form", "render_linear_model", "render_eigen", "render_model_closed_form", "FORMATS"]

FORMATS = ("text", "latex", "json")


def render_closed_form(case: str, fmt: str) -> str:
    """Render ``Mbar, Dbar, Kbar`` of a case (see :func:`~brakesqueal.symbolic.linearize.closed_form`)."""
    import sympy as sp

    from .symbolic.linearize import closed_form

    cf = closed_form(cast("Case", case))  # closed_form refuses an unknown case
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


def _unit(coord: str) -> str:
    from .model.components import coordinate_unit

    return coordinate_unit(coord)


#: Largest model whose matrices the text output of ``linearize`` prints.
MAX_PRINTED_DOF = 12


def render_linear_model(lm: LinearModel, fmt: str) -> str:
    """Render a :class:`~brakesqueal.analysis.linear.LinearModel` (any model) as text or JSON.

    The verdict is that of :meth:`EigenAnalysis.verdict
    <brakesqueal.analysis.eigen.EigenAnalysis.verdict>` (stable, unstable or
    undecided within its error bound), the same everywhere.
    """
    from .analysis.eigen import eigen_analysis

    v = eigen_analysis(lm).verdict()
    if fmt == "json":
        d = lm.to_dict()
        d["verdict"] = _verdict_dict(v)
        return json.dumps(_json_safe(d), indent=2, allow_nan=False)
    sm = lm.silent
    lines = [f"Model '{lm.model.name}' ({lm.n} DOF: {', '.join(lm.coords)})", "Parameters:"]
    for k, val in lm.params.to_json_dict().items():
        lines.append(f"  {k:8s} = {val}")
    if sm.method == "matrices":
        lines[0] = f"Model '{lm.model.name}' ({lm.n} DOF, given by coefficient matrices)"
        lines.append("Linearization: the model's matrices at these parameters (silent motion x = 0)")
    else:
        kind = "trivial" if sm.trivial else f"non-trivial ({sm.method}, {sm.iterations} iterations)"
        lines.append("Silent motion (eq. 46): " + ", ".join(f"{c} = {x:.6e} {_unit(c)}"
                                                            for c, x in zip(lm.coords, lm.q0)) + f"  [{kind}]")
        pads = [p.name for p in lm.model.pads]
        lines.append("  normal forces: " + ", ".join(f"pad {n}: {f:.6g} N" for n, f in zip(pads, sm.normal_forces)))
    if lm.n <= MAX_PRINTED_DOF:
        lines += _fmt_matrix("M", lm.M) + _fmt_matrix("D", lm.D) + _fmt_matrix("K", lm.K)
    else:
        lines.append(f"M, D, K: {lm.n} x {lm.n} (not printed above {MAX_PRINTED_DOF} DOF; --format json lists them)")
    if lm.pad_states:
        lines.append(f"Pads kept as first-order states (tangential rates matter here): {', '.join(lm.pad_states)}")
    lines.append("Eigenvalues [1/s]          frequency [Hz]   damping ratio")
    for z in lm.eigenvalues:
        f = abs(z.imag) / (2 * np.pi)
        zeta = -z.real / abs(z) if abs(z) > 0 else 0.0
        lines.append(f"  {z.real: .6e} {z.imag:+.6e}j  {_hz(f)}  {zeta: .3e}")
    lines += verdict_lines(v)
    return "\n".join(lines) + "\n"


def verdict_lines(v: Verdict) -> list[str]:
    """The verdict in words: what it is, what carries it, how it is certified (and, for a verdict carried by a
    massless pad's own tangential rate, that pad's effective damping and the disk modes' verdict)."""
    if v.pad_mode:
        word = {"stable": "stable", "unstable": "UNSTABLE", "undecided": "UNDECIDED"}[v.status]
    else:
        word = {"stable": "stable", "unstable": "UNSTABLE (squeal)", "undecided": "UNDECIDED"}[v.status]
    how = _how(v)
    head = f"Silent motion is {word}: max Re(lambda) = {v.max_real:.6e} 1/s"
    if v.carrier and not v.pad_mode:
        f = "" if not math.isfinite(v.frequency) else f" at {v.frequency:.6g} Hz"
        head += f", carried by a {v.carrier} mode{f}"
    lines = [f"{head} ({how})"]
    if not v.listed_resolved:
        lines.append(f"  note: the listed eigenvalues are those of the matrices rounded to double precision; here they "
                     f"are not resolved (largest real part {v.listed:.3e} 1/s, error bound {v.listed_bound:.1e} "
                     "1/s); the verdict is that of the exact linearization")
    if v.pad_mode:
        c = v.pad_damping
        pad = (v.carrier or "").removesuffix(" tangential rate")  # pad_mode: a carrier
        lines.append(f"  carried by {pad}'s tangential rate: a non-oscillatory mode of the massless pad alone, not "
                     "a disk vibration")
        if c is not None and math.isfinite(c):
            fix = (f"; a tangential damper d_ip above {abs(c):.2g} N s/m (or pad mass with damping) removes it"
                   if c < 0 else "")
            lines.append(f"  its effective tangential damping is {c:.3g} N s/m{fix}")
        if v.disk is not None:
            d = v.disk
            lines.append(f"  disk modes alone: {d.status}, max Re(lambda) = {d.max_real:.6e} 1/s ({_how(d)})")
    return lines


def _how(v: Verdict) -> str:
    """How a verdict is certified: its error bound (smaller than the margin) or the route that decided it."""
    if v.status == "undecided":
        b = float(v.error_bound)
        return f"|max Re| within its error bound {b:.1e} 1/s" if math.isfinite(b) else "not certifiable"
    if math.isfinite(float(v.error_bound)):
        return f"error bound {float(v.error_bound):.1e} 1/s; route {v.method}"
    return f"certified by route {v.method}"


def _hz(f: float, width: int = 12) -> str:
    """A frequency in a column (scientific notation from 1e9 Hz: a 1e46 pad mode took 46 digits)."""
    return f"{f:{width}.4f}" if f < 1e9 else f"{f:{width}.4e}"


def _json_safe(obj: Any) -> Any:
    """``obj`` with every non-finite float replaced by ``None`` (JSON has no Infinity or NaN)."""
    if isinstance(obj, dict):
        return {k: _json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_safe(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def _verdict_dict(v: Verdict) -> dict[str, Any]:
    """The verdict as JSON (a non-finite error bound is ``null``: JSON has no Infinity)."""
    b = float(v.error_bound)
    out = {"status": v.status, "max_real": v.max_real, "error_bound": b if math.isfinite(b) else None,
           "frequency": v.frequency, "carrier": v.carrier, "route": v.method}
    if v.pad_mode:
        out["pad_damping"] = v.pad_damping
        if v.disk is not None:
            out["disk_modes"] = _verdict_dict(v.disk)
    return out


def render_eigen(ea: EigenAnalysis, fmt: str, *, mode: int = 0) -> str:
    """Render an :class:`~brakesqueal.analysis.eigen.EigenAnalysis`: modes, sensitivities, attribution of Re λ."""
    lm = ea.model
    v = ea.verdict()
    sens = ea.parameter_sensitivities()
    contrib = {} if lm.pad_states else {n: ea.contributions(n, mode) for n in lm.params.names}
    if fmt == "json":
        return json.dumps(_json_safe({
            "model": lm.model.name, "parameters": lm.params.to_json_dict(), "coords": list(lm.coords),
            "verdict": _verdict_dict(v),
            "modes": [{"eigenvalue": [float(z.real), float(z.imag)], "frequency_hz": float(f),
                       "damping_ratio": float(zt), "condition": float(c),
                       "shape": [[float(x.real), float(x.imag)] for x in ea.modes[:, i]]}
                      for i, (z, f, zt, c) in enumerate(zip(ea.eigenvalues, ea.frequencies, ea.damping_ratios,
                                                             ea.condition))],
            "sensitivities": {n: [[float(x.real), float(x.imag)] for x in s] for n, s in sens.items()},
            "attribution": {"mode": mode, "d_Re_lambda_d_ln_p": contrib},
        }), indent=2, allow_nan=False) + "\n"
    lines = [f"Model '{lm.model.name}': verdict {v.status}, max Re(lambda) = {v.max_real:.6e} 1/s "
             f"({_how(v)})", *verdict_lines(v)[1:], "",
             "mode  Re(lambda) [1/s]   frequency [Hz]  damping ratio  condition   shape (|x|, largest first)"]
    for i, (z, f, zt, c) in enumerate(zip(ea.eigenvalues, ea.frequencies, ea.damping_ratios, ea.condition)):
        x = ea.modes[:, i]
        order = np.argsort(-np.abs(x))[:3]
        shape = ", ".join(f"{lm.coords[k]} {abs(x[k]):.3f}" for k in order)
        lines.append(f"{i:4d}  {z.real: .6e}  {_hz(f, 14)}  {zt: .3e}  {c:9.3g}   {shape}")
    lines += ["", f"Sensitivities d Re(lambda_{mode}) / d ln p [1/s]:"]
    ranked = sorted(sens.items(), key=lambda kv: -abs(kv[1][mode].real))
    for n, s in ranked:
        if s[mode] != 0:
            lines.append(f"  {n:8s} {s[mode].real: .6e}")
    if contrib:
        lines += ["", f"Attribution of d Re(lambda_{mode}) / d ln p to matrix entries (largest parameters):"]
        for n, _ in ranked[:3]:
            parts = sorted(contrib[n].items(), key=lambda kv: -abs(kv[1]))[:4]
            total = sum(contrib[n].values()) or 1.0
            lines.append(f"  {n:8s} " + ", ".join(f"{k} {100 * val / total:.1f}%" for k, val in parts))
    return "\n".join(lines) + "\n"


def render_model_closed_form(spec: ModelSpec, fmt: str) -> str:
    """Render the symbolic ``M, D, K`` of any model about the zero state (and kept pad blocks)."""
    import sympy as sp

    from .symbolic.linearize import model_closed_form

    cf = model_closed_form(spec)
    coords = cf.coords
    mats = {"M": cf.M, "D": cf.D, "K": cf.K}
    note = "about the zero state (the silent motion when it is trivial)"
    extra = {k: v for k, v in cf.rate_blocks.items() if k != "pads"}
    if fmt == "json":
        data = {"model": spec.name, "coordinates": list(coords), "operating_point": note,
                **{k: [[str(e) for e in m.row(i)] for i in range(m.rows)] for k, m in mats.items()}}  # fmt: skip
        if extra:
            data["pad_states"] = list(cf.rate_blocks["pads"])
            data.update({k: [[str(e) for e in m.row(i)] for i in range(m.rows)] for k, m in extra.items()})
        return json.dumps(data, indent=2)
    if fmt == "latex":
        body = [f"% brakesqueal model {spec.name}, coordinates {', '.join(coords)}, {note}"]
        body += [rf"\mathbf{{{k}}} = {sp.latex(m, mat_delim='[')}" for k, m in {**mats, **extra}.items()]
        return "\n\n".join(body)
    lines = [f"Model '{spec.name}': {spec.description}", f"Coordinates: {', '.join(coords)}; linearized {note}", ""]
    for k, m in mats.items():
        for i in range(m.rows):
            for j in range(m.cols):
                if m[i, j] != 0:
                    lines.append(f"{k}[{coords[i]},{coords[j]}] = {sp.sstr(m[i, j])}")
        lines.append("")
    if extra:
        lines.append(f"Pads with first-order dynamics at the zero state: {', '.join(cf.rate_blocks['pads'])}")
        for k, m in extra.items():
            lines.append(f"{k} = {sp.sstr(m)}")
    return "\n".join(lines).rstrip() + "\n"
