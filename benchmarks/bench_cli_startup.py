"""Wall times of the command line as a user runs it, interpreter start included, against ``python -c pass``.

* ``brakesqueal --help``;
* ``brakesqueal linearize`` with a warm cache (target ≤ 0.2 s), and the same with ``--no-cache``;
* ``brakesqueal derive --case general`` with an empty cache (target ≤ 0.4 s; the paper's closed forms are
  shipped text, :mod:`brakesqueal.cli.closed_forms`), and the same with ``--no-cache`` (the live derivation
  with SymPy, which the command ran before the shipped texts);
* the baselines, in the same run: ``python -c pass`` (interpreter start) and ``python -c "import numpy"``
  (the floor of any command that computes).

Each command runs as a fresh process (``python -m brakesqueal``); the best of ``--repeat`` runs is
reported (cold runs each get a new empty cache directory).  Run by ``make bench`` (``python -m benchmarks``)
or directly: ``python benchmarks/bench_cli_startup.py [--repeat N]``.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, emit, user_env  # noqa: E402


def wall(cmd: list[str], env: dict[str, str], repeat: int, *, fresh_cache: bool = False) -> float:
    """Best wall time [s] of a command over ``repeat`` runs (a new empty cache per run if ``fresh_cache``)."""
    best = float("inf")
    for _ in range(repeat):
        tmp = tempfile.mkdtemp(prefix="brakesqueal-bench-cache-") if fresh_cache else None
        run_env = {**env, "BRAKESQUEAL_CACHE_DIR": tmp} if tmp else env
        try:
            t0 = time.perf_counter()
            subprocess.run(cmd, env=run_env, check=True, capture_output=True)
            best = min(best, time.perf_counter() - t0)
        finally:
            if tmp:
                shutil.rmtree(tmp, ignore_errors=True)
    return best


def run(repeat: int = 5) -> list[BenchResult]:
    bq = [sys.executable, "-m", "brakesqueal"]
    with tempfile.TemporaryDirectory() as cache:
        env = user_env(BRAKESQUEAL_CACHE_DIR=cache)
        subprocess.run([*bq, "linearize"], env=env, check=True, capture_output=True)  # warm the cache
        t_pass = wall([sys.executable, "-c", "pass"], env, repeat)
        t_numpy = wall([sys.executable, "-c", "import numpy"], env, repeat)
        t_help = wall([*bq, "--help"], env, repeat)
        t_lin = wall([*bq, "linearize"], env, repeat)
        t_nocache = wall([*bq, "linearize", "--no-cache"], env, max(1, repeat // 2))
        t_derive = wall([*bq, "derive", "--case", "general"], env, repeat, fresh_cache=True)
        t_derive_live = wall([*bq, "derive", "--case", "general", "--no-cache"], env, max(1, repeat // 2))
    base = {"baseline": "python -c pass (interpreter start) in the same run",
            "python_-c_import_numpy_s": round(t_numpy, 3)}
    return [
        BenchResult("brakesqueal linearize, warm cache (interpreter start included)", t_lin, "s", t_pass,
                    t_lin / t_pass, {**base, "target_s": 0.2, "above_interpreter_start_s": round(t_lin - t_pass, 3),
                                     "above_import_numpy_s": round(t_lin - t_numpy, 3)}),
        BenchResult("brakesqueal derive --case general, empty cache (interpreter start included)", t_derive, "s",
                    t_pass, t_derive / t_pass, {**base, "target_s": 0.4, "help_s": round(t_help, 3),
                                                "over_help": round(t_derive / t_help, 2)}),
        BenchResult("brakesqueal derive --case general --no-cache (live SymPy derivation)", t_derive_live, "s",
                    t_pass, t_derive_live / t_pass, {**base, "shipped_text_s": round(t_derive, 3),
                                                     "live_over_shipped": round(t_derive_live / t_derive, 2)}),
        BenchResult("brakesqueal --help", t_help, "s", t_pass, t_help / t_pass, base),
        BenchResult("brakesqueal linearize --no-cache vs warm cache", t_nocache, "s", t_lin, t_nocache / t_lin,
                    {"baseline": "the same command with a warm cache"}),
    ]


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=5, help="runs per command (the best is reported)")
    emit(run(ap.parse_args().repeat))
