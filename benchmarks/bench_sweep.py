"""Sweep throughput in-process and on a local Dask cluster; peak memory.

Measured in one run (nothing here is asserted by the test suite):

* the in-process kernel: :func:`brakesqueal.sweep.compute.compute_chunk` over every chunk of a
  3-D verdict-only study, no store (the baseline);
* the same study through :func:`brakesqueal.sweep.sweep` in-process (Zarr store, markers);
* the same study on a ``LocalCluster`` with 1 and 2 single-threaded workers,
  after one warm-up chunk per worker (numba loads per process), and cold
  (cluster start included);
* optionally a 1e8-point 3-D study in a fresh subprocess, reporting that
  process's peak RSS (``resource.getrusage``).

Run by ``make bench`` (``python -m benchmarks``) or directly:
``python benchmarks/bench_sweep.py [--points N] [--no-large]``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, emit  # noqa: E402


def grid_study(points: int, *, chunk_points: int = 1 << 22, quantities: tuple[str, ...] = ("stable",)
               ) -> dict[str, Any]:
    """A 3-D paper-fig2 study (Omega x mu x k_ip) of about ``points`` points."""
    n = max(2, round((points / 100) ** 0.5))
    n_om = max(2, round(points / n / n))
    return {"name": f"bench-{n_om}x{n}x{n}", "preset": "paper-fig2",
            "axes": {"Omega": f"10:1000:{n_om}:log", "mu": f"0.05:1:{n}", "k_ip": f"1e5:1e10:{n}:log"},
            "compute": {"quantities": list(quantities)}, "execution": {"chunk_points": chunk_points}}


_CHILD = r"""
import json, resource, sys, time
from brakesqueal.sweep import sweep
study, store = json.loads(sys.argv[1]), sys.argv[2]
t0 = time.perf_counter()
ds = sweep(study, store=store, overwrite=True)
t = time.perf_counter() - t0
print(json.dumps({"seconds": t, "points": int(ds["stable"].size),
                  "peak_rss_bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
                  "stable_fraction": float(ds["stable"].mean().compute())}))
