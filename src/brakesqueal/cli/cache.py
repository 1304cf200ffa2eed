"""``brakesqueal cache info | clear`` (registered by :mod:`brakesqueal.cli`)."""

from __future__ import annotations

import sys
from typing import Annotated

import typer

__all__ = ["register"]

cache_app = typer.Typer(help="Inspect or clear the code cache ($BRAKESQUEAL_CACHE_DIR, default ~/.cache/brakesqueal).",
                        no_args_is_help=True)  # fmt: skip


@cache_app.command("info")
def _info_cmd() -> None:
    """Print the cache root and the files and bytes per package version (* = in use)."""
    from ..codegen.cache import MARKER, cache_info

    info = cache_info()
    sys.stdout.write(f"root {info['root']}\n")
    for name, v in info["versions"].items():
        mark = "*" if name == info["current"] else " "
        note = "" if v["marked"] else f"  (no {MARKER} marker: not the cache's; 'cache clear' leaves it)"
        sys.stdout.write(f"{mark} {name:24s} {v['files']:6d} files {v['bytes'] / 2 ** 20:10.2f} MiB{note}\n")
    if info["current"] not in info["versions"]:
        sys.stdout.write(f"* {info['current']:24s} (not created yet)\n")


@cache_app.command("clear")
def _clear_cmd(
    stale: Annotated[bool, typer.Option("--stale", help="Only remove directories of other versions.")] = False,
) -> None:
    """Delete cached code (regenerated on the next run); only what the cache made (marked
    directories) is deleted, everything else in the cache directory is listed as skipped."""
    from ..codegen.cache import clear_cache

    report = clear_cache(stale_only=stale)
    for d in report.removed:
        sys.stdout.write(f"removed {d}\n")
    for d, why in report.skipped:
        sys.stdout.write(f"skipped {d}: {why}\n")
    if not report.removed and not report.skipped:
        sys.stdout.write("nothing to remove\n")


def register(app: typer.Typer) -> None:
    """Add the ``cache`` command group to the application.

    Parameters
    ----------
    app : typer.Typer
        The main application (:data:`brakesqueal.cli.app`).
    """
    app.add_typer(cache_app, name="cache")
