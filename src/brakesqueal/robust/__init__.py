r"""Certified robust design windows (issue 27, item 4): is every point of a parameter box stable?

``robust_box(engine, space, {"mu": (0.35, 0.55), "k_ip": (2e5, 2e6)})`` answers
*stable for every point of the box*, *unstable somewhere* (with a witness
point that the verdict dispatcher certifies unstable) or *undecided in these
sub-boxes*, by branch and bound on the exact characteristic quartic of the
trivial silent motion — never by sampling:

* the quartic's coefficients ``a_i = N_i / Den`` and the Hurwitz determinant
  ``H3`` are exact polynomials in the box's names (ties applied, computed
  once with SymPy and kept in the on-disk cache: :mod:`._table`);
* over each sub-box they are enclosed rigorously by the Taylor (centred) form
  about its centre, rounding errors bounded (:mod:`._enclose`, vectorised
  over many boxes);
* a sub-box is stable when the Liénard–Chipart signs (one sign of ``Den``
  and of every ``N_i``, ``s H3 > 0``) hold over all of it; its centre is a
  witness when a sign is certified wrong there; anything else is bisected
  across its widest dimension until a budget is spent (:mod:`._bnb`).

:func:`decide_boxes` decides many boxes at once; :func:`stable_margins` gives
per-parameter certified-stable windows and the largest stable box around a
nominal design; :func:`worst_case` a certified upper bound of ``max Re λ``
over a box (the same branch and bound on the shifted quartic ``p(λ + σ)``,
bisecting on ``σ``) with the largest value found at a point.  Models without a closed form (more than two coordinates)
and boxes where the silent motion is not the zero state throughout are
refused with a one-line error.
"""

from __future__ import annotations

from ._api import (METHOD, BoxVerdicts, Margins, RobustResult, WorstCase, decide_boxes, parse_box, robust_box,
                   stable_margins, worst_case)

__all__ = ["METHOD", "RobustResult", "BoxVerdicts", "Margins", "WorstCase", "parse_box", "robust_box",
           "decide_boxes", "stable_margins", "worst_case"]