"""


def _large(tmp: Path) -> dict[str, Any]:
    study = grid_study(10**8, chunk_points=1 << 22)
    proc = subprocess.run([sys.executable, "-c", _CHILD, json.dumps(study), str(tmp / "large.zarr")],
                          capture_output=True, text=True, check=True)
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    out["study"] = study
    return out


def _coords(study: Any, chunk: int) -> dict[str, Any]:
    """The coordinate values of one chunk of a study."""
    region = study.region(chunk)
    if study.kind == "grid":
        return {a.name: a.values[r] for a, r in zip(study.axes, region)}
    return {n: v[region[0]] for n, v in study.samples().items()}


def _measure(study_dict: dict[str, Any], tmp: Path, tag: str) -> dict[str, Any]:
    """Kernel-only, in-process sweep, and 1 / 2 worker LocalCluster sweeps of one study."""
    from distributed import Client, get_task_stream

    from brakesqueal.sweep import load_study, sweep
    from brakesqueal.sweep.compute import ChunkSpec, compute_chunk
    from brakesqueal.sweep.runner import local_cluster

    study = load_study(study_dict)
    spec = ChunkSpec.from_study(study)
    n = study.n_points
    compute_chunk(spec, _coords(study, 0))  # compile / load
    sweep(grid_study(1000), store=tmp / f"{tag}-warm.zarr", overwrite=True)  # imports, codecs
    t0 = time.perf_counter()
    for c in range(study.n_chunks):
        compute_chunk(spec, _coords(study, c))
    t_kernel = time.perf_counter() - t0
    t0 = time.perf_counter()
    sweep(study, store=tmp / f"{tag}-inproc.zarr", overwrite=True)
    t_inproc = time.perf_counter() - t0
    out: dict[str, Any] = {"points": n, "chunks": study.n_chunks, "dims": dict(zip(study.dims, study.shape)),
                           "kernel_s": t_kernel, "inproc_s": t_inproc}
    for w in (1, 2):
        t0 = time.perf_counter()
        with local_cluster(w) as cluster, Client(cluster) as client:
            t_start = time.perf_counter() - t0
            client.run(lambda: compute_chunk(spec, _coords(study, 0)) and None)  # warm every worker
            t_warm = time.perf_counter() - t0 - t_start
            t1 = time.perf_counter()
            with get_task_stream(client) as ts:
                sweep(study, store=tmp / f"{tag}-w{w}.zarr", client=client, overwrite=True)
            t_run = time.perf_counter() - t1
        busy = sum(ss["stop"] - ss["start"] for task in ts.data for ss in task["startstops"]
                   if ss["action"] == "compute")
        out[f"w{w}"] = {"seconds": t_run, "cluster_start_s": t_start, "warmup_s": t_warm, "worker_compute_s": busy}
    return out


def bench_sweep(*, points: int = 20_000_000, large: bool = True) -> list[BenchResult]:
    """Throughput in-process vs. 1 and 2 local Dask workers (3-D studies); peak memory of a 1e8-point study."""
    tmp = Path(tempfile.mkdtemp(prefix="brakesqueal-bench-sweep-"))
    try:
        res: list[BenchResult] = []
        if large:  # first, in its own process
            big = _large(tmp)
            res.append(BenchResult(
                "sweep: 1e8-point 3-D study (verdict only) in a fresh process, into Zarr",
                big["points"] / big["seconds"], "points/s", math.nan, math.nan,
                {"seconds_incl_imports_and_kernel_build": round(big["seconds"], 2),
                 "peak_rss_GiB": round(big["peak_rss_bytes"] / 2**30, 3), "target_peak_GiB": 2,
                 "axes": big["study"]["axes"], "stable_fraction": round(big["stable_fraction"], 4)}))
        work = {"verdict only": grid_study(points),
                "stable+margin+max_real+frequency": grid_study(max(points // 40, 1000), chunk_points=1 << 15,
                                                               quantities=("stable", "margin", "max_real",
                                                                           "frequency"))}
        for label, sd in work.items():
            m = _measure(sd, tmp, "v" if label == "verdict only" else "f")
            n = m["points"]
            kern = n / m["kernel_s"]
            w1, w2 = m["w1"], m["w2"]
            per_worker = n / w1["worker_compute_s"]
            common = {"points": n, "chunks": m["chunks"], "dims": m["dims"]}
            res += [
                BenchResult(f"sweep [{label}]: in-process kernel (compute_chunk loop, no store)", kern, "points/s",
                            kern, 1.0, {**common, "seconds": round(m["kernel_s"], 3)}),
                BenchResult(f"sweep [{label}]: in-process sweep (Zarr + markers) vs kernel", n / m["inproc_s"],
                            "points/s", kern, n / m["inproc_s"] / kern, {"seconds": round(m["inproc_s"], 3)}),
                BenchResult(f"sweep [{label}]: 1 worker, per-worker compute throughput vs kernel", per_worker,
                            "points/s", kern, per_worker / kern,
                            {"worker_compute_s": round(w1["worker_compute_s"], 3), "target": "ratio >= 0.8",
                             "end_to_end_points_per_s": round(n / w1["seconds"]),
                             "end_to_end_s": round(w1["seconds"], 3),
                             "cluster_start_s": round(w1["cluster_start_s"], 2),
                             "worker_warmup_s": round(w1["warmup_s"], 2)}),
                BenchResult(f"sweep [{label}]: 2 workers vs 1 worker, end to end", n / w2["seconds"], "points/s",
                            n / w1["seconds"], w1["seconds"] / w2["seconds"],
                            {"seconds": round(w2["seconds"], 3), "cpu_count": os.cpu_count(),
                             "per_worker_compute_points_per_s": round(n / w2["worker_compute_s"] * 2),
                             "note": "2 vCPU (about 1 core of compute) shared by 2 workers and the writing client"}),
            ]
        return res
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--points", type=int, default=20_000_000, help="points of the scaling study (3-D, verdict only)")
    ap.add_argument("--no-large", action="store_true", help="skip the 1e8-point peak-memory study")
    a = ap.parse_args()
    emit(bench_sweep(points=a.points, large=not a.no_large))
