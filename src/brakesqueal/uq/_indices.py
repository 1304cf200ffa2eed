"""Sobol' indices of precomputed Saltelli evaluations (scipy or SALib), bootstrap intervals, P(squeal)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..errors import ParameterError
from ..validation import validated

__all__ = ["SobolEstimate", "sobol_estimate", "probability_interval", "BACKENDS"]

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
    f_a, f_b, f_ab = (np.asarray(x, dtype=float) for x in (f_a, f_b, f_ab))
    if f_a.ndim != 1 or f_b.shape != f_a.shape or f_ab.ndim != 2 or f_ab.shape[1] != f_a.size:
        raise ParameterError(f"sobol_estimate(): f_a, f_b must have shape (n,) and f_ab (d, n); got {f_a.shape}, "
                             f"{f_b.shape}, {f_ab.shape}")
    if not (np.isfinite(f_a).all() and np.isfinite(f_b).all() and np.isfinite(f_ab).all()):
        raise ParameterError("sobol_estimate(): the evaluations must be finite (drop rows without a verdict)")
    n, d = f_a.size, f_ab.shape[0]
    if n < 2:
        raise ParameterError(f"sobol_estimate(): needs at least 2 rows; got {n}")
    if not 0 < confidence < 1:
        raise ParameterError(f"sobol_estimate(): confidence must be in (0, 1); got {confidence!r}")
    if n_resamples < 10:
        raise ParameterError(f"sobol_estimate(): n_resamples must be >= 10; got {n_resamples}")
    mean = float(np.mean(np.concatenate([f_a, f_b])))
    var = float(np.var(np.concatenate([f_a, f_b])))
    nan = np.full(d, np.nan)
    if not var > 0:  # a constant output has no variance to apportion
        return SobolEstimate(nan, nan, np.full((d, 2), np.nan), np.full((d, 2), np.nan), n, mean, var)
    if backend == "salib":
        return _salib(f_a, f_b, f_ab, confidence, n_resamples, seed, mean, var)
    # centred by the mean of A and B as scipy does (Sobol' and Levitan 1999); the bootstrap resamples these
    f_a, f_b, f_ab = f_a - mean, f_b - mean, f_ab - mean
    if n & (n - 1) == 0:
        from scipy.stats import sobol_indices

        # the output twice: scipy squeezes its result, and one output of one input became a scalar it then indexes
        two = {"f_A": np.stack([f_a, f_a]), "f_B": np.stack([f_b, f_b]), "f_AB": np.stack([f_ab, f_ab], axis=1)}
        res = sobol_indices(func=two, n=n)
        first = np.asarray(res.first_order, dtype=float).reshape(2, d)[0]
        total = np.asarray(res.total_order, dtype=float).reshape(2, d)[0]
    else:  # rows left out (no verdict): scipy wants a power of two; the same estimators, written out
        first, total = _saltelli_jansen(f_a, f_b, f_ab)
    boot_s, boot_t = _bootstrap(f_a, f_b, f_ab, n_resamples, seed)
    q = 100 * np.array([(1 - confidence) / 2, (1 + confidence) / 2])
    first_ci = np.percentile(boot_s, q, axis=0).T
    total_ci = np.percentile(boot_t, q, axis=0).T
    return SobolEstimate(first, total, first_ci, total_ci, n, mean, var)


def _bootstrap(f_a: np.ndarray, f_b: np.ndarray, f_ab: np.ndarray, n_resamples: int,
               seed: int) -> tuple[np.ndarray, np.ndarray]:
    """The estimators of :func:`_saltelli_jansen` on ``n_resamples`` resamples of the rows (with replacement).

    Every term is a mean over the rows, so a resample is a vector of row counts ``w`` and its means are
    ``w @ terms / n``: one matrix product per batch of resamples instead of gathering ``(d + 2) n`` values each.
    Returns first and total, each ``(n_resamples, d)``.
    """
    d, n = f_ab.shape
    terms = np.column_stack([f_a + f_b, f_a**2 + f_b**2, (f_b * (f_ab - f_a)).T, ((f_a - f_ab) ** 2).T])
    rng = np.random.default_rng(seed)
    batch = max(1, min(n_resamples, 2**24 // n))
    means = []
    for start in range(0, n_resamples, batch):
        k = min(batch, n_resamples - start)
        rows = rng.integers(0, n, (k, n)) + n * np.arange(k)[:, None]
        w = np.bincount(rows.ravel(), minlength=k * n).reshape(k, n).astype(float)
        means.append(w @ terms / n)
    m = np.concatenate(means)
    var = m[:, 1] / 2 - (m[:, 0] / 2) ** 2
    with np.errstate(all="ignore"):
        return m[:, 2:2 + d] / var[:, None], 0.5 * m[:, 2 + d:] / var[:, None]


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
