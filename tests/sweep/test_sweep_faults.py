"""Fault injection for sweep stores (issue 11).

Every scenario ends with a run that must complete, and the resulting store is
compared file by file (bytes; JSON minus the creation time) with a reference
store computed here by an uninterrupted in-process run:

* SIGKILL of real ``brakesqueal sweep`` processes at random moments during
  store creation and during computation, then resume;
* deleting / corrupting each kind of file (metadata, coordinate chunk, data
  chunk, marker, creation record, whole arrays), then ``--status`` and resume;
* two processes on one fresh store and on one partially computed store;
* ENOSPC injected at random write counts (plain and torn writes), and a real
  full tmpfs when mounting is permitted;
* unwritable output locations, oversize studies and bad scheduler addresses:
  one error line, before anything is computed.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import tracemalloc
import zlib
from pathlib import Path

import numpy as np
import pytest

xr = pytest.importorskip("xarray")
pytest.importorskip("zarr")
pytest.importorskip("distributed")

import brakesqueal.sweep.runner as runner  # noqa: E402
import brakesqueal.sweep.store as store_mod  # noqa: E402
from brakesqueal.cli import main  # noqa: E402
from brakesqueal.errors import BrakesquealError, ParameterError  # noqa: E402
from brakesqueal.sweep import StoreError, load_study, open_sweep, sweep, sweep_status  # noqa: E402
from brakesqueal.sweep.lock import StoreLock, lock_holder, lock_path  # noqa: E402
from brakesqueal.sweep.runner import check_scheduler_address  # noqa: E402
from brakesqueal.sweep.store import MANIFEST, MARKERS  # noqa: E402
from brakesqueal.sweep.study import MAX_AXIS_POINTS, MAX_CHUNK_POINTS, MAX_CHUNKS, MAX_POINTS  # noqa: E402

GRID = """\
name = "faults"
preset = "paper-fig2"
[axes]
Omega = {{ values = [20, 50.26548245743669, 100] }}
mu = "0.05:1:24"
k_ip = "1e5:1e10:40:log"
[compute]
quantities = ["stable", "margin", "max_real", "frequency"]
[execution]
chunks = {{ Omega = 1, mu = 4 }}
[output]
store = "{store}"
"""

SAMPLES = """\
name = "faults-s"
preset = "paper-fig3"
[tied]
mu2 = "1 - mu1"
[samples]
method = "lhs"
n = 1200
seed = 7
[samples.ranges]
mu1 = "0.1:0.9"
k_ip = "1e6:1e10:log"
[compute]
quantities = ["stable", "max_real"]
[execution]
chunk_points = 200
[output]
store = "{store}"
"""

# A real `brakesqueal sweep` whose file writes are slowed down (BSQ_WRITE_DELAY seconds each), so that
# kills land in the creation or computation phase as chosen; the computation itself is untouched.
DRIVER = r"""
import os, sys, time
import brakesqueal.sweep.store as store
delay = float(os.environ.get("BSQ_WRITE_DELAY", "0"))
orig = store.write_file
def slow(path, data):
    time.sleep(delay)
    orig(path, data)
