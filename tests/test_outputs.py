"""Output files: checked before computing, written atomically, failures in one line (issue 11).

The writer is exercised directly with injected failures (a full disk, an
interrupt) and through a real command; every output kind of every command
goes through :mod:`brakesqueal.outputs` (command-level tests live with the
commands: test_cli_stability, test_simulate_models, test_export, test_sweep_faults).
"""

from __future__ import annotations

import errno
import os
import stat

import pytest

from brakesqueal.errors import OutputError
from brakesqueal.outputs import atomic_write, check_output, check_output_dir


def _listing(d):
    return sorted(p.name for p in d.iterdir())


def test_atomic_write_replaces_only_when_complete(tmp_path):
    f = tmp_path / "out.nc"
    f.write_text("old")
    with atomic_write(f) as tmp:
        tmp.write_text("new")
        assert f.read_text() == "old"  # not visible before the end
    assert f.read_text() == "new" and _listing(tmp_path) == ["out.nc"]
    mode = stat.S_IMODE(os.stat(f).st_mode)
    umask = os.umask(0)
    os.umask(umask)
    assert mode == 0o666 & ~umask


@pytest.mark.parametrize("exc", [OSError(errno.ENOSPC, "No space left on device"), KeyboardInterrupt(),
                                 RuntimeError("writer failed")])
def test_a_failed_write_keeps_the_old_file_and_leaves_nothing(tmp_path, exc):
    f = tmp_path / "out.png"
    f.write_bytes(b"old image")
    expected = OutputError if isinstance(exc, OSError) else type(exc)
    with pytest.raises(expected) as info:
        with atomic_write(f, what="--plot") as tmp:
            tmp.write_bytes(b"half")
            raise exc
    assert f.read_bytes() == b"old image" and _listing(tmp_path) == ["out.png"]
    if expected is OutputError:
        assert str(info.value) == f"--plot: cannot write '{f}': no space left on device"


@pytest.mark.parametrize("make,message", [
    (lambda d: d / "missing" / "m.nc", "does not exist"),
    (lambda d: d, "is a directory"),
    (lambda d: d / "m.xyz", "must end in .nc"),
])
def test_bad_paths_fail_in_one_line_before_any_work(tmp_path, make, message):
    with pytest.raises(OutputError, match=message) as info:
        check_output(make(tmp_path), what="--out", suffixes=(".nc",))
    assert "\n" not in str(info.value)


def test_output_directory_below_a_regular_file_is_refused(tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(OutputError, match="is a regular file"):
        check_output_dir(tmp_path / "file" / "results", what="--out")
    assert check_output_dir(tmp_path / "a").is_dir()  # the output directory itself is created, not its parents
    with pytest.raises(OutputError, match="directory '.*b' does not exist"):
        check_output_dir(tmp_path / "b" / "a")


@pytest.mark.skipif(os.geteuid() == 0, reason="root can write into read-only directories")
def test_read_only_directory_is_refused(tmp_path):
    d = tmp_path / "ro"
    d.mkdir()
    d.chmod(0o500)
    try:
        with pytest.raises(OutputError, match="not writable"):
            check_output(d / "m.nc")
    finally:
        d.chmod(0o700)
