"""A component field or kind is defined once, in ``model/components.py``; roles, TOML files, schema and physics follow.

Each test defines, inside the test, what a developer would add to ``components.py`` — a field made with
:func:`~brakesqueal.model.components.param` on ``Pad`` (here on a subclass, registered in place of ``Pad``), or a
new kind of component with its :class:`~brakesqueal.model.components.Kind` entry — and checks that
:mod:`.roles` (ranges, units, descriptions, validation messages), :mod:`.io` (TOML read and write) and
:mod:`.schema` pick it up with no change to those modules.  A new kind with physics (a tilt spring and damper
on the disk, written as hooks only) reaches the assembled equations, the linearization and the energy with no
change to :mod:`brakesqueal.symbolic` or the simulation.  The registration is undone by ``monkeypatch``; a
later test checks that nothing of it is left.

The expected texts are written out by hand from the definitions in the tests (unit, description template,
interval), not read back from the code under test; the spring's expected rows, stiffness, damping and energy
are its closed forms written out by hand (below).
"""

from __future__ import annotations

import copy
import dataclasses
import math
import tomllib
from typing import Any

import pytest

import numpy as np
import symengine as se

from brakesqueal import linearize
from brakesqueal.errors import ParameterError
from brakesqueal.model import io as model_io
from brakesqueal.model.components import COMPONENTS, Kind, ModelSpec, Pad, Value, attribute, param
from brakesqueal.model.library import get_preset
from brakesqueal.model.parameters import Parameters
from brakesqueal.symbolic.assemble import ENERGY_TERMS, build_equations, energy_terms
from brakesqueal.model.io import model_to_toml, spec_from_dict, spec_to_dict
from brakesqueal.model.library import get_model
from brakesqueal.model.roles import ROLES, parameter_roles, problems
from brakesqueal.model.schema import build_schema

jsonschema = pytest.importorskip("jsonschema")


@dataclasses.dataclass(frozen=True)
class WornPad(Pad):
    """``Pad`` with one more parameter-valued field, as if it had been added to ``Pad``."""

    wear: Value = param("wear", "m", "wear depth of {owner}", (0.0, math.inf, False, True), " Test-only field.")


@dataclasses.dataclass(frozen=True)
class Damper:
    """A new kind of component: a named damper with one coefficient."""

    name: str = attribute({"$ref": "#/$defs/componentName", "description": "Damper name."})
    c: Value = param("c_damp", "N s/m", "damping of {owner}", (0.0, math.inf, True, True))

    def validate(self) -> None:
        from brakesqueal.model.components import _check_fields

        _check_fields(self, f"damper '{self.name}'")


@dataclasses.dataclass(frozen=True)
class SpecWithDampers(ModelSpec):
    """What adding the kind's field to ``ModelSpec`` would give."""

    dampers: tuple[Damper, ...] = ()


@dataclasses.dataclass(frozen=True)
class TiltSpring:
    """A new kind with physics: a rotational spring and damper between the tilting disk and ground.

    Written as a developer would write it in ``components.py``: fields by ``param``/``attribute`` and the physics
    hooks (no computer algebra imported; ``ctx.sm`` is the backend).  Its moment on the disk about O is
    ``-x0 (k_s q1 + d_s q1dot) - y1 (k_s q2 + d_s q2dot)`` (as the supports of eq. 38), its potential
    ``k_s (q1^2 + q2^2) / 2``.
    """

    name: str = attribute({"$ref": "#/$defs/componentName", "description": "Spring name."})
    k_s: Value = param("k_s", "N m/rad", "tilt stiffness of {owner}", (0.0, math.inf, False, True))
    d_s: Value = param("d_s", "N m s/rad", "tilt damping of {owner}", (0.0, math.inf, False, True))

    def validate(self) -> None:
        from brakesqueal.model.components import _check_fields

        _check_fields(self, f"tilt spring '{self.name}'")

    def assemble(self, ctx: Any) -> None:
        kin, Q, dQ, v = ctx.kinematics, ctx.Q, ctx.dQ, ctx.val
        x0, y1 = kin.A1[:, 0], kin.A1[:, 1]
        ctx.moment = ctx.moment - x0 * (v(self.k_s) * Q["q1"] + v(self.d_s) * dQ["q1"]) \
            - y1 * (v(self.k_s) * Q["q2"] + v(self.d_s) * dQ["q2"])

    def energy(self, ctx: Any) -> dict[str, Any]:
        return {"V_support": ctx.sm.Rational(1, 2) * ctx.val(self.k_s) * (ctx.Q["q1"] ** 2 + ctx.Q["q2"] ** 2)}


