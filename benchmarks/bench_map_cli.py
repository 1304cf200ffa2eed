"""End-to-end ``brakesqueal map`` as a user runs it: wall time and peak RSS of a fresh process (warm cache).

Commands (paper-fig2, 1e6 points)::

    brakesqueal map --x k_ip=1e5:1e10:1000:log --y mu=0.05:1:1000 --out m.nc [--no-eigen] [--plot m.png]

The baseline, run in the same session, is the in-memory route the command
used before (``stability_map(...).to_netcdf(...)`` through an xarray Dataset,
in a fresh interpreter with the same imports).  Best of ``--repeat`` runs;
peak RSS from :func:`os.wait4`.

Run by ``make bench`` (``python -m benchmarks``) or directly:
``python benchmarks/bench_map_cli.py [--repeat N]``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, emit, user_env  # noqa: E402

X, Y = "k_ip=1e5:1e10:1000:log", "mu=0.05:1:1000"
_DATASET = ("import sys\n"
            "from brakesqueal.analysis.maps import parse_axis, stability_map\n"
            "from brakesqueal.model import resolve_space\n"
            "m = stability_map(resolve_space(None, 'paper-fig2'), parse_axis(sys.argv[1]), parse_axis(sys.argv[2]),"
            " eigen=sys.argv[4] == '1')\n"
            "m.to_netcdf(sys.argv[3])\n")


def measure(cmd: list[str], env: dict[str, str], repeat: int) -> tuple[float, float]:
    """Best wall time [s] and the largest peak RSS [MB] of ``repeat`` runs of ``cmd`` (CPU time in ``CPU``)."""
    best, rss, cpu = float("inf"), 0.0, float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        _, status, ru = os.wait4(p.pid, 0)
        dt = time.perf_counter() - t0
        p.returncode = os.waitstatus_to_exitcode(status)
        if p.returncode:
            raise RuntimeError(f"{' '.join(cmd)} failed: {p.stderr.read().decode() if p.stderr else ''}")
        best, rss, cpu = min(best, dt), max(rss, ru.ru_maxrss / 1024), min(cpu, ru.ru_utime + ru.ru_stime)
    CPU.append(cpu)
    return best, rss


#: CPU time (user + system, best run) of each :func:`measure` call, in order (wall times suffer on a loaded machine).
CPU: list[float] = []


def run(repeat: int = 3) -> list[BenchResult]:
    res = []
    with tempfile.TemporaryDirectory() as d:
        env = user_env(BRAKESQUEAL_CACHE_DIR=os.path.join(d, "cache"))
        cli = [sys.executable, "-m", "brakesqueal", "map", "--x", X, "--y", Y, "--out", os.path.join(d, "m.nc")]
        measure(cli, env, 1)  # fills the cache (code generation, numba)
        for label, extra, eigen, target in (("with max_real and frequency", [], "1", "<= 1.5 s, <= 250 MB"),
                                            ("--no-eigen", ["--no-eigen"], "0", "<= 1 s")):
            t, rss = measure(cli + extra, env, repeat)
            tb, rssb = measure([sys.executable, "-c", _DATASET, X, Y, os.path.join(d, "b.nc"), eigen], env, repeat)
            res.append(BenchResult(f"brakesqueal map 1e6 points {label}: wall time", t, "s", tb, tb / t,
                                   {"peak_rss_MB": round(rss), "baseline_peak_rss_MB": round(rssb),
                                    "cpu_s": round(CPU[-2], 3), "baseline_cpu_s": round(CPU[-1], 3),
                                    "baseline": "stability_map(...).to_netcdf(...) (xarray Dataset) in a fresh "
                                                "interpreter", "target": target}))
        t, rss = measure(cli + ["--plot", os.path.join(d, "m.png")], env, repeat)
        t0, _ = measure(cli, env, repeat)
        res.append(BenchResult("brakesqueal map 1e6 points --plot: wall time", t, "s", t0, None,
                               {"peak_rss_MB": round(rss), "plot_adds_s": round(t - t0, 3),
                                "cpu_s": round(CPU[-2], 3), "plot_adds_cpu_s": round(CPU[-2] - CPU[-1], 3),
                                "baseline": "same command without --plot", "target": "plot adds <= 1 s"}))
    return res


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=3)
    emit(run(ap.parse_args().repeat))
