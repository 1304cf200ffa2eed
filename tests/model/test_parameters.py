"""Parameter sets, presets and files of :mod:`brakesqueal.model` (the paper's model), and the expressions.

Ported from the tests of the former paper-only ``brakesqueal.parameters``
module (now a thin alias of :mod:`brakesqueal.model`): the same behaviour is
checked on the one parameter-set type of the package.
"""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from brakesqueal.errors import ParameterError
from brakesqueal.model.expressions import (
    CONSTANTS,
    FUNCTIONS,
    dependency_order,
    evaluate,
    names_in,
)
from brakesqueal.model import Parameters, Preset, get_model, get_preset, parse_sets
from brakesqueal.model.io import load_parameter_file, parameters_to_toml
from brakesqueal.model.library import PRESETS
from brakesqueal.model.options import resolve_parameters

PAPER = get_model("paper")
PARAMETER_NAMES = tuple(PAPER.parameters)

VALID = {
    "Theta": 0.16, "Phi": 0.32, "k_t": 1.88e7, "d_t": 0.1, "k1": 6e6, "k2": 6e6,
    "d1": 5.0, "d2": 5.0, "k_ip1": 1e8, "k_ip2": 1e8, "mu1": 0.5, "mu2": 0.5,
    "h10": 0.01, "h20": 0.01, "r": 0.13, "N0": 3600.0, "Omega": 16 * math.pi,
}

# name -> (an invalid value, the allowed interval printed in the message)
VIOLATIONS = {
    "Theta": (0.0, "(0, inf)"), "Phi": (-0.32, "(0, inf)"),
    "k_t": (-1.0, "[0, inf)"), "d_t": (-0.1, "[0, inf)"),
    "k1": (-6e6, "[0, inf)"), "k2": (-1e-9, "[0, inf)"),
    "d1": (-5.0, "[0, inf)"), "d2": (-5.0, "[0, inf)"),
    "k_ip1": (0.0, "(0, inf]"), "k_ip2": (-1e8, "(0, inf]"),
    "mu1": (-0.2, "[0, inf)"), "mu2": (-0.2, "[0, inf)"),
    "h10": (math.inf, "(-inf, inf)"), "h20": (-math.inf, "(-inf, inf)"),
    "r": (0.0, "(0, inf)"), "N0": (-3000.0, "(0, inf)"), "Omega": (0.0, "(0, inf)"),
}


def make(**changes: object) -> Parameters:
    """Build the paper model's Parameters from VALID with some values changed."""
    return Parameters(PAPER, {**VALID, **changes})  # type: ignore[dict-item]


def message(excinfo: pytest.ExceptionInfo[ParameterError]) -> str:
    """Return the error message and check that it is one line."""
    text = str(excinfo.value)
    assert "\n" not in text
    return text


def compliances(p: Parameters) -> tuple[float, float]:
    """``1/k_ip1, 1/k_ip2`` from the packed vector (0 for a rigid support)."""
    v = p.vector()
    return float(v[PARAMETER_NAMES.index("k_ip1")]), float(v[PARAMETER_NAMES.index("k_ip2")])


def trivial(p: Parameters) -> bool:
    """Whether the silent motion is the zero state (eq. 49), from the package's silent-motion solver."""
    from brakesqueal import silent_motion

    return silent_motion(p).trivial


# --------------------------------------------------------------------------- bounds


def test_names_units_descriptions() -> None:
    assert len(PARAMETER_NAMES) == 17
    assert PARAMETER_NAMES == ("Theta", "Phi", "k_t", "d_t", "k1", "k2", "d1", "d2", "k_ip1", "k_ip2", "mu1", "mu2",
                               "h10", "h20", "r", "N0", "Omega")
    assert PAPER.unit("Omega") == "rad/s" and PAPER.unit("mu1") == "" and PAPER.unit("k_ip1") == "N/m"
    assert all(PAPER.describe_parameter(name) for name in PARAMETER_NAMES)


