"""Units on input: a number with a unit suffix (``1200rpm``, ``5 mm``, ``50km/h@0.3m``), converted to SI.

One small table (no unit library: importing ``pint`` alone takes ~0.45 s, twice the warm start-up of a
command).  Each SI unit that a model declares for a parameter (:meth:`~.components.ModelSpec.unit`,
:meth:`~.parameters.Preset.unit`) has a few physically unambiguous alternatives; a value is typed as a
plain number or a constant expression followed by one of them, with or without a space
(``1200rpm``, ``1200 rpm``, ``16*pi rpm``, ``(16*pi)rpm``).  An angular speed may also be given as a
vehicle speed at a wheel radius, ``SPEED@RADIUS`` (``50km/h@0.3m``: ``Omega = v/r``).

:func:`parse_quantity` reads the text (no model needed) and gives a :class:`Quantity`, a ``float`` in SI
that remembers what was typed; :func:`check_quantity` refuses it, in one line, for a parameter of another
unit.  :func:`brakesqueal.model.parameters.parse_sets` (``--set``) and the parameter spaces use them.
"""

from __future__ import annotations

import math
import re
from typing import NamedTuple

from ..errors import ParameterError

__all__ = ["Quantity", "UnitGroup", "UNIT_GROUPS", "parse_quantity", "check_quantity", "accepted_units"]


class UnitGroup(NamedTuple):
    """The accepted units of one SI unit.

    Attributes
    ----------
    si : str
        The SI unit as the models spell it (``"rad/s"``, ``"N s/m"``).
    kind : str
        What it measures, for messages (``"an angular speed"``).
    units : dict
        ``{suffix: (numerator, denominator, pi)}``: ``1 suffix = numerator/denominator * pi**pi`` SI units.
    """

    si: str
    kind: str
    units: dict[str, tuple[int, int, int]]


#: The table: each SI unit with its accepted alternatives (exact rational factors, times pi for angles).
UNIT_GROUPS: tuple[UnitGroup, ...] = (
    UnitGroup("rad/s", "an angular speed", {"rad/s": (1, 1, 0), "rpm": (1, 30, 1), "rev/s": (2, 1, 1),
                                            "Hz": (2, 1, 1), "deg/s": (1, 180, 1)}),
    UnitGroup("rad", "an angle", {"rad": (1, 1, 0), "deg": (1, 180, 1)}),
    UnitGroup("m", "a length", {"m": (1, 1, 0), "mm": (1, 1000, 0), "cm": (1, 100, 0), "km": (1000, 1, 0)}),
    UnitGroup("m/s", "a speed", {"m/s": (1, 1, 0), "mm/s": (1, 1000, 0), "km/h": (5, 18, 0)}),
    UnitGroup("s", "a time", {"s": (1, 1, 0), "ms": (1, 1000, 0)}),
    UnitGroup("kg", "a mass", {"kg": (1, 1, 0), "g": (1, 1000, 0), "t": (1000, 1, 0)}),
    UnitGroup("N", "a force", {"N": (1, 1, 0), "kN": (1000, 1, 0)}),
    UnitGroup("N/m", "a stiffness", {"N/m": (1, 1, 0), "N/mm": (1000, 1, 0), "kN/m": (1000, 1, 0),
                                     "kN/mm": (10**6, 1, 0), "MN/m": (10**6, 1, 0)}),
    UnitGroup("N s/m", "a damping", {"N s/m": (1, 1, 0), "N*s/m": (1, 1, 0), "kN s/m": (1000, 1, 0),
                                     "kN*s/m": (1000, 1, 0)}),
    UnitGroup("kg m^2", "a moment of inertia", {"kg m^2": (1, 1, 0), "kg*m^2": (1, 1, 0),
                                                "kg cm^2": (1, 10**4, 0), "kg*cm^2": (1, 10**4, 0),
                                                "kg mm^2": (1, 10**6, 0), "kg*mm^2": (1, 10**6, 0)}),
    UnitGroup("N m/rad", "a torsional stiffness", {"N m/rad": (1, 1, 0), "N*m/rad": (1, 1, 0)}),
    UnitGroup("N m s/rad", "a torsional damping", {"N m s/rad": (1, 1, 0), "N*m*s/rad": (1, 1, 0)}),
)

_GROUP_OF: dict[str, UnitGroup] = {u: g for g in UNIT_GROUPS for u in g.units}
_BY_SI: dict[str, UnitGroup] = {g.si: g for g in UNIT_GROUPS}
# longest first, so that "kN/mm" is tried before "mm" and "m"
_SUFFIXES = sorted(_GROUP_OF, key=len, reverse=True)
# a decimal literal that is not the tail of a name (``k1`` is a name, not ``k`` and 1)
# (compiled on first use, by re's cache: no cost at start-up)
_LITERAL = r"(?<![A-Za-z0-9_.])(?:\d[\d_]*\.?[\d_]*|\.\d[\d_]*)(?:[eE][+-]?\d+)?$"
_SPEED_AT_RADIUS = "vehicle speed at a wheel radius, e.g. 50km/h@0.3m"


