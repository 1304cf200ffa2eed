"""Compatibility shim: moved to :mod:`brakesqueal.model.io`."""

from ..model.io import *  # noqa: F401,F403
from ..model.io import __all__  # noqa: F401
