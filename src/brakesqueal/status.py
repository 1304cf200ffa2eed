"""Point and run statuses shared by maps, sweeps, crossings and the simulation.

Codes are small integers stored in files (``int8``); their meanings are the
``flag_meanings`` attribute of stored arrays.  Decisions are taken on these
codes, never on message text.
"""

from __future__ import annotations

from enum import Enum, IntEnum

__all__ = ["PointStatus", "RunStatus", "STATUS_MEANINGS", "status_of_error", "DECIDED", "verdict_counts_text",
           "TRIVIAL_NOISE_FLOOR"]

#: The one rule of a trivial silent motion, for every command: a zero-state residual is zero "to rounding" when
#: ``|F_i| <= TRIVIAL_NOISE_FLOOR eps S_i`` (``S_i`` the magnitude of the terms that cancel in it); at one point
#: :func:`brakesqueal.analysis.equilibrium.is_trivial`, along a path or a map's axes its symbolic analogue
#: (:func:`brakesqueal.symbolic.stability_forms.quartic_numerators`, per monomial of the path's variables).
TRIVIAL_NOISE_FLOOR = 64.0


class PointStatus(IntEnum):
    """Status of one parameter point of a map or a sweep.

    ``OK`` and ``OK_NONTRIVIAL`` carry a decided verdict (``stable`` and
    ``max_real`` agree); every other status is never marked stable.
    """

    OK = 0                   #: trivial silent motion, verdict decided
    OK_NONTRIVIAL = 1        #: non-trivial silent motion, verdict decided
    NO_SILENT_MOTION = 2     #: established: no silent motion on the branch from the trivial one
    CONTACT_LOSS = 3         #: a pad's normal force is not positive at the silent motion
    INVALID = 4              #: parameters outside their allowed ranges
    UNDECIDED = 5            #: |max Re λ| within the error bound of the computation
    SOLVER_FAILED = 6        #: the silent-motion solver failed (nothing established)
    NO_SLIDING = 7           #: a pad does not slide at the silent motion
    NOT_COMPUTED = 8         #: not computed (e.g. a sweep chunk still missing)

    @property
    def meaning(self) -> str:
        """Snake-case meaning (``"no_silent_motion"``)."""
        return _MEANINGS[self]


class RunStatus(str, Enum):
    """How a simulation run ended (:attr:`brakesqueal.simulation.Trajectory.status`).

    A ``str`` enum: it compares equal to its value (``status == "finished"``), is written as that string in
    JSON and NetCDF attributes, and is decided by the integrator's return code, never by message text.
    """

    FINISHED = "finished"                  #: reached the end time
    CONTACT_LOSS = "contact-loss"          #: stopped at a pad's contact loss (``events="stop"``)
    SLIDING_REVERSAL = "sliding-reversal"  #: stopped at a pad's sliding reversal (``events="stop"``)
    FAILED = "failed"                      #: the integration failed (the message says why)

    def __str__(self) -> str:
        return str(self.value)


_MEANINGS = {
    PointStatus.OK: "ok",
    PointStatus.OK_NONTRIVIAL: "ok_nontrivial_silent_motion",
    PointStatus.NO_SILENT_MOTION: "no_silent_motion",
    PointStatus.CONTACT_LOSS: "pad_loses_contact",
    PointStatus.INVALID: "invalid_parameters",
    PointStatus.UNDECIDED: "undecided",
    PointStatus.SOLVER_FAILED: "solver_failed",
    PointStatus.NO_SLIDING: "pad_does_not_slide",
    PointStatus.NOT_COMPUTED: "not_computed",
}

#: ``flag_meanings`` of stored status arrays (space-separated, in code order).
STATUS_MEANINGS = " ".join(_MEANINGS[s] for s in PointStatus)


def status_of_error(exc: BaseException) -> PointStatus:
    """The status of a point whose silent motion raised ``exc`` (by type, never by message)."""
    from .errors import (
        ContactLossError, NoSilentMotionError, NoSlidingError, ParameterError, SolverFailedError,
    )

    if isinstance(exc, ContactLossError):
        return PointStatus.CONTACT_LOSS
    if isinstance(exc, NoSlidingError):
        return PointStatus.NO_SLIDING
    if isinstance(exc, NoSilentMotionError):
        return PointStatus.NO_SILENT_MOTION
    if isinstance(exc, SolverFailedError):
        return PointStatus.SOLVER_FAILED
    if isinstance(exc, ParameterError):
        return PointStatus.INVALID
    raise TypeError(f"not a point failure: {exc!r}")


#: The statuses whose points carry a verdict (stable or unstable).
DECIDED = (PointStatus.OK, PointStatus.OK_NONTRIVIAL)


def verdict_counts_text(points: int, stable: int, unstable: int, status_counts: dict[str, int]) -> str:
    """One line about the verdicts of a map or sweep: stable and unstable points, and those without a verdict.

    The percentages are of the points with a verdict; the points without one are counted by status, so
    that a grid of undecided or invalid points never reads as "0% stable".

    Parameters
    ----------
    points : int
        Number of points.
    stable, unstable : int
        Points with the verdict stable / unstable.
    status_counts : dict of str to int
        Points per status meaning (:attr:`PointStatus.meaning`).

    Returns
    -------
    str
        E.g. ``"25 points: 5 stable, 15 unstable (25.0% / 75.0% of the 20 with a verdict); 5 without a
        verdict (invalid_parameters 5)"``.
    """
    decided = stable + unstable
    text = f"{points} points: {stable} stable, {unstable} unstable"
    if decided:
        text += f" ({100 * stable / decided:.1f}% / {100 * unstable / decided:.1f}% of the {decided} with a verdict)"
    if points > decided:
        ok = {s.meaning for s in DECIDED}
        parts = ", ".join(f"{k} {v}" for k, v in status_counts.items() if k not in ok and v)
        text += f"; {points - decided} without a verdict ({parts})"
    return text
