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

The file is generated from the package's own tables (component fields,
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
from typing import Any

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
def _default(v: Any) -> Any:
    if isinstance(v, float) and math.isinf(v):
        return "inf"
    return list(v) if isinstance(v, tuple) else v


def _value(role_key: str, owner: str, extra: str = "", default: Any = dataclasses.MISSING) -> dict[str, Any]:
    """A field that is a number in its role's interval or a parameter name (or ``inf`` where allowed)."""
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
        out["default"] = _default(default)
    return out


def _defaults(cls: Any) -> dict[str, Any]:
    return {f.name: f.default for f in dataclasses.fields(cls) if f.default is not dataclasses.MISSING}


def _has_dof(dof: str) -> dict[str, Any]:
    return {"required": ["dofs"], "properties": {"dofs": {"contains": {"const": dof}}}}


def _disk() -> dict[str, Any]:
    from .components import Disk

    defaults = _defaults(Disk)
    unused = " Unused (but checked) when tilting = false."
    extra = {
        "Theta": unused, "Phi": unused, "k_t": unused, "d_t": unused,
        "h_upper": " 'upper' pads touch the face z0 = -h_upper; h_upper + h_lower must be > 0.",
        "h_lower": " 'lower' pads touch the face z0 = +h_lower; h_upper + h_lower must be > 0.",
        "Omega": "",
        "radius": " Only used to check that every pad's radius is at most the disk radius.",
    }  # fmt: skip
    props = {f: _value(f"disk.{f}", "the disk", text, defaults[f]) for f, text in extra.items()}
    props["tilting"] = {
        "type": "boolean", "default": True,
        "description": "true: the tilt angles q1, q2 are degrees of freedom. false: the tilt is locked and the "
                       "disk is a belt moving at Omega * radius under each pad (planar pad models; then some pad "
                       "needs a mass with a DOF).",
    }  # fmt: skip
    return {
        "title": "Disk", "type": "object", "additionalProperties": False, "properties": props,
        "description": "The rigid disk (table [disk]): tilting DOFs q1, q2 on rotational supports, constant "
                       "spin Omega. Every key is optional; a missing key takes its default, which is a parameter "
                       "name (Theta, Phi, k_t, d_t, h10, h20, Omega) that [parameters] must then define.",
    }  # fmt: skip


def _law_text(law: Any) -> str:
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


def _pad() -> dict[str, Any]:
    from .components import FACES, Pad

    defaults = _defaults(Pad)
    extra = {
        "radius": " Must not exceed the disk radius.", "k": "", "d": "", "preload": "",
        "k_ip": " Default 'inf' (rigid); a tangential DOF needs a finite k_ip.",
        "d_ip": " Must be 0 unless the pad has a tangential DOF.",
        "mass": " Needs at least one entry in dofs; absent = massless pad.",
        "k_c": " Needed by a normal DOF: the contact force is preload + k_c * penetration + d_c * its rate.",
        "d_c": "",
    }  # fmt: skip
    props: dict[str, Any] = {
        "name": {"$ref": "#/$defs/componentName",
                 "description": "Unique component name (ASCII letters, digits, '_'; unique among pads and "
                                "calipers)."},
        "face": {"enum": list(FACES),
                 "description": "Disk face the pad touches: 'upper' (face z0 = -h_upper, pushes along +z0) or "
                                "'lower' (face z0 = +h_lower, pushes along -z0)."},
        "angle_deg": {"type": "number", "minimum": -_MAX_FLOAT, "maximum": _MAX_FLOAT, "default": 0.0,
                      "description": "[deg] angular position of the pad around z0 (0 = the paper's pads, at "
                                     "y0 = -radius). A finite number (not a parameter name)."},
        "dofs": {"type": "array", "uniqueItems": True, "default": [], "items": {"enum": ["normal", "tangential"]},
                 "description": "Directions in which the pad mass moves as its own DOF (distinct entries of "
                                "'normal', 'tangential'); empty = massless pad (normal force from its "
                                "equilibrium, tangentially quasi-static). Non-empty needs mass."},
        "friction": {"$ref": "#/$defs/friction",
                     "description": "Friction law at this contact (default: coulomb with mu = parameter 'mu')."},
        "mount": {"$ref": "#/$defs/componentName",
                  "description": "Name of the [[calipers]] entry carrying the pad's normal and tangential "
                                 "supports (absent: the supports act on ground)."},
    }  # fmt: skip
    props |= {f: _value(f"pad.{f}", "this pad", text, defaults.get(f)) for f, text in extra.items()}
    infinite = {"anyOf": [{"const": "inf"}, {"type": "number", "minimum": _MAX_FLOAT}]}
    return {
        "title": "Pad", "type": "object", "additionalProperties": False, "required": ["name", "face"],
        "description": "One brake pad in point contact with a disk face (one [[pads]] table per pad).",
        "properties": {f.name: props[f.name] for f in dataclasses.fields(Pad)},
        "allOf": [
            {"if": {"required": ["dofs"], "properties": {"dofs": {"minItems": 1}}}, "then": {"required": ["mass"]}},
            {"if": {"required": ["mass"]}, "then": {"required": ["dofs"], "properties": {"dofs": {"minItems": 1}}}},
            {"if": _has_dof("normal"), "then": {"required": ["k_c"]}},
            {"if": _has_dof("tangential"),
             "then": {"required": ["k_ip"], "properties": {"k_ip": {"not": infinite}}},
             "else": {"properties": {"d_ip": {"const": 0}}}},
        ],
    }  # fmt: skip


