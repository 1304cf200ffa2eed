"""On-disk cache of derived models, keyed on package version and model options.

The cache lives in ``$BRAKESQUEAL_CACHE_DIR`` if set, otherwise in
``$XDG_CACHE_HOME/brakesqueal`` (``~/.cache/brakesqueal``).  Each entry is a
directory ``<version>/<key>/`` holding generated Python source and rendered
text; writes are atomic (temporary file + rename), so concurrent processes
never read half-written files.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

from .. import __version__

__all__ = ["cache_root", "entry_dir", "read_text", "write_text", "source_fingerprint"]


def cache_root() -> Path:
    """Root directory of the cache (not created)."""
    env = os.environ.get("BRAKESQUEAL_CACHE_DIR")
    if env:
        return Path(env).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "brakesqueal"


def source_fingerprint() -> str:
    """Short hash of the symbolic layer's source (invalidates stale development caches)."""
    h = hashlib.sha256()
    sym = Path(__file__).resolve().parent.parent / "symbolic"
    for f in sorted(sym.glob("*.py")) + [Path(__file__).with_name("codegen.py")]:
        h.update(f.read_bytes())
    return h.hexdigest()[:12]


def entry_dir(key: str) -> Path:
    """Directory of one cache entry: ``<root>/<version>-<fingerprint>/<key>``."""
    return cache_root() / f"{__version__}-{source_fingerprint()}" / key


def read_text(key: str, name: str) -> str | None:
    """Cached file content, or ``None`` when absent or unreadable."""
    try:
        return (entry_dir(key) / name).read_text(encoding="utf-8")
    except OSError:
        return None


def write_text(key: str, name: str, text: str) -> Path | None:
    """Atomically write a cache file; returns its path, or ``None`` if the cache is not writable."""
    d = entry_dir(key)
    try:
        d.mkdir(parents=True, exist_ok=True)
        tmp = d / f".{name}.{os.getpid()}.tmp"
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, d / name)
        return d / name
    except OSError:
        return None
