"""Fault injection into the code cache (issue 11): a damaged, relocated or bypassed cache never breaks a run.

Reference values: every command is first run on a fresh (empty) cache in
:func:`warm`; a run on a damaged copy of that cache must print exactly the same
(and write the same map), and the damaged entry must afterwards be byte-for-byte
the fresh one (code generation is deterministic: checked across
``PYTHONHASHSEED`` values when this test was written, and implied by every
byte-equality assertion below).
"""

from __future__ import annotations

import ast
import hashlib
import json
import os
import pickle
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from brakesqueal.codegen import cache

PKG = Path(cache.__file__).resolve().parent.parent

# ------------------------------------------------------------------ the real commands
#: kind of cache entry -> (command, glob of its entry file below the cache root)
def _key(name: str) -> str:
    from brakesqueal.codegen import model_key
    from brakesqueal.model import get_model

    return model_key(get_model(name))


KINDS = {
    "numeric": (["linearize", "--format", "json"], f"*/{_key('paper')}/model.py"),
    "stability": (["map", "--x", "mu=0.1:0.8:12", "--y", "Omega=1:100:9", "--out", "m.nc", "--no-eigen"],
                  "*/stability-kernels/brakesqueal_kernel_map_*.py"),
    "simulation": (["simulate", "--t-end", "0.01", "--format", "json", "--no-progress"],
                   f"*/{_key('paper')}/simulate.py"),
    "built": (["linearize", "--model", "six-dof", "--format", "json"], f"*/{_key('six-dof')}/model.py"),
}  # fmt: skip
# (``derive`` of the paper's cases prints shipped text and caches nothing while that text is current:
#  tests/cli/test_derive_shipped.py covers its fallback to the cached derivation)


def run(args: list[str], cache_dir: Path, cwd: Path, **env: str) -> subprocess.CompletedProcess:
    full = {**os.environ, "BRAKESQUEAL_CACHE_DIR": str(cache_dir), **env}
    return subprocess.run([sys.executable, "-m", "brakesqueal", *args], cwd=cwd, env=full,
                          capture_output=True, text=True, timeout=600)  # fmt: skip


def outcome(kind: str, res: subprocess.CompletedProcess, cwd: Path) -> tuple:
    """What a run produced, comparable between runs (timings removed, the map's NetCDF read back)."""
    assert res.returncode == 0, f"{kind}: exit {res.returncode}\n{res.stderr[-3000:]}"
    assert "Traceback" not in res.stderr, res.stderr[-3000:]
    out = res.stdout
    if kind == "simulation":
        data = json.loads(out)
        data.pop("wall_s")
        out = json.dumps(data, sort_keys=True)
    if kind == "stability":
        import xarray as xr

        with xr.open_dataset(cwd / "m.nc") as ds:
            ds = ds.load()
        return out, ds
    return out, None


def same(a: tuple, b: tuple) -> bool:
    return a[0] == b[0] and (a[1] is None and b[1] is None or a[1].identical(b[1]))


def entry(root: Path, kind: str) -> Path:
    files = sorted(root.glob(KINDS[kind][1]))
    assert len(files) == 1, (kind, files)
    return files[0]


@pytest.fixture(scope="session")
def warm(tmp_path_factory):
    """A cache filled by one run of every command on an empty cache, and those runs' outcomes."""
    root = tmp_path_factory.mktemp("warm-cache")
    work = tmp_path_factory.mktemp("warm-work")
    # all at once (also exercises concurrent writers of the shared entries, e.g. the 2-DOF numeric module)
    env = {**os.environ, "BRAKESQUEAL_CACHE_DIR": str(root)}
    procs = {kind: subprocess.Popen([sys.executable, "-m", "brakesqueal", *cmd], cwd=work, env=env, text=True,
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE)
             for kind, (cmd, _) in KINDS.items()}  # fmt: skip
    ref = {}
    for kind, proc in procs.items():
        out, err = proc.communicate(timeout=600)
        ref[kind] = outcome(kind, subprocess.CompletedProcess(proc.args, proc.returncode, out, err), work)
    return root, ref


@pytest.fixture
def damaged(warm, tmp_path):
    """A private copy of the warm cache (tests damage it) and a working directory."""
    root = tmp_path / "cache"
    shutil.copytree(warm[0], root)
    work = tmp_path / "work"
    work.mkdir()
    return root, work


