"""Closest-name suggestions for misspelled parameter, model, preset and key names."""

from __future__ import annotations

import difflib
from collections.abc import Iterable

__all__ = ["closest", "did_you_mean"]


def closest(name: str, candidates: Iterable[str]) -> str | None:
    """The candidate closest to ``name`` (case-insensitive first, then by similarity), or ``None``.

    Parameters
    ----------
    name : str
        The unknown name, e.g. ``"kip"`` or ``"Omgea"``.
    candidates : iterable of str
        The valid names.

    Returns
    -------
    str or None
        A valid name that differs only in case, else the most similar one
        with a similarity ratio of at least 0.6 (:func:`difflib.get_close_matches`).
    """
    cands = [c for c in candidates if isinstance(c, str)]
    folded = {c.lower().replace("_", ""): c for c in cands}
    key = str(name).lower().replace("_", "")
    if key in folded:
        return folded[key]
    match = difflib.get_close_matches(key, list(folded), n=1, cutoff=0.6)
    return folded[match[0]] if match else None


def did_you_mean(name: str, candidates: Iterable[str]) -> str:
    """``" (did you mean 'k_ip'?)"`` or ``""`` when nothing is close."""
    c = closest(name, candidates)
    return f" (did you mean '{c}'?)" if c is not None and c != name else ""