store.write_file = slow
from brakesqueal.cli import main
sys.exit(main(sys.argv[1:]))
"""


# ---------------------------------------------------------------- helpers
@pytest.fixture(scope="module")
def ref(tmp_path_factory):
    """Study files and their reference stores (uninterrupted in-process runs)."""
    d = tmp_path_factory.mktemp("ref")
    out = {}
    for tag, text in (("grid", GRID), ("samples", SAMPLES)):
        f = d / f"{tag}.toml"
        f.write_text(text.format(store=f"{tag}.zarr"))
        sweep(f, store=d / f"{tag}-ref.zarr")
        out[tag] = (f, d / f"{tag}-ref.zarr")
    (d / "driver.py").write_text(DRIVER)
    out["driver"] = d / "driver.py"
    return out


def files(p: Path) -> dict[str, Path]:
    return {f.relative_to(p).as_posix(): f for f in p.rglob("*") if f.is_file()}


def _without_created(key: str, data: bytes) -> object:
    j = json.loads(data)
    if key == "zarr.json":
        j["attributes"].pop("created")
    if key == MANIFEST:
        j.pop("created")
        j.pop("record_sha256")
        root = json.loads(j["nodes"].pop("zarr.json"))
        root["attributes"].pop("created")
        j["root"] = root
    return j


def assert_bit_identical(store: Path, reference: Path) -> None:
    """Same files with the same bytes (root metadata and creation record: same JSON except the creation time)."""
    a, b = files(store), files(reference)
    assert sorted(a) == sorted(b)
    for k in a:
        da, db = a[k].read_bytes(), b[k].read_bytes()
        if k in ("zarr.json", MANIFEST):
            assert _without_created(k, da) == _without_created(k, db), k
        else:
            assert da == db, k
    assert open_sweep(store)["stable"].dims == open_sweep(reference)["stable"].dims  # opens (after any repair)
    assert not lock_path(store).exists()
    assert not [p for p in store.parent.iterdir() if p.name.startswith(f".{store.name}.")]


def one_line(err: str, *needles: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("brakesqueal: error: ")
    for n in needles:
        assert n in lines[0], (n, lines[0])
    return lines[0]


def count_computes(monkeypatch) -> list[int]:
    calls: list[int] = []
    orig = runner.compute_chunk
    monkeypatch.setattr(runner, "compute_chunk", lambda spec, coords: calls.append(1) or orig(spec, coords))
    return calls


def no_compute(monkeypatch) -> None:
    def fail(*a):
        raise AssertionError("a chunk was computed")

    monkeypatch.setattr(runner, "compute_chunk", fail)


def driver(ref, *args: str, delay: float = 0.0) -> subprocess.Popen:
    env = {**os.environ, "BSQ_WRITE_DELAY": str(delay), "PYTHONUNBUFFERED": "1"}
    return subprocess.Popen([sys.executable, str(ref["driver"]), "sweep", *args, "--no-progress"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def n_markers(store: Path) -> int:
    return len(list((store / MARKERS).glob("[0-9]*.json"))) if (store / MARKERS).is_dir() else 0


def wait_for(cond, proc: subprocess.Popen, what: str, timeout: float = 60) -> None:
    deadline = time.monotonic() + timeout
    while not cond():
        assert proc.poll() is None, f"finished before {what}: {proc.communicate()}"
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.001)


def kill(proc: subprocess.Popen) -> None:
    os.kill(proc.pid, signal.SIGKILL)
    proc.communicate()
    assert proc.returncode == -signal.SIGKILL


# ---------------------------------------------------------------- SIGKILL
@pytest.mark.slow
def test_sigkill_during_creation_and_computation_then_resume_bit_identical(ref, tmp_path, capsys):
    rng = np.random.default_rng(11)
    f, reference = ref["grid"]
    store = tmp_path / "k.zarr"
    n = load_study(f).n_chunks
    creating = lambda: any(p.name.startswith(".k.zarr.creating-") for p in tmp_path.iterdir())  # noqa: E731
    # 1: killed while the skeleton is being created (at a random moment of that phase)
    p = driver(ref, str(f), "--out", str(store), delay=0.02)
    wait_for(lambda: creating() or store.exists(), p, "store creation")
    time.sleep(rng.uniform(0, 0.3))
    kill(p)
    s = sweep_status(f, store=store)
    assert not s.damaged, s.text()  # either no store or a complete skeleton: never a half-made one
    assert not s.complete
    # 2-3: killed at random moments while chunks are computed (some markers already written)
    done_before = -1
    for _ in range(2):
        k = n_markers(store) + int(rng.integers(1, 5))
        p = driver(ref, str(f), "--out", str(store), delay=0.01)
        wait_for(lambda: n_markers(store) >= k, p, f"{k} markers")
        time.sleep(rng.uniform(0, 0.05))
        kill(p)
        assert lock_path(store).exists()  # left behind by the killed run: must count as stale
        s = sweep_status(f, store=store)
        assert not s.damaged and not s.corrupt and s.in_use is None
        assert done_before <= len(s.completed) < n
        done_before = len(s.completed)
    # resume: only the missing chunks are computed
    capsys.readouterr()
    assert main(["sweep", str(f), "--out", str(store), "--format", "json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["reused_chunks"] == done_before and out["computed_chunks"] == n - done_before
    assert sweep_status(f, store=store).complete
    assert_bit_identical(store, reference)


# ---------------------------------------------------------------- concurrent runs
@pytest.mark.slow
def test_two_runs_on_a_fresh_store_exactly_one_runs(ref, tmp_path):
    f, reference = ref["grid"]
    store = tmp_path / "c.zarr"
    procs = [driver(ref, str(f), "--out", str(store), "--format", "json", delay=0.02) for _ in range(2)]
    outs = [p.communicate(timeout=120) for p in procs]
    codes = sorted(p.returncode for p in procs)
    assert codes == [0, 2], outs
    win = next(i for i, p in enumerate(procs) if p.returncode == 0)
    lose = 1 - win
    one_line(outs[lose][1], f"store '{store}' is in use by PID {procs[win].pid} (started ")
    assert json.loads(outs[win][0])["computed_chunks"] == load_study(f).n_chunks
    assert_bit_identical(store, reference)


@pytest.mark.slow
def test_two_resumes_of_a_partial_store_exactly_one_computes(ref, tmp_path, monkeypatch, capsys):
    f, reference = ref["grid"]
    store = tmp_path / "p.zarr"
    n = load_study(f).n_chunks
    inject = FailingWrites(fail_at=40)  # about a third of the chunks, then a full disk
    monkeypatch.setattr(store_mod, "write_file", inject)
    assert main(["sweep", str(f), "--out", str(store), "--no-progress"]) == 2
    monkeypatch.undo()
    done = len(sweep_status(f, store=store).completed)
    assert 0 < done < n
    procs = [driver(ref, str(f), "--out", str(store), "--format", "json", delay=0.02) for _ in range(2)]
    outs = [p.communicate(timeout=120) for p in procs]
    assert sorted(p.returncode for p in procs) == [0, 2], outs
    win = next(i for i, p in enumerate(procs) if p.returncode == 0)
    one_line(outs[1 - win][1], "is in use by PID", str(procs[win].pid))
    out = json.loads(outs[win][0])
    assert out["computed_chunks"] == n - done and out["reused_chunks"] == done
    assert_bit_identical(store, reference)


def test_lock_stale_live_foreign_and_without_flock(ref, tmp_path, monkeypatch):
    import brakesqueal.sweep.lock as lock_mod

    store = tmp_path / "l.zarr"
    lp = lock_path(store)
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    host = socket.gethostname()
    # a lock file of a dead process, an empty one (killed while taking it): taken over
    for text in (json.dumps({"pid": dead.pid, "host": host, "started": "x"}), ""):
        lp.write_text(text)
        assert lock_holder(store) is None
        with StoreLock(store):
            assert json.loads(lp.read_text())["pid"] == os.getpid()
        assert not lp.exists()
    # a live holder in another process (holds the flock): refused with its PID; status names it
    code = ("import sys, time; from pathlib import Path; from brakesqueal.sweep.lock import StoreLock; "
            f"l = StoreLock(Path({str(store)!r})); l.acquire(); print('locked', flush=True); time.sleep(60)")
    holder = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(StoreError, match=rf"is in use by PID {holder.pid} \(started "):
            StoreLock(store).acquire()
        assert lock_holder(store).pid == holder.pid
        assert f"in use by PID {holder.pid} (started " in sweep_status(ref["grid"][0], store=store).text()
        # without flock (e.g. some network file systems) the PID decides: alive -> refused
        monkeypatch.setattr(lock_mod, "_flock", lambda fd: None)
        with pytest.raises(StoreError, match=f"PID {holder.pid}"):
            StoreLock(store).acquire()
    finally:
        holder.kill()
        holder.wait()
    # ... and dead -> taken over (the kernel dropped the flock anyway)
    with StoreLock(store):
        pass
    monkeypatch.undo()
    # a lock taken on another host cannot be checked: refused, naming the host and the file to delete
    lp.write_text(json.dumps({"pid": 1, "host": "elsewhere.example", "started": "2026-01-01T00:00:00"}))
    with pytest.raises(StoreError, match=r"in use by PID 1 on host elsewhere.example .*delete"):
        StoreLock(store).acquire()
    lp.unlink()


# ---------------------------------------------------------------- damaged files
def _damage(p: Path, action: str, rng: np.random.Generator) -> None:
    if action == "delete":
        shutil.rmtree(p) if p.is_dir() else p.unlink()
        return
    data = bytearray(p.read_bytes())
    mode = rng.integers(3)
    if mode == 0:
        p.write_bytes(bytes(data[: len(data) // 2]))  # truncated
    elif mode == 1:
        p.write_bytes(rng.bytes(max(len(data), 8)))  # garbage
    else:
        i = int(rng.integers(len(data)))
        data[i] ^= 0x20  # one flipped bit
        p.write_bytes(bytes(data))


def _pick(store: Path, kind: str, rng: np.random.Generator, study) -> tuple[Path, int | None]:
    """A file (or directory) of ``kind`` and the number of chunks its damage makes recompute (None: any >= 1)."""
    coords = list(store_mod.coordinates(study))
    data = ["stable", "status", *[q for q in ("margin", "max_real", "frequency") if q in study.quantities]]
    choose = lambda seq: seq[int(rng.integers(len(seq)))]  # noqa: E731
    if kind == "root-metadata":
        return store / "zarr.json", 0
    if kind == "data-metadata":
        return store / choose(data) / "zarr.json", 0
    if kind == "coord-metadata":
        return store / choose(coords) / "zarr.json", 0
    if kind == "markers-metadata":
        return store / MARKERS / "zarr.json", 0
    if kind == "record":
        return store / MANIFEST, 0
    if kind == "coord-chunk":
        return choose(sorted(f for c in coords for f in (store / c / "c").rglob("*") if f.is_file())), 0
    if kind == "data-chunk":
        return choose(sorted(f for v in data for f in (store / v / "c").rglob("*") if f.is_file())), 1
    if kind == "marker":
        return choose(sorted((store / MARKERS).glob("[0-9]*.json"))), 1
    if kind == "data-array":
        v = choose(data)
        return store / v, sum(1 for f in (store / v / "c").rglob("*") if f.is_file())
    if kind == "markers-dir":
        return store / MARKERS, study.n_chunks
    raise AssertionError(kind)


KINDS = ["root-metadata", "data-metadata", "coord-metadata", "markers-metadata", "record", "coord-chunk",
         "data-chunk", "marker"]


# every kind on the grid study; on the sampled study the kinds whose files differ (chunked coordinates)
CASES = [("grid", k) for k in KINDS + ["data-array", "markers-dir"]] + \
        [("samples", k) for k in ("coord-metadata", "coord-chunk", "data-chunk", "marker", "record")]


@pytest.mark.slow
@pytest.mark.parametrize(("tag", "kind"), CASES)
def test_damaged_file_status_then_resume(ref, tmp_path, monkeypatch, capsys, tag, kind):
    rng = np.random.default_rng(zlib.crc32(f"{tag}/{kind}".encode()))
    f, reference = ref[tag]
    study = load_study(f)
    actions = ["delete"] if kind in ("data-array", "markers-dir") else ["delete", "corrupt"]
    for action in actions:
        store = tmp_path / f"{action}.zarr"
        shutil.copytree(reference, store)
        target, recompute = _pick(store, kind, rng, study)
        _damage(target, action, rng)
        capsys.readouterr()
        assert main(["sweep", "--status", str(f), "--out", str(store), "--format", "json"]) == 0
        cap = capsys.readouterr()
        s = json.loads(cap.out)
        damaged = recompute == 0 or kind in ("data-array", "markers-dir")  # metadata lost with the directory
        assert cap.err == "" and s["complete"] is False, (kind, action, s)
        assert bool(s["damaged"]) == damaged
        if recompute:
            assert len(s["missing"]) == recompute
        calls = count_computes(monkeypatch)
        assert main(["sweep", str(f), "--out", str(store), "--format", "json"]) == 0, capsys.readouterr().err
        cap = capsys.readouterr()
        assert cap.err == ""
        out = json.loads(cap.out)
        assert len(calls) == recompute == out["computed_chunks"]
        assert bool(out["repaired"]) == damaged
        monkeypatch.undo()
        assert sweep_status(f, store=store).complete
        assert_bit_identical(store, reference)


def test_legacy_half_created_store_is_repaired_keeping_verified_chunks(ref, tmp_path, monkeypatch, capsys):
    """The reported defect: arrays missing after an interrupted creation (old layout, no creation record)."""
    f, reference = ref["grid"]
    store = tmp_path / "legacy.zarr"
    shutil.copytree(reference, store)
    (store / MANIFEST).unlink()
    root = json.loads((store / "zarr.json").read_text())
    root.pop("consolidated_metadata")  # stores of earlier versions were not consolidated
    (store / "zarr.json").write_text(json.dumps(root))
    lost = sum(1 for p in (store / "stable" / "c").rglob("*") if p.is_file())
    shutil.rmtree(store / "stable")
    (store / "margin" / "zarr.json").unlink()
    markers = {p.name: p.stat().st_mtime_ns for p in (store / MARKERS).glob("[0-9]*.json")}
    assert main(["sweep", "--status", str(f), "--out", str(store)]) == 0
    text = capsys.readouterr().out
    assert "damaged (will be repaired on resume)" in text and "stable/zarr.json" in text
    calls = count_computes(monkeypatch)
    assert main(["sweep", str(f), "--out", str(store)]) == 0
    assert len(calls) == lost > 0  # only the chunks whose 'stable' data were lost
    after = {p.name: p.stat().st_mtime_ns for p in (store / MARKERS).glob("[0-9]*.json")}
    assert sum(after[k] != v for k, v in markers.items()) == lost and set(after) == set(markers)
    assert_bit_identical(store, reference)


def test_unidentifiable_store_one_line_then_overwrite(ref, tmp_path, capsys):
    f, reference = ref["grid"]
    store = tmp_path / "x.zarr"
    shutil.copytree(reference, store)
    (store / MANIFEST).unlink()
    (store / "zarr.json").write_text("{garbage")
    for args in (["sweep", str(f), "--out", str(store)], ["sweep", "--status", str(f), "--out", str(store)]):
        assert main(args) == 2
        one_line(capsys.readouterr().err, "damaged beyond repair", "--overwrite")
    assert main(["sweep", str(f), "--out", str(store), "--overwrite"]) == 0
    assert_bit_identical(store, reference)


# ---------------------------------------------------------------- full disk
class FailingWrites:
    """Stand-in for ``store.write_file`` that fails with ENOSPC at write number ``fail_at`` (optionally torn)."""

    def __init__(self, fail_at: int | None = None, torn: bool = False) -> None:
        self.n, self.fail_at, self.torn = 0, fail_at, torn
        self.orig = store_mod.write_file

    def __call__(self, path: Path, data) -> None:
        self.n += 1
        if self.fail_at is not None and self.n >= self.fail_at:
            if self.torn and self.n == self.fail_at:
                b = bytes(memoryview(data).cast("B"))
                Path(path).write_bytes(b[: len(b) // 2])  # worse than reality: a torn file at the target
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        self.orig(path, data)


def _completed_are_correct(f, store: Path, reference: Path) -> list[int]:
    """The chunks ``--status`` calls complete hold the reference's values; returns them."""
    st = load_study(f)
    s = sweep_status(f, store=store)  # must not raise
    assert not s.corrupt or all(c in s.missing for c in s.corrupt)
    if not s.exists or not s.completed:
        return []
    g = store_mod.open_group(store, store_mod.read_manifest(store), read_only=True)
    r = open_sweep(reference).load()
    for c in s.completed:
        region = st.region(c)
        for v in ("stable", "status", "margin", "max_real", "frequency"):
            np.testing.assert_array_equal(g[v][region], r[v].values[region])
    return s.completed


