"""Components of a wobbling-disk model: disk, pads, calipers, friction laws.

A component field is either a number or the *name* of a model parameter
(a string); :class:`ModelSpec` keeps the default values of the named
parameters.  Validation happens when a spec is built and names the component
in every message.

Physical conventions (see ``docs/model-builder.md``):

* A pad at angle ``angle_deg`` sits at ``Rz(angle) (0, -radius, 0)``; the
  paper's pads have angle 0.  Its tangential direction is ``Rz(angle) x0``,
  the direction in which the disk surface moves for ``Omega > 0``.
* ``face="upper"`` pads touch the face at ``z0 = -h_upper`` and push along
  ``+z0``; ``"lower"`` pads touch ``z0 = +h_lower`` and push along ``-z0``.
* A pad's mass acts only in the directions listed in ``dofs``; in the others
  the pad is massless: along the normal its force follows from its
  equilibrium (paper eqs. 29-30), tangentially it is quasi-static (eqs. 33-34).
* A normal DOF needs a contact stiffness ``k_c`` (optionally ``d_c``): the
  contact force is ``preload + k_c δ + d_c δdot`` with ``δ`` the penetration.
* Tangential springs are pre-tensioned by ``mu(v*) preload`` (``v*`` the
  nominal sliding speed ``Omega radius``) so that deformations are measured
  from the silent motion, as in the paper; a caliper's tangential spring is
  pre-tensioned likewise by the friction it carries.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal, Union

from ..errors import ParameterError
from .expressions import RESERVED_NAMES

if TYPE_CHECKING:
    from .parameters import Preset
    from .roles import ParameterRoles

__all__ = ["Value", "FrictionLaw", "Disk", "Pad", "Caliper", "ModelSpec", "MAX_PADS", "MAX_COORDINATES"]

Value = Union[float, str]
FACES = ("upper", "lower")
_NAME = re.compile(r"^\w+$", re.ASCII)


def _is_name(v: object) -> bool:
    return isinstance(v, str)


def _check_value(
    component: str, field_name: str, v: object, *, allow_inf: bool = False, optional: bool = False
) -> None:
    if v is None and optional:
        return
    if isinstance(v, str):
        if not (v.isidentifier() and v.isascii()):
            raise ParameterError(f"{component}: {field_name} = {v!r} is neither a number nor a parameter name "
                                 "(an ASCII identifier)")
        if v in RESERVED_NAMES:
            raise ParameterError(f"{component}: {field_name} = {v!r}: '{v}' is reserved and cannot name a parameter"
                                 + (" (for infinity write the number inf)" if v == "inf" else ""))
        return
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ParameterError(f"{component}: {field_name} must be a number or a parameter name; got {v!r}")
    if math.isnan(v) or (math.isinf(v) and not (allow_inf and v > 0)):
        raise ParameterError(f"{component}: {field_name} must be finite{' or +inf' if allow_inf else ''}; got {v}")


class FrictionLaw:
    """Coefficient of kinetic friction as a function of the sliding speed ``v`` (laws: :mod:`.friction`).

    Parameters
    ----------
    law : str
        A law of :data:`brakesqueal.model.friction.LAWS`: ``"coulomb"``
        (``mu(v) = mu``), ``"linear"`` (``mu(v) = mu - slope v``, the
        negative-slope mechanism of planar models) or ``"stribeck"``
        (``mu(v) = mu + (mu_s - mu) exp(-v / v_s)``).
    mu : float or str
        Kinetic coefficient (the intercept at ``v = 0`` for ``linear``): a
        number or a parameter name.
    **fields : float or str
        The law's other fields (``slope``; ``mu_s``, ``v_s``), numbers or
        parameter names.
    """

    __slots__ = ("law", "mu", "fields")

    def __init__(self, law: str = "coulomb", mu: Value = "mu", **fields: Value | None) -> None:
        object.__setattr__(self, "law", law)
        object.__setattr__(self, "mu", mu)
        object.__setattr__(self, "fields", tuple((k, v) for k, v in fields.items() if v is not None))

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        return dict(object.__getattribute__(self, "fields")).get(name)

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("FrictionLaw is immutable")

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, FrictionLaw) and (self.law, self.mu, dict(self.fields))
                == (other.law, other.mu, dict(other.fields)))

    def __hash__(self) -> int:
        return hash((self.law, self.mu, self.fields))

    def __repr__(self) -> str:
        extra = "".join(f", {k}={v!r}" for k, v in self.fields)
        return f"FrictionLaw({self.law!r}, mu={self.mu!r}{extra})"

    def __reduce__(self) -> tuple[Any, ...]:
        return (_friction_law, (self.law, self.mu, dict(self.fields)))

    @property
    def __dict__(self) -> dict[str, Any]:  # type: ignore[override]
        """``law``, ``mu`` and the fields (for ``vars()``)."""
        return {"law": self.law, **self.values()}

    @property
    def definition(self) -> Any:
        """The :class:`~brakesqueal.model.friction.LawDef` of this law."""
        from .friction import LAWS

        return LAWS[self.law]

    @property
    def rate_dependent(self) -> bool:
        """Whether ``mu`` depends on the sliding speed."""
        return bool(self.definition.rate_dependent)

    def values(self) -> dict[str, Value]:
        """``mu`` and the law's fields, by name."""
        return {"mu": self.mu, **dict(self.fields)}

    def validate(self, component: str) -> None:
        """Check the law and its fields; raise :class:`ParameterError` naming ``component``."""
        from ..suggest import did_you_mean
        from .friction import LAWS

        if not isinstance(self.law, str) or self.law not in LAWS:
            raise ParameterError(f"{component}: friction law must be one of {', '.join(LAWS)}; got {self.law!r}"
                                 f"{did_you_mean(str(self.law), LAWS)}")
        _check_value(component, "mu", self.mu)
        needed = self.definition.fields
        for name, v in self.fields:
            if name not in needed:
                raise ParameterError(f"{component}: '{name}' does not belong to the {self.law} friction law"
                                     f"{did_you_mean(name, needed)}" + (f"; its fields: mu, {', '.join(needed)}"))
            _check_value(component, name, v)
        for name in needed:
            if name not in dict(self.fields):
                raise ParameterError(f"{component}: the {self.law} friction law needs '{name}'")


