"""``brakesqueal sweep`` (parameter studies on Dask).

Registered by :mod:`brakesqueal.cli` through :func:`register`; dask, zarr and
xarray are imported inside the commands.
"""

from __future__ import annotations

import json
import sys
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Optional

import typer

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["register"]


class _Fmt(str, Enum):
    text = "text"
    json = "json"


def sweep(
    study: Annotated[str, typer.Argument(help="Study file (TOML): model, axes or samples, quantities.")],
    out: Annotated[Optional[str], typer.Option("--out", help="Zarr store (default: [output] store, "
                                                             "else STUDY.zarr).")] = None,
    workers: Annotated[Optional[int], typer.Option("--workers", help="Start a local Dask cluster with N "
                                                                     "worker processes (at most 4 per usable core; "
                                                                     "BRAKESQUEAL_MAX_WORKERS=N raises the cap).")
                       ] = None,
    scheduler: Annotated[Optional[str], typer.Option("--scheduler", help="Address of an existing Dask "
                                                                         "scheduler (tcp://host:8786).")] = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace an existing store.")] = False,
    status: Annotated[bool, typer.Option("--status", help="Only report completed and missing chunks.")] = False,
    progress: Annotated[Optional[bool], typer.Option("--progress/--no-progress",
                                                     help="Progress: a bar on a terminal, a line every "
                                                          "10 s otherwise (default); --no-progress: none.")] = None,
    fmt: Annotated[_Fmt, typer.Option("--format", help="Output format.")] = _Fmt.text,
) -> None:
    """Run a parameter study in chunks (resumable) into a Zarr store; --status reports its progress."""
    from ..errors import ParameterError
    from ..sweep import run_sweep, sweep_status
    from ..sweep.runner import check_scheduler_address, default_store
    from ..status import verdict_counts_text
    from ..sweep.study import load_study

    st = load_study(study)
    if status:
        s = sweep_status(st, store=out)
        sys.stdout.write(json.dumps(s.to_dict(), indent=2) + "\n" if fmt == _Fmt.json else s.text())
        return
    if scheduler is not None:
        scheduler = check_scheduler_address(scheduler)
    store = Path(out) if out else default_store(st)
    if store is None:  # pragma: no cover - a file study always has a default store
        raise ParameterError("no store: give --out")
    from ._progress import progress as _progress

    with _progress("sweep", progress) as cb:
        run = run_sweep(st, store=store, workers=workers, scheduler=scheduler, overwrite=overwrite, progress=cb)
    ds = run.dataset
    counts = _verdict_counts(ds)
    stable = counts["stable"] / st.n_points
    dims = " x ".join(f"{k}={v}" for k, v in zip(st.dims, st.shape))
    summary = {"store": str(store), "dims": dict(zip(st.dims, st.shape)), "points": st.n_points,
               "chunks": st.n_chunks, "computed_chunks": run.computed, "reused_chunks": run.reused,
               "repaired": run.repaired, "stable_fraction": stable, "stable": counts["stable"],
               "unstable": counts["unstable"], "status_counts": counts["status_counts"],
               "variables": list(ds.data_vars)}
    if fmt == _Fmt.json:
        sys.stdout.write(json.dumps(summary, indent=2) + "\n")
    else:
        fixed = f"; repaired: {'; '.join(run.repaired)}" if run.repaired else ""
        verdicts = verdict_counts_text(st.n_points, counts["stable"], counts["unstable"], counts["status_counts"])
        sys.stdout.write(f"wrote {store}: {dims} ({st.n_chunks} chunks: {run.computed} computed, {run.reused} "
                         f"reused{fixed}); {verdicts}\n")


def _verdict_counts(ds: xr.Dataset) -> dict[str, Any]:
    """Stable and unstable points (by status: only decided points have a verdict) and points per status."""
    import dask

    from ..status import DECIDED, PointStatus

    status, stable = ds["status"], ds["stable"].astype(bool)
    decided = status.isin([int(s) for s in DECIDED])
    sums = [stable.sum(), (decided & ~stable).sum(), *[(status == int(s)).sum() for s in PointStatus]]
    vals = [int(v) for v in dask.compute(*[x.data for x in sums])]
    return {"stable": vals[0], "unstable": vals[1],
            "status_counts": {s.meaning: v for s, v in zip(PointStatus, vals[2:]) if v}}


def register(app: typer.Typer) -> None:
    """Add ``sweep`` to ``app``."""
    app.command("sweep")(sweep)
