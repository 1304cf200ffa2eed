"""Units on input (``--set Omega=1200rpm``, ``50km/h@0.3m``, ``"5 mm"`` in parameter files), echoed in SI."""

from __future__ import annotations

import json
import math
import os
import pickle
import random
import subprocess
import sys
from pathlib import Path

import pytest
import scipy.constants as const

from brakesqueal.errors import ParameterError
from brakesqueal.model import parse_sets
from brakesqueal.model.options import resolve_parameters, resolve_space
from brakesqueal.model.units import UNIT_GROUPS, Quantity, accepted_units, check_quantity, parse_quantity

# Independent definitions of every unit in the table: {unit: (SI unit, value of 1 unit in SI)}.
DEFINITIONS: dict[str, tuple[str, float]] = {
    "rad/s": ("rad/s", 1.0), "rpm": ("rad/s", 2 * math.pi / const.minute), "rev/s": ("rad/s", 2 * math.pi),
    "Hz": ("rad/s", 2 * math.pi), "deg/s": ("rad/s", const.degree),
    "rad": ("rad", 1.0), "deg": ("rad", const.degree),
    "m": ("m", 1.0), "mm": ("m", const.milli), "cm": ("m", const.centi), "km": ("m", const.kilo),
    "m/s": ("m/s", 1.0), "mm/s": ("m/s", const.milli), "km/h": ("m/s", const.kmh),
    "s": ("s", 1.0), "ms": ("s", const.milli),
    "kg": ("kg", 1.0), "g": ("kg", const.gram), "t": ("kg", const.metric_ton),
    "N": ("N", 1.0), "kN": ("N", const.kilo),
    "N/m": ("N/m", 1.0), "N/mm": ("N/m", 1 / const.milli), "kN/m": ("N/m", const.kilo),
    "kN/mm": ("N/m", const.kilo / const.milli), "MN/m": ("N/m", const.mega),
    "N s/m": ("N s/m", 1.0), "N*s/m": ("N s/m", 1.0), "kN s/m": ("N s/m", const.kilo),
    "kN*s/m": ("N s/m", const.kilo),
    "kg m^2": ("kg m^2", 1.0), "kg*m^2": ("kg m^2", 1.0), "kg cm^2": ("kg m^2", const.centi ** 2),
    "kg*cm^2": ("kg m^2", const.centi ** 2), "kg mm^2": ("kg m^2", const.milli ** 2),
    "kg*mm^2": ("kg m^2", const.milli ** 2),
    "N m/rad": ("N m/rad", 1.0), "N*m/rad": ("N m/rad", 1.0),
    "N m s/rad": ("N m s/rad", 1.0), "N*m*s/rad": ("N m s/rad", 1.0),
}
TABLE = {u: g.si for g in UNIT_GROUPS for u in g.units}


# ------------------------------------------------------------------------------ the table


def test_every_table_entry_matches_an_independent_definition() -> None:
    assert set(TABLE) == set(DEFINITIONS)  # a new unit needs its definition here
    for unit, (si, factor) in DEFINITIONS.items():
        q = parse_quantity(f"1{unit}")
        assert isinstance(q, Quantity) and q.si == si == TABLE[unit] and q.unit == unit
        assert math.isclose(q, factor, rel_tol=1e-15), unit
        assert unit in accepted_units(si)


def test_rpm_is_exactly_two_pi_over_sixty() -> None:
    assert parse_quantity("1rpm") == 2 * math.pi / 60
    assert parse_quantity("1200rpm") == 40 * math.pi == 125.66370614359172
    assert parse_quantity("60 rpm") == 2 * math.pi
    assert parse_quantity("3000rpm") == 100 * math.pi
    assert parse_quantity("1 rev/s") == parse_quantity("1Hz") == 2 * math.pi
    assert parse_quantity("180 deg/s") == math.pi
    assert parse_quantity("36 km/h") == 10.0
    assert parse_quantity("3kN/mm") == 3e6