def test_parameters_are_immutable_and_complete() -> None:
    params = make()
    with pytest.raises(AttributeError):
        params.mu1 = 0.1  # type: ignore[misc]
    with pytest.raises(ParameterError, match="missing parameter"):
        Parameters(PAPER, {k: v for k, v in VALID.items() if k != "r"})


@pytest.mark.parametrize("name", PARAMETER_NAMES)
def test_bound_violation_message_names_parameter_and_range(name: str) -> None:
    value, interval = VIOLATIONS[name]
    with pytest.raises(ParameterError) as excinfo:
        make(**{name: value})
    text = message(excinfo)
    unit = f" {PAPER.unit(name)}" if PAPER.unit(name) else ""
    assert text.startswith(f"The parameter '{name}' (")
    assert text.endswith(f"must be in {interval}{unit}; got {float(value)!r}")


def test_documented_messages() -> None:
    with pytest.raises(ParameterError) as excinfo:
        make(mu1=-0.2)
    assert message(excinfo).endswith("must be in [0, inf); got -0.2")
    with pytest.raises(ParameterError) as excinfo:
        make(Omega=0)
    text = message(excinfo)
    assert "reverse rotation is not modelled" in text and text.endswith("(0, inf) rad/s; got 0.0")


@pytest.mark.parametrize("name", PARAMETER_NAMES)
def test_nan_is_always_rejected(name: str) -> None:
    with pytest.raises(ParameterError, match=rf"'{name}' must be a number; got nan"):
        make(**{name: math.nan})


@pytest.mark.parametrize("name", PARAMETER_NAMES)
def test_infinity_only_allowed_for_tangential_stiffness(name: str) -> None:
    with pytest.raises(ParameterError, match=f"'{name}'"):
        make(**{name: -math.inf})
    if name in ("k_ip1", "k_ip2"):
        assert getattr(make(**{name: math.inf}), name) == math.inf
        assert getattr(make(**{name: "inf"}), name) == math.inf
    else:
        with pytest.raises(ParameterError, match=rf"'{name}'.*got inf"):
            make(**{name: math.inf})


@pytest.mark.parametrize("bad", [True, None, [0.5], 1j])
def test_non_real_values_are_rejected(bad: object) -> None:
    with pytest.raises(ParameterError) as excinfo:
        make(mu2=bad)
    assert "value of 'mu2' must be a number or an expression string; got" in message(excinfo)


def test_expression_strings_are_values() -> None:
    assert make(mu2="0.5").mu2 == 0.5 and make(Omega="16*pi").Omega == pytest.approx(16 * math.pi)


def test_boundary_values_and_integer_input() -> None:
    params = make(k_t=0, d_t=0, k1=0, k2=0, d1=0, d2=0, mu1=0, mu2=0, h10=-0.005)
    assert params.k_t == 0.0 and type(params.k_t) is float
    assert params.h10 + params.h20 == pytest.approx(0.005)


@pytest.mark.parametrize(("h10", "h20"), [(0.0, 0.0), (-0.01, 0.01), (-0.03, 0.02)])
def test_thickness_must_be_positive_and_message_names_both(h10: float, h20: float) -> None:
    with pytest.raises(ParameterError) as excinfo:
        make(h10=h10, h20=h20)
    text = message(excinfo)
    assert "'h10'" in text and "'h20'" in text and "h10 + h20 > 0" in text


def test_magnitudes_are_bounded() -> None:
    with pytest.raises(ParameterError, match="'k_t'.*magnitude of at most 1e\\+100"):
        make(k_t=1e200)


def test_all_violations_are_reported_at_once() -> None:
    with pytest.raises(ParameterError) as excinfo:
        make(Theta=-1.0, mu2=-0.1, r=0.0)
    text = message(excinfo)
    assert all(f"'{name}'" in text for name in ("Theta", "mu2", "r"))


# -------------------------------------------------------------------------- methods


