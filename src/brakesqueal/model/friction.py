r"""Friction laws: the coefficient of kinetic friction as a function of the sliding speed.

This module is the one place a friction law is defined: its fields (with
their unit, meaning and allowed range), its formula ``mu(v)`` (written with
the functions of the symbolic backend it is given, so this module imports no
computer algebra) and whether it depends on the sliding speed.  Adding a law
means adding one :class:`LawDef` to :data:`LAWS`; validation, TOML files,
parameter roles, the symbolic assembly (:mod:`brakesqueal.symbolic.contact`),
the pads' treatment in linearization, simulation and export all read it from
here.  See ``docs/extending.md``.

========== ================================== ==========================================
law        fields                             ``mu(v)``
========== ================================== ==========================================
coulomb    ``mu``                             ``mu`` (the paper's model, eqs. 31-32)
linear     ``mu``, ``slope``                  ``mu - slope v`` (falling for ``slope > 0``)
stribeck   ``mu``, ``mu_s``, ``v_s``          ``mu + (mu_s - mu) exp(-v / v_s)``
stick      ``mu``, ``v_reg``, ``slope``       ``mu v / sqrt(v^2 + v_reg^2) - slope v``
========== ================================== ==========================================

``stick`` is Coulomb friction with *regularised stick-slip*: the friction force
``mu(|v_r|) F_n v_r / |v_r| = F_n (mu / sqrt(|v_r|^2 + v_reg^2) - slope) v_r``
is smooth through ``v_r = 0`` and bounded by ``mu F_n`` plus the slope's term.
A pad that should stick creeps instead, at a relative speed below
``v_reg |f_t| / sqrt((mu F_n)^2 - f_t^2)`` (``f_t`` its tangential spring force),
and sliding reversals (the pad faster than the disk) are ordinary motion.  With
``slope < 0`` (a rising term) a massless pad's tangential rate is a regular
state whose balance has a root for every spring force.  The error against
set-valued Coulomb stick-slip is O(``v_reg``) plus O(``slope``) (``docs/simulation.md``, stick-slip).

The speed scales ``v_s`` and ``v_reg`` lie in :data:`SPEED_SCALE`, ``(1e-50, 1e50)`` m/s:
the generated code evaluates ``v / v_s^2`` (the derivative of ``exp(-v / v_s)``
with respect to ``v_s``) and ``(v^2 + v_reg^2)^2`` (the pads' simplified rate
terms of ``stick``), which overflow beyond (the latter also at sliding speeds
beyond 1e77 m/s).  A decay ``exp(-v / v_s)`` stays the exponential of a
non-positive number in every generated function (the symbolic simplifications
keep it in the numerators, :func:`brakesqueal.symbolic.linearize.simplify_entry`),
so at sliding speeds of many ``v_s`` it vanishes instead of overflowing.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType, ModuleType
from typing import Any

__all__ = ["FieldDef", "LawDef", "LAWS", "SPEED_SCALE", "register_law"]

_INF = math.inf

#: Allowed interval ``(low, high, low_open, high_open)`` of a law's speed scale (``v_s``, ``v_reg``) [m/s]: within
#: it ``v / v_s^2`` (sliding speeds ``v`` up to 1e100 m/s) and ``v_reg^4`` of the generated code stay finite.
SPEED_SCALE = (1e-50, 1e50, True, True)


@dataclass(frozen=True)
class FieldDef:
    """One parameter-valued field of a friction law or a component: unit, meaning and allowed interval (:mod:`.roles`).

    Attributes
    ----------
    unit, description : str
        SI unit (``""`` dimensionless) and a description template with ``{owner}``.
    low, high : float
        Interval bounds.
    low_open, high_open : bool
        Whether they are excluded.
    """

    unit: str
    description: str
    low: float
    high: float
    low_open: bool
    high_open: bool


@dataclass(frozen=True)
class LawDef:
    """A friction law.

    Attributes
    ----------
    name : str
        Its name in model files (``law = "stribeck"``).
    fields : Mapping[str, FieldDef]
        Its fields besides the kinetic coefficient ``mu`` (which every law has).
    formula : callable
        ``formula(sm, v, f)`` → ``mu(v)`` for the symbolic backend ``sm``
        (``symengine`` or ``sympy``), the sliding speed ``v`` and ``f``, a
        mapping from field name (``"mu"`` included) to its symbolic value.
    rate_dependent : bool
        Whether ``mu`` depends on ``v``; a massless pad with such a law keeps
        its tangential rate as a first-order state (``docs/theory.md``).
    text : str
        The formula as shown to users (model-file schema, ``brakesqueal show``).
    """

    name: str
    fields: Mapping[str, FieldDef]
    formula: Callable[[ModuleType, Any, Mapping[str, Any]], Any]  # (sympy, v, fields) -> mu(v), SymPy expressions
    rate_dependent: bool
    text: str = ""


_MU = FieldDef("", "kinetic friction coefficient at {owner}", 0.0, _INF, False, True)

_LAWS: dict[str, LawDef] = {}
#: Every friction law, by name (a read-only view; :func:`register_law` adds one).
LAWS: Mapping[str, LawDef] = MappingProxyType(_LAWS)
_LAWS.update({law.name: law for law in (
    LawDef("coulomb", {}, lambda sm, v, f: f["mu"], rate_dependent=False, text="mu(v) = mu"),
    LawDef("linear", {"slope": FieldDef("s/m", "friction slope -dmu/dv at {owner}", -_INF, _INF, True, True)},
           lambda sm, v, f: f["mu"] - f["slope"] * v, rate_dependent=True, text="mu(v) = mu - slope * v"),
    LawDef("stribeck", {"mu_s": FieldDef("", "static friction coefficient (Stribeck) at {owner}", 0.0, _INF,
                                         False, True),
                        "v_s": FieldDef("m/s", "Stribeck speed at {owner}", *SPEED_SCALE)},
           lambda sm, v, f: f["mu"] + (f["mu_s"] - f["mu"]) * sm.exp(-v / f["v_s"]), rate_dependent=True,
           text="mu(v) = mu + (mu_s - mu) * exp(-v / v_s)"),
    LawDef("stick", {"v_reg": FieldDef("m/s", "stick-slip regularisation speed at {owner}", *SPEED_SCALE),
                     "slope": FieldDef("s/m", "friction slope -dmu/dv (beyond stick) at {owner}", -_INF, _INF,
                                       True, True)},
           # written as v * (...) so that mu(v) v_r / v cancels symbolically: the force is defined at v_r = 0
           lambda sm, v, f: v * (f["mu"] / sm.sqrt(v**2 + f["v_reg"] ** 2) - f["slope"]), rate_dependent=True,
           text="mu(v) = mu * v / sqrt(v^2 + v_reg^2) - slope * v"),
)})


def register_law(law: LawDef) -> None:
    """Add a friction law (model files, validation, the equations and the pads' treatment then know it).

    Parameters
    ----------
    law : LawDef
        The law; its name must be new.

    Raises
    ------
    ValueError
        A law of that name exists.
    """
    if law.name in _LAWS:
        raise ValueError(f"a friction law named {law.name!r} exists already")
    _LAWS[law.name] = law


#: The field every law has.
MU_FIELD = _MU
