"""All computer algebra lives in the symbolic layer and runs once per model: warm commands never import it.

``map``, ``critical-speed``, ``simulate`` and ``cycles`` run twice in fresh interpreters on one cache: the first
fills it, the second must not import SymPy or symengine (analysis, simulation and nonlinear read what the engine
generated; exact root isolation is pure Python).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"

_PROBE = """
import json, sys
from brakesqueal.cli import main
try:
    main({args!r})
except SystemExit as exc:
    code = exc.code
else:
    code = 0
print(json.dumps({{"code": code, "cas": sorted(m for m in ("sympy", "symengine") if m in sys.modules)}}))
"""

COMMANDS = {
    "map": ["map", "--preset", "paper-fig2", "--x", "mu=0.1:1:12", "--y", "k_ip=1e5:1e7:10", "--out", "m.nc"],
    "map-tilted": ["map", "--preset", "paper-fig3", "--set", "h10=0.012", "--x", "mu1=0.1:0.9:8", "--y",
                   "mu2=0.1:0.9:8", "--out", "t.nc"],
    "critical-speed": ["critical-speed", "--preset", "paper-fig3"],
    "crossings": ["crossings", "--along", "k_ip=1e5:1e10:log", "--set", "mu=0.5"],
    "simulate": ["simulate", "--preset", "paper-fig2", "--t-end", "0.005", "--no-progress"],
    "cycles": ["cycles", "--preset", "paper-fig2", "--set", "k_ip=inf", "--along", "mu=0.05:1", "--max-points",
               "6"],
}


def _probe(args: list[str], cache: Path, cwd: Path) -> dict[str, object]:
    env = {**os.environ, "BRAKESQUEAL_CACHE_DIR": str(cache), "PYTHONPATH": str(SRC), "MPLBACKEND": "Agg"}
    res = subprocess.run([sys.executable, "-c", _PROBE.format(args=args)], cwd=cwd, env=env, capture_output=True,
                         text=True, timeout=900)
    assert res.returncode == 0, res.stderr[-2000:]
    out: dict[str, object] = json.loads(res.stdout.strip().splitlines()[-1])
    return out


@pytest.mark.slow
@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_warm_commands_import_no_computer_algebra(command, tmp_path):
    cache = tmp_path / "cache"
    first = _probe(COMMANDS[command], cache, tmp_path)
    assert first["code"] == 0, first
    warm = _probe(COMMANDS[command], cache, tmp_path)
    assert warm["code"] == 0 and warm["cas"] == [], warm
