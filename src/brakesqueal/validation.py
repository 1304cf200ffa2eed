"""Typed public functions: one decorator checks every argument against the function's type hints.

:func:`validated` evaluates a function's annotations (as :func:`typing.get_type_hints` would, in the
function's module; names imported only under ``TYPE_CHECKING`` resolved without importing anything) and
binds each call with :func:`inspect.signature`: one piece of logic for every public function, no per-function
checks.  ``Annotated[int, Range(1)]`` adds bounds (:class:`Range`).  A wrong argument is one
:class:`~brakesqueal.errors.ParameterError` line naming the function, the argument and what is allowed
(``"stability_map(): argument 'x' must be an Axis; got 'mu' (str)"``), before the function does anything.
The limits of input files and texts are in :mod:`brakesqueal.inputs`.
"""

from __future__ import annotations

import functools
import math
import os
import re
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from .inputs import MAX_TEXT_CHARS, shown
from .errors import ParameterError

__all__ = ["Range", "validated"]


@dataclass(frozen=True)
class Range:
    """A bound of a number, in an ``Annotated`` hint: ``Annotated[int, Range(1)]`` is an integer ``>= 1``.

    Parameters
    ----------
    low, high : float, optional
        The bounds (``None``: unbounded).
    open_low, open_high : bool, optional
        Exclude the bound (``Range(0, open_low=True)``: ``> 0``).
    """

    low: float | None = None
    high: float | None = None
    open_low: bool = False
    open_high: bool = False

    def holds(self, x: Any) -> bool:
        """Whether ``x`` is within the bounds."""
        if self.low is not None and (x <= self.low if self.open_low else x < self.low):
            return False
        return not (self.high is not None and (x >= self.high if self.open_high else x > self.high))

    def __str__(self) -> str:
        parts = []
        if self.low is not None:
            parts.append(f"{'>' if self.open_low else '>='} {self.low:g}")
        if self.high is not None:
            parts.append(f"{'<' if self.open_high else '<='} {self.high:g}")
        return " and ".join(parts)


class _LazyType(type):
    """A class named in a module's ``if TYPE_CHECKING:`` imports, resolved when a value is checked: no
    instance of it can exist before its module is imported, so nothing is imported for the check."""

    _module: str
    _attr: str

    def target(cls) -> Any:
        mod = sys.modules.get(cls._module)
        return None if mod is None else getattr(mod, cls._attr, None)

    def __instancecheck__(cls, obj: object) -> bool:
        target = cls.target()
        if target is None:
            return False
        if isinstance(target, type):
            return isinstance(obj, target)
        return _allows(target, obj)  # a type alias

    def __repr__(cls) -> str:
        return cls._attr


class _LazyModule:
    """A module imported under ``TYPE_CHECKING`` (``import numpy as np``): its attributes are lazy types."""

    def __init__(self, module: str) -> None:
        self._module = module

    def __getattr__(self, attr: str) -> Any:
        mod = sys.modules.get(self._module)
        if mod is not None:
            return getattr(mod, attr)
        return _LazyType(attr, (), {"_module": self._module, "_attr": attr})


@functools.lru_cache(maxsize=None)
def _type_only_imports(module: str) -> dict[str, tuple[str, str | None]]:
    """``{name: (module, attribute or None)}`` of the imports under ``if TYPE_CHECKING:`` of a module's source."""
    import ast
    import importlib.util

    mod = sys.modules.get(module)
    file = getattr(mod, "__file__", None)
    if not file or not file.endswith(".py"):
        return {}
    try:
        with open(file, encoding="utf-8") as f:
            tree = ast.parse(f.read())
    except (OSError, SyntaxError, ValueError):
        return {}
    package = getattr(mod, "__package__", None) or module.rpartition(".")[0]
    out: dict[str, tuple[str, str | None]] = {}
    for node in tree.body:
        if not (isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)):
            continue
        for stmt in ast.walk(node):
            if isinstance(stmt, ast.ImportFrom):
                try:
                    base = importlib.util.resolve_name("." * stmt.level + (stmt.module or ""), package)
                except (ImportError, ValueError):
                    continue
                for alias in stmt.names:
                    out[alias.asname or alias.name] = (base, alias.name)
            elif isinstance(stmt, ast.Import):
                for alias in stmt.names:
                    out[alias.asname or alias.name.partition(".")[0]] = (
                        alias.name if alias.asname else alias.name.partition(".")[0], None)
    return out


class _Namespace(dict):  # type: ignore[type-arg]
    """Names of type hints that the module imports only for type checkers, as lazy types."""

    def __init__(self, module: str) -> None:
        super().__init__()
        self._module = module

    def __missing__(self, name: str) -> Any:
        found = _type_only_imports(self._module).get(name)
        if found is None:
            raise KeyError(name)
        module, attr = found
        if attr is None:
            return _LazyModule(module)
        mod = sys.modules.get(module)
        if mod is not None and hasattr(mod, attr):
            return getattr(mod, attr)
        sub = sys.modules.get(f"{module}.{attr}")
        if sub is not None:
            return sub
        return _LazyType(attr, (), {"_module": module, "_attr": attr})


