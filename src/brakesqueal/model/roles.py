"""Roles of model parameters: allowed ranges, units and descriptions, for scalars and arrays.

A parameter of a model is a *name* used by one or more component fields
(:mod:`.components`); the field is its *role*: ``pad.k`` (a normal support
stiffness), ``disk.Omega`` (the spin rate of eq. 40), ``friction.mu`` ...
The roles are defined with the fields themselves (:func:`.components.param`,
:data:`.friction.LAWS`); this module derives the table :data:`ROLES` and the
roles of a model's parameters from them.  Every input channel (presets,
parameter files, ``--set``, model files, map and sweep axes, the explorer)
validates through :func:`problems` (scalars) or :func:`valid_mask` (arrays),
so a value is accepted or refused the same way everywhere.

A field whose interval allows ``inf`` may refuse it in some components (its
``finite_if`` rule, :func:`.components.param`): a pad's tangential stiffness
``k_ip`` may be ``inf`` (a rigid support) unless the pad has a tangential
DOF.  The role of a parameter in such a component is the interval without
``inf`` (:attr:`Role.finite` says why), so every channel refuses it there.

Besides each role's interval, two rules hold for every parameter:

* finite values must have a magnitude of at most :data:`MAX_MAGNITUDE`
  (larger ones overflow in products; write ``inf`` for a rigid support where
  the role allows it), and non-zero ones of at least :data:`MIN_MAGNITUDE`
  (``1e-300`` overflowed in the generated equations' powers);
* joint constraints: the disk thickness ``h_upper + h_lower`` is positive
  (eq. 58), a pad sits on the disk (``radius <= disk radius``), a caliper DOF
  has a stiffness.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from functools import lru_cache
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from .friction import FieldDef

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from .components import Kind, ModelSpec, Value

_T = TypeVar("_T")

__all__ = ["Role", "ROLES", "MAX_MAGNITUDE", "MIN_MAGNITUDE", "ParameterRoles", "parameter_roles", "problems",
           "valid_mask", "format_interval", "role_message"]

#: Largest magnitude of a finite parameter value.
MAX_MAGNITUDE = 1e100
#: Smallest magnitude of a finite non-zero value (1e-300 overflowed in the generated equations' powers).
MIN_MAGNITUDE = 1e-100

_INF = math.inf


@dataclass(frozen=True)
class Role(FieldDef):
    """What a component field means and which values it allows: its :class:`~.friction.FieldDef` and its key.

    Attributes
    ----------
    key : str
        ``"<component>.<field>"``, e.g. ``"pad.k_ip"``; the other attributes are those of the FieldDef (a
        ``description`` template with ``{owner}``; ``high = inf`` with ``high_open = False`` allows ``+inf``).
    finite : str
        ``""``, or why ``+inf`` is refused here although the field's interval allows it (the field's
        ``finite_if`` rule for its component, :func:`.components.param`); the interval is then open at ``inf``.
    """

    key: str = ""
    finite: str = ""

    @property
    def allows_inf(self) -> bool:
        """Whether ``+inf`` is an allowed value."""
        return math.isinf(self.high) and not self.high_open

    def interval(self) -> str:
        """The allowed interval, e.g. ``[0, inf)``."""
        return format_interval(self.low, self.high, self.low_open, self.high_open)

    def contains(self, v: Any) -> Any:
        """Element-wise membership (NaN is never a member; magnitude limit applied)."""
        above = (v > self.low) if self.low_open else (v >= self.low)
        below = (v < self.high) if self.high_open else (v <= self.high)
        big = np.abs(v) > MAX_MAGNITUDE
        if self.allows_inf:
            big = big & ~(v == _INF)
        tiny = (v != 0) & (np.abs(v) < MIN_MAGNITUDE)
        return above & below & ~big & ~tiny


def _fmt(value: float) -> str:
    if math.isfinite(value) and float(value).is_integer() and abs(value) < 1e16:
        return str(int(value))
    return repr(float(value))


def format_interval(low: float, high: float, low_open: bool, high_open: bool) -> str:
    """Interval notation such as ``(0, inf]``."""
    return f"{'(' if low_open else '['}{_fmt(low)}, {_fmt(high)}{')' if high_open else ']'}"


def _from_def(key: str, f: FieldDef) -> Role:
    return Role(**{g.name: getattr(f, g.name) for g in dataclasses.fields(f)}, key=key)


@lru_cache(maxsize=8)
def _derive(kinds: tuple[Kind, ...], laws: tuple[str, ...]) -> Mapping[str, Role]:
    from .components import FrictionLaw
    from .friction import LAWS, MU_FIELD

    out: dict[str, Role] = {}
    for kind in kinds:
        for f in dataclasses.fields(kind.cls):
            if "role" in f.metadata:
                out[f"{kind.key}.{f.name}"] = _from_def(f"{kind.key}.{f.name}", f.metadata["role"])
            elif f.default_factory is FrictionLaw:
                out.setdefault("friction.mu", _from_def("friction.mu", MU_FIELD))
    for law in (LAWS[name] for name in laws):
        out |= {f"friction.{name}": _from_def(f"friction.{name}", f) for name, f in law.fields.items()}
    return MappingProxyType(out)


def _table() -> Mapping[str, Role]:
    from .components import COMPONENTS
    from .friction import LAWS

    return _derive(tuple(COMPONENTS.values()), tuple(LAWS))  # kinds and laws registered later count too


class _Roles(Mapping[str, Role]):
    """Every role, derived from :data:`.components.COMPONENTS` (also kinds registered later) and the friction laws."""

    def __getitem__(self, key: str) -> Role:
        return _table()[key]

    def __iter__(self) -> Iterator[str]:
        return iter(_table())

    def __len__(self) -> int:
        return len(_table())


#: Every role, keyed ``"<component>.<field>"`` (read from the component and friction-law definitions).
ROLES: Mapping[str, Role] = _Roles()


@dataclass(frozen=True)
class ParameterRoles:
    """The roles of every named parameter of a model and its joint constraints.

    Attributes
    ----------
    uses : Mapping[str, tuple of (Role, str)]
        Parameter name → the roles it plays, each with its owner label.
    fixed : tuple of (Role, str, float)
        Numeric (literal) component fields with their role, owner and value.
    thickness : tuple of (object, object)
        ``(h_upper, h_lower)`` of the disk: names or numbers.
    pad_radii : tuple of (str, object)
        ``(owner, radius)`` of every pad (name or number), checked against the disk radius.
    disk_radius : object
        The disk radius: a name or a number.
    caliper_dofs : tuple of (str, str, object)
        ``(owner, field, stiffness)`` for every caliper DOF (its stiffness must be positive).
    """

    uses: Mapping[str, tuple[tuple[Role, str], ...]]
    fixed: tuple[tuple[Role, str, float], ...]
    thickness: tuple[Value, Value]
    pad_radii: tuple[tuple[str, Value], ...]
    disk_radius: Value
    caliper_dofs: tuple[tuple[str, str, Value], ...]

    def unit(self, name: str) -> str:
        """SI unit of a parameter (``""`` if dimensionless or unknown)."""
        roles = self.uses.get(name, ())
        return roles[0][0].unit if roles else ""

    def description(self, name: str) -> str:
        """One-line description built from the parameter's roles."""
        roles = self.uses.get(name, ())
        if not roles:
            return ""
        texts: list[str] = []
        for role, owner in roles:
            t = role.description.format(owner=owner)
            if t not in texts:
                texts.append(t)
        if len(texts) > 3:
            return f"{texts[0]} (and {len(texts) - 1} more uses)"
        return "; ".join(texts)

    def interval(self, name: str) -> str:
        """Allowed interval of a parameter (the intersection over its roles)."""
        low, high, lo_open, hi_open = self._bounds(name)
        return format_interval(low, high, lo_open, hi_open)

    def _bounds(self, name: str) -> tuple[float, float, bool, bool]:
        low, high, lo_open, hi_open = -_INF, _INF, True, False
        for role, _ in self.uses.get(name, ()):
            if role.low > low or (role.low == low and role.low_open):
                low, lo_open = role.low, role.low_open
            if role.high < high or (role.high == high and role.high_open):
                high, hi_open = role.high, role.high_open
        return low, high, lo_open, hi_open

    def allows_inf(self, name: str) -> bool:
        """Whether ``+inf`` is allowed (every role of the name allows it)."""
        roles = self.uses.get(name, ())
        return bool(roles) and all(r.allows_inf for r, _ in roles)


