"""Components of a wobbling-disk model: disk, pads, calipers, friction laws.

A component field is either a number or the *name* of a model parameter
(a string); :class:`ModelSpec` keeps the default values of the named
parameters.  Validation happens when a spec is built and names the component
in every message.

This module is the one definition of the components: every field carries its
metadata (:func:`param`: the role's unit, meaning, interval and a schema
note; :func:`attribute`: the schema fragment of a non-parameter field), and
:data:`COMPONENTS` registers each kind (its model-file table, list or single
table, how messages name it).  Roles (:mod:`.roles`), model files
(:mod:`.io`) and the schema (:mod:`.schema`) are derived from them
(``docs/extending.md``).

A component's physics is written here too, as methods of its class that
import no computer algebra (they receive an assembly context ``ctx``,
:class:`brakesqueal.symbolic.assemble.Assembly`, whose ``ctx.sm`` is
``symengine`` or ``sympy``): ``coordinates()`` and ``deformations()`` name
its coordinates ``Q`` and pad deformations ``L``; ``prepare(ctx)``,
``assemble(ctx)`` and ``finish(ctx)`` add its residual rows, its forces on
other components and its moments on the disk (called in that order, each
over every component: the disk's kinematics first, its Euler equations last);
``energy(ctx)`` returns its kinetic and potential energy terms.  A class
without a hook contributes nothing there.

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

import dataclasses
import functools
import math
import re
import sys
import textwrap
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal, Union

from ..errors import ParameterError
from .expressions import RESERVED_NAMES
from .friction import FieldDef

if TYPE_CHECKING:
    from ..symbolic.assemble import Assembly
    from .friction import LawDef
    from .parameters import Preset
    from .roles import ParameterRoles

__all__ = ["Value", "FrictionLaw", "Disk", "Pad", "Caliper", "ModelSpec", "Component", "MAX_PADS", "MAX_COORDINATES",
           "Kind", "COMPONENTS", "param", "attribute", "components", "coordinate_unit"]

Value = Union[float, str]
FACES = ("upper", "lower")


def coordinate_unit(name: str) -> str:
    """Unit of a coordinate or pad deformation: ``rad`` for the disk tilts ``q...``, else ``m`` (pad and caliper
    displacements, the pads' tangential deformations ``l...``)."""
    return "rad" if name.startswith("q") else "m"

_NAME = re.compile(r"^\w+$", re.ASCII)


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


# ------------------------------------------------------------------------------------- field definitions
# The one description of every component field (parameters: role and schema note; others: schema fragment);
# roles.py, io.py, schema.py and the classes' Parameters sections (_document) are derived from it.
_INF = math.inf
_MAX_FLOAT = sys.float_info.max
_POS = (0.0, _INF, True, True)      # (0, inf)
_NONNEG = (0.0, _INF, False, True)  # [0, inf)
_REAL = (-_INF, _INF, True, True)   # (-inf, inf)
_POS_INF = (0.0, _INF, True, False)  # (0, inf]


def param(default: Any, unit: str, description: str, interval: tuple[float, float, bool, bool], note: str = "",
          *, unless: str | None = None, finite_if: Callable[[Any], str | None] | None = None) -> Any:
    """A component field holding a number or a parameter name: its *role* and schema note in the field's metadata.

    Parameters
    ----------
    default : float, str or None
        Default value (a parameter name, a number, or ``None`` for an optional field).
    unit, description : str
        SI unit (``""``: dimensionless) and meaning, a template with ``{owner}`` (``"pad '1' (upper face)"``).
    interval : tuple of (float, float, bool, bool)
        ``(low, high, low_open, high_open)``; ``high = inf`` with ``high_open = False`` allows ``+inf``.
    note : str, optional
        Extra sentence(s) for the model-file schema (starting with a space).
    unless : str, optional
        A flag field of the component; when it is false the field does not enter the equations (still
        checked; its role comes after the used ones).
    finite_if : callable, optional
        For an interval that allows ``+inf``: ``finite_if(component)`` is ``None`` where ``inf`` is allowed in
        this component, else why it is not (``"a pad with a tangential DOF needs a finite k_ip ..."``);
        the parameter's role in such a component is then the interval without ``inf``
        (:func:`.roles.parameter_roles`), so every input channel refuses it.
    """
    return field(default=default, metadata={"role": FieldDef(unit, description, *interval), "note": note,
                                            "unless": unless, "finite_if": finite_if})


def attribute(schema: Mapping[str, Any], default: Any = dataclasses.MISSING, *,
              default_factory: Any = dataclasses.MISSING) -> Any:
    """A component field that is not a parameter (a name, a choice, a flag, a list, a friction law).

    Parameters
    ----------
    schema : Mapping
        Its JSON Schema fragment (``"type": "number"``: ``"inf"`` is a number; ``"array"``: a list, held as a tuple).
    default, default_factory : optional
        As for :func:`dataclasses.field` (neither: a required key).
    """
    # field()'s overloads take a default or a default_factory, not both arguments (one of them is MISSING here)
    return field(default=default, default_factory=default_factory,  # type: ignore[call-overload]
                 metadata={"schema": dict(schema)})


def _check_fields(obj: Component, component: str) -> None:
    """Check a component's fields by their definitions: parameters, names, choices and lists (``component``: label)."""
    for f in dataclasses.fields(obj):
        v, fd, schema = getattr(obj, f.name), f.metadata.get("role"), f.metadata.get("schema", {})
        if fd is not None:  # a number (finite, or +inf where the role allows it) or a parameter name
            _check_value(component, f.name, v, allow_inf=math.isinf(fd.high) and not fd.high_open,
                         optional=f.default is None)
        elif schema.get("$ref") == _COMPONENT_NAME["$ref"] and v is not None:
            if not isinstance(v, str):
                raise ParameterError(f"{component}: '{f.name}' must be a string; got {v!r}")
            if not _NAME.match(v):
                raise ParameterError(f"{component}: {f.name} {v!r}: a component name must be letters, digits or '_'")
        elif "enum" in schema and v not in schema["enum"]:
            raise ParameterError(f"{component}: {f.name} must be {' or '.join(map(repr, schema['enum']))}; got {v!r}")
        elif schema.get("type") == "array":
            allowed, least = schema["items"]["enum"], schema.get("minItems", 0)
            if any(x not in allowed for x in v) or len(set(v)) != len(v) or len(v) < least:
                raise ParameterError(f"{component}: {f.name} must be {'a non-empty list of ' if least else ''}distinct "
                                     f"entries of {', '.join(map(repr, allowed))}; got {list(v)}")


def _has_dof(dof: str) -> dict[str, Any]:
    return {"required": ["dofs"], "properties": {"dofs": {"contains": {"const": dof}}}}


def _positive_with(dof: str, key: str) -> dict[str, Any]:
    return {"if": {"anyOf": [{"not": {"required": ["dofs"]}}, _has_dof(dof)]},
            "then": {"properties": {key: {"not": {"const": 0}}}}}  # fmt: skip


_COMPONENT_NAME = {"$ref": "#/$defs/componentName"}
_tilt = functools.partial(param, unless="tilting")  # a disk field unused when the disk does not tilt


def state_name(prefix: str, component: str) -> str:
    """Name of a component's coordinate: ``w1`` for pad ``"1"`` (the paper's names), ``w_upper`` otherwise."""
    return f"{prefix}{component}" if component.isdigit() else f"{prefix}_{component}"


_TILT = ("q1", "q2")  # the disk's tilt coordinates


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

    def __setattr__(self, name: str, value: object) -> None:
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
    def __dict__(self) -> dict[str, Any]:  # type: ignore[override]  # a property: the class has __slots__
        """``law``, ``mu`` and the fields (for ``vars()``)."""
        return {"law": self.law, **self.values()}

    @property
    def definition(self) -> LawDef:
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

    Every field except ``tilting`` is a number or the name of a model parameter (default: the paper's
    names); ``I3 = diag(Theta, Theta, Phi)`` in eqs. (36)-(38), ``k_t``, ``d_t`` are ``K_m``, ``D_m`` of
    eq. (45).  With ``tilting=False`` the disk is a rotating belt (speed ``Omega r`` at a pad's radius
    ``r``) for planar pad models.
    """

    Theta: Value = _tilt("Theta", "kg m^2", "moment of inertia of the disk about a diameter (eqs. 36-38)", _POS)
    Phi: Value = _tilt("Phi", "kg m^2", "moment of inertia of the disk about its axis (eqs. 36-38)", _POS)
    k_t: Value = _tilt("k_t", "N m/rad", "stiffness of the disk's rotational supports (eq. 45)", _NONNEG)
    d_t: Value = _tilt("d_t", "N m s/rad", "damping of the disk's rotational supports (eq. 45)", _NONNEG)
    h_upper: Value = param("h10", "m", "distance from O to the upper disk surface (eq. 14)", _REAL,
                           " 'upper' pads touch the face z0 = -h_upper; h_upper + h_lower must be > 0.")
    h_lower: Value = param("h20", "m", "distance from O to the lower disk surface (eq. 15)", _REAL,
                           " 'lower' pads touch the face z0 = +h_lower; h_upper + h_lower must be > 0.")
    Omega: Value = param("Omega", "rad/s", "spin rate of the disk (eq. 40; reverse rotation is not modelled, "
                         "mirror the model instead)", _POS)
    radius: Value = param(math.inf, "m", "outer radius of the disk (inf: not checked)", _POS_INF,
                          " Only used to check that every pad's radius is at most the disk radius.")
    tilting: bool = attribute({
        "type": "boolean", "default": True,
        "description": "true: the tilt angles q1, q2 are degrees of freedom. false: the tilt is locked and the "
                       "disk is a belt moving at Omega * radius under each pad (planar pad models; then some pad "
                       "needs a mass with a DOF).",
    }, True)  # fmt: skip

    def validate(self) -> None:
        """Check the fields; raise :class:`ParameterError` naming the disk."""
        _check_fields(self, "disk")

    # physics hooks (docs/extending.md): ctx is a brakesqueal.symbolic.assemble.Assembly
    def coordinates(self) -> tuple[str, ...]:
        """The tilt angles ``q1, q2`` of a tilting disk (none for a belt)."""
        return _TILT if self.tilting else ()

    def prepare(self, ctx: Assembly) -> None:
        """The disk's kinematics, before every other component: Cardan angles with the spin constraint
        (eqs. 2-11, 40-42), or a belt spinning about ``z0``."""
        ctx.disk_kinematics(ctx.val(self.Omega), _TILT if self.tilting else None)

    def finish(self, ctx: Assembly) -> None:
        """The Euler equations of the tilting disk (eqs. 35-45) with the moments the other components added."""
        if self.tilting:
            v = ctx.val
            psi = ctx.euler_rows(_TILT, ctx.sm.diag(v(self.Theta), v(self.Theta), v(self.Phi)), v(self.k_t),
                                 v(self.d_t))
            ctx.add_row("q1", psi[0])
            ctx.add_row("q2", psi[1])

    def energy(self, ctx: Assembly) -> dict[str, Any]:
        """Kinetic energy by degree in the tilt rates (spin constraint substituted) and the supports' potential."""
        if not self.tilting:
            return {}
        sm, v, kin = ctx.sm, ctx.val, ctx.kinematics
        assert kin is not None, "a tilting disk's equations carry its kinematics"
        w3 = kin.A.T * (kin.J_R0 * ctx.qdot)  # body-frame angular velocity with the constraint (eq. 41)
        I3 = sm.diag(v(self.Theta), v(self.Theta), v(self.Phi))
        T = (w3.T * I3 * w3)[0, 0] / 2
        dq1, dq2 = (ctx.dQ[n] for n in _TILT)
        Tm = T.subs({dq1: -dq1, dq2: -dq2})  # T2 and T0 are even in the tilt rates, T1 odd
        T0 = T.subs({dq1: 0, dq2: 0})
        q1, q2 = (ctx.Q[n] for n in _TILT)
        return {"T2": sm.expand((T + Tm) / 2 - T0), "T1": sm.expand((T - Tm) / 2), "T0": T0,
                "V_support": sm.Rational(1, 2) * v(self.k_t) * (q1**2 + q2**2)}


def _k_ip_finite(pad: Pad) -> str | None:
    """Why a pad's ``k_ip`` must be finite (``None``: ``inf``, a rigid tangential support, is allowed)."""
    if "tangential" in pad.dofs:
        return "a pad with a tangential DOF needs a finite k_ip (a rigid tangential support would remove that DOF)"
    return None


@dataclass(frozen=True)
class Pad:
    """One brake pad in point contact with a disk face."""

    name: str = attribute({**_COMPONENT_NAME, "description": "Unique component name (ASCII letters, digits, '_'; "
                                                            "unique among pads and calipers)."})
    face: Literal["upper", "lower"] = attribute({
        "enum": list(FACES), "description": "Disk face the pad touches: 'upper' (face z0 = -h_upper, pushes along "
                                            "+z0) or 'lower' (face z0 = +h_lower, pushes along -z0)."})
    angle_deg: float = attribute({
        "type": "number", "minimum": -_MAX_FLOAT, "maximum": _MAX_FLOAT, "default": 0.0,
        "description": "[deg] angular position of the pad around z0 (0 = the paper's pads, at y0 = -radius). A "
                       "finite number (not a parameter name)."}, 0.0)
    radius: Value = param("r", "m", "effective braking radius of {owner}", _POS, " Must not exceed the disk radius.")
    k: Value = param("k", "N/m", "normal support stiffness of {owner}", _NONNEG)
    d: Value = param("d", "N s/m", "normal support damping of {owner}", _NONNEG)
    preload: Value = param("N0", "N", "normal preload of {owner}", _POS)
    k_ip: Value = param(math.inf, "N/m", "tangential support stiffness of {owner} (inf = rigid)", _POS_INF,
                        " Default 'inf' (rigid); a tangential DOF needs a finite k_ip.", finite_if=_k_ip_finite)
    d_ip: Value = param(0.0, "N s/m", "tangential support damping of {owner}", _NONNEG,
                        " In parallel with the tangential spring; needs a finite k_ip. On a massless pad it makes "
                        "the pad's tangential rate a state that stays determined through lift-off (not in the "
                        "paper; default 0).")
    mass: Value | None = param(None, "kg", "mass of {owner}", _POS,
                               " Needs at least one entry in dofs; absent = massless pad.")
    dofs: tuple[str, ...] = attribute({
        "type": "array", "uniqueItems": True, "default": [], "items": {"enum": ["normal", "tangential"]},
        "description": "Directions in which the pad mass moves as its own DOF (distinct entries of 'normal', "
                       "'tangential'); empty = massless pad (normal force from its equilibrium, tangentially "
                       "quasi-static). Non-empty needs mass."}, ())
    k_c: Value | None = param(None, "N/m", "contact stiffness of {owner}", _POS,
                              " Needed by a normal DOF: the contact force is preload + k_c * penetration + d_c * "
                              "its rate.")
    d_c: Value = param(0.0, "N s/m", "contact damping of {owner}", _NONNEG)
    friction: FrictionLaw = attribute({"$ref": "#/$defs/friction", "description": "Friction law at this contact "
                                       "(default: coulomb with mu = parameter 'mu')."}, default_factory=FrictionLaw)
    mount: str | None = attribute({**_COMPONENT_NAME, "description": "Name of the [[calipers]] entry carrying the "
                                   "pad's normal and tangential supports (absent: the supports act on ground)."},
                                  None)

    @property
    def tangentially_damped(self) -> bool:
        """Whether the pad has a tangential damper (``d_ip`` a parameter name or a nonzero number)."""
        return isinstance(self.d_ip, str) or self.d_ip != 0.0

    @property
    def label(self) -> str:
        """``pad 'name'`` for messages."""
        return f"pad '{self.name}'"

    @property
    def rigid(self) -> bool:
        """Whether the tangential support is rigid (``k_ip`` the number ``inf``)."""
        return not isinstance(self.k_ip, str) and math.isinf(self.k_ip)

    @property
    def quasi_static(self) -> bool:
        """Whether the pad is massless tangentially with a finite stiffness: its deformation ``l`` is in ``L``."""
        return "tangential" not in self.dofs and not self.rigid

    @property
    def treatment(self) -> str | None:
        """How the pad's tangential deformation ``l`` enters the linearization and the simulation.

        The one place this is decided: ``None`` for a pad without a deformation in ``L`` (a tangential DOF or
        a rigid support); ``"dynamic"`` (``l`` keeps a first-order rate state) when its friction law depends on
        the sliding speed (:attr:`LawDef.rate_dependent <brakesqueal.model.friction.LawDef.rate_dependent>`)
        or it has a tangential damper; ``"quasi-static"`` otherwise (``l`` follows the disk through its
        balance; the paper's pads).  Decided from the model, never from parameter values or a law's name.
        """
        if not self.quasi_static:
            return None
        from .friction import LAWS

        return "dynamic" if LAWS[self.friction.law].rate_dependent or self.tangentially_damped else "quasi-static"

    # physics hooks (docs/extending.md): ctx is a brakesqueal.symbolic.assemble.Assembly
    def coordinates(self) -> list[str]:
        """``w_<pad>`` and ``u_<pad>`` of its normal and tangential DOFs."""
        return [state_name("w" if d == "normal" else "u", self.name) for d in ("normal", "tangential")
                if d in self.dofs]

    def deformations(self) -> list[str]:
        """``l_<pad>``: the tangential deformation of a massless pad with a finite tangential stiffness."""
        return [state_name("l", self.name)] if self.quasi_static else []

    def _mount(self, ctx: Assembly) -> tuple[Caliper | None, Any, Any, Any]:
        """The caliper carrying the supports, its normal and tangential (along ``e_t``) displacements, ``cos a``."""
        ca = ctx.angle_cos_sin(self.angle_deg)[0]
        mount = next((c for c in ctx.spec.calipers if c.name == self.mount), None) if self.mount else None
        zero = ctx.sm.Integer(0)
        w_m = ctx.Q[state_name("wc", mount.name)] if mount and "normal" in mount.dofs else zero
        u_m = ctx.Q[state_name("uc", mount.name)] * ca if mount and "tangential" in mount.dofs else zero
        return mount, w_m, u_m, ca

    def _l(self, ctx: Assembly, u_m: Any) -> Any:
        """The pad's tangential position: its coordinate, its deformation, or the mount's (rigid support)."""
        if "tangential" in self.dofs:
            return ctx.Q[state_name("u", self.name)]
        return u_m if self.rigid else ctx.L[state_name("l", self.name)]

    def assemble(self, ctx: Assembly) -> None:
        """The pad's contact (eqs. 12-34), its rows (pad mass), balance ``G``, reactions on its caliper, moment on
        the disk."""
        sm, val, disk = ctx.sm, ctx.val, ctx.spec.disk
        s = 1 if self.face == "upper" else -1
        r, N0 = val(self.radius), val(self.preload)
        ca, sa = ctx.angle_cos_sin(self.angle_deg)
        mount, w_m, u_m, _ = self._mount(ctx)
        l = self._l(ctx, u_m)
        normal, quasi = "normal" in self.dofs, self.quasi_static
        law = self.friction
        c = ctx.pad_contact(
            side=s, h0=val(disk.h_upper if s == 1 else disk.h_lower), base=sm.Matrix([r * sa, -r * ca, 0]),
            e_t=sm.Matrix([ca, sa, 0]), l=l, friction=lambda v: ctx.friction(law, v), N0=N0,
            nominal_speed=ctx.Omega * r, k=val(self.k), d=val(self.d), w_m=w_m,
            normal_dof=ctx.Q[state_name("w", self.name)] if normal else None, k_c=val(self.k_c) if normal else None,
            d_c=val(self.d_c) if normal else None, u_m=u_m, compliance=val.compliance(self.k_ip) if quasi else None,
            engaged=ctx.engagement.get(self.name) if ctx.engagement else None,
            damping_t=val(self.d_ip) if quasi else None,
        )  # fmt: skip
        if normal:
            n = state_name("w", self.name)
            ctx.add_row(n, val(self.mass) * ctx.ddQ[n] - c.support_normal + c.f_p[2])
        if "tangential" in self.dofs:
            n = state_name("u", self.name)
            F_t = -(val(self.k_ip) * (l - u_m) + val(self.d_ip) * (ctx.dQ[n] - ctx.rate(u_m)) + c.mu_star * N0)
            ctx.add_row(n, val(self.mass) * ctx.ddQ[n] - F_t + c.f_t)
        else:
            F_t = c.f_t
            if quasi:
                ctx.G_rows.append(c.g)
        if mount:  # the supports' reactions on the caliper
            if "normal" in mount.dofs:
                ctx.add_row(state_name("wc", mount.name), c.support_normal - s * N0)
            if "tangential" in mount.dofs:
                ctx.add_row(state_name("uc", mount.name), (F_t + c.mu_star * N0) * ca)
        ctx.moment = ctx.moment + c.moment
        ctx.contacts[self.name] = c
        ctx.tangential[self.name] = l

    def energy(self, ctx: Assembly) -> dict[str, Any]:
        """Kinetic energy of the pad mass; potential of the pad's springs and preload (``V_pads``)."""
        sm, val = ctx.sm, ctx.val
        half = sm.Rational(1, 2)
        c, l = ctx.contacts[self.name], ctx.tangential[self.name]
        s = 1 if self.face == "upper" else -1
        N0, k = val(self.preload), val(self.k)
        mount, w_m, u_m, ca = self._mount(ctx)
        T2 = V = sm.Integer(0)
        if "normal" in self.dofs:
            n = state_name("w", self.name)
            T2 += half * val(self.mass) * ctx.dQ[n] ** 2
            delta = s * (ctx.Q[n] - c.h)
            V += half * k * (ctx.Q[n] - w_m) ** 2 - s * N0 * ctx.Q[n] + N0 * delta + half * val(self.k_c) * delta**2
        else:
            V += half * k * (c.h - w_m) ** 2 - s * N0 * c.h
        if "tangential" in self.dofs:
            n = state_name("u", self.name)
            T2 += half * val(self.mass) * ctx.dQ[n] ** 2
            V += half * val(self.k_ip) * (ctx.Q[n] - u_m) ** 2 + c.mu_star * N0 * ctx.Q[n]
        elif not self.rigid:
            # massless pad on its balance g = 0 (eqs. 33-34): k_ip (l - u_m)^2 / 2 = -(l - u_m)(f_t + mu* N0
            # + d_ip (ldot - u_mdot)) / 2, finite also for a rigid support given as k_ip = inf (compliance 0)
            u_dot = ctx.dQ[state_name("uc", mount.name)] * ca if mount and "tangential" in mount.dofs else 0
            F = c.f_t + c.mu_star * N0 + val(self.d_ip) * (ctx.dL[state_name("l", self.name)] - u_dot)
            V += -half * (l - u_m) * F + c.mu_star * N0 * l
        return {"T2": T2, "V_pads": V}

    def validate(self) -> None:
        """Check the fields; raise :class:`ParameterError` naming the pad."""
        c = self.label
        _check_fields(self, c)
        a = self.angle_deg
        if isinstance(a, bool) or not isinstance(a, (int, float)) or not math.isfinite(a):
            raise ParameterError(f"{c}: angle_deg must be a finite number of degrees; got {self.angle_deg!r}")
        if self.dofs and self.mass is None:
            raise ParameterError(f"{c}: a DOF without mass ({', '.join(self.dofs)}): give the pad a mass")
        if self.mass is not None and not self.dofs:
            raise ParameterError(f"{c}: a pad mass needs at least one DOF ('normal' and/or 'tangential')")
        if "normal" in self.dofs and self.k_c is None:
            raise ParameterError(f"{c}: a normal DOF needs a contact stiffness k_c")
        if _k_ip_finite(self) and isinstance(self.k_ip, float) and math.isinf(self.k_ip):
            raise ParameterError(f"{c}: a tangential DOF without stiffness (k_ip = inf): give a finite k_ip")
        if self.d_ip != 0.0 and isinstance(self.k_ip, float) and math.isinf(self.k_ip):
            raise ParameterError(f"{c}: a tangential damper d_ip needs a finite tangential stiffness k_ip (a "
                                 "damper beside a rigid support does nothing)")
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
    """

    name: str = attribute({**_COMPONENT_NAME, "description": "Unique component name (ASCII letters, digits, '_'), "
                                                            "referenced by the mount key of pads."})
    mass: Value = param("m_c", "kg", "mass of {owner}", _POS)
    dofs: tuple[str, ...] = attribute({
        "type": "array", "minItems": 1, "uniqueItems": True, "default": ["normal", "tangential"],
        "items": {"enum": ["normal", "tangential"]},
        "description": "Translations of the caliper that are DOFs: 'normal' (along z0, coordinate wc_<name>) and/or "
                       "'tangential' (along x0, coordinate uc_<name>) [m]. Non-empty; default both."},
        ("normal", "tangential"))
    k_n: Value = param("k_cn", "N/m", "normal stiffness of {owner} to ground", _NONNEG,
                       " Must be > 0 with a normal DOF.")
    d_n: Value = param(0.0, "N s/m", "normal damping of {owner} to ground", _NONNEG)
    k_t: Value = param("k_ct", "N/m", "tangential stiffness of {owner} to ground", _NONNEG,
                       " Must be > 0 with a tangential DOF.")
    d_t: Value = param(0.0, "N s/m", "tangential damping of {owner} to ground", _NONNEG)

    def validate(self) -> None:
        """Check the fields; raise :class:`ParameterError` naming the caliper."""
        _check_fields(self, f"caliper '{self.name}'")

    # physics hooks (docs/extending.md): ctx is a brakesqueal.symbolic.assemble.Assembly
    def _dofs(self) -> list[tuple[str, Value, Value]]:
        return [(state_name(pre, self.name), k, d) for dof, pre, k, d in
                (("normal", "wc", self.k_n, self.d_n), ("tangential", "uc", self.k_t, self.d_t)) if dof in self.dofs]

    def coordinates(self) -> list[str]:
        """``wc_<caliper>`` and ``uc_<caliper>`` of its normal and tangential translations."""
        return [n for n, _, _ in self._dofs()]

    def assemble(self, ctx: Assembly) -> None:
        """Newton's law of each translation; the reactions of the pads mounted on it are added by the pads."""
        v = ctx.val
        for n, k, d in self._dofs():
            ctx.add_row(n, v(self.mass) * ctx.ddQ[n] + v(k) * ctx.Q[n] + v(d) * ctx.dQ[n])

    def energy(self, ctx: Assembly) -> dict[str, Any]:
        """Kinetic energy of the caliper mass and potential of its springs to ground (``V_support``)."""
        half, v = ctx.sm.Rational(1, 2), ctx.val
        T2 = V = ctx.sm.Integer(0)
        for n, k, _ in self._dofs():
            T2 += half * v(self.mass) * ctx.dQ[n] ** 2
            V += half * v(k) * ctx.Q[n] ** 2
        return {"T2": T2, "V_support": V}


#: A component of a model (:func:`components`).
Component = Union[Disk, Pad, Caliper]

#: Largest number of pads a model may have (assembly cost grows quickly with it).
MAX_PADS = 24
#: Largest number of generalized coordinates of a model.
MAX_COORDINATES = 24


@dataclass(frozen=True, eq=False)
class Kind:
    """A kind of component: how models hold it, model files write it and messages name it.

    Attributes
    ----------
    cls : type
        Its frozen dataclass (fields made with :func:`param` and :func:`attribute`).
    key, table : str
        Role prefix and schema definition (``"pad"``); :class:`ModelSpec` attribute and model-file key (``"pads"``).
    many : bool
        A list of components (``[[pads]]``, a tuple in the spec) rather than one table (``[disk]``).
    owner : callable
        ``owner(component)``: how roles name a component (``"pad '1' (upper face)"``).
    schema_owner, doc, description : str
        How the schema names one (``"this pad"``); its descriptions of the model-file key and of one component.
    required : bool
        A model needs at least one (lists).
    max_count : int or None
        Largest number of them (lists).
    rules : tuple of dict
        Cross-field JSON Schema rules (``allOf``) of one component.
    """

    cls: type
    key: str
    table: str
    many: bool
    owner: Callable[[Any], str]
    schema_owner: str
    doc: str
    description: str
    required: bool = False
    max_count: int | None = None
    rules: tuple[dict[str, Any], ...] = ()


#: Schema of a finite stiffness (not 'inf', not a number at the float limit).
_FINITE_K = {"not": {"anyOf": [{"const": "inf"}, {"type": "number", "minimum": _MAX_FLOAT}]}}

#: Every kind of component, by role prefix, in the order of model files (register a new kind here).
COMPONENTS: dict[str, Kind] = {kind.key: kind for kind in (
    Kind(Disk, "disk", "disk", False, lambda d: "the disk", "the disk",
         "The disk ([disk] table; optional, every key has a default).",
         "The rigid disk (table [disk]): tilting DOFs q1, q2 on rotational supports, constant spin Omega. Every "
         "key is optional; a missing key takes its default, which is a parameter name (Theta, Phi, k_t, d_t, h10, "
         "h20, Omega) that [parameters] must then define."),
    Kind(Pad, "pad", "pads", True, lambda p: f"pad '{p.name}' ({p.face} face)", "this pad",
         f"The pads ([[pads]] tables): at least 1, at most {MAX_PADS}.",
         "One brake pad in point contact with a disk face (one [[pads]] table per pad).", required=True,
         max_count=MAX_PADS, rules=(
             {"if": {"required": ["dofs"], "properties": {"dofs": {"minItems": 1}}}, "then": {"required": ["mass"]}},
             {"if": {"required": ["mass"]}, "then": {"required": ["dofs"], "properties": {"dofs": {"minItems": 1}}}},
             {"if": _has_dof("normal"), "then": {"required": ["k_c"]}},
             {"if": _has_dof("tangential"),
              "then": {"required": ["k_ip"], "properties": {"k_ip": _FINITE_K}}},
             {"if": {"required": ["d_ip"], "properties": {"d_ip": {"not": {"const": 0}}}},
              "then": {"required": ["k_ip"], "properties": {"k_ip": _FINITE_K}}})),
    Kind(Caliper, "caliper", "calipers", True, lambda c: f"caliper '{c.name}'", "the caliper",
         "Optional caliper masses ([[calipers]] tables).",
         "A rigid caliper (mounting) mass on springs to ground, coupling the supports of the pads mounted on it "
         "(one [[calipers]] table per caliper).",
         rules=(_positive_with("normal", "k_n"), _positive_with("tangential", "k_t"))),
)}  # fmt: skip


def _document(kind: Kind) -> None:
    """Append to a kind's class docstring its numpydoc Parameters section, written from the fields' metadata."""
    lines = ["", "Parameters", "----------"]
    for f in dataclasses.fields(kind.cls):
        has_default = f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING
        if "role" in f.metadata:
            r, typ = f.metadata["role"], "float or str"
            interval = f"{'(' if r.low_open else '['}{r.low:g}, {r.high:g}{')' if r.high_open else ']'}"
            text = (f"{r.description.format(owner=kind.schema_owner)}{f' [{r.unit}]' if r.unit else ''}, a number "
                    f"in {interval} or a parameter name.{f.metadata['note']}")
        else:
            typ, text = str(f.type), f.metadata["schema"]["description"]
        if f.default is not dataclasses.MISSING and f.default is not None and "Default" not in text:
            text += f" Default {f.default!r}."
        lines += [f"{f.name} : {typ}{', optional' if has_default else ''}",
                  *textwrap.wrap(text[0].upper() + text[1:], 100, initial_indent="    ", subsequent_indent="    ")]
    kind.cls.__doc__ = (kind.cls.__doc__ or "").rstrip() + "\n" + "\n".join(("    " + x).rstrip() for x in lines)


for _kind in COMPONENTS.values():
    _document(_kind)


def components(spec: ModelSpec) -> Iterator[tuple[Kind, Component]]:
    """Every component of a model as ``(kind, component)``, in :data:`COMPONENTS` order (``spec``: a ModelSpec)."""
    for kind in COMPONENTS.values():
        held = getattr(spec, kind.table)
        yield from ((kind, c) for c in (held if kind.many else (held,)))


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
        for kind in COMPONENTS.values():
            if kind.many:
                object.__setattr__(self, kind.table, tuple(getattr(self, kind.table)))
        object.__setattr__(self, "presets", tuple(self.presets))
        self.validate()

    def validate(self) -> None:
        """Check components, names, default values (roles) and presets."""
        from . import roles as _roles

        where = f"model '{self.name}'"
        _check_type("model", "name", self.name, str, "a string")
        _check_type(where, "parameters", self.parameters, dict, "a table of parameter values")
        for key in ("description", "reference"):
            _check_type(where, key, getattr(self, key), str, "a string")
        for kind in COMPONENTS.values():
            held = getattr(self, kind.table)
            if not kind.many:
                _check_type(where, kind.table, held, kind.cls, f"a {kind.key} table")
                continue
            if kind.required and not held:
                raise ParameterError(f"{where}: needs at least one {kind.key}")
            if kind.max_count is not None and len(held) > kind.max_count:
                raise ParameterError(f"{where}: has {len(held)} {kind.table}; at most {kind.max_count} are supported")
            for comp in held:
                if not isinstance(comp, kind.cls):
                    raise ParameterError(f"{where}: {kind.table} must be {kind.key} tables; got {comp!r}")
        names: set[str] = set()
        for kind, comp in components(self):
            comp.validate()
            if kind.many and hasattr(comp, "name"):
                if comp.name in names:
                    raise ParameterError(f"{where}: duplicate component name '{comp.name}'")
                names.add(comp.name)
        calipers = {c.name for c in self.calipers}
        for p in self.pads:
            if p.mount is not None and p.mount not in calipers:
                raise ParameterError(f"{p.label}: mount '{p.mount}' is not a caliper of the model")
        n = (2 if self.disk.tilting else 0) + sum(len(getattr(c, "dofs", ())) for _, c in components(self))
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
        """Roles (ranges, units, descriptions) of the named parameters (:func:`.roles.parameter_roles`).

        Collected once per model object (they follow from its frozen components alone; every resolution of a
        parameter set asks for them, 4 ms each on the paper's model).
        """
        cached = self.__dict__.get("_roles")
        if cached is None:
            from .roles import parameter_roles

            cached = self.__dict__["_roles"] = parameter_roles(self)
        return cached

    def parameter_names(self) -> list[str]:
        """Names of all parameters the components use, in first-use order."""
        out: list[str] = []

        def add(v: object) -> None:
            if isinstance(v, str) and v not in out:
                out.append(v)

        for _, comp in components(self):
            for f in dataclasses.fields(comp):
                v = getattr(comp, f.name)
                if "role" in f.metadata:
                    add(v)
                elif isinstance(v, FrictionLaw):
                    for x in v.values().values():
                        add(x)
        return out

    @property
    def spin(self) -> Value:
        """The disk's spin Ω: a parameter name, or the number written in the model (``disk.Omega``)."""
        return self.disk.Omega

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
