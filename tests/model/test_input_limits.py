"""Every input file channel refuses overflowing numbers and oversized files with one line (exit 2)."""

from __future__ import annotations

import pytest

from brakesqueal.cli import main
from brakesqueal.model import get_model, model_to_toml
from brakesqueal.model.io import MAX_FILE_BYTES


def _run(capsys, *args):
    rc = main(list(args))
    err = capsys.readouterr().err.strip().splitlines()
    return rc, err


@pytest.mark.parametrize("number", ["1e400", "-1e999", "2e308"])
def test_overflowing_toml_numbers_are_refused_everywhere(tmp_path, capsys, number):
    params = tmp_path / "p.toml"
    params.write_text(f'preset = "paper-fig2"\n[parameters]\nk_ip = {number}\n')
    rc, err = _run(capsys, "linearize", "--params", str(params))
    assert rc == 2 and len(err) == 1 and "overflows" in err[0] and number in err[0]
    model = tmp_path / "m.toml"
    text = model_to_toml(get_model("paper"))
    assert "k_ip1 = " in text
    lines = [f"k_ip1 = {number}" if ln.startswith("k_ip1 = ") else ln for ln in text.splitlines()]
    model.write_text("\n".join(lines) + "\n")
    rc, err = _run(capsys, "linearize", "--model", str(model))
    assert rc == 2 and len(err) == 1 and "overflows" in err[0]
    study = tmp_path / "s.toml"
    study.write_text(f'preset = "paper-fig2"\n[parameters]\nk_ip = {number}\n[axes]\nmu = "0.1:1:3"\n'
                     'N0 = "1000:2000:2"\n')
    rc, err = _run(capsys, "sweep", str(study), "--out", str(tmp_path / "s.zarr"))
    assert rc == 2 and len(err) == 1 and "overflows" in err[0]


def test_inf_is_still_a_rigid_support(tmp_path, capsys):
    params = tmp_path / "p.toml"
    params.write_text('preset = "paper-fig2"\n[parameters]\nk_ip = inf\n')
    assert main(["linearize", "--params", str(params), "--format", "json"]) == 0
    assert '"k_ip1": "inf"' in capsys.readouterr().out


@pytest.mark.parametrize("command", [["sweep"], ["sweep", "--status"], ["linearize", "--params"],
                                     ["linearize", "--model"]])
def test_oversized_and_endless_files_are_refused(tmp_path, capsys, command):
    big = tmp_path / "big.toml"
    big.write_text("# " + "x" * (MAX_FILE_BYTES + 10) + "\n")
    rc, err = _run(capsys, *command, str(big))
    assert rc == 2 and len(err) == 1 and "larger than" in err[0], err
    rc, err = _run(capsys, *command, "/dev/zero")  # endless: not a regular file, refused before it is read
    assert rc == 2 and len(err) == 1 and "not a regular file" in err[0], err


@pytest.mark.parametrize("command", [("linearize",), ("eigen",), ("modes", "--along", "N0=1000:2000")])
@pytest.mark.parametrize("setting", ["k_ip=1e-300", "Theta=1e-300", "Omega=1e-200", "mu=-1e-200"])
def test_tiny_magnitudes_are_refused_with_one_line(capsys, command, setting):
    """1e-300 overflowed in the generated equations' powers (LinAlgError, ZeroDivisionError tracebacks)."""
    rc, err = _run(capsys, *command, "--set", setting)
    assert rc == 2 and len(err) == 1 and "magnitude of at least 1e-100" in err[0], err


def test_tiny_magnitudes_are_invalid_map_cells_and_zero_stays_allowed():
    import numpy as np

    from brakesqueal import resolve_space

    space = resolve_space(None, "paper-fig2", None, [])
    arr = space.arrays({"k_ip": np.array([1e-300, 1e-100, 1e6])})
    assert space.valid(arr).tolist() == [False, True, True]
    space.resolve({"d_t": 0.0})  # zero where the role allows it
    arr = space.arrays({"d_t": np.array([0.0, 1e-200, 1e-3])})
    assert space.valid(arr).tolist() == [True, False, True]


@pytest.mark.parametrize("setting", ["Theta=1e-100", "mu=1e90"])
def test_json_output_is_strict_json_at_extreme_values(capsys, setting):
    """The error bound can be infinite there: JSON carries null, never the invalid token Infinity."""
    import json

    for command in ("linearize", "eigen"):
        rc = main([command, "--set", setting, "--format", "json"])
        out = capsys.readouterr().out

        def refuse(token):
            raise AssertionError(f"non-JSON token {token}")

        assert rc == 0
        d = json.loads(out, parse_constant=refuse)
        assert d["verdict"]["status"] in ("stable", "unstable", "undecided")


def test_map_at_the_smallest_allowed_omega_gives_statuses_not_a_traceback(tmp_path, capsys):
    """Omega = 1e-99 made numba's complex division in the quartic root kernel raise ZeroDivisionError."""
    import xarray as xr

    out = tmp_path / "z.nc"
    rc = main(["map", "--x", "mu=0.1:1:4", "--y", "k_ip=1e5:1e9:3:log", "--out", str(out), "--set", "Omega=1e-99"])
    capsys.readouterr()
    assert rc == 0
    with xr.open_dataset(out) as ds:
        status = ds["status"].values
        stable = ds["stable"].values
    assert status.size == 12 and not stable[status > 1].any()
