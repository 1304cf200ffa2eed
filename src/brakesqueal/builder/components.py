"""Compatibility shim: moved to :mod:`brakesqueal.model.components`."""

from ..model.components import *  # noqa: F401,F403
from ..model.components import __all__  # noqa: F401
