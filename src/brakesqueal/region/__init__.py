"""Two-parameter squeal regions (issue 28): Hopf curves with l1 along them and codimension-2 points.

* :func:`hopf_curves` (:mod:`.diagram`) — every Hopf curve in a box of two settable parameters, seeded at the
  exact stability crossings, continued by pseudo-arclength (:mod:`.curves`), ``l1`` at each point;
* :func:`region_diagram` — the same with the certified linear stability map, JSON/NetCDF/figure (:class:`RegionResult`);
* :func:`fold_curves` (:mod:`.folds`) — the fold-of-cycles curve born at every generalised-Hopf point, by slices
  (one cycle branch per slice, the route of ``brakesqueal cycles``), with the contact loss where it comes first;
  :func:`region_diagram` shades "squeal possible although linearly stable" and "contact lost" from them;
* :mod:`.auto` — the model as AUTO-07p C user functions and a side-by-side run of AUTO.
"""

from __future__ import annotations

from .curves import SPECIAL_TYPES, CurvePoint, HopfCurve, SpecialPoint, continue_hopf_curve, correct_point
from .diagram import FOLD_OF_CYCLES, REGIONS, RegionResult, hopf_curves, region_diagram
from .folds import FOLD_KINDS, FoldCurve, FoldPoint, fold_curves


__all__ = ["SPECIAL_TYPES", "CurvePoint", "HopfCurve", "SpecialPoint", "continue_hopf_curve", "correct_point",
           "FOLD_OF_CYCLES", "REGIONS", "RegionResult", "hopf_curves", "region_diagram",
           "FOLD_KINDS", "FoldCurve", "FoldPoint", "fold_curves"]
