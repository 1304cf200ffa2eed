"""Options shared by every command: ``--model``, ``--preset``, ``--params``, ``--set``, ``--format``.

They mean the same on every command and are resolved once, by
:func:`brakesqueal.model.options.resolve_space` (the function the Python API uses).
"""

from __future__ import annotations

import sys
from enum import Enum
from typing import TYPE_CHECKING, Annotated, Any, Optional

import typer

if TYPE_CHECKING:
    from ..model.parameters import ParameterSpace

__all__ = ["PLOT_SUFFIXES", "number", "NUMBER", "ContactLaw", "ModelOpt", "PresetOpt", "ParamsOpt", "SetOpt",
           "FormatOpt", "OutFormat", "NoCacheOpt", "ProgressOpt", "Modes", "ModesOpt", "space_from", "note",
           "refuse_set_of_axes", "with_equations"]


class OutFormat(str, Enum):
    """Text for people, JSON for scripts."""

    text = "text"
    json = "json"


#: Formats of every command's ``--plot`` figure.
PLOT_SUFFIXES = (".png", ".svg", ".pdf")


class Modes(str, Enum):
    """``--modes``: what a verdict judges (every eigenvalue, or the disk's modes alone)."""

    all = "all"
    disk = "disk"


class ContactLaw(str, Enum):
    """``--contact``: the pads stay pressed (bilateral) or lift off and come back (unilateral)."""

    bilateral = "bilateral"
    unilateral = "unilateral"


ModelOpt = Annotated[Optional[str], typer.Option(
    "--model", help="Built-in model (brakesqueal list models) or a model TOML file.", rich_help_panel="Model")]
PresetOpt = Annotated[Optional[str], typer.Option(
    "--preset", help="Preset of the model (brakesqueal list presets); default: the model's own, or paper-fig2.",
    rich_help_panel="Model")]
ParamsOpt = Annotated[Optional[str], typer.Option(
    "--params", help="Parameter file (TOML: model, preset, [parameters]).", rich_help_panel="Model")]
SetOpt = Annotated[Optional[list[str]], typer.Option(
    "--set", help="NAME=VALUE in SI units, or with a unit: 1200rpm, 5mm, 2kN/mm, 50km/h@0.3m (vehicle speed at "
                  "a wheel radius), echoed in SI (repeatable; 'inf' = rigid; setting a tied name replaces its tie).",
    rich_help_panel="Model")]
FormatOpt = Annotated[OutFormat, typer.Option("--format", help="Output format.")]
NoCacheOpt = Annotated[bool, typer.Option("--no-cache", help="Derive in-process; do not read or write the cache.")]


def number(text: str) -> float:
    """A number option read as typed: ``1e-400`` (underflows to 0) and ``1e400`` (overflows) are refused with
    the text the user wrote (:func:`brakesqueal.inputs.number_problem`), never read as 0.0 or inf.

    Parameters
    ----------
    text : str
        The option's value as typed.

    Returns
    -------
    float
    """
    if isinstance(text, float):
        return text
    from ..inputs import number_problem, shown

    value = str(text).strip()
    problem = number_problem(value)
    if problem:
        raise typer.BadParameter(f"the number {shown(value, 40)[1:-1]} {problem}")
    try:
        return float(value)
    except ValueError:
        raise typer.BadParameter(f"{shown(value, 40)} is not a number") from None


#: Keyword arguments of :func:`typer.Option` for a number read as typed (:func:`number`).
NUMBER: dict[str, Any] = {"parser": number, "metavar": "<float>"}

PadSlopeOpt = Annotated[Optional[float], typer.Option(
    "--pad-slope", **NUMBER,
    help="Keep the massless Coulomb pads' tangential rates, regularised by mu + S v "
         "(S in (0, 0.01] s/m; error O(S), e.g. 1e-4). Default: quasi-static pads.")]
StickSpeedOpt = Annotated[Optional[float], typer.Option(
    "--stick-speed", **NUMBER,
    help="With --pad-slope: regularise stick-slip too, mu v / sqrt(v^2 + V^2) + S v (V in (0, 1] m/s; "
         "a sticking pad creeps at speeds of order V; error O(V), e.g. 1e-3).")]
PadDampingOpt = Annotated[Optional[float], typer.Option(
    "--pad-damping", **NUMBER,
    help="Give every massless pad a tangential damper d_ip beside its spring (N s/m, in (0, 1e6]; "
         "not in the paper): the pads' rates are kept as states, also through lift-off and "
         "re-contact (--contact unilateral). Default: none.")]
