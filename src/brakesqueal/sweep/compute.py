"""Per-chunk computation of a study (runs in the client or on Dask workers).

Everything here reuses the stability kernels of :mod:`brakesqueal.analysis`:

* **Verdict on grids** — the generated Hurwitz classifier of
  :mod:`~brakesqueal.analysis.kernels` (same source, same numba cache as
  ``stability_map``).  For an N-D grid the closed form is specialised once with
  *all* grid axes symbolic (:func:`~brakesqueal.analysis.kernels._specialise`,
  ``_numerators``); the quartic's coefficients become polynomials in one
  *inner* axis whose coefficients depend on the other axes, evaluated per row
  with NumPy and normalised exactly like ``MapKernel.row_coefficients``.  With
  two axes this is the map kernel.
* **Samples, or grids without a closed-form kernel** — closed-form matrices per
  point (``compiled_model().trivial_matrices``) + :func:`quartic_coefficients`
  + :func:`hurwitz_stable`.
* ``margin``, ``max_real``, ``frequency`` — roots of the quartic (batched
  companion eigenvalues, ``analysis.maps._roots_summary``), in sub-batches.
* ``critical_speed`` — :func:`~brakesqueal.analysis.kernels.critical_speeds_batch`.
* Points with a non-trivial silent motion use the numeric linearization
  (``analysis.maps._numeric_point``); invalid parameters, no silent motion and
  contact loss are flagged in ``status`` (codes of ``analysis.maps.STATUS``)
  and never marked stable.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from ..analysis.kernels import critical_speeds_batch, hurwitz_stable, normalise_rows, quartic_coefficients
from ..analysis.maps import _numeric_point, _roots_summary, _trivial
from ..analysis.space import VECTOR_NAMES, ParameterSpace
from ..parameters import _BOUNDS, PARAMETER_NAMES, Value

__all__ = ["ChunkSpec", "build_space", "model_space", "compute_chunk", "grid_kernel", "FLOAT_QUANTITIES"]

#: Float quantities and their attributes.
FLOAT_QUANTITIES = {
    "margin": {"units": "1", "long_name": "damping ratio of the least-stable mode, -Re(lambda)/|lambda| "
                                          "(> 0: stable)"},
    "max_real": {"units": "1/s", "long_name": "largest real part of the eigenvalues"},
    "frequency": {"units": "Hz", "long_name": "frequency of the least-stable mode"},
    "critical_speed": {"units": "rad/s", "long_name": "smallest Omega in the searched range where the silent "
                                                      "motion becomes unstable (NaN: none)"},
}
_BATCH = 1 << 16


@dataclass(frozen=True)
class ChunkSpec:
    """What a worker needs to compute any chunk of a study (plain, picklable data).

    ``names`` are the grid dimensions (grid) or the sampled names (samples);
    ``refs`` and ``signs`` are per grid axis: the scale magnitude of the whole
    axis and the sign of all its values (0 = mixed), so that a chunk's result
    does not depend on how the study is chunked.
    """

    key: str
    preset: str | None
    values: tuple[tuple[str, Value], ...]
    tied: tuple[tuple[str, str], ...]
    kind: str
    names: tuple[str, ...]
    refs: tuple[float, ...]
    signs: tuple[int, ...]
    quantities: tuple[str, ...]
    critical_speed_range: tuple[float, float]
    model: str | None = None

    @classmethod
    def from_study(cls, study: Any) -> ChunkSpec:
        if study.kind == "grid":
            refs = tuple(a.ref for a in study.axes)
            signs = tuple(1 if np.all(a.values > 0) else -1 if np.all(a.values < 0) else 0 for a in study.axes)
        else:
            refs, signs = (), ()
        names = study.dims if study.kind == "grid" else study.sample_names
        return cls(study.hash(), study.preset, tuple(study.values.items()), tuple(study.tied.items()), study.kind,
                   names, refs, signs, study.quantities, study.critical_speed_range, study.model)


# ---------------------------------------------------------------- parameter space
@lru_cache(maxsize=16)
def build_space(preset: str | None, values: tuple[tuple[str, Value], ...],
                tied: tuple[tuple[str, str], ...]) -> ParameterSpace:
    """The study's parameter space: a preset (with the study's ties added) or a complete parameter set."""
    from ..errors import ParameterError
    from ..parameters import Parameters, Preset, get_preset

    vals = dict(values)
    if not tied:
        if preset is not None:
            return ParameterSpace.from_preset(preset, vals)
        return ParameterSpace.from_parameters(Parameters.from_dict(vals, source="[parameters]"))
    base = get_preset(preset) if preset is not None else None
    defs: dict[str, Value] = {**base.fixed, **base.free} if base else {}
    defs.update(vals)
    ties = dict(base.tied) if base else {}
    for name, expr in tied:
        if name not in defs and name not in ties:
            where = f"preset '{preset}'" if base else "the model parameters"
            raise ParameterError(f"cannot tie '{name}': it is not a name of {where}")
        defs.pop(name, None)
        ties[name] = expr
    p = Preset(name=f"{preset or 'parameters'}+ties", description="study with extra ties",
               reference="study file", fixed=defs, free={}, tied=ties,
               auxiliary=dict(base.auxiliary) if base else {})
    space = ParameterSpace(p.name, p, {})
    space.resolve({})
    return space


@lru_cache(maxsize=16)
def model_space(model_json: str, values: tuple[tuple[str, Value], ...]) -> Any:
    """The :class:`~brakesqueal.builder.analysis.ModelSpace` of a built-model study (cached per process)."""
    import json

    from ..builder import spec_from_dict
    from ..builder.analysis import ModelSpace

    return ModelSpace(spec_from_dict(json.loads(model_json), source="study model"), dict(values))


def _model_chunk(spec: ChunkSpec, coords: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """One chunk of a built-model study: batched eigenvalues (``builder.analysis``)."""
    from ..builder.analysis import NONTRIVIAL, _batch

    space = model_space(spec.model, spec.values)  # type: ignore[arg-type]
    if spec.kind == "grid":
        shape = tuple(int(np.size(coords[n])) for n in spec.names)
        nd = len(shape)
        grid = {n: np.asarray(coords[n], dtype=float).reshape([-1 if i == k else 1 for i in range(nd)])
                for k, n in enumerate(spec.names)}  # fmt: skip
    else:
        shape = (int(np.size(coords[spec.names[0]])),)
        grid = {n: np.asarray(coords[n], dtype=float) for n in spec.names}
    r = _batch(space, grid, shape)
    mr, fr = r["max_real"], r["frequency"]
    out: dict[str, np.ndarray] = {"stable": (mr < 0) & (r["status"] <= NONTRIVIAL), "status": r["status"]}
    with np.errstate(all="ignore"):
        s = {"max_real": mr, "frequency": fr, "margin": -mr / np.hypot(mr, 2 * np.pi * fr)}
    for q in FLOAT_QUANTITIES:
        if q in spec.quantities:
            a = np.array(s[q], dtype=float)
            a[np.isnan(a)] = np.nan
            out[q] = a
    return out


# ---------------------------------------------------------------- N-D grid kernel
@dataclass(frozen=True)
class GridKernel:
    """Compiled Hurwitz classifier over the grid axes (``inner`` = index of the contiguous axis)."""

    inner: int
    degrees: tuple[int, ...]
    rows: Callable[..., list[Any]]
    classify: Callable[..., None]

    def row_coefficients(self, outer: list[np.ndarray], n_rows: int, inner_ref: float) -> np.ndarray:
        """Per-row coefficient table, scaled and normalised as ``MapKernel.row_coefficients``."""
        cols = [np.broadcast_to(np.asarray(c, dtype=float), (n_rows,)) for c in self.rows(*outer)]
        return normalise_rows(np.stack(cols, axis=1), self.degrees, inner_ref)[0]


@lru_cache(maxsize=8)
def grid_kernel(space: ParameterSpace, names: tuple[str, ...], signs: tuple[int, ...]) -> GridKernel | None:
    """Build the classifier for a grid over ``names``; ``None`` if no closed-form kernel applies.

    That is the case when the silent motion is not identically trivial on the
    grid, the dependence is not rational, or an axis has values of both signs.
    """
    import sympy as sp

    from ..analysis.kernels import _identically_zero, _kernel_source, _load_generated, _numerators, _specialise

    if 0 in signs:
        return None
    syms = [sp.Symbol(f"X{i}", real=True) for i in range(len(names))]
    M, D, K, moment = _specialise(space, dict(zip(names, syms)))
    if not _identically_zero(moment):
        return None
    nums = _numerators(M, D, K, dict(zip(syms, signs)))
    if nums is None:
        return None
    polys = [sp.Poly(a, *syms) if a != 0 else None for a in nums]
    degs = [tuple(p.degree(s) if p is not None else 0 for p in polys) for s in syms]
    totals = [sum(d) for d in degs]
    inner = max(i for i in range(len(syms)) if totals[i] == min(totals))  # ties: the trailing axis
    I, others = syms[inner], [s for i, s in enumerate(syms) if i != inner]
    exprs = []
    for a, d in zip(nums, degs[inner]):
        p = sp.Poly(a, I)
        exprs.extend(p.coeff_monomial(I ** k) if k else p.coeff_monomial(1) for k in range(d + 1))
    rows = sp.lambdify(others, exprs, modules="numpy")
    mod = _load_generated(_kernel_source(degs[inner]), "map")
    return GridKernel(inner=inner, degrees=degs[inner], rows=rows, classify=mod.classify)


# ---------------------------------------------------------------- masks
def _compact(a: np.ndarray) -> np.ndarray:
    """The smallest broadcastable array equal to a broadcast view (stride-0 axes reduced to length 1)."""
    a = np.asarray(a)
    return a[tuple(slice(0, 1) if st == 0 and n > 1 else slice(None) for st, n in zip(a.strides, a.shape))]


def _valid(arr: dict[str, np.ndarray]) -> np.ndarray:
    """Like ``analysis.maps._valid`` on compact arrays, returned compact (broadcastable to the chunk).

    Conditions are combined per shape first, so a chunk whose parameters each
    depend on one axis costs only a few full-size operations.
    """
    parts: dict[tuple[int, ...], Any] = {}

    def add(c: np.ndarray) -> None:
        c = np.asarray(c)
        parts[c.shape] = parts[c.shape] & c if c.shape in parts else c

    for name, vname in zip(PARAMETER_NAMES, VECTOR_NAMES):
        v = arr[vname]
        if vname != name:
            add((v >= 0) & np.isfinite(v))
            continue
        low, high, low_open, high_open = _BOUNDS[name]
        add((v > low if low_open else v >= low) & (v < high if high_open else v <= high))
    add(arr["h10"] + arr["h20"] > 0)
    if all(bool(np.all(c)) for c in parts.values()):
        return np.ones((1,) * max(len(k) for k in parts), dtype=bool)
    ok: Any = np.True_
    for shape in sorted(parts, key=lambda sh: math.prod(sh)):
        ok = ok & parts[shape]
    return ok


# ---------------------------------------------------------------- per-point quantities
def _points(arr: dict[str, np.ndarray], shape: tuple[int, ...], flat: np.ndarray) -> list[np.ndarray]:
    ix = np.unravel_index(flat, shape)
    return [np.broadcast_to(arr[n], shape)[ix] for n in VECTOR_NAMES]


def _quartic(p: list[np.ndarray]) -> tuple[np.ndarray, ...]:
    from ..numeric.compiled import compiled_model

    n = p[0].size
    with np.errstate(all="ignore"):
        ent = [np.broadcast_to(np.asarray(e, dtype=float), (n,)) for e in compiled_model().trivial_matrices(p)]
    M = np.stack(ent[0:4], -1).reshape(n, 2, 2)
    D = np.stack(ent[4:8], -1).reshape(n, 2, 2)
    K = np.stack(ent[8:12], -1).reshape(n, 2, 2)
    return quartic_coefficients(M, D, K)


def _summary(coef: tuple[np.ndarray, ...]) -> dict[str, np.ndarray]:
    mr, fr = _roots_summary(coef)
    with np.errstate(all="ignore"):
        margin = -mr / np.hypot(mr, 2 * np.pi * fr)
    return {"max_real": mr, "frequency": fr, "margin": margin}


def _omega_crit(p: list[np.ndarray], lo: float, hi: float) -> np.ndarray:
    P = np.stack(p, axis=1)
    roots, dirs, counts, _ = critical_speeds_batch(P, lo, hi, max_crossings=8)
    k = np.arange(roots.shape[1])
    onset = (dirs == -1) & (k[None, :] < counts[:, None])
    first = np.argmax(onset, axis=1)
    return np.where(onset.any(axis=1), roots[np.arange(roots.shape[0]), first], np.nan)


def compute_chunk(spec: ChunkSpec, coords: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Compute one chunk.

    Parameters
    ----------
    spec : ChunkSpec
        The study.
    coords : dict
        Grid: the chunk's values of every axis (1-D each).  Samples: the
        chunk's values of every sampled name (1-D, equal lengths).

    Returns
    -------
    dict of ndarray
        ``stable`` (bool), ``status`` (int8) and the requested float
        quantities, shaped like the chunk (dimensions in study order).
    """
    if spec.model is not None:
        return _model_chunk(spec, coords)
    space = build_space(spec.preset, spec.values, spec.tied)
    if spec.kind == "grid":
        shape = tuple(int(np.size(coords[n])) for n in spec.names)
        nd = len(shape)
        axes = {n: np.asarray(coords[n], dtype=float).reshape([-1 if i == k else 1 for i in range(nd)])
                for k, n in enumerate(spec.names)}
    else:
        shape = (int(np.size(coords[spec.names[0]])),)
        axes = {n: np.asarray(coords[n], dtype=float) for n in spec.names}
    arr = {k: _compact(v) for k, v in space.arrays(axes).items()}
    valid = _valid(arr)
    triv = valid & _trivial(arr)
    all_good = bool(np.all(triv))
    stable = np.zeros(shape, dtype=bool)
    status = np.zeros(shape, dtype=np.int8)
    if not all_good:
        status[~np.broadcast_to(valid, shape)] = 4
    floats = [q for q in FLOAT_QUANTITIES if q in spec.quantities]
    out: dict[str, np.ndarray] = {q: np.full(shape, np.nan) for q in floats}
    kern = grid_kernel(space, spec.names, spec.signs) if spec.kind == "grid" else None
    if kern is not None:
        i = kern.inner
        others = [k for k in range(len(shape)) if k != i]
        mesh = np.meshgrid(*[np.asarray(coords[spec.names[k]], dtype=float) for k in others], indexing="ij")
        n_rows = math.prod(shape[k] for k in others)
        C = kern.row_coefficients([m.ravel() for m in mesh], n_rows, spec.refs[i])
        res = np.empty((n_rows, shape[i]), dtype=np.uint8)
        kern.classify(C, np.asarray(coords[spec.names[i]], dtype=float) / spec.refs[i], res)
        res = np.moveaxis(res.reshape([shape[k] for k in others] + [shape[i]]), -1, i)
        stable[...] = res.view(bool)
        if not all_good:
            stable &= np.broadcast_to(triv, shape)
    need_points = kern is None or floats
    if need_points and np.any(triv):
        flat_all = np.flatnonzero(np.broadcast_to(triv, shape)) if not all_good else None
        n_t = flat_all.size if flat_all is not None else math.prod(shape)
        for b0 in range(0, n_t, _BATCH):
            flat = flat_all[b0:b0 + _BATCH] if flat_all is not None else np.arange(b0, min(n_t, b0 + _BATCH))
            p = _points(arr, shape, flat)
            ix = np.unravel_index(flat, shape)
            if kern is None or set(floats) - {"critical_speed"}:
                coef = _quartic(p)
                if kern is None:
                    stable[ix] = hurwitz_stable(*coef)
                if set(floats) - {"critical_speed"}:
                    s = _summary(coef)
                    for q in floats:
                        if q in s:
                            out[q][ix] = s[q]
            if "critical_speed" in floats:
                out["critical_speed"][ix] = _omega_crit(p, *spec.critical_speed_range)
    if not all_good:
        _nontrivial(spec, space, coords, shape, np.broadcast_to(valid & ~triv, shape), stable, status, out, floats)
    for q in floats:
        a = out[q]
        a[np.isnan(a)] = np.nan  # one NaN bit pattern (checksums, zarr's empty-chunk test)
    return {"stable": stable, "status": status, **out}


def _nontrivial(spec: ChunkSpec, space: ParameterSpace, coords: dict[str, np.ndarray], shape: tuple[int, ...],
                mask: np.ndarray, stable: np.ndarray, status: np.ndarray, out: dict[str, np.ndarray],
                floats: list[str]) -> None:
    """Points with a non-trivial silent motion: numeric linearization one by one."""
    for flat in np.flatnonzero(mask):
        ix = np.unravel_index(flat, shape)
        if spec.kind == "grid":
            vals = {n: float(coords[n][ix[k]]) for k, n in enumerate(spec.names)}
        else:
            vals = {n: float(coords[n][ix[0]]) for n in spec.names}
        code, c = _numeric_point(space, vals)
        status[ix] = code
        if c is None:
            continue
        stable[ix] = bool(hurwitz_stable(*c))
        s = _summary(tuple(np.atleast_1d(x) for x in c))
        for q in floats:
            if q in s:
                out[q][ix] = s[q][0]
            # critical_speed stays NaN at non-trivial silent motions (no batched kernel there)