def _hint(func: Callable[..., Any], annotation: Any) -> Any:
    """The hint of an annotation (strings evaluated in the function's module; ``Any`` if it cannot be)."""
    if not isinstance(annotation, str):
        return annotation
    try:
        return eval(annotation, func.__globals__, _Namespace(func.__module__))  # noqa: S307 - source annotations
    except Exception:  # noqa: BLE001 - an annotation that cannot be evaluated is not checked
        return Any


def _numpy() -> Any:
    return sys.modules.get("numpy")


def _is_real(v: object) -> bool:
    if isinstance(v, bool):
        return False
    if isinstance(v, (int, float)):
        return True
    np = _numpy()
    return np is not None and isinstance(v, (np.integer, np.floating)) and not isinstance(v, np.bool_)


def _is_int(v: object) -> bool:
    if isinstance(v, bool):
        return False
    if isinstance(v, int):
        return True
    np = _numpy()
    return np is not None and isinstance(v, np.integer)


def _finite(v: Any) -> bool:
    try:
        return math.isfinite(v)
    except OverflowError:  # an int beyond the double range
        return False


def _is_array(v: object) -> bool:
    np = _numpy()
    return np is not None and isinstance(v, np.ndarray)


def _parts(hint: Any) -> tuple[Any, tuple[Any, ...]]:
    import typing

    return typing.get_origin(hint), typing.get_args(hint)


def _allows(hint: Any, v: Any) -> bool:
    """Whether ``v`` is a value of ``hint`` (numbers: finite; sequences and mappings: every item)."""
    import types
    import typing

    if hint is Any or hint is object or isinstance(hint, (TypeVar, str)):
        return True
    if hint is None or hint is type(None):
        return v is None
    origin, args = _parts(hint)
    if origin is typing.Annotated:
        return _allows(args[0], v) and all(r.holds(v) for r in args[1:] if isinstance(r, Range))
    if origin in (typing.Union, types.UnionType):
        return any(_allows(a, v) for a in args)
    if origin is typing.Literal:
        return any(type(v) is type(a) and v == a for a in args)  # the type first: an array is never a literal
    if hint is float:
        return _is_real(v) and _finite(v)
    if hint is int:
        return _is_int(v)
    if hint is bool:
        np = _numpy()
        return isinstance(v, bool) or (np is not None and isinstance(v, np.bool_))
    if hint is str:
        return isinstance(v, str)
    if hint is complex:
        return _is_real(v) or isinstance(v, complex)
    if origin is None:
        if isinstance(hint, type) and hint not in (typing.IO, typing.TextIO, typing.BinaryIO):
            return _instance(v, hint)
        return True  # a typing construct not checked here
    if origin is Callable:
        return callable(v)
    if origin in (Mapping, dict):
        if not isinstance(v, Mapping):
            return False
        kt, vt = (args + (Any, Any))[:2]
        return all(_allows(kt, k) for k in v) and (vt is Any or all(_allows(vt, x) for x in v.values()))
    if origin in (Sequence, list, tuple):
        if isinstance(v, (str, bytes)) or not (isinstance(v, (list, tuple, Sequence)) or _is_array(v)):
            return False
        if origin is list and isinstance(v, tuple):
            return False
        if origin is tuple and args and args[-1] is not Ellipsis:
            return len(v) == len(args) and all(_allows(a, x) for a, x in zip(args, v))
        item = args[0] if args else Any
        if item is Any:
            return True
        if _is_array(v) and item in (float, int):
            np = _numpy()
            kind = "iu" if item is int else "iuf"
            return v.dtype.kind in kind and bool(np.isfinite(v).all())
        return all(_allows(item, x) for x in v)
    if isinstance(origin, type):
        return _instance(v, origin)
    return True


def _instance(v: Any, cls: type) -> bool:
    """``isinstance``, true for classes that cannot be checked (protocols that are not runtime-checkable)."""
    try:
        return isinstance(v, cls)
    except TypeError:
        return True


_ARTICLE = re.compile(r"[aeiouAEIOU]")


def _a(name: str) -> str:
    return f"{'an' if _ARTICLE.match(name) else 'a'} {name}"