def test_random_values_round_trip_in_every_unit() -> None:
    rng = random.Random(29)
    for _ in range(300):
        unit = rng.choice(sorted(DEFINITIONS))
        si, factor = DEFINITIONS[unit]
        v = rng.uniform(-1e6, 1e6) * 10.0 ** rng.randint(-6, 6)
        for text in (f"{v!r}{unit}", f"{v!r} {unit}", f"({v!r}){unit}"):
            q = parse_quantity(text)
            assert q is not None and q.si == si and math.isclose(q / factor, v, rel_tol=1e-14), text
        assert parse_quantity(f"{float(q)!r} {si}") == float(q)  # back in SI: the same double


# ------------------------------------------------------------------------------ syntax


@pytest.mark.parametrize("text", ["0.4", "inf", "16*pi", "k1", "d_t", "2*k1m", "1800/mu", "1e3", "rpm", "2pi"])
def test_no_unit_suffix_leaves_the_text_alone(text: str) -> None:
    assert parse_quantity(text) is None


@pytest.mark.parametrize(("text", "si", "value"), [
    ("16*pi rpm", "rad/s", 16 * math.pi * 2 * math.pi / 60), ("(16*pi)rpm", "rad/s", 16 * math.pi * math.pi / 30),
    ("-5mm", "m", -0.005), ("1e3 N/mm", "N/m", 1e6), ("inf kN/m", "N/m", math.inf), ("2 kg*mm^2", "kg m^2", 2e-6),
])
def test_expressions_and_exponents_take_a_unit(text: str, si: str, value: float) -> None:
    q = parse_quantity(text)
    assert q is not None and q.si == si and math.isclose(q, value, rel_tol=1e-15)


def test_vehicle_speed_at_a_wheel_radius_is_v_over_r() -> None:
    q = parse_quantity("50km/h@0.3m", "--set Omega=50km/h@0.3m")
    assert q is not None and q.si == "rad/s" and math.isclose(q, 50 / 3.6 / 0.3, rel_tol=1e-15)
    assert parse_quantity("10 m/s @ 300 mm") == pytest.approx(10 / 0.3, rel=1e-15)
    with pytest.raises(ParameterError, match=r"^--set Omega=3rpm@1m: expected SPEED@RADIUS"):
        parse_quantity("3rpm@1m", "--set Omega=3rpm@1m")
    with pytest.raises(ParameterError, match="wheel radius must be positive"):
        parse_quantity("50km/h@0m")


def test_quantity_pickles_and_echoes_in_si() -> None:
    q = parse_quantity("1200rpm", "--set Omega=1200rpm")
    r = pickle.loads(pickle.dumps(q))
    assert isinstance(r, Quantity) and r == q and r.where == q.where and r.unit == "rpm"
    assert q.echo("Omega") == "Omega = 1200 rpm = 125.66370614359172 rad/s"
    assert parse_quantity("5 mm").echo("h") == "h = 5 mm = 0.005 m"


@pytest.mark.parametrize(("name", "text", "si", "needle"), [
    ("Omega", "3mm", "rad/s", "--set Omega=3mm: mm is a length, Omega is in rad/s (accepted: rpm, rev/s, Hz, "
                              "deg/s, rad/s; or a vehicle speed"),
    ("mu1", "3kg", "", "--set mu1=3kg: kg is a mass, mu1 is dimensionless (give a plain number)"),
    ("h", "50km/h@0.3m", "m", "an angular speed, h is in m (accepted: mm, cm, km, m)"),
    ("x", "5 N", "s/m", "N is a force, x is in s/m (give a plain number in s/m)"),
])
def test_a_unit_of_another_quantity_is_refused_in_one_line(name: str, text: str, si: str, needle: str) -> None:
    with pytest.raises(ParameterError) as info:
        check_quantity(name, parse_quantity(text, f"--set {name}={text}"), si)
    assert needle in str(info.value) and "\n" not in str(info.value) and info.value.parameter == name


# ------------------------------------------------------------------------------ --set, spaces, files


