"""outputs.write_set: a set of files replaces its predecessors completely or not at all (issue 11)."""

from __future__ import annotations

import errno

import pytest

from brakesqueal.errors import OutputError
from brakesqueal.outputs import write_set

NAMES = ("a.png", "a.nc", "a.csv", "a.json")


def _previous(d):
    d.mkdir(exist_ok=True)
    for n in NAMES:
        (d / n).write_text(f"old {n}")


@pytest.mark.parametrize("fail_after", range(len(NAMES) + 1))
@pytest.mark.parametrize("fault", ["disk full", "interrupt", "bug"])
def test_a_failure_at_any_file_keeps_the_previous_set(tmp_path, fail_after, fault):
    d = tmp_path / "out"
    _previous(d)
    exc = {"disk full": OSError(errno.ENOSPC, "No space left on device"), "interrupt": KeyboardInterrupt(),
           "bug": ValueError("a writer's bug")}[fault]
    expected = {"disk full": OutputError, "interrupt": KeyboardInterrupt, "bug": ValueError}[fault]
    with pytest.raises(expected) as info:
        with write_set(d, what="--out") as tmp:
            for i, n in enumerate(NAMES):
                if i == fail_after:
                    raise exc
                (tmp / n).write_text(f"new {n}")
            raise exc  # fail_after == len(NAMES): every file is written, then the block fails
    if fault == "disk full":
        msg = str(info.value)
        assert "\n" not in msg and "--out" in msg and "no space left on device" in msg and "unchanged" in msg
    assert {p.name: p.read_text() for p in d.iterdir()} == {n: f"old {n}" for n in NAMES}  # nothing left over


def test_success_replaces_every_file_and_keeps_others(tmp_path):
    d = tmp_path / "out"
    _previous(d)
    (d / "notes.txt").write_text("mine")
    with write_set(d) as tmp:
        for n in NAMES[:3]:
            (tmp / n).write_text(f"new {n}")
    got = {p.name: p.read_text() for p in d.iterdir()}
    assert got == {**{n: f"new {n}" for n in NAMES[:3]}, "a.json": "old a.json", "notes.txt": "mine"}


def test_an_unwritable_directory_is_one_line(tmp_path):
    import os

    d = tmp_path / "ro"
    _previous(d)
    os.chmod(d, 0o555)
    try:
        if os.access(d, os.W_OK):
            pytest.skip("running as a user who can write anywhere")
        with pytest.raises(OutputError, match="cannot write into"):
            with write_set(d) as tmp:
                (tmp / "x").write_text("x")
    finally:
        os.chmod(d, 0o755)
