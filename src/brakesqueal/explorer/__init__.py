"""The squeal explorer: the toolkit in the browser, live and offline (``brakesqueal explore``).

Needs the optional extra ``explorer`` (``pip install brakesqueal[explorer]``,
which brings Panel and Bokeh).  :mod:`.state` holds the view state and the
computations (no user-interface code), :mod:`.app` the page, :mod:`.serve`
the server; see ``docs/explorer.md``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .state import MAX_MAP_POINTS, MAX_T_END, Origin, ViewState

__all__ = ["MAX_MAP_POINTS", "MAX_T_END", "Origin", "ViewState", "serve", "make_server"]


if TYPE_CHECKING:  # their signatures; at run time the wrappers below import the server module on first use
    from .server import make_server, serve
else:
    def serve(*args, **kwargs):
        """:func:`brakesqueal.explorer.server.serve` (imports Panel on first use)."""
        from .server import serve as _serve

        _serve(*args, **kwargs)

    def make_server(*args, **kwargs):
        """:func:`brakesqueal.explorer.server.make_server` (imports Panel on first use)."""
        from .server import make_server as _make_server

        return _make_server(*args, **kwargs)
