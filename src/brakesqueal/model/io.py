"""Model files and parameter files in TOML (and plain dictionaries).

Model file::

    name = "my-model"
    description = "..."
    [parameters]            # default values of every named parameter (canonical order)
    Theta = 0.16
    k_ip1 = "inf"           # strings: "inf" or constant expressions like "16*pi"
    [disk]                  # fields of Disk; numbers or parameter names
    Theta = "Theta"
    [[pads]]                # one table per pad (fields of Pad)
    name = "upper"
    face = "upper"
    k_ip = "k_ip1"
    friction = { law = "coulomb", mu = "mu1" }
    [[calipers]]            # optional (fields of Caliper)
    name = "caliper"
    [presets.symmetric]     # optional presets: free, fixed and tied names
    description = "..."
    free = { mu = 0.5 }
    tied = { mu1 = "mu", mu2 = "mu" }

In component fields a string is a parameter name, except ``"inf"``.

Parameter file::

    model = "paper"          # optional: a built-in model name or a model file
    preset = "paper-fig3"    # optional: a preset of that model
    [parameters]             # values overriding the preset (or all parameters)
    mu1 = 0.7

Every file is read by the one input reader of :mod:`brakesqueal.inputs`:
a regular file (never a FIFO or device) of at most :data:`MAX_FILE_BYTES`,
whose nesting and value lengths are bounded before it is parsed; every
problem is one :class:`~brakesqueal.errors.ParameterError` line naming the
file and the key.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
import tomllib
from dataclasses import MISSING
from typing import Any, Mapping

from ..inputs import MAX_FILE_BYTES, check_data, check_text, number_problem, read_input
from ..errors import ParameterError
from .components import COMPONENTS, Component, FrictionLaw, Kind, ModelSpec
from .expressions import evaluate
from .parameters import Parameters, Preset, Value

__all__ = ["spec_from_dict", "spec_to_dict", "load_model", "model_to_toml", "read_toml", "load_parameter_file",
           "parameters_to_toml", "MAX_FILE_BYTES", "read_toml_text", "presets_from_dict"]

_PRESET_KEYS = ("description", "reference", "free", "fixed", "tied", "auxiliary")
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")
_ESCAPES = {"\\": "\\\\", '"': '\\"', "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r"}


class _BadNumber(ValueError):
    """A TOML number that a double cannot hold as typed (the text and the problem)."""


def _number(text: str) -> float:
    """TOML float parser that refuses numbers beyond the double range, as typed (``1e400``, ``1e-400``); only a
    literal ``inf`` means infinity."""
    problem = number_problem(text)
    if problem:
        raise _BadNumber(text, problem)
    return float(text)


def read_toml_text(path: str | os.PathLike[str], what: str) -> tuple[str, dict[str, Any]]:
    """Read a TOML file through the one input reader: its text and document; every failure one ParameterError.

    The file is read by :func:`brakesqueal.inputs.read_input` (a regular file of at most
    :data:`MAX_FILE_BYTES`, never a FIFO or device), its nesting and value lengths are bounded before it is
    parsed (:func:`~brakesqueal.inputs.check_text`), numbers a double cannot hold are refused as typed, and
    the document is checked by :func:`~brakesqueal.inputs.check_data`.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str
        What the file is, for messages (``"model file"``, ``"parameter file"``, ``"study file"``).

    Returns
    -------
    text : str
        The file's text.
    data : dict
        The parsed TOML document.
    """
    text = read_input(path, what)
    where = f"{what} '{os.fspath(path)}'"
    check_text(text, where)
    try:
        data = tomllib.loads(text, parse_float=_number)
    except _BadNumber as exc:
        typed, problem = exc.args
        line = text[:text.find(typed)].count("\n") + 1 if typed in text else None
        at = f" (line {line})" if line else ""
        raise ParameterError(f"{where}: the number {typed}{at} {problem}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{where} is not valid TOML: {exc}") from None
    check_data(data, where)
    return text, data


def read_toml(path: str | os.PathLike[str], what: str) -> dict[str, Any]:
    """Read a TOML file (:func:`read_toml_text`), turning every failure into one ParameterError line.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str
        What the file is, for messages (``"model file"``, ``"parameter file"``).

    Returns
    -------
    dict
        The parsed TOML document.
    """
    return read_toml_text(path, what)[1]


def _fields(kind: Kind, data: Mapping[str, Any], where: str) -> dict[str, Any]:
    """The keyword arguments of a component from its table (fields as :mod:`.components` defines them)."""
    from ..suggest import did_you_mean

    fields = dataclasses.fields(kind.cls)
    names = [f.name for f in fields]
    unknown = sorted(set(data) - set(names))
    if unknown:
        raise ParameterError(f"{where}: unknown key '{unknown[0]}'{did_you_mean(unknown[0], names)}; valid keys: "
                             f"{', '.join(names)}")
    missing = [f"'{f.name}'" for f in fields if f.name not in data and f.default is f.default_factory is MISSING]
    if missing:
        raise ParameterError(f"{where}: a {kind.key} needs {' and '.join(missing)}")
    out = {}
    for f in (f for f in fields if f.name in data):
        v, schema = data[f.name], f.metadata.get("schema", {})
        if f.default_factory is FrictionLaw:
            if not isinstance(v, dict):
                raise ParameterError(f"{where}: {f.name} must be a table like {{ law = 'coulomb', mu = 'mu1' }}")
            table: dict[str, Any] = {k: (math.inf if x == "inf" else x) for k, x in v.items()}  # checked by the law
            v = FrictionLaw(**table)
        elif schema.get("type") == "array":
            if not isinstance(v, (list, tuple)):
                example = ", ".join(f'"{x}"' for x in schema.get("items", {}).get("enum", ()))
                raise ParameterError(f"{where}: '{f.name}' must be a list such as [{example}]; got {v!r}")
            v = tuple(v)
        elif v == "inf" and ("role" in f.metadata or schema.get("type") == "number"):  # elsewhere "inf" is a name
            v = math.inf
        out[f.name] = v
    return out


def _table(data: Mapping[str, Any], key: str, where: str, *, kind: type = dict, what: str = "a table") -> Any:
    v = data.get(key, kind())
    if not isinstance(v, kind):
        raise ParameterError(f"{where}: key '{key}' must be {what}; got {v!r} ({type(v).__name__})")
    return v


def presets_from_dict(data: Mapping[str, Any], source: str) -> tuple[Preset, ...]:
    """The ``[presets.NAME]`` tables of a model file (unbound :class:`Preset` objects)."""
    out = []
    for name, raw in _table(data, "presets", source).items():
        where = f"{source}: presets.{name}"
        if not isinstance(raw, dict):
            raise ParameterError(f"{where}: must be a table with free/fixed/tied")
        unknown = sorted(set(raw) - set(_PRESET_KEYS))
        if unknown:
            raise ParameterError(f"{where}: unknown key '{unknown[0]}'; valid keys: {', '.join(_PRESET_KEYS)}")
        kw = {k: _table(raw, k, where) for k in ("free", "fixed", "tied", "auxiliary")}
        for k in ("description", "reference"):
            kw[k] = str(raw.get(k, ""))
        out.append(Preset(name=name, **kw))
    return tuple(out)


def spec_from_dict(data: Mapping[str, Any], *, source: str = "model") -> ModelSpec:
    """Build a :class:`ModelSpec` from a dictionary (the TOML layout of the module docstring).

    Parameters
    ----------
    data : Mapping[str, Any]
        Keys ``name``, ``description``, ``reference`` (strings),
        ``parameters`` (name → number or constant expression string such as
        ``"16*pi"`` or ``"inf"``, SI units), ``disk`` (fields of
        :class:`Disk`), ``pads`` (required: a list of tables of :class:`Pad`
        fields, each with ``name``, ``face`` and an optional ``friction``
        table of :class:`FrictionLaw` fields), ``calipers`` (optional list of
        tables of :class:`Caliper` fields) and ``presets`` (optional tables).
    source : str, optional
        How to name the data in error messages (default ``"model"``).

    Returns
    -------
    ModelSpec
        The validated model.

    Raises
    ------
    ParameterError
        Unknown or missing keys, a value of the wrong type, an expression
        that cannot be evaluated, or a model that fails validation; the
        message names ``source`` and the key.
    """
    from ..suggest import did_you_mean
    from .matrices import is_matrix_model_data, matrix_spec_from_dict

    if not isinstance(data, Mapping):
        raise ParameterError(f"{source}: must be a table")
    check_data(data, source)
    if is_matrix_model_data(data):  # a model given by coefficient matrices (file paths absolute or from here)
        return matrix_spec_from_dict(data, source=source)  # type: ignore[return-value]
    top = ("name", "description", "reference", "parameters", *(k.table for k in COMPONENTS.values()), "presets")
    unknown = sorted(set(data) - set(top))
    if unknown:
        raise ParameterError(f"{source}: unknown key '{unknown[0]}'{did_you_mean(unknown[0], top)}; valid keys: "
                             f"{', '.join(top)}")
    for key in ("name", "description", "reference"):
        if key in data and not isinstance(data[key], str):
            raise ParameterError(f"{source}: key '{key}' must be a string; got {data[key]!r}")
    for kind in COMPONENTS.values():
        if kind.many and kind.required and not (isinstance(data.get(kind.table), list) and data[kind.table]):
            raise ParameterError(f"{source}: needs a non-empty list of [[{kind.table}]] tables")
    params: dict[str, float] = {}
    for k, v in _table(data, "parameters", source).items():
        if isinstance(v, bool) or not isinstance(v, (int, float, str)):
            raise ParameterError(f"{source}: parameters.{k} must be a number or an expression string; got {v!r}")
        params[k] = float(v) if not isinstance(v, str) else evaluate(v, {}, what=f"{source}: parameter '{k}'")
    try:
        held: dict[str, Any] = {}
        for kind in COMPONENTS.values():
            if not kind.many:
                table = _table(data, kind.table, source)
                held[kind.table] = kind.cls(**_fields(kind, table, f"{source}: {kind.table}"))
                continue
            items = []
            for i, raw in enumerate(_table(data, kind.table, source, kind=list,
                                           what=f"a list of [[{kind.table}]] tables")):
                where = f"{source}: {kind.table}[{i}]" + (f" ('{raw['name']}')" if isinstance(raw, dict)
                                                          and "name" in raw else "")
                if not isinstance(raw, dict):
                    raise ParameterError(f"{where}: must be a table")
                items.append(kind.cls(**_fields(kind, raw, where)))
            held[kind.table] = tuple(items)
        return ModelSpec(
            name=str(data.get("name", "model")), **held,
            parameters=params, description=str(data.get("description", "")),
            reference=str(data.get("reference", "")), presets=presets_from_dict(data, source),
        )  # fmt: skip
    except ParameterError as exc:
        msg = str(exc)
        raise ParameterError(msg if msg.startswith(source) else f"{source}: {msg}") from None
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{source}: {exc}") from None


def _plain(v: Any) -> Any:
    if isinstance(v, float) and math.isinf(v):
        return "inf"
    if isinstance(v, tuple):
        return list(v)
    return v


def spec_to_dict(spec: ModelSpec, *, presets: bool = True) -> dict[str, Any]:
    """The dictionary (TOML layout) of a spec; :func:`spec_from_dict` reads it back.

    Parameters
    ----------
    spec : ModelSpec
        The model.
    presets : bool, optional
        Include the ``presets`` table (default ``True``).

    Returns
    -------
    dict
        Keys ``name``, ``description``, ``reference``, ``parameters``,
        ``disk``, ``pads``, ``calipers`` (and ``presets``); every component
        field that is not ``None`` is present, infinite numbers are written
        ``"inf"`` and tuples as lists (plain JSON/TOML types).
    """
    from .matrices import MatrixSpec, matrix_spec_to_dict

    if isinstance(spec, MatrixSpec):  # a model given by coefficient matrices: its files, law and a checksum
        return matrix_spec_to_dict(spec, checksum=True)

    def comp(obj: Component) -> dict[str, Any]:
        out = {}
        for f in dataclasses.fields(obj):
            v = getattr(obj, f.name)
            if isinstance(v, FrictionLaw):
                out[f.name] = {"law": v.law, **{k: _plain(x) for k, x in v.values().items()}}
            elif v is not None:
                out[f.name] = _plain(v)
        return out

    d: dict[str, Any] = {
        "name": spec.name, "description": spec.description, "reference": spec.reference,
        "parameters": {k: _plain(v) for k, v in spec.parameters.items()},
    }  # fmt: skip
    for kind in COMPONENTS.values():
        held = getattr(spec, kind.table)
        d[kind.table] = [comp(c) for c in held] if kind.many else comp(held)
    if presets and spec.presets:
        d["presets"] = {p.name: {"description": p.description, "reference": p.reference,
                                 "free": {k: _plain(v) for k, v in p.free.items()},
                                 "fixed": {k: _plain(v) for k, v in p.fixed.items()},
                                 "tied": dict(p.tied), "auxiliary": dict(p.auxiliary)} for p in spec.presets}
    return d


def load_model(path: str | os.PathLike[str]) -> ModelSpec:
    """Read a model TOML file; errors name the file and the key.

    Parameters
    ----------
    path : str or os.PathLike
        Path of the TOML file (layout in the module docstring); never a file descriptor.

    Returns
    -------
    ModelSpec
        The validated model.

    Raises
    ------
    ParameterError
        If ``path`` is not a path, the file cannot be read, is not a regular
        file, is too large, nests too deeply, is not UTF-8, not valid TOML,
        or describes an invalid model.
    """
    data = read_toml(path, "model file")
    path = os.fspath(path)
    source = f"model file '{path}'"
    from .matrices import is_matrix_model_data, matrix_spec_from_dict

    if is_matrix_model_data(data):  # a model given by coefficient matrices (imported finite-element models)
        return matrix_spec_from_dict(data, source=source, base=os.path.dirname(os.path.abspath(path)))  # type: ignore[return-value]
    return spec_from_dict(data, source=source)


def _toml_string(text: str) -> str:
    """A TOML basic string: quotes, backslashes and every control character escaped (reads back exactly)."""
    out = []
    for ch in text:
        if ch in _ESCAPES:
            out.append(_ESCAPES[ch])
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _toml_key(key: str) -> str:
    """A TOML key: bare when it is made of ASCII letters, digits, ``_`` and ``-``, else quoted."""
    return key if _BARE_KEY.fullmatch(key) else _toml_string(key)


def _toml_value(v: Any) -> str:
    if isinstance(v, str):
        return _toml_string(v)
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_toml_key(k)} = {_toml_value(x)}" for k, x in v.items()) + " }"
    if isinstance(v, float):
        return "inf" if v == math.inf else "-inf" if v == -math.inf else "nan" if math.isnan(v) else repr(v)
    return str(v)


def model_to_toml(spec: ModelSpec) -> str:
    """A TOML model file for ``spec`` (round-trips through :func:`load_model`).

    Parameters
    ----------
    spec : ModelSpec
        The model.

    Returns
    -------
    str
        The TOML text: top-level ``name``, ``description``, ``reference``,
        then ``[parameters]``, ``[disk]``, one ``[[pads]]`` table per pad
        (friction as an inline table), one ``[[calipers]]`` table per caliper
        and one ``[presets.NAME]`` table per preset.  Floats are written with
        ``repr`` (exact round trip), infinity as ``"inf"``.
    """
    d = spec_to_dict(spec)
    lines = [f"name = {_toml_value(d['name'])}", f"description = {_toml_value(d['description'])}",
             f"reference = {_toml_value(d['reference'])}", "", "[parameters]"]  # fmt: skip
    lines += [f"{_toml_key(k)} = {_toml_value(v)}" for k, v in d["parameters"].items()]
    for kind in COMPONENTS.values():
        header = f"[[{kind.table}]]" if kind.many else f"[{kind.table}]"
        for c in d[kind.table] if kind.many else [d[kind.table]]:
            lines += ["", header] + [f"{k} = {_toml_value(v)}" for k, v in c.items()]
    for name, p in d.get("presets", {}).items():
        lines += ["", f"[presets.{_toml_key(name)}]"] + [f"{k} = {_toml_value(v)}" for k, v in p.items()]
    return "\n".join(lines) + "\n"


def load_parameter_file(path: str) -> tuple[str | None, str | None, dict[str, Value]]:
    """Read a parameter file: optional ``model`` and ``preset`` keys and a ``[parameters]`` table.

    Returns
    -------
    model : str or None
        The ``model`` key (built-in name or model file path, relative paths
        resolved against the parameter file's directory).
    preset : str or None
        The ``preset`` key.
    entries : dict
        The ``[parameters]`` table: numbers or expression strings (a number with a unit, ``"1200 rpm"``,
        in SI: a :class:`~.units.Quantity`).

    Raises
    ------
    ParameterError
        One line naming the file and the key for an unreadable file, invalid
        TOML, unknown top-level keys or wrong types.
    """
    from ..suggest import did_you_mean

    data = read_toml(path, "parameter file")
    where = f"parameter file '{path}'"
    allowed = ("model", "preset", "parameters")
    for key in data:
        if key not in allowed:
            raise ParameterError(f"{where}: unknown top-level key '{key}'{did_you_mean(key, allowed)}; "
                                 f"allowed keys: {', '.join(allowed)}")
    model, preset = data.get("model"), data.get("preset")
    for key, v in (("model", model), ("preset", preset)):
        if v is not None and not isinstance(v, str):
            raise ParameterError(f"{where}: key '{key}' must be a string; got {v!r}")
    if isinstance(model, str) and (model.endswith(".toml") and not os.path.isabs(model)):
        model = os.path.join(os.path.dirname(os.path.abspath(path)), model)
    table = _table(data, "parameters", where, what="a table ([parameters])")
    from .units import parse_quantity

    entries: dict[str, Value] = {}
    for key, value in table.items():
        if isinstance(value, bool) or not isinstance(value, (int, float, str)):
            raise ParameterError(f"{where}: key 'parameters.{key}' must be a number or an expression string; "
                                 f"got {value!r} ({type(value).__name__})")
        quantity = parse_quantity(value, f"{where}: parameters.{key} = {value!r}") if isinstance(value, str) else None
        entries[key] = value if quantity is None else quantity  # "1200 rpm": in SI, checked against the unit
    return model, preset, entries


def parameters_to_toml(params: Parameters) -> str:
    """A complete parameter file for ``params`` (a :class:`~.parameters.Parameters`) that reads back exactly.

    Floats are written with ``repr`` (exact round trip); ``inf`` as ``"inf"``.
    """
    spec = params.model
    lines = ["# brakesqueal parameter set (SI units)", f"model = {_toml_value(spec.name)}", "[parameters]"]
    for name, value in params.to_json_dict().items():
        text = '"inf"' if isinstance(value, str) else repr(float(value))
        unit = spec.unit(name)
        note = f"{('[' + unit + '] ') if unit else ''}{spec.describe_parameter(name)}".replace("\n", " ")
        lines.append(f"{_toml_key(name)} = {text}  # {note}")
    return "\n".join(lines) + "\n"