# ------------------------------------------------------------------ damage
def _body_start(data: bytes) -> int:
    return data.find(b"\n") + 1


FILE_DAMAGE = {
    "truncate": lambda d, rng: d[: int(rng.integers(1, len(d)))],
    "garbage": lambda d, rng: rng.bytes(len(d)),
    "empty": lambda d, rng: b"",
    "no-checksum": lambda d, rng: d[_body_start(d):],
    "flip-byte": lambda d, rng: _flip(d, int(rng.integers(_body_start(d), len(d)))),
}


def _flip(data: bytes, i: int) -> bytes:
    return data[:i] + bytes([data[i] ^ 0x5A]) + data[i + 1:]


def _seed(*parts: str) -> int:
    return int.from_bytes(hashlib.sha256("/".join(parts).encode()).digest()[:8], "little")


@pytest.mark.slow
@pytest.mark.parametrize("damage", list(FILE_DAMAGE))
@pytest.mark.parametrize("kind", list(KINDS))
def test_damaged_entry_is_regenerated(kind, damage, warm, damaged):
    root, work = damaged
    path = entry(root, kind)
    fresh = path.read_bytes()
    rng = np.random.default_rng(_seed(kind, damage))
    bad = FILE_DAMAGE[damage](fresh, rng)
    assert bad != fresh
    path.write_bytes(bad)
    assert same(outcome(kind, run(KINDS[kind][0], root, work), work), warm[1][kind])
    assert path.read_bytes() == fresh  # regenerated and rewritten


