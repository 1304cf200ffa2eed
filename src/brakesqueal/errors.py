"""Exception and warning types of brakesqueal.

Every error a user can trigger with bad input is a :class:`BrakesquealError`
whose message is one line naming the offending parameter, its value and what
is allowed.  The command line prints that line and exits with status 2.
Failures of the silent-motion solver are typed (never recognised by their
text): :class:`NoSilentMotionError` (non-existence established),
:class:`ContactLossError`, :class:`NoSlidingError` (the silent motion exists
but leaves the model's validity range) and :class:`SolverFailedError` (the
solver gave up; nothing is established).
"""

from __future__ import annotations

__all__ = [
    "BrakesquealError",
    "ParameterError",
    "SilentMotionError",
    "NoSilentMotionError",
    "ContactLossError",
    "NoSlidingError",
    "SolverFailedError",
    "OutputError",
    "BrakesquealWarning",
]


class BrakesquealError(Exception):
    """Base class of all errors raised deliberately by brakesqueal."""


class ParameterError(BrakesquealError, ValueError):
    """A model parameter, preset or option has a missing, unknown or invalid value."""


class SilentMotionError(BrakesquealError):
    """The silent motion (eq. 46) cannot be used: base class of the four cases below."""


class NoSilentMotionError(SilentMotionError):
    """It is established that no silent motion exists on the branch connected to the trivial one."""


class ContactLossError(SilentMotionError):
    """A silent motion exists but a pad's normal force is not positive there (the pad lifts off)."""


class NoSlidingError(SilentMotionError):
    """A silent motion exists but a pad does not slide there (``|v_r| = 0``)."""


class SolverFailedError(SilentMotionError):
    """The silent-motion solver failed without establishing whether a silent motion exists."""


class OutputError(BrakesquealError):
    """An output file cannot be written (path, permissions, full disk)."""


class BrakesquealWarning(UserWarning):
    """Warnings issued by brakesqueal (turned into errors in the test suite)."""
