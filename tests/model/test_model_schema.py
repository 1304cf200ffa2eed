"""The JSON Schema of model files agrees with the reader (``spec_from_dict``) and ships with the package.

* every built-in model, written by ``model_to_toml`` and parsed with
  ``tomllib``, is valid under the schema;
* hand-made bad model files that the reader rejects with a
  :class:`~brakesqueal.errors.ParameterError` are rejected by the schema too;
* the shipped file equals ``build_schema()``, and its component fields,
  friction laws, units and ranges are those of the package's own tables
  (components, friction laws, roles), so the schema cannot drift silently
  from the code;
* the complete example of ``docs/model-format.md`` loads and validates;
* the file is installed (``schema_path().exists()``).
"""

from __future__ import annotations

import copy
import dataclasses
import math
import pathlib
import re
import tomllib
from collections.abc import Callable
from typing import Any

import pytest

from brakesqueal.errors import ParameterError
from brakesqueal.model import MODELS, get_model, load_model, model_to_toml, spec_from_dict
from brakesqueal.model.components import Caliper, Disk, Pad
from brakesqueal.model.friction import LAWS
from brakesqueal.model.roles import ROLES
from brakesqueal.model.schema import build_schema, schema, schema_path

jsonschema = pytest.importorskip("jsonschema")


@pytest.fixture(scope="module")
def validator() -> Any:
    s = schema()
    jsonschema.Draft202012Validator.check_schema(s)
    return jsonschema.Draft202012Validator(s)


def _doc(name: str) -> dict[str, Any]:
    return tomllib.loads(model_to_toml(get_model(name)))


