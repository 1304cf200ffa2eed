r"""Elimination of the non-holonomic spin constraint (paper eqs. 40-45).

The constraint ``z0^T omega0 = q2dot sin q1 + q3dot cos q1 cos q2 = Omega``
(eq. 40) is written ``qdot = s(q_m) + S(q_m) q_mdot`` (eqs. 41-42), hence
``qddot = S q_mddot + (dS/dq_m)(q_mdot ⊗ q_mdot) + (ds/dq_m) q_mdot``.
Premultiplying eq. (35) by ``G = [E2 0]`` (eq. 43) removes the driving torque
``M_A z0`` and gives eq. (44)

``psi = M_m q_mddot + C_m (q_mdot ⊗ q_mdot) + D_m q_mdot + K_m q_m - f_m + h_m``

with the matrices of eq. (45).  ``h_m = G Cstar0 (s ⊗ s)`` is not printed in
the paper; it vanishes identically for an axisymmetric disk because pure spin
about the disk axis has ``omega ∥ I omega`` (checked in the tests), but it is
kept so that other inertia tensors stay correct.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType
from typing import Any, Sequence

from .kinematics import dmat_dvec, kron

__all__ = ["SpinConstraint", "spin_constraint", "ReducedEquations", "reduce_equations"]


@dataclass(frozen=True)
class SpinConstraint:
    """``qdot = s + S q_mdot`` (eqs. 41-42) and the derivatives needed in eq. (45)."""

    s: Any
    S: Any
    ds_dqm: Any
    dS_dqm: Any


def spin_constraint(sm: ModuleType, q_m: Sequence[Any], Omega: Any) -> SpinConstraint:
    """Build ``s``, ``S`` of eq. (42) and their derivatives with respect to ``q_m``."""
    q1, q2 = q_m
    den = sm.cos(q1) * sm.cos(q2)
    s = sm.Matrix([0, 0, Omega / den])
    S = sm.Matrix([[1, 0], [0, 1], [0, -sm.sin(q1) / den]])
    return SpinConstraint(s=s, S=S, ds_dqm=dmat_dvec(sm, s, q_m), dS_dqm=dmat_dvec(sm, S, q_m))


@dataclass(frozen=True)
class ReducedEquations:
    """The matrices of eq. (45) and the residual of eq. (44)."""

    M_m: Any
    C_m: Any
    D_m: Any
    K_m: Any
    f_m: Any
    h_m: Any
    psi: Any


def reduce_equations(
    sm: ModuleType,
    M0: Any,
    Cstar0: Any,
    con: SpinConstraint,
    q_m: Sequence[Any],
    dq_m: Sequence[Any],
    ddq_m: Sequence[Any],
    k_t: Any,
    d_t: Any,
    contact_moment: Any,
) -> ReducedEquations:
    """Apply eqs. (43)-(45).

    Parameters
    ----------
    sm : module
        Symbolic backend.
    M0, Cstar0 : Matrix
        Matrices of eqs. (36)-(37).
    con : SpinConstraint
        Constraint data of eq. (42).
    q_m, dq_m, ddq_m : sequence
        Independent coordinates ``(q1, q2)`` and their rates.
    k_t, d_t : expression
        Rotational support stiffness and damping.
    contact_moment : Matrix
        ``sum_i tilde(p_i) f_pi`` with the constraint already substituted.

    Returns
    -------
    ReducedEquations
    """
    G = sm.Matrix([[1, 0, 0], [0, 1, 0]])  # eq. (43)
    s, S = con.s, con.S
    GM0 = G * M0
    GC = G * Cstar0
    c1 = sm.cos(q_m[0])
    M_m = GM0 * S
    C_m = GM0 * con.dS_dqm + GC * kron(sm, S, S)
    D_m = GM0 * con.ds_dqm + GC * (kron(sm, s, S) + kron(sm, S, s)) + sm.Matrix([[d_t, 0], [0, d_t * c1]])
    K_m = sm.Matrix([[k_t, 0], [0, k_t * c1]])
    f_m = G * contact_moment
    h_m = GC * kron(sm, s, s)
    qv = sm.Matrix(list(q_m))
    dqv = sm.Matrix(list(dq_m))
    ddqv = sm.Matrix(list(ddq_m))
    psi = M_m * ddqv + C_m * kron(sm, dqv, dqv) + D_m * dqv + K_m * qv - f_m + h_m  # eq. (44)
    return ReducedEquations(M_m=M_m, C_m=C_m, D_m=D_m, K_m=K_m, f_m=f_m, h_m=h_m, psi=psi)
