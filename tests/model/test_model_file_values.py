"""Every numeric field of a model file refuses every bad value in one line naming the key (issue 11).

Looped over every component field of a model with pads of mass, a caliper and
every friction law's fields, and every default value in ``[parameters]``:
a value outside the field's range (both sides), beyond the magnitude bound,
NaN, infinities, a string that is not a name, a boolean, an array, a table.
Required: exit status 2, exactly one line that names the field (and the
component), and, for a number outside the range, the allowed range.
"""

from __future__ import annotations

import math
import re

import pytest

from brakesqueal.cli import main
from brakesqueal.model import get_model, model_to_toml
from brakesqueal.model.roles import MAX_MAGNITUDE, ROLES

SECTIONS = {"disk": ("Theta", "Phi", "k_t", "d_t", "h_upper", "h_lower", "Omega", "radius"),
            "pads": ("angle_deg", "radius", "k", "d", "preload", "k_ip", "d_ip", "mass", "k_c", "d_c"),
            "calipers": ("mass", "k_n", "d_n", "k_t", "d_t")}
FRICTION = {"coulomb": ("mu",), "linear": ("mu", "slope"), "stribeck": ("mu", "mu_s", "v_s")}
NOT_NUMBERS = ['"abc def"', '""', "true", "[1.0]", "{ a = 1.0 }"]


def _toml(v: float) -> str:
    if math.isnan(v):
        return "nan"
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return repr(v)


def _numbers(key: str) -> list[float]:
    """Numbers outside the role's range (both sides), beyond the magnitude bound, NaN, infinities."""
    if key == "pad.angle_deg":
        return [math.nan, math.inf, -math.inf]
    r = ROLES[key]
    out = [math.nan, -math.inf, 1e300, -1e300]
    if not r.allows_inf:
        out.append(math.inf)
    if math.isfinite(r.low):
        out += [r.low - 1.0] + ([r.low] if r.low_open else [])
    if math.isfinite(r.high):
        out += [r.high + 1.0] + ([r.high] if r.high_open else [])
    return out


def _cases() -> list[tuple[str, str, str]]:
    cases = []
    for section, fields in SECTIONS.items():
        kind = {"disk": "disk", "pads": "pad", "calipers": "caliper"}[section]
        for f in fields:
            for v in _numbers(f"{kind}.{f}"):
                cases.append((section, f, _toml(v)))
            cases += [(section, f, t) for t in NOT_NUMBERS]
    for law, fields in FRICTION.items():
        for f in fields:
            for v in _numbers(f"friction.{f}"):
                cases.append((f"friction:{law}", f, _toml(v)))
            cases += [(f"friction:{law}", f, t) for t in NOT_NUMBERS]
    cases += [("disk", "h_upper", "-0.02"), ("disk", "h_lower", "-0.03")]  # thickness h_upper + h_lower <= 0
    return cases


def _edit(text: str, section: str, field: str, value: str) -> str:
    """Set ``field`` of the first table of ``section`` to the literal ``value``."""
    lines = text.splitlines()
    if section.startswith("friction:"):
        law = section.split(":")[1]
        base = {"coulomb": {}, "linear": {"slope": "-1e-4"}, "stribeck": {"mu_s": "0.6", "v_s": "0.5"}}[law]
        fr = {"law": f'"{law}"', "mu": '"mu1"', **base, field: value}
        i = next(i for i, ln in enumerate(lines) if ln.startswith("friction = "))
        lines[i] = "friction = { " + ", ".join(f"{k} = {v}" for k, v in fr.items()) + " }"
        return "\n".join(lines) + "\n"
    head = {"disk": "[disk]", "pads": "[[pads]]", "calipers": "[[calipers]]"}[section]
    start = lines.index(head)
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("[")), len(lines))
    body = [ln for ln in lines[start + 1:end] if not ln.startswith(f"{field} = ")]
    lines[start + 1:end] = [f"{field} = {value}", *body]
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module")
def base_text() -> str:
    return model_to_toml(get_model("eight-dof"))


def _run(capsys, path) -> tuple[int, list[str]]:
    rc = main(["show", str(path)])
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    return rc, err


@pytest.mark.parametrize("section,field,value", _cases())
def test_a_bad_literal_field_is_one_line_naming_the_key(tmp_path, capsys, base_text, section, field, value):
    path = tmp_path / "m.toml"
    path.write_text(_edit(base_text, section, field, value))
    rc, err = _run(capsys, path)
    assert rc == 2 and len(err) == 1, err
    line = err[0]
    assert re.search(rf"\b{re.escape(field)}\b", line), line  # names the field
    if section == "pads":
        assert "pad" in line, line
    if section == "calipers":
        assert "caliper" in line, line
    if section.startswith("friction"):
        assert "pad" in line, line
    try:
        number = float(value)
    except ValueError:
        return
    if math.isfinite(number) and abs(number) <= MAX_MAGNITUDE and field != "angle_deg":
        assert re.search(r"[\[(][^\])]*, [^\])]*[\])]", line), line  # the allowed range, e.g. (0, inf)


def _parameter_cases() -> list[tuple[str, str]]:
    spec = get_model("eight-dof")
    roles = spec.roles()
    cases = []
    for name in spec.parameters:
        low, high, lo_open, hi_open = roles._bounds(name)
        vals = ["nan", "-inf", "1e300", '"abc def"', "true", "[1.0]"]
        if math.isfinite(low):
            vals.append(repr(low - 1.0))
        if not roles.allows_inf(name):
            vals.append("inf")
        cases += [(name, v) for v in vals]
    return cases + [("h10", "-0.02")]


@pytest.mark.parametrize("name,value", _parameter_cases())
def test_a_bad_parameter_value_is_one_line_naming_it(tmp_path, capsys, base_text, name, value):
    lines = [f"{name} = {value}" if ln.startswith(f"{name} = ") else ln for ln in base_text.splitlines()]
    path = tmp_path / "m.toml"
    path.write_text("\n".join(lines) + "\n")
    rc, err = _run(capsys, path)
    assert rc == 2 and len(err) == 1, err
    assert re.search(rf"\b{re.escape(name)}\b", err[0]), err
