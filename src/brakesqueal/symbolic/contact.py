r"""Frictional point contact of one pad with the disk (paper eqs. 12-34, generalized).

This is the one implementation of pad contact used for every model.  A pad
sits at angle ``a`` on the line ``Rz(a) (0, -r, 0) + l Rz(a) x0`` (the paper's
pads have ``a = 0``, eqs. 14-15) and touches the face ``z0 = -s h0`` of the
disk (``s = +1`` upper face, ``s = -1`` lower face, eqs. 17-18).

* Contact point height: the third row of eq. (16), solved by Cramer's rule:
  the pad line ``p_l + h z0`` meets the disk face ``z3 . p = -s h0``, hence
  ``h = (-s h0 - z3 . p_l) / (z3 . z0)``; the contact point is ``p = p_l + h z0``
  (eqs. 12-13).
* Relative sliding velocity ``v_r = pdot - omega x p`` (eqs. 21-24): the
  velocity of the pad's contact point relative to the disk material point
  under it.  ``pdot`` contains the pad's tangential rate ``ldot`` (no
  quasi-static assumption here; see :mod:`brakesqueal.analysis.linear` for
  how the rates enter the linearization).
* Friction direction ``t_p = v_r / |v_r|`` (eqs. 25-26) and coefficient
  ``mu(|v_r|)`` of the pad's friction law.
* Normal force: a massless normal direction gives eqs. (29)-(30),
  ``F_n = F_s / (s z3_z + mu t_pz)`` with the support force
  ``F_s = s N0 - k (h - w_m) - d (hdot - w_mdot)``; a pad with a normal DOF
  ``w`` has the contact law ``F_n = N0 + k_c delta + d_c deltadot``,
  ``delta = s (w - h)``.
* Contact force on the disk ``f_p = s F_n z3 + mu F_n t_p`` (eqs. 27-28, 31-32).
* Tangential balance of a massless pad (eqs. 33-34) as the residual
  ``g = (l - u_m) + c_ip (e_t . f_p + mu* N0 + d_ip (ldot - u_mdot))`` with the
  compliance ``c_ip = 1/k_ip`` (0 = rigid), the preload friction
  ``mu* = mu(Omega r)`` at the nominal sliding speed, so that ``l`` is measured
  from the silent motion, and an optional tangential damper ``d_ip`` in parallel
  with the spring (not in the paper; 0 there).  The damper adds ``c_ip d_ip`` to
  ``dg/dldot``, whose other terms shrink with the normal force (to the support
  damper's share, of either sign, at lift-off), so the pad's rate stays
  determined down to and through lift-off (``docs/simulation.md``, unilateral
  contact).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from types import ModuleType
from typing import TYPE_CHECKING, Any, Callable

from .kinematics import tilde

if TYPE_CHECKING:
    from ..model.components import FrictionLaw

__all__ = ["PadContact", "pad_contact", "friction_coefficient", "angle_cos_sin"]


@dataclass(frozen=True)
class PadContact:
    """Contact quantities of one pad (fixed-frame components).

    Attributes
    ----------
    p : Matrix
        Contact point (eqs. 12-13).
    h, hdot : expression
        Height of the contact point along ``z0`` (eq. 16) and its rate.
    v_r : Matrix
        Relative sliding velocity (eqs. 21-24).
    speed : expression
        ``|v_r|``.
    t_p : Matrix
        Friction direction on the disk (eqs. 25-26).
    mu : expression
        Friction coefficient at the actual sliding speed.
    F_n : expression
        Normal force (eqs. 29-30, or the contact law of a pad with a normal DOF).
    f_p : Matrix
        Contact force on the disk (eqs. 27-28).
    moment : Matrix
        Its moment about O, ``tilde(p) f_p`` (a term of eq. 38).
    f_t : expression
        Component of ``f_p`` along the pad's tangential direction ``e_t``.
    support_normal : expression
        Force of the pad's normal support on the pad (``F_s``; equals the
        contact force's ``z0`` component for a massless normal direction).
    g : expression or None
        Residual of the tangential balance (eqs. 33-34, plus the damper
        ``d_ip`` when given), for a massless pad with a finite tangential
        stiffness.
    mu_star : expression
        Friction coefficient at the nominal sliding speed ``Omega r`` (preload).
    """

    p: Any
    h: Any
    hdot: Any
    v_r: Any
    speed: Any
    t_p: Any
    mu: Any
    F_n: Any
    f_p: Any
    moment: Any
    f_t: Any
    support_normal: Any
    g: Any
    mu_star: Any


def angle_cos_sin(sm: ModuleType, deg: float) -> tuple[Any, Any]:
    """Exact ``cos``/``sin`` of an angle in degrees (a rational multiple of pi)."""
    fr = Fraction(deg).limit_denominator(10**6)
    a = sm.pi * sm.Integer(fr.numerator) / sm.Integer(fr.denominator * 180)
    return sm.cos(a), sm.sin(a)


def friction_coefficient(sm: ModuleType, law: FrictionLaw, v: Any, val: Callable[[Any], Any]) -> Any:
    """``mu(v)`` of a :class:`~brakesqueal.model.components.FrictionLaw` (``val`` maps fields to symbols).

    The formula is the law's own (:data:`brakesqueal.model.friction.LAWS`).
    """
    return law.definition.formula(sm, v, {k: val(x) for k, x in law.values().items()})


def pad_contact(
    sm: ModuleType,
    *,
    side: int,
    h0: Any,
    base: Any,
    e_t: Any,
    l: Any,
    z3: Any,
    omega0: Any,
    rate: Callable[[Any], Any],
    friction: Callable[[Any], Any],
    N0: Any,
    nominal_speed: Any,
    k: Any,
    d: Any,
    w_m: Any,
    normal_dof: Any = None,
    k_c: Any = None,
    d_c: Any = None,
    u_m: Any = None,
    compliance: Any = None,
    engaged: Any = None,
    damping_t: Any = None,
) -> PadContact:
    """Build the contact quantities of one pad.

    Parameters
    ----------
    sm : module
        Symbolic backend.
    side : {+1, -1}
        Upper (``+1``, face ``z0 = -h0``) or lower (``-1``, face ``z0 = +h0``) face.
    h0 : expression
        Distance from O to the pad's face.
    base, e_t : Matrix
        Point of the pad line at ``l = 0`` and its tangential direction.
    l : expression
        Tangential position of the pad on its line.
    z3 : Matrix
        Disk axis in the fixed frame.
    omega0 : Matrix
        Disk angular velocity in the fixed frame (constraint substituted).
    rate : callable
        Time derivative along the motion of an expression of the coordinates.
    friction : callable
        ``mu(v)`` of the pad's friction law.
    N0 : expression
        Normal preload.
    nominal_speed : expression
        ``Omega r``: the sliding speed of the silent motion (preload friction).
    k, d : expression
        Normal support stiffness and damping.
    w_m : expression
        Normal displacement of the support's mount (a caliper; 0 for ground).
    normal_dof, k_c, d_c : expression, optional
        The pad's normal coordinate ``w`` (a pad with mass moving normally)
        and its contact stiffness and damping.
    u_m : expression, optional
        Tangential displacement of the mount along ``e_t`` (for ``g``).
    compliance : expression, optional
        ``1/k_ip`` of a massless pad with a finite tangential stiffness (``g`` is built).
    engaged : expression, optional
        Factor of the contact force ``f_p`` (a symbol ``chi`` for unilateral
        contact: 1 pressed, 0 lifted off); ``None`` (default) is 1.
    damping_t : expression, optional
        Tangential damping ``d_ip`` of a massless pad, in parallel with its
        spring (enters ``g``; ``None`` or 0: the paper's pad).

    Returns
    -------
    PadContact
    """
    s = side
    z0 = sm.Matrix([0, 0, 1])
    p_l = base + e_t * l + z0 * (-s * h0)  # eqs. (14)-(15), generalized
    z3_pl = z3[0] * p_l[0] + z3[1] * p_l[1] + z3[2] * p_l[2]
    h = (-s * h0 - z3_pl) / z3[2]  # eq. (16), third row (Cramer)
    p = p_l + z0 * h  # eqs. (12)-(13)
    pdot = sm.Matrix([rate(p[i]) for i in range(3)])
    v_r = pdot - tilde(sm, omega0) * p  # eqs. (21)-(24)
    speed = sm.sqrt(v_r[0] ** 2 + v_r[1] ** 2 + v_r[2] ** 2)
    t_p = v_r / speed  # eqs. (25)-(26)
    mu = friction(speed)
    mu_star = friction(nominal_speed)
    hdot, wdot_m = rate(h), rate(w_m)
    if normal_dof is not None:
        delta = s * (normal_dof - h)
        F_n = N0 + k_c * delta + d_c * rate(delta)
        F_s = s * N0 - k * (normal_dof - w_m) - d * (rate(normal_dof) - wdot_m)
    else:
        F_s = s * N0 - k * (h - w_m) - d * (hdot - wdot_m)
        F_n = F_s / (s * z3[2] + mu * t_p[2])  # eqs. (29)-(30)
    F_e = F_n if engaged is None else F_n * engaged
    f_p = z3 * (s * F_e) + t_p * (mu * F_e)  # eqs. (27)-(28), (31)-(32)
    f_t = e_t[0] * f_p[0] + e_t[1] * f_p[1] + e_t[2] * f_p[2]
    if normal_dof is None:
        F_s = f_p[2]  # massless: the support carries the contact force
    g = None
    if compliance is not None:
        rel = l - (u_m if u_m is not None else 0)
        g = rel + compliance * (f_t + mu_star * N0)  # eqs. (33)-(34)
        if damping_t is not None and damping_t != 0:
            g = g + compliance * damping_t * rate(rel)  # the tangential damper (not in the paper)
    return PadContact(p=p, h=h, hdot=hdot, v_r=v_r, speed=speed, t_p=t_p, mu=mu, F_n=F_n, f_p=f_p,
                      moment=tilde(sm, p) * f_p, f_t=f_t, support_normal=F_s, g=g, mu_star=mu_star)


def _isinf(v: Any) -> bool:
    return not isinstance(v, str) and v is not None and math.isinf(float(v))
