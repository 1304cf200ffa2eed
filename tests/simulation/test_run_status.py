"""Run statuses of the simulation are the shared enum ``brakesqueal.status.RunStatus`` (a ``str`` enum).

Checked: the status of runs ending each way is the enum member, equals its documented string, and is
written as that string in JSON (the CLI) and in the NetCDF attributes (read back with xarray).
"""

from __future__ import annotations

import json

import pytest
import xarray as xr

from brakesqueal import resolve_parameters
from brakesqueal.cli import main
from brakesqueal import simulate
from brakesqueal.status import RunStatus


def test_statuses_are_the_shared_enum(tmp_path):
    params = resolve_parameters(None, "paper-fig2", None, ["mu=1", "h=0.05"])
    done = simulate(params, 0.002)
    assert done.status is RunStatus.FINISHED and done.status == "finished" and done.success
    lost = simulate(params, 0.5, perturbation=[2e-3, 0.0])  # paper-fig2 with mu = 1: contact loss at 0.1 s
    assert lost.status is RunStatus.CONTACT_LOSS and lost.status == "contact-loss" and not lost.success
    assert json.loads(json.dumps(lost.summary.to_dict()))["status"] == "contact-loss"
    path = tmp_path / "run.nc"
    lost.to_netcdf(str(path))
    with xr.open_dataset(path) as ds:
        assert ds.attrs["status"] == "contact-loss"
    assert {s.value for s in RunStatus} == {"finished", "contact-loss", "sliding-reversal", "failed"}


@pytest.mark.parametrize("status", list(RunStatus))
def test_run_status_prints_as_its_value(status):
    assert f"{status}" == str(status) == status.value and f"{status:>20}".strip() == status.value


def test_cli_json_status(capsys):
    assert main(["simulate", "--t-end", "0.002", "--format", "json"]) == 0
    assert json.loads(capsys.readouterr().out)["status"] == "finished"


@pytest.mark.parametrize("method, kernel, after", [("DOP853-jit", "dop853", 0), ("RK45", "rhs", 3)])
def test_a_division_by_zero_in_compiled_code_is_a_failed_run(monkeypatch, method, kernel, after):
    """numba raises ZeroDivisionError for ``0.0 ** -1`` under any error model (a Coulomb friction direction at
    exactly zero sliding speed): the run ends ``failed`` with a message saying so, never with a traceback."""
    from brakesqueal import simulation_model

    params = resolve_parameters(None, "paper-fig2", None, [])
    sim = simulation_model(params.model)
    real = getattr(sim.kernels, kernel)
    calls = {"n": 0}

    def flaky(*args):
        calls["n"] += 1
        if calls["n"] > after:
            raise ZeroDivisionError("division by zero")
        return real(*args)

    monkeypatch.setattr(sim.kernels, kernel, flaky)
    tr = simulate(params, 0.002, method=method)
    assert tr.status is RunStatus.FAILED and "divided by zero" in tr.message, tr.message
    assert calls["n"] > after
