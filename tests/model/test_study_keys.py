"""Errors of the parameter layer carry the offending names as data; study files report them under the right key.

The study maps an error to its key with ``ParameterError.parameter`` / ``.names`` (never by the message text):
these cases were chosen so that the message alone would mislead (the name appears only as ``mu=0``, or several
names of the study appear in the message).
"""

from __future__ import annotations

import pytest

from brakesqueal.errors import ParameterError
from brakesqueal.model import Parameters, get_model, get_preset
from brakesqueal.model.expressions import dependency_order
from brakesqueal.sweep import load_study


# ---------------------------------------------------------------- the data on the errors
def test_cycle_carries_its_members_in_order():
    with pytest.raises(ParameterError) as info:
        dependency_order({"x": "1", "a": "b + x", "b": "2 * c", "c": "a"})
    assert info.value.parameter == "a" and info.value.names == ("a", "b", "c")
    assert "a -> b -> c -> a" in str(info.value)


def test_value_out_of_range_names_the_parameter():
    values = dict(get_preset("paper-fig2").resolve())
    with pytest.raises(ParameterError) as info:
        Parameters(get_model("paper"), {**values, "m": -1.0})
    assert info.value.parameter == "m" and info.value.names == ("m",)


def test_tie_that_cannot_be_evaluated_names_the_tie_and_its_inputs():
    with pytest.raises(ParameterError) as info:
        get_preset("paper-fig2").resolve({"mu": 0.0})  # N0 = 1800/mu
    assert info.value.parameter == "N0" and set(info.value.names) == {"N0", "mu"}
    assert "'mu'" not in str(info.value)  # the message says "at mu=0": text matching would miss it


def test_tied_value_out_of_range_names_the_tie_then_its_inputs():
    with pytest.raises(ParameterError) as info:
        get_preset("paper-fig2").resolve({"mu": -0.5})  # N0 = 1800/mu < 0
    assert info.value.names[0] in {"mu", "N0"} and {"mu", "N0"} <= set(info.value.names)


def test_unknown_name_and_bad_expression_are_named():
    pr = get_preset("paper-fig2")
    with pytest.raises(ParameterError) as info:
        pr.resolve({"muu": 0.3})
    assert info.value.parameter == "muu"
    with pytest.raises(ParameterError) as info:
        pr.resolve({"mu": "__import__('os')"})
    assert info.value.parameter == "mu"


def test_errors_without_a_name_have_none_and_survive_pickling():
    import pickle

    e = ParameterError("plain")
    assert e.parameter is None and e.names == ()
    e = pickle.loads(pickle.dumps(ParameterError("x", parameter="a", names=("b",))))
    assert (e.parameter, e.names, str(e)) == ("a", ("a", "b"), "x")


# ---------------------------------------------------------------- study files
def _err(text: str, tmp_path) -> str:
    f = tmp_path / "s.toml"
    f.write_text(text + '\n[axes]\nmu = "0.1:0.5:3"\n')
    with pytest.raises(ParameterError) as info:
        load_study(f)
    msg = str(info.value)
    assert "\n" not in msg and "s.toml" in msg
    return msg


@pytest.mark.parametrize(("text", "key"), [
    # a tie cycle: a study tie on the cycle (the first one met; here the preset's tie k_ip1 = k_ip leads to it)
    ('preset = "paper-fig2"\n[tied]\nk_ip = "Omega * 5e5"\nOmega = "2e-6 * k_ip"', "tied.k_ip"),
    ('preset = "paper-fig2"\n[tied]\nOmega = "2e-6 * k_ip"\nk_ip = "Omega * 5e5"', "tied.k_ip"),
    ('preset = "paper-fig2"\n[tied]\nOmega = "100 * d1"\nd1 = "Omega / 100"', "tied.Omega"),
    ('preset = "paper-fig2"\n[tied]\nd1 = "Omega / 100"\nOmega = "100 * d1"', "tied.d1"),
    ('preset = "paper-fig3"\n[tied]\nk_ip2 = "k_ip1"\nk_ip1 = "2 * k_ip2"', "tied.k_ip1"),
    # a cycle through the preset's own tie N0 = 1800/mu: only mu is the study's
    ('preset = "paper-fig2"\n[tied]\nmu = "N0 / 1800"', "tied.mu"),
    # a bad value given directly
    ('preset = "paper-fig2"\n[parameters]\nk_ip = 1e5\nm = -1', "parameters.m"),
    # a bad value that breaks the preset's tie: reported under the study's input, not the tie
    ('preset = "paper-fig2"\n[parameters]\nk_ip = 1e5\nmu = 0', "parameters.mu"),
    # a study tie whose expression uses an unknown name, and one that makes the preset's ties k_ip1, k_ip2 = k_ip
    # out of range: reported under the study's tie (the message names only k_ip1 and k_ip2)
    ('preset = "paper-fig3"\n[tied]\nmu2 = "mu1 * nosuch"', "tied.mu2"),
    ('preset = "paper-fig2"\n[tied]\nk_ip = "-1e5 * mu"', "tied.k_ip"),
])
def test_study_reports_the_offending_key(tmp_path, text, key):
    msg = _err(text, tmp_path)
    assert f"key '{key}':" in msg, msg


def test_model_study_reports_the_offending_parameter(tmp_path):
    msg = _err('model = "paper"\n[parameters]\nk_ip1 = 1e5\nh10 = -1\nh20 = -1', tmp_path)
    assert "key 'parameters.h10':" in msg, msg
    msg = _err('model = "paper"\n[parameters]\nk_ip1 = 1e5\nmu1 = "2 * nosuch"', tmp_path)
    assert "key 'parameters.mu1':" in msg, msg