def _component_role(role: Role, f: dataclasses.Field[Any], comp: object) -> Role:
    """The role of field ``f`` in component ``comp``: without ``inf`` where its ``finite_if`` rule says so."""
    rule = f.metadata.get("finite_if")
    why = rule(comp) if rule is not None and role.allows_inf else None
    return dataclasses.replace(role, high_open=True, finite=why) if why else role


def parameter_roles(spec: ModelSpec) -> ParameterRoles:
    """Collect the roles of the named parameters of ``spec`` (a :class:`~.components.ModelSpec`)."""
    from .components import COMPONENTS, FrictionLaw, components

    uses: dict[str, list[tuple[Role, str]]] = {}
    fixed: list[tuple[Role, str, float]] = []
    used: list[tuple[Role, Value | None, str]] = []
    unused: list[tuple[Role, Value | None, str]] = []  # fields that do not enter the equations: their roles come last
    table = _table()
    for kind, comp in components(spec):
        owner = kind.owner(comp)
        for f in dataclasses.fields(comp):
            v, unless = getattr(comp, f.name), f.metadata.get("unless")
            if "role" in f.metadata:
                later = unless and not getattr(comp, unless)
                (unused if later else used).append((_component_role(table[f"{kind.key}.{f.name}"], f, comp), v,
                                                    owner))
            elif isinstance(v, FrictionLaw):
                used += [(table[f"friction.{name}"], x, owner) for name, x in v.values().items()]
    for role, value, owner in (*used, *unused):
        if isinstance(value, str):
            lst = uses.setdefault(value, [])
            if (role, owner) not in lst:
                lst.append((role, owner))
        elif value is not None and not isinstance(value, bool):
            fixed.append((role, owner, float(value)))
    owner_pad, owner_caliper = COMPONENTS["pad"].owner, COMPONENTS["caliper"].owner
    d = spec.disk
    cal_dofs = [(owner_caliper(c), f, getattr(c, f)) for c in spec.calipers
                for dof, f in (("normal", "k_n"), ("tangential", "k_t")) if dof in c.dofs]
    return ParameterRoles(
        uses={k: tuple(v) for k, v in uses.items()}, fixed=tuple(fixed), thickness=(d.h_upper, d.h_lower),
        pad_radii=tuple((owner_pad(p), p.radius) for p in spec.pads), disk_radius=d.radius,
        caliper_dofs=tuple(cal_dofs),
    )


