"""Parameter studies at scale: N-D grids or random / Latin-hypercube samples, chunked, on Dask, resumable.

* :func:`sweep` — run a study (in-process, ``workers=N`` local Dask cluster,
  ``scheduler=ADDRESS`` or ``client=``) into a Zarr store and return an
  :class:`xarray.Dataset` with named dimensions;
* :func:`run_sweep` — the same, also reporting computed / reused chunks and repairs;
* :func:`sweep_status` — completed / missing / corrupt chunks of a store, damage, lock holder;
* :func:`load_study` / :class:`Study` — the validated study file;
* :func:`open_sweep` — open a store;
* :func:`plot_sweep` — the figure of a store (map, slice or histograms; ``brakesqueal plot``).

See ``docs/sweeps.md`` for the study-file format.
"""

from __future__ import annotations

from .plots import plot_sweep
from .runner import SweepRun, SweepStatus, open_sweep, run_sweep, sweep, sweep_status
from .store import StoreError
from .study import QUANTITIES, Study, load_study

__all__ = ["QUANTITIES", "Study", "StoreError", "SweepRun", "SweepStatus", "load_study", "open_sweep", "plot_sweep",
           "run_sweep", "sweep", "sweep_status"]
