"""Export of the explorer's current view (issue 29): the shown map as NetCDF and CSV, the root locus's modes as
CSV, each parsed back and compared with what the page shows; PNG through the figures' save tools."""

from __future__ import annotations

import io
import time

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from brakesqueal import ParameterError, resolve_space
from brakesqueal.explorer.state import Origin, map_file


def _wait(predicate, timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.02)
    return False


@pytest.fixture(scope="module")
def explorer():
    from brakesqueal.explorer import app

    ex = app.Explorer(Origin(resolve_space(None, "paper-fig2", None, [])), {"nx": "7", "ny": "5"})
    assert _wait(lambda: "map" in ex.shown and ex._drawn_tracks is not None, 120), ex.shown
    yield ex
    ex.stop()


def shown_codes(ex) -> np.ndarray:
    """The map's colour codes as drawn, ``[y, x]``: 0 unstable, 1 stable, 2 no verdict."""
    return np.asarray(ex.src_map.data["image"][0])


def test_the_map_exports_as_netcdf_with_the_shown_verdicts(explorer):
    ex = explorer
    assert not ex.map_nc_download.disabled and ex.map_nc_download.filename == "map_k_ip_mu.nc"
    data = ex.map_nc_download.callback().getvalue()
    ds = xr.open_dataset(io.BytesIO(data), engine="scipy").load()
    assert (ds.sizes["k_ip"], ds.sizes["mu"]) == (7, 5)
    stable = ds["stable"].transpose("mu", "k_ip").values.astype(bool)
    decided = ds["status"].transpose("mu", "k_ip").values <= 1
    assert np.array_equal(np.where(decided, stable, 2), shown_codes(ex))
    assert float(stable.mean()) == pytest.approx(ex.shown["map"]["stable_fraction"])
    np.testing.assert_allclose(np.log10(ds["k_ip"].values[0]), ex.src_map.data["x"][0]
                               + (np.log10(ds["k_ip"].values[1]) - np.log10(ds["k_ip"].values[0])) / 2)


def test_the_map_exports_as_csv_with_the_shown_verdicts(explorer):
    ex = explorer
    table = pd.read_csv(io.BytesIO(ex.map_csv_download.callback().getvalue()))
    assert len(table) == ex.shown["map"]["points"] == 35
    grid = table.pivot(index="mu", columns="k_ip", values="stable").values.astype(bool)
    status = table.pivot(index="mu", columns="k_ip", values="status").values
    assert np.array_equal(np.where(status <= 1, grid, 2), shown_codes(ex))


def test_the_locus_exports_the_drawn_modes(explorer):
    ex = explorer
    assert ex.locus_download.filename == "locus_mu.csv"
    table = pd.read_csv(io.BytesIO(ex.locus_download.callback().getvalue()))
    drawn = ex._drawn_tracks
    assert len(table) == drawn.eigenvalues.size
    real = table.pivot(index="mu", columns="mode", values="real").values
    np.testing.assert_allclose(real, drawn.eigenvalues.real, rtol=1e-12)
    # the path spans the current value (paper-fig2: mu = 0.5)
    assert table["mu"].min() <= 0.5 <= table["mu"].max()


def test_figures_save_png_and_a_view_without_a_map_refuses():
    from brakesqueal.explorer import app
    from brakesqueal.explorer.state import MapView

    ex = app.Explorer(Origin(resolve_space(None, "paper-fig2", None, [])), {"nx": "2", "ny": "2"})
    try:
        assert "SaveTool" in {type(t).__name__ for t in ex.fig_map.tools}
        assert "SaveTool" in {type(t).__name__ for t in ex.fig_locus.tools}
    finally:
        ex.stop()
    empty = MapView(*(np.empty(0),) * 2, False, False, *(np.empty(0),) * 5, "")
    with pytest.raises(ParameterError, match="no map"):
        map_file(empty, "csv")
    with pytest.raises(ParameterError, match="netcdf, csv"):
        map_file(empty, "xlsx")


def test_the_map_shows_the_disk_modes_and_marks_pad_only_points():
    """Asymmetric friction: a massless pad's own 0 Hz mode is unstable where the disk's modes are stable; the
    map draws those points apart (code 3), as the figures hatch them, and says how many there are."""
    from brakesqueal.explorer import app

    ex = app.Explorer(Origin(resolve_space(None, "paper-fig2", None, ["mu1=0.5", "mu2=0.5"])),
                      {"x": "mu1", "y": "mu2", "nx": "6", "ny": "6"})
    try:
        assert _wait(lambda: "map" in ex.shown, 120), ex.shown
        ds = ex._map_view.result.data
        disk = ds["disk_stable"].transpose("mu2", "mu1").values
        stable = ds["stable"].transpose("mu2", "mu1").values.astype(bool)
        decided = ds["status"].transpose("mu2", "mu1").values <= 1
        expected = np.where(decided, np.where(~stable & (disk == 1), 3, stable), 2)
        assert np.array_equal(shown_codes(ex), expected)
        assert ex.shown["map"]["pad_only"] == int((expected == 3).sum()) > 0
        assert "only a massless pad's own 0 Hz mode" in ex.map_text.object
    finally:
        ex.stop()
