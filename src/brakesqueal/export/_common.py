"""Helpers shared by the code printers (formatting only)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from .model import NEWTON_MAXIT, NEWTON_RTOL, RESIDUAL_FLOOR, ExportFunction, ExportModel, temporary_name

__all__ = ["fmt_float", "comment", "used_inputs", "unused_arguments", "flat_outputs", "grouped", "function_names",
           "is_number", "with_temporaries", "RTOL", "FLOOR", "MAXIT"]

#: Newton settings as source text (identical in every language).
RTOL = repr(NEWTON_RTOL)
FLOOR = repr(RESIDUAL_FLOOR)
MAXIT = NEWTON_MAXIT


def fmt_float(v: float) -> str:
    """Round-trip decimal text of a float."""
    return repr(float(v))


def comment(lines: list[str], prefix: str) -> list[str]:
    """Prefix every line with a comment marker (no trailing blanks)."""
    return [(prefix + " " + ln).rstrip() for ln in lines]


def used_inputs(fn: ExportFunction) -> list[tuple[str, int, str]]:
    """``(argument, index, local)`` for the entries the function uses, in order."""
    used = fn.used_symbols()
    return [(arg, i, n) for arg, names in fn.inputs for i, n in enumerate(names) if n in used]


def unused_arguments(fn: ExportFunction) -> list[str]:
    """Arguments of which no entry is used (C needs ``(void)arg;`` for them)."""
    used = fn.used_symbols()
    return [arg for arg, names in fn.inputs if not any(n in used for n in names)]


def flat_outputs(fn: ExportFunction) -> list[tuple[str, int, Any]]:
    """``(output, index, expression)`` over all output groups."""
    out, k = [], 0
    for name, labels, _, _ in fn.outputs:
        for i in range(len(labels)):
            out.append((name, i, fn.exprs[k]))
            k += 1
    return out


def grouped(fn: ExportFunction) -> list[tuple[str, tuple[int, ...], list[Any]]]:
    """``(output, shape, expressions)`` per output group."""
    out, k = [], 0
    for name, labels, _, shape in fn.outputs:
        out.append((name, shape, list(fn.exprs[k : k + len(labels)])))
        k += len(labels)
    return out


def function_names(model: ExportModel) -> list[str]:
    """Names of every function of the exported file (generated ones, helpers, ``parameters``)."""
    names = [fn.name for fn in model.functions]
    if model.what == "nonlinear":
        names += ["solve_pads", "state_derivative", "rhs"]
    return [*names, "parameters"]


def is_number(e: Any) -> bool:
    """Whether a SymPy expression is a plain number (printed without a temporary)."""
    return bool(getattr(e, "is_Number", False))


def with_temporaries(output: str, exprs: list[Any], code: Callable[[Any], str],
                     assign: str) -> tuple[list[str], list[str]]:
    """One temporary per entry of an output that is not a plain number, for array literals.

    No expression then stands inside ``[...]``, where spaces may separate elements (Julia, Octave).

    Parameters
    ----------
    output : str
        Name of the output (the temporaries are named after it, :func:`~.model.temporary_name`).
    exprs : list
        Its entries (SymPy expressions).
    code : callable
        ``code(expr) -> str``, the language's printer.
    assign : str
        Format of one assignment, ``assign.format(temporary, value)``.

    Returns
    -------
    lines : list of str
        The assignments of the temporaries, in order.
    entries : list of str
        The text of each entry: the number or its temporary.
    """
    lines, entries = [], []
    for i, e in enumerate(exprs):
        if is_number(e):
            entries.append(code(e))
        else:
            t = temporary_name(output, i)
            lines.append(assign.format(t, code(e)))
            entries.append(t)
    return lines, entries
