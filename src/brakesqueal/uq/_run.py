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
from ._indices import probability_interval, sobol_many

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["UQ_QUANTITIES", "UQRun", "run_uq", "uq_summary", "IN_MEMORY_POINTS"]

#: The outputs whose indices are estimated: max Re λ [1/s], the squeal indicator 1{max Re λ > 0} (from the
#: certified verdict), and the frequency [Hz] of the least-stable mode (the leading unstable mode where the point
#: squeals).
UQ_QUANTITIES = ("max_real", "squeal", "frequency")
#: How per-mode quantities follow a mode from point to point (``run_uq(per_mode=True)``).
MODE_RULE = ("modes are the eigenvalue pairs with Im > 0, numbered at every point by ascending frequency; points with "
             "another number of oscillating modes than most are left out of the per-mode indices")
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
              progress: Any, per_mode: bool = False) -> tuple[dict[str, np.ndarray], str | None, int, int]:
    """The design's evaluations: one batched evaluator call per chunk (in memory) or the sweep runner (store);
    with ``per_mode``, every point's eigenvalues too (``"eigenvalues"``, batched per chunk, in this process)."""
    from ..sweep.compute import ChunkSpec, compute_chunk

    names = ("status", "stable", "max_real", "frequency")
    spec = ChunkSpec.from_study(st)
    samples = st.samples()
    if store is None and workers is None and scheduler is None:
        out = {k: np.empty(st.n_points, dtype=bool if k == "stable" else np.int8 if k == "status" else float)
               for k in names}
        for c in range(st.n_chunks):
            (r,) = st.region(c)
            res = compute_chunk(spec, {k: v[r] for k, v in samples.items()})
            for k in names:
                out[k][r] = res[k]
            if callable(progress):
                progress((c + 1) / st.n_chunks)
        used, computed, reused = None, st.n_chunks, 0
    else:
        run = run_sweep(st, store=store, workers=workers, scheduler=scheduler, overwrite=overwrite,
                        progress=progress)
        out = {k: np.asarray(run.dataset[k].values) for k in names}
        used, computed, reused = run.store, run.computed, run.reused
    if per_mode:
        from ._modes import mode_eigenvalues

        parts = []
        for c in range(st.n_chunks):
            (r,) = st.region(c)
            parts.append(mode_eigenvalues(spec, {k: v[r] for k, v in samples.items()}))
        width = max(p.shape[1] for p in parts)
        out["eigenvalues"] = np.concatenate([np.pad(p, ((0, 0), (0, width - p.shape[1])), constant_values=np.nan)
                                             for p in parts])
    return out, used, computed, reused


@validated
def run_uq(study: Union[Study, str, Path, Mapping[str, Any]], *, store: Union[str, Path, None] = None,
           workers: int | None = None, scheduler: str | None = None, overwrite: bool = False,
           backend: Literal["scipy", "salib"] = "scipy", confidence: float = 0.95, n_resamples: int = 999,
           progress: Any = False, per_mode: bool = False) -> UQRun:
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
    per_mode : bool
        Also the indices of the real part and the frequency of every tracked mode (quantities ``mode1_real``,
        ``mode1_frequency``, ...): a mode is an eigenvalue pair with ``Im λ > 0``, numbered at every point by
        ascending frequency; points with another number of oscillating modes than most have no per-mode values
        (their rows are left out of these indices only).  The eigenvalues are computed in this process, batched
        per chunk (also for a store-backed run).

    Returns
    -------
    UQRun
        ``dataset`` has dimensions ``quantity`` (:data:`UQ_QUANTITIES`, then with ``per_mode`` ``mode1_real``,
        ``mode1_frequency``, ``mode2_real``, ...), ``input``, ``bound`` (low, high) and
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
    values, used_store, computed, reused = _evaluate(st, path, workers, scheduler, overwrite, progress, per_mode)
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
    mode_re = mode_fr = None
    if "eigenvalues" in values:
        from ._modes import track_modes

        mode_re, mode_fr = track_modes(values["eigenvalues"])
        for k in range(mode_re.shape[1]):
            outputs[f"mode{k + 1}_real"] = mode_re[:, k].reshape(d + 2, n)
            outputs[f"mode{k + 1}_frequency"] = mode_fr[:, k].reshape(d + 2, n)
    keys = list(outputs)
    nq = len(keys)
    names = [r.name for r in st.ranges]
    first = np.full((nq, d), np.nan)
    total = np.full((nq, d), np.nan)
    first_ci = np.full((nq, d, 2), np.nan)
    total_ci = np.full((nq, d, 2), np.nan)
    rows, mean, var = np.zeros(nq, dtype=np.int64), np.full(nq, np.nan), np.full(nq, np.nan)
    oks = []
    for q, key in enumerate(keys):
        f = outputs[key]
        oks.append(decided.all(axis=0) & np.isfinite(f).all(axis=0))
        rows[q] = int(oks[-1].sum())
    # quantities of the same rows share one bootstrap pass (the same resamples as each would get alone)
    groups: dict[bytes, list[int]] = {}
    for q, ok in enumerate(oks):
        if rows[q] >= 2:
            groups.setdefault(np.packbits(ok).tobytes(), []).append(q)
    for qs in groups.values():
        ok = oks[qs[0]]
        ests = sobol_many([(outputs[keys[q]][0, ok], outputs[keys[q]][1, ok], outputs[keys[q]][2:, ok]) for q in qs],
                          backend=backend, confidence=confidence, n_resamples=n_resamples, seed=st.seed)
        for q, est in zip(qs, ests):
            first[q], total[q], first_ci[q], total_ci[q] = est.first, est.total, est.first_ci, est.total_ci
            mean[q], var[q] = est.mean, est.variance
    ab = decided[:2].ravel()
    k, m, u = int(squeal[:2].sum()), int(ab.sum()), int((~ab).sum())
    p, lo, hi = probability_interval(k, m, confidence)
    counts = np.array([int((status == int(s)).sum()) for s in PointStatus], dtype=np.int64)
    samples = st.samples()
    draws: dict[str, Any] = {f"input_{nm}": ("draw", samples[nm][: 2 * n]) for nm in names}
    draws.update(max_real=("draw", outputs["max_real"][:2].ravel()),
                 frequency=("draw", outputs["frequency"][:2].ravel()),
                 squeal=("draw", squeal[:2].ravel().astype(np.int8)), status=("draw", status[:2].ravel()))
    extra_coords: dict[str, Any] = {}
    if mode_re is not None and mode_fr is not None:
        extra_coords["mode"] = np.arange(1, mode_re.shape[1] + 1)
        draws.update(mode_real=(("draw", "mode"), mode_re[:2 * n], {"long_name": "Re λ of the mode [1/s]"}),
                     mode_frequency=(("draw", "mode"), mode_fr[:2 * n],
                                     {"long_name": "frequency of the mode [Hz] (modes by ascending frequency)"}))
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
        coords={"quantity": keys, "input": names, "bound": ["low", "high"],
                "point_status": [s.meaning for s in PointStatus], **extra_coords},
        attrs={"title": f"brakesqueal uq '{st.name}'", "study_file": st.source, "study_hash": st.hash(),
               "study_text": st.text, "design": "Saltelli: A, B, AB_i from a scrambled Sobol' sequence",
               "n_base": n, "n_inputs": d, "n_evaluations": st.n_points, "seed": st.seed, "backend": backend,
               "confidence": confidence, "n_resamples": n_resamples,
               "no_verdict": int((~decided).sum()), "no_verdict_in_a_b": u, "squeal_count": k, "decided_in_a_b": m,
               "distributions": json.dumps({r.name: r.distribution.spec() for r in st.ranges if r.distribution}),
               "frequency_note": "frequency of the least-stable mode: the leading unstable mode where it squeals",
               "per_mode": int(mode_re is not None),
               "mode_rule": MODE_RULE if mode_re is not None else ""})
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
        and the counts of points without a verdict.  A per-mode study (``run_uq(per_mode=True)``) adds
        ``modes``: per tracked mode ``mode`` (1, 2, ... by ascending frequency), ``real`` and ``frequency`` (each
        as a quantity) and ``frequency_range`` (over the ``A`` and ``B`` points), and ``mode_rule``.
    """
    names = [str(x) for x in ds["input"].values]
    quantities: dict[str, Any] = {}
    per_mode: dict[str, Any] = {}
    for q in ds["quantity"].values:
        sel = ds.sel(quantity=q)
        if str(q) not in UQ_QUANTITIES:
            per_mode[str(q)] = sel
            continue
        quantities[str(q)] = {
            "first": {nm: _num(sel["first"].values[i]) for i, nm in enumerate(names)},
            "total": {nm: _num(sel["total"].values[i]) for i, nm in enumerate(names)},
            "first_ci": {nm: [_num(x) for x in sel["first_ci"].values[i]] for i, nm in enumerate(names)},
            "total_ci": {nm: [_num(x) for x in sel["total_ci"].values[i]] for i, nm in enumerate(names)},
            "rows": int(sel["rows"]), "mean": _num(sel["mean"]), "variance": _num(sel["variance"]),
        }
    a = ds.attrs
    out = {
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
    if int(a.get("per_mode", 0)):
        modes = []
        for k in (int(x) for x in ds["mode"].values):
            entry: dict[str, Any] = {"mode": k}
            for part in ("real", "frequency"):
                sel = per_mode[f"mode{k}_{part}"]
                entry[part] = {
                    "first": {nm: _num(sel["first"].values[i]) for i, nm in enumerate(names)},
                    "total": {nm: _num(sel["total"].values[i]) for i, nm in enumerate(names)},
                    "first_ci": {nm: [_num(x) for x in sel["first_ci"].values[i]] for i, nm in enumerate(names)},
                    "total_ci": {nm: [_num(x) for x in sel["total_ci"].values[i]] for i, nm in enumerate(names)},
                    "rows": int(sel["rows"]), "mean": _num(sel["mean"]), "variance": _num(sel["variance"]),
                }
            f = np.asarray(ds["mode_frequency"].sel(mode=k).values, dtype=float)
            f = f[np.isfinite(f)]
            entry["frequency_range"] = [_num(f.min()), _num(f.max())] if f.size else [None, None]
            modes.append(entry)
        out["modes"] = modes
        out["mode_rule"] = a["mode_rule"]
    return out
