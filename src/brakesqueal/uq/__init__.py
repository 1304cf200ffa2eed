"""Squeal as a probability (issue 27): distributions of study inputs, Sobol' indices, P(squeal).

* :class:`Distribution` / :func:`parse_distribution` / :func:`check_support` — the ``[distributions]`` table
  of a study file (uniform, normal, truncnormal, lognormal, beta), checked against the parameters' allowed
  ranges (read by :func:`brakesqueal.sweep.load_study`);
* :func:`saltelli_design` — the unit-cube Saltelli design from a scrambled, seeded Sobol' sequence;
* :func:`sobol_estimate` — first/total indices of precomputed evaluations (scipy or SALib) with bootstrap
  intervals; :func:`probability_interval` — a probability with its Wilson interval;
* :func:`run_uq` — the whole study (``brakesqueal uq``): design, evaluation through the sweep machinery (in
  memory or a resumable Zarr store on Dask), indices of max Re λ, the squeal indicator and the frequency, and
  P(squeal), as an :class:`xarray.Dataset` (``per_mode=True``: also Re λ and the frequency of every tracked mode,
  modes numbered by ascending frequency); :func:`uq_summary` its JSON form; :func:`plot_uq` its figure;
* :func:`fit_pce` — a polynomial chaos surrogate (:class:`PCESurrogate`: inputs standardised by their
  distributions, least squares or sparse, leave-one-out error, Sobol' indices from the coefficients, P(squeal)
  by sampling it); :func:`fit_study_pce` the same for a study's quantity from a few hundred runs
  (:func:`pce_design`).

See ``docs/uq.md``.
"""

from __future__ import annotations

from ._design import saltelli_design
from ._distributions import KINDS, Distribution, check_support, parse_distribution
from ._indices import BACKENDS, SobolEstimate, probability_interval, sobol_estimate
from ._plot import plot_uq
from ._run import UQ_QUANTITIES, UQRun, run_uq, uq_summary
from ._surrogate import PCESurrogate, fit_pce, pce_basis_size
from ._surrogate_study import SURROGATE_QUANTITIES, StudySurrogate, fit_study_pce, pce_design

__all__ = ["KINDS", "Distribution", "check_support", "parse_distribution", "saltelli_design", "sobol_estimate",
           "probability_interval", "SobolEstimate", "run_uq", "UQRun", "uq_summary", "UQ_QUANTITIES", "plot_uq",
           "BACKENDS", "PCESurrogate", "fit_pce", "pce_basis_size", "StudySurrogate", "fit_study_pce", "pce_design",
           "SURROGATE_QUANTITIES"]
