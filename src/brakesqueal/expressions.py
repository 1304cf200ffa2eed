"""Compatibility shim: the expression grammar lives in :mod:`brakesqueal.model.expressions`."""

from .model.expressions import *  # noqa: F401,F403
from .model.expressions import __all__  # noqa: F401