def _describe(hint: Any) -> str:
    """What ``hint`` allows, in words (``"a finite number"``, ``"a ParameterSpace or None"``)."""
    import types
    import typing

    if hint is None or hint is type(None):
        return "None"
    origin, args = _parts(hint)
    if origin is typing.Annotated:
        bounds = " and ".join(str(r) for r in args[1:] if isinstance(r, Range))
        return f"{_describe(args[0])} {bounds}".strip()
    if origin in (typing.Union, types.UnionType):
        named = [_describe(a) for a in args if a is not type(None)]
        return " or ".join(dict.fromkeys(named + (["None"] if type(None) in args else [])))
    if origin is typing.Literal:
        return "one of " + ", ".join(repr(a) for a in args)
    simple = {float: "a finite number", int: "an integer", bool: "True or False",
              str: "a string", complex: "a number"}
    if hint in simple:
        return simple[hint]
    if origin is Callable:
        return "a callable"
    if origin in (Mapping, dict):
        kt, vt = (args + (Any, Any))[:2]
        parts = [f"{role}: {_plural(t)}" for role, t in (("keys", kt), ("values", vt)) if t is not Any]
        return "a mapping" + (f" ({', '.join(parts)})" if parts else "")
    if origin in (Sequence, list, tuple):
        kind = {list: "a list", tuple: "a tuple"}.get(origin, "a sequence")
        if origin is tuple and args and args[-1] is not Ellipsis:
            if len(set(args)) == 1:
                return f"{'a pair' if len(args) == 2 else f'a tuple of {len(args)}'} of {_plural(args[0])}"
            return f"{kind} of {len(args)} items ({', '.join(_describe(a) for a in args)})"
        return kind if not args or args[0] is Any else f"{kind} of {_plural(args[0])}"
    if origin is os.PathLike or hint is os.PathLike:
        return "a path (os.PathLike)"
    if isinstance(hint, type):
        name = hint.__name__
        if name == "ndarray":
            return "a NumPy array"
        return f"a {name} object" if name.endswith("s") else _a(name)
    return str(hint)


def _plural(hint: Any) -> str:
    text = _describe(hint)
    for one, many in (("a finite number", "finite numbers"), ("an integer", "integers"), ("a string", "strings")):
        if text.startswith(one):
            return many + text[len(one):]
    return text


_F = TypeVar("_F", bound=Callable[..., Any])


def validated(func: _F) -> _F:
    """Check the arguments of a public function against its type hints before it runs.

    Each argument given must be a value of its parameter's hint: numbers (``float``) finite real numbers
    (``int``, ``float``, NumPy scalars; never ``bool``, NaN or infinity), integers (``int``) integers,
    strings strings of at most :data:`MAX_TEXT_CHARS` characters, classes their instances, unions any of
    their members, ``Literal`` one of its values, sequences, tuples and mappings every item (a string is not
    a sequence of numbers), callables callables, and ``Annotated[..., Range(...)]`` the bounds.  Names that
    the function's module imports only under ``TYPE_CHECKING`` are resolved without importing anything (no
    instance of a class can exist before its module is imported).  ``Any`` is not checked.

    Parameters
    ----------
    func : callable
        The function (its hints may be strings, ``from __future__ import annotations``).

    Returns
    -------
    callable
        The checking wrapper (``functools.wraps``; its ``__wrapped__`` is ``func``).

    Raises
    ------
    ParameterError
        From the wrapper: one line ``"f(): argument 'x' must be ...; got ..."`` naming the argument; also for
        arguments the signature does not have or misses.
    """
    import inspect

    plan: list[dict[str, Any]] = []

    def checks() -> dict[str, Any]:
        if not plan:
            sig = inspect.signature(func)
            hints = {name: _hint(func, p.annotation) for name, p in sig.parameters.items()
                     if p.annotation is not inspect.Parameter.empty}
            kinds = {name: p.kind for name, p in sig.parameters.items()}
            plan.append({"sig": sig, "hints": hints, "kinds": kinds})
        return plan[0]

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        c = checks()
        try:
            bound = c["sig"].bind(*args, **kwargs)
        except TypeError as exc:
            raise ParameterError(f"{func.__name__}(): {exc}") from None
        for name, value in bound.arguments.items():
            hint = c["hints"].get(name, Any)
            kind = c["kinds"][name]
            if hint is Any:
                continue
            if kind is inspect.Parameter.VAR_KEYWORD:
                items = list(value.items())
            elif kind is inspect.Parameter.VAR_POSITIONAL:
                items = [(f"{name}[{i}]", x) for i, x in enumerate(value)]
            else:
                items = [(name, value)]
            for label, x in items:
                if isinstance(x, str) and len(x) > MAX_TEXT_CHARS:
                    raise ParameterError(f"{func.__name__}(): argument '{label}' is {len(x)} characters long (at "
                                         f"most {MAX_TEXT_CHARS})", parameter=str(label))
                if not _allows(hint, x):
                    raise ParameterError(f"{func.__name__}(): argument '{label}' must be {_describe(hint)}; got "
                                         f"{shown(x)} ({type(x).__name__})", parameter=str(label))
        return func(*args, **kwargs)

    wrapper.__dict__["__validated__"] = True
    return wrapper  # type: ignore[return-value]
