"""On-disk cache of generated code and rendered text, verified on every read.

The cache lives in ``$BRAKESQUEAL_CACHE_DIR`` if set, otherwise in
``$XDG_CACHE_HOME/brakesqueal`` (``~/.cache/brakesqueal``).  Entries are
files ``<root>/<version>-<fingerprint>/<key>/<name>``; the fingerprint is a
hash of every module that generates code (:data:`GENERATOR_MODULES`), so
editing a generator never reuses stale code.

Integrity
    Every file starts with one header line
    ``# brakesqueal-cache sha256=<hex> bytes=<n> entry=<version dir>/<key>/<name>``
    describing the rest of the file and the place it was written for (the
    header is a comment, so a cached ``.py`` file is importable as it is).
    Files are written atomically (temporary file + :func:`os.replace`).  A
    file whose header is missing, whose size or checksum does not match,
    whose content is not UTF-8, or that was written for another entry (a
    file swapped with, or copied from, another entry or version) is a miss:
    it is regenerated and overwritten.

Ownership
    Every version directory and every entry directory holds a marker file
    :data:`MARKER` (``.brakesqueal-cache``, a small JSON: kind, package
    version, fingerprint, key), written when the directory is made.
    :func:`clear_cache` removes only marked directories and reports every
    other item it finds (the user's own folders and files, symbolic links,
    directories of versions that wrote no marker) as skipped: it never
    deletes what the cache did not make, and never follows a symbolic link.

Generated modules
    :func:`load_module` executes a cached (or freshly generated) source file
    under a module name derived from the *content* hash, never from the path,
    so a cache directory copied elsewhere (CI cache restores) keeps working.
    numba's own on-disk cache (``cache=True``; ``*.nbi`` / ``*.nbc`` files in
    ``__pycache__`` beside the module) is guarded per function
    (:func:`guard_numba_caches`): each file gets a ``.sha256`` sidecar when
    numba writes it, and a damaged, unverifiable or unreadable file is
    deleted and treated as a miss (numba recompiles that function).

Adding a code generator
    A module whose source influences generated code or cached text must be
    matched by a pattern of :data:`GENERATOR_MODULES` (paths relative to the
    package, :meth:`pathlib.Path.glob` patterns).  ``tests/codegen/test_cache_faults.py``
    checks that every module that calls a code generator or the cache, and
    every package module those import, is listed (or explicitly exempted
    there); when code moves into a new module or package (say ``codegen/``),
    add its pattern here.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import linecache
import os
import re
import shutil
import stat
import sys
import threading
import types
import uuid
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping

from .. import __version__
from ..errors import BrakesquealError
from ..fingerprint import sources_digest

__all__ = [
    "GENERATOR_MODULES", "MARKER", "CacheError", "ClearReport", "cache_root", "source_fingerprint", "version_dir",
    "entry_dir", "generator_files", "read_text", "write_text", "cached_text", "load_module", "remove_entry",
    "guard_numba_caches", "cache_info", "clear_cache",
]  # fmt: skip

#: Package modules whose source determines generated code or cached text
#: (globs relative to ``src/brakesqueal``); they make up :func:`source_fingerprint`.
GENERATOR_MODULES: tuple[str, ...] = (
    "symbolic/*.py",  # the equations themselves
    "codegen/*.py",  # the engine, the unified code generator, compiled models, stability and silent kernels
    "codegen/templates/*.py",  # static parts of generated kernels (read as text)
    "model/components.py",  # components: their equations and parameter order
    "model/friction.py",  # friction laws: their formulas enter the equations
    "model/expressions.py",  # ties as SymPy enter cached kernels (the characteristic polynomial of a space)
    "analysis/_compiled.py",  # numba root isolation linked with the stability kernels
    "export/*.py",  # exported code and LaTeX
    "render.py",  # the rendered closed forms cached by ``derive``
    "fingerprint.py",  # the fingerprint itself
    "status.py",  # the triviality rule (TRIVIAL_NOISE_FLOOR) decides the cached closed-route tables
)


#: Name of the marker file in every directory the cache makes (version and entry directories).
MARKER = ".brakesqueal-cache"
_KIND_VERSION = "brakesqueal code cache: version directory"
_KIND_ENTRY = "brakesqueal code cache: entry"

_HEADER = re.compile(rb"# brakesqueal-cache sha256=([0-9a-f]{64}) bytes=([0-9]+) entry=(\S+)")
_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*")
_LOCK = threading.RLock()


class CacheError(BrakesquealError):
    """Generated code could not be loaded, even after regenerating it."""


# ------------------------------------------------------------------ locations
def cache_root() -> Path:
    """Root directory of the cache (not created).

    Returns
    -------
    Path
        ``$BRAKESQUEAL_CACHE_DIR``, else ``$XDG_CACHE_HOME/brakesqueal``, else
        ``~/.cache/brakesqueal``.
    """
    env = os.environ.get("BRAKESQUEAL_CACHE_DIR")
    if env:
        return Path(env).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "brakesqueal"


def _package_dir() -> Path:
    return Path(__file__).resolve().parent.parent


def generator_files() -> list[Path]:
    """The package files matched by :data:`GENERATOR_MODULES`, sorted, without duplicates.

    Returns
    -------
    list of Path
        Absolute paths.
    """
    pkg = _package_dir()
    return sorted({f for pattern in GENERATOR_MODULES for f in pkg.glob(pattern) if f.is_file()})


@lru_cache(maxsize=1)
def source_fingerprint() -> str:
    """Short hash of every code-generating module and of the SymPy/symengine versions.

    Returns
    -------
    str
        12 hex digits; part of :func:`version_dir`, so any change to a file of
        :data:`GENERATOR_MODULES` starts a fresh cache.
    """
    pkg = _package_dir()
    return sources_digest((f.relative_to(pkg).as_posix(), f) for f in generator_files())[:12]


def version_dir() -> Path:
    """Directory holding every entry of this package version: ``<root>/<version>-<fingerprint>``.

    Returns
    -------
    Path
        Not necessarily existing.
    """
    return cache_root() / f"{__version__}-{source_fingerprint()}"


def _check_name(what: str, value: str) -> None:
    if not _NAME.fullmatch(value) or value.endswith(".tmp"):
        raise ValueError(f"invalid cache {what} {value!r} (letters, digits, '_', '.', '-'; no path separators)")


def entry_dir(key: str) -> Path:
    """Directory of one cache entry: ``<root>/<version>-<fingerprint>/<key>``.

    Parameters
    ----------
    key : str
        Entry key (a plain name, no path separators).

    Returns
    -------
    Path
        Not necessarily existing.
    """
    _check_name("key", key)
    return version_dir() / key


# ------------------------------------------------------------------ verified text files
def _place(key: str, name: str) -> bytes:
    """Where a file belongs: ``<version dir>/<key>/<name>`` (relative, so a relocated cache stays valid)."""
    return f"{version_dir().name}/{key}/{name}".encode("utf-8")


def _frame(text: str, key: str, name: str) -> bytes:
    body = text.encode("utf-8")
    return (b"# brakesqueal-cache sha256=%s bytes=%d entry=%s\n"
            % (hashlib.sha256(body).hexdigest().encode(), len(body), _place(key, name)) + body)


def _unframe(data: bytes, key: str, name: str) -> str | None:
    """Body of a framed file, or ``None`` if the header is missing, does not describe the body, or names
    another entry (a file swapped with or copied from another entry or version)."""
    nl = data.find(b"\n")
    m = _HEADER.fullmatch(data[:nl]) if nl >= 0 else None
    if m is None or m[3] != _place(key, name):
        return None
    body = data[nl + 1:]
    if int(m[2]) != len(body) or hashlib.sha256(body).hexdigest().encode() != m[1]:
        return None
    try:
        return body.decode("utf-8")
    except UnicodeDecodeError:
        return None


def _read_verified(path: Path, key: str, name: str) -> str | None:
    try:
        return _unframe(path.read_bytes(), key, name)
    except OSError:
        return None


def _marker(kind: str, key: str | None = None) -> bytes:
    body: dict[str, Any] = {"kind": kind, "version": __version__, "fingerprint": source_fingerprint()}
    if key is not None:
        body["key"] = key
    return (json.dumps(body) + "\n").encode("utf-8")


def _marked(d: Path, kind: str) -> bool:
    """Whether directory ``d`` (not a symbolic link) holds a marker of ``kind`` written by the cache."""
    try:
        if d.is_symlink() or not d.is_dir():
            return False
        m = (d / MARKER).lstat()
        if not stat.S_ISREG(m.st_mode) or m.st_size > 4096:
            return False
        data = json.loads((d / MARKER).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(data, dict) and data.get("kind") == kind


def _make_entry(key: str) -> Path:
    """Create the entry directory of ``key`` (and its version directory), each with its :data:`MARKER`."""
    d = entry_dir(key)
    for directory, kind, k in ((d.parent, _KIND_VERSION, None), (d, _KIND_ENTRY, key)):
        if not (directory / MARKER).is_file():
            directory.mkdir(parents=True, exist_ok=True)
            _atomic_write(directory / MARKER, _marker(kind, k))
    return d


def _atomic_write(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same directory and :func:`os.replace`."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{uuid.uuid4().hex[:12]}.tmp")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)  # permissions from the umask
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def read_text(key: str, name: str) -> str | None:
    """Verified content of a cache file.

    Parameters
    ----------
    key : str
        Entry key (see :func:`entry_dir`).
    name : str
        File name within the entry.

    Returns
    -------
    str or None
        The text exactly as written by :func:`write_text`; ``None`` when the
        file is absent, unreadable, truncated, altered (checksum mismatch),
        lacks its checksum header, or is not UTF-8.
    """
    _check_name("name", name)
    return _read_verified(entry_dir(key) / name, key, name)


def write_text(key: str, name: str, text: str) -> Path | None:
    """Atomically write a cache file with its checksum header.

    Parameters
    ----------
    key : str
        Entry key (see :func:`entry_dir`).
    name : str
        File name within the entry.
    text : str
        Content.

    Returns
    -------
    Path or None
        The file's path, or ``None`` if the cache is not writable.
    """
    _check_name("name", name)
    try:
        d = _make_entry(key)
        _atomic_write(d / name, _frame(text, key, name))
        return d / name
    except OSError:
        return None


def cached_text(key: str, name: str, generate: Callable[[], str], *, use_cache: bool = True) -> str:
    """Cached text, generated (and written) on a miss.

    Parameters
    ----------
    key : str
        Entry key (see :func:`entry_dir`).
    name : str
        File name within the entry.
    generate : callable
        ``generate() -> str``, called on a miss (absent or damaged file).
    use_cache : bool, optional
        ``False`` calls ``generate`` and touches no file.

    Returns
    -------
    str
        The verified cached text or the freshly generated one.
    """
    if not use_cache:
        return generate()
    with _LOCK:
        text = read_text(key, name)
        if text is None:
            text = generate()
            write_text(key, name, text)
        return text


def remove_entry(key: str, name: str) -> None:
    """Delete one cache file and the numba / bytecode cache files beside it.

    Parameters
    ----------
    key : str
        Entry key (see :func:`entry_dir`).
    name : str
        File name within the entry; ``__pycache__/<stem>.*`` goes with it.
    """
    _check_name("name", name)
    d = entry_dir(key)
    stem = name[:-3] if name.endswith(".py") else name
    victims = [d / name, *(d / "__pycache__").glob(f"{stem}.*")]
    for f in victims:
        try:
            f.unlink()
        except OSError:
            pass


# ------------------------------------------------------------------ generated modules
_NO_NUMBA_CACHE = re.compile(r"\bcache\s*=\s*True\b")


def _module_name(source: str, variant: str) -> str:
    digest = hashlib.sha256(source.encode("utf-8")).hexdigest()[:24]
    tag = re.sub(r"\W", "_", variant)
    return f"brakesqueal_generated_{digest}" + (f"_{tag}" if tag else "")


def _exec(modname: str, text: str, filename: str, namespace: Mapping[str, Any] | None) -> types.ModuleType:
    """Execute ``text`` as module ``modname`` (registered in ``sys.modules`` while and after it runs)."""
    mod = types.ModuleType(modname)
    mod.__file__ = filename
    mod.__dict__.update(namespace or {})
    sys.modules[modname] = mod
    try:
        exec(compile(text, filename, "exec", dont_inherit=True), mod.__dict__)
    except BaseException:
        sys.modules.pop(modname, None)
        raise
    return mod


def _memory_module(source: str, label: str, namespace: Mapping[str, Any] | None, variant: str
                   ) -> types.ModuleType:
    """Execute generated source without any file (numba's on-disk cache disabled)."""
    modname = _module_name(source, variant) + "_nocache"
    if modname in sys.modules:
        return sys.modules[modname]
    text = _NO_NUMBA_CACHE.sub("cache=False", source)
    filename = f"<brakesqueal generated {label}>"
    linecache.cache[filename] = (len(text), None, text.splitlines(True), filename)
    mod = _exec(modname, text, filename, namespace)
    mod.__source__ = source  # type: ignore[attr-defined]
    return mod


def load_module(key: str, name: str, generate: Callable[[], str], *, use_cache: bool = True,
                namespace: Mapping[str, Any] | None = None, variant: str = "") -> types.ModuleType:
    """The module of a generated source file, from the cache or freshly generated.

    The source is read from ``<entry_dir(key)>/<name>`` and verified (see
    :func:`read_text`); on a miss it is generated and written.  It is
    executed under the module name
    ``brakesqueal_generated_<sha256(source)[:24]>[_<variant>]`` (registered
    in :data:`sys.modules`; a second call with the same source and variant
    returns the same module), with ``__file__`` set to the cache file so that
    numba's ``cache=True`` stores machine code in ``__pycache__`` beside it.
    Every numba function of the module gets a guarded cache
    (:func:`guard_numba_caches`).  If executing a *cached* file fails in any
    way, the file and its ``__pycache__`` files are deleted and the source
    is generated once more.

    Parameters
    ----------
    key : str
        Entry key (see :func:`entry_dir`).
    name : str
        File name within the entry, e.g. ``"numeric.py"``.
    generate : callable
        ``generate() -> str``: the module source, called on a miss.
    use_cache : bool, optional
        ``False`` generates and executes in memory: no file is read or
        written anywhere, and ``cache=True`` in the source is replaced by
        ``cache=False`` for numba.
    namespace : Mapping, optional
        Globals bound in the module before its code runs (e.g. ``sin``,
        ``cos`` from :mod:`math` or :mod:`numpy`).
    variant : str, optional
        Distinguishes modules made from the same source with different
        ``namespace`` (part of the module name).

    Returns
    -------
    types.ModuleType
        The executed module; its source (without the cache header) is in
        ``module.__source__``.

    Raises
    ------
    CacheError
        When freshly generated code cannot be executed either.
    """
    with _LOCK:
        label = f"{key}/{name}"
        if not use_cache:
            return _memory_module(generate(), label, namespace, variant)
        _check_name("name", name)
        path = entry_dir(key) / name
        source = _read_verified(path, key, name)
        fresh = source is None
        for attempt in range(2):
            if source is None:
                source = generate()
                if write_text(key, name, source) is None:  # cache not writable: run from memory
                    return _memory_module(source, label, namespace, variant)
            modname = _module_name(source, variant)
            if modname in sys.modules:
                return sys.modules[modname]
            try:
                # the file's exact text (header included), so line numbers match the file numba reads
                mod = _exec(modname, _frame(source, key, name).decode("utf-8"), str(path), namespace)
                mod.__source__ = source  # type: ignore[attr-defined]
                guard_numba_caches(vars(mod))
                return mod
            except Exception as exc:  # a damaged entry: delete it and generate once more
                remove_entry(key, name)
                if fresh or attempt:
                    raise CacheError(
                        f"cannot load generated code {label} ({type(exc).__name__}: {exc}); "
                        f"try 'brakesqueal cache clear' or --no-cache"
                    ) from exc
                source, fresh = None, True
        raise AssertionError("unreachable")  # pragma: no cover


# ------------------------------------------------------------------ numba's on-disk cache
_SIDECAR = ".sha256"


def _digest_file(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@lru_cache(maxsize=1)
def _guarded_cache_class() -> type:
    from numba.core.caching import FunctionCache

    class GuardedFunctionCache(FunctionCache):  # type: ignore[misc]
        """numba's per-function cache with sha256 sidecars; damage is a miss, never an error."""

        def _files(self) -> list[Path]:
            base = self._impl.filename_base
            pat = re.compile(re.escape(base) + r"(\.nbi|\.[0-9]+\.nbc)")
            d = Path(self._cache_path)
            try:
                return [p for p in d.glob(f"{base}.*") if pat.fullmatch(p.name)]
            except OSError:
                return []

        def _verified(self) -> bool:
            for f in self._files():
                side = f.with_name(f.name + _SIDECAR)
                if not side.is_file() or side.read_text(encoding="ascii").strip() != _digest_file(f):
                    return False
            return True

        def _seal(self) -> None:
            for f in self._files():
                _atomic_write(f.with_name(f.name + _SIDECAR), _digest_file(f).encode("ascii") + b"\n")

        def _purge(self) -> None:
            base = self._impl.filename_base
            try:
                victims = list(Path(self._cache_path).glob(f"{base}.*"))
            except OSError:
                victims = []
            pat = re.compile(re.escape(base) + r"(\.nbi|\.[0-9]+\.nbc)(\.sha256)?")
            for f in victims:
                if pat.fullmatch(f.name):
                    try:
                        f.unlink()
                    except OSError:
                        pass

        def load_overload(self, sig: Any, target_context: Any) -> Any:
            try:
                if not self._verified():
                    self._purge()
                    return None
                return super().load_overload(sig, target_context)
            except Exception:  # unreadable or unpicklable index/data: recompile
                self._purge()
                return None

        def save_overload(self, sig: Any, data: Any) -> None:
            for _ in range(2):
                try:
                    super().save_overload(sig, data)
                    self._seal()
                    return
                except Exception:  # a damaged index blocks numba's save: clear it and retry once
                    self._purge()

    return GuardedFunctionCache


def guard_numba_caches(namespace: Mapping[str, Any] | Iterable[Any]) -> int:
    """Protect numba's on-disk cache of the jitted functions in ``namespace``.

    Each ``numba.njit(cache=True)`` dispatcher gets a cache that writes a
    ``.sha256`` sidecar beside every index / data file it saves and, before
    loading, checks them: a file that is truncated, altered, lacks its
    sidecar or cannot be unpickled is deleted and the function recompiled.

    Parameters
    ----------
    namespace : Mapping or iterable
        A module's ``vars()`` (or any mapping / iterable of objects);
        objects other than cached numba dispatchers are ignored.

    Returns
    -------
    int
        Number of dispatchers guarded.
    """
    if "numba" not in sys.modules:
        return 0
    from numba.core.caching import FunctionCache

    objs = namespace.values() if isinstance(namespace, Mapping) else namespace
    cls = None
    count = 0
    for obj in list(objs):
        cache = getattr(obj, "_cache", None)
        if type(cache) is FunctionCache and hasattr(obj, "py_func"):
            cls = cls or _guarded_cache_class()
            obj._cache = cls(obj.py_func)
            count += 1
    return count


# ------------------------------------------------------------------ maintenance
def cache_info() -> dict[str, Any]:
    """Summary of the cache for ``brakesqueal cache info``.

    Returns
    -------
    dict
        ``root``, ``current`` (this version's directory name) and
        ``versions``: ``{directory name: {"files": n, "bytes": size, "marked": bool}}``
        for every directory in the root (``marked``: made by the cache, see
        :data:`MARKER`; unmarked ones are never removed by :func:`clear_cache`).
        Symbolic links are neither listed nor followed.
    """
    root = cache_root()
    versions: dict[str, dict[str, int]] = {}
    if root.is_dir():
        for d in sorted(p for p in root.iterdir() if p.is_dir() and not p.is_symlink()):
            files = [f for f in d.rglob("*") if f.is_file() and not f.is_symlink()]
            versions[d.name] = {"files": len(files), "bytes": sum(f.lstat().st_size for f in files),
                                "marked": _marked(d, _KIND_VERSION)}
    return {"root": str(root), "current": version_dir().name, "versions": versions}


@dataclass
class ClearReport:
    """What :func:`clear_cache` did.

    Attributes
    ----------
    removed : list of Path
        Directories deleted (a whole version directory, or single entries of a
        version directory that also holds items the cache did not make).
    skipped : list of (Path, str)
        Items left in place and why (not made by the cache, a symbolic link,
        or a directory that could not be deleted).
    """

    removed: list[Path] = field(default_factory=list)
    skipped: list[tuple[Path, str]] = field(default_factory=list)


_NOT_OURS = "not made by the brakesqueal cache (no {marker} marker)"
_OLD = ("no {marker} marker (an older brakesqueal's cache, or not a cache at all): left alone; "
        "if it is an old cache, delete it by hand")
_LINK = "a symbolic link: left alone (the cache makes none, and never deletes through one)"


def _why_not_ours(p: Path) -> str:
    if p.is_symlink():
        return _LINK
    if p.is_dir() and re.fullmatch(r"[0-9][^/]*-[0-9a-f]{12}", p.name):
        return _OLD.format(marker=MARKER)
    return _NOT_OURS.format(marker=MARKER)


def _rmtree(d: Path) -> str | None:
    """Delete a directory tree (never following symbolic links); the reason if it (partly) stays."""
    errors: list[OSError] = []

    def onerror(func: Any, path: str, exc_info: Any) -> None:
        errors.append(exc_info[1])

    shutil.rmtree(d, onerror=onerror)  # symbolic links inside are removed as links, their targets stay
    if os.path.lexists(d):
        exc = next((e for e in errors if isinstance(e, OSError)), None)
        return "could not be deleted: " + ((exc.strerror or str(exc)).lower() if exc else "unknown reason")
    return None


def clear_cache(stale_only: bool = False) -> ClearReport:
    """Delete what the cache made: marked version directories and their marked entries.

    Only directories that carry the cache's :data:`MARKER` are removed.  In a
    marked version directory every marked entry is removed; anything else
    found there (or in the root) is left in place and reported, and the
    version directory itself is then kept.  Symbolic links are never
    followed: a link is left in place and reported, as is what it points to.

    Parameters
    ----------
    stale_only : bool, optional
        Keep the directory of the running package version and fingerprint.

    Returns
    -------
    ClearReport
        What was deleted and what was left, with the reason.
    """
    root = cache_root()
    current = version_dir().name
    report = ClearReport()
    if not root.is_dir():
        return report
    for d in sorted(root.iterdir()):
        if stale_only and d.name == current and not d.is_symlink():
            continue
        if not _marked(d, _KIND_VERSION):
            report.skipped.append((d, _why_not_ours(d)))
            continue
        kept = False
        for e in sorted(d.iterdir()):
            if e.name == MARKER:
                continue
            if not _marked(e, _KIND_ENTRY):
                report.skipped.append((e, _why_not_ours(e)))
                kept = True
                continue
            why = _rmtree(e)
            if why is None:
                report.removed.append(e)
            else:
                report.skipped.append((e, why))
                kept = True
        if kept:
            continue
        try:
            mark = (d / MARKER).read_bytes()
            (d / MARKER).unlink()
        except OSError as exc:
            report.skipped.append((d, "could not be deleted: " + (exc.strerror or str(exc)).lower()))
            continue
        try:
            d.rmdir()
        except OSError as exc:  # e.g. a run wrote a new entry meanwhile: the directory stays, marked
            with contextlib.suppress(OSError):
                _atomic_write(d / MARKER, mark)
            report.skipped.append((d, "could not be deleted: " + (exc.strerror or str(exc)).lower()))
            continue
        report.removed[:] = [p for p in report.removed if p.parent != d]
        report.removed.append(d)
    return report