# numba's files of one function: "<module>.<function>-<line>.py311.nbi" and ".<n>.nbc", each with a ".sha256"
NUMBA_DAMAGE = {
    "index-truncate": ("nbi", lambda d, rng: d[: int(rng.integers(1, len(d)))]),
    "index-garbage": ("nbi", lambda d, rng: rng.bytes(len(d))),
    "data-truncate": ("nbc", lambda d, rng: d[: int(rng.integers(1, len(d)))]),
    "data-flip-byte": ("nbc", lambda d, rng: _flip(d, int(rng.integers(len(d) // 4, len(d))))),
    "sidecar-deleted": ("nbi.sha256", None),
    "sidecar-garbage": ("nbc.sha256", lambda d, rng: rng.bytes(len(d))),
}
#: which function's numba cache is damaged (small ones: recompiling them is quick)
#: (called from Python, so loaded in every run; ``dense_eval`` say is only called from compiled code, and a
#: damaged file of it would stay unread, harmlessly, until something calls it from Python)
NUMBA_TARGET = {"stability": "classify", "simulation": "contact"}
#: the sidecar cases are also covered in-process (test_numba_cache_damage_is_a_miss_in_process)
NUMBA_CASES = [("stability", d) for d in NUMBA_DAMAGE if not d.startswith("sidecar")] + [
    ("simulation", "index-garbage"), ("simulation", "data-flip-byte"), ("simulation", "sidecar-deleted")]


def numba_files(root: Path, kind: str) -> dict[str, Path]:
    pyc = entry(root, kind).parent / "__pycache__"
    files = sorted(pyc.glob(f"*.{NUMBA_TARGET[kind]}-*"))
    out = {}
    for f in files:
        m = re.search(r"\.py\d+(\.\d+)?\.(nbi|nbc)(\.sha256)?$", f.name)
        assert m, f.name
        out[m[2] + (m[3] or "")] = f
    assert set(out) == {"nbi", "nbc", "nbi.sha256", "nbc.sha256"}, files
    return out


@pytest.mark.slow
@pytest.mark.parametrize("kind, damage", NUMBA_CASES)
def test_damaged_numba_cache_is_recompiled(kind, damage, warm, damaged):
    root, work = damaged
    files = numba_files(root, kind)
    which, fn = NUMBA_DAMAGE[damage]
    rng = np.random.default_rng(_seed(kind, damage))
    if fn is None:
        files[which].unlink()
    else:
        files[which].write_bytes(fn(files[which].read_bytes(), rng))
    assert same(outcome(kind, run(KINDS[kind][0], root, work), work), warm[1][kind])
    after = numba_files(root, kind)
    assert {k: p.name for k, p in after.items()} == {k: p.name for k, p in files.items()}
    for k in ("nbi", "nbc"):  # rewritten, sealed with a matching checksum
        assert after[k + ".sha256"].read_text().strip() == hashlib.sha256(after[k].read_bytes()).hexdigest()
    with open(after["nbi"], "rb") as f:
        pickle.load(f)  # numba version
        stamp, overloads = pickle.loads(f.read())
    assert len(overloads) == 1


# ------------------------------------------------------------------ relocation and --no-cache
@pytest.mark.slow
@pytest.mark.parametrize("cp_args", [["-a"], ["-r"]], ids=["cp-a", "cp-r"])
def test_relocated_cache_is_used_without_recompiling(cp_args, warm, tmp_path):
    """A warm cache copied to another path (with or without mtimes) is used as it is: same output, no new files."""
    first = tmp_path / "restored-from-ci"
    shutil.copytree(warm[0], first)
    moved = tmp_path / "elsewhere" / "cache"
    moved.parent.mkdir()
    subprocess.run(["cp", *cp_args, str(first), str(moved)], check=True)
    shutil.rmtree(first)
    before = {p.relative_to(moved): p.read_bytes() for p in moved.rglob("*") if p.is_file()}
    work = tmp_path / "work"
    work.mkdir()
    for kind, (cmd, _) in KINDS.items():
        assert same(outcome(kind, run(cmd, moved, work), work), warm[1][kind])
    after = {p.relative_to(moved): p.read_bytes() for p in moved.rglob("*") if p.is_file()}
    import numba.core.caching as nc

    if cp_args == ["-r"] and not hasattr(nc, "_hash_source_file"):
        # older numba stamps its index with the source mtime: a copy without mtimes recompiles (never crashes)
        before = {k: v for k, v in before.items() if "__pycache__" not in k.parts}
        after = {k: v for k, v in after.items() if "__pycache__" not in k.parts}
    assert after == before  # numba loaded its machine code: nothing recompiled or rewritten


@pytest.mark.slow
def test_no_cache_leaves_no_files(warm, tmp_path):
    """``--no-cache`` reads and writes nothing: no cache directory, nothing in TMPDIR; same output."""
    tmp, root, work = tmp_path / "tmp", tmp_path / "cache", tmp_path / "work"
    tmp.mkdir()
    work.mkdir()
    for kind in ("numeric", "simulation", "built"):
        res = run([*KINDS[kind][0], "--no-cache"], root, work, TMPDIR=str(tmp))
        assert same(outcome(kind, res, work), warm[1][kind])
    assert not root.exists()
    assert list(tmp.iterdir()) == []
    assert list(work.iterdir()) == []


# ------------------------------------------------------------------ in-process: verified text files
@pytest.fixture
def private_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("BRAKESQUEAL_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache"


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(text=st.text(min_size=1, max_size=300), data=st.data())
def test_read_text_returns_what_was_written_or_nothing(text, data, tmp_path_factory):
    """Random damage (cut, splice, flip, insert, header edits) is always a miss, never altered text."""
    d = tmp_path_factory.mktemp("t")
    os.environ["BRAKESQUEAL_CACHE_DIR"] = str(d)
    try:
        path = cache.write_text("k", "f.txt", text)
        assert path is not None and cache.read_text("k", "f.txt") == text
        raw = path.read_bytes()
        n = len(raw)
        how = data.draw(st.sampled_from(["cut", "flip", "insert", "delete", "splice", "header"]))
        i = data.draw(st.integers(0, n - 1))
        if how == "cut":
            bad = raw[:i]
        elif how == "flip":
            bad = raw[:i] + bytes([raw[i] ^ data.draw(st.integers(1, 255))]) + raw[i + 1:]
        elif how == "insert":
            bad = raw[:i] + data.draw(st.binary(min_size=1, max_size=8)) + raw[i:]
        elif how == "delete":
            bad = raw[:i] + raw[i + data.draw(st.integers(1, 8)):]
        elif how == "splice":
            bad = raw[:i] + data.draw(st.binary(max_size=40))
        else:  # a header describing other content, or none
            body = raw[raw.index(b"\n") + 1:]
            zero = b"# brakesqueal-cache sha256=" + b"0" * 64 + b" bytes=%d\n" % len(body)
            bad = data.draw(st.sampled_from([body, zero + body, raw.replace(b"bytes=", b"bytes=1", 1)]))
        path.write_bytes(bad)
        got = cache.read_text("k", "f.txt")
        assert got is None if bad != raw else got == text
        # cached_text regenerates a damaged entry and rewrites it intact
        assert cache.cached_text("k", "f.txt", lambda: text) == text
        assert path.read_bytes() == raw
    finally:
        os.environ.pop("BRAKESQUEAL_CACHE_DIR")


def test_read_text_rejects_invalid_utf8_even_with_valid_checksum(private_cache):
    path = cache.write_text("k", "f.txt", "x")
    body = b"\xff\xfe not utf-8"
    path.write_bytes(b"# brakesqueal-cache sha256=%s bytes=%d\n" % (hashlib.sha256(body).hexdigest().encode(),
                                                                     len(body)) + body)  # fmt: skip
    assert cache.read_text("k", "f.txt") is None


# ------------------------------------------------------------------ in-process: load_module
_JIT_SOURCE = '''import numba


@numba.njit(cache=True)
def poly(x):
    """x^3 - 2x + {c}"""
    return x * x * x - 2.0 * x + {c}
'''


def _fresh_module(key: str, source: str, **kw):
    """load_module in a state as if a new process started (module forgotten)."""
    for name in [n for n in sys.modules if n.startswith("brakesqueal_generated_")]:
        if getattr(sys.modules[name], "__source__", None) == source:
            del sys.modules[name]
    return cache.load_module(key, "poly.py", lambda: source, **kw)


def test_load_module_regenerates_a_cached_file_that_fails_to_run(private_cache):
    good = "VALUE = 42\n"
    for bad in ("def f(:\n", "import brakesqueal_no_such_module\n", "raise EOFError('index')\n"):
        cache.write_text("k", "m.py", bad)  # intact checksum, but the code fails (e.g. left by a broken version)
        calls = []
        mod = cache.load_module("k", "m.py", lambda: calls.append(1) or good)
        assert mod.VALUE == 42 and calls == [1]
        assert cache.read_text("k", "m.py") == good
        del sys.modules[mod.__name__]


def test_load_module_reports_broken_fresh_code_in_one_line(private_cache):
    from brakesqueal.errors import BrakesquealError

    cache.write_text("k", "m.py", "x = (\n")
    calls = []
    with pytest.raises(cache.CacheError) as err:
        cache.load_module("k", "m.py", lambda: calls.append(1) or "y = )\n")
    assert isinstance(err.value, BrakesquealError) and "\n" not in str(err.value) and "k/m.py" in str(err.value)
    assert calls == [1]  # regenerated exactly once
    assert cache.read_text("k", "m.py") is None  # the bad entry is not kept


def test_module_name_depends_on_content_not_path(private_cache, monkeypatch, tmp_path):
    src = "A = 1\n"
    a = cache.load_module("k", "a.py", lambda: src, variant="v")
    monkeypatch.setenv("BRAKESQUEAL_CACHE_DIR", str(tmp_path / "other"))
    b = cache.load_module("k2", "b.py", lambda: src, variant="v")
    c = cache.load_module("k", "a.py", lambda: "A = 2\n", variant="v")
    assert a is b and a.__name__ == b.__name__ and c.__name__ != a.__name__
    assert a.__name__ == "brakesqueal_generated_" + hashlib.sha256(src.encode()).hexdigest()[:24] + "_v"


def test_numba_cache_damage_is_a_miss_in_process(private_cache):
    """Random damage to numba's index, data and sidecar files of a small function: recompiled, same result."""
    source = _JIT_SOURCE.format(c="0.25")
    mod = _fresh_module("jit", source)
    x = 1.7
    expect = x ** 3 - 2 * x + 0.25
    assert mod.poly(x) == expect
    pyc = private_cache.glob("*/jit/__pycache__")
    (pyc,) = list(pyc)

    def files():
        return {re.sub(r".*\.py\d+", "", f.name): f for f in pyc.iterdir()}

    names = set(files())
    assert names == {".nbi", ".nbi.sha256", ".1.nbc", ".1.nbc.sha256"}
    rng = np.random.default_rng(11)
    for trial in range(12):
        target = files()[rng.choice(sorted(names))]
        raw = target.read_bytes()
        how = trial % 4
        if how == 0:
            target.write_bytes(raw[: int(rng.integers(0, len(raw)))])
        elif how == 1:
            i = int(rng.integers(0, len(raw)))
            target.write_bytes(_flip(raw, i))
        elif how == 2:
            target.write_bytes(rng.bytes(len(raw)))
        else:
            target.unlink()
        mod = _fresh_module("jit", source)
        assert mod.poly(x) == expect
        assert set(files()) == names
        for k in (".nbi", ".1.nbc"):
            assert files()[k + ".sha256"].read_text().strip() == hashlib.sha256(files()[k].read_bytes()).hexdigest()


def test_no_cache_module_writes_nothing(private_cache, tmp_path, monkeypatch):
    import tempfile

    tmp = tmp_path / "tmp"
    tmp.mkdir()
    monkeypatch.setenv("TMPDIR", str(tmp))
    monkeypatch.setattr(tempfile, "tempdir", None)
    mod = cache.load_module("jit", "poly.py", lambda: _JIT_SOURCE.format(c="0.5"), use_cache=False)
    assert mod.poly(2.0) == 8.0 - 4.0 + 0.5
    assert mod.__source__ == _JIT_SOURCE.format(c="0.5")
    assert not private_cache.exists() and list(tmp.iterdir()) == []


def test_cache_command_info_and_clear(private_cache, tmp_path, monkeypatch):
    cache.write_text("k", "f.txt", "x")
    with monkeypatch.context() as m:  # a (marked) directory of another version
        m.setattr(cache, "__version__", "0.0.1")
        stale = cache.version_dir()
        cache.write_text("k", "f.txt", "old")
    res = run(["cache", "info"], private_cache, tmp_path)
    assert res.returncode == 0 and cache.version_dir().name in res.stdout and stale.name in res.stdout
    assert run(["cache", "clear", "--stale"], private_cache, tmp_path).returncode == 0
    assert not stale.exists() and cache.read_text("k", "f.txt") == "x"
    assert run(["cache", "clear"], private_cache, tmp_path).returncode == 0
    assert cache.read_text("k", "f.txt") is None


# ------------------------------------------------------------------ fingerprint covers every generator
#: names whose calls generate code or use the cache
_GENERATORS = {"generate_module", "FunctionSpec", "cse", "pycode", "ccode", "octave_code", "julia_code", "latex",
               "lambdify", "load_module", "cached_text", "_load_generated", "load_kernels"}  # fmt: skip
_CACHE_IO = {"read_text", "write_text", "entry_dir"}

#: modules that call a generator or import a listed module's dependency but cannot change cached content
EXEMPT = {
    "__init__.py": "the package version is part of the cache directory name",
    "errors.py": "exception classes only",
    "inputs.py": "input limits and number checks: they refuse input, never change a value or generated code",
    "analysis/equilibrium.py": "numeric silent motion: runs generated code, generates none",
    "cli/__init__.py": "caches the output of render.py (listed)",
    "model/io.py": "model description <-> TOML; the code cache key is a hash of the components (content-addressed)",
    "model/library.py": "built-in model definitions: their components are hashed into the code cache key",
    "analysis/eigen.py": "numeric eigen-analysis of a linear model (render_linear_model's verdict): generates no code "
                         "and its text is not cached",
    "suggest.py": "closest-name suggestions in error messages",
    "region/auto.py": "writes AUTO-07p user functions (export_code's C text) into a temporary build directory "
                      "per run: nothing of it is cached",
    "model/parameters.py": "parameter values and presets: never enter generated code",
    "model/roles.py": "ranges and units of parameters: validation only",
    "model/matrices.py": "models given by coefficient matrices: nothing is generated for them (their engine is keyed "
                         "by a hash of the matrices); build() and the nonlinear refusal only test for the kind",
}  # fmt: skip


def _rel(p: Path) -> str:
    return p.relative_to(PKG).as_posix()


def _modules() -> dict[str, Path]:
    return {_rel(p): p for p in PKG.rglob("*.py")}


def _calls_generator(tree: ast.AST) -> bool:
    docstrings = {id(n.body[0].value) for n in ast.walk(tree)
                  if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and n.body
                  and isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant)}  # fmt: skip
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            f = node.func
            name = f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else ""
            if name in _GENERATORS:
                return True
            if name in _CACHE_IO and isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name) \
                    and f.value.id == "cache":  # fmt: skip
                return True
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings \
                and re.search(r"njit\(", node.value):  # fmt: skip
            return True  # a numba source template
    return False


def _imports(rel: str, tree: ast.AST, mods: dict[str, Path]) -> set[str]:
    """Package modules imported anywhere in a module (function-level imports included; not those for type checking)."""
    here = rel.split("/")[:-1]
    out = set()
    typing_only = {id(n) for blk in ast.walk(tree) if isinstance(blk, ast.If) and "TYPE_CHECKING" in ast.unparse(blk.test)
                   for b in blk.body for n in ast.walk(b)}  # fmt: skip
    for node in ast.walk(tree):
        if id(node) in typing_only:
            continue
        if isinstance(node, ast.ImportFrom) and node.level:
            base = here[: len(here) - (node.level - 1)] + (node.module.split(".") if node.module else [])
            for alias in node.names:
                for cand in ("/".join(base + [alias.name]) + ".py", "/".join(base + [alias.name, "__init__.py"]),
                             "/".join(base) + ".py", "/".join(base + ["__init__.py"])):  # fmt: skip
                    if cand in mods:
                        out.add(cand)
                        break
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else [node.module or ""]
            for n in names:
                parts = n.split(".")
                if parts[0] == "brakesqueal":
                    for cand in ("/".join(parts[1:]) + ".py", "/".join(parts[1:] + ["__init__.py"])):
                        if cand in mods:
                            out.add(cand)
    return out


@pytest.mark.slow
def test_every_generator_module_is_in_the_fingerprint():
    mods = _modules()
    listed = {_rel(p) for p in cache.generator_files()}
    for pattern in cache.GENERATOR_MODULES:  # no stale pattern (a renamed module would silently drop out)
        assert list(PKG.glob(pattern)), pattern
    assert {"symbolic/assemble.py", "codegen/simulation.py", "codegen/stability.py", "render.py"} <= listed
    trees = {rel: ast.parse(p.read_text(encoding="utf-8")) for rel, p in mods.items()}
    seeds = {rel for rel, t in trees.items() if _calls_generator(t)}
    assert {"codegen/engine.py", "codegen/compiled.py", "codegen/simulation.py", "codegen/stability.py"} <= seeds
    missing = sorted(seeds - listed - set(EXEMPT))
    assert not missing, f"modules generating code are not in GENERATOR_MODULES: {missing}"
    # and everything the listed modules import (transitively) is listed or exempt
    closure, stack, used = set(), sorted(listed), seeds & set(EXEMPT)
    while stack:
        m = stack.pop()
        if m in EXEMPT:
            used.add(m)
        if m in closure or m in EXEMPT:
            continue
        closure.add(m)
        stack.extend(_imports(m, trees[m], mods))
    unlisted = sorted(closure - listed)
    assert not unlisted, f"imported by code generators but not in GENERATOR_MODULES (nor exempt): {unlisted}"
    assert sorted(set(EXEMPT) - used) == [], f"exemptions no longer needed: {sorted(set(EXEMPT) - used)}"


def test_fingerprint_changes_with_every_generator_file(tmp_path, monkeypatch):
    copy = tmp_path / "brakesqueal"
    shutil.copytree(PKG, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(cache, "_package_dir", lambda: copy)
    cache.source_fingerprint.cache_clear()
    try:
        base = cache.source_fingerprint()
        files = cache.generator_files()
        assert len(files) >= 20
        seen = {base}
        for f in files:
            old = f.read_bytes()
            f.write_bytes(old + b"\n# edited\n")
            cache.source_fingerprint.cache_clear()
            fp = cache.source_fingerprint()
            assert fp not in seen, f.relative_to(copy)
            seen.add(fp)
            f.write_bytes(old)
        (copy / "cli_cache.py").write_bytes(b"# not a generator\n")  # an unlisted file does not matter
        cache.source_fingerprint.cache_clear()
        assert cache.source_fingerprint() == base
    finally:
        cache.source_fingerprint.cache_clear()


@pytest.mark.slow
def test_every_module_with_numba_disk_caching_guards_it():
    """A module with ``njit(cache=True)`` functions must guard them (damaged or unwritable cache files are misses)."""
    unguarded = []
    for rel, path in _modules().items():
        if rel.startswith("codegen/templates/"):
            continue  # read as text into generated modules, which the cache's loader guards; never imported
        text = path.read_text(encoding="utf-8")
        tree = ast.parse(text)
        decorated = any(
            isinstance(d, ast.Call) and any(k.arg == "cache" and getattr(k.value, "value", None) is True
                                            for k in d.keywords)
            for node in ast.walk(tree) if isinstance(node, ast.FunctionDef) for d in node.decorator_list
        )
        if decorated and "guard_numba_caches(" not in text:
            unguarded.append(rel)
    assert not unguarded, f"numba disk caches not guarded (call guard_numba_caches): {unguarded}"