# ------------------------------------------------------------------ (c) shipped
def test_schema_file_ships() -> None:
    path = schema_path()
    assert path.exists() and path.name == "model.schema.json"
    s = schema()
    assert s["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert s["$id"] == "https://brakesqueal.invalid/model.schema.json" and s["title"]
    assert schema() is not s  # a fresh copy


# ------------------------------------------------------------------ (a) built-in models validate
@pytest.mark.parametrize("name", list(MODELS))
def test_builtin_model_files_validate(name: str, validator: Any) -> None:
    doc = _doc(name)
    errors = sorted(validator.iter_errors(doc), key=lambda e: list(e.path))
    assert not errors, "; ".join(f"{'/'.join(map(str, e.path))}: {e.message}" for e in errors)
    spec_from_dict(doc)  # and the reader accepts it (round trip)


def test_small_valid_files(validator: Any) -> None:
    """A minimal file and a file using every optional feature are valid for both."""
    minimal = {"pads": [{"name": "1", "face": "upper", "radius": 0.1, "k": 1e6, "d": 1.0, "preload": 100.0,
                         "friction": {"mu": 0.4}}],
               "disk": {"Theta": 0.1, "Phi": 0.2, "k_t": 1e6, "d_t": 0.1, "h_upper": 0.01, "h_lower": 0.01,
                        "Omega": 10.0}}
    doc = _doc("eight-dof")
    doc["pads"][0]["friction"] = {"law": "stribeck", "mu": "mu1", "mu_s": 0.7, "v_s": 0.05}
    doc["pads"][1]["friction"] = {"law": "linear", "mu": "mu2", "slope": -0.01}
    doc["pads"][1]["k_ip"] = "k_ip2"
    doc["presets"] = {"sym": {"description": "mu1 = mu2", "free": {"mu": 0.5},
                              "fixed": {n: v for n, v in doc["parameters"].items() if n not in ("mu1", "mu2")},
                              "tied": {"mu1": "mu", "mu2": "mu"}, "auxiliary": {"mu": "both contacts"}}}
    for d in (minimal, doc):
        assert not list(validator.iter_errors(d))
        assert len(spec_from_dict(d).pads) == len(d["pads"])


DOC = pathlib.Path(__file__).resolve().parents[2] / "docs" / "model-format.md"


@pytest.mark.skipif(not DOC.exists(), reason="documentation not available")
def test_documented_example_loads_and_validates(validator: Any, tmp_path: pathlib.Path) -> None:
    """The complete example of docs/model-format.md (its first toml block) is a valid model."""
    block = re.search(r"^```toml\n(.*?)^```$", DOC.read_text(encoding="utf-8"), re.S | re.M)
    assert block is not None
    path = tmp_path / "caliper-stribeck.toml"
    path.write_text(block.group(1), encoding="utf-8")
    spec = load_model(str(path))
    assert len(spec.pads) == 2 and len(spec.calipers) == 1
    assert {p.friction.law for p in spec.pads} == {"stribeck"}
    assert spec.preset_names() == ["caliper-stribeck", "stribeck-drop"]
    assert spec.get_preset("stribeck-drop").resolve({"mu": 0.5})["mu_s"] == pytest.approx(0.65)
    validator.validate(tomllib.loads(block.group(1)))


# ------------------------------------------------------------------ (b) bad files: reader and schema agree
def _set(path: str, value: Any) -> Callable[[dict[str, Any]], None]:
    def edit(d: dict[str, Any]) -> None:
        *head, last = path.split(".")
        node: Any = d
        for key in head:
            node = node[int(key)] if isinstance(node, list) else node[key]
        if isinstance(node, list):
            node[int(last)] = value
        else:
            node[last] = value
    return edit


def _drop(path: str) -> Callable[[dict[str, Any]], None]:
    def edit(d: dict[str, Any]) -> None:
        *head, last = path.split(".")
        node: Any = d
        for key in head:
            node = node[int(key)] if isinstance(node, list) else node[key]
        del node[last]
    return edit


def _both(*edits: Callable[[dict[str, Any]], None]) -> Callable[[dict[str, Any]], None]:
    def edit(d: dict[str, Any]) -> None:
        for e in edits:
            e(d)
    return edit


_CALIPER = {"name": "c", "mass": 1.0, "k_n": 1e6, "k_t": 1e6}

#: (case, where, model, edit): each edit makes a file the reader rejects; the schema must report an error
#: at ``where`` (a JSON path, "/"-separated) or below it.
BAD: list[tuple[str, str, str, Callable[[dict[str, Any]], None]]] = [
    ("unknown top-level key", "", "paper", _set("Omgea", 1.0)),
    ("unknown disk key", "disk", "paper", _set("disk.omega", "Omega")),
    ("unknown pad key", "pads/0", "paper", _set("pads.0.stiffness", 1e6)),
    ("unknown caliper key", "calipers/0", "eight-dof", _set("calipers.0.k", 1e6)),
    ("unknown preset key", "presets/general", "paper", _set("presets.general.values", {})),
    ("unknown friction law", "pads/0/friction", "paper", _set("pads.0.friction.law", "viscous")),
    ("friction law not a string", "pads/0/friction", "paper", _set("pads.0.friction.law", 3)),
    ("field of another law", "pads/0/friction", "paper", _set("pads.0.friction.slope", 0.1)),
    ("stribeck without v_s", "pads/0/friction", "paper",
     _set("pads.0.friction", {"law": "stribeck", "mu": "mu1", "mu_s": 0.6})),
    ("linear without slope", "pads/0/friction", "belt", _drop("pads.0.friction.slope")),
    ("friction not a table", "pads/0/friction", "paper", _set("pads.0.friction", "coulomb")),
    ("pad without name", "pads/0", "paper", _drop("pads.0.name")),
    ("pad without face", "pads/1", "paper", _drop("pads.1.face")),
    ("no pads", "", "paper", _drop("pads")),
    ("empty pads", "pads", "paper", _set("pads", [])),
    ("pads not a list", "pads", "paper", _set("pads", {"name": "1", "face": "upper"})),
    ("pad not a table", "pads/0", "paper", _set("pads.0", "upper")),
    ("caliper without name", "calipers/0", "eight-dof", _drop("calipers.0.name")),
    ("calipers not a list", "calipers", "eight-dof", _set("calipers", {"name": "caliper"})),
    ("unknown face", "pads/0/face", "paper", _set("pads.0.face", "top")),
    ("unknown pad DOF", "pads/0/dofs", "six-dof", _set("pads.0.dofs", ["normal", "axial"])),
    ("duplicate pad DOF", "pads/0/dofs", "six-dof", _set("pads.0.dofs", ["normal", "normal"])),
    ("dofs not a list", "pads/0/dofs", "six-dof", _set("pads.0.dofs", "normal")),
    ("unknown caliper DOF", "calipers/0/dofs", "eight-dof", _set("calipers.0.dofs", ["vertical"])),
    ("caliper without DOFs", "calipers/0/dofs", "eight-dof", _set("calipers.0.dofs", [])),
    ("name not a string", "name", "paper", _set("name", 3)),
    ("description not a string", "description", "paper", _set("description", ["a"])),
    ("pad name not a string", "pads/0/name", "paper", _set("pads.0.name", 1)),
    ("pad name with a space", "pads/0/name", "paper", _set("pads.0.name", "pad 1")),
    ("stiffness is a boolean", "pads/0/k", "paper", _set("pads.0.k", True)),
    ("stiffness is a list", "pads/0/k", "paper", _set("pads.0.k", [1e6])),
    ("value neither number nor name", "pads/0/k", "paper", _set("pads.0.k", "6e6 N/m")),
    ("angle given as a name", "pads/0/angle_deg", "paper", _set("pads.0.angle_deg", "theta")),
    ("angle infinite", "pads/0/angle_deg", "paper", _set("pads.0.angle_deg", "inf")),
    ("tilting not a boolean (0: no DOF left)", "disk/tilting", "paper", _set("disk.tilting", 0)),
    ("negative literal stiffness", "pads/0/k", "paper", _set("pads.0.k", -1.0)),
    ("zero literal preload", "pads/0/preload", "paper", _set("pads.0.preload", 0)),
    ("zero literal spin", "disk/Omega", "paper", _set("disk.Omega", 0.0)),
    ("literal beyond 1e100", "pads/0/k", "paper", _set("pads.0.k", 1e200)),
    ("inf where not allowed", "pads/0/k", "paper", _set("pads.0.k", "inf")),
    ("TOML inf where not allowed", "disk/Theta", "paper", _set("disk.Theta", math.inf)),
    ("TOML -inf for a length", "disk/h_upper", "paper", _set("disk.h_upper", -math.inf)),
    ("negative friction coefficient", "pads/0/friction", "paper", _set("pads.0.friction.mu", -0.1)),
    ("infinite friction coefficient", "pads/0/friction", "paper", _set("pads.0.friction.mu", "inf")),
    ("non-positive Stribeck speed", "pads/0/friction", "paper",
     _set("pads.0.friction", {"law": "stribeck", "mu": "mu1", "mu_s": 0.6, "v_s": 0.0})),
    ("parameter value boolean", "parameters/mu1", "paper", _set("parameters.mu1", True)),
    ("parameter value table", "parameters/mu1", "paper", _set("parameters.mu1", {"value": 0.5})),
    ("parameters not a table", "parameters", "paper", _set("parameters", [1.0])),
    ("disk not a table", "disk", "paper", _set("disk", "rigid")),
    ("presets not a table", "presets", "paper", _set("presets", ["general"])),
    ("preset not a table", "presets/general", "paper", _set("presets.general", 1)),
    ("preset free value boolean", "presets/general/free/mu1", "paper", _set("presets.general.free.mu1", False)),
    ("preset tied value a number", "presets/paper-fig2/tied/N0", "paper", _set("presets.paper-fig2.tied.N0", 3600.0)),
    ("preset free not a table", "presets/general/free", "paper", _set("presets.general.free", [1])),
    ("preset uses a reserved name", "presets/paper-fig2/fixed", "paper", _set("presets.paper-fig2.fixed.pi", 3.0)),
    ("mass without DOF", "pads/0", "paper", _set("pads.0.mass", 0.5)),
    ("DOF without mass", "pads/0", "six-dof", _drop("pads.0.mass")),
    ("normal DOF without contact stiffness", "pads/0", "six-dof", _drop("pads.0.k_c")),
    ("tangential DOF with rigid support", "pads/0/k_ip", "six-dof", _set("pads.0.k_ip", "inf")),
    ("tangential DOF without k_ip (default inf)", "pads/0", "six-dof", _drop("pads.0.k_ip")),
    ("tangential damper beside a rigid support (default k_ip)", "pads/0", "minimal", _set("pads.0.d_ip", 1.0)),
    ("named tangential damper beside a rigid support", "pads/0/k_ip", "paper",
     lambda d: (_set("pads.0.d_ip", "d1")(d), _set("pads.0.k_ip", "inf")(d))),
    ("caliper normal DOF with zero stiffness", "calipers/0/k_n", "eight-dof",
     _set("calipers.0", {**_CALIPER, "dofs": ["normal"], "k_n": 0.0})),
    ("caliper default DOFs with zero stiffness", "calipers/0/k_t", "eight-dof",
     _set("calipers.0", {**_CALIPER, "k_t": 0})),
    ("too many pads", "pads", "four-pad",
     lambda d: d.__setitem__("pads", [{**d["pads"][0], "name": f"p{i}"} for i in range(25)])),
]


def _paths(errors: Any) -> set[str]:
    """JSON paths of every error, including those inside anyOf/oneOf alternatives."""
    out = set()
    for e in errors:
        out.add("/".join(map(str, e.absolute_path)))
        out |= _paths(e.context)
    return out


@pytest.mark.parametrize("case,where,model,edit", BAD, ids=[c for c, *_ in BAD])
def test_bad_files_rejected_by_reader_and_schema(case: str, where: str, model: str,
                                                 edit: Callable[[dict[str, Any]], None], validator: Any) -> None:
    doc = copy.deepcopy(_doc(model))
    edit(doc)
    with pytest.raises(ParameterError):
        spec_from_dict(doc, source="bad model")
    paths = _paths(validator.iter_errors(doc))
    assert paths, f"the schema accepts a file the reader rejects ({case})"
    assert any(p == where or p.startswith(where + "/") or not where for p in paths), (case, sorted(paths))


# ------------------------------------------------------------------ the schema follows the code's tables
def test_shipped_schema_is_up_to_date() -> None:
    assert schema() == build_schema(), (
        "model.schema.json differs from the package's tables: regenerate it with "
        "'python -m brakesqueal.model.schema --write'")


def test_schema_lists_every_component_field() -> None:
    defs = schema()["$defs"]
    for key, cls in (("disk", Disk), ("pad", Pad), ("caliper", Caliper)):
        assert list(defs[key]["properties"]) == [f.name for f in dataclasses.fields(cls)], key
        assert defs[key]["additionalProperties"] is False
    assert schema()["additionalProperties"] is False
    friction = defs["friction"]
    assert friction["properties"]["law"]["enum"] == list(LAWS)
    branches = {b["properties"]["law"]["const"]: b for b in friction["oneOf"]}
    assert list(branches) == list(LAWS)
    for name, law in LAWS.items():
        assert set(branches[name]["properties"]) == {"law", "mu", *law.fields}


def test_schema_units_and_ranges_match_roles() -> None:
    """Every role's unit is in its field's description; literal bounds are the role's interval."""
    defs = schema()["$defs"]
    fields = {("disk", f): defs["disk"]["properties"][f] for f in defs["disk"]["properties"]}
    fields |= {("pad", f): defs["pad"]["properties"][f] for f in defs["pad"]["properties"]}
    fields |= {("caliper", f): defs["caliper"]["properties"][f] for f in defs["caliper"]["properties"]}
    fields |= {("friction", f): defs["friction"]["properties"][f] for f in defs["friction"]["properties"]}
    checked = 0
    for (comp, f), prop in fields.items():
        role = ROLES.get(f"{comp}.{f}")
        assert "description" in prop, (comp, f)
        if role is None:
            continue
        checked += 1
        assert f"[{role.unit or 'dimensionless'}]" in prop["description"], (comp, f)
        assert role.interval() in prop["description"], (comp, f)
        number = prop["anyOf"][0]
        if math.isfinite(role.low):
            assert number["exclusiveMinimum" if role.low_open else "minimum"] == role.low, (comp, f)
        assert any(alt.get("const") == "inf" for alt in prop["anyOf"]) == role.allows_inf, (comp, f)
    assert checked == len(ROLES)
