"""``run_uq``: the Saltelli design of a study evaluated by the sweep machinery, then Sobol' indices and
P(squeal) as an :class:`xarray.Dataset`."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, Union

import numpy as np

from ..errors import ParameterError
from ..status import DECIDED, PointStatus
from ..sweep import Study, load_study, run_sweep
from ..validation import validated
from ._design import SaltelliStudy, design_study
from ._indices import probability_interval, sobol_estimate

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["UQ_QUANTITIES", "UQRun", "run_uq", "uq_summary", "IN_MEMORY_POINTS"]

#: The outputs whose indices are estimated: max Re λ [1/s], the squeal indicator 1{max Re λ > 0} (from the
#: certified verdict), and the frequency [Hz] of the least-stable mode (the leading unstable mode where the point
#: squeals).
UQ_QUANTITIES = ("max_real", "squeal", "frequency")
#: Designs of at most this many evaluations run in memory unless a store is given; larger ones go into
#: ``STUDY.uq.zarr`` beside the study file (resumable).
IN_MEMORY_POINTS = 1 << 20


@dataclass
class UQRun:
    """What :func:`run_uq` did.

    Attributes
    ----------
    dataset : xarray.Dataset
        Indices, intervals, P(squeal), the counts of points without a verdict and the ``A``/``B`` samples
        (see :func:`run_uq`).
    store : str or None
        The design's Zarr store (None: computed in memory).
    computed, reused : int
        Chunks of the design computed by this run / kept from an earlier run.
    """

    dataset: xr.Dataset
    store: str | None
    computed: int
    reused: int


def _default_uq_store(st: SaltelliStudy, executor: bool) -> Path | None:
    """``[output] store`` or the study file, with the suffix ``.uq.zarr`` (never the sweep's own store): for large
    designs and designs run on Dask; None (in memory) otherwise."""
    if not (executor or st.n_points > IN_MEMORY_POINTS):
        return None
    if st.store:
        return Path(st.store).with_suffix(".uq.zarr")
    return Path(st.source).with_suffix(".uq.zarr") if st.source != "<dict>" else None


def _check_valid(st: SaltelliStudy) -> None:
    """Refuse a design with points outside the allowed ranges (a tie can carry a sample out of its range)."""
    space = st.space()
    values = st.samples()
    step = 1 << 18  # the parameter arrays of a block at a time (a large design's would not fit in memory)
    ok = np.concatenate([np.asarray(space.valid(space.arrays({k: v[i:i + step] for k, v in values.items()})),
                                    dtype=bool).reshape(-1) for i in range(0, st.n_points, step)])
    if ok.all():
        return
    j = int(np.flatnonzero(~ok)[0])
    point = {k: float(v[j]) for k, v in values.items()}
    try:
        space.resolve(point)
        why = "invalid parameters"
    except ParameterError as exc:
        why = str(exc)
    names = ", ".join(values)
    raise ParameterError(f"study file '{st.source}': key 'distributions': {int((~ok).sum())} of {ok.size} design "
                         f"points of {names} give parameters outside their allowed ranges (through the ties), e.g. "
                         f"{', '.join(f'{k} = {v:.6g}' for k, v in point.items())}: {why}")


def _evaluate(st: SaltelliStudy, store: Path | None, workers: int | None, scheduler: str | None, overwrite: bool,
              progress: Any) -> tuple[dict[str, np.ndarray], str | None, int, int]:
    names = ("status", "stable", "max_real", "frequency")
    if store is None and workers is None and scheduler is None:
        from ..sweep.compute import ChunkSpec, compute_chunk

        spec = ChunkSpec.from_study(st)
        samples = st.samples()
        out = {k: np.empty(st.n_points, dtype=bool if k == "stable" else np.int8 if k == "status" else float)
               for k in names}
        for c in range(st.n_chunks):
            (r,) = st.region(c)
            res = compute_chunk(spec, {k: v[r] for k, v in samples.items()})
            for k in names:
                out[k][r] = res[k]
            if callable(progress):
                progress((c + 1) / st.n_chunks)
        return out, None, st.n_chunks, 0
    run = run_sweep(st, store=store, workers=workers, scheduler=scheduler, overwrite=overwrite, progress=progress)
    ds = run.dataset
    return ({k: np.asarray(ds[k].values) for k in names}, run.store, run.computed, run.reused)


@validated
def run_uq(study: Union[Study, str, Path, Mapping[str, Any]], *, store: Union[str, Path, None] = None,
           workers: int | None = None, scheduler: str | None = None, overwrite: bool = False,
           backend: Literal["scipy", "salib"] = "scipy", confidence: float = 0.95, n_resamples: int = 999,
           progress: Any = False) -> UQRun:
    """Sobol' indices and the probability of squeal of a study with ``[distributions]``.

    The study's inputs are drawn with a Saltelli design (:func:`~brakesqueal.uq.saltelli_design`: ``N`` =
    ``[samples] n`` rounded up to a power of two, ``(d + 2) N`` evaluations, scrambled Sobol' sequence seeded by
    ``[samples] seed``) mapped through the inputs' inverse CDFs, and evaluated by the sweep machinery (the one
    grid evaluator, certified verdicts): in memory for small designs, else in a resumable Zarr store on Dask
    (:func:`brakesqueal.sweep.run_sweep`; a killed run resumes and gives identical indices).

    Points without a verdict (no silent motion, contact loss, undecided, ...) are counted, never taken as
    stable: a row of the design with one of them is left out of the indices of every output, and P(squeal) is
    estimated over the ``A`` and ``B`` points with a verdict, with the bounds it would have if all points
    without a verdict were stable / squealed.

    Parameters
    ----------
    study : Study, str, Path or dict
        A study file with ``[distributions]`` and ``[samples] n, seed`` (or its content as a dict).
    store : str or Path, optional
        Zarr store of the design's evaluations.  Default: designs of more than :data:`IN_MEMORY_POINTS`
        evaluations, and designs run on Dask, go into ``STUDY.uq.zarr`` beside the study file (or ``[output]
        store`` with the suffix ``.uq.zarr``; never the sweep's own store); smaller ones run in memory.
    workers : int, optional
        Local Dask worker processes (as :func:`brakesqueal.sweep.run_sweep`).
    scheduler : str, optional
        Address of a Dask scheduler.
    overwrite : bool
        Replace an existing store.
    backend : {"scipy", "salib"}
        Estimator implementation (:func:`~brakesqueal.uq.sobol_estimate`).
    confidence : float
        Confidence level of every interval.
    n_resamples : int
        Bootstrap resamples.
    progress : bool or callable
        As :func:`brakesqueal.sweep.run_sweep`.

    Returns
    -------
    UQRun
        ``dataset`` has dimensions ``quantity`` (:data:`UQ_QUANTITIES`), ``input``, ``bound`` (low, high) and
        ``draw`` (the ``2 N`` points of ``A`` and ``B``); variables ``first``, ``total``, ``first_ci``,
        ``total_ci``, ``rows``, ``mean``, ``variance``, ``p_squeal``, ``p_squeal_ci``, ``p_squeal_bounds``,
        ``no_verdict`` and per draw the inputs and outputs.

    Raises
    ------
    ParameterError
        A bad study (one line naming the file and the key), a design point outside the allowed ranges, bad
        options.
    """
    st0 = load_study(study)
    st = design_study(st0, ("max_real", "frequency"))
    _check_valid(st)
    path = Path(store) if store is not None else _default_uq_store(st, workers is not None or scheduler is not None)
    values, used_store, computed, reused = _evaluate(st, path, workers, scheduler, overwrite, progress)
    ds = _analyse(st, values, backend, confidence, n_resamples)
    ds.attrs.update(store=used_store or "", computed_chunks=computed, reused_chunks=reused)
    return UQRun(ds, used_store, computed, reused)


def _analyse(st: SaltelliStudy, values: dict[str, np.ndarray], backend: str, confidence: float,
             n_resamples: int) -> xr.Dataset:
    import xarray as xr

    d, n = len(st.ranges), st.n_base
    status = values["status"].reshape(d + 2, n)
    decided = np.isin(status, [int(s) for s in DECIDED])
    squeal = decided & ~values["stable"].reshape(d + 2, n)
    outputs = {"max_real": values["max_real"].reshape(d + 2, n), "squeal": squeal.astype(float),
               "frequency": values["frequency"].reshape(d + 2, n)}
    names = [r.name for r in st.ranges]
    first = np.full((3, d), np.nan)
    total = np.full((3, d), np.nan)
    first_ci = np.full((3, d, 2), np.nan)
    total_ci = np.full((3, d, 2), np.nan)
    rows, mean, var = np.zeros(3, dtype=np.int64), np.full(3, np.nan), np.full(3, np.nan)
    for q, key in enumerate(UQ_QUANTITIES):
        f = outputs[key]
        ok = decided.all(axis=0) & np.isfinite(f).all(axis=0)
        rows[q] = int(ok.sum())
        if rows[q] < 2:
            continue
        est = sobol_estimate(f[0, ok], f[1, ok], f[2:, ok], backend=backend,  # type: ignore[arg-type]
                             confidence=confidence, n_resamples=n_resamples, seed=st.seed)
        first[q], total[q], first_ci[q], total_ci[q] = est.first, est.total, est.first_ci, est.total_ci
        mean[q], var[q] = est.mean, est.variance
    ab = decided[:2].ravel()
    k, m, u = int(squeal[:2].sum()), int(ab.sum()), int((~ab).sum())
    p, lo, hi = probability_interval(k, m, confidence)
    counts = np.array([int((status == int(s)).sum()) for s in PointStatus], dtype=np.int64)
    samples = st.samples()
    draws = {f"input_{nm}": ("draw", samples[nm][: 2 * n]) for nm in names}
    draws.update(max_real=("draw", outputs["max_real"][:2].ravel()),
                 frequency=("draw", outputs["frequency"][:2].ravel()),
                 squeal=("draw", squeal[:2].ravel().astype(np.int8)), status=("draw", status[:2].ravel()))
    qd, bd = ("quantity", "input"), ("quantity", "input", "bound")
    ds = xr.Dataset(
        {"first": (qd, first, {"long_name": "first-order Sobol' index (Saltelli 2010)"}),
         "total": (qd, total, {"long_name": "total-order Sobol' index (Jansen 1999)"}),
         "first_ci": (bd, first_ci, {"long_name": f"{confidence:g} confidence interval of first"}),
         "total_ci": (bd, total_ci, {"long_name": f"{confidence:g} confidence interval of total"}),
         "rows": ("quantity", rows, {"long_name": "rows of the design used (every point of the row has a verdict)"}),
         "mean": ("quantity", mean), "variance": ("quantity", var),
         "p_squeal": ((), p, {"long_name": "probability of squeal (points of A and B with a verdict)"}),
         "p_squeal_ci": ("bound", np.array([lo, hi]), {"long_name": f"{confidence:g} Wilson score interval"}),
         "p_squeal_bounds": ("bound", np.array([k / (m + u), (k + u) / (m + u)]) if m + u else np.full(2, np.nan),
                             {"long_name": "P(squeal) if every point without a verdict were stable / squealed"}),
         "status_counts": ("point_status", counts, {"long_name": "design points per status"}),
         **draws},
        coords={"quantity": list(UQ_QUANTITIES), "input": names, "bound": ["low", "high"],
                "point_status": [s.meaning for s in PointStatus]},
        attrs={"title": f"brakesqueal uq '{st.name}'", "study_file": st.source, "study_hash": st.hash(),
               "study_text": st.text, "design": "Saltelli: A, B, AB_i from a scrambled Sobol' sequence",
               "n_base": n, "n_inputs": d, "n_evaluations": st.n_points, "seed": st.seed, "backend": backend,
               "confidence": confidence, "n_resamples": n_resamples,
               "no_verdict": int((~decided).sum()), "no_verdict_in_a_b": u, "squeal_count": k, "decided_in_a_b": m,
               "distributions": json.dumps({r.name: r.distribution.spec() for r in st.ranges if r.distribution}),
               "frequency_note": "frequency of the least-stable mode: the leading unstable mode where it squeals"})
    return ds


def _num(x: Any) -> float | None:
    v = float(x)
    return v if math.isfinite(v) else None


@validated
def uq_summary(ds: Any) -> dict[str, Any]:
    """The JSON form of :func:`run_uq`'s dataset (NaN as ``null``).

    Parameters
    ----------
    ds : xarray.Dataset
        ``run_uq(...).dataset``.

    Returns
    -------
    dict
        ``quantities[q]`` with ``first``, ``total`` (keyed by input), ``first_ci``, ``total_ci`` (``[low, high]``
        per input), ``rows``, ``mean``, ``variance``; ``p_squeal`` with ``value``, ``ci``, ``bounds``; the design
        and the counts of points without a verdict.
    """
    names = [str(x) for x in ds["input"].values]
    quantities: dict[str, Any] = {}
    for q in ds["quantity"].values:
        sel = ds.sel(quantity=q)
        quantities[str(q)] = {
            "first": {nm: _num(sel["first"].values[i]) for i, nm in enumerate(names)},
            "total": {nm: _num(sel["total"].values[i]) for i, nm in enumerate(names)},
            "first_ci": {nm: [_num(x) for x in sel["first_ci"].values[i]] for i, nm in enumerate(names)},
            "total_ci": {nm: [_num(x) for x in sel["total_ci"].values[i]] for i, nm in enumerate(names)},
            "rows": int(sel["rows"]), "mean": _num(sel["mean"]), "variance": _num(sel["variance"]),
        }
    a = ds.attrs
    return {
        "study": a["study_file"], "inputs": json.loads(a["distributions"]), "n_base": int(a["n_base"]),
        "evaluations": int(a["n_evaluations"]), "seed": int(a["seed"]), "backend": a["backend"],
        "confidence": float(a["confidence"]),
        "quantities": quantities,
        "p_squeal": {"value": _num(ds["p_squeal"]), "ci": [_num(x) for x in ds["p_squeal_ci"].values],
                     "bounds": [_num(x) for x in ds["p_squeal_bounds"].values], "squealing": int(a["squeal_count"]),
                     "with_verdict": int(a["decided_in_a_b"]), "without_verdict": int(a["no_verdict_in_a_b"])},
        "no_verdict": int(a["no_verdict"]),
        "status_counts": {str(s): int(c) for s, c in zip(ds["point_status"].values, ds["status_counts"].values) if c},
        "store": a["store"] or None, "computed_chunks": int(a["computed_chunks"]),
        "reused_chunks": int(a["reused_chunks"]),
    }
