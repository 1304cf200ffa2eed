r"""Robust design (issue 27, item 5): choose design variables that minimise P(squeal) or maximise the certified
stability margin.

* :func:`robust_design` — a seeded global search (:func:`scipy.optimize.differential_evolution`) over the bounds of
  chosen settable parameters (pad stiffnesses, dampers, friction asymmetry at a fixed sum through a tie, ...) of
  either the probability of squeal over common seeded draws of the uncertain parameters (the certified verdicts
  of the one evaluator, as ``brakesqueal uq``) or the certified scale of the uncertainty box (the branch and bound
  of :mod:`brakesqueal.robust`); the result (:class:`DesignResult`) reports the optimum, P(squeal) at the
  baseline and the optimum with Wilson intervals, and the certified decision of the whole uncertainty box at both;
* :func:`squeal_counts`, :func:`certified_scales` — the two objectives, vectorised over candidate designs;
* :func:`stable_windows` — certified-stable intervals of one variable (e.g. ``k_ip`` at ``mu = 0.5``: between the
  paper's points B and A), at the nominal parameters or over a box of them;
* :func:`run_design` / :func:`load_design` — the same from a study file with a ``[design]`` table
  (``brakesqueal design``).

See ``docs/design.md``.
"""

from __future__ import annotations

from ._api import OBJECTIVES, DesignResult, draw_samples, robust_design, uncertainty_box
from ._objectives import SampleCounts, certified_scales, squeal_counts
from ._study import DESIGN_KEYS, DesignStudy, load_design, run_design
from ._windows import stable_windows

__all__ = ["OBJECTIVES", "DesignResult", "robust_design", "draw_samples", "uncertainty_box", "stable_windows",
           "DESIGN_KEYS", "DesignStudy", "load_design", "run_design", "SampleCounts", "squeal_counts",
           "certified_scales"]
