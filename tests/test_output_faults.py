"""Fault injection per output kind, at command level: a full disk never leaves a truncated or lost file.

Every command that writes a file is run in a fresh process whose file-size
limit (``RLIMIT_FSIZE``) is a few KiB: any write beyond it fails with
``EFBIG`` inside whatever library writes the file (NetCDF, PNG, WAV, text),
exactly as a full disk does part-way through.  Python ignores ``SIGXFSZ``,
so the failure surfaces as an ``OSError`` in the writer.  Required: exit
status 2, one line on stderr naming the option and the file, the file that
was there before unchanged, and no temporary file left behind.  The code
cache is warmed first without the limit (the cache has its own fault tests
in test_cache_faults.py).
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest

LIMIT = 4096  # bytes: every output below is larger

CASES = {
    "map --out": (["map", "--x", "k_ip=1e5:1e10:80:log", "--y", "mu=0.05:1:80", "--no-eigen"], "--out", "m.nc"),
    "map --plot": (["map", "--x", "k_ip=1e5:1e10:8:log", "--y", "mu=0.05:1:8", "--no-eigen", "--out", "small.nc"],
                   "--plot", "m.png"),  # the NetCDF file (with its boundary) fits below the limit, the figure does not
    "crossings --plot": (["crossings", "--along", "k_ip=1e5:1e10:log", "--set", "mu=0.5"], "--plot", "c.png"),
    "critical-speed --plot": (["critical-speed", "--preset", "paper-fig3", "--set", "mu1=0.6", "--set", "mu2=0.4"],
                              "--plot", "o.png"),
    "modes --out": (["modes", "--along", "k_ip=1e5:1e10:log"], "--out", "modes.nc"),
    "simulate --out": (["simulate", "--t-end", "0.02", "--no-progress"], "--out", "s.nc"),
    "simulate --wav": (["simulate", "--t-end", "0.1", "--no-progress"], "--wav", "s.wav"),
    "export --out": (["export", "--to", "c", "--what", "nonlinear"], "--out", "model.c"),
}


def _run(args: list[str], cwd: Path, limit: int | None) -> subprocess.CompletedProcess[str]:
    def cap() -> None:
        if limit is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    env = {**os.environ, "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, "-m", "brakesqueal", *args], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=600, preexec_fn=cap)


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(CASES))
def test_a_full_disk_keeps_the_old_file_and_says_so_in_one_line(tmp_path, case):
    args, option, name = CASES[case]
    warm = _run([*args, option, "warm" + Path(name).suffix], tmp_path, None)  # fills the code cache; no limit
    assert warm.returncode == 0, warm.stderr
    assert (tmp_path / ("warm" + Path(name).suffix)).stat().st_size > LIMIT  # the limit really cuts this output
    target = tmp_path / name
    target.write_bytes(b"the previous result")
    before = sorted(p.name for p in tmp_path.iterdir())
    out = _run([*args, option, name], tmp_path, LIMIT)
    assert out.returncode == 2, (out.returncode, out.stderr[-2000:])
    lines = [ln for ln in out.stderr.splitlines() if ln.strip() and "%" not in ln]  # progress lines aside
    assert len(lines) == 1 and "error" in lines[0] and name in lines[0], out.stderr[-2000:]
    assert target.read_bytes() == b"the previous result"
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # no temporary or partial file left


@pytest.mark.slow
def test_reproduce_on_a_full_disk_keeps_the_whole_previous_set(tmp_path):
    """The figure's files form one set: a write failing part-way (the PNG fits, the NetCDF does not) replaces none."""
    warm = _run(["reproduce", "fig2", "--out", "warm", "--no-progress"], tmp_path, None)
    assert warm.returncode == 0, warm.stderr
    sizes = {p.name: p.stat().st_size for p in (tmp_path / "warm").iterdir()}
    assert sorted(sizes) == ["fig2.csv", "fig2.json", "fig2.nc", "fig2.png"]
    limit = 1 << 20
    assert sizes["fig2.png"] < limit < sizes["fig2.nc"]  # some files of the set fit, others do not
    out_dir = tmp_path / "R"
    out_dir.mkdir()
    for name in sizes:
        (out_dir / name).write_text(f"previous {name}")
    out = _run(["reproduce", "fig2", "--out", "R", "--no-progress"], tmp_path, limit)
    assert out.returncode == 2, (out.returncode, out.stderr[-2000:])
    lines = [ln for ln in out.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "error" in lines[0] and "'R'" in lines[0] and "unchanged" in lines[0], out.stderr
    assert {p.name: p.read_text() for p in out_dir.iterdir()} == {n: f"previous {n}" for n in sizes}
    rerun = _run(["reproduce", "fig2", "--out", "R", "--no-progress"], tmp_path, None)  # and a later run succeeds
    assert rerun.returncode == 0, rerun.stderr
    new = {p.name: p.stat().st_size for p in out_dir.iterdir()}
    assert sorted(new) == sorted(sizes) and all(new[n] == sizes[n] for n in ("fig2.png", "fig2.nc", "fig2.csv"))
