"""The derived closed forms equal the paper's printed eqs. (51)-(54) and (59)-(61).

The printed matrices are typed in below from the OCR text of the paper.  One
OCR glitch is corrected where marked (``ERRATUM E2`` in docs/paper-errata.md):
the term ``Phi*Omega`` printed at the end of the first row of Dbar in eqs.
(52) and (54) belongs in entry (1, 2), as eq. (60) prints it.  The literal
reading is tested too, and shown to be wrong.
"""

from __future__ import annotations

import pytest
import sympy as sp

from brakesqueal.symbolic.linearize import closed_form


def _check_equal(derived: sp.Matrix, printed: sp.Matrix, label: str) -> None:
    for i in range(printed.rows):
        for j in range(printed.cols):
            diff = sp.simplify(derived[i, j] - printed[i, j])
            assert diff == 0, f"{label}[{i + 1},{j + 1}]: derived - printed = {diff}"


def _names(cf, *names):
    return [cf.symbols[n] for n in names]


def test_symmetric_case_equals_eqs_51_to_53():
    cf = closed_form("symmetric")
    Th, Ph, kt, dt, k1, k2, d1, d2, kip1, kip2, N0, r, Om, mu, h = _names(
        cf, "Theta", "Phi", "k_t", "d_t", "k1", "k2", "d1", "d2", "k_ip1", "k_ip2", "N0", "r", "Omega", "mu", "h"
    )
    M = sp.Matrix([[Th, 0], [0, Th]])  # eq. (51)
    D = sp.Matrix(  # eq. (52), ERRATUM E2: Phi*Omega moved from (1,1) to (1,2)
        [
            [dt + (d1 + d2) * r**2 + mu**2 * N0 * h / 2 * (d1 / kip1 + d2 / kip2) + mu * N0 * h**2 / (2 * Om * r),
             Ph * Om],
            [mu * N0 * r * (d1 / kip1 + d2 / kip2) - (d1 + d2) * mu * h * r / 2 - Ph * Om, dt],
        ]
    )  # fmt: skip
    K = sp.Matrix(  # eq. (53)
        [
            [kt + N0 * h + (k1 + k2) * r**2 + mu**2 * N0 * h / 2 * (k1 / kip1 + k2 / kip2),
             mu * N0 * h / (2 * r) * (h - (1 + mu**2) * (N0 / kip1 + N0 / kip2))],
            [-mu * r * (2 * N0 - N0 * k1 / kip1 - N0 * k2 / kip2 + k1 * h / 2 + k2 * h / 2),
             kt + (1 + mu**2) * N0 * (h - N0 / kip1 - N0 / kip2)],
        ]
    )  # fmt: skip
    _check_equal(cf.M, M, "M (51)")
    _check_equal(cf.D, D, "D (52)")
    _check_equal(cf.K, K, "K (53)")
    # the literal OCR reading (Phi*Omega multiplying the friction term, (1,2) empty) is not the model
    literal_D11 = D[0, 0] - mu * N0 * h**2 / (2 * Om * r) + mu * N0 * h**2 / (2 * Om * r) * Ph * Om
    assert sp.simplify(cf.D[0, 0] - literal_D11) != 0
    assert sp.simplify(cf.D[0, 1]) != 0


def test_minimal_case_equals_eq_54():
    cf = closed_form("minimal")
    Th, Ph, kt, dt, k, d, N0, r, Om, mu, h = _names(
        cf, "Theta", "Phi", "k_t", "d_t", "k", "d", "N0", "r", "Omega", "mu", "h"
    )
    M = sp.Matrix([[Th, 0], [0, Th]])
    D = sp.Matrix(  # eq. (54), ERRATUM E2 as in eq. (52)
        [[dt + 2 * d * r**2 + mu * N0 * h**2 / (2 * Om * r), Ph * Om], [-Ph * Om - mu * d * h * r, dt]]
    )
    K = sp.Matrix(
        [[kt + N0 * h + 2 * k * r**2, mu * N0 * h**2 / (2 * r)], [-mu * r * (2 * N0 + k * h), kt + (1 + mu**2) * N0 * h]]
    )
    _check_equal(cf.M, M, "M (54)")
    _check_equal(cf.D, D, "D (54)")
    _check_equal(cf.K, K, "K (54)")


def test_asymmetric_friction_case_equals_eqs_59_to_61():
    cf = closed_form("asymmetric-friction")
    Th, Ph, kt, dt, k, d, kip, N0, r, Om, m1, m2, h = _names(
        cf, "Theta", "Phi", "k_t", "d_t", "k", "d", "k_ip", "N0", "r", "Omega", "mu1", "mu2", "h"
    )
    M = sp.Matrix([[Th, 0], [0, Th]])  # eq. (59)
    D = sp.Matrix(  # eq. (60)
        [
            [dt + 2 * d * r**2 + N0 * d * h * m1 * m2 / kip + N0 / (Om * r) * h**2 * m1 * m2 / (m1 + m2), Ph * Om],
            [N0 * d * r / kip * (m1 + m2) - 2 * h * m1 * m2 * d * r / (m1 + m2) - Ph * Om, dt],
        ]
    )
    K = sp.Matrix(  # eq. (61)
        [
            [kt + N0 * h + 2 * k * r**2 + N0 * k / kip * h * m1 * m2,
             N0 * h**2 * m1 * m2 / (r * (m1 + m2)) - N0**2 * h * m1 * m2 / (r * kip * (m1 + m2)) * (2 + m1**2 + m2**2)],
            [-r * N0 * (m1 + m2) * (1 - k / kip) - 2 * r * k * h * m1 * m2 / (m1 + m2),
             kt + N0 * h * (1 + m1 * m2) - N0**2 / kip * (2 + m1**2 + m2**2)],
        ]
    )  # fmt: skip
    _check_equal(cf.M, M, "M (59)")
    _check_equal(cf.D, D, "D (60)")
    _check_equal(cf.K, K, "K (61)")


def test_general_case_reduces_to_the_symmetric_one():
    """The general closed form, specialized by eq. (50), equals the symmetric case (consistency of substitution)."""
    g = closed_form("general")
    s = closed_form("symmetric")
    S = g.symbols
    sub = {S["h10"]: S["h"] / 2, S["h20"]: S["h"] / 2, S["mu1"]: S["mu"], S["mu2"]: S["mu"]}
    for name in "MDK":
        _check_equal(getattr(g, name).xreplace(sub), getattr(s, name), f"general->symmetric {name}")


@pytest.mark.parametrize("case", ["general", "symmetric", "asymmetric-friction", "minimal"])
def test_closed_forms_contain_only_model_symbols(case):
    cf = closed_form(case)
    allowed = set(cf.symbols.values())
    for m in (cf.M, cf.D, cf.K):
        assert m.free_symbols <= allowed
        assert not any(s.name.startswith("c_ip") for s in m.free_symbols)


def test_unknown_case_is_a_parameter_error_with_a_suggestion():
    import pytest

    from brakesqueal import ParameterError, closed_form

    with pytest.raises(ParameterError, match=r"did you mean 'symmetric'") as excinfo:
        closed_form("symetric")
    assert excinfo.value.parameter == "case" and isinstance(excinfo.value, ValueError)
