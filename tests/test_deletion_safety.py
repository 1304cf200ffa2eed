"""Never delete or replace what is not ours (issue 30): stores, links, pipes, inputs, temporary files, plots.

* ``sweep --overwrite`` deletes only a store brakesqueal made (its marker or creation record); any other
  directory, even one holding a file named ``zarr.json``, is refused in one line and left as it was.
* An output never replaces a symbolic link (nor writes through it) and never replaces a pipe, socket or
  device: refused in one line, before any work.
* An output never replaces an input of the same command (named on the command line, or read by it).
* Temporary files of killed writers are removed by the next write into the directory (only this host's,
  only those whose process has ended); SIGTERM and SIGHUP take the Ctrl-C path (nothing left, exit 128+N).
* A full disk while a figure is written is one line and keeps the old file, in every format.
"""

from __future__ import annotations

import builtins
import errno
import io
import os
import signal
import stat
import subprocess
import sys
import textwrap
import zlib
from pathlib import Path

import numpy as np
import pytest

from brakesqueal.cli import main
from brakesqueal.errors import OutputError
from brakesqueal.outputs import atomic_write, check_output, guard_inputs, remove_stale_parts, write_set

STUDY = 'preset = "paper-fig2"\n[axes]\nmu = "0.1:1:3"\nk_ip = "1e6:1e8:2"\n'
OTHER = 'preset = "paper-fig2"\n[axes]\nmu = "0.2:1:3"\nk_ip = "1e6:1e8:2"\n'


def _tree(root: Path) -> dict[str, bytes | str]:
    out: dict[str, bytes | str] = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for n in dirnames + filenames:
            p = Path(dirpath) / n
            rel = p.relative_to(root).as_posix()
            out[rel] = ("-> " + os.readlink(p)) if p.is_symlink() else p.read_bytes() if p.is_file() else "dir"
    return out


def _one_error_line(err: str, *needles: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("brakesqueal: error: "), err
    for n in needles:
        assert n in lines[0], (n, lines[0])
    return lines[0]


# ------------------------------------------------------------------ scenario 4: sweep --overwrite
#: things found in directories that are not our stores (relative path -> content)
FOREIGN = {
    "plain zarr.json": {"zarr.json": "just a text file that happens to be called zarr.json\n"},
    "another program's Zarr group": {"zarr.json": '{"zarr_format": 3, "node_type": "group", "attributes": '
                                                  '{"owner": "someone else"}}'},
    "a folder named like our markers": {"_sweep_chunks/notes.txt": "mine"},
    "a fake creation record": {"_sweep_chunks/_creation.json": '{"format": "brakesqueal-sweep-store/1"}'},
}


@pytest.mark.parametrize("case", sorted(FOREIGN))
def test_overwrite_refuses_a_directory_brakesqueal_did_not_make(tmp_path, monkeypatch, capsys, case):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text(STUDY)
    store = tmp_path / "s.zarr"
    rng = np.random.default_rng(zlib.crc32(case.encode()))
    for rel, text in FOREIGN[case].items():
        (store / rel).parent.mkdir(parents=True, exist_ok=True)
        (store / rel).write_text(text)
    (store / "data.bin").write_bytes(rng.bytes(64))  # the user's data beside it
    before = _tree(store)
    assert main(["sweep", "s.toml", "--out", str(store), "--overwrite", "--no-progress"]) == 2
    _one_error_line(capsys.readouterr().err, str(store), "refusing to overwrite", "remove it by hand")
    assert _tree(store) == before
    # without --overwrite: refused too, and the message does not suggest --overwrite (which would refuse)
    assert main(["sweep", "s.toml", "--out", str(store), "--no-progress"]) == 2
    line = _one_error_line(capsys.readouterr().err, str(store))
    assert "--overwrite" not in line
    assert _tree(store) == before


def test_overwrite_replaces_our_own_stores_marked_or_from_before_the_marker(tmp_path, monkeypatch, capsys):
    from brakesqueal.sweep import open_sweep
    from brakesqueal.sweep.store import STORE_MARKER, is_own_store
    from brakesqueal.sweep.study import load_study

    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text(STUDY)
    (tmp_path / "o.toml").write_text(OTHER)
    store = tmp_path / "s.zarr"
    assert main(["sweep", "s.toml", "--out", str(store), "--no-progress"]) == 0
    assert (store / STORE_MARKER).is_file() and is_own_store(store)
    assert main(["sweep", "o.toml", "--out", str(store), "--overwrite", "--no-progress"]) == 0
    assert open_sweep(store).attrs["study_hash"] == load_study(tmp_path / "o.toml").hash()
    (store / STORE_MARKER).unlink()  # a store of a version before the marker: its creation record identifies it
    assert is_own_store(store)
    assert main(["sweep", "s.toml", "--out", str(store), "--overwrite", "--no-progress"]) == 0
    assert open_sweep(store).attrs["study_hash"] == load_study(tmp_path / "s.toml").hash()
    capsys.readouterr()


# ------------------------------------------------------------------ scenario 5: links, pipes, devices
def test_an_output_never_replaces_a_symbolic_link_nor_writes_through_it(tmp_path, monkeypatch, capsys):
    real = tmp_path / "elsewhere" / "model.c"
    real.parent.mkdir()
    real.write_text("the user's file")
    link = tmp_path / "out.c"
    link.symlink_to(real)
    dangling = tmp_path / "dangling.c"
    dangling.symlink_to(tmp_path / "nowhere" / "x.c")
    for p in (link, dangling):
        with pytest.raises(OutputError, match="symbolic link") as info:
            check_output(p, what="--out", suffixes=(".c",))
        assert "\n" not in str(info.value) and str(p) in str(info.value)
        with pytest.raises(OutputError, match="symbolic link"):
            with atomic_write(p, what="--out") as tmp:
                tmp.write_text("new")
        assert p.is_symlink()
    assert real.read_text() == "the user's file" and not (tmp_path / "nowhere").exists()
    monkeypatch.chdir(tmp_path)
    assert main(["export", "--to", "c", "--out", str(link)]) == 2
    _one_error_line(capsys.readouterr().err, str(link), "symbolic link")
    assert link.is_symlink() and real.read_text() == "the user's file"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dangling.c", "elsewhere", "out.c"]


def test_an_output_never_replaces_a_pipe_or_a_device(tmp_path, monkeypatch, capsys):
    fifo = tmp_path / "out.c"
    os.mkfifo(fifo)
    with pytest.raises(OutputError, match=r"named pipe \(FIFO\), not a regular file") as info:
        check_output(fifo, what="--out", suffixes=(".c",))
    assert "\n" not in str(info.value)
    with pytest.raises(OutputError, match="named pipe"):
        with atomic_write(fifo, what="--out") as tmp:
            tmp.write_text("new")
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    monkeypatch.chdir(tmp_path)
    assert main(["export", "--to", "c", "--out", "out.c"]) == 2  # refused before any work, nothing opened
    _one_error_line(capsys.readouterr().err, "out.c", "named pipe")
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode) and sorted(os.listdir(tmp_path)) == ["out.c"]
    # a device: only checked (check_output opens nothing), never written
    with pytest.raises(OutputError, match="character device"):
        check_output("/dev/null", what="--out")


