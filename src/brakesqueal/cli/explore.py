"""``brakesqueal explore``: the squeal explorer in the browser (optional extra ``explorer``)."""

from __future__ import annotations

from typing import Annotated

import typer

from ._options import ModelOpt, ParamsOpt, PresetOpt, SetOpt, space_from

__all__ = ["register"]


def explore(
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
    port: Annotated[int, typer.Option("--port", help="TCP port (0: any free port).", min=0, max=65535)] = 5006,
    host: Annotated[str, typer.Option("--host", help="Address to bind; anything but loopback needs "
                                      "--allow-remote.")] = "127.0.0.1",
    allow_remote: Annotated[bool, typer.Option("--allow-remote", help="Allow a --host beyond loopback (the URL's "
                                               "token and the Host/Origin checks stay).")] = False,
    no_browser: Annotated[bool, typer.Option("--no-browser", help="Do not open a browser tab.")] = False,
) -> None:
    """Serve the squeal explorer: sliders, root locus, stability map, critical speeds, Hopf criticality, simulation
    and the squeal as audio, live in the browser and offline.

    The URL printed at start carries the server's token (?token=...): the explorer serves only requests that
    carry it (or the cookie it sets), name this server in their Host header and come from its own page.
    Needs the optional dependencies: pip install 'brakesqueal[explorer]'.  Ctrl-C stops the server.
    """
    from ..errors import ParameterError

    from ..explorer.server import check_address

    check_address(host, port, allow_remote)  # before resolving the model: a refused address is said at once
    space = space_from(model, preset, params, set_)
    try:
        import panel  # noqa: F401
    except ImportError:
        raise ParameterError("the explorer needs Panel: pip install 'brakesqueal[explorer]'") from None
    from ..explorer.server import serve

    serve(space, port=port, host=host, open_browser=not no_browser, allow_remote=allow_remote)


def register(app: typer.Typer, *_: typer.Typer) -> None:
    """Add ``explore`` to the application."""
    app.command("explore")(explore)