def test_as_dict_is_ordered_and_replace_validates() -> None:
    params = make()
    assert list(params.as_dict()) == list(PARAMETER_NAMES)
    assert params.replace(mu1=0.7).mu1 == 0.7
    assert params.replace(mu1=0.7).mu2 == params.mu2
    with pytest.raises(ParameterError, match=r"'mu1'.*must be in \[0, inf\)"):
        params.replace(mu1=-1.0)
    with pytest.raises(ParameterError) as excinfo:
        params.replace(mu=0.7)
    assert "'mu'" in message(excinfo) and "valid names: Theta, Phi" in message(excinfo)


def test_vector_packs_compliances() -> None:
    assert compliances(make(k_ip1=1e8, k_ip2=2e8)) == (1e-8, 5e-9)
    assert compliances(make(k_ip1=math.inf, k_ip2=4.0)) == (0.0, 0.25)
    assert make().vector()[PARAMETER_NAMES.index("Omega")] == pytest.approx(16 * math.pi)


def test_to_json_dict_writes_inf_as_string() -> None:
    data = make(k_ip1=math.inf).to_json_dict()
    assert data["k_ip1"] == "inf" and data["k_ip2"] == 1e8
    assert list(data) == list(PARAMETER_NAMES)
    json.dumps(data, allow_nan=False)


def test_trivial_silent_motion_eq_49() -> None:
    assert trivial(make())
    assert not trivial(make(mu2=0.4))
    assert trivial(make(mu1=0.6, mu2=0.4, h10=0.008, h20=0.012))
    assert trivial(make(mu1=0.0, mu2=0.0))
    assert not trivial(make(h10=0.01 * (1 + 1e-9)))


# -------------------------------------------------------------------------- presets


def test_paper_fig2_resolves_to_the_paper_numbers() -> None:
    params = get_preset("paper-fig2").resolve({"mu": 0.6})
    assert params.model.name == "paper"
    assert params.N0 == pytest.approx(3000.0, rel=1e-15)
    assert (params.mu1, params.mu2) == (0.6, 0.6)
    assert (params.h10, params.h20) == (0.01, 0.01)
    assert params.Phi == 2 * params.Theta == 0.32
    assert params.Omega == pytest.approx(2 * math.pi * 8)
    assert (params.k_ip1, params.k_ip2) == (1e8, 1e8)
    assert (params.k_t, params.d_t, params.r) == (1.88e7, 0.1, 0.13)
    assert (params.k1, params.k2, params.d1, params.d2) == (6e6, 6e6, 5.0, 5.0)
    assert get_preset("paper-fig2").resolve().N0 == pytest.approx(3600.0)


def test_paper_fig3_resolves_by_eqs_57_and_63() -> None:
    mu1, mu2, h = 0.7, 0.3, 0.02
    params = get_preset("paper-fig3").resolve({"mu1": mu1, "mu2": mu2})
    eq57 = h * mu1 * mu2 / (mu1 + mu2)
    assert params.mu1 * params.h10 == pytest.approx(eq57, rel=1e-14)
    assert params.mu2 * params.h20 == pytest.approx(eq57, rel=1e-14)
    assert params.h10 + params.h20 == pytest.approx(h, rel=1e-14)
    assert params.Theta == pytest.approx(0.32 / 2 + 0.32 / 0.045 * (0.006 - 0.014) ** 2, rel=1e-14)
    assert trivial(params)
    assert (params.N0, params.Phi) == (3000.0, 0.32)


def test_paper_fig3_default_keeps_eq_62() -> None:
    params = get_preset("paper-fig3").resolve()
    assert params.mu1 + params.mu2 == pytest.approx(1.0)
    assert params.mu1 != params.mu2 and trivial(params)


def test_minimal_model_has_rigid_tangential_supports() -> None:
    params = get_preset("minimal-model").resolve({"mu": 0.3})
    assert compliances(params) == (0.0, 0.0)
    assert (params.mu1, params.mu2, params.N0) == (0.3, 0.3, 3600.0)
    assert trivial(params)