def _friction_law(law: str, mu: Value, fields: dict[str, Value]) -> FrictionLaw:
    return FrictionLaw(law, mu, **fields)


@dataclass(frozen=True)
class Disk:
    """The rigid disk: tilting DOFs ``q1, q2`` on rotational supports, constant spin ``Omega``.

    Every field except ``tilting`` is a number or the name of a model
    parameter (default: the paper's names); the fields are checked by
    :meth:`validate` when a :class:`ModelSpec` is built.

    Parameters
    ----------
    Theta : float or str, optional
        Moment of inertia about a diameter (the body axes ``x3``, ``y3``)
        [kg m²]; ``I3 = diag(Theta, Theta, Phi)`` in eqs. (36)-(38).
    Phi : float or str, optional
        Moment of inertia about the disk's axis ``z3`` [kg m²].
    k_t : float or str, optional
        Stiffness of the rotational supports [N m/rad] (``K_m``, eq. 45).
    d_t : float or str, optional
        Damping of the rotational supports [N m s/rad] (``D_m``, eq. 45).
    h_upper : float or str, optional
        Distance ``h10`` from O to the upper surface [m]; ``"upper"`` pads
        touch the face ``z0 = -h_upper`` (eq. 14).
    h_lower : float or str, optional
        Distance ``h20`` from O to the lower surface [m]; ``"lower"`` pads
        touch the face ``z0 = +h_lower`` (eq. 15).
    Omega : float or str, optional
        Constant spin rate ``Omega_d`` of the non-holonomic constraint,
        eq. (40) [rad/s].
    radius : float or str, optional
        Outer radius [m], only used to check that the pads sit on the disk
        (default ``inf``: no check).
    tilting : bool, optional
        ``True`` (default): the tilt angles ``q1, q2`` are DOFs.  ``False``
        locks the tilt: the disk becomes a rotating belt (speed ``Omega r``
        at a pad's radius ``r``) for its pads (planar pad models); ``Theta``,
        ``Phi``, ``k_t`` and ``d_t`` then do not enter the equations but
        still need values.
    """

    Theta: Value = "Theta"
    Phi: Value = "Phi"
    k_t: Value = "k_t"
    d_t: Value = "d_t"
    h_upper: Value = "h10"
    h_lower: Value = "h20"
    Omega: Value = "Omega"
    radius: Value = math.inf
    tilting: bool = True

    def validate(self) -> None:
        """Check the fields; raise :class:`ParameterError` naming the disk."""
        for f in ("Theta", "Phi", "k_t", "d_t", "h_upper", "h_lower", "Omega"):
            _check_value("disk", f, getattr(self, f))
        _check_value("disk", "radius", self.radius, allow_inf=True)