def test_a_set_of_files_never_replaces_a_link_in_the_directory(tmp_path):
    outside = tmp_path / "outside.png"
    outside.write_bytes(b"the user's image")
    d = tmp_path / "R"
    d.mkdir()
    (d / "a.json").write_text("previous a")
    (d / "b.png").symlink_to(outside)
    with pytest.raises(OutputError, match="symbolic link"):
        with write_set(d, what="--out") as tmp:
            (tmp / "a.json").write_text("new a")
            (tmp / "b.png").write_bytes(b"new b")
    assert (d / "a.json").read_text() == "previous a" and (d / "b.png").is_symlink()
    assert outside.read_bytes() == b"the user's image" and sorted(os.listdir(d)) == ["a.json", "b.png"]


# ------------------------------------------------------------------ scenario 6: an output is never an input
@pytest.fixture
def model_file(tmp_path):
    from brakesqueal.model import get_model
    from brakesqueal.model.io import model_to_toml

    p = tmp_path / "m.py"  # a model file (TOML) whose name is also a valid Python export target
    p.write_text(model_to_toml(get_model("paper")))
    return p


@pytest.mark.parametrize("spelling", ["same", "dot-slash", "absolute", "hard-link"])
def test_export_never_overwrites_its_model_file(model_file, tmp_path, monkeypatch, capsys, spelling):
    monkeypatch.chdir(tmp_path)
    before = model_file.read_bytes()
    out = {"same": "m.py", "dot-slash": "./m.py", "absolute": str(model_file), "hard-link": "h.py"}[spelling]
    if spelling == "hard-link":
        os.link(model_file, tmp_path / "h.py")
    assert main(["export", "--to", "python", "--model", "m.py", "--out", out]) == 2
    _one_error_line(capsys.readouterr().err, out, "input of this command")
    assert model_file.read_bytes() == before
    assert not [p for p in os.listdir(tmp_path) if ".part" in p]


