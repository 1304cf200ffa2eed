"""Python source generation from symengine expressions (with CSE).

Every generated function documents its argument order in its docstring and
takes ``(x, p)`` — the state in :data:`~brakesqueal.symbolic.model.STATE_SYMBOLS`
order and the parameters in :data:`~brakesqueal.symbolic.model.PARAMETER_SYMBOLS`
order — or ``(p,)`` alone.  The same source runs with ``math`` (fast scalars)
or ``numpy`` (vectorized over broadcastable arrays) functions bound.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

__all__ = ["FunctionSpec", "generate_module"]


@dataclass(frozen=True)
class FunctionSpec:
    """One function to generate.

    Attributes
    ----------
    name : str
        Function name.
    args : tuple of (str, sequence of symbols)
        Argument names and the symbols each unpacks into.
    outputs : sequence of expressions
        Flat list of output expressions (returned as a tuple).
    doc : str
        Docstring (meaning and shape of the outputs).
    """

    name: str
    args: tuple[tuple[str, Sequence[Any]], ...]
    outputs: Sequence[Any]
    doc: str


def _py(expr: Any) -> str:
    text = str(expr)
    # symengine prints Python-compatible infix; guard against the two non-Python tokens it may emit
    if "I" in text.split() or "zoo" in text or "nan" in text:
        raise ValueError(f"cannot generate numeric code for {text!r}")
    return text


def _function_source(spec: FunctionSpec) -> list[str]:
    import symengine as se

    lines = [f"def {spec.name}({', '.join(a for a, _ in spec.args)}):", f'    """{spec.doc}"""']
    for arg, syms in spec.args:
        names = ", ".join(str(s) for s in syms)
        lines.append(f"    ({names},) = {arg}")
    reps, reduced = se.cse([se.sympify(e) for e in spec.outputs])
    for sym, val in reps:
        lines.append(f"    {sym} = {_py(val)}")
    outs = ", ".join(_py(e) for e in reduced)
    lines.append(f"    return ({outs},)")
    return lines


def generate_module(specs: Sequence[FunctionSpec], header: str) -> str:
    """Source of a module defining every function of ``specs``.

    The module expects ``sin``, ``cos``, ``tan``, ``sqrt`` and ``pi`` in its
    globals (bound by the loader to ``math`` or ``numpy``).
    """
    lines = ['"""' + header + '"""', ""]
    for spec in specs:
        lines.extend(_function_source(spec))
        lines.append("")
    return "\n".join(lines) + "\n"
