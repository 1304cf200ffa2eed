"""The JSON Schema of model files, shipped with the package.

``model.schema.json`` (JSON Schema draft 2020-12) describes a model TOML file
as :func:`brakesqueal.model.io.spec_from_dict` reads it: the top-level keys,
the ``[disk]`` table, ``[[pads]]`` with their friction tables,
``[[calipers]]``, ``[parameters]`` and ``[presets.NAME]``, with the unit and
allowed range of every key in its ``description``.  Editors use it for
completion and validation (``docs/model-format.md``); Python code can
validate a parsed file with the ``jsonschema`` package::

    import tomllib, jsonschema
    from brakesqueal.model.schema import schema

    with open("my-model.toml", "rb") as fh:
        jsonschema.validate(tomllib.load(fh), schema())

The schema checks each table on its own; what needs the whole model (a
default value for every parameter name used and for no other, parameter
values inside the ranges of the fields that use them, unique component
names, a ``mount`` naming an existing caliper, the number of coordinates,
presets that define every parameter) is left to the reader,
:func:`brakesqueal.model.io.load_model`.

The file is generated from the package's own tables (the component kinds of
:data:`brakesqueal.model.components.COMPONENTS` and their fields,
:data:`brakesqueal.model.friction.LAWS`, :data:`brakesqueal.model.roles.ROLES`)
by :func:`build_schema`; after changing them, regenerate it with
``python -m brakesqueal.model.schema --write`` (a test compares the two).
"""

from __future__ import annotations

import dataclasses
import json
import math
import pathlib
import sys
from importlib import resources
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .components import Kind
    from .friction import LawDef

__all__ = ["SCHEMA_FILE", "SCHEMA_ID", "schema", "schema_path", "build_schema"]

#: File name of the schema inside the ``brakesqueal.model`` package.
SCHEMA_FILE = "model.schema.json"
#: The schema's ``$id`` (an identifier only; nothing is fetched from it).
SCHEMA_ID = "https://brakesqueal.invalid/model.schema.json"

_MAX_FLOAT = sys.float_info.max
_NAME_PATTERN = "^[A-Za-z_][A-Za-z0-9_]*$"
_COMPONENT_PATTERN = "^[A-Za-z0-9_]+$"


def schema_path() -> pathlib.Path:
    """Path of the installed schema file, for editors (e.g. Taplo's ``#:schema`` directive).

    Returns
    -------
    pathlib.Path
        Absolute path of ``model.schema.json`` inside the installed
        ``brakesqueal.model`` package.
    """
    return pathlib.Path(str(resources.files("brakesqueal.model").joinpath(SCHEMA_FILE))).resolve()


def schema() -> dict[str, Any]:
    """The JSON Schema of model files as a dictionary (a fresh copy on every call).

    Returns
    -------
    dict
        The parsed ``model.schema.json`` (draft 2020-12), ready for
        ``jsonschema.validate(document, schema())``.
    """
    text = resources.files("brakesqueal.model").joinpath(SCHEMA_FILE).read_text(encoding="utf-8")
    out: dict[str, Any] = json.loads(text)
    return out


# ---------------------------------------------------------------------------------------------- generation
def _value(role_key: str, owner: str, extra: str = "", default: object = dataclasses.MISSING) -> dict[str, Any]:
    """A field that is a number in its role's interval or a parameter name (or ``inf`` where allowed)."""
    from .io import _plain
    from .roles import MAX_MAGNITUDE, ROLES

    r = ROLES[role_key]
    number: dict[str, Any] = {"type": "number"}
    if math.isinf(r.low):
        number["minimum"] = -MAX_MAGNITUDE
    else:
        number["exclusiveMinimum" if r.low_open else "minimum"] = r.low
    if math.isinf(r.high):
        number["maximum"] = MAX_MAGNITUDE
    else:
        number["exclusiveMaximum" if r.high_open else "maximum"] = r.high
    alternatives: list[dict[str, Any]] = [number, {"$ref": "#/$defs/parameterName"}]
    if r.allows_inf:
        alternatives.append({"const": "inf", "description": "+infinity (a rigid support / no limit)"})
        alternatives.append({"type": "number", "minimum": _MAX_FLOAT, "description": "TOML's bare inf"})
    unit = f"[{r.unit}] " if r.unit else "[dimensionless] "
    text = (unit + r.description.format(owner=owner) + f". A number in {r.interval()}"
            + ("" if r.allows_inf else f" (magnitude at most {MAX_MAGNITUDE:.0e})")
            + (", 'inf'," if r.allows_inf else "") + " or the name of a parameter of [parameters]." + extra)
    out: dict[str, Any] = {"description": text, "anyOf": alternatives}
    if default is not dataclasses.MISSING and default is not None:
        out["default"] = _plain(default)
    return out


