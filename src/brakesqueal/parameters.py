"""Named, validated parameter sets of the wobbling-disk model, presets, TOML in/out.

Every model quantity comes from a complete parameter set or from a named
:class:`Preset` of the paper; there are no silent defaults.  Names follow the
paper (Sec. 2, Fig. 1); all values are SI (see :data:`UNITS`,
:data:`DESCRIPTIONS`).  ``k_ip1 = k_ip2 = inf`` means rigid tangential
supports, the minimal model of the paper's ref. [6].

Every invalid value raises :class:`~brakesqueal.errors.ParameterError` with
one line such as ``The parameter 'mu1' must be in [0, inf); got -0.2``.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from brakesqueal.errors import ParameterError
from brakesqueal.expressions import RESERVED_NAMES, dependency_order, evaluate, names_in

__all__ = [
    "DESCRIPTIONS", "PARAMETER_NAMES", "PRESETS", "UNITS", "Parameters", "Preset",
    "get_preset", "load_parameters", "parameters_from_toml", "parameters_to_toml",
    "parse_assignment", "resolve_parameters",
]

Value = float | str  # a number or an expression string such as "16*pi"

_INF = math.inf
_OMEGA_NOTE = "reverse rotation is not modelled; mirror the model instead"

# name, unit ("" = dimensionless), description, (low, high, low_open, high_open)
_TABLE: tuple[tuple[str, str, str, tuple[float, float, bool, bool]], ...] = (
    ("Theta", "kg m^2", "disk moment of inertia about a diameter", (0, _INF, True, True)),
    ("Phi", "kg m^2", "disk moment of inertia about its axis", (0, _INF, True, True)),
    ("k_t", "N m/rad", "stiffness of the disk's rotational supports", (0, _INF, False, True)),
    ("d_t", "N m s/rad", "damping of the disk's rotational supports", (0, _INF, False, True)),
    ("k1", "N/m", "normal support stiffness of the upper pad", (0, _INF, False, True)),
    ("k2", "N/m", "normal support stiffness of the lower pad", (0, _INF, False, True)),
    ("d1", "N s/m", "normal support damping of the upper pad", (0, _INF, False, True)),
    ("d2", "N s/m", "normal support damping of the lower pad", (0, _INF, False, True)),
    ("k_ip1", "N/m", "tangential support stiffness of the upper pad (inf = rigid)",
     (0, _INF, True, False)),
    ("k_ip2", "N/m", "tangential support stiffness of the lower pad (inf = rigid)",
     (0, _INF, True, False)),
    ("mu1", "", "kinetic friction coefficient at the upper contact", (0, _INF, False, True)),
    ("mu2", "", "kinetic friction coefficient at the lower contact", (0, _INF, False, True)),
    ("h10", "m", "distance from O to the upper disk surface", (-_INF, _INF, True, True)),
    ("h20", "m", "distance from O to the lower disk surface", (-_INF, _INF, True, True)),
    ("r", "m", "effective braking radius", (0, _INF, True, True)),
    ("N0", "N", "preload of the pads' normal supports", (0, _INF, True, True)),
    ("Omega", "rad/s", "spin rate of the disk", (0, _INF, True, True)),
)

#: The 17 model parameters in their canonical order.
PARAMETER_NAMES: tuple[str, ...] = tuple(row[0] for row in _TABLE)
#: SI unit of every model parameter ("" = dimensionless).
UNITS: Mapping[str, str] = MappingProxyType({row[0]: row[1] for row in _TABLE})
#: One-line description of every model parameter.
DESCRIPTIONS: Mapping[str, str] = MappingProxyType({row[0]: row[2] for row in _TABLE})
_BOUNDS = MappingProxyType({row[0]: row[3] for row in _TABLE})
_NOTES = MappingProxyType({"Omega": _OMEGA_NOTE})
_TRIVIAL_RTOL = 1e-12


def _fmt(value: float) -> str:
    """Format a number compactly: ``0``, ``inf``, ``-0.2``, ``100000000``."""
    value = float(value)
    if math.isfinite(value) and value.is_integer() and abs(value) < 1e16:
        return str(int(value))
    return repr(float(value))


def _is_real(value: object) -> bool:
    """Return whether ``value`` is a real number (``bool`` excluded)."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _interval(name: str) -> str:
    """Return the allowed interval of a parameter, e.g. ``[0, inf)``."""
    low, high, low_open, high_open = _BOUNDS[name]
    return f"{'(' if low_open else '['}{_fmt(low)}, {_fmt(high)}{')' if high_open else ']'}"


