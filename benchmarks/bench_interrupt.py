"""Ctrl-C latency of the command line: SIGINT to process exit (issue 11: within a second, exit status 130).

* ``brakesqueal simulate --t-end 200`` with an empty code cache and an empty numba cache, interrupted at
  several moments of its cold start (most of them during numba compilations, which cannot be unwound: the
  CLI's watchdog ends the process after 0.5 s);
* the same with a warm cache (interrupted while integrating);
* ``brakesqueal reproduce all`` (warm), interrupted while computing;
* the baseline, in the same run: ``python -c "import time; time.sleep(100)"`` interrupted the same way
  (the interpreter's own exit after a KeyboardInterrupt).

The worst latency over the interrupt moments is reported, with its ratio to the baseline's.  Run by
``make bench`` (``python -m benchmarks``) or directly: ``python benchmarks/bench_interrupt.py``.
"""

from __future__ import annotations

import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, emit, user_env  # noqa: E402


def latency(cmd: list[str], delay: float, env: dict[str, str], cwd: str) -> tuple[float, int]:
    """Seconds from SIGINT (sent ``delay`` s after the start) to the exit, and the exit status."""
    p = subprocess.Popen(cmd, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(delay)
    t0 = time.perf_counter()
    p.send_signal(signal.SIGINT)
    try:
        rc = p.wait(timeout=60)
    except subprocess.TimeoutExpired:
        p.kill()
        p.wait()
        return float("inf"), -9
    return time.perf_counter() - t0, rc


def worst(cmd: list[str], delays: list[float], *, cold: bool) -> tuple[float, list[int], list[float]]:
    times, codes = [], []
    for d in delays:
        tmp = tempfile.mkdtemp(prefix="brakesqueal-bench-int-")
        env = user_env(MPLBACKEND="Agg")
        if cold:
            env.update(BRAKESQUEAL_CACHE_DIR=f"{tmp}/cache", NUMBA_CACHE_DIR=f"{tmp}/numba")
        try:
            t, rc = latency(cmd, d, env, tmp)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        times.append(round(t, 3))
        codes.append(rc)
    return max(times), codes, times


def main() -> None:
    cli = [sys.executable, "-m", "brakesqueal"]
    base, base_codes, base_times = worst([sys.executable, "-c", "import time; time.sleep(100)"], [0.5, 1.0, 1.5],
                                         cold=False)
    subprocess.run([*cli, "simulate", "--t-end", "0.01", "--no-progress"], capture_output=True, check=True)  # warm
    cases = [
        ("Ctrl-C latency, simulate, cold caches", [*cli, "simulate", "--t-end", "200", "--no-progress"],
         [1.5, 3.0, 4.5, 6.0], True),
        ("Ctrl-C latency, simulate, warm cache", [*cli, "simulate", "--t-end", "200", "--no-progress"], [3.0, 5.0],
         False),
        ("Ctrl-C latency, reproduce all, warm cache", [*cli, "reproduce", "all", "--out", "R", "--no-progress"],
         [3.0, 6.0], False),
    ]
    results = []
    for metric, cmd, delays, cold in cases:
        t, codes, times = worst(cmd, delays, cold=cold)
        results.append(BenchResult(metric, t, "s", base, t / base,
                                   {"interrupted after [s]": delays, "latencies [s]": times, "exit statuses": codes,
                                    "baseline latencies [s]": base_times, "target": "<= 1 s, status 130"}))
    emit(results)


if __name__ == "__main__":
    main()