ModesOpt = Annotated[Modes, typer.Option(
    "--modes", help="What the verdict judges: every eigenvalue (all, the default), or the disk's modes alone "
                    "(disk: a non-oscillatory mode of a massless pad's own tangential rate is reported, not "
                    "judged).")]
ProgressOpt = Annotated[Optional[bool], typer.Option(
    "--progress/--no-progress", help="Progress on stderr (default: a bar on a terminal, periodic lines otherwise).")]


def with_equations(space: ParameterSpace, command: str) -> ParameterSpace:
    """``space``, or the one-line refusal of a command that needs a model's nonlinear equations (a model given
    by coefficient matrices has none: :func:`~brakesqueal.model.matrices.require_equations`); builds nothing."""
    from ..model.matrices import require_equations

    require_equations(space.model, command)
    return space


def note(message: str) -> None:
    """One informational line on stderr (``brakesqueal: note: ...``)."""
    print(f"brakesqueal: note: {message}", file=sys.stderr)


def pads_option(space: ParameterSpace, pad_slope: float | None, stick_speed: float | None,
                pad_damping: float | None = None) -> ParameterSpace:
    """``space`` with the pads of ``--pad-slope``, ``--stick-speed`` and ``--pad-damping``.

    See :func:`brakesqueal.model.options.regularised_pads` and :func:`~brakesqueal.model.options.damped_pads`.
    """
    from ..errors import ParameterError

    if pad_damping is not None:
        from ..model.options import damped_pads

        space = damped_pads(space, pad_damping)

    if pad_slope is None:
        if stick_speed is not None:
            raise ParameterError("--stick-speed regularises the pads of --pad-slope; give --pad-slope too "
                                 "(e.g. --pad-slope 1e-4 --stick-speed 1e-3)")
        return space
    from ..model.options import regularised_pads

    return regularised_pads(space, pad_slope, stick_speed)


def space_from(model: str | None, preset: str | None, params: str | None, sets: list[str] | None,
               axes: dict[str, str] | None = None) -> ParameterSpace:
    """The :class:`~brakesqueal.model.parameters.ParameterSpace` of the shared options (notes values given
    with units, in SI, and replaced ties).

    A name that an axis of the command varies (``axes``: name -> option, e.g. ``{"mu1": "--x"}``) and that the
    preset ties replaces its tie, as ``--set`` would (with a note): a map over ``mu1`` and ``mu2`` of
    ``paper-fig2`` needs no ``--set``.

    The options are checked first (:func:`brakesqueal.inputs.check_option`: never empty, never longer than
    the limits), so that messages name them as typed (``--preset``), not as the library's arguments."""
    from ..inputs import check_option
    from ..model.options import resolve_space

    check_option(model, "--model")
    check_option(preset, "--preset", name=True)
    check_option(params, "--params")
    from ..model.units import Quantity

    space = resolve_space(model, preset, params, list(sets or []))
    for name, value in space.values.items():
        if isinstance(value, Quantity):
            note(value.echo(name))
    for name in space.untied:
        note(f"--set {name}=... replaces the tie {name} = {space.preset.tied[name]} of preset '{space.label}'")
    tied = [n for n in (axes or {}) if n in space.tied]
    if tied:
        current = space.resolve()
        for name in tied:
            note(f"the {(axes or {})[name]} axis replaces the tie {name} = {space.tied[name]} of preset "
                 f"'{space.label}'")
        space = space.with_values({n: float(current[n]) for n in tied})
    return space


def refuse_set_of_axes(sets: list[str] | None, axes: dict[str, str]) -> None:
    """Refuse ``--set NAME=...`` of a name that an axis or path of the command varies (it would be ignored).

    Parameters
    ----------
    sets : list of str or None
        The ``--set`` arguments (``NAME=VALUE``).
    axes : dict
        The varied names and the option that varies each (e.g. ``{"mu": "--along"}``).

    Raises
    ------
    ParameterError
        If a ``--set`` names one of ``axes``.
    """
    from ..errors import ParameterError

    for item in sets or []:
        name = item.partition("=")[0].strip()
        if name in axes:
            raise ParameterError(f"--set {name} is also the {axes[name]} axis; leave it out of --set (the axis "
                                 f"gives its values)", parameter=name)