def test_overrides_accept_fixed_names_and_expression_strings() -> None:
    params = get_preset("paper-fig2").resolve({"Omega": "8*pi", "k_ip": "inf", "h": 0.04})
    assert params.Omega == pytest.approx(8 * math.pi)
    assert compliances(params) == (0.0, 0.0)
    assert params.h10 == params.h20 == 0.02


def test_setting_a_tied_name_replaces_its_tie() -> None:
    params = get_preset("paper-fig2").resolve({"N0": 3000.0})
    assert params.N0 == 3000.0 and params.mu1 == 0.5  # N0 = 1800/mu no longer applies


@pytest.mark.parametrize(("preset", "name"),
                         [(p.name, n) for p in PRESETS.values() for n in p.tied])
def test_tied_names_can_be_replaced_but_not_varied(preset: str, name: str) -> None:
    from brakesqueal.model import ParameterSpace

    space = ParameterSpace.from_preset(preset)
    with pytest.raises(ParameterError, match=f"cannot vary '{name}': it is tied in preset '{preset}'"):
        space.check_axis(name)


def test_free_name_of_other_preset_gets_helpful_message() -> None:
    with pytest.raises(ParameterError) as excinfo:
        get_preset("paper-fig3").resolve({"mu": 0.5})
    text = message(excinfo)
    assert "'mu' is not defined in preset 'paper-fig3'" in text
    assert "free parameter of preset 'paper-fig2', 'minimal-model'" in text
    assert "mu1, mu2" in text
    with pytest.raises(ParameterError, match="'paper-fig2', 'paper-fig3'"):
        get_preset("minimal-model").resolve({"k_ip": 1e7})


def test_unknown_name_lists_settable_names() -> None:
    with pytest.raises(ParameterError) as excinfo:
        get_preset("paper-fig2").resolve({"speed": 3.0})
    assert "free parameter" not in message(excinfo)
    assert "settable names: mu, k_ip, h, r" in message(excinfo)


def test_tied_expression_errors_name_the_values() -> None:
    with pytest.raises(ParameterError) as excinfo:
        get_preset("paper-fig2").resolve({"mu": 0})
    assert message(excinfo) == "tied parameter 'N0' = 1800/mu cannot be evaluated at mu=0: division by zero"
    with pytest.raises(ParameterError, match=r"N0 = 1800/mu at mu=-0\.5"):
        get_preset("paper-fig2").resolve({"mu": -0.5})


def test_bad_override_values() -> None:
    with pytest.raises(ParameterError, match="value of 'mu'"):
        get_preset("paper-fig2").resolve({"mu": True})
    with pytest.raises(ParameterError, match="unknown name 'mu2'"):
        get_preset("paper-fig3").resolve({"mu1": "mu2/2"})


def test_get_preset_and_describe() -> None:
    with pytest.raises(ParameterError) as excinfo:
        get_preset("paper-fig4")
    assert "paper-fig2, paper-fig3, minimal-model" in message(excinfo)
    text = get_preset("paper-fig3").describe()
    assert len(text.splitlines()) > 10
    assert "eqs. 56-63" in text and "h10" in text and "h*mu2/(mu1+mu2)" in text
    assert get_preset("paper-fig2").settable_names()[:2] == ("mu", "k_ip")


def _preset(**kwargs: object) -> Preset:
    base = {n: 1.0 for n in PARAMETER_NAMES}
    fixed = {k: v for k, v in base.items() if k not in kwargs.get("tied", {})}
    spec = {"name": "test", "description": "", "reference": "", "fixed": fixed,
            "free": {}, "tied": {}, **kwargs}
    return Preset(**spec).bind(PAPER)  # type: ignore[arg-type]


