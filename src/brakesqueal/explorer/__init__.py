"""The squeal explorer: the toolkit in the browser, live and offline (``brakesqueal explore``).

Needs the optional extra ``explorer`` (``pip install brakesqueal[explorer]``,
which brings Panel and Bokeh).  :mod:`.state` holds the view state and the
computations (no user-interface code), :mod:`.app` the page, :mod:`.serve`
the server; see ``docs/explorer.md``.
"""

from __future__ import annotations

from .state import MAX_MAP_POINTS, MAX_T_END, Origin, ViewState

__all__ = ["MAX_MAP_POINTS", "MAX_T_END", "Origin", "ViewState", "serve", "make_server"]


def serve(*args: object, **kwargs: object) -> None:
    """:func:`brakesqueal.explorer.server.serve` (imports Panel on first use)."""
    from .server import serve as _serve

    _serve(*args, **kwargs)  # type: ignore[arg-type]


def make_server(*args: object, **kwargs: object) -> object:
    """:func:`brakesqueal.explorer.server.make_server` (imports Panel on first use)."""
    from .server import make_server as _make_server

    return _make_server(*args, **kwargs)  # type: ignore[arg-type]
