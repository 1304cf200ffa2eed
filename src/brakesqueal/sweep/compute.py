"""Per-chunk computation of a study (runs in the client or on Dask workers).

Everything here reuses the certified stability routes of :mod:`brakesqueal.analysis`:

* **Verdict on grids** — the generated certified Hurwitz classifier of
  :mod:`~brakesqueal.analysis.kernels` (:func:`~brakesqueal.analysis.kernels.grid_kernel`,
  same source and numba cache as ``stability_map``): the closed form is
  specialised once with *all* grid axes symbolic, the exact numerators of the
  quartic's coefficients are polynomials in one *inner* axis whose
  coefficients depend on the other axes; rows are evaluated in
  exponent-scaled floating point with error bounds, and every point is
  classified stable / unstable / uncertain.  With two axes this is the map kernel.
* **Uncertain points, samples, or grids without a kernel** — the per-point
  robust route :func:`~brakesqueal.analysis.robust.trivial_verdicts`
  (bounded closed-form matrices → interval quartic → certified Routh → exact
  rational evaluation).
* ``margin``, ``max_real``, ``frequency`` — roots of the quartic, reconciled
  with the verdict (a stable point has ``max_real < 0``, an unstable one
  ``max_real >= 0``).
* ``critical_speed`` — :func:`~brakesqueal.analysis.kernels.critical_speeds_batch`
  (certified compiled kernel, exact fallback); a point whose critical speed
  could not be established gets status 5.
* Points with a non-trivial silent motion use the numeric linearization
  (:func:`~brakesqueal.analysis.maps.numeric_point_verdict`); invalid
  parameters, no silent motion, contact loss and undecided verdicts are
  flagged in ``status`` (codes of ``analysis.maps.STATUS``) and never marked stable.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from ..analysis.kernels import critical_speeds_batch, grid_kernel, kernel_segments
from ..analysis.maps import _kernel_usable, _trivial, numeric_point_verdict, point_verdicts
from ..analysis.robust import STABLE, STATUS_UNDECIDED, UNDECIDED
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
    axis and the sign of all its values (0 = mixed).  They are kept for
    provenance only: no verdict depends on them (the kernels scale every
    chunk exactly and take signs per point).
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
    out: dict[str, np.ndarray] = {"stable": r["stable"] & (r["status"] <= NONTRIVIAL), "status": r["status"]}
    with np.errstate(all="ignore"):
        s = {"max_real": mr, "frequency": fr, "margin": -mr / np.hypot(mr, 2 * np.pi * fr)}
    for q in FLOAT_QUANTITIES:
        if q in spec.quantities:
            a = np.array(s[q], dtype=float)
            a[np.isnan(a)] = np.nan
            out[q] = a
    return out


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

    with np.errstate(all="ignore"):
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
def _points(arr: dict[str, np.ndarray], shape: tuple[int, ...], flat: np.ndarray) -> np.ndarray:
    ix = np.unravel_index(flat, shape)
    return np.stack([np.broadcast_to(arr[n], shape)[ix] for n in VECTOR_NAMES], axis=1)


def _summary(mr: np.ndarray, fr: np.ndarray) -> dict[str, np.ndarray]:
    with np.errstate(all="ignore"):
        margin = -mr / np.hypot(mr, 2 * np.pi * fr)
    return {"max_real": mr, "frequency": fr, "margin": margin}


def _omega_crit(P: np.ndarray, lo: float, hi: float) -> tuple[np.ndarray, np.ndarray]:
    roots, dirs, counts, _, status = critical_speeds_batch(P, lo, hi, max_crossings=8, return_status=True)
    k = np.arange(roots.shape[1])
    onset = (dirs == -1) & (k[None, :] < counts[:, None])
    first = np.argmax(onset, axis=1)
    crit = np.where(onset.any(axis=1), roots[np.arange(roots.shape[0]), first], np.nan)
    # an onset beyond the stored columns cannot be the first one (columns are ascending)
    return crit, status


def _kernel_codes(spec: ChunkSpec, space: ParameterSpace, coords: dict[str, np.ndarray],
                  shape: tuple[int, ...]) -> np.ndarray | None:
    """Certified kernel codes on the chunk's grid (0/1/2, study dimension order), or None without a kernel."""
    kern = grid_kernel(space, tuple(spec.names))
    if kern is None:
        return None
    i = kern.inner
    iv = np.asarray(coords[spec.names[i]], dtype=float)
    scaled = _kernel_usable(kern, iv)
    if scaled is None:
        return None
    others = [k for k in range(len(shape)) if k != i]
    mesh = np.meshgrid(*[np.asarray(coords[spec.names[k]], dtype=float) for k in others], indexing="ij")
    C, EC = kern.row_coefficients([m.ravel() for m in mesh], scaled[0])
    seg, T = kernel_segments(scaled[1])
    res = np.empty((C.shape[0], shape[i]), dtype=np.uint8)
    kern.classify(C, EC, scaled[1], seg, T, res)
    return np.moveaxis(res.reshape([shape[k] for k in others] + [shape[i]]), -1, i)


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
        quantities, shaped like the chunk (dimensions in study order).  For
        status 0/1, ``stable`` ⇔ ``max_real < 0``.
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
    triv = np.broadcast_to(valid & _trivial(arr), shape)
    stable = np.zeros(shape, dtype=bool)
    status = np.zeros(shape, dtype=np.int8)
    status[~np.broadcast_to(valid, shape)] = 4
    floats = [q for q in FLOAT_QUANTITIES if q in spec.quantities]
    out: dict[str, np.ndarray] = {q: np.full(shape, np.nan) for q in floats}
    codes = _kernel_codes(spec, space, coords, shape) if spec.kind == "grid" else None
    eig = bool(set(floats) - {"critical_speed"})
    if codes is None:
        codes = np.full(shape, UNDECIDED, dtype=np.uint8)
    elif not eig:
        sure = triv & (codes != UNDECIDED)
        stable[sure] = codes[sure] == STABLE
    need = triv if (eig or "critical_speed" in floats) else (triv & (codes == UNDECIDED))
    flat_all = np.flatnonzero(need)
    for b0 in range(0, flat_all.size, _BATCH):
        flat = flat_all[b0:b0 + _BATCH]
        ix = np.unravel_index(flat, shape)
        P = _points(arr, shape, flat)
        c, mr, fr = point_verdicts(P, eigen=eig, codes=codes[ix])
        stable[ix] = c == STABLE
        status[ix] = np.where(c == UNDECIDED, STATUS_UNDECIDED, status[ix])
        if eig:
            s = _summary(mr, fr)
            for q in floats:
                if q in s:
                    out[q][ix] = s[q]
        if "critical_speed" in floats:
            crit, cst = _omega_crit(P, *spec.critical_speed_range)
            out["critical_speed"][ix] = crit
            status[ix] = np.where(cst != 0, STATUS_UNDECIDED, status[ix])
            stable[ix] &= cst == 0
    _nontrivial(spec, space, coords, shape, np.broadcast_to(valid, shape) & ~triv, stable, status, out, floats)
    for q in floats:
        a = out[q]
        a[np.isnan(a)] = np.nan  # one NaN bit pattern (checksums, zarr's empty-chunk test)
    return {"stable": stable, "status": status, **out}


def _nontrivial(spec: ChunkSpec, space: ParameterSpace, coords: dict[str, np.ndarray], shape: tuple[int, ...],
                mask: np.ndarray, stable: np.ndarray, status: np.ndarray, out: dict[str, np.ndarray],
                floats: list[str]) -> None:
    """Points with a non-trivial silent motion: numeric linearization one by one (robust verdict)."""
    for flat in np.flatnonzero(mask):
        ix = np.unravel_index(flat, shape)
        if spec.kind == "grid":
            vals = {n: float(coords[n][ix[k]]) for k, n in enumerate(spec.names)}
        else:
            vals = {n: float(coords[n][ix[0]]) for n in spec.names}
        code, st, mr, fr = numeric_point_verdict(space, vals)
        status[ix] = code
        stable[ix] = st
        if code in (2, 3, 4):
            continue
        s = _summary(np.array([mr]), np.array([fr]))
        for q in floats:
            if q in s:
                out[q][ix] = s[q][0]
            # critical_speed stays NaN at non-trivial silent motions (no batched kernel there)