@dataclass(frozen=True)
class Pad:
    """One brake pad in point contact with a disk face.

    Parameters
    ----------
    name : str
        Unique component name.
    face : {"upper", "lower"}
        Which disk face it touches.
    angle_deg : float
        Angular position around ``z0`` (0 = the paper's pads, at ``y0 = -radius``).
    radius : float or str
        Distance of the contact line from the axis [m].
    k, d : float or str
        Normal support stiffness [N/m] and damping [N s/m].
    preload : float or str
        Normal preload ``N0`` [N] (> 0).
    k_ip : float or str
        Tangential support stiffness [N/m]; ``inf`` = rigid.
    d_ip : float or str
        Tangential damper [N s/m]; needs a tangential DOF.
    mass : float or str, optional
        Pad mass [kg]; needs ``dofs``.
    dofs : tuple of {"normal", "tangential"}
        Directions in which the mass moves as its own DOF.
    k_c, d_c : float or str, optional
        Contact stiffness and damping, needed by a normal DOF.
    friction : FrictionLaw
        The friction law at this contact.
    mount : str, optional
        Name of the :class:`Caliper` carrying the pad's supports (default: ground).
    """

    name: str
    face: Literal["upper", "lower"]
    angle_deg: float = 0.0
    radius: Value = "r"
    k: Value = "k"
    d: Value = "d"
    preload: Value = "N0"
    k_ip: Value = math.inf
    d_ip: Value = 0.0
    mass: Value | None = None
    dofs: tuple[str, ...] = ()
    k_c: Value | None = None
    d_c: Value = 0.0
    friction: FrictionLaw = field(default_factory=FrictionLaw)
    mount: str | None = None

    @property
    def label(self) -> str:
        """``pad 'name'`` for messages."""
        return f"pad '{self.name}'"

    def validate(self) -> None:
        """Check the fields; raise :class:`ParameterError` naming the pad."""
        if not isinstance(self.name, str):
            raise ParameterError(f"pad: 'name' must be a string; got {self.name!r}")
        c = self.label
        if not _NAME.match(self.name):
            raise ParameterError(f"{c}: a component name must be letters, digits or '_'")
        if self.face not in FACES:
            raise ParameterError(f"{c}: face must be 'upper' or 'lower'; got {self.face!r}")
        if (
            isinstance(self.angle_deg, bool)
            or not isinstance(self.angle_deg, (int, float))
            or not math.isfinite(self.angle_deg)
        ):
            raise ParameterError(f"{c}: angle_deg must be a finite number of degrees; got {self.angle_deg!r}")
        for f in ("radius", "k", "d", "preload", "d_ip", "d_c"):
            _check_value(c, f, getattr(self, f))
        _check_value(c, "k_ip", self.k_ip, allow_inf=True)
        _check_value(c, "mass", self.mass, optional=True)
        _check_value(c, "k_c", self.k_c, optional=True)
        bad = [x for x in self.dofs if x not in ("normal", "tangential")]
        if bad or len(set(self.dofs)) != len(self.dofs):
            raise ParameterError(f"{c}: dofs must be distinct entries of 'normal', 'tangential'; got {list(self.dofs)}")
        if self.dofs and self.mass is None:
            raise ParameterError(f"{c}: a DOF without mass ({', '.join(self.dofs)}): give the pad a mass")
        if self.mass is not None and not self.dofs:
            raise ParameterError(f"{c}: a pad mass needs at least one DOF ('normal' and/or 'tangential')")
        if "normal" in self.dofs and self.k_c is None:
            raise ParameterError(f"{c}: a normal DOF needs a contact stiffness k_c")
        if "tangential" in self.dofs and isinstance(self.k_ip, float) and math.isinf(self.k_ip):
            raise ParameterError(f"{c}: a tangential DOF without stiffness (k_ip = inf): give a finite k_ip")
        if "tangential" not in self.dofs and self.d_ip != 0.0:
            raise ParameterError(f"{c}: a tangential damper d_ip needs a pad mass with a tangential DOF")
        self.friction.validate(c)


