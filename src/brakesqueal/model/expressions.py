"""Safe evaluation of small arithmetic expressions (never :func:`eval`).

Parameter files, presets and the command line accept values such as
``"16*pi"``, ``"inf"`` or ``"1800/mu"``.  They are parsed with
:func:`ast.parse` and evaluated by walking a whitelist of node types:

* numbers (``int`` and ``float`` literals) and names from a given mapping,
* the binary operators ``+ - * / **`` and the unary operators ``+ -``,
* calls with one positional argument to ``sqrt, sin, cos, tan, exp, log, abs``,
* the constants ``pi`` and ``inf``.

Anything else (attribute access, subscripts, lambdas, comprehensions, strings,
unknown functions or names) raises :class:`~brakesqueal.errors.ParameterError`
with a one-line message naming the expression and the offending piece, and so
does a number literal that a double cannot hold as typed (``1e400`` overflows,
``1e-400`` underflows: :func:`brakesqueal.inputs.number_problem`).
Arithmetic failures (division by zero, overflow, domain errors, a NaN result)
raise the same error, naming the values of the names the expression used.
:func:`dependency_order` sorts a set of definitions that refer to each other.
"""

from __future__ import annotations

import ast
import functools
import math
from collections.abc import Callable, Mapping
from typing import Any

from brakesqueal.inputs import DOUBLE_MAX, DOUBLE_MIN, MAX_EXPRESSION_CHARS, number_problem
from brakesqueal.errors import ParameterError

__all__ = [
    "CONSTANTS", "FUNCTIONS", "RESERVED_NAMES", "dependency_order", "evaluate", "evaluate_array", "names_in",
    "to_sympy",
]

#: Functions an expression may call, each with exactly one argument.
FUNCTIONS: Mapping[str, Callable[[float], float]] = {
    "sqrt": math.sqrt,
    "sin": math.sin,
    "cos": math.cos,
    "tan": math.tan,
    "exp": math.exp,
    "log": math.log,
    "abs": abs,
}

#: Named constants; they cannot be redefined by the names mapping.
CONSTANTS: Mapping[str, float] = {"pi": math.pi, "inf": math.inf}

#: Names that parameters and auxiliary quantities must not use.
RESERVED_NAMES: frozenset[str] = frozenset(FUNCTIONS) | frozenset(CONSTANTS)

_MAX_LENGTH = MAX_EXPRESSION_CHARS

_BINARY_SYMBOLS: Mapping[type[ast.operator], str] = {
    ast.Add: "+",
    ast.Sub: "-",
    ast.Mult: "*",
    ast.Div: "/",
    ast.Pow: "**",
}

_FORBIDDEN_KINDS: Mapping[type[ast.AST], str] = {
    ast.Attribute: "attribute access",
    ast.Subscript: "subscript",
    ast.Lambda: "lambda",
    ast.ListComp: "comprehension",
    ast.SetComp: "comprehension",
    ast.DictComp: "comprehension",
    ast.GeneratorExp: "comprehension",
    ast.Compare: "comparison",
    ast.BoolOp: "boolean operator",
    ast.IfExp: "conditional expression",
    ast.NamedExpr: "assignment expression",
    ast.Starred: "starred expression",
    ast.JoinedStr: "f-string",
}


class _ArithmeticFailure(Exception):
    """Internal: an operation failed; the argument is the human-readable reason."""


