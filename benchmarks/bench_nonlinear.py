"""Nonlinear analysis speed: ``python benchmarks/bench_nonlinear.py``.

first_lyapunov (warm, exact vs finite-difference multilinear forms) and a 200-point limit-cycle branch of
a 4-state 2-DOF friction-type oscillator (CompiledFlow and ScipyFlow) against a brute-force baseline
(long simulations until the transient decays) measured in the same process.  ``--format json`` prints
BenchResult JSON; ``--points N`` sets the branch size, ``--brute-points M`` the simulated subset.
"""

from __future__ import annotations

import argparse
import sys

from brakesqueal.bench import report
from brakesqueal.nonlinear.bench import bench_nonlinear

if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--format", choices=("text", "json"), default="text")
    ap.add_argument("--points", type=int, default=200)
    ap.add_argument("--brute-points", type=int, default=10)
    a = ap.parse_args()
    sys.stdout.write(report(bench_nonlinear(points=a.points, brute_points=a.brute_points), a.format))
