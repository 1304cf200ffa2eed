"""Static parts of generated kernels, kept as real (linted, typed) Python files and read as text.

Each template is a module whose text below the line ``# ---- template body ----`` is appended to generated
code; the stand-ins above that line make the file importable and lintable on its own.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["template", "MARKER"]

#: The line that separates a template's stand-ins from its body.
MARKER = "# ---- template body ----"


def template(name: str) -> str:
    """The body of template ``name`` (a file of this package, without ``.py``).

    Parameters
    ----------
    name : str
        The template's module name, e.g. ``"silent_newton"``.

    Returns
    -------
    str
        The text below :data:`MARKER`.
    """
    text = (Path(__file__).parent / f"{name}.py").read_text(encoding="utf-8")
    head, sep, body = text.partition(MARKER + "\n")
    if not sep:
        raise ValueError(f"template {name!r} has no line {MARKER!r}")
    return "\n\n" + body
