r"""One verdict dispatcher: every stability verdict of brakesqueal is decided here.

:func:`decide` takes a model's :class:`~brakesqueal.codegen.engine.Engine`,
a parameter space and :class:`Points` (scattered or a grid) and returns
:class:`Verdicts`: per point a status, a certified verdict, ``max_real``,
frequency, error bound, the mode that carries the verdict (``carrier``) and
the route that decided (``method``).  Maps, sweeps, crossings, critical
speeds, eigen-analysis, the explorer and the nonlinear analyses all call it;
nothing else chooses a route.  One route per module (:data:`ROUTES`, in
order); :func:`register` adds one.
"""

from ._base import (
    DECIDED, STABLE, UNDECIDED, UNSTABLE, Context, Grid, LinearGroup, Points, Result, Route, Verdicts, carrier_labels,
    compact, valid_points,
)
from ._dispatch import MODES, ROUTES, decide, decide_model, point_eigenvalues, register, route_names

__all__ = ["decide", "decide_model", "point_eigenvalues", "register", "route_names", "ROUTES", "MODES", "Points",
           "Grid", "Verdicts", "Route", "Result", "Context", "LinearGroup", "carrier_labels", "valid_points", "compact",
           "STABLE", "UNSTABLE", "UNDECIDED", "DECIDED"]
