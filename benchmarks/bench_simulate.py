"""Simulation speed: ``python benchmarks/bench_simulate.py`` (same as ``brakesqueal bench simulate``)."""

from __future__ import annotations

import sys

from brakesqueal.bench import report
from brakesqueal.simulation.bench import bench_simulate

if __name__ == "__main__":
    sys.stdout.write(report(bench_simulate(), "text"))
