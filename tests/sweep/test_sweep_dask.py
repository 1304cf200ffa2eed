"""Parameter studies on a Dask cluster and after SIGKILL: same results as an uninterrupted in-process run."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

xr = pytest.importorskip("xarray")
pytest.importorskip("zarr")
distributed = pytest.importorskip("distributed")

from brakesqueal.sweep import load_study, sweep, sweep_status  # noqa: E402
from brakesqueal.sweep.store import MARKERS  # noqa: E402

EIGEN = ["stable", "margin", "max_real", "frequency"]


def assert_same(a, b) -> None:
    xr.testing.assert_identical(a.load().drop_attrs(deep=False), b.load().drop_attrs(deep=False))
    assert {k: v for k, v in a.attrs.items() if k != "created"} == {k: v for k, v in b.attrs.items() if k != "created"}


@pytest.mark.slow
def test_local_cluster_two_workers_identical_to_in_process(tmp_path):
    grid = {"name": "cluster", "preset": "paper-fig2",
            "axes": {"Omega": {"values": [20.0, 60.0]}, "mu": "0.05:1:20", "k_ip": "1e5:1e10:30:log"},
            "compute": {"quantities": EIGEN}, "execution": {"chunk_points": 150}}
    samples = {"name": "cluster-s", "preset": "paper-fig3", "tied": {"mu2": "1 - mu1"},
               "samples": {"method": "lhs", "n": 300, "seed": 1,
                           "ranges": {"mu1": "0.1:0.9", "k_ip": "1e6:1e10:log"}},
               "compute": {"quantities": ["stable", "max_real", "critical_speed"]},
               "execution": {"chunk_points": 64}}
    ref_g = sweep(grid, store=tmp_path / "g-ref.zarr")
    ref_s = sweep(samples, store=tmp_path / "s-ref.zarr")
    g = sweep(grid, store=tmp_path / "g.zarr", workers=2)  # brakesqueal's LocalCluster (--workers 2)
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    try:  # a plain LocalCluster, as a user's existing cluster
        with distributed.Client(cluster) as client:
            assert len(client.nthreads()) == 2
            s = sweep(samples, store=tmp_path / "s.zarr", client=client)
            seen = client.run(lambda: 1)
    finally:
        cluster.close()
    assert len(seen) == 2
    assert load_study(grid).n_chunks == 8 and load_study(samples).n_chunks == 5
    assert_same(ref_g, g)
    assert_same(ref_s, s)
    assert np.isfinite(s["critical_speed"].values).any()


STUDY = """\
name = "killed"
preset = "paper-fig2"
[axes]
Omega = "20:200:6:log"
mu = "0.05:1:50"
k_ip = "1e5:1e10:600:log"
[compute]
quantities = ["stable", "margin", "max_real", "frequency"]
[execution]
chunks = {{ Omega = 1, mu = 10 }}
[output]
store = "{store}"
"""


def _markers(store: Path) -> dict[str, int]:
    d = store / MARKERS
    return {p.name: p.stat().st_mtime_ns for p in d.glob("[0-9]*.json")} if d.is_dir() else {}


@pytest.mark.slow
def test_sigkill_then_resume_loses_nothing(tmp_path):
    f = tmp_path / "study.toml"
    f.write_text(STUDY.format(store="killed.zarr"))
    store = tmp_path / "killed.zarr"
    st = load_study(f)
    assert st.n_chunks == 30
    cmd = [sys.executable, "-m", "brakesqueal", "sweep", str(f), "--no-progress"]
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 60
        while len(_markers(store)) < 4:
            assert proc.poll() is None, proc.stderr.read().decode()
            assert time.monotonic() < deadline, "no chunk completed within 60 s"
            time.sleep(0.005)
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait()
    assert proc.returncode == -signal.SIGKILL
    done = _markers(store)
    assert 4 <= len(done) < st.n_chunks - 5, f"the study was nearly finished when killed ({len(done)} chunks)"
    status = sweep_status(f)
    assert len(status.completed) == len(done) and not status.corrupt
    # resume in a new process: only the missing chunks are computed, completed ones are kept as they are
    r = subprocess.run(cmd + ["--format", "json"], env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    summary = json.loads(r.stdout)
    assert summary["reused_chunks"] == len(done) and summary["computed_chunks"] == st.n_chunks - len(done)
    after = _markers(store)
    assert all(after[k] == v for k, v in done.items())
    assert sweep_status(f).complete
    ref = sweep(f, store=tmp_path / "uninterrupted.zarr")
    resumed = xr.open_zarr(store, consolidated=False)
    assert_same(ref, resumed)