def test_an_input_named_only_inside_another_input_is_not_overwritten(model_file, tmp_path, monkeypatch, capsys):
    """The model is named in a parameter file only: the file actually read is the input that is protected."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "p.toml").write_text(f'model = "{model_file}"\n')
    before = model_file.read_bytes()
    assert main(["export", "--to", "python", "--params", "p.toml", "--out", "m.py"]) == 2
    _one_error_line(capsys.readouterr().err, "m.py", "input of this command")
    assert model_file.read_bytes() == before and sorted(os.listdir(tmp_path)) == ["m.py", "p.toml"]


def test_map_never_overwrites_its_parameter_file(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    params = tmp_path / "p.nc"  # a parameter file (TOML) under the name of the map
    params.write_text('preset = "paper"\n')
    args = ["map", "--x", "mu1=0.1:0.8:4", "--y", "Omega=1:100:3", "--no-eigen", "--params", "p.nc", "--out", "p.nc"]
    assert main(args) == 2
    _one_error_line(capsys.readouterr().err, "p.nc", "input of this command")
    assert params.read_text() == 'preset = "paper"\n'
    assert main([*args[:-1], "map.nc"]) == 0  # another name: written
    assert (tmp_path / "map.nc").stat().st_size > 0 and params.read_text() == 'preset = "paper"\n'


def test_outside_a_command_a_file_may_be_read_and_written_back(tmp_path):
    """The guard belongs to commands: a library caller (a notebook) may rewrite a file it read."""
    f = tmp_path / "notes.txt"
    f.write_text("v1")
    text = f.read_text()
    with atomic_write(f) as tmp:
        tmp.write_text(text + " v2")
    assert f.read_text() == "v1 v2"
    with guard_inputs([]):
        f.read_text()
        with pytest.raises(OutputError, match="input of this command"):
            with atomic_write(f) as tmp:
                tmp.write_text("v3")
    assert f.read_text() == "v1 v2" and os.listdir(tmp_path) == ["notes.txt"]


# ------------------------------------------------------------------ scenario 7: temporary files of killed runs
def _host() -> str:
    import hashlib
    import socket

    return hashlib.sha256(socket.gethostname().encode()).hexdigest()[:8]


def _dead_pid() -> int:
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


@pytest.fixture
def live_child():
    p = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
    yield p.pid
    p.kill()
    p.wait()


@pytest.mark.parametrize("writer", ["atomic_write", "write_set"])
def test_the_next_write_removes_temporary_files_of_dead_writers_only(tmp_path, live_child, writer):
    host, dead = _host(), _dead_pid()
    outside = tmp_path / "outside.txt"
    outside.write_text("the user's")
    d = tmp_path / "out"
    d.mkdir()
    stale_file = d / f".map.nc.brakesqueal-{host}-{dead}-abcd_123.part.nc"
    stale_dir = d / f".brakesqueal-{host}-{dead}-zz9x8y7w.part"
    stale_file.write_bytes(b"x" * 4096)
    stale_dir.mkdir()
    (stale_dir / "fig2.png").write_bytes(b"half")
    recycled = d / f".s.nc.brakesqueal-{host}-{live_child}-qwertyui.part.nc"  # PID now of a younger process
    recycled.write_bytes(b"old")
    os.utime(recycled, (1e9, 1e9))
    kept = {
        d / f".map.nc.brakesqueal-{host}-{live_child}-abcdefgh.part.nc": "a live writer",
        d / f".map.nc.brakesqueal-{host}-{os.getpid()}-abcdefgh.part.nc": "this process",
        d / f".map.nc.brakesqueal-00000000-{dead}-abcdefgh.part.nc": "another host",
        d / ".map.nc.abcdefgh.part.nc": "an older version (no PID in the name)",
        d / "notes.part": "the user's",
    }
    for p in kept:
        p.write_text("keep")
    link = d / f".l.nc.brakesqueal-{host}-{dead}-abcdefgh.part.nc"
    link.symlink_to(outside)
    if writer == "atomic_write":
        with atomic_write(d / "new.nc") as tmp:
            tmp.write_text("new")
    else:
        with write_set(d) as tmp:
            (tmp / "new.nc").write_text("new")
    assert not stale_file.exists() and not stale_dir.exists() and not recycled.exists()
    for p, why in kept.items():
        assert p.read_text() == "keep", why
    assert link.is_symlink() and outside.read_text() == "the user's"
    assert (d / "new.nc").read_text() == "new"
    assert remove_stale_parts(d) == []  # nothing more to do


def test_the_next_sweep_removes_the_temporary_files_of_a_killed_one(tmp_path, monkeypatch, capsys):
    """A store's ``.partial`` files and an interrupted creation's sibling go with the next run (under its lock)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text(STUDY)
    store = tmp_path / "s.zarr"
    assert main(["sweep", "s.toml", "--out", str(store), "--no-progress"]) == 0
    left = [store / "stable" / f".c.{os.urandom(6).hex()}.partial", store / "_sweep_chunks" / ".0.json.ab12.partial"]
    for p in left:
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(b"x" * 1000)
    sibling = tmp_path / f".s.zarr.creating-{_dead_pid()}-abcd1234"
    (sibling / "stable").mkdir(parents=True)
    assert main(["sweep", "s.toml", "--out", str(store), "--no-progress"]) == 0
    assert not any(p.exists() for p in left) and not sibling.exists()
    capsys.readouterr()


