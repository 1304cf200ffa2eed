"""The cache of parsed tie expressions (``Preset.resolve`` at every point of a path) changes no result and no error."""

from __future__ import annotations

import math

import pytest

from brakesqueal.errors import ParameterError
from brakesqueal.model import expressions
from brakesqueal.model.expressions import evaluate, names_in
from brakesqueal.model.library import get_preset


def _error(fn: object, *args: object, **kwargs: object) -> tuple[str, object, object]:
    with pytest.raises(ParameterError) as excinfo:
        fn(*args, **kwargs)  # type: ignore[operator]
    exc = excinfo.value
    return str(exc), getattr(exc, "parameter", None), getattr(exc, "names", None)


@pytest.mark.parametrize(("expr", "what"), [
    ("1800/mu", "tied parameter 'N0'"),
    ("h*mu2/(mu1+mu2)", "tied parameter 'h10'"),
    ("sqrt(k)*2**-1 + sin(pi/6)", "x"),
])
def test_cached_values_equal_the_formula_and_cold_parse(expr: str, what: str) -> None:
    names = {"mu": 0.3, "h": 0.02, "mu1": 0.4, "mu2": 0.6, "k": 9.0}
    formula = {"1800/mu": 1800 / 0.3, "h*mu2/(mu1+mu2)": 0.02 * 0.6 / (0.4 + 0.6),
               "sqrt(k)*2**-1 + sin(pi/6)": 3.0 * 0.5 + math.sin(math.pi / 6)}[expr]
    expressions._cached_tree.cache_clear()
    cold = evaluate(expr, names, what=what)
    warm = [evaluate(expr, names, what=what) for _ in range(3)]
    assert cold == warm[0] == warm[1] == warm[2] == pytest.approx(formula, rel=1e-15)
    assert expressions._cached_tree.cache_info().hits >= 3
    # names_in hands out a fresh set: mutating it does not poison the cache
    first = names_in(expr, what=what)
    first.add("poison")
    assert "poison" not in names_in(expr, what=what)


@pytest.mark.parametrize(("expr", "names"), [
    ("1800/mu", {"mu": 0.0}),              # arithmetic failure of a valid (cached) tree
    ("1800/nu", {"mu": 0.5}),              # unknown name
    ("__import__('os')", {}),               # outside the grammar
    ("1800/", {"mu": 0.5}),                 # syntax error
    ("", {}),                               # empty
])
def test_errors_are_identical_cold_and_warm(expr: str, names: dict[str, float]) -> None:
    expressions._cached_tree.cache_clear()
    cold = _error(evaluate, expr, names, what="tied parameter 'N0'")
    evaluate("1800/mu", {"mu": 2.0}, what="tied parameter 'N0'")   # warm the valid tree
    warm = [_error(evaluate, expr, names, what="tied parameter 'N0'") for _ in range(2)]
    assert cold == warm[0] == warm[1]
    assert "tied parameter 'N0'" in cold[0]
    # the same expression under another label names that label (the label is part of the key)
    other = _error(evaluate, expr, names, what="tied parameter 'X'")
    assert "tied parameter 'X'" in other[0] and "'N0'" not in other[0]


def test_non_string_expression_is_still_rejected() -> None:
    for bad in (1.5, None, ["1"]):
        message, _, _ = _error(evaluate, bad, {}, what="tied parameter 'N0'")
        assert message.startswith("tied parameter 'N0' must be an expression string")


def test_preset_resolve_errors_and_values_unchanged_by_the_cache() -> None:
    preset = get_preset("paper-fig3")
    expressions._cached_tree.cache_clear()
    cold_values = preset.resolve({"mu1": 0.5, "mu2": 0.5}).as_dict()
    cold_error = _error(preset.resolve, {"mu1": 0.0, "mu2": 0.0})
    for _ in range(3):
        assert preset.resolve({"mu1": 0.5, "mu2": 0.5}).as_dict() == cold_values
        assert _error(preset.resolve, {"mu1": 0.0, "mu2": 0.0}) == cold_error
    assert expressions._cached_tree.cache_info().hits > 0
