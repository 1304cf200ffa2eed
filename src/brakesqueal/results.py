"""Result objects of the stability analysis: conversion to xarray, files, ``.plot()``.

``.plot()`` returns the matplotlib figure (Agg backend, never ``plt.show()``).
NetCDF files are NetCDF3 (64-bit offset, no extra dependency), written with
xarray's ``scipy`` engine or, for maps computed chunk by chunk, by
:class:`MapFile` (same variables and attributes, bounded memory); booleans are
stored as ``int8`` with ``flag_values`` / ``flag_meanings`` and restored by
:func:`open_map`.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast, overload

import numpy as np

from .labels import unit

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure, SubFigure
    from numpy.typing import DTypeLike

    from .analysis.boundary import Boundary
    from .analysis.maps import Axis
    from .model.parameters import ParameterSpace

__all__ = ["StabilityMap", "CrossingResult", "CriticalSpeedResult", "open_map", "MapFile", "plot_map_file",
           "NC3_MAX_VAR_BYTES", "MAX_PLOT_POINTS", "plot_indices", "label_names"]

def _status_attrs() -> dict[str, Any]:
    from .status import STATUS_MEANINGS, PointStatus

    return {"flag_values": np.array([int(s) for s in PointStatus], dtype=np.int8), "flag_meanings": STATUS_MEANINGS}


def _map_attrs(space: ParameterSpace, method: str) -> dict[str, Any]:
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


def label_names(attrs: Mapping[Any, object]) -> tuple[str, ...]:
    """The labels of a flag variable (``carrier``, ``route``) from its attributes (``flag_meanings``)."""
    return tuple(m.replace("_", " ") for m in str(attrs.get("flag_meanings", "")).split())


def _coord_attrs(ax: Axis, space: ParameterSpace) -> dict[str, Any]:
    return {"units": unit(ax.name, space), "scale": "log" if ax.log else "linear"}


#: Dimension of the stored boundary vertices (curves separated by NaN).
BOUNDARY_DIM = "boundary_vertex"


def _boundary_attrs(name: str, space: ParameterSpace) -> dict[str, Any]:
    return {"units": unit(name, space),
            "long_name": f"{name} along the stability boundary (curves separated by NaN; vertices refined "
                         "onto the boundary by bisection, brakesqueal.analysis.boundary)"}


def boundary_of(ds_or_vars: xr.Dataset | Mapping[str, Any],
                names: tuple[str, str]) -> tuple[np.ndarray, np.ndarray] | None:
    """The stored boundary ``(values of names[0], values of names[1])`` of a map, or ``None``."""
    keys = [f"boundary_{n}" for n in names]
    if not all(k in ds_or_vars for k in keys):
        return None
    # xarray variables have .values, scipy.io.netcdf variables .data
    a, b = (np.array(v.values if hasattr(v, "dims") else v.data, dtype=float) for v in (ds_or_vars[k] for k in keys))
    return a, b


#: NetCDF3 type codes (classic format specification) of the numpy types a map file stores.
_NC_TYPE = {"i1": 1, "S1": 2, "i2": 3, "i4": 4, "f4": 5, "f8": 6}
#: Default fill bytes of the NetCDF3 types (padding of a variable without ``_FillValue``).
_NC_FILL = {1: b"\x81", 2: b"\x00", 3: b"\x80\x01", 4: b"\x80\x00\x00\x01", 5: b"\x7c\xf0\x00\x00",
            6: b"\x47\x9e\x00\x00\x00\x00\x00\x00"}
#: Largest size [bytes] of one variable of a NetCDF3 64-bit-offset file (its ``vsize`` is a 32-bit count).
NC3_MAX_VAR_BYTES = 2**32 - 4


def _nc_int(n: int) -> bytes:
    return int(n).to_bytes(4, "big", signed=True)


def _nc_name(name: str) -> bytes:
    b = name.encode("utf-8")
    return _nc_int(len(b)) + b + b"\x00" * (-len(b) % 4)


def _nc_att_values(value: Any) -> tuple[int, bytes]:
    """NetCDF3 type and encoded values of an attribute (the types :func:`scipy.io.netcdf_file` gives them)."""
    if isinstance(value, (str, bytes)):
        data = value.encode("utf-8") if isinstance(value, str) else value
        return 2, _nc_int(len(data)) + data + b"\x00" * (-len(data) % 4)
    if hasattr(value, "dtype"):
        a = np.asarray(value)
    elif isinstance(value, int):
        a = np.asarray(value, dtype=np.int32)
    else:
        a = np.asarray(value, dtype=np.float32)
    a = np.atleast_1d(a)
    key = f"{a.dtype.kind}{a.dtype.itemsize}"
    if key not in _NC_TYPE:
        raise TypeError(f"attribute of type {a.dtype} cannot be stored in NetCDF3")
    data = a.astype(a.dtype.newbyteorder(">")).tobytes()
    return _NC_TYPE[key], _nc_int(a.size) + data + b"\x00" * (-len(data) % 4)


def _nc_atts(attrs: dict[str, Any]) -> bytes:
    if not attrs:
        return b"\x00" * 8
    out = [b"\x00\x00\x00\x0c", _nc_int(len(attrs))]
    for k, v in attrs.items():
        t, data = _nc_att_values(v)
        out += [_nc_name(k), _nc_int(t), data]
    return b"".join(out)


@dataclass
class _NcVar:
    """One fixed-size variable of a NetCDF3 file: its metadata and where its data start (``begin``)."""

    name: str
    dims: tuple[str, ...]
    dtype: np.dtype  # big-endian, as stored
    attrs: dict[str, Any]
    size: int
    begin: int = 0

    @property
    def nbytes(self) -> int:
        return self.size * self.dtype.itemsize

    @property
    def vsize(self) -> int:
        return self.nbytes + (-self.nbytes % 4)

    def padding(self) -> bytes:
        """The bytes after the data up to a multiple of 4 (the fill value, as :func:`scipy.io.netcdf_file`)."""
        fill = self.attrs.get("_FillValue")
        code = _NC_TYPE[f"{self.dtype.kind}{self.dtype.itemsize}"]
        enc = np.asarray(fill, dtype=self.dtype).tobytes() if fill is not None else _NC_FILL[code]
        return enc * ((self.vsize - self.nbytes) // len(enc))


def _nc3_header(dims: list[tuple[str, int]], attrs: dict[str, Any], variables: list[_NcVar]) -> bytes:
    """The header of a NetCDF3 64-bit-offset file (``CDF\\x02``) without record variables."""
    names = [d for d, _ in dims]
    out = [b"CDF\x02", _nc_int(0)]
    out += [b"\x00\x00\x00\x0a", _nc_int(len(dims))] if dims else [b"\x00" * 8]
    out += [_nc_name(d) + _nc_int(n) for d, n in dims]
    out.append(_nc_atts(attrs))
    out += [b"\x00\x00\x00\x0b", _nc_int(len(variables))] if variables else [b"\x00" * 8]
    for v in variables:
        out += [_nc_name(v.name), _nc_int(len(v.dims)), *(_nc_int(names.index(d)) for d in v.dims), _nc_atts(v.attrs),
                _nc_int(_NC_TYPE[f"{v.dtype.kind}{v.dtype.itemsize}"]),
                _nc_int(min(v.vsize, 2**32 - 1)), int(v.begin).to_bytes(8, "big", signed=True)]
    return b"".join(out)


class MapFile:
    """A stability map's NetCDF3 file written row block by row block (memory bounded for any map size).

    The file has the layout :meth:`StabilityMap.to_netcdf` writes (NetCDF3
    64-bit offset, the variables, types and attributes of
    :func:`scipy.io.netcdf_file`) and is read back by :func:`open_map` or
    :func:`xarray.open_dataset`.  The variables' sizes are known from the axes,
    so each one's place in the file is fixed when the file is created: every
    block of rows (:meth:`write_rows`) is written to its place at once and
    nothing of the map is held; the header (which names the route, known at
    the end, and the boundary's length) is written by :meth:`close`.  When a
    boundary may follow (``boundary=True``), room for its dimension and two
    variables is kept in front of the data; a map without a boundary then has
    zero bytes between its header and its first variable (allowed by the
    format: every variable's data start at its recorded offset).

    Parameters
    ----------
    path : str
        The file (created or truncated).
    space : ParameterSpace
        The map's parameter space.
    outer, inner : Axis
        The axes (dimension order; :class:`~brakesqueal.analysis.maps.Axis`, their
        values are written block by block with ``values_range``).
    eigen : bool
        Whether ``max_real`` and ``frequency`` are stored.
    float_dtype : numpy dtype
        Type of ``max_real`` and ``frequency`` (float32 or float64).
    method : str
        The route (global attribute ``method``; :meth:`close` may give
        another name of at most the same length).
    boundary : bool
        Keep room in the header for :meth:`write_boundary` (default ``True``).

    Raises
    ------
    ParameterError
        If a variable would exceed :data:`NC3_MAX_VAR_BYTES` (the format's limit).
    """

    def __init__(self, path: str, space: ParameterSpace, outer: Axis, inner: Axis, *, eigen: bool,
                 float_dtype: DTypeLike = np.float64, method: str = "", boundary: bool = True,
                 extras: tuple[tuple[str, DTypeLike, dict[str, Any]], ...] = ()) -> None:
        from .errors import ParameterError

        self.space, self.outer, self.inner = space, outer, inner
        ft: np.dtype[Any] = np.dtype(float_dtype).newbyteorder(">")
        n = outer.num * inner.num
        size = ft.itemsize if eigen else 1
        if n * size > NC3_MAX_VAR_BYTES:
            raise ParameterError(f"the map has {n:.4g} points: a NetCDF3 variable holds at most "
                                 f"{NC3_MAX_VAR_BYTES // size:.4g} values of {size} byte(s) (4 GiB); use fewer "
                                 "points or a sweep (brakesqueal sweep)")
        dims = (outer.name, inner.name)
        self._dims = [(ax.name, int(ax.num)) for ax in (outer, inner)]
        self._vars = [_NcVar(ax.name, (ax.name,), np.dtype(">f8"),
                             {**_coord_attrs(ax, space), "_FillValue": np.float64(np.nan)}, int(ax.num))
                      for ax in (outer, inner)]
        grid: list[tuple[str, np.dtype, dict[str, Any]]] = [
            ("stable", np.dtype("i1"), {**_VAR_ATTRS["stable"], **_STABLE_FLAGS}),
            ("status", np.dtype("i1"), _status_attrs())]
        for name, dt, attrs in extras:
            d: np.dtype = np.dtype(dt)
            if d.kind == "f":
                grid.append((name, ft, {**attrs, "_FillValue": ft.type(np.nan)}))
            else:
                grid.append((name, d.newbyteorder(">") if d.itemsize > 1 else d, dict(attrs)))
        if eigen:
            grid.insert(0, ("max_real", ft, {**_VAR_ATTRS["max_real"], "_FillValue": ft.type(np.nan)}))
            grid.insert(2, ("frequency", ft, {**_VAR_ATTRS["frequency"], "_FillValue": ft.type(np.nan)}))
        self._vars += [_NcVar(name, dims, dt, attrs, n) for name, dt, attrs in grid]
        self._grid = {v.name: v for v in self._vars[2:]}
        self.eigen = eigen
        # the header's length depends on the names and attributes, not on the lengths and offsets in it
        self._bnames = [f"boundary_{ax.name}" for ax in (outer, inner)]
        self.method = method
        self._room = len(self._header(method, self._boundary_vars(1) if boundary else None))
        offset = self._room
        for v in self._vars:
            v.begin = offset
            offset += v.vsize
        self._end = offset
        self._fp = open(path, "wb")
        try:
            for v, ax in zip(self._vars[:2], (outer, inner)):
                for i in range(0, ax.num, 1 << 20):  # a long axis: no array of its length
                    self._put(v, i, ax.values_range(i, min(ax.num, i + (1 << 20))))
        except BaseException:
            self._fp.close()
            raise
        self._boundary: list[_NcVar] = []

    def _boundary_vars(self, n: int) -> list[_NcVar]:
        return [_NcVar(name, (BOUNDARY_DIM,), np.dtype(">f8"),
                       {**_boundary_attrs(ax.name, self.space), "_FillValue": np.float64(np.nan)}, n)
                for name, ax in zip(self._bnames, (self.outer, self.inner))]

    def _header(self, method: str, boundary: list[_NcVar] | None) -> bytes:
        dims = self._dims + ([(BOUNDARY_DIM, boundary[0].size)] if boundary else [])
        return _nc3_header(dims, _map_attrs(self.space, method), self._vars + (boundary or []))

    def _put(self, v: _NcVar, start: int, values: np.ndarray) -> None:
        """Write ``values`` (flattened) at element ``start`` of variable ``v``."""
        a = np.ascontiguousarray(values, dtype=v.dtype)
        self._fp.seek(v.begin + start * v.dtype.itemsize)
        self._fp.write(a.data)

    def write_rows(self, r0: int, r1: int, stable: np.ndarray, status: np.ndarray,
                   max_real: np.ndarray | None = None, frequency: np.ndarray | None = None, *, c0: int = 0,
                   extra: dict[str, np.ndarray] | None = None) -> None:
        """Write the block ``[r0:r1, c0:c0 + width]`` of the map: whole outer rows, or a piece of one row.

        The arrays have shape ``(r1 - r0, width)``: ``width = inner.num``
        (and ``c0 = 0``) for whole rows; a piece of one row (``r1 = r0 + 1``)
        may start at any ``c0``.  ``max_real`` and ``frequency`` are required
        when the file stores them (``eigen``) and ignored otherwise; ``extra`` holds the further variables given
        at creation (``extras``).
        """
        n_i = self.inner.num
        width = int(np.shape(stable)[-1]) if np.ndim(stable) == 2 else -1
        whole = c0 == 0 and width == n_i
        if not (0 <= r0 < r1 <= self.outer.num and (whole or (r1 == r0 + 1 and 0 <= c0 and c0 + width <= n_i))):
            raise ValueError(f"rows {r0}:{r1}, columns from {c0}, width {width}: not whole rows nor a piece of "
                             f"one row of the ({self.outer.num}, {n_i}) grid")
        start = r0 * n_i + c0
        cells = {"stable": stable, "status": status}
        for name in self._grid:
            if name not in ("stable", "status", "max_real", "frequency"):
                if extra is None or name not in extra:
                    raise ValueError(f"this map file stores {name}: give it")
                cells[name] = extra[name]
        if self.eigen:
            if max_real is None or frequency is None:
                raise ValueError("this map file stores max_real and frequency: give both")
            cells.update(max_real=max_real, frequency=frequency)
        for name, values in cells.items():
            if np.shape(values) != (r1 - r0, width):
                raise ValueError(f"{name}: expected shape {(r1 - r0, width)}, got {np.shape(values)}")
            self._put(self._grid[name], start, values)

    def write_boundary(self, b: Boundary) -> None:
        """Add the refined stability boundary (:class:`~brakesqueal.analysis.boundary.Boundary`) before closing."""
        n = int(b.coords[0].size)
        if n == 0:
            return
        if self._room < len(self._header("", self._boundary_vars(n))):
            raise RuntimeError("MapFile: no room for a boundary (created with boundary=False)")
        self._boundary = self._boundary_vars(n)
        offset = self._end
        for v, values in zip(self._boundary, b.coords):
            v.begin = offset
            offset += v.vsize
            self._put(v, 0, np.asarray(values, dtype=float))

    def close(self, method: str | None = None) -> None:
        """Write the header (global attribute ``method`` names the route, default the one given at creation)
        and the padding, and close the file."""
        try:
            header = self._header(self.method if method is None else method, self._boundary or None)
            if len(header) > self._room:
                raise ValueError(f"MapFile: the header ({len(header)} bytes) does not fit before the data "
                                 f"({self._room} bytes): the route's name is longer than the one given at creation")
            for v in self._vars + self._boundary:
                self._fp.seek(v.begin + v.nbytes)
                self._fp.write(v.padding())
            self._fp.seek(0)
            self._fp.write(header + b"\x00" * (self._room - len(header)))
        finally:
            self._fp.close()

    def abort(self) -> None:
        """Close without meaningful content (the caller removes the file)."""
        self._fp.close()


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
          [Hz] — only when they were computed (not for verdict-only maps);
        * ``carrier``: int8, the mode carrying the verdict (``flag_meanings``
          name the model's components: ``disk``, ``pad_1``, ...,
          ``pad_1_tangential_rate``; -1 without a verdict);
        * ``route``: int8, the route of :mod:`brakesqueal.analysis.verdict`
          that decided the point (``flag_meanings``; 0 none).

        Dataset attributes: ``model``, ``space`` (preset label), ``settings``
        and ``tied`` (JSON), ``method`` (the route) and ``criterion``.
    """

    data: xr.Dataset

    @classmethod
    def from_arrays(cls, space: ParameterSpace, outer: Axis, inner: Axis, *, stable: np.ndarray, status: np.ndarray,
                    max_real: np.ndarray | None, frequency: np.ndarray | None, method: str,
                    boundary: Boundary | None = None, extra: dict[str, tuple[np.ndarray, dict[str, Any]]] | None = None
                    ) -> StabilityMap:
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
        extra : dict, optional
            Further variables ``name -> (array, attributes)`` (the map's other quantities, e.g. ``carrier`` and
            ``route``: :mod:`brakesqueal.analysis.quantities`).

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
        for name, (values, attrs) in (extra or {}).items():
            data[name] = (dims, values, dict(attrs))
        if boundary is not None and boundary.coords[0].size:
            for name, values in zip(boundary.names, boundary.coords):
                data[f"boundary_{name}"] = ((BOUNDARY_DIM,), values, _boundary_attrs(name, space))
        return cls(xr.Dataset(data, coords=coords, attrs=_map_attrs(space, method)))

    @property
    def dims(self) -> tuple[str, str]:
        """The two axis names ``(outer, inner)``."""
        return cast("tuple[str, str]", tuple(self.data["stable"].dims))  # the two axes' parameter names

    def _repr_html_(self) -> str:
        """xarray's HTML view of :attr:`data`, for notebooks."""
        return str(self.data._repr_html_())

    def to_xarray(self) -> xr.Dataset:
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
        return list(cast("list[np.ndarray]", gen.lines(0.5)))  # the default line type: one array per line

    @overload
    def plot(self, ax: None = None, *, x: str | None = None, title: str | None = None,
             color: str = "verdict") -> Figure: ...
    @overload
    def plot(self, ax: Axes, *, x: str | None = None, title: str | None = None,
             color: str = "verdict") -> Figure | SubFigure: ...

    def plot(self, ax: Axes | None = None, *, x: str | None = None, title: str | None = None,
             color: str = "verdict") -> Figure | SubFigure:
        """Stability map: stable region shaded (or ``color = "max_real" | "frequency"``), refined boundary drawn,
        points without a verdict hatched; returns the figure (:func:`~brakesqueal.plotting.plot_map`)."""
        from .plotting import plot_map

        return plot_map(self, ax=ax, x=x, title=title, color=color)


def open_map(path: str | os.PathLike[str]) -> StabilityMap:
    """Read a map written by :meth:`StabilityMap.to_netcdf`.

    Parameters
    ----------
    path : str or os.PathLike
        Path of the NetCDF3 file (read with xarray's ``scipy`` engine and
        loaded into memory, so the file is not kept open).

    Returns
    -------
    StabilityMap
        The map, with ``stable`` converted back from int8 flags to bool.

    Raises
    ------
    ParameterError
        One line naming the file: missing, not a regular file
        (:func:`brakesqueal.inputs.check_input_file`), or not a map
        (not NetCDF3, truncated, or without the ``stable`` variable).
    """
    import xarray as xr

    from .inputs import check_input_file
    from .errors import ParameterError

    path = check_input_file(path, "map file")
    try:
        ds = xr.open_dataset(path, engine="scipy").load()
        ds["stable"] = ds["stable"].astype(bool)
    except Exception as exc:  # noqa: BLE001 - whatever a damaged file raises deep in SciPy: one line
        reason = " ".join(str(exc).split())[:120] or type(exc).__name__
        raise ParameterError(f"map file '{path}' is not a stability map written by brakesqueal (NetCDF3): "
                             f"{reason}") from None
    return StabilityMap(ds)


#: Largest number of grid points per axis :func:`plot_map_file` draws (more than the figure's pixels at 300 dpi);
#: larger maps are drawn from every k-th point.
MAX_PLOT_POINTS = 1200


def plot_indices(n: int, most: int = MAX_PLOT_POINTS) -> np.ndarray:
    """Indices of the grid points of an axis of ``n`` points a figure draws: all of them up to ``most``,
    else every ``k``-th (``k = ceil(n / most)``) and the last one (the axis keeps its range).

    Parameters
    ----------
    n : int
        Number of grid points of the axis.
    most : int
        Largest number of points drawn (``>= 2``).

    Returns
    -------
    ndarray of int64
        Increasing indices, first ``0`` and last ``n - 1``.
    """
    if n <= most:
        return np.arange(n, dtype=np.int64)
    k = -(-n // (most - 1))
    idx = np.arange(0, n, k, dtype=np.int64)
    return idx if idx[-1] == n - 1 else np.append(idx, n - 1)


def plot_map_file(path: str, *, x: str | None = None, title: str | None = None, color: str = "verdict") -> Figure:
    """Plot a map file written by :class:`MapFile` or :meth:`StabilityMap.to_netcdf` without xarray.

    Maps with more than :data:`MAX_PLOT_POINTS` points along an axis are drawn
    from every k-th grid point of that axis (:func:`plot_indices`; the figure
    has fewer pixels than that): only those points are read from the file
    (memory-mapped), so the memory does not grow with the map.  Each drawn cell
    is a computed point with its own verdict and status; the stored, refined
    boundary is drawn in full.

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
        The same figure :meth:`StabilityMap.plot` draws for the map (up to
        :data:`MAX_PLOT_POINTS` points per axis).
    """
    from scipy.io import netcdf_file

    from .plotting import map_title, plot_map_arrays

    f = netcdf_file(path, "r", mmap=True, maskandscale=False)
    try:
        outer, inner = f.variables["stable"].dimensions
        take = {d: plot_indices(int(f.dimensions[d]), MAX_PLOT_POINTS) for d in (outer, inner)}
        sel = np.ix_(take[outer], take[inner])

        def grid(name: str, dtype: DTypeLike | None = None) -> np.ndarray:
            return np.array(f.variables[name].data[sel], dtype=dtype)  # a copy of the drawn points only

        xn = x or inner
        yn = outer if xn == inner else inner
        st, ss = grid("stable"), grid("status")
        field = grid(color, float) if color in f.variables and color in ("max_real", "frequency") else None
        disk = grid("disk_stable") if "disk_stable" in f.variables else None
        if xn == outer:
            st, ss = st.T, ss.T
            field = None if field is None else field.T
            disk = None if disk is None else disk.T

        def axis(n: str) -> tuple[str, np.ndarray, str, bool]:
            v = f.variables[n]
            text = {k: (a.decode() if isinstance(a, bytes) else a) for k, a in v._attributes.items()}
            return n, np.array(v.data[take[n]], dtype=float), str(text.get("units", "")), text.get("scale") == "log"

        space = f._attributes.get("space", b"")
        space = space.decode() if isinstance(space, bytes) else str(space)
        xa, ya = axis(xn), axis(yn)
        b = boundary_of(f.variables, (xn, yn))
        label = title if title is not None else map_title(space, xn, yn)
    finally:
        f.variables.clear()  # the variables' arrays view the mapped file: drop them so it can be unmapped
        f.close()
    return plot_map_arrays(xa, ya, st.astype(bool), ss, title=label, boundary=b, color=color, field=field,
                           disk_stable=disk)


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
    carrier_at_start : str, optional
        The mode carrying the verdict at ``start`` (e.g. ``"disk"``, ``"pad 1 tangential rate"``; ``""``:
        not determined, the default).
    """

    parameter: str
    start: float
    stop: float
    log: bool
    stable_at_start: bool
    crossings: tuple[tuple[float, str], ...]
    method: str
    space: ParameterSpace | None = field(default=None, repr=False, compare=False)
    undecided_ranges: tuple[tuple[float, float], ...] = ()
    exhaustive: bool = True
    profile: tuple[np.ndarray, np.ndarray] | None = field(default=None, repr=False, compare=False)
    carrier_at_start: str = ""

    @property
    def complete(self) -> bool:
        """Whether the result is guaranteed on the whole range (exhaustive and nothing undecided)."""
        return self.exhaustive and not self.undecided_ranges

    def to_dict(self) -> dict[str, Any]:
        """The JSON schema of ``brakesqueal crossings --format json``."""
        return {"parameter": self.parameter, "stable_at_start": self.stable_at_start,
                "crossings": [{"value": v, "direction": d} for v, d in self.crossings],
                "range": [self.start, self.stop], "method": self.method,
                "undecided_ranges": [[a, b] for a, b in self.undecided_ranges], "exhaustive": self.exhaustive,
                "carrier_at_start": self.carrier_at_start or None}

    def to_xarray(self) -> xr.Dataset:
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
        if not self.stable_at_start and self.carrier_at_start.endswith("tangential rate"):
            lines.append(f"  unstable at start through {self.carrier_at_start}: a non-oscillatory mode of the massless "
                         "pad alone, not a disk vibration (modes='disk', --modes disk, judges the disk modes alone)")
        lines += [f"  {self.parameter} = {v:.12g}: {d}" for v, d in self.crossings] or (
            ["  no stability change"] if self.complete else ["  no stability change found"])
        lines += [f"  UNDECIDED for {self.parameter} in [{a:.6g}, {b:.6g}] (crossings there may be missing)"
                  for a, b in self.undecided_ranges]
        if not self.exhaustive:
            lines.append("  note: grid search, crossings closer together than the grid spacing may be missing")
        return "\n".join(lines) + "\n"

    def _repr_html_(self) -> str:
        """The :meth:`text` of the result, escaped, for notebooks."""
        import html

        return f"<pre>{html.escape(self.text())}</pre>"

    @overload
    def plot(self, ax: None = None) -> Figure: ...
    @overload
    def plot(self, ax: Axes) -> Figure | SubFigure: ...

    def plot(self, ax: Axes | None = None) -> Figure | SubFigure:
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
    carrier_at_start : str, optional
        The mode carrying the verdict at ``start`` (``""``: not determined).
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

    @property
    def unstable_intervals(self) -> tuple[tuple[float, float], ...]:
        """The Ω intervals [rad/s] where the silent motion was found unstable, in increasing order.

        Read off :attr:`stable_at_start` and the crossings: an interval opens at the range start when the
        motion is unstable there, or at a destabilizing crossing, and closes at the next stabilizing crossing
        or the range's end.  Undecided ranges are not in it (see :attr:`undecided_ranges`).
        """
        out: list[tuple[float, float]] = []
        opened: float | None = None if self.stable_at_start else self.start
        for v, d in self.crossings:
            if d == "destabilizing" and opened is None:
                opened = v
            elif d == "stabilizing" and opened is not None:
                out.append((opened, v))
                opened = None
        if opened is not None:
            out.append((opened, self.stop))
        return tuple(out)

    @property
    def squeal_from(self) -> float | None:
        """The lowest Ω [rad/s] in the range at which squeal (an unstable silent motion) was found, or None.

        The range start when the motion is unstable there (then :attr:`Omega_crit`, the first destabilizing
        crossing, lies above a speed range that already squeals), else :attr:`Omega_crit`.
        """
        iv = self.unstable_intervals
        return iv[0][0] if iv else None

    @property
    def outcome(self) -> str:
        """What the result says about squeal onsets, in one word shared by :meth:`text` and :meth:`to_dict`.

        ``"onset"`` (stable at the start and :attr:`Omega_crit` found; :attr:`Omega_crit_certain` says
        whether a smaller one may be missing); ``"unstable_at_start"`` (squeal from the range start; stability
        changes further up, listed in :attr:`unstable_intervals`); ``"unknown"`` (no onset found, but part of
        the range is undecided, or a grid search found the motion stable: a pair of crossings closer together
        than the grid spacing may hide an onset); ``"unstable_throughout"`` / ``"stable_throughout"`` (no
        stability change found, nothing undecided; a grid search: unstable at every grid point, never "stable
        throughout").
        """
        if not self.stable_at_start and self.crossings:
            return "unstable_at_start"
        if self.Omega_crit is not None:
            return "onset"
        if self.undecided_ranges or (self.stable_at_start and not self.exhaustive):
            return "unknown"
        if not self.crossings:
            return "stable_throughout" if self.stable_at_start else "unstable_throughout"
        return "unstable_at_start"

    def to_dict(self) -> dict[str, Any]:
        d = super().to_dict()
        d["Omega_crit"] = self.Omega_crit
        d["Omega_crit_certain"] = self.Omega_crit_certain
        d["outcome"] = self.outcome
        d["squeal_from"] = self.squeal_from
        d["unstable_intervals"] = [list(iv) for iv in self.unstable_intervals]
        return d

    def _intervals_text(self) -> str:
        """``"from 1 (the range start) up to 11.56 rad/s, and from 35 rad/s to the range end (1e+05)"``."""
        parts = []
        for i, (a, b) in enumerate(self.unstable_intervals):
            lo = f"{a:.12g} (the range start)" if a == self.start else f"{a:.12g}"
            hi = f"the range end ({b:.6g} rad/s)" if b == self.stop else f"{b:.12g} rad/s"
            parts.append(f"from {lo} up to {hi}")
        return ", and ".join(parts)

    def text(self) -> str:
        oc, outcome = self.Omega_crit, self.outcome
        grid = "" if self.exhaustive else " (at every grid point; see the note below)"
        if outcome == "unstable_at_start":
            head = ("Squeal from the range start: unstable already at the start of the range, "
                    f"{self._intervals_text()}{grid}")
            if oc is not None:
                head += f" (the first onset from stable, Omega_crit of the paper's Fig. 3, is at {oc:.12g} rad/s)"
        elif oc is not None:
            head = f"Omega_crit = {oc:.12g} rad/s ({oc / (2 * math.pi):.6g} rev/s)"
            if not self.Omega_crit_certain:
                head += " (NOT certain: a smaller onset may lie in an undecided range or between grid points)"
            if len(self.unstable_intervals) > 1 or self.unstable_intervals[0][1] != self.stop:
                head += f"; unstable {self._intervals_text()}"
        elif outcome == "unknown" and self.undecided_ranges:
            head = "Omega_crit = UNKNOWN (no destabilizing crossing found, but part of the range is undecided)"
            if not self.stable_at_start:
                head = f"Squeal from the range start (unstable at {self.start:.12g} rad/s); " + head
        elif outcome == "unknown":
            head = ("Omega_crit = UNKNOWN (stable at every grid point, but a grid search can miss a pair of crossings "
                    "closer together than its spacing)")
        elif outcome == "unstable_throughout":
            head = f"Omega_crit = none in the range: unstable throughout the range{grid}"
        elif outcome == "stable_throughout":
            head = "Omega_crit = none (no destabilizing crossing in the range): stable throughout the range"
        else:  # not reached: every outcome is handled above
            head = f"Omega_crit = none in the range: unstable already at the start of the range{grid}"
        return head + "\n" + super().text()