def role_message(role: Role, owner: str, subject: str, v: float) -> str | None:
    """Why ``v`` is not allowed in ``role`` (one line starting with ``subject``), or ``None`` when it is.

    Parameters
    ----------
    role : Role
        The field's role.
    owner : str
        The component, for the description (``"pad '1' (upper face)"``).
    subject : str
        How the value is named: ``"The parameter 'k1'"`` or ``"pad '1': k"``.
    v : float
        The value.

    Returns
    -------
    str or None
        The message: the allowed range (or the magnitude bound) and the value.
    """
    if bool(role.contains(v)):
        return None
    what = role.description.format(owner=owner)
    if v != 0 and abs(v) < MIN_MAGNITUDE and bool(role.contains(0.0) or role.low < MIN_MAGNITUDE):
        zero = " be 0 or" if bool(role.contains(0.0)) else ""
        return f"{subject} ({what}) must{zero} have a magnitude of at least {MIN_MAGNITUDE:.0e}; got {v!r}"
    if math.isfinite(v) and abs(v) > MAX_MAGNITUDE:
        return (f"{subject} ({what}) must have a magnitude of at most {MAX_MAGNITUDE:.0e}"
                f"{' or be inf' if role.allows_inf else ''}; got {v!r}")
    unit = f" {role.unit}" if role.unit else ""
    why = f": {role.finite}" if role.finite and v == _INF else ""
    return f"{subject} ({what}) must be in {role.interval()}{unit}{why}; got {v!r}"


def _value_message(name: str, value: object, roles: ParameterRoles) -> str | None:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        return f"The parameter '{name}' must be a real number; got {value!r} ({type(value).__name__})"
    v = float(value)
    if math.isnan(v):
        return f"The parameter '{name}' must be a number; got nan"
    for role, owner in roles.uses.get(name, ()):
        msg = role_message(role, owner, f"The parameter '{name}'", v)
        if msg is not None:
            return msg
    return None