def test_preset_definition_errors() -> None:
    with pytest.raises(ParameterError, match="mu1 -> mu2 -> mu1"):
        _preset(tied={"mu1": "mu2", "mu2": "mu1"})
    with pytest.raises(ParameterError, match="not defined: mu1"):
        _preset(fixed={n: 1.0 for n in PARAMETER_NAMES if n != "mu1"})
    with pytest.raises(ParameterError, match="unknown name 'q'"):
        _preset(tied={"mu1": "2*q"})
    with pytest.raises(ParameterError, match="reserved name 'pi'"):
        _preset(free={"pi": 3.0})
    with pytest.raises(ParameterError, match="more than one.*mu1"):
        _preset(free={"mu1": 0.5})
    with pytest.raises(ParameterError, match="auxiliary name 'extra' is not used"):
        _preset(free={"extra": 0.5})
    assert _preset(tied={"mu1": "mu2", "mu2": "Theta"}).resolve().mu1 == 1.0


# ---------------------------------------------------------------------- expressions


@pytest.mark.parametrize(("expr", "expected"), [
    ("16*pi", 16 * math.pi), ("inf", math.inf), ("-2**2", -4.0), ("+3", 3.0),
    ("sqrt(4) + abs(-1) + exp(0) + log(1) + sin(0) + cos(0) + tan(0)", 5.0),
    ("1800/mu", 3600.0), ("(1 + mu) * 2", 3.0), ("1e8", 1e8), ("1/inf", 0.0),
])
def test_evaluate_whitelisted_expressions(expr: str, expected: float) -> None:
    assert evaluate(expr, {"mu": 0.5}, what="test") == pytest.approx(expected)


@pytest.mark.parametrize("expr", [
    "__import__('os')", "__import__('os').system('true')", "().__class__",
    "mu.real", "(lambda: 1)()", "lambda: 1", "[x for x in (1, 2)]", "'abc'",
    "mu[0]", "open('f')", "eval('1')", "mu < 1", "mu if mu else 1", "True",
    "sqrt(x=4)", "sqrt(1, 2)", "sqrt", "mu // 2", "mu % 2", "~1", "1j", "(a := 1)",
    "not mu", "f'{mu}'", "{1: 2}", "nope", "1 +", "", "getattr(mu)", "globals()",
    "print(1)", "max(1, 2)", "pow(2, 3)",
])
def test_evaluate_rejects_everything_else(expr: str) -> None:
    with pytest.raises(ParameterError) as excinfo:
        evaluate(expr, {"mu": 0.5}, what="tied parameter 'N0'")
    assert message(excinfo).startswith("tied parameter 'N0'")


def test_function_whitelist_is_exactly_the_documented_one() -> None:
    assert set(FUNCTIONS) == {"sqrt", "sin", "cos", "tan", "exp", "log", "abs"}
    assert set(CONSTANTS) == {"pi", "inf"}


def test_rejection_names_the_offending_piece() -> None:
    with pytest.raises(ParameterError, match=r"call of '__import__' is not allowed"):
        evaluate("__import__('os')", {}, what="x")
    with pytest.raises(ParameterError, match=r"attribute access 'mu\.real'"):
        evaluate("2*mu.real", {"mu": 1.0}, what="x")
    with pytest.raises(ParameterError, match=r"lambda"):
        evaluate("(lambda: 1)", {}, what="x")
    with pytest.raises(ParameterError, match=r"unknown name 'nu'.*known names: mu"):
        evaluate("nu", {"mu": 1.0}, what="x")


@pytest.mark.parametrize(("expr", "reason"), [
    ("1/mu", "division by zero"), ("1e308*10", "overflow"), ("exp(1000)", "overflow"),
    ("10**400", "overflow"), ("sqrt(mu - 1)", "sqrt"), ("log(mu)", "log"),
    ("inf - inf", "nan"), ("(-8)**(1/3)", "undefined"),
])
def test_evaluate_arithmetic_failures(expr: str, reason: str) -> None:
    with pytest.raises(ParameterError) as excinfo:
        evaluate(expr, {"mu": 0.0}, what="value of 'x'")
    text = message(excinfo)
    assert text.startswith(f"value of 'x' = {expr} cannot be evaluated") and reason in text
    if "mu" in expr:
        assert "at mu=0" in text


