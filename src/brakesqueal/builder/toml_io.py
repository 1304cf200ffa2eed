"""Model descriptions in TOML (and plain dictionaries).

Format::

    name = "my-model"
    description = "..."
    [parameters]            # default values of every named parameter
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

In component fields a string is a parameter name, except ``"inf"``.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from typing import Any, Mapping

from ..errors import ParameterError
from ..expressions import evaluate
from .components import Caliper, Disk, FrictionLaw, ModelSpec, Pad

__all__ = ["spec_from_dict", "spec_to_dict", "load_model", "model_to_toml"]

_TOP = ("name", "description", "reference", "parameters", "disk", "pads", "calipers")


def _fields(cls: type, data: Mapping[str, Any], where: str) -> dict[str, Any]:
    names = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - names)
    if unknown:
        raise ParameterError(f"{where}: unknown key(s) {', '.join(unknown)}; valid keys: {', '.join(sorted(names))}")
    out = {}
    for k, v in data.items():
        if v == "inf":
            v = math.inf
        if k == "dofs":
            v = tuple(v)
        out[k] = v
    return out


def spec_from_dict(data: Mapping[str, Any], *, source: str = "model") -> ModelSpec:
    """Build a :class:`ModelSpec` from a dictionary (the TOML layout).

    Parameters
    ----------
    data : Mapping[str, Any]
        Keys ``name``, ``description``, ``reference`` (strings),
        ``parameters`` (name → number or constant expression string such as
        ``"16*pi"`` or ``"inf"``, SI units), ``disk`` (fields of
        :class:`Disk`), ``pads`` (required: a list of tables of :class:`Pad`
        fields, each with ``name``, ``face`` and an optional ``friction``
        table of :class:`FrictionLaw` fields) and ``calipers`` (optional list
        of tables of :class:`Caliper` fields).  In component fields a string
        is a parameter name, except ``"inf"``.
    source : str, optional
        How to name the data in error messages (default ``"model"``;
        :func:`load_model` passes the file).

    Returns
    -------
    ModelSpec
        The validated model.

    Raises
    ------
    ParameterError
        Unknown or missing keys, a value that is not a table where one is
        needed, an expression that cannot be evaluated, or a model that fails
        validation; the message names ``source`` and the key.
    """
    unknown = sorted(set(data) - set(_TOP))
    if unknown:
        raise ParameterError(f"{source}: unknown key(s) {', '.join(unknown)}; valid keys: {', '.join(_TOP)}")
    if "pads" not in data or not isinstance(data["pads"], list):
        raise ParameterError(f"{source}: needs a list of [[pads]]")
    params = {}
    for k, v in dict(data.get("parameters", {})).items():
        params[k] = float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else \
            evaluate(str(v), {}, what=f"{source}: parameter '{k}'")  # fmt: skip
    pads = []
    for i, raw in enumerate(data["pads"]):
        where = f"{source}: pads[{i}]" + (f" ('{raw.get('name')}')" if isinstance(raw, dict) else "")
        if not isinstance(raw, dict):
            raise ParameterError(f"{where}: must be a table")
        raw = dict(raw)
        fr = raw.pop("friction", {})
        if not isinstance(fr, dict):
            raise ParameterError(f"{where}: friction must be a table like {{ law = 'coulomb', mu = 'mu1' }}")
        if "name" not in raw or "face" not in raw:
            raise ParameterError(f"{where}: a pad needs 'name' and 'face'")
        pads.append(Pad(**_fields(Pad, raw, where), friction=FrictionLaw(**_fields(FrictionLaw, fr, f"{where} friction"))))
    calipers = []
    for i, raw in enumerate(data.get("calipers", [])):
        where = f"{source}: calipers[{i}]"
        if not isinstance(raw, dict) or "name" not in raw:
            raise ParameterError(f"{where}: a caliper needs a 'name'")
        calipers.append(Caliper(**_fields(Caliper, raw, where)))
    disk = Disk(**_fields(Disk, dict(data.get("disk", {})), f"{source}: disk"))
    return ModelSpec(
        name=str(data.get("name", "model")), disk=disk, pads=tuple(pads), calipers=tuple(calipers),
        parameters=params, description=str(data.get("description", "")), reference=str(data.get("reference", "")),
    )  # fmt: skip


def _plain(v: Any) -> Any:
    if isinstance(v, float) and math.isinf(v):
        return "inf"
    if isinstance(v, tuple):
        return list(v)
    return v


def spec_to_dict(spec: ModelSpec) -> dict[str, Any]:
    """The dictionary (TOML layout) of a spec; ``spec_from_dict`` reads it back.

    Parameters
    ----------
    spec : ModelSpec
        The model.

    Returns
    -------
    dict
        Keys ``name``, ``description``, ``reference``, ``parameters``,
        ``disk``, ``pads`` and ``calipers``; every component field that is not
        ``None`` is present, infinite numbers are written ``"inf"`` and tuples
        as lists (plain JSON/TOML types).
    """

    def comp(obj: Any) -> dict[str, Any]:
        out = {}
        for f in dataclasses.fields(obj):
            v = getattr(obj, f.name)
            if f.name == "friction":
                out["friction"] = {k: _plain(x) for k, x in comp(v).items()}
            elif v is not None:
                out[f.name] = _plain(v)
        return out

    return {
        "name": spec.name, "description": spec.description, "reference": spec.reference,
        "parameters": {k: _plain(v) for k, v in spec.parameters.items()}, "disk": comp(spec.disk),
        "pads": [comp(p) for p in spec.pads], "calipers": [comp(c) for c in spec.calipers],
    }  # fmt: skip


def load_model(path: str) -> ModelSpec:
    """Read a model TOML file; errors name the file and the key.

    Parameters
    ----------
    path : str
        Path of the TOML file (layout in the module docstring and
        :func:`spec_from_dict`).

    Returns
    -------
    ModelSpec
        The validated model.

    Raises
    ------
    ParameterError
        If the file cannot be read, is not valid TOML, or describes an
        invalid model.
    """
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except OSError as exc:
        raise ParameterError(f"cannot read model file '{path}': {exc.strerror}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"model file '{path}' is not valid TOML: {exc}") from None
    try:
        return spec_from_dict(data, source=f"model file '{path}'")
    except TypeError as exc:
        raise ParameterError(f"model file '{path}': {exc}") from None


def _toml_value(v: Any) -> str:
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + " }"
    return repr(float(v)) if isinstance(v, float) else str(v)


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
        (friction as an inline table) and one ``[[calipers]]`` table per
        caliper.  Floats are written with ``repr`` (exact round trip),
        infinity as ``"inf"``.
    """
    d = spec_to_dict(spec)
    lines = [f"name = {_toml_value(d['name'])}", f"description = {_toml_value(d['description'])}",
             f"reference = {_toml_value(d['reference'])}", "", "[parameters]"]  # fmt: skip
    lines += [f"{k} = {_toml_value(v)}" for k, v in d["parameters"].items()]
    lines += ["", "[disk]"] + [f"{k} = {_toml_value(v)}" for k, v in d["disk"].items()]
    for p in d["pads"]:
        lines += ["", "[[pads]]"] + [f"{k} = {_toml_value(v)}" for k, v in p.items()]
    for c in d["calipers"]:
        lines += ["", "[[calipers]]"] + [f"{k} = {_toml_value(v)}" for k, v in c.items()]
    return "\n".join(lines) + "\n"