def _in_bounds(name: str, value: float) -> bool:
    """Return whether ``value`` (possibly NaN) lies in the interval of ``name``."""
    low, high, low_open, high_open = _BOUNDS[name]
    above = value > low if low_open else value >= low
    below = value < high if high_open else value <= high
    return above and below


def _bound_message(name: str, value: object) -> str | None:
    """Return the violation message for one parameter value, or None if valid."""
    if not _is_real(value):
        return (f"The parameter '{name}' must be a real number; "
                f"got {value!r} ({type(value).__name__})")
    number = float(value)  # type: ignore[arg-type]
    if _in_bounds(name, number):
        return None
    unit = f" {UNITS[name]}" if UNITS[name] else ""
    note = f" ({_NOTES[name]})" if name in _NOTES else ""
    return f"The parameter '{name}' must be in {_interval(name)}{unit}{note}; got {number!r}"


def _problems(values: Mapping[str, object]) -> list[tuple[str, str]]:
    """Return ``(name, message)`` for every violated bound, joint ones included."""
    problems = [(name, msg) for name in PARAMETER_NAMES
                if (msg := _bound_message(name, values[name])) is not None]
    if not any(name in ("h10", "h20") for name, _ in problems):
        h10, h20 = float(values["h10"]), float(values["h20"])  # type: ignore[arg-type]
        if not h10 + h20 > 0.0:
            problems.append(("h10", (
                "The parameters 'h10' and 'h20' must satisfy h10 + h20 > 0 (disk "
                f"thickness, eq. 58); got h10 = {h10!r}, h20 = {h20!r}")))
    return problems


