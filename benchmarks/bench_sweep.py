"""Sweep throughput and memory: ``python benchmarks/bench_sweep.py`` (same as ``brakesqueal bench sweep``).

Reports BenchResult JSON with ``--format json``; ``--points N`` sets the size of the scaling study,
``--no-large`` skips the 1e8-point peak-memory run.
"""

from __future__ import annotations

import argparse
import sys

from brakesqueal.bench import report
from brakesqueal.sweep.bench import bench_sweep

if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--format", choices=("text", "json"), default="text")
    ap.add_argument("--points", type=int, default=20_000_000)
    ap.add_argument("--no-large", action="store_true")
    a = ap.parse_args()
    sys.stdout.write(report(bench_sweep(points=a.points, large=not a.no_large), a.format))
