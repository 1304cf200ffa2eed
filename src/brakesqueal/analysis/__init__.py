"""Analysis layer: silent motion, linear models and (later) stability analysis."""

from .equilibrium import SilentMotion, silent_motion
from .linear import LinearModel, linearize, pad_rate_eigenvalues

__all__ = ["SilentMotion", "silent_motion", "LinearModel", "linearize", "pad_rate_eigenvalues"]
