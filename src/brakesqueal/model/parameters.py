"""Parameter sets, presets and parameter spaces of any model.

* :class:`Parameters` — a complete, validated set of values of one model's
  named parameters (the one parameter-set type of the package), in the
  model's canonical order, which is also the packing order of every numeric
  function (:meth:`Parameters.vector`).
* :class:`Preset` — a named template of a model: *free* names (the intended
  knobs), *fixed* names and *tied* names (safe expressions of the others, e.g.
  Fig. 2's ``N0 = 1800/mu``).  Free and fixed names may be auxiliary
  quantities (``mu``, ``k_ip``, ``h``) that are not model parameters.
* :class:`ParameterSpace` — a preset with overrides, seen as a function of its
  settable names; it resolves scalar points (:meth:`ParameterSpace.resolve`),
  arrays for maps and sweeps (:meth:`ParameterSpace.arrays`) and SymPy
  expressions for generated kernels (:meth:`ParameterSpace.symbolic`), all
  from the one expression grammar of :mod:`.expressions`.

There are no silent defaults: values come from a preset (every model has an
implicit preset named after it, with its default values free) or a complete
parameter set.  Validation goes through :mod:`.roles` for every channel.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Union, cast, overload

import numpy as np

from ..inputs import MAX_EXPRESSION_CHARS, MAX_NAME_CHARS, number_problem, shown
from ..errors import ParameterError
from .expressions import RESERVED_NAMES, dependency_order, evaluate, evaluate_array, names_in, to_sympy
from .units import check_quantity, parse_quantity

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from .components import ModelSpec

__all__ = ["Value", "Parameters", "Preset", "ParameterSpace", "as_model_spec", "compliance"]

Value = Union[float, str]  # a number or an expression string such as "16*pi"


def _fmt(value: float) -> str:
    value = float(value)
    if math.isfinite(value) and value.is_integer() and abs(value) < 1e16:
        return str(int(value))
    return repr(value)


def _number(value: object, what: str, name: str | None = None) -> float:
    """A float from a number or a constant expression (``"16*pi"``, ``"inf"``); errors name ``name``."""
    if isinstance(value, str):
        try:
            return evaluate(value, {}, what=what)
        except ParameterError as exc:
            raise (exc.about(name) if name else exc) from None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ParameterError(f"{what} must be a number or an expression string; got {value!r} "
                             f"({type(value).__name__})", parameter=name)
    v = float(value)
    if math.isnan(v):
        raise ParameterError(f"{what} must be a number; got nan", parameter=name)
    return v


@overload
def compliance(value: float) -> float: ...
@overload
def compliance(value: np.ndarray) -> np.ndarray: ...  # (a 0-d array gives a float)


def compliance(value: ArrayLike) -> float | np.ndarray:
    """``1/k`` for a stiffness, ``0`` for a rigid support (``k = inf``); works on arrays."""
    with np.errstate(divide="ignore"):
        out = np.where(np.isinf(value), 0.0, 1.0 / np.asarray(value, dtype=float))
    return float(out) if np.ndim(out) == 0 else out


def as_model_spec(model: ModelSpec | str | os.PathLike[str]) -> ModelSpec:
    """The :class:`~brakesqueal.model.components.ModelSpec` named by ``model``.

    Parameters
    ----------
    model : ModelSpec, MatrixSpec, str or os.PathLike
        A model, a built-in model name or the path of a model TOML file.

    Returns
    -------
    ModelSpec
        ``model`` itself, or :func:`~brakesqueal.model.library.resolve_model` of the name.

    Raises
    ------
    ParameterError
        For anything else, or a name that is neither a built-in model nor a model file.
    """
    from .components import ModelSpec
    from .library import resolve_model
    from .matrices import MatrixSpec

    if isinstance(model, ModelSpec):
        return model
    if isinstance(model, MatrixSpec):  # the same parameter interface (name, parameters, presets, roles, unit)
        return cast("ModelSpec", model)
    if isinstance(model, os.PathLike):
        model = os.fspath(model)
    if isinstance(model, str):
        return resolve_model(model)
    raise ParameterError(f"model must be a ModelSpec, a MatrixSpec, a built-in model's name or a model file; got "
                         f"{shown(model)} ({type(model).__name__})", parameter="model")


class Parameters(Mapping[str, float]):
    """A complete, validated set of parameter values of one model (SI units).

    It is a read-only mapping from parameter name to float, in the model's
    canonical order; values are also attributes (``p.mu1``).

    Parameters
    ----------
    model : ModelSpec or str
        The model (or a built-in model's name / a model file path).
    values : Mapping[str, float or str]
        A value for every parameter of the model: numbers or constant
        expressions such as ``"16*pi"`` or ``"inf"`` (a rigid tangential support).
    source : str, optional
        Label for error messages (e.g. a file name).

    Raises
    ------
    ParameterError
        Unknown or missing names, or values outside the ranges of their roles
        (:mod:`brakesqueal.model.roles`); all problems in one line.
    """

    __slots__ = ("_model", "_values")
    _model: ModelSpec
    _values: Mapping[str, float]

    def __init__(self, model: ModelSpec | str, values: Mapping[str, Value], *, source: str | None = None) -> None:
        from .roles import problems

        spec = as_model_spec(model)
        where = f"{source}: " if source else ""
        names = list(spec.parameters)
        unknown = [n for n in values if n not in spec.parameters]
        if unknown:
            from ..suggest import did_you_mean

            raise ParameterError(f"{where}unknown parameter '{unknown[0]}' of model '{spec.name}'"
                                 f"{did_you_mean(unknown[0], names)}; valid names: {', '.join(names)}",
                                 parameter=unknown[0], names=tuple(unknown))
        missing = [n for n in names if n not in values]
        if missing:
            raise ParameterError(f"{where}missing parameter(s) {', '.join(missing)} of model '{spec.name}' "
                                 "(give all of them or start from a preset)", parameter=missing[0],
                                 names=tuple(missing))
        for n in names:
            check_quantity(n, values[n], spec.unit(n))
        vals = {n: _number(values[n], f"{where}value of '{n}'", n) for n in names}
        probs = problems(spec.roles(), vals)
        if probs:
            raise ParameterError(where + "; ".join(m for _, m in probs), parameter=probs[0][0],
                                 names=tuple(n for n, _ in probs))
        object.__setattr__(self, "_model", spec)
        object.__setattr__(self, "_values", MappingProxyType(vals))

    # ---------------------------------------------------------------- mapping protocol
    def __getitem__(self, name: str) -> float:
        return self._values[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def __getattr__(self, name: str) -> float:
        if name.startswith("_"):
            raise AttributeError(name)
        try:
            return self._values[name]
        except KeyError:
            raise AttributeError(f"model '{self._model.name}' has no parameter '{name}'") from None

    def __setattr__(self, name: str, value: object) -> None:
        raise AttributeError("Parameters are immutable; use replace()")

    def __repr__(self) -> str:
        inner = ", ".join(f"{k}={_fmt(v)}" for k, v in self._values.items())
        return f"Parameters(model={self._model.name!r}, {inner})"

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Parameters) and other._model.name == self._model.name
                and dict(other._values) == dict(self._values))

    def __hash__(self) -> int:
        return hash((self._model.name, tuple(self._values.items())))

    def __reduce__(self) -> tuple[Any, ...]:
        return (Parameters, (self._model, dict(self._values)))

    # ---------------------------------------------------------------- queries
    @property
    def model(self) -> ModelSpec:
        """The :class:`~brakesqueal.model.components.ModelSpec`."""
        return self._model

    @property
    def names(self) -> tuple[str, ...]:
        """Parameter names in the model's canonical (packing) order."""
        return tuple(self._values)

    def as_dict(self) -> dict[str, float]:
        """Plain dict of the values, in canonical order."""
        return dict(self._values)

    def to_json_dict(self) -> dict[str, float | str]:
        """JSON-compatible dict; ``inf`` becomes the string ``"inf"``."""
        return {k: "inf" if math.isinf(v) else v for k, v in self._values.items()}

    def replace(self, **changes: Value) -> Parameters:
        """A validated copy with some values changed (unknown names are refused)."""
        return Parameters(self._model, {**self._values, **changes})

    def vector(self) -> np.ndarray:
        """Values in packing order, tangential stiffnesses ``k_ip`` replaced by compliances ``1/k_ip``.

        This is the ``p`` argument of every generated numeric function of the
        model (rigid supports, ``k_ip = inf``, become the regular value 0).
        """
        kip = self._model.stiffness_names()
        return np.array([compliance(v) if n in kip else v for n, v in self._values.items()], dtype=float)


@dataclass(frozen=True)
class Preset:
    """A named parameter template of a model with free, fixed and tied names.

    Attributes
    ----------
    name, description : str
        Identifier (``"paper-fig2"``) and one-line summary.
    reference : str
        Where the values come from (paper section, equations, figure).
    fixed : Mapping[str, float or str]
        Numbers or constant expressions that rarely change (settable); may
        include auxiliary names such as ``h``.
    free : Mapping[str, float or str]
        The intended knobs with their defaults (settable): model parameters or
        auxiliary names such as ``mu`` or ``k_ip``.
    tied : Mapping[str, str]
        Expressions of free, fixed and other tied names, evaluated in
        dependency order.  Setting a tied name replaces its tie.
    auxiliary : Mapping[str, str]
        Descriptions (with units) of auxiliary names.
    model : ModelSpec or None
        The model the preset belongs to (set by :meth:`bind`).
    """

    name: str
    description: str
    reference: str
    fixed: Mapping[str, Value]
    free: Mapping[str, Value]
    tied: Mapping[str, str]
    auxiliary: Mapping[str, str] = field(default_factory=dict)
    model: ModelSpec | None = field(default=None, repr=False, compare=False)

    __hash__ = None  # type: ignore[assignment]  # unhashable (it holds mappings): the data-model idiom

    def __post_init__(self) -> None:
        for attribute in ("fixed", "free", "tied", "auxiliary"):
            object.__setattr__(self, attribute, MappingProxyType(dict(getattr(self, attribute))))

    # ---------------------------------------------------------------- definition
    def check(self, spec: ModelSpec) -> None:
        """Check the definition against a model; raise ParameterError naming the preset."""
        where = f"preset '{self.name}'"
        every = [*self.fixed, *self.free, *self.tied]
        duplicates = sorted({n for n in every if every.count(n) > 1})
        if duplicates:
            raise ParameterError(f"{where}: names in more than one of fixed/free/tied: {', '.join(duplicates)}",
                                 parameter=duplicates[0], names=tuple(duplicates))
        bad = [n for n in every if not n.isidentifier() or n in RESERVED_NAMES]
        if bad:
            raise ParameterError(f"{where}: invalid or reserved name '{bad[0]}'", parameter=bad[0])
        missing = [n for n in spec.parameters if n not in every]
        if missing:
            raise ParameterError(f"{where}: parameter(s) of model '{spec.name}' not defined: {', '.join(missing)}",
                                 parameter=missing[0], names=tuple(missing))
        for name, value in {**self.fixed, **self.free}.items():
            _number(value, f"{where}: value of '{name}'", name)
        used: set[str] = set()
        for name, expr in self.tied.items():
            try:
                refs = names_in(expr, what=f"{where}: tied parameter '{name}'")
            except ParameterError as exc:
                raise exc.about(name) from None
            unknown = sorted(refs - set(every))
            if unknown:
                raise ParameterError(f"{where}: tied parameter '{name}' = {expr} uses unknown name '{unknown[0]}'",
                                     parameter=name, names=(unknown[0],))
            used |= refs
        unused = [n for n in every if n not in spec.parameters and n not in used]
        if unused:
            raise ParameterError(f"{where}: auxiliary name '{unused[0]}' is not used", parameter=unused[0])
        dependency_order(self.tied, what=where)

    def bind(self, spec: ModelSpec) -> Preset:
        """This preset attached to ``spec`` (checked)."""
        self.check(spec)
        return replace(self, model=spec)

    def _spec(self) -> ModelSpec:
        if self.model is None:
            raise ParameterError(f"preset '{self.name}' is not attached to a model (use ModelSpec.get_preset)")
        return self.model

    @property
    def bound_model(self) -> ModelSpec:
        """The model of a bound preset (:meth:`bind`, :meth:`ModelSpec.get_preset
        <brakesqueal.model.components.ModelSpec.get_preset>`); ParameterError for an unbound one."""
        return self._spec()

    # ---------------------------------------------------------------- use
    def settable_names(self) -> tuple[str, ...]:
        """Names :meth:`resolve` accepts without replacing a tie: free names first, then fixed."""
        return (*self.free, *self.fixed)

    def all_names(self) -> tuple[str, ...]:
        """Free, fixed and tied names."""
        return (*self.free, *self.fixed, *self.tied)

    def unit(self, name: str) -> str:
        """SI unit of a model or auxiliary name (auxiliary units come from the ``[unit]`` prefix)."""
        spec = self._spec()
        if name in spec.parameters:
            return spec.unit(name)
        text = self.auxiliary.get(name, "")
        return text[1:text.index("]")] if text.startswith("[") and "]" in text else ""

    def describe_name(self, name: str) -> str:
        """Description of a model or auxiliary name."""
        spec = self._spec()
        if name in spec.parameters:
            return spec.describe_parameter(name)
        text = self.auxiliary.get(name, "auxiliary quantity")
        return text[text.index("]") + 1:].strip() if text.startswith("[") and "]" in text else text

    def resolve(self, overrides: Mapping[str, Value] | None = None) -> Parameters:
        """A validated parameter set, optionally overriding names.

        Parameters
        ----------
        overrides : Mapping[str, float or str], optional
            New values: numbers or constant expressions such as ``"inf"``.
            Overriding a tied name replaces its tie by the given value.

        Raises
        ------
        ParameterError
            An unknown name (with a suggestion), an expression that cannot be
            evaluated, or a result outside the allowed ranges (the message
            says where a tied value came from).
        """
        spec = self._spec()
        overrides = dict(overrides or {})
        for name in overrides:
            self.check_name(name)
            check_quantity(name, overrides[name], self.unit(name))
        defs = {**self.fixed, **self.free}
        tied = {k: v for k, v in self.tied.items() if k not in overrides}
        values = {n: _number(overrides.get(n, d), f"value of '{n}'", n) for n, d in defs.items()}
        for n in overrides:
            if n not in defs:
                values[n] = _number(overrides[n], f"value of '{n}'", n)
        for name in dependency_order(tied, what=f"preset '{self.name}'"):
            try:
                values[name] = evaluate(tied[name], values, what=f"tied parameter '{name}'")
            except ParameterError as exc:
                raise exc.about(name, tuple(sorted(names_in(tied[name])))) from None
        model_values = {n: values[n] for n in spec.parameters}
        from .roles import problems

        probs = problems(spec.roles(), model_values)
        if probs:
            inputs = tuple(sorted({r for n, _ in probs if n in tied for r in names_in(tied[n])}))
            raise ParameterError("; ".join(self._explain(n, m, values, tied) for n, m in probs),
                                 parameter=probs[0][0], names=(*(n for n, _ in probs), *inputs))
        return Parameters(spec, model_values)

    def check_name(self, name: str) -> None:
        """Raise a helpful error unless ``name`` is a free, fixed or tied name of this preset."""
        if name in self.free or name in self.fixed or name in self.tied:
            return
        from ..suggest import did_you_mean

        spec = self._spec()
        elsewhere = [f"'{p.name}'" for p in spec.presets if name in p.free] if spec is not None else []
        hint = f"; it is a free parameter of preset {', '.join(elsewhere)}" if elsewhere else ""
        raise ParameterError(f"The parameter '{name}' is not defined in preset '{self.name}'"
                             f"{did_you_mean(name, self.all_names())}{hint}; settable names: "
                             + ", ".join(self.settable_names()), parameter=name)

    def _explain(self, name: str, message: str, values: Mapping[str, float], tied: Mapping[str, str]) -> str:
        if name not in tied:
            return message
        at = ", ".join(f"{n}={_fmt(values[n])}" for n in sorted(names_in(tied[name])))
        return f"{message} (tied in preset '{self.name}': {name} = {tied[name]}" + (f" at {at})" if at else ")")

    def describe(self) -> str:
        """Multi-line human-readable description: free, fixed and tied names with units."""
        spec = self._spec()
        lines = [f"{self.name} (model '{spec.name}'): {self.description}"]
        if self.reference:
            lines.append(f"  reference: {self.reference}")
        for title, entries in (("free", self.free), ("fixed", self.fixed), ("tied", self.tied)):
            if not entries:
                continue
            lines.append(f"  {title}:")
            for n, v in entries.items():
                unit = self.unit(n)
                shown = v if isinstance(v, str) else _fmt(float(v))
                lines.append(f"    {n:<8} = {shown:<28} {('[' + unit + '] ') if unit else ''}{self.describe_name(n)}")
        return "\n".join(lines)


@dataclass(frozen=True, eq=False)
class ParameterSpace:
    """A preset with overrides, seen as a function of its settable names.

    Attributes
    ----------
    preset : Preset
        The (bound) preset.
    values : Mapping[str, float or str]
        Overrides of free, fixed or tied names (an overridden tied name becomes fixed).
    """

    preset: Preset
    values: Mapping[str, Value] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "values", MappingProxyType(dict(self.values)))
        for n, v in self.values.items():
            self.preset.check_name(n)
            check_quantity(n, v, self.preset.unit(n))

    # ---------------------------------------------------------------- construction
    @classmethod
    def from_preset(cls, name: str = "paper-fig2", overrides: Mapping[str, Value] | None = None,
                    *, model: ModelSpec | str | None = None) -> ParameterSpace:
        """A preset (of ``model``, or any built-in preset) with validated overrides."""
        from .library import get_preset

        pr = as_model_spec(model).get_preset(name) if model is not None else get_preset(name)
        space = cls(pr, dict(overrides or {}))
        space.resolve({})
        return space

    @classmethod
    def from_parameters(cls, params: Parameters) -> ParameterSpace:
        """Every model parameter fixed at ``params`` (any of them may be an axis)."""
        spec = params.model
        pr = Preset(name="parameters", description="a complete parameter set", reference="",
                    fixed={}, free=params.as_dict(), tied={}).bind(spec)
        return cls(pr, {})

    # ---------------------------------------------------------------- queries
    @property
    def model(self) -> ModelSpec:
        """The model."""
        # a space's preset is bound (ModelSpec.get_preset / Preset.bind): its model is set
        return cast("ModelSpec", self.preset.model)

    @property
    def label(self) -> str:
        """The preset's name."""
        return self.preset.name

    @property
    def tied(self) -> Mapping[str, str]:
        """Tie expressions in force (ties of overridden names are dropped)."""
        return {k: v for k, v in self.preset.tied.items() if k not in self.values}

    @property
    def untied(self) -> tuple[str, ...]:
        """Tied names of the preset that the overrides replaced by values."""
        return tuple(n for n in self.values if n in self.preset.tied)

    def settable(self) -> tuple[str, ...]:
        """Names an axis may vary: free, then fixed names, then replaced ties."""
        return (*self.preset.free, *self.preset.fixed, *self.untied)

    def definitions(self) -> dict[str, Value]:
        """Values of every settable name (preset defaults with the overrides applied)."""
        return {**self.preset.fixed, **self.preset.free, **self.values}

    def value(self, name: str) -> float:
        """Current value of a settable name."""
        self.check_axis(name)
        return _number(self.definitions()[name], f"value of '{name}'", name)

    def check_axis(self, name: str) -> None:
        """Raise ParameterError (one line) unless ``name`` can be varied in this space."""
        if name in self.tied:
            raise ParameterError(
                f"cannot vary '{name}': it is tied in preset '{self.label}' ({name} = {self.tied[name]}); "
                f"vary one of {', '.join(self.settable())}, or give '{name}' a value to replace its tie",
                parameter=name)
        if name not in self.settable():
            from ..suggest import did_you_mean

            raise ParameterError(f"unknown parameter '{name}' for preset '{self.label}'"
                                 f"{did_you_mean(name, self.settable())}; settable names: "
                                 + ", ".join(self.settable()), parameter=name)

    def with_values(self, changes: Mapping[str, Value]) -> ParameterSpace:
        """A new space with more overrides."""
        return ParameterSpace(self.preset, {**self.values, **changes})

    def resolve(self, changes: Mapping[str, Value] | None = None) -> Parameters:
        """Validated parameter set with some settable names changed."""
        return self.preset.resolve({**self.values, **dict(changes or {})})

    def key(self) -> str:
        """A string identifying the space (model, preset, values, ties) for caches."""
        items = sorted((k, str(v)) for k, v in self.definitions().items())
        return repr((self.model.name, self.label, items, sorted(self.tied.items())))

    def __hash__(self) -> int:
        return hash(self.key())

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ParameterSpace) and self.key() == other.key()

    # ---------------------------------------------------------------- vectorized / symbolic
    def arrays(self, axes: Mapping[str, ArrayLike]) -> dict[str, np.ndarray]:
        """Every model parameter evaluated on broadcastable axis arrays (ties applied element-wise).

        Parameters
        ----------
        axes : Mapping[str, array_like]
            Settable names → values (broadcastable arrays).

        Returns
        -------
        dict of str to ndarray
            Model parameter name → values, broadcast to the common shape.
            Where a tie cannot be evaluated (e.g. division by zero) the value
            is NaN, which :meth:`valid` marks invalid.
        """
        for n in axes:
            self.check_axis(n)
        shape = np.broadcast_shapes(*(np.shape(a) for a in axes.values())) if axes else ()
        defs = self.definitions()
        env: dict[str, Any] = {}
        for n, v in defs.items():
            env[n] = np.asarray(axes[n], dtype=float) if n in axes else _number(v, f"value of '{n}'")
        for n in dependency_order(self.tied, what=f"preset '{self.label}'"):
            env[n] = evaluate_array(self.tied[n], env, what=f"tied parameter '{n}'")
        return {n: np.broadcast_to(np.asarray(env[n], dtype=float), shape) for n in self.model.parameters}

    def valid(self, arrays: Mapping[str, ArrayLike]) -> np.ndarray:
        """Element-wise validity of :meth:`arrays` output (the array form of the scalar checks)."""
        from .roles import valid_mask

        return valid_mask(self.model.roles(), arrays)

    def symbolic(self, axes: Mapping[str, Any]) -> dict[str, Any]:
        """SymPy expressions of every model parameter with ``axes`` (name → SymPy symbol) free.

        Numbers become exact rationals of their float values; ``inf`` becomes ``sympy.oo``.
        """
        import sympy as sp

        for n in axes:
            self.check_axis(n)
        vals: dict[str, Any] = {}
        for n, v in self.definitions().items():
            if n in axes:
                vals[n] = axes[n]
            else:
                x = _number(v, f"value of '{n}'")
                vals[n] = sp.oo if math.isinf(x) else sp.Rational(x)
        for n in dependency_order(self.tied, what=f"preset '{self.label}'"):
            vals[n] = to_sympy(self.tied[n], vals, what=f"tied parameter '{n}'")
        return {n: vals[n] for n in self.model.parameters}

    def vectors(self, arrays: Mapping[str, np.ndarray]) -> list[np.ndarray]:
        """Packing-order parameter arrays (compliances for ``k_ip``), for the vectorized generated code."""
        kip = self.model.stiffness_names()
        return [compliance(arrays[n]) if n in kip else np.asarray(arrays[n], dtype=float)
                for n in self.model.parameters]