def test_names_in_and_dependency_order() -> None:
    assert names_in("h*mu2/(mu1+mu2) + pi + sqrt(inf)") == {"h", "mu1", "mu2"}
    with pytest.raises(ParameterError):
        names_in("os.system")
    order = dependency_order({"Theta": "h10 - h20", "h10": "h/2", "h20": "h10"})
    assert order.index("h10") < order.index("h20") < order.index("Theta")


# ----------------------------------------------------------------------------- TOML


def write(tmp_path: Path, text: str, name: str = "p.toml") -> str:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


def from_file(path: str, sets: dict[str, object] | None = None) -> Parameters:
    return resolve_parameters(params=path, sets=dict(sets or {}))


def test_toml_round_trip(tmp_path: Path) -> None:
    params = get_preset("paper-fig3").resolve({"mu1": 0.7, "mu2": 0.3, "k_ip": math.inf})
    text = parameters_to_toml(params)
    assert 'k_ip1 = "inf"' in text and 'model = "paper"' in text
    assert from_file(write(tmp_path, text)) == params


def test_toml_with_preset_and_overrides(tmp_path: Path) -> None:
    path = write(tmp_path, 'preset = "paper-fig2"\n[parameters]\nmu = 0.6\nOmega = "4*pi"\n')
    params = from_file(path)
    assert params.N0 == pytest.approx(3000.0) and params.Omega == pytest.approx(4 * math.pi)
    assert from_file(path, {"mu": 0.9}).mu1 == 0.9
    assert load_parameter_file(path)[1] == "paper-fig2"


@pytest.mark.parametrize(("text", "pieces"), [
    ('preset = "paper-fig2"\n[parameters]\nfoo = 1\n', ["'foo'"]),
    ('preset = "nope"\n', ["Unknown preset 'nope'", "presets:"]),
    ("preset = 3\n", ["key 'preset' must be a string"]),
    ('presets = "paper-fig2"\n', ["unknown top-level key 'presets'"]),
    ("[parameters]\nmu1 = true\n", ["key 'parameters.mu1'", "bool"]),
    ("[parameters]\nmu1 = [1]\n", ["key 'parameters.mu1'"]),
    ("parameters = 3\n", ["key 'parameters' must be a table"]),
    ("[parameters]\nmu1 = 0.5\nTheta = 1\n", ["missing parameter(s) Phi, k_t", "Omega"]),
    ("[parameters]\nmu1 = = 0.5\n", ["not valid TOML", "line 2"]),
])
def test_toml_errors_name_file_and_key(tmp_path: Path, text: str, pieces: list[str]) -> None:
    path = write(tmp_path, text)
    with pytest.raises(ParameterError) as excinfo:
        from_file(path)
    text = message(excinfo)
    assert path in text
    assert all(piece in text for piece in pieces), text


def test_toml_unknown_name_without_preset(tmp_path: Path) -> None:
    body = "".join(f"{k} = {v!r}\n" for k, v in VALID.items())
    path = write(tmp_path, "[parameters]\n" + body + "mu = 0.3\n")
    with pytest.raises(ParameterError, match="unknown parameter 'mu'.*valid names"):
        from_file(path)
    path = write(tmp_path, "[parameters]\n" + body.replace("mu1 = 0.5", "mu1 = -0.5"))
    with pytest.raises(ParameterError, match=r"p\.toml.*'mu1'.*must be in"):
        from_file(path)


def test_unreadable_file() -> None:
    with pytest.raises(ParameterError, match="cannot read parameter file '/nonexistent"):
        from_file("/nonexistent/params.toml")


# ------------------------------------------------------------------------------ CLI


@pytest.mark.parametrize(("text", "expected"), [
    ("mu=0.6", ("mu", 0.6)), (" k_ip = inf ", ("k_ip", math.inf)),
    ("Omega=16*pi", ("Omega", "16*pi")), ("a=b=c", ("a", "b=c")),
])
def test_parse_sets(text: str, expected: tuple[str, object]) -> None:
    assert parse_sets([text]) == dict([expected])