@dataclass(frozen=True, kw_only=True)
class Parameters:
    """A complete, validated parameter set of the wobbling-disk model (SI units).

    Attributes
    ----------
    Theta, Phi : float
        Disk inertia about a diameter and about the axis [kg m^2], both > 0.
    k_t, d_t : float
        Rotational support stiffness [N m/rad] and damping [N m s/rad], >= 0.
    k1, k2, d1, d2 : float
        Normal support stiffnesses [N/m] and dampings [N s/m] of the upper
        (1) and lower (2) pad, >= 0.
    k_ip1, k_ip2 : float
        Tangential pad support stiffnesses [N/m] in (0, inf]; ``inf`` = rigid.
    mu1, mu2 : float
        Kinetic friction coefficients at the upper and lower contact, >= 0.
    h10, h20 : float
        Distances from O to the upper and lower disk surface [m], finite,
        with ``h10 + h20 > 0`` (eq. 58).
    r, N0, Omega : float
        Effective braking radius [m], preload [N], spin rate [rad/s]; all > 0
        (reverse rotation is not modelled).

    Raises
    ------
    ParameterError
        If any value is not a real number, is NaN, infinite (except
        ``k_ip1``, ``k_ip2`` = +inf) or out of bounds; all violations are
        reported in one line, separated by ``"; "``.
    """

    Theta: float
    Phi: float
    k_t: float
    d_t: float
    k1: float
    k2: float
    d1: float
    d2: float
    k_ip1: float
    k_ip2: float
    mu1: float
    mu2: float
    h10: float
    h20: float
    r: float
    N0: float
    Omega: float

    def __post_init__(self) -> None:
        """Validate every field and store it as a built-in ``float``."""
        values = {name: getattr(self, name) for name in PARAMETER_NAMES}
        problems = _problems(values)
        if problems:
            raise ParameterError("; ".join(message for _, message in problems))
        for name, value in values.items():
            object.__setattr__(self, name, float(value))

    @classmethod
    def from_dict(cls, data: Mapping[str, Value], *, source: str = "parameter set"
                  ) -> Parameters:
        """Build from all 17 names mapped to numbers or constant expressions.

        ``data`` may be the output of :meth:`to_json_dict`; ``source`` labels
        error messages.  Raises ParameterError for missing or unknown names
        and invalid values.
        """
        unknown = [name for name in data if name not in PARAMETER_NAMES]
        if unknown:
            raise ParameterError(f"{source}: unknown parameter '{unknown[0]}'; "
                                 "valid names: " + ", ".join(PARAMETER_NAMES))
        missing = [name for name in PARAMETER_NAMES if name not in data]
        if missing:
            raise ParameterError(f"{source}: missing parameter(s) " + ", ".join(missing)
                                 + " (give all 17 model parameters or choose a preset)")
        return cls(**{name: _constant(data[name], f"value of '{name}'")
                      for name in PARAMETER_NAMES})

    @property
    def thickness(self) -> float:
        """Disk thickness ``h = h10 + h20`` [m] (eq. 58)."""
        return self.h10 + self.h20

    def as_dict(self) -> dict[str, float]:
        """Return the values keyed by name, in the order of ``PARAMETER_NAMES``."""
        return {name: getattr(self, name) for name in PARAMETER_NAMES}

    def replace(self, **changes: float) -> Parameters:
        """Return a validated copy with some values changed.

        Raises ParameterError if a name is not a model parameter (the message
        lists the valid names) or a new value is invalid.
        """
        unknown = [name for name in changes if name not in PARAMETER_NAMES]
        if unknown:
            raise ParameterError(f"Unknown parameter '{unknown[0]}'; valid names: "
                                 + ", ".join(PARAMETER_NAMES))
        return dataclasses.replace(self, **changes)

    def compliances(self) -> tuple[float, float]:
        """Return the tangential compliances ``(1/k_ip1, 1/k_ip2)``; 0.0 if rigid."""
        return (0.0 if math.isinf(self.k_ip1) else 1.0 / self.k_ip1,
                0.0 if math.isinf(self.k_ip2) else 1.0 / self.k_ip2)

    def to_json_dict(self) -> dict[str, float | str]:
        """Return a JSON-compatible ordered dict; ``inf`` becomes the string ``"inf"``."""
        return {name: "inf" if math.isinf(value) else value
                for name, value in self.as_dict().items()}

    def trivial_silent_motion(self) -> bool:
        """Return whether q = 0 is the silent motion, ``mu1*h10 == mu2*h20`` (eq. 49).

        The comparison uses a relative tolerance of 1e-12.
        """
        a, b = self.mu1 * self.h10, self.mu2 * self.h20
        return abs(a - b) <= _TRIVIAL_RTOL * max(abs(a), abs(b))


def _constant(value: object, what: str) -> float:
    """Turn a number or a constant expression string (``"16*pi"``) into a float."""
    if isinstance(value, str):
        return evaluate(value, {}, what=what)
    if not _is_real(value):
        raise ParameterError(f"The {what} must be a real number or an expression "
                             f"string; got {value!r} ({type(value).__name__})")
    return float(value)  # type: ignore[arg-type]