class Quantity(float):
    """A value given with a unit: a ``float`` in SI that remembers what was typed.

    Attributes
    ----------
    text : str
        The value as typed (``"1200rpm"``).
    si : str
        Its SI unit (``"rad/s"``).
    shown : str
        The value as typed, spelled out for the echo (``"1200 rpm"``, ``"50 km/h at a wheel radius of 0.3 m"``).
    where : str
        How messages name it (``"--set Omega=1200rpm"``).
    unit : str
        The unit typed (``"rpm"``; ``""`` for a vehicle speed at a wheel radius).
    """

    text: str
    si: str
    shown: str
    where: str
    unit: str

    def __new__(cls, value: float, text: str, si: str, shown: str, where: str = "", unit: str = "") -> Quantity:
        q = super().__new__(cls, value)
        q.text, q.si, q.shown, q.where, q.unit = text, si, shown, where or text, unit
        return q

    def __reduce__(self) -> tuple[object, ...]:
        return (Quantity, (float(self), self.text, self.si, self.shown, self.where, self.unit))

    def echo(self, name: str) -> str:
        """``"Omega = 1200 rpm = 125.66370614359172 rad/s"``."""
        v = float(self)
        number = str(int(v)) if math.isfinite(v) and v.is_integer() and abs(v) < 1e16 else repr(v)
        return f"{name} = {self.shown} = {number} {self.si}"


def accepted_units(si: str) -> tuple[str, ...]:
    """The units accepted for a parameter whose SI unit is ``si`` (``()`` if none but plain numbers)."""
    group = _BY_SI.get(si)
    return tuple(u for u in group.units if u != si) + (si,) if group else ()


def _split(text: str) -> tuple[str, str] | None:
    """``(body, unit)`` of ``"<number or expression><unit>"``, or ``None`` (no unit suffix)."""
    for unit in _SUFFIXES:
        if not text.endswith(unit):
            continue
        body = text[:-len(unit)]
        stripped = body.rstrip()
        if not stripped:
            continue
        if stripped != body or stripped.endswith(")") or re.search(_LITERAL, stripped):
            return stripped, unit
    return None


def _magnitude(body: str, what: str) -> float:
    from ..inputs import number_problem
    from .expressions import evaluate

    problem = number_problem(body)
    if problem:
        raise ParameterError(f"{what}: the number {problem}")
    try:
        return float(body)
    except ValueError:
        pass
    value = evaluate(body, {}, what=what)
    if math.isnan(value):
        raise ParameterError(f"{what}: not a number")
    return value


def _convert(body: str, unit: str, what: str) -> float:
    num, den, pi = _GROUP_OF[unit].units[unit]
    value = _magnitude(body, what) * num / den
    return value * math.pi if pi else value


def parse_quantity(text: str, where: str = "") -> Quantity | None:
    """A number with a unit suffix, in SI; ``None`` if ``text`` has no unit suffix of the table.

    Parameters
    ----------
    text : str
        ``"1200rpm"``, ``"1200 rpm"``, ``"16*pi rpm"``, ``"(16*pi)rpm"``, ``"5 mm"``, or a vehicle speed at
        a wheel radius, ``"50km/h@0.3m"`` (an angular speed ``v/r``).
    where : str, optional
        How messages name the value (e.g. ``"--set Omega=1200rpm"``; default: the text).

    Returns
    -------
    Quantity or None

    Raises
    ------
    ParameterError
        A number that a double cannot hold as typed (``1e400rpm``), an expression that cannot be
        evaluated, a ``SPEED@RADIUS`` whose parts are not a speed and a length, or a radius that is not
        positive and finite.
    """
    t = str(text).strip()
    what = where or t
    if "@" in t:
        speed_text, _, radius_text = (s.strip() for s in t.partition("@"))
        speed, radius = _split(speed_text), _split(radius_text)
        if (speed is None or radius is None or _GROUP_OF[speed[1]].si != "m/s"
                or _GROUP_OF[radius[1]].si != "m"):
            raise ParameterError(f"{what}: expected SPEED@RADIUS, a {_SPEED_AT_RADIUS} (speeds: "
                                 f"{', '.join(accepted_units('m/s'))}; radii: {', '.join(accepted_units('m'))})")
        v, r = _convert(*speed, what), _convert(*radius, what)
        if not (math.isfinite(r) and r > 0):
            raise ParameterError(f"{what}: the wheel radius must be positive and finite; got {r!r} m")
        shown = f"{speed[0]} {speed[1]} at a wheel radius of {radius[0]} {radius[1]}"
        return Quantity(v / r, t, "rad/s", shown, what)
    split = _split(t)
    if split is None:
        return None
    body, unit = split
    return Quantity(_convert(body, unit, what), t, _GROUP_OF[unit].si, f"{body} {unit}", what, unit)


def check_quantity(name: str, value: object, si: str) -> None:
    """Refuse, in one line, a :class:`Quantity` whose unit is not that of parameter ``name`` (SI unit ``si``).

    Parameters
    ----------
    name : str
        The parameter.
    value : object
        Its value (anything but a Quantity passes).
    si : str
        The parameter's SI unit (``""``: dimensionless).

    Raises
    ------
    ParameterError
        ``"--set Omega=3mm: mm is a length, Omega is in rad/s (accepted: rpm, rev/s, Hz, deg/s, rad/s)"``.
    """
    if not isinstance(value, Quantity) or value.si == si:
        return
    given = (f"{value.unit} is {_GROUP_OF[value.unit].kind}" if value.unit in _GROUP_OF
             else "a vehicle speed at a wheel radius is an angular speed")
    if not si:
        raise ParameterError(f"{value.where}: {given}, {name} is dimensionless (give a plain number)",
                             parameter=name)
    accepted = accepted_units(si)
    if si == "rad/s":
        hint = f" (accepted: {', '.join(accepted)}; or a {_SPEED_AT_RADIUS})"
    elif accepted:
        hint = f" (accepted: {', '.join(accepted)})"
    else:
        hint = f" (give a plain number in {si})"
    raise ParameterError(f"{value.where}: {given}, {name} is in {si}{hint}", parameter=name)