def test_parse_sets_converts_units_and_keeps_numbers_expressions_and_refusals() -> None:
    sets = parse_sets(["Omega=1200rpm", "k_ip=inf", "mu1=0.4", "N0=16*pi", "h=5 mm"])
    assert isinstance(sets["Omega"], Quantity) and sets["Omega"] == 40 * math.pi
    assert sets["k_ip"] == math.inf and sets["mu1"] == 0.4 and sets["N0"] == "16*pi" and sets["h"] == 0.005
    assert not isinstance(sets["k_ip"], Quantity)
    for text in ("k1=1e400", "Omega=1e400rpm"):
        with pytest.raises(ParameterError, match="overflows a double"):
            parse_sets([text])


def test_space_with_units_resolves_like_si_and_refuses_other_units() -> None:
    a = resolve_parameters(preset="paper-fig3", sets=["Omega=1200rpm", "h=5mm", "k1=2kN/mm"])
    b = resolve_parameters(preset="paper-fig3", sets=["Omega=40*pi", "h=0.005", "k1=2e6"])
    assert a.as_dict() == b.as_dict()
    with pytest.raises(ParameterError, match=r"^--set Omega=3mm: mm is a length, Omega is in rad/s"):
        resolve_space(preset="paper-fig3", sets=["Omega=3mm"])
    with pytest.raises(ParameterError, match="k_ip is in N/m"):  # an auxiliary name's unit (from its [unit])
        resolve_space(preset="paper-fig3", sets=["k_ip=3 mm"])


def test_parameter_file_strings_with_units(tmp_path: Path) -> None:
    good = tmp_path / "good.toml"
    good.write_text('preset = "paper-fig3"\n[parameters]\nOmega = "1200 rpm"\nk1 = "2 kN/mm"\n')
    p = resolve_parameters(params=str(good))
    assert p["Omega"] == 40 * math.pi and p["k1"] == 2e6
    bad = tmp_path / "bad.toml"
    bad.write_text('preset = "paper-fig3"\n[parameters]\nOmega = "3 mm"\n')
    with pytest.raises(ParameterError, match=r"bad.toml': parameters.Omega = '3 mm': mm is a length"):
        resolve_space(params=str(bad))


# ------------------------------------------------------------------------------ CLI


def run(*args: str, cache: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "BRAKESQUEAL_CACHE_DIR": str(cache), "OPENBLAS_NUM_THREADS": "1"}
    return subprocess.run([sys.executable, "-m", "brakesqueal", *args], capture_output=True, text=True, env=env)


def test_cli_echoes_si_once_and_gives_the_same_parameters_as_si(tmp_path: Path) -> None:
    a = run("linearize", "--preset", "paper-fig3", "--set", "Omega=1200rpm", "--format", "json", cache=tmp_path)
    b = run("linearize", "--preset", "paper-fig3", "--set", "Omega=40*pi", "--format", "json", cache=tmp_path)
    assert a.returncode == b.returncode == 0, a.stderr
    assert json.loads(a.stdout)["parameters"] == json.loads(b.stdout)["parameters"]
    assert a.stderr.count("brakesqueal: note: Omega = 1200 rpm = 125.66370614359172 rad/s\n") == 1
    assert "rad/s" not in b.stderr


@pytest.mark.parametrize(("value", "needle"), [
    ("Omega=3mm", "brakesqueal: error: --set Omega=3mm: mm is a length, Omega is in rad/s (accepted: rpm"),
    ("mu1=3kg", "brakesqueal: error: --set mu1=3kg: kg is a mass, mu1 is dimensionless"),
    ("k1=1e400", "brakesqueal: error: --set k1=1e400: the number overflows a double"),
])
def test_cli_refuses_wrong_units_in_one_line(value: str, needle: str, tmp_path: Path) -> None:
    r = run("linearize", "--preset", "paper-fig3", "--set", value, cache=tmp_path)
    assert r.returncode == 2 and r.stderr.startswith(needle), r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr
