"""Sobol' indices of precomputed Saltelli evaluations (scipy or SALib), bootstrap intervals, P(squeal)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..errors import ParameterError
from ..validation import validated

__all__ = ["SobolEstimate", "sobol_estimate", "sobol_many", "bootstrap_many", "probability_interval", "BACKENDS"]

#: Estimators: ``scipy`` (:func:`scipy.stats.sobol_indices`, percentile bootstrap seeded here) or ``salib``
#: (:func:`SALib.analyze.sobol.analyze`, its normal-approximation bootstrap).
BACKENDS = ("scipy", "salib")


@dataclass(frozen=True)
class SobolEstimate:
    """First-order and total Sobol' indices of one output, with confidence intervals.

    Attributes
    ----------
    first, total : ndarray, shape (d,)
        Saltelli (2010) first-order and Jansen (1999) total-order estimates (NaN: the output is constant).
    first_ci, total_ci : ndarray, shape (d, 2)
        Their confidence intervals ``[low, high]``.
    n : int
        Rows of the design used (each row: one point of ``A``, ``B`` and every ``AB_i``).
    mean, variance : float
        Of the output over ``A`` and ``B``.
    """

    first: np.ndarray
    total: np.ndarray
    first_ci: np.ndarray
    total_ci: np.ndarray
    n: int
    mean: float
    variance: float


def _saltelli_jansen(f_a: np.ndarray, f_b: np.ndarray, f_ab: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Estimators of :func:`scipy.stats.sobol_indices` (``saltelli_2010``) along the last axis, batched.

    ``f_a``, ``f_b``: (..., n); ``f_ab``: (d, ..., n).  Returns first and total, each (d, ...).
    """
    var = np.var(np.stack([f_a, f_b]), axis=(0, -1))
    with np.errstate(all="ignore"):
        s = np.mean(f_b * (f_ab - f_a), axis=-1) / var
        st = 0.5 * np.mean((f_a - f_ab) ** 2, axis=-1) / var
    return s, st


@validated
def sobol_estimate(f_a: np.ndarray, f_b: np.ndarray, f_ab: np.ndarray, *, backend: Literal["scipy", "salib"] = "scipy",
                   confidence: float = 0.95, n_resamples: int = 999, seed: int = 0) -> SobolEstimate:
    """Sobol' indices from precomputed evaluations of a Saltelli design.

    The scipy backend calls :func:`scipy.stats.sobol_indices` with ``func = {"f_A", "f_B", "f_AB"}`` (Saltelli
    et al. 2010 first order, Jansen total order) and a percentile bootstrap of the design's rows, seeded
    (identical on every run; scipy's own ``bootstrap()`` is not seeded).  The SALib backend calls
    :func:`SALib.analyze.sobol.analyze` (the same estimators; a normal-approximation bootstrap interval).

    Parameters
    ----------
    f_a, f_b : ndarray, shape (n,)
        The output at the rows of ``A`` and ``B``.
    f_ab : ndarray, shape (d, n)
        The output at the rows of every ``AB_i``.
    backend : {"scipy", "salib"}
        The estimator's implementation.
    confidence : float
        Confidence level of the intervals.
    n_resamples : int
        Bootstrap resamples.
    seed : int
        Seed of the bootstrap.

    Returns
    -------
    SobolEstimate

    Raises
    ------
    ParameterError
        Shapes that do not match, non-finite values, fewer than 2 rows, a confidence level outside (0, 1), or the
        SALib backend without SALib installed.
    """
    return sobol_many([(f_a, f_b, f_ab)], backend=backend, confidence=confidence, n_resamples=n_resamples,
                      seed=seed)[0]


def sobol_many(outputs: list[tuple[np.ndarray, np.ndarray, np.ndarray]], *, backend: str = "scipy",
               confidence: float = 0.95, n_resamples: int = 999, seed: int = 0) -> list[SobolEstimate]:
    """:func:`sobol_estimate` of several outputs of the same design rows, the bootstrap resamples drawn once.

    Each output's estimate is the one :func:`sobol_estimate` gives it alone (same seed, same resamples); the
    scipy backend's bootstrap is one pass over the rows for all of them (:func:`bootstrap_many`).

    Parameters
    ----------
    outputs : list of (f_a, f_b, f_ab)
        Per output, as :func:`sobol_estimate`; the same number of rows for all.
    backend, confidence, n_resamples, seed
        As :func:`sobol_estimate`.

    Returns
    -------
    list of SobolEstimate

    Raises
    ------
    ParameterError
        As :func:`sobol_estimate`.
    """
    checked = [_checked(*o, confidence=confidence, n_resamples=n_resamples) for o in outputs]
    res: list[SobolEstimate | None] = [None] * len(checked)
    boot = []
    for i, (f_a, f_b, f_ab) in enumerate(checked):
        n, d = f_a.size, f_ab.shape[0]
        mean = float(np.mean(np.concatenate([f_a, f_b])))
        var = float(np.var(np.concatenate([f_a, f_b])))
        nan = np.full(d, np.nan)
        if not var > 0:  # a constant output has no variance to apportion
            res[i] = SobolEstimate(nan, nan, np.full((d, 2), np.nan), np.full((d, 2), np.nan), n, mean, var)
        elif backend == "salib":
            res[i] = _salib(f_a, f_b, f_ab, confidence, n_resamples, seed, mean, var)
        else:
            boot.append((i, mean, var, f_a - mean, f_b - mean, f_ab - mean))
    if boot:
        # centred by the mean of A and B as scipy does (Sobol' and Levitan 1999); the bootstrap resamples these
        groups: dict[int, list[tuple[int, float, float, np.ndarray, np.ndarray, np.ndarray]]] = {}
        for b in boot:
            groups.setdefault(b[3].size, []).append(b)
        for size, group in groups.items():
            draws = bootstrap_many([(g[3], g[4], g[5]) for g in group], n_resamples, seed)
            for (i, mean, var, f_a, f_b, f_ab), (boot_s, boot_t) in zip(group, draws):
                first, total = _point(f_a, f_b, f_ab)
                q = 100 * np.array([(1 - confidence) / 2, (1 + confidence) / 2])
                res[i] = SobolEstimate(first, total, np.percentile(boot_s, q, axis=0).T,
                                       np.percentile(boot_t, q, axis=0).T, size, mean, var)
    return [r for r in res if r is not None]


def _checked(f_a: np.ndarray, f_b: np.ndarray, f_ab: np.ndarray, *, confidence: float,
             n_resamples: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    f_a, f_b, f_ab = (np.asarray(x, dtype=float) for x in (f_a, f_b, f_ab))
    if f_a.ndim != 1 or f_b.shape != f_a.shape or f_ab.ndim != 2 or f_ab.shape[1] != f_a.size:
        raise ParameterError(f"sobol_estimate(): f_a, f_b must have shape (n,) and f_ab (d, n); got {f_a.shape}, "
                             f"{f_b.shape}, {f_ab.shape}")
    if not (np.isfinite(f_a).all() and np.isfinite(f_b).all() and np.isfinite(f_ab).all()):
        raise ParameterError("sobol_estimate(): the evaluations must be finite (drop rows without a verdict)")
    if f_a.size < 2:
        raise ParameterError(f"sobol_estimate(): needs at least 2 rows; got {f_a.size}")
    if not 0 < confidence < 1:
        raise ParameterError(f"sobol_estimate(): confidence must be in (0, 1); got {confidence!r}")
    if n_resamples < 10:
        raise ParameterError(f"sobol_estimate(): n_resamples must be >= 10; got {n_resamples}")
    return f_a, f_b, f_ab


def _point(f_a: np.ndarray, f_b: np.ndarray, f_ab: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First and total indices of centred evaluations: :func:`scipy.stats.sobol_indices` for a power of two of
    rows, else the same estimators written out."""
    n, d = f_a.size, f_ab.shape[0]
    if n & (n - 1) == 0:
        from scipy.stats import sobol_indices

        # the output twice: scipy squeezes its result, and one output of one input became a scalar it then indexes
        two = {"f_A": np.stack([f_a, f_a]), "f_B": np.stack([f_b, f_b]), "f_AB": np.stack([f_ab, f_ab], axis=1)}
        res = sobol_indices(func=two, n=n)
        return (np.asarray(res.first_order, dtype=float).reshape(2, d)[0],
                np.asarray(res.total_order, dtype=float).reshape(2, d)[0])
    return _saltelli_jansen(f_a, f_b, f_ab)


def _bootstrap(f_a: np.ndarray, f_b: np.ndarray, f_ab: np.ndarray, n_resamples: int,
               seed: int) -> tuple[np.ndarray, np.ndarray]:
    """The estimators of :func:`_saltelli_jansen` on ``n_resamples`` resamples of the rows (with replacement).

    Returns first and total, each ``(n_resamples, d)`` (:func:`bootstrap_many` of one output).
    """
    ((s, t),) = bootstrap_many([(f_a, f_b, f_ab)], n_resamples, seed)
    return s, t


#: Row draws per batch of the bootstrap (a few MB: the weights stay in cache, no large temporary arrays).
BOOT_BATCH = 1 << 20


def bootstrap_many(outputs: list[tuple[np.ndarray, np.ndarray, np.ndarray]], n_resamples: int,
                   seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """:func:`_bootstrap` of several outputs of the same rows, on the same resamples (drawn once).

    Every term is a mean over the rows, so a resample is a vector of row counts ``w`` and its means are
    ``w @ terms / n``: one matrix product per batch of resamples for the terms of every output at once,
    instead of gathering ``(d + 2) n`` values per resample and output.  The resamples are those one output
    alone would get with the same seed (one generator, drawn in the same order).

    Parameters
    ----------
    outputs : list of (f_a, f_b, f_ab)
        Centred evaluations of each output: ``(n,)``, ``(n,)``, ``(d, n)``; the same ``n`` for all.
    n_resamples : int
        Bootstrap resamples.
    seed : int
        Seed of the resampling.

    Returns
    -------
    list of (first, total)
        Per output, each ``(n_resamples, d)``.
    """
    n = outputs[0][0].size
    cols: list[np.ndarray] = []
    spans: list[tuple[int, int]] = []
    for f_a, f_b, f_ab in outputs:
        d = f_ab.shape[0]
        spans.append((sum(c.shape[1] for c in cols), d))
        cols.append(np.column_stack([f_a + f_b, f_a**2 + f_b**2, (f_b * (f_ab - f_a)).T, ((f_a - f_ab) ** 2).T]))
    terms = np.ascontiguousarray(np.concatenate(cols, axis=1))
    rng = np.random.default_rng(seed)
    batch = max(1, min(n_resamples, BOOT_BATCH // n))
    m = np.empty((n_resamples, terms.shape[1]))
    offset = n * np.arange(batch)[:, None]
    for start in range(0, n_resamples, batch):
        k = min(batch, n_resamples - start)
        rows = rng.integers(0, n, (k, n))
        rows += offset[:k]
        w = np.bincount(rows.ravel(), minlength=k * n).reshape(k, n)
        np.matmul(w.astype(float), terms, out=m[start:start + k])
    m /= n
    out = []
    for c0, d in spans:
        var = m[:, c0 + 1] / 2 - (m[:, c0] / 2) ** 2
        with np.errstate(all="ignore"):
            out.append((m[:, c0 + 2:c0 + 2 + d] / var[:, None], 0.5 * m[:, c0 + 2 + d:c0 + 2 + 2 * d] / var[:, None]))
    return out


def _salib(f_a: np.ndarray, f_b: np.ndarray, f_ab: np.ndarray, confidence: float, n_resamples: int, seed: int,
           mean: float, var: float) -> SobolEstimate:
    try:
        from SALib.analyze import sobol
    except ImportError:
        raise ParameterError("--backend salib needs SALib (pip install SALib); or use --backend scipy") from None
    d, n = f_ab.shape
    y = np.empty((n, d + 2))  # SALib's order without second-order terms: A, AB_1..AB_d, B per row
    y[:, 0], y[:, 1:-1], y[:, -1] = f_a, f_ab.T, f_b
    problem = {"num_vars": d, "names": [f"x{i}" for i in range(d)], "bounds": [[0.0, 1.0]] * d}
    r = sobol.analyze(problem, y.ravel(), calc_second_order=False, num_resamples=n_resamples,
                      conf_level=confidence, print_to_console=False, seed=seed)
    s1, st = np.asarray(r["S1"], dtype=float), np.asarray(r["ST"], dtype=float)
    c1, ct = np.asarray(r["S1_conf"], dtype=float), np.asarray(r["ST_conf"], dtype=float)
    return SobolEstimate(s1, st, np.stack([s1 - c1, s1 + c1], axis=1), np.stack([st - ct, st + ct], axis=1), n,
                         mean, var)


@validated
def probability_interval(k: int, m: int, confidence: float = 0.95) -> tuple[float, float, float]:
    """Probability estimate ``k/m`` and its Wilson score interval (Wilson 1927).

    Parameters
    ----------
    k : int
        Events (squealing points).
    m : int
        Trials (points with a verdict).
    confidence : float
        Confidence level.

    Returns
    -------
    p, low, high : float
        NaN for ``m = 0``.

    Raises
    ------
    ParameterError
        ``k`` outside ``[0, m]`` or ``confidence`` outside (0, 1).
    """
    if not 0 <= k <= m:
        raise ParameterError(f"probability_interval(): needs 0 <= k <= m; got k = {k}, m = {m}")
    if not 0 < confidence < 1:
        raise ParameterError(f"probability_interval(): confidence must be in (0, 1); got {confidence!r}")
    if m == 0:
        return math.nan, math.nan, math.nan
    from scipy.stats import norm

    z = float(norm.ppf((1 + confidence) / 2))
    p = k / m
    den = 1 + z * z / m
    centre = (p + z * z / (2 * m)) / den
    half = z * math.sqrt(p * (1 - p) / m + z * z / (4 * m * m)) / den
    return p, 0.0 if k == 0 else max(0.0, centre - half), 1.0 if k == m else min(1.0, centre + half)