@pytest.mark.parametrize("text", ["abc", "=1", "mu=", "1mu=2", "m u=1"])
def test_parse_sets_malformed(text: str) -> None:
    with pytest.raises(ParameterError) as excinfo:
        parse_sets([text])
    assert message(excinfo) == f"malformed --set {text!r}: expected NAME=VALUE"


def test_resolve_parameters_combinations(tmp_path: Path) -> None:
    assert resolve_parameters() == get_preset("paper-fig2").resolve()
    assert resolve_parameters(preset="minimal-model", sets=["mu=0.2"]).mu2 == 0.2
    path = write(tmp_path, 'preset = "paper-fig2"\n[parameters]\nmu = 0.6\n')
    assert resolve_parameters(params=path).N0 == pytest.approx(3000.0)
    assert resolve_parameters(preset="paper-fig2", params=path, sets=["mu=0.9"]).mu1 == 0.9
    with pytest.raises(ParameterError, match="conflicts with --preset 'paper-fig3'"):
        resolve_parameters(preset="paper-fig3", params=path)
    bare = write(tmp_path, "[parameters]\nmu = 0.6\n", "bare.toml")
    assert resolve_parameters(preset="paper-fig2", params=bare).mu1 == 0.6
    with pytest.raises(ParameterError, match="given more than once"):
        resolve_parameters(sets=["mu=0.1", "mu=0.2"])
    with pytest.raises(ParameterError, match="malformed --set"):
        resolve_parameters(sets=["mu"])
    full = write(tmp_path, parameters_to_toml(make()), "full.toml")
    assert resolve_parameters(params=full, sets=["mu1=0.1"]) == make(mu1=0.1)


# ------------------------------------------------------------------------ properties

positive = st.floats(min_value=1e-12, max_value=1e12, allow_nan=False)
nonnegative = st.one_of(st.just(0.0), positive)  # non-zero magnitudes below 1e-100 are refused (MIN_MAGNITUDE)
stiffness = st.one_of(positive, st.just(math.inf))


@st.composite
def parameter_sets(draw: st.DrawFn) -> Parameters:
    """Draw any valid parameter set of the paper's model."""
    h10 = draw(st.floats(min_value=-1.0, max_value=1.0, allow_nan=False).filter(lambda x: x == 0 or abs(x) >= 1e-100))
    h20 = draw(st.floats(min_value=-h10 + 1e-6, max_value=2.0, allow_nan=False)
               .filter(lambda x: x == 0 or abs(x) >= 1e-100))
    return Parameters(PAPER, dict(
        Theta=draw(positive), Phi=draw(positive), k_t=draw(nonnegative),
        d_t=draw(nonnegative), k1=draw(nonnegative), k2=draw(nonnegative),
        d1=draw(nonnegative), d2=draw(nonnegative), k_ip1=draw(stiffness),
        k_ip2=draw(stiffness), mu1=draw(nonnegative), mu2=draw(nonnegative),
        h10=h10, h20=h20, r=draw(positive), N0=draw(positive), Omega=draw(positive)))


@given(parameter_sets())
def test_property_json_round_trip(params: Parameters) -> None:
    data = json.loads(json.dumps(params.to_json_dict(), allow_nan=False))
    assert Parameters(PAPER, data) == params


@settings(max_examples=50)
@given(parameter_sets())
def test_property_toml_round_trip(params: Parameters) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "p.toml"
        path.write_text(parameters_to_toml(params), encoding="utf-8")
        assert from_file(str(path)) == params


@given(st.sampled_from(PARAMETER_NAMES), st.floats(max_value=-1e-300))
def test_property_negative_values_rejected_except_h(name: str, value: float) -> None:
    if name in ("h10", "h20") and math.isfinite(value) and value > -0.01:
        return
    with pytest.raises(ParameterError, match=f"'{name}'"):
        make(**{name: value})
