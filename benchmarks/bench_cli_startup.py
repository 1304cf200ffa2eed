"""Wall time of ``brakesqueal linearize`` with a warm cache vs. ``--no-cache``, interpreter start included.

Run by ``make bench`` (``python -m benchmarks``).  Each command runs as a fresh
process; the best of 5 runs is reported.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time


def wall(args: list[str], env: dict[str, str], repeat: int = 5) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "brakesqueal", *args], env=env, check=True, capture_output=True)
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "BRAKESQUEAL_CACHE_DIR": cache}
        subprocess.run([sys.executable, "-m", "brakesqueal", "linearize"], env=env, check=True, capture_output=True)
        warm = wall(["linearize"], env)
        cold = wall(["linearize", "--no-cache"], env, repeat=3)
    rec = {"metric": "brakesqueal linearize wall time, warm cache (interpreter start included)",
           "value": warm, "unit": "s", "baseline": cold, "ratio": cold / warm,
           "details": {"baseline": "same command with --no-cache (derivation + code generation in-process)"}}
    print(f"  {rec['metric']}: {warm:.3f} s (baseline --no-cache {cold:.3f} s) ratio {cold / warm:.1f}x")
    print(json.dumps(rec))


if __name__ == "__main__":
    main()
