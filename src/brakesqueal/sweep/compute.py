"""Per-chunk computation of a study (runs in the client or on Dask workers).

A chunk is a grid (or a set of samples) of the study's parameter space,
decided by the one verdict dispatcher (:func:`brakesqueal.analysis.verdict.decide`)
exactly as a map's block is: the grid routes where they apply (the compiled
Hurwitz kernel of a closed form, specialised once with *all* grid axes
symbolic; same source and numba cache as ``stability_map``), every point
they leave by the per-point routes.  The worker builds the model's engine
once per process (:func:`engine_of`: a chunk is an entry point, like a
command).  It stores ``stable``, ``status`` and the quantities asked for
(:mod:`brakesqueal.analysis.quantities`, the one list (:mod:`brakesqueal.analysis.quantities`, the one list
maps use too: ``max_real``, ``frequency``, ``margin``, ``carrier``, ``route``,
``critical_speed`` and any registered one), computed by the same grid
evaluator, :func:`~brakesqueal.analysis.quantities.evaluate_block`.

Invalid parameters, no silent motion, contact loss, solver failures and
undecided verdicts are flagged in ``status``
(:class:`~brakesqueal.status.PointStatus`) and never marked stable.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

from ..analysis.verdict import Grid, Points, compact
from ..model.parameters import ParameterSpace, Value

if TYPE_CHECKING:
    from ..codegen.engine import Engine
    from .study import Study

__all__ = ["ChunkSpec", "build_space", "compute_chunk", "engine_of"]



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
    def from_study(cls, study: Study) -> ChunkSpec:
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
                tied: tuple[tuple[str, str], ...], model: str | None = None) -> ParameterSpace:
    """The study's parameter space: a model's preset (with the study's ties added) or a complete parameter set.

    Parameters
    ----------
    preset : str or None
        Preset name (of ``model``, or any built-in preset without a model);
        ``None``: the model's default preset, or without a model a complete
        parameter set of the paper's model given by ``values``.
    values : tuple of (str, value)
        Overrides of settable names (or every parameter of the paper's model).
    tied : tuple of (str, str)
        Tie expressions added or replaced by the study.
    model : str or None
        Canonical JSON of a model description (``spec_to_dict``).

    Returns
    -------
    ParameterSpace
        Validated (its current point resolves).  Memoized by content (the
        model's description, not its name).

    Raises
    ------
    ParameterError
        Unknown names, invalid values or ties.
    """
    import json

    from ..errors import ParameterError
    from ..model.io import spec_from_dict
    from ..model.library import get_model, get_preset
    from ..model.parameters import Parameters, Preset

    spec = spec_from_dict(json.loads(model), source="study model") if model is not None else None
    vals = dict(values)
    if spec is not None:
        base: Preset | None = spec.get_preset(preset)
    elif preset is not None:
        base = get_preset(preset)
    else:
        base = None
    if not tied:
        if base is not None:
            space = ParameterSpace(base, vals)
        else:
            space = ParameterSpace.from_parameters(Parameters(get_model("paper"), vals, source="[parameters]"))
        space.resolve({})
        return space
    target = base.bound_model if base is not None else get_model("paper")
    defs: dict[str, Value] = {**base.fixed, **base.free} if base else {}
    defs.update(vals)
    ties = dict(base.tied) if base else {}
    for name, expr in tied:
        if name not in defs and name not in ties:
            where = f"preset '{base.name}'" if base else "the model parameters"
            raise ParameterError(f"cannot tie '{name}': it is not a name of {where}", parameter=name)
        defs.pop(name, None)
        ties[name] = expr
    from ..model.expressions import names_in

    used = set().union(*(names_in(e) for e in ties.values())) if ties else set()
    defs = {k: v for k, v in defs.items() if k in target.parameters or k in used}
    p = Preset(name=f"{base.name if base else 'parameters'}+ties", description="study with extra ties",
               reference="study file", fixed=defs, free={}, tied=ties,
               auxiliary=dict(base.auxiliary) if base else {}).bind(target)
    space = ParameterSpace(p, {})
    space.resolve({})
    return space


def engine_of(space: ParameterSpace) -> Engine:
    """The engine of a study's model in this worker process (built once per model; a chunk is an entry point)."""
    from ..codegen import build

    return build(space.model)


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
    from ..analysis.quantities import evaluate_block

    space = build_space(spec.preset, spec.values, spec.tied, spec.model)
    engine = engine_of(space)
    if spec.kind == "grid":
        shape = tuple(int(np.size(coords[n])) for n in spec.names)
        nd = len(shape)
        axes = {n: np.asarray(coords[n], dtype=float).reshape([-1 if i == k else 1 for i in range(nd)])
                for k, n in enumerate(spec.names)}
        arr = {k: compact(v) for k, v in space.arrays(axes).items()}
        grid = Grid(tuple(spec.names), tuple(np.asarray(coords[n], dtype=float).ravel() for n in spec.names))
        pts = Points(space, arr, tuple(spec.names), grid=grid, settable=axes)
    else:
        shape = (int(np.size(coords[spec.names[0]])),)
        axes = {n: np.asarray(coords[n], dtype=float) for n in spec.names}
        pts = Points(space, space.arrays(axes), tuple(spec.names), settable=axes)
    out = evaluate_block(engine, space, pts, tuple(spec.quantities),
                         options={"critical_speed_range": spec.critical_speed_range})
    for a in out.values():
        if a.dtype.kind == "f":
            a[np.isnan(a)] = np.nan  # one NaN bit pattern (checksums, zarr's empty-chunk test)
    return {k: v.reshape(shape) for k, v in out.items()}
