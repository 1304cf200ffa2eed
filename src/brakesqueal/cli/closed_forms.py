"""The paper model's closed forms as shipped text: ``brakesqueal derive`` without SymPy.

``derive --case C --format F`` prints text that depends only on the source of the
derivation (:func:`brakesqueal.render.render_closed_form` and the modules it
imports) and on the SymPy/symengine versions.  That text, for every case and
format, is generated once into :mod:`brakesqueal.cli._closed_forms` together with a
fingerprint of those sources; the command prints it when the fingerprint still
matches the installed files, so a cold ``derive`` imports neither SymPy nor NumPy.
When anything the derivation reads has changed, :func:`shipped_text` returns
``None`` and the command derives as before.

``tests/cli/test_derive_shipped.py`` checks every shipped text against the live
derivation, that the fingerprint is current and that it covers every code-generating
module (:data:`brakesqueal.codegen.cache.GENERATOR_MODULES`) the derivation imports.
Check, and regenerate after editing the derivation (or upgrading SymPy/symengine)::

    python -m brakesqueal.cli.closed_forms          # exit 1 when stale
    python -m brakesqueal.cli.closed_forms --write
"""

from __future__ import annotations

from pathlib import Path

from ..fingerprint import sources_digest

__all__ = ["CASES", "FORMATS", "shipped_text", "fingerprint", "derivation_sources", "live_texts", "data_source",
           "write_data"]

#: Closed-form cases of the paper's model (``derive --case``).
CASES: tuple[str, ...] = ("general", "symmetric", "asymmetric-friction", "minimal")
#: Output formats of ``derive --format``.
FORMATS: tuple[str, ...] = ("text", "latex", "json")
_PKG = Path(__file__).resolve().parent.parent
_DATA = Path(__file__).resolve().parent / "_closed_forms.py"


def fingerprint(sources: tuple[str, ...]) -> str:
    """Hash of package source files and of the SymPy/symengine version files.

    Parameters
    ----------
    sources : tuple of str
        Paths relative to the ``brakesqueal`` package directory (``"symbolic/model.py"``).

    Returns
    -------
    str
        64 hex digits; a missing file hashes as ``missing`` (so it differs from any content), line
        endings are normalised to ``\\n``.
    """
    return sources_digest((rel, _PKG / rel) for rel in sources)


def shipped_text(case: str, fmt: str) -> str | None:
    """The shipped output of ``derive --case case --format fmt``, if it is still current.

    Parameters
    ----------
    case : str
        One of :data:`CASES`.
    fmt : str
        One of :data:`FORMATS`.

    Returns
    -------
    str or None
        The text exactly as :func:`brakesqueal.render.render_closed_form` returns it, or ``None``
        when there is none for this case and format or the derivation's sources (or SymPy/symengine)
        differ from those it was generated from.
    """
    try:
        from . import _closed_forms as data
    except ImportError:
        return None
    text = data.TEXTS.get((case, fmt))
    if text is None or fingerprint(data.SOURCES) != data.FINGERPRINT:
        return None
    return text


_PROBE = """
import json, sys
from brakesqueal.render import render_closed_form
texts = {{f"{{c}}|{{f}}": render_closed_form(c, f) for c in {cases!r} for f in {formats!r}}}
from pathlib import Path
files = {{str(Path(m.__file__).resolve()) for n, m in list(sys.modules.items())
         if n.split(".")[0] == "brakesqueal" and getattr(m, "__file__", None)}}
from brakesqueal.codegen import cache
gen = {{str(p.resolve()) for p in cache.generator_files()}}
print(json.dumps({{"texts": texts, "files": sorted(f for f in files if f in gen)}}))
"""


def _probe() -> dict[str, object]:
    """Run the live derivation of every case and format in a fresh interpreter."""
    import json
    import subprocess
    import sys

    proc = subprocess.run([sys.executable, "-c", _PROBE.format(cases=CASES, formats=FORMATS)], capture_output=True,
                          text=True, check=True)
    out: dict[str, object] = json.loads(proc.stdout.strip().splitlines()[-1])
    return out


def derivation_sources() -> tuple[str, ...]:
    """Code-generating package modules a fresh interpreter imports to derive every closed form.

    Returns
    -------
    tuple of str
        Paths relative to the package directory, sorted: the modules of
        :data:`brakesqueal.codegen.cache.GENERATOR_MODULES` that the live derivation imports.
    """
    files = _probe()["files"]
    assert isinstance(files, list)
    return tuple(sorted(Path(f).resolve().relative_to(_PKG).as_posix() for f in files))


def live_texts() -> dict[tuple[str, str], str]:
    """The live derivation's output for every case and format, derived in a fresh interpreter.

    Returns
    -------
    dict
        ``(case, fmt) -> text`` exactly as :func:`brakesqueal.render.render_closed_form` returns it.
    """
    texts = _probe()["texts"]
    assert isinstance(texts, dict)
    out: dict[tuple[str, str], str] = {}
    for key, text in texts.items():
        case, _, fmt = key.partition("|")
        out[case, fmt] = text
    return out


def data_source() -> str:
    """Source of :mod:`brakesqueal.cli._closed_forms` for the installed derivation.

    Returns
    -------
    str
        A Python module defining ``SOURCES``, ``FINGERPRINT`` and ``TEXTS``.
    """
    probe = _probe()
    files, texts = probe["files"], probe["texts"]
    assert isinstance(files, list) and isinstance(texts, dict)
    sources = tuple(sorted(Path(f).resolve().relative_to(_PKG).as_posix() for f in files))
    lines = [
        '"""Generated by ``python -m brakesqueal.cli.closed_forms --write``; do not edit (see '
        ':mod:`.closed_forms`)."""',
        "# ruff: noqa: E501",
        "",
        "#: Package files (relative to ``brakesqueal/``) the texts were derived from.",
        "SOURCES: tuple[str, ...] = (",
        *(f"    {s!r}," for s in sources),
        ")",
        "#: :func:`brakesqueal.cli.closed_forms.fingerprint` of ``SOURCES`` when the texts were derived.",
        f"FINGERPRINT = {fingerprint(sources)!r}",
        "#: ``(case, format) -> derive output``.",
        "TEXTS: dict[tuple[str, str], str] = {",
        *(f"    ({c!r}, {f!r}): {texts[f'{c}|{f}']!r}," for c in CASES for f in FORMATS),
        "}",
    ]
    return "\n".join(lines) + "\n"


def write_data() -> Path:
    """Regenerate :mod:`brakesqueal.cli._closed_forms` from the live derivation.

    Returns
    -------
    Path
        The written file.
    """
    _DATA.write_text(data_source(), encoding="utf-8")
    return _DATA


def _main(argv: list[str]) -> int:
    """``python -m brakesqueal.cli.closed_forms [--write]``: check (exit 1 when stale) or regenerate."""
    if argv == ["--write"]:
        print(f"wrote {write_data()}")
        return 0
    if argv:
        print("usage: python -m brakesqueal.cli.closed_forms [--write]")
        return 2
    current = _DATA.exists() and _DATA.read_text(encoding="utf-8") == data_source()
    print(f"{_DATA} is {'current' if current else 'stale: regenerate it with --write'}")
    return 0 if current else 1


if __name__ == "__main__":
    import sys

    raise SystemExit(_main(sys.argv[1:]))
