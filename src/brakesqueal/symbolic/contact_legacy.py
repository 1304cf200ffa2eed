r"""Frictional point contacts of massless pads with the disk (paper eqs. 12-34).

A :class:`PadSymbols` bundles the symbols of one pad; :func:`pad_contact`
builds every contact quantity of that pad from the disk kinematics.  The
paper's two pads are ``side=+1`` (upper face, at ``z = -h10``) and ``side=-1``
(lower face, at ``z = +h20``); both lie on the line ``y0 = -r``.

Notes
-----
* The contact point height ``h_i`` is the third row of eq. (16) solved by
  Cramer's rule: the pad line ``p_li + h z0`` meets the disk face plane
  ``z3 · p = z_K`` (``z_K = -h10`` or ``+h20``, the body-frame offset of the
  face, eqs. 17-18), hence ``h = (z_K - z3·p_l) / (z3·z0)``.
* The relative velocity ``v_r = A d/dt(A^T p) = pdot - omega × p`` (eqs. 21-24)
  is the velocity of the pad's contact point relative to the disk material
  point under it.  ``pdot`` contains the pad's tangential rate ``ldot``.
* The tangential equilibrium of the massless pad (eqs. 33-34) is stored as the
  residual ``g = l + c_ip (x0 · f_p + mu N0)`` with the compliance
  ``c_ip = 1/k_ip``: ``c_ip = 0`` is a rigid tangential support (``l = 0``).
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType
from typing import Any, Sequence

from .kinematics import tilde

__all__ = ["PadSymbols", "PadContact", "pad_contact"]


@dataclass(frozen=True)
class PadSymbols:
    """Symbols of one massless pad.

    Attributes
    ----------
    side : int
        ``+1`` for the upper pad (face at ``z0 = -h0``), ``-1`` for the lower
        pad (face at ``z0 = +h0``).
    k, d : expression
        Normal support stiffness and damping (``k1``/``d1`` or ``k2``/``d2``).
    c_ip : expression
        Tangential compliance ``1/k_ip``.
    mu : expression
        Coefficient of kinetic friction.
    h0 : expression
        Distance from O to the pad's disk face (``h10`` or ``h20``).
    l, dl : expression
        Tangential spring deformation and its rate.
    """

    side: int
    k: Any
    d: Any
    c_ip: Any
    mu: Any
    h0: Any
    l: Any
    dl: Any


@dataclass(frozen=True)
class PadContact:
    """Contact quantities of one pad (fixed-frame components).

    Attributes
    ----------
    h : expression
        Normal displacement of the pad (eqs. 12-16).
    hdot : expression
        Its time derivative.
    p : Matrix
        Contact point position (eqs. 12-13).
    v_r : Matrix
        Relative sliding velocity (eqs. 23-24).
    t_p : Matrix
        Friction direction on the disk (eqs. 25-26).
    F_n, F_t : expression
        Normal and friction force magnitudes (eqs. 29-32).
    f_p : Matrix
        Contact force on the disk (eqs. 27-28).
    moment : Matrix
        Its moment about O, ``tilde(p) f_p`` (a term of eq. 38).
    g : expression
        Residual of the pad's tangential equilibrium (eqs. 33-34).
    """

    h: Any
    hdot: Any
    p: Any
    v_r: Any
    t_p: Any
    F_n: Any
    F_t: Any
    f_p: Any
    moment: Any
    g: Any


def pad_contact(
    sm: ModuleType,
    pad: PadSymbols,
    *,
    r: Any,
    N0: Any,
    z3: Any,
    omega0: Any,
    q: Sequence[Any],
    dq: Sequence[Any],
) -> PadContact:
    """Build the contact quantities of one pad.

    Parameters
    ----------
    sm : module
        Symbolic backend.
    pad : PadSymbols
        The pad.
    r, N0 : expression
        Effective braking radius and normal preload.
    z3 : Matrix
        Disk axis in the fixed frame (third column of ``A``).
    omega0 : Matrix
        Disk angular velocity in the fixed frame, ``J_R0 qdot`` (eq. 6).
    q, dq : sequence
        Generalized coordinates the geometry depends on and their rates.

    Returns
    -------
    PadContact
    """
    s = pad.side
    z0 = sm.Matrix([0, 0, 1])
    p_l = sm.Matrix([pad.l, -r, -s * pad.h0])  # eqs. (14)-(15)
    z_K = -s * pad.h0  # face offset in the body frame, eqs. (17)-(18)
    z3_dot_pl = z3[0] * p_l[0] + z3[1] * p_l[1] + z3[2] * p_l[2]
    h = (z_K - z3_dot_pl) / z3[2]  # eq. (16), third row (Cramer)
    p = p_l + z0 * h  # eqs. (12)-(13)
    coords = list(q) + [pad.l]
    rates = list(dq) + [pad.dl]
    hdot = sum((h.diff(c) * v for c, v in zip(coords, rates)), sm.Integer(0))
    pdot = sm.Matrix([pad.dl, 0, hdot])
    v_r = pdot - tilde(sm, omega0) * p  # eqs. (21)-(24)
    speed = sm.sqrt(v_r[0] ** 2 + v_r[1] ** 2 + v_r[2] ** 2)
    t_p = v_r / speed  # eqs. (25)-(26)
    # eqs. (29)-(30): z0-equilibrium of the massless pad
    F_n = (s * N0 - pad.k * h - pad.d * hdot) / (s * z3[2] + pad.mu * t_p[2])
    F_t = pad.mu * F_n  # eqs. (31)-(32)
    f_p = z3 * (s * F_n) + t_p * F_t  # eqs. (27)-(28)
    moment = tilde(sm, p) * f_p
    g = pad.l + pad.c_ip * (f_p[0] + pad.mu * N0)  # eqs. (33)-(34)
    return PadContact(h=h, hdot=hdot, p=p, v_r=v_r, t_p=t_p, F_n=F_n, F_t=F_t, f_p=f_p, moment=moment, g=g)
