"""Python source generation from symengine expressions (with CSE).

Every generated function documents its argument order in its docstring and
takes ``(x, p)`` — the state in :data:`~brakesqueal.symbolic.model.STATE_SYMBOLS`
order and the parameters in :data:`~brakesqueal.symbolic.model.PARAMETER_SYMBOLS`
order — or ``(p,)`` alone.  The same source runs with ``math`` (fast scalars)
or ``numpy`` (vectorized over broadcastable arrays) functions bound; with a
decorator, index unpacking and an output array the same printer writes numba
kernels (:mod:`brakesqueal.simulation._kernels`).
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


def _function_source(spec: FunctionSpec, *, decorator: str | None = None, unpack: str = "tuple",
                     out: str | None = None) -> list[str]:
    import symengine as se

    args = [a for a, _ in spec.args] + ([out] if out else [])
    lines = [decorator] if decorator else []
    lines += [f"def {spec.name}({', '.join(args)}):", f'    """{spec.doc}"""']
    for arg, syms in spec.args:
        if unpack == "index":
            lines.extend(f"    {s} = {arg}[{i}]" for i, s in enumerate(syms))
        elif syms:
            names = ", ".join(str(s) for s in syms)
            lines.append(f"    ({names},) = {arg}")
    reps, reduced = se.cse([se.sympify(e) for e in spec.outputs])
    for sym, val in reps:
        lines.append(f"    {sym} = {_py(val)}")
    if out:
        lines.extend(f"    {out}[{i}] = {_py(e)}" for i, e in enumerate(reduced))
        lines.append("    return None")
    else:
        outs = ", ".join(_py(e) for e in reduced)
        lines.append(f"    return ({outs},)" if reduced else "    return ()")
    return lines


def generate_module(specs: Sequence[FunctionSpec], header: str, *, decorator: str | None = None,
                    unpack: str = "tuple", out: str | None = None, preamble: str = "") -> str:
    """Source of a module defining every function of ``specs``.

    The module expects ``sin``, ``cos``, ``tan``, ``sqrt``, ``exp``, ``log``
    and ``pi`` in its globals (bound by the loader to ``math`` or ``numpy``,
    or imported by ``preamble``).

    Parameters
    ----------
    specs : sequence of FunctionSpec
        The functions.
    header : str
        Module docstring.
    decorator : str, optional
        A line put before every ``def`` (e.g. ``"@njit(cache=True)"`` for numba).
    unpack : {"tuple", "index"}, optional
        How arguments are unpacked into their symbols: one tuple assignment
        (default) or one ``name = arg[i]`` line per symbol (numba arrays).
    out : str, optional
        Name of an output array appended to every signature: the outputs are
        stored into it (``out[i] = ...``) and the function returns ``None``
        instead of a tuple.
    preamble : str, optional
        Source placed after the docstring (imports, constants).

    Returns
    -------
    str
        The module source.
    """
    if unpack not in ("tuple", "index"):
        raise ValueError(f"unpack must be 'tuple' or 'index'; got {unpack!r}")
    lines = ['"""' + header + '"""', ""]
    if preamble:
        lines.extend([preamble.rstrip("\n"), ""])
    for spec in specs:
        lines.extend(_function_source(spec, decorator=decorator, unpack=unpack, out=out))
        lines.append("")
    return "\n".join(lines) + "\n"