_WRITER = """
import sys, time
import brakesqueal.cli as cli
from brakesqueal.outputs import atomic_write

def app(*args, **kwargs):  # a command writing a large output slowly
    with atomic_write(sys.argv[1], what="--out") as tmp:
        with open(tmp, "wb") as f:
            f.write(b"x" * (64 << 20))
        print("writing", flush=True)
        {stall}

cli.app = app
sys.exit(cli.main())
"""
_STALLS = {
    "python": "time.sleep(300)",
    # as in a cold numba compilation: the interrupt cannot be raised; the watchdog ends the process
    "native": "from numba.core.compiler_lock import global_compiler_lock\n"
              "        with global_compiler_lock:\n            time.sleep(300)",
}


@pytest.mark.parametrize("stall", sorted(_STALLS))
@pytest.mark.parametrize("signame", ["SIGTERM", "SIGHUP"])
def test_sigterm_and_sighup_leave_no_temporary_file(tmp_path, signame, stall):
    out = tmp_path / "big.nc"
    out.write_text("the previous result")
    code = _WRITER.replace("{stall}", _STALLS[stall])
    proc = subprocess.Popen([sys.executable, "-c", textwrap.dedent(code), str(out)], cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "writing"
        assert [p for p in os.listdir(tmp_path) if ".part" in p]  # the temporary file exists now
        sig = getattr(signal, signame)
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 128 + sig, (proc.returncode, err)
    assert err.strip() == "brakesqueal: interrupted"
    assert sorted(os.listdir(tmp_path)) == ["big.nc"] and out.read_text() == "the previous result"


# ------------------------------------------------------------------ scenario 8: a full disk in every plot format
class _FullDisk:
    """A file whose writes fail with ENOSPC after ``room`` bytes (no file descriptor: every write goes here)."""

    def __init__(self, f, room: int) -> None:
        self._f, self._room = f, room

    def write(self, data):
        if len(data) > self._room:
            raise OSError(errno.ENOSPC, "No space left on device")
        self._room -= len(data)
        return self._f.write(data)

    def fileno(self):
        raise io.UnsupportedOperation("fileno")

    def __getattr__(self, name):
        return getattr(self._f, name)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._f.close()


@pytest.fixture
def full_disk(monkeypatch, tmp_path):
    """Writes of temporary files below ``tmp_path`` run out of space after 2 KiB (other files are untouched)."""
    real_open = builtins.open

    def fake_open(file, mode="r", *args, **kwargs):
        f = real_open(file, mode, *args, **kwargs)
        if isinstance(file, (str, os.PathLike)) and ".part" in os.fspath(file) and \
                str(tmp_path) in os.path.abspath(os.fspath(file)) and any(c in mode for c in "wax"):
            return _FullDisk(f, 2048)
        return f

    monkeypatch.setattr(builtins, "open", fake_open)


def _figure():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    rng = np.random.default_rng(3)
    ax.plot(rng.normal(size=2000), rng.normal(size=2000), ".")
    ax.set_title("squeal")
    return fig


@pytest.mark.parametrize("fmt", ["png", "pdf", "svg"])
def test_a_full_disk_while_saving_a_figure_is_one_line_and_keeps_the_old_file(tmp_path, full_disk, fmt):
    from brakesqueal.cli.stability import _write_plot
    from brakesqueal.plotting import save

    fig = _figure()
    for i, write in enumerate((_write_plot, save)):
        target = tmp_path / f"plot{i}.{fmt}"
        target.write_bytes(b"the previous figure")
        with pytest.raises(OutputError) as info:
            write(fig, str(target))
        msg = str(info.value)
        assert "\n" not in msg and str(target) in msg and msg.endswith("no space left on device"), msg
        assert target.read_bytes() == b"the previous figure"
    assert sorted(os.listdir(tmp_path)) == [f"plot0.{fmt}", f"plot1.{fmt}"]


def test_a_full_disk_during_a_pdf_plot_of_a_command(tmp_path, monkeypatch, capsys, full_disk):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "c.pdf").write_bytes(b"the previous figure")
    assert main(["crossings", "--along", "k_ip=1e5:1e10:log", "--set", "mu=0.5", "--plot", "c.pdf"]) == 2
    _one_error_line(capsys.readouterr().err, "--plot", "c.pdf", "no space left on device")
    assert (tmp_path / "c.pdf").read_bytes() == b"the previous figure" and os.listdir(tmp_path) == ["c.pdf"]