def _component(kind: Kind) -> dict[str, Any]:
    """The schema of one component of a kind (:data:`.components.COMPONENTS`), from its dataclass fields."""
    props: dict[str, Any] = {}
    fields = dataclasses.fields(kind.cls)
    for f in fields:
        if "role" in f.metadata:
            unless = f.metadata["unless"]
            note = f.metadata["note"] + (f" Unused (but checked) when {unless} = false." if unless else "")
            props[f.name] = _value(f"{kind.key}.{f.name}", kind.schema_owner, note, f.default)
        else:
            props[f.name] = dict(f.metadata["schema"])
    out: dict[str, Any] = {"title": kind.cls.__name__, "type": "object", "additionalProperties": False}
    required = [f.name for f in fields if f.default is f.default_factory is dataclasses.MISSING]
    out |= ({"required": required} if required else {}) | {"description": kind.description, "properties": props}
    return out | ({"allOf": list(kind.rules)} if kind.rules else {})


def _listed(kind: Kind) -> dict[str, Any]:
    """The model file's key of a kind: a table, or a list of tables."""
    ref = {"$ref": f"#/$defs/{kind.key}"}
    if not kind.many:
        return {**ref, "description": kind.doc}
    count = {"minItems": 1} if kind.required else {}
    count |= {} if kind.max_count is None else {"maxItems": kind.max_count}
    default: dict[str, Any] = {} if kind.required else {"default": []}
    return {"type": "array", **count, "items": ref, **default, "description": kind.doc}


def _law_text(law: LawDef) -> str:
    fields = ", ".join(["mu", *law.fields])
    formula = law.text
    return f"{law.name}: {formula} (fields: {fields})" if formula else f"{law.name} (fields: {fields})"


def _friction() -> dict[str, Any]:
    from .friction import LAWS

    texts = "; ".join(_law_text(law) for law in LAWS.values())
    branches = []
    for law in LAWS.values():
        props: dict[str, Any] = {
            "law": {"const": law.name, "description": _law_text(law)},
            "mu": _value("friction.mu", "this contact", " For the linear law, the intercept at v = 0.", "mu"),
        }
        props |= {name: _value(f"friction.{name}", "this contact") for name in law.fields}
        branch: dict[str, Any] = {"title": f"{law.name} friction", "type": "object",
                                  "additionalProperties": False, "properties": props}  # fmt: skip
        if law.name != "coulomb":  # the law may be omitted only for the default, coulomb
            branch["required"] = ["law", *law.fields]
        branches.append(branch)
    law_key = {"enum": list(LAWS), "default": "coulomb", "description": f"Friction law: {texts}."}
    every: dict[str, Any] = {"law": law_key}
    for branch in branches:  # every field at the top for editor completion; the branches restrict them per law
        for key, prop in branch["properties"].items():
            if key != "law":
                every.setdefault(key, prop)
    return {
        "title": "Friction law", "type": "object", "properties": every, "oneOf": branches,
        "description": "Friction law at the pad's contact (inline table friction = { law = ..., mu = ... } or a "
                       "[pads.friction] table): the kinetic friction coefficient as a function of the sliding "
                       f"speed v [m/s]. {texts}. Missing table: coulomb with mu = parameter 'mu'.",
    }  # fmt: skip


def _preset() -> dict[str, Any]:
    def names(values: dict[str, Any], text: str) -> dict[str, Any]:
        return {"type": "object", "default": {}, "propertyNames": {"$ref": "#/$defs/presetName"},
                "additionalProperties": values, "description": text}  # fmt: skip

    number = {"$ref": "#/$defs/numberOrExpression"}
    return {
        "title": "Preset", "type": "object", "additionalProperties": False,
        "description": "A named parameter template ([presets.NAME]): free names (the intended knobs), fixed "
                       "names and tied names (expressions of the others). Together free, fixed and tied must "
                       "define every parameter of the model, each name once; they may also define auxiliary "
                       "names (e.g. mu, h) that tied expressions use. The name must differ from the model's "
                       "name, which is the implicit preset with every parameter free.",
        "properties": {
            "description": {"type": "string", "default": "", "description": "One-line summary of the preset."},
            "reference": {"type": "string", "default": "",
                          "description": "Where the values come from (paper section, equations, figure)."},
            "free": names(number, "The intended knobs with their default values (settable): parameter or "
                                  "auxiliary name = number or constant expression."),
            "fixed": names(number, "Values that rarely change (still settable): parameter or auxiliary name = "
                                   "number or constant expression."),
            "tied": names({"type": "string", "description": "Expression of free, fixed and other tied names, "
                                                            "e.g. \"1800/mu\" (no cycles)."},
                          "Names computed from others: name = expression string. Setting a tied name (--set) "
                          "replaces its tie."),
            "auxiliary": names({"type": "string"}, "Descriptions of auxiliary (non-parameter) names, optionally "
                                                   "starting with the unit in brackets: h = \"[m] disk thickness\"."),
        },
    }  # fmt: skip