@dataclass(frozen=True, eq=False)
class Preset:
    """A named parameter set of the paper with free, fixed and tied names.

    Attributes
    ----------
    name, description : str
        Identifier (``"paper-fig2"``) and one-line summary.
    reference : str
        Where the values come from in the paper (section, equations, figure).
    fixed : Mapping[str, float or str]
        Numbers or constant expressions that rarely change (may be
        overridden); may include auxiliary names such as ``h``.
    free : Mapping[str, float or str]
        The intended knobs with their defaults: model parameters or
        auxiliary names such as ``mu`` or ``k_ip``.
    tied : Mapping[str, str]
        Expressions of free, fixed and other tied names, evaluated in
        dependency order; they cannot be set directly.
    auxiliary : Mapping[str, str]
        Descriptions of the auxiliary (non-model) names.

    Raises
    ------
    ParameterError
        If the definition is inconsistent: overlapping or reserved names,
        model parameters not covered, unknown or unused names, a cycle.
    """

    name: str
    description: str
    reference: str
    fixed: Mapping[str, Value]
    free: Mapping[str, Value]
    tied: Mapping[str, str]
    auxiliary: Mapping[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        """Freeze the mappings and check the definition for consistency."""
        for attribute in ("fixed", "free", "tied", "auxiliary"):
            frozen = MappingProxyType(dict(getattr(self, attribute)))
            object.__setattr__(self, attribute, frozen)
        _check_preset(self)

    def settable_names(self) -> tuple[str, ...]:
        """Return the names :meth:`resolve` accepts: free names first, then fixed."""
        return (*self.free, *self.fixed)

    def resolve(self, overrides: Mapping[str, Value] | None = None) -> Parameters:
        """Compute a validated parameter set, optionally overriding free or fixed names.

        Parameters
        ----------
        overrides : Mapping[str, float or str], optional
            New values: numbers or constant expressions such as ``"inf"``.

        Raises
        ------
        ParameterError
            If a name is tied or unknown to this preset, a value or tied
            expression cannot be evaluated, or the result violates a bound.
        """
        overrides = dict(overrides or {})
        for name in overrides:
            self._check_settable(name)
        values = {name: _constant(overrides.get(name, default), f"value of '{name}'")
                  for name, default in {**self.fixed, **self.free}.items()}
        for name in dependency_order(self.tied, what=f"preset '{self.name}'"):
            values[name] = evaluate(self.tied[name], values, what=f"tied parameter '{name}'")
        model = {name: values[name] for name in PARAMETER_NAMES}
        problems = _problems(model)
        if problems:
            raise ParameterError("; ".join(self._explain(n, m, values) for n, m in problems))
        return Parameters(**model)

    def describe(self) -> str:
        """Return a multi-line human-readable description of the preset."""
        lines = [f"{self.name}: {self.description}", f"  reference: {self.reference}"]
        for title, entries in (("free (settable)", self.free),
                               ("fixed (settable)", self.fixed), ("tied", self.tied)):
            lines.append(f"  {title}:")
            lines.extend(f"    {name:<7} = {_show(value):<32} {self._label(name)}"
                         for name, value in entries.items())
        return "\n".join(lines)

    def _label(self, name: str) -> str:
        """Unit and description of a model or auxiliary name."""
        if name in PARAMETER_NAMES:
            return (f"[{UNITS[name]}] " if UNITS[name] else "") + DESCRIPTIONS[name]
        return self.auxiliary.get(name, "auxiliary quantity")

    def _explain(self, name: str, message: str, values: Mapping[str, float]) -> str:
        """Append to a bound violation of a tied name where its value came from."""
        if name not in self.tied:
            return message
        at = ", ".join(f"{n}={_fmt(values[n])}" for n in sorted(names_in(self.tied[name])))
        return (f"{message} (tied in preset '{self.name}': {name} = {self.tied[name]}"
                + (f" at {at})" if at else ")"))

    def _check_settable(self, name: str) -> None:
        """Raise a helpful error unless ``name`` may be overridden in this preset."""
        if name in self.tied:
            raise ParameterError(
                f"The parameter '{name}' is tied in preset '{self.name}' "
                f"({name} = {self.tied[name]}); set one of its free parameters: "
                + ", ".join(self.free))
        if name in self.free or name in self.fixed:
            return
        elsewhere = [f"'{p.name}'" for p in PRESETS.values() if name in p.free]
        hint = f"; it is a free parameter of preset {', '.join(elsewhere)}" if elsewhere else ""
        raise ParameterError(
            f"The parameter '{name}' is not defined in preset '{self.name}'{hint}; "
            "settable names: " + ", ".join(self.settable_names()))


def _show(value: Value) -> str:
    """Format a preset value for :meth:`Preset.describe`."""
    return value if isinstance(value, str) else _fmt(float(value))


def _check_preset(preset: Preset) -> None:
    """Validate a preset definition (see :class:`Preset`)."""
    where = f"preset '{preset.name}'"
    every = [*preset.fixed, *preset.free, *preset.tied]
    duplicates = sorted({name for name in every if every.count(name) > 1})
    if duplicates:
        raise ParameterError(f"{where}: names in more than one of fixed/free/tied: "
                             + ", ".join(duplicates))
    bad = [n for n in every if not n.isidentifier() or n in RESERVED_NAMES]
    if bad:
        raise ParameterError(f"{where}: invalid or reserved name '{bad[0]}'")
    missing = [name for name in PARAMETER_NAMES if name not in every]
    if missing:
        raise ParameterError(f"{where}: model parameter(s) not defined: " + ", ".join(missing))
    for name, value in {**preset.fixed, **preset.free}.items():
        _constant(value, f"value of '{name}' in {where}")
    used: set[str] = set()
    for name, expr in preset.tied.items():
        refs = names_in(expr, what=f"{where}: tied parameter '{name}'")
        unknown = sorted(refs - set(every))
        if unknown:
            raise ParameterError(f"{where}: tied parameter '{name}' = {expr} uses "
                                 f"unknown name '{unknown[0]}'")
        used |= refs
    unused = [n for n in every if n not in PARAMETER_NAMES and n not in used]
    if unused:
        raise ParameterError(f"{where}: auxiliary name '{unused[0]}' is not used")
    dependency_order(preset.tied, what=where)


_PAPER_SUPPORTS: Mapping[str, Value] = {"h": 0.02, "r": 0.13, "k_t": 1.88e7, "d_t": 0.1,
                                         "k1": 6e6, "k2": 6e6, "d1": 5.0, "d2": 5.0}
_AUX = {"h": "[m] disk thickness h = h10 + h20 (eq. 58)",
        "mu": "kinetic friction coefficient of both contacts (mu1 = mu2)",
        "k_ip": "[N/m] tangential stiffness of both pads (k_ip1 = k_ip2)",
        "R_disk": "[m] disk radius, for the inertia of eq. 63"}
_SYMMETRIC: Mapping[str, str] = {"mu1": "mu", "mu2": "mu", "h10": "h/2", "h20": "h/2",
                                 "Phi": "2*Theta"}

#: The presets of the paper, by name.
PRESETS: dict[str, Preset] = {preset.name: preset for preset in (
    Preset(
        name="paper-fig2",
        description="symmetric model with tangential pad springs; stability map "
                    "over k_ip and mu with N0 = 1800/mu",
        reference="paper Sec. 3.1, eqs. 50-53 and the parameters below eq. 55, Fig. 2",
        fixed={**_PAPER_SUPPORTS, "Theta": 0.16, "Omega": "16*pi"},
        free={"mu": 0.5, "k_ip": 1e8},
        tied={**_SYMMETRIC, "k_ip1": "k_ip", "k_ip2": "k_ip", "N0": "1800/mu"},
        auxiliary=_AUX,
    ),
    Preset(
        name="paper-fig3",
        description="asymmetric friction mu1 != mu2 with O placed so that eq. 49 "
                    "holds (eq. 57); Fig. 3 keeps mu1 + mu2 = 1 (eq. 62)",
        reference="paper Sec. 3.2, eqs. 56-63, Fig. 3",
        fixed={**_PAPER_SUPPORTS, "Phi": 0.32, "N0": 3000.0, "R_disk": 0.15},
        free={"mu1": 0.6, "mu2": 0.4, "k_ip": 1e8, "Omega": "16*pi"},
        tied={"h10": "h*mu2/(mu1+mu2)", "h20": "h*mu1/(mu1+mu2)",
              "Theta": "Phi/2 + Phi/(2*R_disk**2)*(h10-h20)**2",
              "k_ip1": "k_ip", "k_ip2": "k_ip"},
        auxiliary=_AUX,
    ),
    Preset(
        name="minimal-model",
        description="symmetric minimal model of the paper's ref. [6] with rigid "
                    "tangential supports (k_ip1 = k_ip2 = inf)",
        reference="paper eqs. 54-55 with the parameters of Sec. 3.1",
        fixed={**_PAPER_SUPPORTS, "Theta": 0.16, "k_ip1": "inf", "k_ip2": "inf"},
        free={"mu": 0.5, "N0": 3600.0, "Omega": "16*pi"},
        tied=_SYMMETRIC,
        auxiliary=_AUX,
    ),
)}


def get_preset(name: str) -> Preset:
    """Return the preset called ``name``; ParameterError lists the valid names.

    Parameters
    ----------
    name : str
        A key of :data:`PRESETS`: ``"paper-fig2"`` (Sec. 3.1, Fig. 2),
        ``"paper-fig3"`` (Sec. 3.2, Fig. 3) or ``"minimal-model"`` (eqs. 54-55).

    Returns
    -------
    Preset
        The (immutable) preset; call :meth:`Preset.resolve` for parameter values.

    Raises
    ------
    ParameterError
        If ``name`` is not a string naming a preset.
    """
    if isinstance(name, str) and name in PRESETS:
        return PRESETS[name]
    raise ParameterError(f"Unknown preset {name!r}; valid presets: " + ", ".join(PRESETS))


def _read_toml(path: str) -> dict[str, object]:
    """Read a TOML file, turning I/O and syntax errors into ParameterError."""
    try:
        with open(path, "rb") as handle:
            return tomllib.load(handle)
    except OSError as exc:
        raise ParameterError(f"cannot read parameter file '{path}': "
                             f"{exc.strerror or exc}") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ParameterError(f"parameter file '{path}' is not valid TOML: {exc}") from None


def load_parameters(path: str) -> tuple[Preset | None, dict[str, Value]]:
    """Read a parameter file: an optional ``preset`` and a ``[parameters]`` table.

    Returns
    -------
    preset : Preset or None
        The preset named by the top-level key ``preset``, if any.
    entries : dict
        The ``[parameters]`` table: numbers or expression strings.

    Raises
    ------
    ParameterError
        One line naming the file and the key for an unreadable file, invalid
        TOML, unknown top-level keys, an unknown preset or wrong types.
    """
    data = _read_toml(path)
    for key in data:
        if key not in ("preset", "parameters"):
            raise ParameterError(f"parameter file '{path}': unknown top-level key "
                                 f"'{key}'; allowed keys: preset, parameters")
    preset_name = data.get("preset")
    if preset_name is not None and not isinstance(preset_name, str):
        raise ParameterError(f"parameter file '{path}': key 'preset' must be a string; "
                             f"got {preset_name!r}")
    table = data.get("parameters", {})
    if not isinstance(table, dict):
        raise ParameterError(f"parameter file '{path}': key 'parameters' must be a "
                             "table ([parameters])")
    for key, value in table.items():
        if not (_is_real(value) or isinstance(value, str)):
            raise ParameterError(
                f"parameter file '{path}': key 'parameters.{key}' must be a number or an "
                f"expression string; got {value!r} ({type(value).__name__})")
    try:
        preset = None if preset_name is None else get_preset(preset_name)
    except ParameterError as exc:
        raise ParameterError(f"parameter file '{path}': key 'preset': {exc}") from None
    return preset, dict(table)


def _from_file(path: str, preset: str | None, overrides: Mapping[str, Value]
               ) -> Parameters:
    """Resolve a parameter file with an optional ``--preset`` and overrides."""
    file_preset, entries = load_parameters(path)
    if preset is not None and file_preset is not None and file_preset.name != preset:
        raise ParameterError(f"parameter file '{path}': key 'preset' = "
                             f"'{file_preset.name}' conflicts with --preset '{preset}'")
    chosen = file_preset or (None if preset is None else get_preset(preset))
    source = f"parameter file '{path}'"
    try:
        if chosen is None:
            return Parameters.from_dict({**entries, **overrides}, source=source)
        return chosen.resolve({**entries, **overrides})
    except ParameterError as exc:
        if str(exc).startswith(source):
            raise
        raise ParameterError(f"{source}: {exc}") from None


def parameters_from_toml(path: str, overrides: Mapping[str, Value] | None = None
                         ) -> Parameters:
    """Read a parameter file and return the validated parameter set.

    With a top-level ``preset`` key the ``[parameters]`` entries override
    that preset (same rules as :meth:`Preset.resolve`); without one, all 17
    model parameters are required.  ``overrides`` apply last.

    Parameters
    ----------
    path : str
        Path of the TOML parameter file (see :func:`load_parameters`).
    overrides : Mapping[str, float or str], optional
        Values applied on top of the file's entries, in SI units: numbers or
        constant expressions such as ``"16*pi"`` or ``"inf"``; names as the
        file's ``[parameters]`` table allows.

    Returns
    -------
    Parameters
        The validated parameter set.

    Raises
    ------
    ParameterError
        One line naming the file and the offending key.
    """
    return _from_file(path, None, dict(overrides or {}))


def parameters_to_toml(params: Parameters) -> str:
    """Return a complete TOML parameter file that :func:`parameters_from_toml` reads back.

    Floats are written with ``repr`` (exact round trip); ``inf`` as ``"inf"``.
    """
    lines = ["# brakesqueal parameter set (SI units)", "[parameters]"]
    for name, value in params.to_json_dict().items():
        text = '"inf"' if isinstance(value, str) else repr(float(value))
        unit = f"[{UNITS[name]}] " if UNITS[name] else ""
        lines.append(f"{name} = {text}  # {unit}{DESCRIPTIONS[name]}")
    return "\n".join(lines) + "\n"


def parse_assignment(text: str) -> tuple[str, Value]:
    """Parse a command-line ``NAME=VALUE``; the value is a float if it is a plain number.

    Raises
    ------
    ParameterError
        ``malformed --set 'abc': expected NAME=VALUE``.
    """
    name, sep, value = text.partition("=")
    name, value = name.strip(), value.strip()
    if not sep or not name.isidentifier() or not value:
        raise ParameterError(f"malformed --set {text!r}: expected NAME=VALUE")
    try:
        return name, float(value)
    except ValueError:
        return name, value


def parse_sets(sets: Sequence[str]) -> dict[str, Value]:
    """Parse repeated ``--set NAME=VALUE`` options into overrides.

    Parameters
    ----------
    sets : sequence of str
        The ``NAME=VALUE`` texts.

    Returns
    -------
    dict
        ``{name: value}``; values are floats where they are plain numbers, else strings.

    Raises
    ------
    ParameterError
        A malformed assignment, or a name given more than once.
    """
    overrides: dict[str, Value] = {}
    for text in sets:
        name, value = parse_assignment(text)
        if name in overrides:
            raise ParameterError(f"--set '{name}' is given more than once")
        overrides[name] = value
    return overrides


def resolve_parameters(preset: str | None, params_file: str | None, sets: list[str]
                       ) -> Parameters:
    """Combine ``--preset``, ``--params FILE`` and ``--set NAME=VALUE`` options.

    Without a preset and a file the preset ``paper-fig2`` is used.  File
    entries override the preset (the file's own or ``preset``); ``--set``
    values override both.

    Parameters
    ----------
    preset : str or None
        Name of a preset (``--preset``), or ``None``.
    params_file : str or None
        Path of a TOML parameter file (``--params``), or ``None``.
    sets : list of str
        ``NAME=VALUE`` assignments (``--set``), values in SI units: numbers
        or constant expressions such as ``16*pi``.

    Returns
    -------
    Parameters
        The validated parameter set.

    Raises
    ------
    ParameterError
        If the file names a preset other than ``preset``, a ``--set`` name
        is given twice, or any value, name or file is invalid.
    """
    overrides = parse_sets(sets)
    if params_file is None:
        return get_preset(preset or "paper-fig2").resolve(overrides)
    return _from_file(params_file, preset, overrides)