def parse_sets(sets: Sequence[str], *, option: str = "--set") -> dict[str, Value]:
    """Parse repeated ``--set NAME=VALUE`` options (values: floats where plain numbers, else expressions).

    Parameters
    ----------
    sets : sequence of str
        The ``NAME=VALUE`` texts.
    option : str, optional
        How messages name the source of the texts (default ``"--set"``); ``""``
        for values typed into named fields (the explorer), whose messages
        name the parameter only.

    Returns
    -------
    dict
        ``{name: value}``.

    Raises
    ------
    ParameterError
        A malformed assignment, a name or value too long (``MAX_NAME_CHARS``, ``MAX_EXPRESSION_CHARS`` of
        :mod:`brakesqueal.inputs`), a number
        that a double cannot hold as typed (``1e400`` overflows, ``1e-400`` underflows:
        :func:`~brakesqueal.inputs.number_problem`), or a name given twice.
    """

    def says(name: str, value: str) -> str:
        return f"{option} {name}={value}" if option else f"{name} = {value}"

    overrides: dict[str, Value] = {}
    for text in sets:
        name, sep, value = str(text).partition("=")
        name, value = name.strip(), value.strip()
        if len(name) > MAX_NAME_CHARS:
            raise ParameterError(f"{option or 'value'}: a name is {len(name)} characters long (at most "
                                 f"{MAX_NAME_CHARS})")
        if len(value) > MAX_EXPRESSION_CHARS:
            raise ParameterError(f"{says(name, '...')}: the value is {len(value)} characters long (at most "
                                 f"{MAX_EXPRESSION_CHARS})", parameter=name if name.isidentifier() else None)
        if not sep or not name.isidentifier() or not value:
            if not option and name.isidentifier():
                raise ParameterError(f"{name}: enter a number or an expression (e.g. 0.4, inf, 16*pi)",
                                     parameter=name)
            raise ParameterError(f"malformed {option or 'value'} {shown(str(text))}: expected NAME=VALUE")
        if name in overrides:
            raise ParameterError(f"{option or 'value'} '{name}' is given more than once", parameter=name)
        problem = number_problem(value)
        if problem:
            raise ParameterError(f"{says(name, value)}: the number {problem}", parameter=name)
        try:
            quantity = parse_quantity(value, says(name, value))
        except ParameterError as exc:
            raise exc.about(name) from None
        if quantity is not None:
            overrides[name] = quantity
            continue
        try:
            number = float(value)
        except ValueError:
            overrides[name] = value
            continue
        if math.isnan(number):
            raise ParameterError(f"{says(name, value)}: not a number", parameter=name)
        overrides[name] = number
    return overrides