def _one_line(expr: str, limit: int = 120) -> str:
    """Collapse whitespace and shorten ``expr`` to fit a one-line message."""
    text = " ".join(str(expr).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _format_value(value: float) -> str:
    """Format a number compactly (``0`` rather than ``0.0``; ``inf`` as is)."""
    if math.isfinite(value) and value.is_integer() and abs(value) < 1e16:
        return str(int(value))
    return repr(value)


def _kind(node: ast.AST) -> str:
    """Describe a forbidden node, e.g. ``"attribute access 'os.path'"``."""
    if isinstance(node, ast.Constant):
        return f"literal {node.value!r} ({type(node.value).__name__})"
    kind = _FORBIDDEN_KINDS.get(type(node), f"{type(node).__name__} node")
    return f"{kind} '{_one_line(ast.unparse(node))}'"


def _reject(what: str, expr: str, piece: str, hint: str = "") -> ParameterError:
    """Build the error for a construct outside the whitelist."""
    extra = f" ({hint})" if hint else ""
    return ParameterError(f"{what} = {_one_line(expr)}: {piece} is not allowed{extra}")


def _parse(expr: object, what: str) -> ast.expr:
    """Parse ``expr`` in ``eval`` mode, turning every failure into ParameterError."""
    if not isinstance(expr, str):
        raise ParameterError(
            f"{what} must be an expression string; got {expr!r} ({type(expr).__name__})"
        )
    if not expr.strip():
        raise ParameterError(f"{what} is an empty expression")
    if len(expr) > _MAX_LENGTH:
        raise ParameterError(f"{what} is longer than {_MAX_LENGTH} characters")
    try:
        return ast.parse(expr.strip(), mode="eval").body
    except (SyntaxError, ValueError, RecursionError, MemoryError) as exc:
        reason = getattr(exc, "msg", None) or type(exc).__name__
        raise ParameterError(
            f"{what} = {_one_line(expr)} is not a valid expression ({reason})"
        ) from None


def _check_call(node: ast.Call, what: str, expr: str) -> None:
    """Accept only ``f(x)`` with ``f`` a whitelisted function."""
    allowed = ", ".join(sorted(FUNCTIONS))
    if not isinstance(node.func, ast.Name) or node.func.id not in FUNCTIONS:
        callee = _one_line(ast.unparse(node.func))
        raise _reject(what, expr, f"call of '{callee}'", f"allowed functions: {allowed}")
    if len(node.args) != 1 or node.keywords:
        call = _one_line(ast.unparse(node))
        raise _reject(what, expr, f"call '{call}'", "functions take one argument")


def _check(node: ast.AST, what: str, expr: str, found: set[str]) -> None:
    """Walk the tree, reject non-whitelisted nodes and collect free names."""
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise _reject(what, expr, _kind(node))
        if abs(node.value) > DOUBLE_MAX or 0 < abs(node.value) < DOUBLE_MIN or node.value == 0:
            typed = ast.get_source_segment(expr.strip(), node) or repr(node.value)
            problem = number_problem(typed)
            if problem:  # a literal a double cannot hold as typed (1e400, 1e-400)
                raise ParameterError(f"{what} = {_one_line(expr)}: the number {_one_line(typed, 40)} {problem}")
    elif isinstance(node, ast.Name):
        if node.id in FUNCTIONS:
            raise _reject(what, expr, f"bare function name '{node.id}'", "call it")
        if node.id not in CONSTANTS:
            found.add(node.id)
    elif isinstance(node, ast.BinOp):
        if type(node.op) not in _BINARY_SYMBOLS:
            raise _reject(what, expr, f"operator in '{_one_line(ast.unparse(node))}'")
        _check(node.left, what, expr, found)
        _check(node.right, what, expr, found)
    elif isinstance(node, ast.UnaryOp):
        if not isinstance(node.op, (ast.UAdd, ast.USub)):
            raise _reject(what, expr, f"operator in '{_one_line(ast.unparse(node))}'")
        _check(node.operand, what, expr, found)
    elif isinstance(node, ast.Call):
        _check_call(node, what, expr)
        _check(node.args[0], what, expr, found)
    else:
        raise _reject(what, expr, _kind(node))


def _parse_and_check(expr: object, what: str) -> tuple[ast.expr, frozenset[str]]:
    """Parse and whitelist-check ``expr``; return the tree and its free names."""
    tree = _parse(expr, what)
    found: set[str] = set()
    assert isinstance(expr, str)  # _parse rejects anything else
    try:
        _check(tree, what, expr, found)
    except RecursionError:
        raise ParameterError(f"{what} = {_one_line(expr)} is nested too deeply") from None
    return tree, frozenset(found)


# Parsed and checked trees by (expression, label): ``Preset.resolve`` evaluates the same ties at every
# point of a path. Only successes are cached (an exception is never stored by ``lru_cache``), so
# every error is built afresh with the same message; the trees are never mutated by the evaluators.
_cached_tree = functools.lru_cache(maxsize=4096)(_parse_and_check)


def _checked_tree(expr: str, what: str) -> tuple[ast.expr, frozenset[str]]:
    """Parse and whitelist-check ``expr`` (cached); return the tree and its free names."""
    if isinstance(expr, str) and isinstance(what, str):
        return _cached_tree(expr, what)
    return _parse_and_check(expr, what)


def names_in(expr: str, *, what: str = "expression") -> set[str]:
    """Return the free names an expression refers to.

    Parameters
    ----------
    expr : str
        Expression such as ``"h*mu2/(mu1+mu2)"``.
    what : str, optional
        Label used in error messages, e.g. ``"tied parameter 'h10'"``.

    Returns
    -------
    set of str
        Names other than the constants ``pi`` and ``inf`` and the functions.

    Raises
    ------
    ParameterError
        If ``expr`` cannot be parsed or uses a construct outside the whitelist.
    """
    return set(_checked_tree(expr, what)[1])


def _binary(op: ast.operator, left: float, right: float) -> float:
    """Apply a whitelisted binary operator, detecting division by zero and overflow."""
    try:
        if isinstance(op, ast.Add):
            result = left + right
        elif isinstance(op, ast.Sub):
            result = left - right
        elif isinstance(op, ast.Mult):
            result = left * right
        elif isinstance(op, ast.Div):
            result = left / right
        else:
            result = math.pow(left, right)
    except ZeroDivisionError:
        raise _ArithmeticFailure("division by zero") from None
    except OverflowError:
        raise _ArithmeticFailure("numerical overflow") from None
    except ValueError:
        if left == 0.0 and right < 0.0:
            raise _ArithmeticFailure("division by zero") from None
        symbol = _BINARY_SYMBOLS[type(op)]
        base = _format_value(left) if left >= 0 else f"({_format_value(left)})"
        reason = f"{base} {symbol} {_format_value(right)} is undefined"
        raise _ArithmeticFailure(reason) from None
    if math.isinf(result) and math.isfinite(left) and math.isfinite(right):
        raise _ArithmeticFailure("numerical overflow")
    return result


def _call(name: str, argument: float) -> float:
    """Apply a whitelisted function, turning math errors into failures."""
    try:
        result = float(FUNCTIONS[name](argument))
    except OverflowError:
        raise _ArithmeticFailure("numerical overflow") from None
    except ValueError:
        raise _ArithmeticFailure(
            f"{name}({_format_value(argument)}) is undefined"
        ) from None
    if math.isinf(result) and math.isfinite(argument):
        raise _ArithmeticFailure("numerical overflow")
    return result


def _compute(node: ast.AST, names: Mapping[str, float]) -> float:
    """Evaluate a tree that has already passed :func:`_check`."""
    if isinstance(node, ast.Constant):
        try:
            value = float(node.value)  # type: ignore[arg-type]  # checked: int or float
        except OverflowError:
            value = math.inf
        if math.isinf(value):
            raise _ArithmeticFailure("a number literal overflows (write inf for an infinite value)")
        return value
    if isinstance(node, ast.Name):
        if node.id in CONSTANTS:
            return CONSTANTS[node.id]
        return float(names[node.id])
    if isinstance(node, ast.BinOp):
        return _binary(node.op, _compute(node.left, names), _compute(node.right, names))
    if isinstance(node, ast.UnaryOp):
        value = _compute(node.operand, names)
        return -value if isinstance(node.op, ast.USub) else value
    assert isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
    return _call(node.func.id, _compute(node.args[0], names))



def _tree_over(expr: str, names: Mapping[str, Any], what: str) -> tuple[ast.expr, frozenset[str]]:
    """The checked tree of ``expr`` and the names it uses, which must all be keys of ``names``."""
    tree, used = _checked_tree(expr, what)
    unknown = sorted(used - set(names))
    if unknown:
        known = ", ".join([*sorted(names), *CONSTANTS]) or "none"
        raise _reject(what, expr, f"unknown name '{unknown[0]}'", f"known names: {known}")
    return tree, used

def evaluate(expr: str, names: Mapping[str, float], *, what: str) -> float:
    """Evaluate an arithmetic expression safely.

    Parameters
    ----------
    expr : str
        Expression such as ``"1800/mu"``, ``"16*pi"`` or ``"inf"``.
    names : Mapping[str, float]
        Values of the names the expression may use.
    what : str
        Label for error messages, e.g. ``"tied parameter 'N0'"``.

    Returns
    -------
    float
        The value; ``inf`` is possible when an input or constant is infinite,
        never through overflow.

    Raises
    ------
    ParameterError
        One-line message naming ``what`` and the offending piece if the
        expression is malformed, uses a construct outside the whitelist or an
        unknown name; naming the expression and the values of its names if
        the arithmetic fails or gives NaN, e.g. ``"tied parameter 'N0' =
        1800/mu cannot be evaluated at mu=0: division by zero"``.
    """
    tree, used = _tree_over(expr, names, what)
    at = ", ".join(f"{name}={_format_value(float(names[name]))}" for name in sorted(used))
    where = f" at {at}" if at else ""
    try:
        result = _compute(tree, names)
    except _ArithmeticFailure as failure:
        reason = str(failure)
    except RecursionError:
        reason = "expression nested too deeply"
    else:
        if not math.isnan(result):
            return result
        reason = "the result is not a number (nan)"
    raise ParameterError(
        f"{what} = {_one_line(expr)} cannot be evaluated{where}: {reason}"
    )


def dependency_order(exprs: Mapping[str, str], *, what: str = "expressions") -> list[str]:
    """Order names defined by expressions so that each follows the names it uses.

    Parameters
    ----------
    exprs : Mapping[str, str]
        Name -> expression; names not in ``exprs`` are treated as inputs.
    what : str, optional
        Label for the error message, e.g. ``"preset 'paper-fig3'"``.

    Returns
    -------
    list of str
        The keys of ``exprs`` in an order in which they can be evaluated;
        ties keep the order of ``exprs``.

    Raises
    ------
    ParameterError
        If the definitions form a cycle (the message shows it, e.g.
        ``a -> b -> a``) or an expression is malformed.
    """
    uses: dict[str, set[str]] = {}
    for name, expr in exprs.items():
        try:
            uses[name] = names_in(expr, what=f"{what}: '{name}'")
        except ParameterError as exc:
            raise exc.about(name) from None
    order: list[str] = []
    path: list[str] = []

    def visit(name: str) -> None:
        if name in order:
            return
        if name in path:
            cycle = " -> ".join([*path[path.index(name):], name])
            raise ParameterError(f"{what}: the definitions form a cycle: {cycle}", parameter=name,
                                 names=tuple(path[path.index(name):]))
        path.append(name)
        for ref in sorted(uses[name] & set(exprs)):
            visit(ref)
        path.pop()
        order.append(name)

    for name in exprs:
        visit(name)
    return order


_NUMPY_FUNCTIONS = {"sqrt": "sqrt", "sin": "sin", "cos": "cos", "tan": "tan", "exp": "exp", "log": "log",
                    "abs": "abs"}


def _compute_array(node: ast.AST, names: Mapping[str, Any]) -> Any:
    """Vectorized evaluation of a checked tree with NumPy (no error checks; see :func:`evaluate_array`)."""
    import numpy as np

    if isinstance(node, ast.Constant):
        return float(node.value)  # type: ignore[arg-type]  # checked: int or float
    if isinstance(node, ast.Name):
        return CONSTANTS[node.id] if node.id in CONSTANTS else names[node.id]
    if isinstance(node, ast.BinOp):
        a, b = _compute_array(node.left, names), _compute_array(node.right, names)
        if isinstance(node.op, ast.Add):
            return np.add(a, b)
        if isinstance(node.op, ast.Sub):
            return np.subtract(a, b)
        if isinstance(node.op, ast.Mult):
            return np.multiply(a, b)
        if isinstance(node.op, ast.Div):
            return np.divide(a, b)
        return np.power(a, b)
    if isinstance(node, ast.UnaryOp):
        value = _compute_array(node.operand, names)
        return np.negative(value) if isinstance(node.op, ast.USub) else value
    assert isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
    return getattr(np, _NUMPY_FUNCTIONS[node.func.id])(_compute_array(node.args[0], names))


def evaluate_array(expr: str, names: Mapping[str, Any], *, what: str) -> Any:
    """Evaluate an expression element-wise on NumPy arrays (same grammar as :func:`evaluate`).

    Parameters
    ----------
    expr : str
        Expression such as ``"1800/mu"``.
    names : Mapping[str, array_like]
        Values of the names the expression may use (broadcastable arrays or floats).
    what : str
        Label for error messages.

    Returns
    -------
    ndarray or float
        The values; points where the arithmetic fails (division by zero,
        overflow, a domain error) are ``nan`` (callers mark them invalid), never
        a warning.

    Raises
    ------
    ParameterError
        If the expression is malformed or uses an unknown name.
    """
    import numpy as np

    tree, used = _tree_over(expr, names, what)
    with np.errstate(all="ignore"):
        out = _compute_array(tree, names)
        finite_in = np.ones(np.shape(out), dtype=bool)
        for name in used:
            finite_in = finite_in & np.isfinite(np.asarray(names[name], dtype=float))
        # overflow of finite inputs is an error, as in evaluate(): report it as nan
        out = np.where(np.isinf(out) & finite_in, np.nan, out)
    return out[()] if isinstance(out, np.ndarray) and out.ndim == 0 else out


def to_sympy(expr: str, symbols: Mapping[str, Any], *, what: str = "expression") -> Any:
    """Convert an expression to SymPy with the same grammar (numbers become exact rationals).

    Parameters
    ----------
    expr : str
        Expression such as ``"h*mu2/(mu1+mu2)"``.
    symbols : Mapping[str, sympy.Expr]
        SymPy expression (or symbol) for every name the expression uses.
    what : str, optional
        Label for error messages.

    Returns
    -------
    sympy.Expr
        The expression; ``pi`` is ``sympy.pi`` and ``inf`` is ``sympy.oo``.

    Raises
    ------
    ParameterError
        If the expression is malformed or uses an unknown name.
    """
    import sympy as sp

    tree, _ = _tree_over(expr, symbols, what)
    funcs = {"sqrt": sp.sqrt, "sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "exp": sp.exp, "log": sp.log,
             "abs": sp.Abs}

    def conv(node: ast.AST) -> Any:
        if isinstance(node, ast.Constant):
            v = node.value
            return sp.Integer(v) if isinstance(v, int) else sp.Rational(v)
        if isinstance(node, ast.Name):
            if node.id == "pi":
                return sp.pi
            if node.id == "inf":
                return sp.oo
            return symbols[node.id]
        if isinstance(node, ast.BinOp):
            a, b = conv(node.left), conv(node.right)
            op = type(node.op)
            return {ast.Add: lambda: a + b, ast.Sub: lambda: a - b, ast.Mult: lambda: a * b,
                    ast.Div: lambda: a / b, ast.Pow: lambda: a ** b}[op]()
        if isinstance(node, ast.UnaryOp):
            v = conv(node.operand)
            return -v if isinstance(node.op, ast.USub) else v
        assert isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
        return funcs[node.func.id](conv(node.args[0]))

    return conv(tree)
