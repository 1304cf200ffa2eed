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
    """A model parameter, preset or option has a missing, unknown or invalid value.

    Parameters
    ----------
    message : str
        One line naming the offending parameter, its value and what is allowed.
    parameter : str, optional
        The name the error is about (a parameter, a tied or auxiliary name),
        when there is one; callers map errors to their own keys with it,
        never by the message text.
    names : tuple of str, optional
        Every name involved, ``parameter`` first: the other violated
        parameters, the inputs of a tie that cannot be evaluated, or the
        names of a cycle of ties in their order.

    Attributes
    ----------
    parameter : str or None
    names : tuple of str
    """

    def __init__(self, message: str = "", *, parameter: str | None = None, names: tuple[str, ...] = ()) -> None:
        super().__init__(message)
        self.parameter = parameter
        self.names = tuple(dict.fromkeys(((parameter,) if parameter else ()) + tuple(names)))

    def about(self, parameter: str, names: tuple[str, ...] = ()) -> ParameterError:
        """Name the parameter of an error raised without one (e.g. by the expression evaluator); returns self."""
        if self.parameter is None:
            self.parameter = parameter
        self.names = tuple(dict.fromkeys((self.parameter, *self.names, parameter, *names)))
        return self


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
