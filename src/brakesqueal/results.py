"""Result objects of the stability analysis: conversion to xarray, files, ``.plot()``.

``.plot()`` returns the matplotlib figure (Agg backend, never ``plt.show()``).
NetCDF files are written with xarray's ``scipy`` engine (NetCDF3, no extra
dependency); booleans are stored as ``int8`` with ``flag_values`` /
``flag_meanings`` and restored by :func:`open_map`.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .labels import unit

__all__ = ["StabilityMap", "CrossingResult", "CriticalSpeedResult", "open_map", "MapFile", "plot_map_file"]

def _status_attrs() -> dict[str, Any]:
    from .status import STATUS_MEANINGS, PointStatus

    return {"flag_values": np.array([int(s) for s in PointStatus], dtype=np.int8), "flag_meanings": STATUS_MEANINGS}


def _map_attrs(space: Any, method: str) -> dict[str, Any]:
    """Global attributes of a stability map (Dataset and NetCDF file)."""
    return {"model": space.model.name, "space": space.label,
            "settings": json.dumps({k: str(v) for k, v in space.definitions().items()}),
            "tied": json.dumps(dict(space.tied)), "method": method,
            "criterion": "certified verdict from every eigenvalue of the linear model about the silent motion "
                         "(Lienard-Chipart on the exact quartic where the closed form applies)"}


_VAR_ATTRS = {
    "max_real": {"units": "1/s", "long_name": "largest real part of the eigenvalues"},
    "stable": {"long_name": "silent motion asymptotically stable (certified)"},
    "frequency": {"units": "Hz", "long_name": "frequency of the least-stable mode"},
}
_STABLE_FLAGS = {"flag_values": np.array([0, 1], dtype=np.int8), "flag_meanings": "unstable stable"}


def _coord_attrs(ax: Any, space: Any) -> dict[str, Any]:
    return {"units": unit(ax.name, space), "scale": "log" if ax.log else "linear"}


#: Dimension of the stored boundary vertices (curves separated by NaN).
BOUNDARY_DIM = "boundary_vertex"


def _boundary_attrs(name: str, space: Any) -> dict[str, Any]:
    return {"units": unit(name, space),
            "long_name": f"{name} along the stability boundary (curves separated by NaN; vertices refined "
                         "onto the boundary by bisection, brakesqueal.analysis.boundary)"}


def boundary_of(ds_or_vars: Any, names: tuple[str, str]) -> tuple[np.ndarray, np.ndarray] | None:
    """The stored boundary ``(values of names[0], values of names[1])`` of a map, or ``None``."""
    keys = [f"boundary_{n}" for n in names]
    if not all(k in ds_or_vars for k in keys):
        return None
    # xarray variables have .values, scipy.io.netcdf variables .data
    a, b = (np.array(v.values if hasattr(v, "dims") else v.data, dtype=float) for v in (ds_or_vars[k] for k in keys))
    return a, b


class MapFile:
    """A stability map's NetCDF3 file whose variables are filled in place, row block by row block.

    The file has the layout :meth:`StabilityMap.to_netcdf` writes and is read
    back by :func:`open_map`.  It is a :func:`scipy.io.netcdf_file` whose
    variables' arrays (attributes ``stable``, ``status``, ``max_real``,
    ``frequency``) are the map's result arrays, so no second copy of the map
    (an xarray Dataset, a converted copy per variable) is built; the data
    are written when the file is closed.

    Parameters
    ----------
    path : str
        The file (created or truncated).
    space : ParameterSpace
        The map's parameter space.
    outer, inner : Axis
        The axes (dimension order).
    eigen : bool
        Whether ``max_real`` and ``frequency`` are stored.
    float_dtype : numpy dtype
        Type of ``max_real`` and ``frequency`` (float32 or float64).
    """

    def __init__(self, path: str, space: Any, outer: Any, inner: Any, *, eigen: bool,
                 float_dtype: Any = np.float64) -> None:
        from scipy.io import netcdf_file

        self.space = space
        self._f = netcdf_file(path, "w", version=2, maskandscale=False)
        ft = np.dtype(float_dtype)
        dims = (outer.name, inner.name)
        for ax in (outer, inner):
            self._f.createDimension(ax.name, ax.num)
            v = self._f.createVariable(ax.name, "d", (ax.name,))
            v[:] = ax.values()
            self._attrs(v, {**_coord_attrs(ax, space), "_FillValue": np.float64(np.nan)})
        self.max_real = self.frequency = None
        if eigen:
            self.max_real = self._var("max_real", ft, dims, {**_VAR_ATTRS["max_real"], "_FillValue": ft.type(np.nan)})
        self.stable = self._var("stable", np.int8, dims, {**_VAR_ATTRS["stable"], **_STABLE_FLAGS})
        if eigen:
            self.frequency = self._var("frequency", ft, dims,
                                       {**_VAR_ATTRS["frequency"], "_FillValue": ft.type(np.nan)})
        self.status = self._var("status", np.int8, dims, _status_attrs())

    @staticmethod
    def _attrs(v: Any, attrs: dict[str, Any]) -> None:
        for k, a in attrs.items():
            setattr(v, k, a)

    def _var(self, name: str, dtype: Any, dims: tuple[str, str], attrs: dict[str, Any]) -> np.ndarray:
        v = self._f.createVariable(name, np.dtype(dtype), dims)
        self._attrs(v, attrs)
        return v.data  # type: ignore[no-any-return]

    def write_boundary(self, b: Any) -> None:
        """Add the refined stability boundary (:class:`~brakesqueal.analysis.boundary.Boundary`) before closing."""
        n = int(b.coords[0].size)
        if n == 0:
            return
        self._f.createDimension(BOUNDARY_DIM, n)
        for name, values in zip(b.names, b.coords):
            v = self._f.createVariable(f"boundary_{name}", "d", (BOUNDARY_DIM,))
            v[:] = values
            self._attrs(v, {**_boundary_attrs(name, self.space), "_FillValue": np.float64(np.nan)})

    def close(self, method: str) -> None:
        """Set the global attributes (``method`` names the route), write the file and close it."""
        self._attrs(self._f, _map_attrs(self.space, method))
        self._f.close()

    def abort(self) -> None:
        """Close without meaningful content (the caller removes the file)."""
        self._f.fp.close()


@dataclass
class StabilityMap:
    """A stability map as an :class:`xarray.Dataset` (attribute :attr:`data`).

    Normally built by :func:`~brakesqueal.analysis.maps.stability_map` (via
    the classmethod ``from_arrays``) or read back with :func:`open_map`.

    Attributes
    ----------
    data : xarray.Dataset
        Two dimensions ``(outer, inner)``, each named after the swept
        parameter, with coordinates carrying ``units`` (SI) and ``scale``
        (``"linear"`` or ``"log"``) attributes.  Variables:

        * ``stable``: bool, silent motion asymptotically stable (certified);
          for status 0/1 ``stable`` ⇔ ``max_real < 0``;
        * ``status``: int8 :class:`~brakesqueal.status.PointStatus` code
          (``0`` ok, ``1`` ok with a non-trivial silent motion, ``2`` no
          silent motion, ``3`` a pad loses contact, ``4`` invalid parameters,
          ``5`` undecided, ``6`` solver failed, ``7`` a pad does not slide;
          see its ``flag_meanings``); points with ``status >= 2`` are never
          stable;
        * ``max_real``: largest real part of the eigenvalues of the linear
          model [1/s], and ``frequency``: frequency of the least-stable mode
          [Hz] — only when they were computed (not for verdict-only maps).

        Dataset attributes: ``model``, ``space`` (preset label), ``settings``
        and ``tied`` (JSON), ``method`` (the route) and ``criterion``.
    """

    data: Any

    @classmethod
    def from_arrays(cls, space: Any, outer: Any, inner: Any, *, stable: np.ndarray, status: np.ndarray,
                    max_real: np.ndarray | None, frequency: np.ndarray | None, method: str,
                    boundary: Any = None) -> StabilityMap:
        """Build the Dataset from computed arrays (``max_real``/``frequency`` ``None``: not computed, left out).

        Parameters
        ----------
        space : ParameterSpace
            The parameter space of the map.
        outer, inner : Axis
            The axes (dimension order).
        stable, status : ndarray
            Verdicts and status codes, shape ``(outer.num, inner.num)``.
        max_real, frequency : ndarray or None
            Least-stable eigenvalue summary, or ``None``.
        method : str
            The route.
        boundary : Boundary, optional
            The refined stability boundary (:func:`~brakesqueal.analysis.boundary.stability_boundary`),
            stored as ``boundary_<outer>``, ``boundary_<inner>`` along the dimension ``boundary_vertex``.

        Returns
        -------
        StabilityMap
        """
        import xarray as xr

        dims = (outer.name, inner.name)
        coords = {}
        for ax in (outer, inner):
            coords[ax.name] = xr.DataArray(ax.values(), dims=(ax.name,), attrs=_coord_attrs(ax, space))
        data: dict[str, Any] = {}
        if max_real is not None:
            data["max_real"] = (dims, max_real, dict(_VAR_ATTRS["max_real"]))
        data["stable"] = (dims, stable, dict(_VAR_ATTRS["stable"]))
        if frequency is not None:
            data["frequency"] = (dims, frequency, dict(_VAR_ATTRS["frequency"]))
        data["status"] = (dims, status, _status_attrs())
        if boundary is not None and boundary.coords[0].size:
            for name, values in zip(boundary.names, boundary.coords):
                data[f"boundary_{name}"] = ((BOUNDARY_DIM,), values, _boundary_attrs(name, space))
        return cls(xr.Dataset(data, coords=coords, attrs=_map_attrs(space, method)))

    @property
    def dims(self) -> tuple[str, str]:
        """The two axis names ``(outer, inner)``."""
        return tuple(self.data["stable"].dims)  # type: ignore[return-value]

    def to_xarray(self) -> Any:
        """The :class:`xarray.Dataset`."""
        return self.data

    def to_netcdf(self, path: str) -> None:
        """Write NetCDF3 (scipy engine); ``stable`` is stored as int8 flags."""
        ds = self.data.copy()
        ds["stable"] = ds["stable"].astype(np.int8)
        ds["stable"].attrs.update(_STABLE_FLAGS)
        ds.to_netcdf(path, engine="scipy")

    def to_csv(self, path: str) -> None:
        """Write a long-format CSV of the variables on the grid (one row per grid point).

        The refined boundary (its own dimension) stays in the NetCDF file:
        ``Dataset.to_dataframe`` of the whole map would form the product of the
        grid with it (gigabytes for a large map).
        """
        ds = self.data
        names = [v for v in ds.data_vars if set(ds[v].dims) == set(self.dims)]
        ds[names].to_dataframe().reset_index().to_csv(path, index=False)

    def boundary(self) -> list[np.ndarray]:
        """Stability boundary as polylines ``(n, 2)`` in (inner, outer) coordinates.

        The stored, refined boundary when the map has one (points on the
        stability boundary to the bisection's precision), else the 0.5 contour
        of ``stable`` (a staircase at the grid's resolution).
        """
        import contourpy

        o, i = self.dims
        stored = boundary_of(self.data, (o, i))
        if stored is not None:
            bo, bi = stored
            cut = np.flatnonzero(~np.isfinite(bo))
            return [np.column_stack([bi[a:b], bo[a:b]])
                    for a, b in zip([0, *(cut + 1).tolist()], [*cut.tolist(), bo.size]) if b > a]
        z = self.data["stable"].values.astype(float)
        z[self.data["status"].values >= 2] = np.nan
        gen = contourpy.contour_generator(self.data[i].values, self.data[o].values, z)
        return list(gen.lines(0.5))

    def plot(self, ax: Any = None, *, x: str | None = None, title: str | None = None,
             color: str = "verdict") -> Any:
        """Stability map: stable region shaded (or ``color = "max_real" | "frequency"``), refined boundary drawn,
        points without a verdict hatched; returns the figure (:func:`~brakesqueal.plotting.plot_map`)."""
        from .plotting import plot_map

        return plot_map(self, ax=ax, x=x, title=title, color=color)


def open_map(path: str) -> StabilityMap:
    """Read a map written by :meth:`StabilityMap.to_netcdf`.

    Parameters
    ----------
    path : str
        Path of the NetCDF3 file (read with xarray's ``scipy`` engine and
        loaded into memory, so the file is not kept open).

    Returns
    -------
    StabilityMap
        The map, with ``stable`` converted back from int8 flags to bool.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.  A file that is not NetCDF3 is rejected by
        :func:`xarray.open_dataset` with its own exception.
    """
    import xarray as xr

    ds = xr.open_dataset(path, engine="scipy").load()
    ds["stable"] = ds["stable"].astype(bool)
    return StabilityMap(ds)


def plot_map_file(path: str, *, x: str | None = None, title: str | None = None, color: str = "verdict") -> Any:
    """Plot a map file written by :class:`MapFile` or :meth:`StabilityMap.to_netcdf` without xarray.

    Parameters
    ----------
    path : str
        The NetCDF3 file (read with :func:`scipy.io.netcdf_file`).
    x : str, optional
        The horizontal axis (default the inner dimension).
    title : str, optional
        Axes title (default names the parameters and the space, as :meth:`StabilityMap.plot`).
    color : {"verdict", "max_real", "frequency"}
        What the colours show (:func:`~brakesqueal.plotting.plot_map_arrays`).

    Returns
    -------
    matplotlib.figure.Figure
        The same figure :meth:`StabilityMap.plot` draws for the map.
    """
    from scipy.io import netcdf_file

    from .plotting import map_title, plot_map_arrays

    with netcdf_file(path, "r", mmap=False, maskandscale=False) as f:
        outer, inner = f.variables["stable"].dimensions
        xn = x or inner
        yn = outer if xn == inner else inner
        st, ss = np.asarray(f.variables["stable"].data), np.asarray(f.variables["status"].data)
        field = None
        if color in f.variables and color in ("max_real", "frequency"):
            field = np.asarray(f.variables[color].data, dtype=float)
        if xn == outer:
            st, ss = st.T, ss.T
            field = None if field is None else field.T

        def axis(n: str) -> tuple[str, np.ndarray, str, bool]:
            v = f.variables[n]
            text = {k: (a.decode() if isinstance(a, bytes) else a) for k, a in v._attributes.items()}
            return n, np.array(v.data, dtype=float), str(text.get("units", "")), text.get("scale") == "log"

        space = f._attributes.get("space", b"")
        space = space.decode() if isinstance(space, bytes) else str(space)
        return plot_map_arrays(axis(xn), axis(yn), st.astype(bool), ss,
                               title=title if title is not None else map_title(space, xn, yn),
                               boundary=boundary_of(f.variables, (xn, yn)), color=color, field=field)


@dataclass(frozen=True)
class CrossingResult:
    """Values along a 1-D path where the stability of the silent motion changes.

    Attributes
    ----------
    parameter : str
        Path parameter (a settable name of the parameter space).
    start, stop : float
        Path range, in the SI unit of ``parameter``.
    log : bool
        Whether the path is meant logarithmically (sampling and plots).
    stable_at_start : bool
        Verdict at ``start``.
    crossings : tuple of (float, str)
        ``(value, "destabilizing" | "stabilizing")`` in increasing order;
        ``"destabilizing"`` means stable before, unstable after the value.
    method : str
        How they were computed (exact roots or numeric linearization).
    space : ParameterSpace or None, optional
        The parameter space the path lies in (default ``None``).  Not part
        of :meth:`to_dict`, the repr or comparisons.
    undecided_ranges : tuple of (float, float), optional
        Sub-ranges where the verdict could not be decided (default none);
        crossings inside them may be missing.
    exhaustive : bool, optional
        ``True`` (default) when every stability change outside
        ``undecided_ranges`` is guaranteed to be listed (exact root
        isolation); ``False`` for grid searches, which can miss two crossings
        closer together than the grid spacing.
    profile : tuple of ndarray or None, optional
        ``(values, max_real)`` along the path, computed with the result
        (NaN where no verdict was established); drawn by :meth:`plot`.  Not
        part of :meth:`to_dict`, the repr or comparisons.
    """

    parameter: str
    start: float
    stop: float
    log: bool
    stable_at_start: bool
    crossings: tuple[tuple[float, str], ...]
    method: str
    space: Any = field(default=None, repr=False, compare=False)
    undecided_ranges: tuple[tuple[float, float], ...] = ()
    exhaustive: bool = True
    profile: Any = field(default=None, repr=False, compare=False)

    @property
    def complete(self) -> bool:
        """Whether the result is guaranteed on the whole range (exhaustive and nothing undecided)."""
        return self.exhaustive and not self.undecided_ranges

    def to_dict(self) -> dict[str, Any]:
        """The JSON schema of ``brakesqueal crossings --format json``."""
        return {"parameter": self.parameter, "stable_at_start": self.stable_at_start,
                "crossings": [{"value": v, "direction": d} for v, d in self.crossings],
                "range": [self.start, self.stop], "method": self.method,
                "undecided_ranges": [[a, b] for a, b in self.undecided_ranges], "exhaustive": self.exhaustive}

    def to_xarray(self) -> Any:
        """Dataset with dimension ``crossing``: ``value`` and ``direction`` (+1 stabilizing, -1 destabilizing)."""
        import xarray as xr

        return xr.Dataset({"value": ("crossing", [v for v, _ in self.crossings],
                                     {"units": unit(self.parameter, self.space)}),
                           "direction": ("crossing", np.array([1 if d == "stabilizing" else -1
                                                               for _, d in self.crossings], dtype=np.int8))},
                          attrs={"parameter": self.parameter, "stable_at_start": int(self.stable_at_start)})

    def text(self) -> str:
        """Human-readable summary."""
        lines = [f"{self.parameter} in [{self.start:g}, {self.stop:g}]: "
                 f"{'stable' if self.stable_at_start else 'unstable'} at start ({self.method})"]
        lines += [f"  {self.parameter} = {v:.12g}: {d}" for v, d in self.crossings] or (
            ["  no stability change"] if self.complete else ["  no stability change found"])
        lines += [f"  UNDECIDED for {self.parameter} in [{a:.6g}, {b:.6g}] (crossings there may be missing)"
                  for a, b in self.undecided_ranges]
        if not self.exhaustive:
            lines.append("  note: grid search, crossings closer together than the grid spacing may be missing")
        return "\n".join(lines) + "\n"

    def plot(self, ax: Any = None) -> Any:
        """Largest real part along the path (the stored :attr:`profile`) with the crossings marked; returns the figure.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw into (default: a new figure).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from .plotting import plot_path

        return plot_path(self, ax=ax)


@dataclass(frozen=True)
class CriticalSpeedResult(CrossingResult):
    """Crossings along Ω; :attr:`Omega_crit` is the smallest destabilizing Ω (None if none).

    Returned by :func:`~brakesqueal.analysis.crossings.critical_speeds`; the
    critical speed is that of the paper's Fig. 3.  :meth:`to_dict` adds
    ``Omega_crit`` and :meth:`text` starts with it.

    Attributes
    ----------
    parameter : str
        Always ``"Omega"``.
    start, stop : float
        The Ω range [rad/s].
    log : bool
        ``True`` (Ω paths are logarithmic).
    stable_at_start : bool
        Verdict at ``start``.
    crossings : tuple of (float, str)
        ``(Omega, "destabilizing" | "stabilizing")`` in increasing order [rad/s].
    method : str
        How they were computed (compiled kernel or
        :func:`~brakesqueal.analysis.crossings.crossings`).
    space : ParameterSpace or None, optional
        The parameter space (default ``None``).
    undecided_ranges : tuple of (float, float), optional
        Ω sub-ranges where the verdict could not be decided.
    exhaustive : bool, optional
        Whether every crossing outside ``undecided_ranges`` is guaranteed listed.
    profile : tuple of ndarray or None, optional
        ``(Omega, max_real)`` along the range, drawn by :meth:`plot`.
    """

    @property
    def Omega_crit(self) -> float | None:
        """Smallest destabilizing Ω [rad/s] found in the range, or None (see :attr:`Omega_crit_certain`)."""
        onsets = [v for v, d in self.crossings if d == "destabilizing"]
        return onsets[0] if onsets else None

    @property
    def Omega_crit_certain(self) -> bool:
        """``True`` when :attr:`Omega_crit` is established: no undecided range below it and an exhaustive search."""
        oc = self.Omega_crit
        if not self.exhaustive:
            return False
        return not any(a < (oc if oc is not None else math.inf) for a, _ in self.undecided_ranges)

    def to_dict(self) -> dict[str, Any]:
        d = super().to_dict()
        d["Omega_crit"] = self.Omega_crit
        d["Omega_crit_certain"] = self.Omega_crit_certain
        return d

    def text(self) -> str:
        oc = self.Omega_crit
        if oc is not None:
            head = f"Omega_crit = {oc:.12g} rad/s ({oc / (2 * math.pi):.6g} rev/s)"
            if not self.Omega_crit_certain:
                head += " (NOT certain: a smaller onset may lie in an undecided range or between grid points)"
        elif not self.stable_at_start and self.complete:
            head = "Omega_crit = none in the range: unstable already at the start of the range"
        elif self.complete:
            head = "Omega_crit = none (no destabilizing crossing in the range)"
        else:
            head = "Omega_crit = UNKNOWN (no destabilizing crossing found, but the range was not fully decided)"
        return head + "\n" + super().text()
