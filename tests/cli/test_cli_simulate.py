"""The ``brakesqueal simulate`` command."""

from __future__ import annotations

import json
import wave

import pytest

from brakesqueal.cli import main


@pytest.mark.slow
def test_simulate_json_outputs(tmp_path, capsys):
    nc, png, wav = tmp_path / "sim.nc", tmp_path / "sim.png", tmp_path / "sq.wav"
    rc = main(["simulate", "--t-end", "0.02", "--q0", "1e-5,0", "--out", str(nc), "--plot", str(png),
               "--wav", str(wav), "--format", "json", "--no-progress"])  # fmt: skip
    assert rc == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("status", "frequency_hz", "growth_rate", "amplitude_final"):
        assert key in data
    assert data["status"] == "finished"
    assert 1700 < data["frequency_hz"] < 1760
    assert nc.stat().st_size > 0 and png.stat().st_size > 0
    with wave.open(str(wav)) as w:
        assert w.getframerate() == 44100 and w.getnframes() > 800


@pytest.mark.slow
def test_simulate_event_written(tmp_path, capsys):
    nc = tmp_path / "ev.nc"
    rc = main(["simulate", "--set", "mu=1", "--set", "h=0.05", "--t-end", "1", "--q0", "2e-3,0",
               "--out", str(nc), "--format", "json", "--no-progress", "--sample-rate", "5000"])  # fmt: skip
    assert rc == 0
    data = json.loads(capsys.readouterr().out)
    assert data["status"] == "contact-loss"
    import xarray as xr

    ds = xr.load_dataset(nc)
    assert ds.attrs["status"] == "contact-loss" and ds.sizes["time"] > 10


@pytest.mark.parametrize(
    "args, match",
    [
        (["--t-end", "0"], "t-end"),
        (["--t-end", "-1"], "t-end"),
        (["--q0", "nan,0"], "finite"),
        (["--q0", "abc"], "numbers"),
        (["--rtol", "1"], "rtol"),
        (["--q0", "0.05,0"], "out of contact"),
        (["--set", "mu=-1"], "mu"),
        (["--format", "xml"], "format"),
    ],
)
@pytest.mark.slow
def test_simulate_bad_input(args, match, capsys):
    rc = main(["simulate", "--t-end", "0.01", "--no-progress", *args])
    err = capsys.readouterr().err
    assert rc == 2
    assert err.count("\n") == 1 and match in err


@pytest.mark.slow
def test_solver_failure_writes_partial(tmp_path, capsys, monkeypatch):
    import brakesqueal.simulation as sim

    orig = sim.simulate

    def limited(*a, **kw):
        return orig(*a, max_steps=100, **kw)

    monkeypatch.setattr(sim, "simulate", limited)
    nc = tmp_path / "fail.nc"
    with pytest.raises(SystemExit) as exc:
        main(["simulate", "--t-end", "0.05", "--out", str(nc), "--format", "json", "--no-progress"])
    assert exc.value.code == 1
    assert json.loads(capsys.readouterr().out)["status"] == "failed"
    assert nc.stat().st_size > 0


def test_simulate_unilateral_contact_matches_library(capsys):
    """``--contact unilateral`` continues through lift-off; its duty cycles are the library's run's, and the
    pads were really lifted (bilateral contact refuses this start: a pad is out of contact)."""
    import numpy as np

    from brakesqueal.model.options import resolve_space
    from brakesqueal import simulate, simulation_model

    args = ["simulate", "--preset", "paper-fig3", "--set", "Omega=60", "--t-end", "0.01", "--q0", "3e-2,0",
            "--events", "continue", "--format", "json", "--no-progress"]  # fmt: skip
    assert main([*args, "--contact", "unilateral"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["contact"] == "unilateral" and data["status"] == "finished"
    p = resolve_space(None, "paper-fig3", None, ["Omega=60"]).resolve({})
    tr = simulate(p, 0.01, contact="unilateral", events="continue",
                  perturbation=[3e-2, 0.0])
    duty = np.asarray(tr.duty_cycle)
    assert np.all(duty < 0.9)  # both pads spend a real part of the run lifted off
    assert [data["duty_cycle"][k] for k in tr.pads] == pytest.approx(duty, rel=1e-12)
    assert main(["simulate", "--preset", "paper-fig3", "--set", "Omega=60", "--t-end", "0.01", "--q0", "3e-2,0",
                 "--format", "json", "--no-progress"]) == 2  # fmt: skip
    assert "out of contact at the initial state" in capsys.readouterr().err
    assert main(["simulate", "--contact", "sideways"]) == 2
    assert "--contact" in capsys.readouterr().err


@pytest.mark.slow
@pytest.mark.parametrize("model,unit", [("paper", "rad"), ("six-dof", "none")])
def test_the_norm_amplitude_says_its_unit_or_that_it_has_none(capsys, model, unit):
    """``amplitude_final`` is a norm over every coordinate: one unit only when all coordinates share it."""
    rc = main(["simulate", "--model", model, "--t-end", "0.002", "--format", "json", "--no-progress"])
    assert rc == 0
    data = json.loads(capsys.readouterr().out)
    units = {v["unit"] for v in data["amplitude_final_by_coordinate"].values()}
    assert data["amplitude_final_unit"].startswith(unit)
    assert (len(units) == 1) == (data["amplitude_final_unit"] in units)
