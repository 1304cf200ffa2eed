"""Two-parameter squeal regions (issue 28): Hopf curves with l1 along them and codimension-2 points.

* :func:`hopf_curves` (:mod:`.diagram`) — every Hopf curve in a box of two settable parameters, seeded at the
  exact stability crossings, continued by pseudo-arclength (:mod:`.curves`), ``l1`` at each point;
* :func:`region_diagram` — the same with the certified linear stability map, JSON/NetCDF/figure (:class:`RegionResult`);
* :mod:`.auto` — the model as AUTO-07p C user functions and a side-by-side run of AUTO.

Fold-of-cycles curves (issue 28 item 2) are not computed yet: no region is shaded as "squeal possible although
linearly stable".
"""

from __future__ import annotations

from .curves import SPECIAL_TYPES, CurvePoint, HopfCurve, SpecialPoint, continue_hopf_curve, correct_point
from .diagram import FOLD_OF_CYCLES, RegionResult, hopf_curves, region_diagram


__all__ = ["SPECIAL_TYPES", "CurvePoint", "HopfCurve", "SpecialPoint", "continue_hopf_curve", "correct_point",
           "FOLD_OF_CYCLES", "RegionResult", "hopf_curves", "region_diagram"]