def _caliper() -> dict[str, Any]:
    from .components import Caliper

    defaults = _defaults(Caliper)
    extra = {"mass": "", "k_n": " Must be > 0 with a normal DOF.", "d_n": "",
             "k_t": " Must be > 0 with a tangential DOF.", "d_t": ""}  # fmt: skip
    props: dict[str, Any] = {
        "name": {"$ref": "#/$defs/componentName",
                 "description": "Unique component name (ASCII letters, digits, '_'), referenced by the mount key "
                                "of pads."},
        "dofs": {"type": "array", "minItems": 1, "uniqueItems": True, "default": list(defaults["dofs"]),
                 "items": {"enum": ["normal", "tangential"]},
                 "description": "Translations of the caliper that are DOFs: 'normal' (along z0, coordinate "
                                "wc_<name>) and/or 'tangential' (along x0, coordinate uc_<name>) [m]. Non-empty; "
                                "default both."},
    }  # fmt: skip
    props |= {f: _value(f"caliper.{f}", "the caliper", text, defaults[f]) for f, text in extra.items()}

    def positive_with(dof: str, key: str) -> dict[str, Any]:
        return {"if": {"anyOf": [{"not": {"required": ["dofs"]}}, _has_dof(dof)]},
                "then": {"properties": {key: {"not": {"const": 0}}}}}  # fmt: skip

    return {
        "title": "Caliper", "type": "object", "additionalProperties": False, "required": ["name"],
        "description": "A rigid caliper (mounting) mass on springs to ground, coupling the supports of the pads "
                       "mounted on it (one [[calipers]] table per caliper).",
        "properties": {f.name: props[f.name] for f in dataclasses.fields(Caliper)},
        "allOf": [positive_with("normal", "k_n"), positive_with("tangential", "k_t")],
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
        The JSON Schema (draft 2020-12): component fields from the
        :class:`~brakesqueal.model.components.Disk`,
        :class:`~brakesqueal.model.components.Pad` and
        :class:`~brakesqueal.model.components.Caliper` dataclasses, units
        and ranges from :data:`brakesqueal.model.roles.ROLES`, friction laws
        from :data:`brakesqueal.model.friction.LAWS`.
    """
    from .components import MAX_PADS
    from .expressions import RESERVED_NAMES

    reserved = sorted(RESERVED_NAMES)
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
            "disk": {"$ref": "#/$defs/disk",
                     "description": "The disk ([disk] table; optional, every key has a default)."},
            "pads": {"type": "array", "minItems": 1, "maxItems": MAX_PADS, "items": {"$ref": "#/$defs/pad"},
                     "description": f"The pads ([[pads]] tables): at least 1, at most {MAX_PADS}."},
            "calipers": {"type": "array", "items": {"$ref": "#/$defs/caliper"}, "default": [],
                         "description": "Optional caliper masses ([[calipers]] tables)."},
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
            "disk": _disk(), "pad": _pad(), "friction": _friction(), "caliper": _caliper(), "preset": _preset(),
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
