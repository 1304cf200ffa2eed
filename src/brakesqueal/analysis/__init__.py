"""Analysis layer: silent motion, linear models, eigen-analysis, stability maps, crossings, critical speeds."""

from .equilibrium import SilentMotion, silent_motion
from .linear import LinearModel, linearize, pad_rate_eigenvalues
from .stability import (
    Axis,
    EigenAnalysis,
    ParameterSpace,
    PointVerdict,
    Points,
    Verdict,
    critical_speeds,
    critical_speeds_many,
    crossings,
    eigen_analysis,
    evaluate,
    evaluate_point,
    stability_map,
)

__all__ = [
    "SilentMotion",
    "silent_motion",
    "LinearModel",
    "linearize",
    "pad_rate_eigenvalues",
    "Axis",
    "EigenAnalysis",
    "ParameterSpace",
    "PointVerdict",
    "Points",
    "Verdict",
    "critical_speeds",
    "critical_speeds_many",
    "crossings",
    "eigen_analysis",
    "evaluate",
    "evaluate_point",
    "stability_map",
]
