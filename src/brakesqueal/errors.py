"""Exception and warning types of brakesqueal.

Every error a user can trigger with bad input is a :class:`BrakesquealError`
whose message is one line naming the offending parameter, its value and what
is allowed.  The command line prints that line and exits with status 2.
"""

from __future__ import annotations

__all__ = [
    "BrakesquealError",
    "ParameterError",
    "SilentMotionError",
    "BrakesquealWarning",
]


class BrakesquealError(Exception):
    """Base class of all errors raised deliberately by brakesqueal."""


class ParameterError(BrakesquealError, ValueError):
    """A model parameter, preset or option has a missing, unknown or invalid value."""


class SilentMotionError(BrakesquealError):
    """The silent motion (eq. 46) cannot be found, or a pad loses contact there."""


class BrakesquealWarning(UserWarning):
    """Warnings issued by brakesqueal (turned into errors in the test suite)."""
