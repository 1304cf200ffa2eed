"""The code cache deletes only what it made and uses only what was written for the entry (issue 30).

``cache clear`` (and ``--stale``) removes only directories carrying the
cache's marker file; the user's own folders and files in the cache
directory, symbolic links (and what they point to) and directories of
versions that wrote no marker are left in place and reported, one line
each.  Every line saying "removed" names something that is gone.  A cached
file swapped with (or copied from) another entry is a miss: regenerated,
never executed.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from brakesqueal.cli import main
from brakesqueal.codegen import cache


@pytest.fixture
def private_cache(tmp_path, monkeypatch):
    root = tmp_path / "cache"
    monkeypatch.setenv("BRAKESQUEAL_CACHE_DIR", str(root))
    return root


def _tree(root: Path) -> dict[str, bytes | str]:
    """Every item below ``root`` (links as their target text, files as bytes), without following links."""
    out: dict[str, bytes | str] = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for n in dirnames + filenames:
            p = Path(dirpath) / n
            rel = p.relative_to(root).as_posix()
            if p.is_symlink():
                out[rel] = "-> " + os.readlink(p)
            elif p.is_file():
                out[rel] = p.read_bytes()
            else:
                out[rel] = "dir"
    return out


def _clear(capsys, *args: str) -> list[str]:
    capsys.readouterr()
    assert main(["cache", "clear", *args]) == 0
    out = capsys.readouterr()
    assert out.err == ""
    return out.out.splitlines()


def _stale_entry(monkeypatch, version: str, key: str, name: str, text: str) -> Path:
    """An entry written by another package version (its own marked version directory)."""
    with monkeypatch.context() as m:
        m.setattr(cache, "__version__", version)
        path = cache.write_text(key, name, text)
    assert path is not None and not path.is_relative_to(cache.version_dir())
    return path


# ------------------------------------------------------------------ scenario 1: the user's own folders
def test_cache_clear_keeps_what_it_did_not_make_and_says_so(private_cache, tmp_path, monkeypatch, capsys):
    ours = cache.write_text("k", "f.txt", "cached")
    stale = _stale_entry(monkeypatch, "0.0.1", "k", "f.txt", "old")
    mine = private_cache / "my-notes"
    mine.mkdir()
    (mine / "keep.txt").write_text("the user's")
    legacy = private_cache / "0.0.1-0123456789ab"  # the layout of an older version's cache, without a marker
    (legacy / "k").mkdir(parents=True)
    (legacy / "k" / "model.py").write_text("x = 1\n")
    (private_cache / "README").write_text("mine too")
    (cache.version_dir() / "scratch").mkdir()  # the user's folder inside our version directory
    (cache.version_dir() / "scratch" / "a.txt").write_text("a")
    keep = {p: _tree(p) for p in (mine, legacy, cache.version_dir() / "scratch")}

    lines = _clear(capsys, "--stale")
    assert f"removed {stale.parent.parent}" in lines and not stale.parent.parent.exists()
    assert ours is not None and cache.read_text("k", "f.txt") == "cached"  # --stale keeps the current version
    for p in (mine, legacy, private_cache / "README"):
        assert sum(ln.startswith(f"skipped {p}: ") for ln in lines) == 1, lines
    assert "delete it by hand" in next(ln for ln in lines if ln.startswith(f"skipped {legacy}:"))

    lines = _clear(capsys)
    assert cache.read_text("k", "f.txt") is None and not ours.parent.exists()  # our entry is gone ...
    assert (cache.version_dir() / "scratch").is_dir()  # ... the user's folder in its version directory is not
    assert any(ln.startswith(f"skipped {cache.version_dir() / 'scratch'}: ") for ln in lines), lines
    for p, before in keep.items():
        assert _tree(p) == before
    assert (private_cache / "README").read_text() == "mine too"
    # once the user's folder is gone, the version directory goes too
    shutil.rmtree(cache.version_dir() / "scratch")
    assert f"removed {cache.version_dir()}" in _clear(capsys) and not cache.version_dir().exists()


def test_entries_carry_a_marker_naming_their_key(private_cache):
    import json

    path = cache.write_text("some-key", "f.txt", "x")
    entry = json.loads((path.parent / cache.MARKER).read_text())
    version = json.loads((path.parent.parent / cache.MARKER).read_text())
    assert entry["key"] == "some-key" and entry["version"] == version["version"]
    assert entry["kind"] != version["kind"]


# ------------------------------------------------------------------ scenario 2: symbolic links
def test_cache_clear_never_deletes_through_a_symbolic_link_and_says_what_it_did(private_cache, tmp_path, capsys):
    cache.write_text("k", "f.txt", "cached")
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "precious.txt").write_text("the user's")
    # a link to an outside folder, in the root and in the version directory, and a link to a marked entry
    (private_cache / "linked").symlink_to(outside, target_is_directory=True)
    (cache.version_dir() / "linked-entry").symlink_to(cache.entry_dir("k"), target_is_directory=True)
    (cache.version_dir() / "linked-out").symlink_to(outside, target_is_directory=True)
    lines = _clear(capsys)
    assert (outside / "precious.txt").read_text() == "the user's"
    for link in (private_cache / "linked", cache.version_dir() / "linked-entry", cache.version_dir() / "linked-out"):
        assert link.is_symlink()
        (line,) = [ln for ln in lines if ln.startswith(f"skipped {link}: ")]
        assert "symbolic link" in line
    for ln in lines:  # every "removed" is true
        if ln.startswith("removed "):
            assert not os.path.lexists(ln[len("removed "):]), ln
    assert not cache.entry_dir("k").exists()


@pytest.mark.parametrize("seed", range(6))
def test_random_cache_directories_lose_only_marked_entries(private_cache, tmp_path, monkeypatch, capsys, seed):
    """Random mixes of the cache's entries, the user's files and folders and links: only marked entries go."""
    rng = np.random.default_rng(seed)
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "o.txt").write_text("outside")
    ours: list[Path] = []
    for i in range(int(rng.integers(1, 4))):
        version = "0.0.%d" % rng.integers(1, 3) if rng.random() < 0.5 else None
        if version is None:
            ours.append(cache.write_text(f"k{i}", "f.txt", f"text {i}").parent)
        else:
            ours.append(_stale_entry(monkeypatch, version, f"k{i}", "f.txt", "old").parent)
    versions = sorted({p.parent for p in ours})
    foreign: list[Path] = []
    for j in range(int(rng.integers(1, 6))):
        where = [private_cache, *versions][int(rng.integers(0, 1 + len(versions)))]
        p = where / f"user-{j}"
        kind = rng.choice(["file", "dir", "link-out", "link-in", "fake-marker"])
        if kind == "file":
            p.write_bytes(rng.bytes(16))
        elif kind == "dir":
            (p / "sub").mkdir(parents=True)
            (p / "sub" / "x").write_bytes(rng.bytes(8))
        elif kind == "link-out":
            p.symlink_to(outside, target_is_directory=True)
        elif kind == "link-in":
            p.symlink_to(ours[int(rng.integers(0, len(ours)))], target_is_directory=True)
        else:  # a folder holding a file of the marker's name but not the cache's content
            p.mkdir()
            (p / cache.MARKER).write_text("my own file of that name")
        foreign.append(p)
    before = {p: _tree(p) if p.is_dir() and not p.is_symlink() else None for p in foreign}
    stale = bool(rng.random() < 0.5)
    lines = _clear(capsys, *(["--stale"] if stale else []))
    for p, tree in before.items():
        assert os.path.lexists(p), (p, lines)
        if tree is not None:
            assert _tree(p) == tree
        looked_at = not (stale and p.parent == cache.version_dir())  # --stale leaves the current version alone
        assert sum(ln.startswith(f"skipped {p}: ") for ln in lines) == looked_at, (p, lines)
    assert (outside / "o.txt").read_text() == "outside"
    for e in ours:
        assert e.exists() == (stale and e.parent == cache.version_dir()), (e, lines)
    for ln in lines:
        assert ln.startswith(("removed ", "skipped ")), ln
        if ln.startswith("removed "):
            assert not os.path.lexists(ln[len("removed "):]), ln


# ------------------------------------------------------------------ scenario 3: swapped entries
_SIM = "KIND = 'simulate'\ndef kinds():\n    return {'kinds': 1}\n"
_MODEL = "KIND = 'model'\n"


def test_a_file_swapped_with_another_entry_is_regenerated_not_used(private_cache):
    a = cache.write_text("key-a", "simulate.py", _SIM)
    b = cache.write_text("key-b", "model.py", _MODEL)
    da, db = a.read_bytes(), b.read_bytes()
    a.write_bytes(db)
    b.write_bytes(da)  # both checksums are intact: each file is a valid cache file, of the other entry
    assert cache.read_text("key-a", "simulate.py") is None and cache.read_text("key-b", "model.py") is None
    calls = []
    mod = cache.load_module("key-a", "simulate.py", lambda: calls.append(1) or _SIM)
    assert calls == [1] and mod.KIND == "simulate" and mod.kinds() == {"kinds": 1}
    assert a.read_bytes() == da  # rewritten for its own entry
    assert cache.cached_text("key-b", "model.py", lambda: _MODEL) == _MODEL and b.read_bytes() == db


def test_a_file_copied_from_another_version_is_regenerated(private_cache, monkeypatch):
    old = _stale_entry(monkeypatch, "0.0.1", "k", "m.py", "VALUE = 'old'\n")
    new = cache.entry_dir("k") / "m.py"
    new.parent.mkdir(parents=True)
    shutil.copy(old, new)
    assert cache.read_text("k", "m.py") is None
    assert cache.load_module("k", "m.py", lambda: "VALUE = 'new'\n").VALUE == "new"


@pytest.mark.slow
def test_simulate_with_its_entry_swapped_for_the_model_module(tmp_path):
    """The trial's case: ``simulate.py`` of the paper model swapped with its ``model.py``; simulate still works."""
    from brakesqueal.codegen import model_key
    from brakesqueal.model import get_model

    root = tmp_path / "cache"
    env = {**os.environ, "BRAKESQUEAL_CACHE_DIR": str(root)}
    cmd = [sys.executable, "-m", "brakesqueal", "simulate", "--t-end", "0.01", "--format", "json", "--no-progress"]
    first = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=900, cwd=tmp_path)
    assert first.returncode == 0, first.stderr[-2000:]
    (entry,) = list(root.glob(f"*/{model_key(get_model('paper'))}"))
    sim, model = entry / "simulate.py", entry / "model.py"
    ds, dm = sim.read_bytes(), model.read_bytes()
    sim.write_bytes(dm)
    model.write_bytes(ds)
    again = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=900, cwd=tmp_path)
    assert again.returncode == 0 and "Traceback" not in again.stderr, again.stderr[-2000:]
    assert sim.read_bytes() == ds  # regenerated for its own entry