@dataclasses.dataclass(frozen=True)
class SpecWithTiltSprings(ModelSpec):
    """What adding the kind's field to ``ModelSpec`` would give."""

    tilt_springs: tuple[TiltSpring, ...] = ()


# built before any registration: the paper's pads are plain Pads
_PAPER = spec_to_dict(get_model("paper"), presets=False)
# the paper's Fig. 2 values (symmetric model: the silent motion is q = 0), resolved before any registration
_FIG2 = get_preset("paper-fig2").resolve().as_dict()


def _paper() -> dict[str, Any]:
    return copy.deepcopy(_PAPER)


@pytest.fixture
def worn(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(COMPONENTS, "pad", dataclasses.replace(COMPONENTS["pad"], cls=WornPad))


@pytest.fixture
def dampers(monkeypatch: pytest.MonkeyPatch) -> None:
    kind = Kind(Damper, "damper", "dampers", True, lambda d: f"damper '{d.name}'", "this damper",
                "Optional dampers ([[dampers]] tables).", "A test-only damper.")
    monkeypatch.setitem(COMPONENTS, "damper", kind)
    monkeypatch.setattr(model_io, "ModelSpec", SpecWithDampers)  # stands for the new field of ModelSpec


def test_a_new_field_has_its_role_and_is_validated(worn: None) -> None:
    data = _paper()
    data["pads"][0]["wear"] = "w1"
    data["pads"][1]["wear"] = 0.001
    data["parameters"]["w1"] = 0.002
    spec = spec_from_dict(data)
    assert type(spec.pads[0]) is WornPad and spec.pads[1].wear == 0.001
    assert "w1" in spec.parameter_names()
    assert spec.unit("w1") == "m"
    assert spec.describe_parameter("w1") == "wear depth of pad '1' (upper face)"
    assert spec.roles().interval("w1") == "[0, inf)"
    role = ROLES["pad.wear"]
    assert (role.unit, role.low, role.low_open, role.allows_inf) == ("m", 0.0, False, False)
    # literal 0.001 of pad 2 is a fixed value with the same role
    assert [(r.key, owner, v) for r, owner, v in parameter_roles(spec).fixed if r.key == "pad.wear"] == [
        ("pad.wear", "pad '2' (lower face)", 0.001)]
    values = dict(spec.parameters, w1=-0.5)
    msgs = [m for n, m in problems(spec.roles(), values) if n == "w1"]
    assert msgs == ["The parameter 'w1' (wear depth of pad '1' (upper face)) must be in [0, inf) m; got -0.5"]
    # bad literals and bad defaults: one line naming the component, the field and the range
    bad = _paper()
    bad["pads"][1]["wear"] = -1.0
    with pytest.raises(ParameterError, match=r"pad '2' \(lower face\): wear \(wear depth of pad '2' \(lower face\)\) "
                                             r"must be in \[0, inf\) m; got -1\.0"):
        spec_from_dict(bad)
    bad["pads"][1]["wear"] = "inf"  # read as +inf, which the role does not allow
    with pytest.raises(ParameterError, match=r"pad '2': wear must be finite; got inf"):
        spec_from_dict(bad)
    bad["pads"][1]["wear"] = "w2"  # a name without a default value
    with pytest.raises(ParameterError, match=r"no default value for parameter\(s\) w2"):
        spec_from_dict(bad)


def test_a_new_field_round_trips_through_toml_and_the_schema(worn: None) -> None:
    data = _paper()
    data["pads"][0]["wear"] = "w1"
    data["pads"][1]["wear"] = 0.001
    data["parameters"]["w1"] = 0.002
    spec = spec_from_dict(data)
    written = spec_to_dict(spec)
    assert written["pads"][0]["wear"] == "w1" and written["pads"][1]["wear"] == 0.001
    text = model_to_toml(spec)
    assert 'wear = "w1"' in text and "wear = 0.001" in text
    doc = tomllib.loads(text)
    assert spec_from_dict(doc) == spec
    s = build_schema()
    prop = s["$defs"]["pad"]["properties"]["wear"]
    assert prop["description"] == ("[m] wear depth of this pad. A number in [0, inf) (magnitude at most 1e+100) or "
                                   "the name of a parameter of [parameters]. Test-only field.")
    assert prop["default"] == "wear" and prop["anyOf"][0] == {"type": "number", "minimum": 0.0, "maximum": 1e100}
    assert list(s["$defs"]["pad"]["properties"])[-1] == "wear"
    validator = jsonschema.Draft202012Validator(s)
    assert not list(validator.iter_errors(doc))
    doc["pads"][0]["wear"] = -1.0
    assert [e.path[-1] for e in validator.iter_errors(doc)] == ["wear"]


def test_a_new_kind_reaches_roles_toml_and_the_schema(dampers: None) -> None:
    data = _paper()
    data["dampers"] = [{"name": "damper1", "c": "c1"}, {"name": "damper2", "c": 3.0}]
    data["parameters"]["c1"] = 2.0
    spec = spec_from_dict(data)
    assert spec.dampers == (Damper("damper1", "c1"), Damper("damper2", 3.0))  # type: ignore[attr-defined]
    assert spec.parameter_names()[-1] == "c1"
    assert spec.unit("c1") == "N s/m" and spec.describe_parameter("c1") == "damping of damper 'damper1'"
    assert ROLES["damper.c"].interval() == "(0, inf)"
    text = model_to_toml(spec)
    assert '[[dampers]]\nname = "damper1"\nc = "c1"' in text
    doc = tomllib.loads(text)
    assert spec_from_dict(doc) == spec
    # validation through the role; names unique across every kind of component
    bad = _paper() | {"dampers": [{"name": "d", "c": 0.0}]}
    with pytest.raises(ParameterError, match=r"damper 'd': c \(damping of damper 'd'\) must be in \(0, inf\) N s/m"):
        spec_from_dict(bad)
    bad["dampers"] = [{"name": "1", "c": 1.0}]  # the paper's upper pad is named '1'
    with pytest.raises(ParameterError, match=r"duplicate component name '1'"):
        spec_from_dict(bad)
    bad["dampers"] = [{"c": 1.0}]
    with pytest.raises(ParameterError, match=r"dampers\[0\]: a damper needs 'name'"):
        spec_from_dict(bad)
    bad["dampers"] = [{"name": "d", "k": 1.0}]
    with pytest.raises(ParameterError, match=r"dampers\[0\] \('d'\): unknown key 'k'.*valid keys: name, c"):
        spec_from_dict(bad)
    s = build_schema()
    assert s["properties"]["dampers"] == {"type": "array", "items": {"$ref": "#/$defs/damper"}, "default": [],
                                          "description": "Optional dampers ([[dampers]] tables)."}
    d = s["$defs"]["damper"]
    assert (d["title"], d["required"], list(d["properties"])) == ("Damper", ["name"], ["name", "c"])
    assert d["properties"]["c"]["anyOf"][0] == {"type": "number", "exclusiveMinimum": 0.0, "maximum": 1e100}
    validator = jsonschema.Draft202012Validator(s)
    assert not list(validator.iter_errors(doc))
    doc["dampers"][1]["c"] = 0.0
    assert [list(e.path) for e in validator.iter_errors(doc)] == [["dampers", 1, "c"]]


@pytest.fixture
def tilt_springs(monkeypatch: pytest.MonkeyPatch) -> None:
    kind = Kind(TiltSpring, "tilt_spring", "tilt_springs", True, lambda t: f"tilt spring '{t.name}'",
                "this tilt spring", "Optional tilt springs ([[tilt_springs]] tables).", "A test-only tilt spring.")
    monkeypatch.setitem(COMPONENTS, "tilt_spring", kind)
    monkeypatch.setattr(model_io, "ModelSpec", SpecWithTiltSprings)


@pytest.mark.slow
def test_a_new_kind_with_physics_reaches_the_equations_the_linearization_and_the_energy(
        tilt_springs: None) -> None:
    """A kind written with hooks only (``TiltSpring``) changes the rows, ``K``, ``D`` and the energy as its closed
    form says: rows ``+ (k_s q1 + d_s q1dot)`` and ``+ cos(q1) (k_s q2 + d_s q2dot)`` (the moment's ``x0``, ``y0``
    components, ``y1 = (0, cos q1, sin q1)``), hence ``K + k_s I``, ``D + d_s I`` at the trivial silent motion
    (``q = 0``), and ``V_support + k_s (q1^2 + q2^2) / 2``."""
    k_s, d_s = 3.0e4, 2.5
    data = _paper()
    data["parameters"].update(k_s=k_s, d_s=d_s)
    data["tilt_springs"] = [{"name": "tilt", "k_s": "k_s", "d_s": "d_s"}]
    spec = spec_from_dict(data)
    assert spec.unit("k_s") == "N m/rad" and spec.describe_parameter("d_s") == "tilt damping of tilt spring 'tilt'"
    assert spec_from_dict(tomllib.loads(model_to_toml(spec))) == spec
    bare = spec_from_dict(_paper())  # the same model without the spring
    assert bare.tilt_springs == ()  # type: ignore[attr-defined]

    q1, q2, dq1, dq2, ks, ds = (se.Symbol(n) for n in ("q1", "q2", "dq1", "dq2", "k_s", "d_s"))
    expected_rows = [ks * q1 + ds * dq1, se.cos(q1) * (ks * q2 + ds * dq2)]
    for kronecker in (True, False):
        eq, eq0 = build_equations(spec, kronecker=kronecker), build_equations(bare, kronecker=kronecker)
        assert eq.coords == eq0.coords == ("q1", "q2")
        for i in range(2):
            assert se.expand(eq.R[i] - eq0.R[i] - expected_rows[i]) == 0
    terms, terms0 = energy_terms(eq), energy_terms(eq0)
    for k in ENERGY_TERMS:
        extra = ks * (q1**2 + q2**2) / 2 if k == "V_support" else 0
        assert se.expand(terms[k] - terms0[k] - extra) == 0, k

    lm = linearize(Parameters(spec, {**_FIG2, "k_s": k_s, "d_s": d_s}))
    lm0 = linearize(Parameters(bare, _FIG2))
    assert lm.silent.trivial and lm0.silent.trivial
    np.testing.assert_allclose(lm.M, lm0.M, rtol=1e-12, atol=0.0)
    scale = np.abs(lm0.K).max()
    np.testing.assert_allclose(lm.K - lm0.K, k_s * np.eye(2), rtol=0.0, atol=1e-12 * scale)
    np.testing.assert_allclose(lm.D - lm0.D, d_s * np.eye(2), rtol=0.0, atol=1e-12 * max(np.abs(lm0.D).max(), d_s))
    assert k_s > 1e6 * 1e-12 * scale and d_s > 1e-6 * np.abs(lm0.D).max()  # the shifts are far above the tolerance


def test_registrations_are_undone() -> None:
    assert list(COMPONENTS) == ["disk", "pad", "caliper"] and COMPONENTS["pad"].cls is Pad
    assert "pad.wear" not in ROLES and "damper.c" not in ROLES and "tilt_spring.k_s" not in ROLES
    s = build_schema()
    assert "wear" not in s["$defs"]["pad"]["properties"] and "dampers" not in s["properties"]
    assert model_io.ModelSpec is ModelSpec


def test_choice_and_list_fields_are_checked_by_their_schema_fragment() -> None:
    """Names, choices and lists are validated from the fragment the schema shows (one definition for both)."""
    from brakesqueal.model.components import Caliper

    # a repeated caliper DOF would give two coordinates of the same name; the schema says uniqueItems
    with pytest.raises(ParameterError, match=r"caliper 'c': dofs must be a non-empty list of distinct entries of "
                                             r"'normal', 'tangential'; got \['normal', 'normal'\]"):
        Caliper("c", dofs=("normal", "normal")).validate()
    with pytest.raises(ParameterError, match=r"caliper 'c': dofs must be a non-empty list"):
        Caliper("c", dofs=()).validate()
    with pytest.raises(ParameterError, match=r"pad 'p': face must be 'upper' or 'lower'; got 'side'"):
        Pad("p", "side").validate()  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match=r"pad 'p': mount 'a b': a component name must be letters"):
        Pad("p", "upper", mount="a b").validate()
    Caliper("c", dofs=("tangential",)).validate()  # a valid one passes
    bad = _paper()
    bad["calipers"] = [{"name": "c", "dofs": ["normal", "normal"]}]
    with pytest.raises(ParameterError, match=r"model: caliper 'c': dofs must be .*distinct"):
        spec_from_dict(bad)
    s = build_schema()
    validator = jsonschema.Draft202012Validator(s)
    assert list(validator.iter_errors(bad))  # the schema refuses the same file
