"""Compatibility shim: moved to :mod:`brakesqueal.model.library`."""

from ..model.library import *  # noqa: F401,F403
from ..model.library import __all__  # noqa: F401