@dataclass(frozen=True)
class Caliper:
    """A rigid caliper (mounting) mass coupling the supports of the pads mounted on it.

    ``dofs`` lists its translations (``"normal"`` along ``z0``, ``"tangential"``
    along ``x0``), each with a spring ``k_n``/``k_t`` and damper ``d_n``/``d_t`` to ground.
    The normal and tangential supports of every pad whose ``mount`` names the
    caliper act between the pad and the caliper instead of ground; a pad at
    ``angle_deg`` sees the tangential translation projected on its own
    tangent.  The coordinates are ``wc_<name>`` and ``uc_<name>`` [m].

    Parameters
    ----------
    name : str
        Unique component name (letters, digits, ``_``), referenced by the
        ``mount`` field of a :class:`Pad`.
    mass : float or str, optional
        Caliper mass [kg] (> 0; default parameter ``m_c``).
    dofs : tuple of {"normal", "tangential"}, optional
        Translations that are DOFs (non-empty; default both).
    k_n : float or str, optional
        Normal spring to ground [N/m] (default parameter ``k_cn``; must not be
        0 with a normal DOF).
    d_n : float or str, optional
        Normal damper to ground [N s/m] (default 0).
    k_t : float or str, optional
        Tangential spring to ground [N/m] (default parameter ``k_ct``; must not
        be 0 with a tangential DOF).
    d_t : float or str, optional
        Tangential damper to ground [N s/m] (default 0).
    """

    name: str
    mass: Value = "m_c"
    dofs: tuple[str, ...] = ("normal", "tangential")
    k_n: Value = "k_cn"
    d_n: Value = 0.0
    k_t: Value = "k_ct"
    d_t: Value = 0.0

    def validate(self) -> None:
        """Check the fields; raise :class:`ParameterError` naming the caliper."""
        if not isinstance(self.name, str):
            raise ParameterError(f"caliper: 'name' must be a string; got {self.name!r}")
        c = f"caliper '{self.name}'"
        if not _NAME.match(self.name):
            raise ParameterError(f"{c}: a component name must be letters, digits or '_'")
        if not self.dofs or any(x not in ("normal", "tangential") for x in self.dofs):
            raise ParameterError(f"{c}: dofs must be a non-empty list of 'normal', 'tangential'")
        for f in ("mass", "k_n", "d_n", "k_t", "d_t"):
            _check_value(c, f, getattr(self, f))