def build_schema() -> dict[str, Any]:
    """Build the model-file schema from the package's tables (what ``model.schema.json`` must contain).

    Returns
    -------
    dict
        The JSON Schema (draft 2020-12): one key and one definition per
        component kind of :data:`brakesqueal.model.components.COMPONENTS`
        (fields, notes and cross-field rules from its dataclass and entry),
        units and ranges from :data:`brakesqueal.model.roles.ROLES`, friction
        laws from :data:`brakesqueal.model.friction.LAWS`.
    """
    from .components import COMPONENTS, FrictionLaw
    from .expressions import RESERVED_NAMES

    reserved = sorted(RESERVED_NAMES)
    components: dict[str, Any] = {}
    for kind in COMPONENTS.values():
        components[kind.key] = _component(kind)
        if any(f.default_factory is FrictionLaw for f in dataclasses.fields(kind.cls)):
            components.setdefault("friction", _friction())
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": SCHEMA_ID,
        "title": "brakesqueal model file (TOML)",
        "description": "A wobbling-disk brake-squeal model: a rigid disk, one or more pads, optional calipers, "
                       "default parameter values and presets (read by brakesqueal.model.load_model; written by "
                       "model_to_toml). SI units throughout. A component field is a number or the name of a "
                       "parameter (a string); the string \"inf\" means +infinity where allowed.",
        "type": "object",
        "additionalProperties": False,
        "required": ["pads"],
        "properties": {
            "name": {"type": "string", "default": "model",
                     "description": "Model name; also the name of its implicit preset in which every parameter "
                                    "is free."},
            "description": {"type": "string", "default": "",
                            "description": "Assumptions of the model (one paragraph)."},
            "reference": {"type": "string", "default": "", "description": "The literature the model follows."},
            "parameters": {
                "type": "object", "default": {},
                "description": "Default value of every parameter name the components use (and no other), in "
                               "the model's canonical order: name = number or constant expression (SI units, the "
                               "unit of the field(s) that use the name). Values must lie in the allowed range of "
                               "every field that uses the name.",
                "propertyNames": {"$ref": "#/$defs/parameterName"},
                "additionalProperties": {"$ref": "#/$defs/numberOrExpression"},
            },
            **{kind.table: _listed(kind) for kind in COMPONENTS.values()},
            "presets": {"type": "object", "default": {}, "additionalProperties": {"$ref": "#/$defs/preset"},
                        "description": "Optional named presets ([presets.NAME] tables)."},
        },
        "$defs": {
            "parameterName": {
                "type": "string", "pattern": _NAME_PATTERN, "not": {"enum": reserved},
                "description": "A parameter name: an ASCII identifier other than the reserved names "
                               + ", ".join(reserved) + ".",
            },
            "presetName": {
                "type": "string", "pattern": _NAME_PATTERN, "not": {"enum": reserved},
                "description": "A parameter or auxiliary name: an ASCII identifier other than the reserved names "
                               + ", ".join(reserved) + ".",
            },
            "componentName": {"type": "string", "pattern": _COMPONENT_PATTERN, "not": {"const": "inf"},
                              "description": "A component name: ASCII letters, digits and '_'."},
            "numberOrExpression": {
                "anyOf": [{"type": "number"}, {"type": "string"}],
                "description": "A number (SI units) or a constant expression string such as \"16*pi\" or "
                               "\"inf\" (numbers, + - * / **, sqrt sin cos tan exp log abs, pi, inf).",
            },
            **components, "preset": _preset(),
        },
    }  # fmt: skip


def _main(argv: list[str]) -> int:
    text = json.dumps(build_schema(), indent=2, ensure_ascii=False) + "\n"
    if argv[:1] == ["--write"]:
        path = pathlib.Path(__file__).with_name(SCHEMA_FILE)
        path.write_text(text, encoding="utf-8")
        print(path)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(_main(sys.argv[1:]))
