"""Content fingerprints of package sources and of the third-party code generators.

One hash for both places that must notice a changed source: the code cache
(:func:`brakesqueal.codegen.cache.source_fingerprint`) and the closed forms shipped
for ``derive`` (:func:`brakesqueal.cli.closed_forms.fingerprint`).  Standard library
only, so a cold ``derive`` stays free of NumPy.
"""

from __future__ import annotations

import hashlib
import importlib.util
from collections.abc import Iterable
from pathlib import Path

__all__ = ["EXTERNAL", "sources_digest"]

#: Third-party files whose content enters every fingerprint (their printers and simplifications shape
#: the generated code and text): upgrading SymPy or symengine changes the hash.
EXTERNAL: tuple[tuple[str, str], ...] = (("sympy", "release.py"), ("symengine", "_version.py"))


def sources_digest(files: Iterable[tuple[str, Path]]) -> str:
    """SHA-256 of source files (name, size, content) and of the :data:`EXTERNAL` files.

    Parameters
    ----------
    files : iterable of (str, Path)
        A stable name (the path relative to the package) and the file, in a fixed order.

    Returns
    -------
    str
        64 hex digits.  Line endings are normalised to ``\\n`` (a CRLF checkout is the same
        source); a missing or unreadable file hashes as ``missing``, so it differs from any content.
    """
    h = hashlib.sha256()
    for name, path in files:
        try:
            data = path.read_bytes().replace(b"\r\n", b"\n")
        except OSError:
            data = b"missing"
        h.update(f"{name}\0{len(data)}\0".encode())
        h.update(data)
    for dist, rel in EXTERNAL:
        spec = importlib.util.find_spec(dist)
        origin = Path(spec.origin).parent / rel if spec is not None and spec.origin else None
        try:
            h.update(dist.encode() + b"\0" + (origin.read_bytes() if origin else b"missing"))
        except OSError:
            h.update(dist.encode() + b"\0unreadable")
    return h.hexdigest()