#: Largest number of pads a model may have (assembly cost grows quickly with it).
MAX_PADS = 24
#: Largest number of generalized coordinates of a model.
MAX_COORDINATES = 24


def _check_type(where: str, key: str, value: object, kind: type | tuple[type, ...], what: str) -> None:
    if not isinstance(value, kind):
        raise ParameterError(f"{where}: '{key}' must be {what}; got {value!r} ({type(value).__name__})")


@dataclass(frozen=True)
class ModelSpec:
    """A complete model: disk, pads, calipers, default parameter values and presets.

    Parameters
    ----------
    name : str
        Model name.
    disk : Disk
        The disk.
    pads : tuple of Pad
        At least one pad (at most :data:`MAX_PADS`).
    calipers : tuple of Caliper
        Mounting masses (optional).
    parameters : dict
        Default value of every parameter name used by the components, in the
        model's canonical order (the packing order of every numeric function).
    description, reference : str
        Documentation: assumptions and the literature the model follows.
    presets : tuple of Preset
        Named parameter templates of this model (free, fixed and tied names;
        see :class:`~brakesqueal.model.parameters.Preset`).  Every model also
        has an implicit preset named after it in which every parameter is free.
    descriptions : dict
        Optional curated one-line descriptions of parameters (default: built
        from the parameter's roles, :mod:`.roles`).

    Raises
    ------
    ParameterError
        One line naming the component and the field for any invalid
        definition, including default values outside their role's range
        (:mod:`.roles`).
    """

    name: str
    disk: Disk
    pads: tuple[Pad, ...]
    calipers: tuple[Caliper, ...] = ()
    parameters: dict[str, float] = field(default_factory=dict)
    description: str = ""
    reference: str = ""
    presets: tuple[Preset, ...] = ()
    descriptions: dict[str, str] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "pads", tuple(self.pads))
        object.__setattr__(self, "calipers", tuple(self.calipers))
        object.__setattr__(self, "presets", tuple(self.presets))
        self.validate()

    def validate(self) -> None:
        """Check components, names, default values (roles) and presets."""
        from . import roles as _roles

        where = f"model '{self.name}'"
        _check_type("model", "name", self.name, str, "a string")
        _check_type(where, "disk", self.disk, Disk, "a disk table")
        _check_type(where, "parameters", self.parameters, dict, "a table of parameter values")
        for key in ("description", "reference"):
            _check_type(where, key, getattr(self, key), str, "a string")
        if not self.pads:
            raise ParameterError(f"{where}: needs at least one pad")
        if len(self.pads) > MAX_PADS:
            raise ParameterError(f"{where}: has {len(self.pads)} pads; at most {MAX_PADS} are supported")
        for comp in (*self.pads, *self.calipers):
            if not isinstance(comp, (Pad, Caliper)):
                raise ParameterError(f"{where}: pads and calipers must be tables; got {comp!r}")
        self.disk.validate()
        names: set[str] = set()
        comps: tuple[Pad | Caliper, ...] = (*self.pads, *self.calipers)
        for comp in comps:
            comp.validate()
            if comp.name in names:
                raise ParameterError(f"{where}: duplicate component name '{comp.name}'")
            names.add(comp.name)
        calipers = {c.name for c in self.calipers}
        for p in self.pads:
            if p.mount is not None and p.mount not in calipers:
                raise ParameterError(f"{p.label}: mount '{p.mount}' is not a caliper of the model")
        n = (
            (2 if self.disk.tilting else 0)
            + sum(len(p.dofs) for p in self.pads)
            + sum(len(c.dofs) for c in self.calipers)
        )
        if n == 0:
            raise ParameterError(f"{where}: has no degree of freedom (a non-tilting disk needs a pad with mass)")
        if n > MAX_COORDINATES:
            raise ParameterError(f"{where}: has {n} coordinates; at most {MAX_COORDINATES} are supported")
        # the numbers written in the components first, then the default values, then unused names: the most
        # specific problem is reported (a literal edited in place often leaves its former parameter unused)
        r = self.roles()
        for role, owner, v in r.fixed:
            msg = _roles.role_message(role, owner, f"{owner}: {role.key.split('.')[1]}", v)
            if msg is not None:
                raise ParameterError(msg)
        missing = sorted(n for n in self.parameter_names() if n not in self.parameters)
        if missing:
            raise ParameterError(f"{where}: no default value for parameter(s) {', '.join(missing)}")
        for k, v in self.parameters.items():
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise ParameterError(f"{where}: default value of parameter '{k}' must be a number; got {v!r}")
        used = {k: v for k, v in self.parameters.items() if k in r.uses}
        probs = _roles.problems(r, used)
        if probs:
            raise ParameterError(f"{where}: default values: " + "; ".join(m for _, m in probs))
        unused = sorted(set(self.parameters) - set(self.parameter_names()))
        if unused:
            raise ParameterError(f"{where}: parameter(s) {', '.join(unused)} are not used by any component")
        from .parameters import Preset

        seen = {self.name}
        for pr in self.presets:
            if not isinstance(pr, Preset):
                raise ParameterError(f"{where}: presets must be Preset objects; got {pr!r}")
            if pr.name in seen:
                raise ParameterError(f"{where}: duplicate preset name '{pr.name}' (the model's own name is "
                                     "its default preset)")
            seen.add(pr.name)
            pr.check(self)

    def roles(self) -> ParameterRoles:
        """Roles (ranges, units, descriptions) of the named parameters (:func:`.roles.parameter_roles`)."""
        from .roles import parameter_roles

        return parameter_roles(self)

    def parameter_names(self) -> list[str]:
        """Names of all parameters the components use, in first-use order."""
        out: list[str] = []

        def add(v: object) -> None:
            if isinstance(v, str) and v not in out:
                out.append(v)

        d = self.disk
        for f in ("Theta", "Phi", "k_t", "d_t", "h_upper", "h_lower", "Omega", "radius"):
            add(getattr(d, f))
        for p in self.pads:
            for f in ("radius", "k", "d", "preload", "k_ip", "d_ip", "mass", "k_c", "d_c"):
                add(getattr(p, f))
            for v in p.friction.values().values():
                add(v)
        for c in self.calipers:
            for f in ("mass", "k_n", "d_n", "k_t", "d_t"):
                add(getattr(c, f))
        return out

    def stiffness_names(self) -> set[str]:
        """Parameter names used as tangential stiffnesses ``k_ip`` (they may be ``inf``)."""
        return {p.k_ip for p in self.pads if isinstance(p.k_ip, str)}

    def get_preset(self, name: str | None = None) -> Preset:
        """A preset of this model bound to it (``None`` or the model's name: every parameter free).

        Raises
        ------
        ParameterError
            If the model has no preset of that name (the message lists them).
        """
        from .parameters import Preset

        if name is None or name == self.name:
            return Preset(name=self.name, description=f"every parameter of model '{self.name}' free",
                          reference=self.reference, fixed={}, free=dict(self.parameters), tied={}).bind(self)
        for pr in self.presets:
            if pr.name == name:
                return pr.bind(self)
        names = ", ".join([self.name, *(p.name for p in self.presets)])
        raise ParameterError(f"model '{self.name}' has no preset '{name}'; its presets: {names}")

    def preset_names(self) -> list[str]:
        """Names of the model's presets, its default preset (the model's name) first."""
        return [self.name, *(p.name for p in self.presets)]

    def describe_parameter(self, name: str) -> str:
        """One-line description of a parameter (curated if given, else from its roles)."""
        if name in self.descriptions:
            return self.descriptions[name]
        return self.roles().description(name)

    def unit(self, name: str) -> str:
        """SI unit of a parameter (``""``: dimensionless)."""
        return self.roles().unit(name)