@pytest.mark.slow
def test_enospc_at_random_writes_then_resume(ref, tmp_path, monkeypatch, capsys):
    f, reference = ref["grid"]
    count = FailingWrites()
    monkeypatch.setattr(store_mod, "write_file", count)
    assert main(["sweep", str(f), "--out", str(tmp_path / "count.zarr")]) == 0
    monkeypatch.undo()
    total = count.n
    assert total > 3 * load_study(f).n_chunks
    rng = np.random.default_rng(7)
    ks = sorted({1, total, *rng.choice(np.arange(2, total), 4, replace=False).tolist()})
    for i, k in enumerate(ks):
        store = tmp_path / f"k{k}.zarr"
        markers_seen: dict[int, int] = {}
        again = [int(rng.integers(1, 30))] if i % 2 else []
        for attempt, fail_at in enumerate((k, *again, None)):  # fail (and fail again while resuming), succeed
            monkeypatch.setattr(store_mod, "write_file", FailingWrites(fail_at, torn=(i + attempt) % 2 == 1))
            capsys.readouterr()
            rc = main(["sweep", str(f), "--out", str(store), "--no-progress"])
            monkeypatch.undo()
            err = capsys.readouterr().err
            if fail_at is None:
                assert rc == 0, err
                break
            if rc == 0:  # the second failure came after the remaining writes
                break
            one_line(err, "no space left on device", str(store))
            assert not lock_path(store).exists()
            good = _completed_are_correct(f, store, reference)
            now = {c: (store / MARKERS / f"{c}.json").stat().st_mtime_ns for c in good}
            assert all(now.get(m) == t for m, t in markers_seen.items())  # no completed chunk lost or rewritten
            markers_seen = now
        assert_bit_identical(store, reference)


