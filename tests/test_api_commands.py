"""Every command of the CLI has its library function in the top-level API (typed, documented, checked)."""

from __future__ import annotations

import inspect
import json
import math

import numpy as np
import pytest

import brakesqueal as bs
from brakesqueal.cli import main

#: command -> the top-level function(s) it runs
COMMANDS = {
    "derive": ["derive_equations"], "linearize": ["linearize"], "eigen": ["eigen_analysis"],
    "list": ["get_model", "get_preset"], "show": ["get_preset", "get_model"], "crossings": ["crossings"],
    "critical-speed": ["critical_speeds"], "hopf": ["hopf_points"], "cycles": ["limit_cycles"],
    "map": ["write_map", "stability_map"], "reproduce": ["reproduce_fig2", "reproduce_fig3"],
    "modes": ["modes_along"], "sweep": ["run_sweep"], "plot": ["plot_sweep"], "simulate": ["simulate"],
    "export": ["export_code"], "import": ["import_matrices"], "box": ["box_eigenvalues"],
    "reduce": ["reduce_matrix_model"], "uq": ["run_uq"], "region": ["region_diagram"], "robust": ["robust_box"],
    "design": ["run_design"],
}


def test_every_command_has_an_exported_function_with_real_types():
    from brakesqueal.cli import app
    import typer

    commands = {c.name for c in typer.main.get_command(app).commands.values()}
    assert commands - {"explore", "cache"} == set(COMMANDS)  # explore serves a page; cache manages files
    for names in COMMANDS.values():
        for name in names:
            assert name in bs.__all__, name
            f = getattr(bs, name)
            assert callable(f) and inspect.getdoc(f), name
            ret = inspect.signature(f).return_annotation
            if inspect.isfunction(f):
                assert ret not in (inspect.Signature.empty, "Any", "object"), (name, ret)


def test_box_eigenvalues_is_what_the_box_command_prints(capsys):
    w = 2 * math.pi
    p = bs.resolve_space("disk_brake100", None, None, [f"Omega={w!r}"]).resolve({})
    r = bs.box_eigenvalues(p, re=(-0.05, 1.0), freq=(0.0, 0.2))
    assert main(["box", "--model", "disk_brake100", "--set", f"Omega={w!r}", "--re=-0.05:1", "--freq", "0:0.2",
                 "--format", "json", "--no-progress"]) == 0
    cli = json.loads(capsys.readouterr().out)
    assert cli["verdict"] == r.verdict and cli["unstable"] == r.unstable == 1
    np.testing.assert_allclose(sorted(e["re"] for e in cli["eigenvalues"]), sorted(np.real(r.eigenvalues)))
    with pytest.raises(bs.ParameterError, match="coefficient matrices"):
        bs.box_eigenvalues(bs.get_preset("paper-fig2").resolve({}), re=(-1.0, 1.0), freq=(0.0, 2000.0))
