"""The on-disk code cache (transitional re-export of :mod:`brakesqueal.numeric.cache`)."""

from ..numeric.cache import *  # noqa: F401,F403
from ..numeric.cache import __all__  # noqa: F401