@contextlib.contextmanager
def tmpfs(where: Path, size: str, ro: bool = False):
    where.mkdir()
    opts = f"size={size}" + (",ro" if ro else "")
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", opts, "tmpfs", str(where)], capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip(f"mounting a tmpfs is not permitted here ({r.stderr.strip() or r.returncode})")
    try:
        yield where
    finally:
        subprocess.run(["umount", "-l", str(where)], check=False)


def test_real_full_filesystem_then_resume(ref, tmp_path, capsys):
    f, reference = ref["grid"]
    used = sum(-(-p.stat().st_size // 4096) * 4096 for p in files(reference).values())
    with tmpfs(tmp_path / "mnt", f"{int(used * 0.5) // 1024}k") as mnt:
        store = mnt / "full.zarr"
        assert main(["sweep", str(f), "--out", str(store), "--no-progress"]) == 2
        one_line(capsys.readouterr().err, "no space left on device", str(store))
        _completed_are_correct(f, store, reference)
        done = len(sweep_status(f, store=store).completed)
        assert 0 < done < load_study(f).n_chunks
        subprocess.run(["mount", "-o", f"remount,size={4 * used // 1024}k", str(mnt)], check=True)
        assert main(["sweep", str(f), "--out", str(store), "--format", "json"]) == 0
        assert json.loads(capsys.readouterr().out)["reused_chunks"] == done
        assert_bit_identical(store, reference)


# ---------------------------------------------------------------- unwritable locations
@contextlib.contextmanager
def read_only_dir(where: Path, content: Path | None = None):
    """A directory that cannot be written (chmod when not root, else a read-only tmpfs)."""
    if os.geteuid() != 0:
        where.mkdir()
        if content is not None:
            shutil.copytree(content, where / content.name)
        for p in [where, *where.rglob("*")]:
            if p.is_dir():
                p.chmod(0o555)
        try:
            yield where
        finally:
            for p in [where, *where.rglob("*")]:
                if p.is_dir():
                    p.chmod(0o755)
        return
    with tmpfs(where, "4m") as mnt:
        if content is not None:
            shutil.copytree(content, mnt / content.name)
        subprocess.run(["mount", "-o", "remount,ro", str(mnt)], check=True)
        yield mnt


def test_unwritable_out_fails_before_computing(ref, tmp_path, monkeypatch, capsys):
    f, reference = ref["grid"]
    no_compute(monkeypatch)
    plain = tmp_path / "file.txt"
    plain.write_text("x")
    cases = [(plain / "s.zarr", "is not a directory"), (plain, "is a file")]
    for out, needle in cases:
        assert main(["sweep", str(f), "--out", str(out)]) == 2
        one_line(capsys.readouterr().err, needle)
    with read_only_dir(tmp_path / "ro") as ro:
        for out in (ro / "s.zarr", ro / "sub" / "s.zarr"):
            assert main(["sweep", str(f), "--out", str(out)]) == 2
            line = one_line(capsys.readouterr().err, str(ro))
            assert ("read-only file system" in line or "permission denied" in line
                    or (out.parent.name == "sub" and "does not exist" in line))  # parents are never created
            assert not out.exists()
    assert plain.read_text() == "x"


def test_read_only_store_complete_is_read_incomplete_is_refused(ref, tmp_path, monkeypatch, capsys):
    f, reference = ref["grid"]
    part = tmp_path / "part.zarr"
    shutil.copytree(reference, part)
    (part / MARKERS / "3.json").unlink()
    no_compute(monkeypatch)
    with read_only_dir(tmp_path / "ro", reference) as ro:
        assert main(["sweep", str(f), "--out", str(ro / reference.name), "--format", "json"]) == 0
        out = json.loads(capsys.readouterr().out)
        assert out["computed_chunks"] == 0 and out["reused_chunks"] == load_study(f).n_chunks
        assert main(["sweep", str(f), "--out", str(ro / reference.name), "--overwrite"]) == 2
        one_line(capsys.readouterr().err, str(ro))
    with read_only_dir(tmp_path / "ro2", part) as ro:
        assert main(["sweep", str(f), "--out", str(ro / part.name)]) == 2
        one_line(capsys.readouterr().err, str(ro))


# ---------------------------------------------------------------- size limits
def _peak(fn) -> tuple[BaseException | None, int]:
    tracemalloc.start()
    try:
        fn()
        exc = None
    except BrakesquealError as e:
        exc = e
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return exc, peak


def test_oversize_studies_refused_before_allocating(tmp_path, capsys):
    rng = np.random.default_rng(5)
    base = {"preset": "paper-fig2", "compute": {"quantities": ["stable"]}}
    names = ["mu", "k_ip", "Omega"]
    for _ in range(6):  # one axis beyond the per-axis limit, in either syntax
        name = names[int(rng.integers(3))]
        num = int(10 ** rng.uniform(np.log10(MAX_AXIS_POINTS) + 0.01, 15))
        spec = f"1:100:{num}" if rng.random() < 0.5 else {"start": 1, "stop": 100, "num": num}
        exc, peak = _peak(lambda: load_study({**base, "axes": {name: spec, "h": "0.01:0.03:3"}}))
        assert isinstance(exc, ParameterError) and peak < 20e6
        key = f"axes.{name}" + (".num" if isinstance(spec, dict) else "")
        assert f"key '{key}'" in str(exc) and f"{MAX_AXIS_POINTS:.0e}" in str(exc), exc
    # the product of axes beyond the per-study limit (every axis fine)
    exc, peak = _peak(lambda: load_study({**base, "axes": {"mu": "0.1:1:100000", "k_ip": "1e5:1e9:100000:log",
                                                           "Omega": "10:100:1000"}}))
    assert isinstance(exc, ParameterError) and "key 'axes'" in str(exc) and f"{MAX_POINTS:.0e}" in str(exc)
    assert peak < 20e6
    # chunks too large / too many
    big = {**base, "compute": {"quantities": ["stable", "margin"]}, "axes": {"mu": "0.1:1:10000",
                                                                            "k_ip": "1e5:1e9:10000:log"}}
    with pytest.raises(ParameterError, match=rf"key 'execution.chunk_points'.*limit of {MAX_CHUNK_POINTS[1]} points"):
        load_study({**big, "execution": {"chunk_points": 2 * MAX_CHUNK_POINTS[1]}})
    with pytest.raises(ParameterError, match=rf"key 'execution.chunks'.*{re.escape(f'{MAX_CHUNKS:.0e}')} chunks"):
        load_study({**big, "execution": {"chunks": {"mu": 1, "k_ip": 10}}})
    # in memory (no store): refused above the stated limit, without allocating
    exc, peak = _peak(lambda: sweep({**base, "axes": {"mu": "0.1:1:100000", "k_ip": "1e5:1e9:100000:log"}}))
    assert isinstance(exc, ParameterError) and "give a store" in str(exc) and peak < 50e6
    # studies of 1e8+ points (chunked) are still accepted
    for axes, q in (({"Omega": "10:100:100", "mu": "0.1:1:1000", "k_ip": "1e5:1e9:1000:log"}, ["stable"]),
                    ({"Omega": "10:100:1000", "mu": "0.1:1:10000", "k_ip": "1e5:1e9:10000:log"}, ["stable"]),
                    ({"mu": "0.1:1:100000", "k_ip": "1e5:1e9:10000:log"}, ["stable", "margin"])):
        st = load_study({**base, "axes": axes, "compute": {"quantities": q}})
        assert st.n_points >= 1e8 and st.n_chunks <= MAX_CHUNKS
    # the command line: one line naming the axis and the limit
    fbad = tmp_path / "huge.toml"
    fbad.write_text('preset = "paper-fig2"\n[axes]\nmu = { start = 0.1, stop = 1, num = 1000000000000 }\n')
    assert main(["sweep", str(fbad)]) == 2
    one_line(capsys.readouterr().err, "key 'axes.mu.num'", "limit")
    assert not (tmp_path / "huge.zarr").exists()


def test_axis_resolution_refusal_agrees_with_distinct_values():
    """Ranges are refused only near the floating-point resolution; accepted ones have distinct values."""
    rng = np.random.default_rng(3)
    eps = np.finfo(float).eps
    refused = 0
    for _ in range(200):
        log = rng.random() < 0.5
        start = float(10 ** rng.uniform(-3, 6)) * (1 if log or rng.random() < 0.5 else -1)
        stop = start + 10 ** rng.uniform(0, 4) * float(np.spacing(abs(start)))  # 1 to 1e4 units of the last place
        num = int(rng.integers(2, 2000))
        spec = {"start": start, "stop": stop, "num": num, "scale": "log" if log else "linear"}
        if log:  # comfortably resolvable: the log-spaced step is far above the rounding of 10**t
            t = max(1.0, abs(np.log10(start)), abs(np.log10(stop)))
            clear = (np.log10(stop) - np.log10(start)) / (num - 1) > 64 * eps * (t + 1)
        else:
            clear = (stop - start) / (num - 1) > 64 * np.spacing(max(abs(start), abs(stop)))
        try:
            st = load_study({"preset": "paper-fig2", "axes": {"k_ip": spec}, "compute": {"quantities": ["stable"]}})
        except ParameterError as exc:
            assert "floating-point resolution" in str(exc) and "key 'axes.k_ip.num'" in str(exc)
            assert not clear, spec
            refused += 1
            continue
        v = st.axes[0].values  # independent check: np.linspace / np.logspace give distinct, increasing values
        assert v.size == num and np.all(np.diff(v) > 0), spec
    assert refused > 20


# ---------------------------------------------------------------- scheduler addresses
BAD_ADDRESSES = ["garbage-address", "tcp://host", "tcp://:8786", "http://h:8786", "tcp://h:0", "tcp://h:99999",
                 "tcp://h:port", "", "   ", "tcp://a b:8786", "tcp://h:8786/path", "inproc://", "8786"]


def test_scheduler_address_validation(ref, monkeypatch, capsys):
    for a in BAD_ADDRESSES:
        with pytest.raises(ParameterError, match="scheduler"):
            check_scheduler_address(a)
    good = {"tcp://10.0.0.5:8786": "tcp://10.0.0.5:8786", "10.0.0.5:8786": "tcp://10.0.0.5:8786",
            "TLS://sched.example.org:8786": "tls://sched.example.org:8786", "tcp://[::1]:8786": "tcp://[::1]:8786",
            "ws://h:1": "ws://h:1", "inproc://10.0.0.5/123/1": "inproc://10.0.0.5/123/1"}
    for a, want in good.items():
        assert check_scheduler_address(a) == want
    f, _ = ref["grid"]

    def fail(*a, **k):
        raise AssertionError("tried to connect")

    monkeypatch.setattr(runner, "_probe_scheduler", fail)
    for a in ("garbage-address", "tcp://h:99999"):
        assert main(["sweep", str(f), "--out", str(f.parent / "never.zarr"), "--scheduler", a]) == 2
        one_line(capsys.readouterr().err, "--scheduler", "tcp://HOST:PORT")
    assert not (f.parent / "never.zarr").exists()


def test_scheduler_garbage_and_unreachable_fail_in_one_line(ref, tmp_path):
    f, _ = ref["grid"]
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen()
    port = srv.getsockname()[1]

    def serve() -> None:  # answers like a web server, not a Dask scheduler
        with contextlib.suppress(OSError):
            while True:
                c, _ = srv.accept()
                c.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n" * 4)
                c.close()

    threading.Thread(target=serve, daemon=True).start()
    try:
        for args in (["--scheduler", "garbage-address"], ["--scheduler", f"tcp://127.0.0.1:{port}"]):
            r = subprocess.run([sys.executable, "-m", "brakesqueal", "sweep", str(f), "--out",
                                str(tmp_path / "s.zarr"), *args], capture_output=True, text=True, timeout=60)
            assert r.returncode == 2
            one_line(r.stderr, args[1])
            assert not (tmp_path / "s.zarr").exists() and not lock_path(tmp_path / "s.zarr").exists()
    finally:
        srv.close()
    # a refused connection (nothing listens) fails within the connect timeout, in one line
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    free = s.getsockname()[1]
    s.close()
    with pytest.raises(ParameterError, match=rf"cannot reach the Dask scheduler at 'tcp://127.0.0.1:{free}' "
                                             r"within 0.5 s"):
        sweep(f, store=tmp_path / "t.zarr", scheduler=f"tcp://127.0.0.1:{free}", scheduler_timeout=0.5)
    assert not (tmp_path / "t.zarr").exists()


# ---------------------------------------------------------------- consolidated metadata
def test_finished_store_is_consolidated_and_opens_without_warnings(ref, tmp_path, monkeypatch):
    import warnings

    for tag in ("grid", "samples"):
        f, reference = ref[tag]
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            ds = xr.open_zarr(reference)
            assert "consolidated_metadata" in json.loads((reference / "zarr.json").read_text())
            xr.testing.assert_identical(ds.load(), xr.open_zarr(reference, consolidated=False).load())
            ds2 = open_sweep(reference)
            assert list(ds2.data_vars)[:2] == ["stable", "status"]
    # a store without consolidated metadata or creation record (earlier versions) still opens; a resume upgrades it
    f, reference = ref["grid"]
    old = tmp_path / "old.zarr"
    shutil.copytree(reference, old)
    (old / MANIFEST).unlink()
    root = json.loads((old / "zarr.json").read_text())
    root.pop("consolidated_metadata")
    (old / "zarr.json").write_text(json.dumps(root))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        open_sweep(old).load()
    calls = count_computes(monkeypatch)
    sweep(f, store=old)
    assert calls == []
    assert_bit_identical(old, reference)