def _thickness_message(hu: Value, hl: Value, a: float, b: float) -> str:
    """The disk thickness ``h_upper + h_lower <= 0``: name the parameters, or the literal field and its range."""
    if isinstance(hu, str) and isinstance(hl, str):
        return (f"The parameters '{hu}' and '{hl}' must satisfy {hu} + {hl} > 0 (disk thickness, eq. 58); "
                f"got {hu} = {a!r}, {hl} = {b!r}")
    # a number written in the model file: name that field and the range its partner leaves it
    field, value, other, ov, oval = (("h_upper", a, "h_lower", hl, b) if not isinstance(hu, str)
                                     else ("h_lower", b, "h_upper", hu, a))
    partner = f"'{ov}' = {oval!r}" if isinstance(ov, str) else f"{oval!r}"
    return (f"disk: {field} = {value!r} must be in ({-oval!r}, inf) m: the disk thickness h_upper + h_lower must "
            f"be positive (eq. 58) and {other} = {partner}")


def _lookup(v: Value, values: Mapping[str, _T]) -> _T | float:
    return values[v] if isinstance(v, str) else v


def problems(roles: ParameterRoles, values: Mapping[str, float]) -> list[tuple[str, str]]:
    """Every violated bound or joint constraint, as ``(parameter name, one-line message)``.

    Parameters
    ----------
    roles : ParameterRoles
        From :func:`parameter_roles`.
    values : Mapping[str, float]
        A value for every named parameter of the model.

    Returns
    -------
    list of (str, str)
        Empty when the values are valid.
    """
    out = [(n, m) for n in roles.uses if (m := _value_message(n, values[n], roles)) is not None]
    bad = {n for n, _ in out}
    hu, hl = roles.thickness
    if not ({hu, hl} & bad):
        a, b = float(_lookup(hu, values)), float(_lookup(hl, values))
        if not a + b > 0.0:
            names = [x for x in (hu, hl) if isinstance(x, str)]
            out.append((names[0] if names else "h_upper", _thickness_message(hu, hl, a, b)))
    R = roles.disk_radius
    if not (isinstance(R, str) and R in bad):
        Rv = float(_lookup(R, values))
        for owner, r in roles.pad_radii:
            if isinstance(r, str) and r in bad:
                continue
            rv = float(_lookup(r, values))
            if rv > Rv:
                out.append((r if isinstance(r, str) else str(R),
                            f"{owner} lies off the disk: radius {rv!r} m > disk radius {Rv!r} m"))
    for owner, field, k in roles.caliper_dofs:
        if isinstance(k, str) and k in bad:
            continue
        if not float(_lookup(k, values)) > 0:
            out.append((k if isinstance(k, str) else field,
                        f"{owner}: a DOF needs a positive stiffness; got {field} = {_lookup(k, values)!r}"))
    return out


def valid_mask(roles: ParameterRoles, arrays: Mapping[str, ArrayLike]) -> np.ndarray:
    """Element-wise validity of broadcastable parameter arrays (the array form of :func:`problems`).

    Parameters
    ----------
    roles : ParameterRoles
        From :func:`parameter_roles`.
    arrays : Mapping[str, array_like]
        Every named parameter of the model (floats or broadcastable arrays).

    Returns
    -------
    ndarray of bool
        Broadcast shape of the inputs; ``True`` where every bound and joint
        constraint holds.
    """
    with np.errstate(invalid="ignore"):
        ok: Any = np.True_
        for name, uses in roles.uses.items():
            v = np.asarray(arrays[name], dtype=float)
            for role, _ in uses:
                ok = ok & role.contains(v)
        hu, hl = roles.thickness
        ok = ok & (np.asarray(_lookup(hu, arrays), float) + np.asarray(_lookup(hl, arrays), float) > 0)
        Rv = np.asarray(_lookup(roles.disk_radius, arrays), float)
        for _, r in roles.pad_radii:
            ok = ok & (np.asarray(_lookup(r, arrays), float) <= Rv)
        for _, _, k in roles.caliper_dofs:
            ok = ok & (np.asarray(_lookup(k, arrays), float) > 0)
    return np.asarray(ok)
