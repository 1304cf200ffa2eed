"""What the command line imports: ``--help``, a warm ``linearize`` and a cold ``derive`` stay off the heavy libraries.

Each case runs in a fresh interpreter (``python -c "import brakesqueal.cli, sys; ..."``) and reports which of
the heavy modules ended up in ``sys.modules``.  Wall times are measured in
``benchmarks/bench_cli_startup.py``, not here.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from brakesqueal.cli._closed_forms import TEXTS

#: Never needed by --help or by a warm linearize (compiled kernels, labelled arrays, parallelism, figures, stores,
#: computer algebra: the warm cache holds the generated code; SciPy: NumPy's eig is enough for one point).
HEAVY = ("numba", "llvmlite", "xarray", "dask", "distributed", "matplotlib", "zarr", "pandas", "scipy", "sympy",
         "symengine")

_SCRIPT = """
import brakesqueal.cli, contextlib, io, json, sys
with contextlib.redirect_stdout(io.StringIO()) as out:
    rc = brakesqueal.cli.main(sys.argv[1:])
heavy = {heavy!r}
print(json.dumps({{"rc": rc, "out": out.getvalue(), "modules": sorted(m for m in heavy if m in sys.modules)}}))
"""


def _run(*args: str, heavy: tuple[str, ...] = HEAVY, env: dict[str, str] | None = None) -> dict:
    proc = subprocess.run([sys.executable, "-c", _SCRIPT.format(heavy=heavy), *args], capture_output=True,
                          text=True, env={**os.environ, **(env or {})}, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_help_imports_no_heavy_module_and_no_numpy():
    res = _run("--help")
    assert res["rc"] == 0 and "linearize" in res["out"]
    assert res["modules"] == []
    assert _run("linearize", "--help")["modules"] == []


@pytest.mark.parametrize("args", [(), ("--model", "eight-dof"), ("--preset", "paper-fig3", "--set", "mu1=0.7")])
def test_warm_linearize_imports_no_heavy_module(args):
    first = _run("linearize", *args)  # fills the code cache if it is cold (then SymPy/symengine are needed)
    assert first["rc"] == 0
    warm = _run("linearize", *args)
    assert warm["rc"] == 0 and warm["out"] == first["out"]  # the same report from the cache
    assert "Silent motion is" in warm["out"]
    assert warm["modules"] == [], warm["modules"]


@pytest.mark.parametrize("fmt", ["text", "latex", "json"])
def test_cold_derive_imports_no_heavy_module_and_no_numpy(fmt, tmp_path):
    """The paper's closed forms are shipped text (checked in test_derive_shipped.py): no SymPy, nothing cached."""
    res = _run("derive", "--case", "general", "--format", fmt, heavy=(*HEAVY, "numpy"),
               env={"BRAKESQUEAL_CACHE_DIR": str(tmp_path / "cache")})
    assert res["rc"] == 0 and res["out"].rstrip("\n") == TEXTS["general", fmt].rstrip("\n")
    assert res["modules"] == []
    assert not (tmp_path / "cache").exists()


def test_the_probe_reports_imported_modules():
    """The probe itself works: modules the command does import are reported."""
    res = _run("--version", heavy=("typer", "json", "numba"))
    assert res["rc"] == 0 and "brakesqueal" in res["out"]
    assert res["modules"] == ["json", "typer"]
