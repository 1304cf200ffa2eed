r"""Matrix form of the Euler equations of the disk (paper eqs. 35-38).

``M0(q) qddot + Cstar0(q) (qdot ⊗ qdot) = sum m0``, all in the fixed frame, with

* ``M0 = A I3 J_R3`` (eq. 36) and
* ``Cstar0 = A I3 H_R3 + A tilde(J_R3) (I3 J_R3 ⊗ E3)`` (eq. 37), where the
  matrix tilde is the row-block convention of :mod:`.kinematics`.

For comparison (and the benchmark of the paper's 5 % claim) the same
left-hand side is also built without Kronecker products, by differentiating
the angular momentum ``A I3 J_R3 qdot`` along the motion with the chain rule.
"""

from __future__ import annotations

from types import ModuleType
from typing import Any, Sequence

from .kinematics import CardanKinematics, kron, tilde_matrix

__all__ = ["euler_matrices", "support_moment", "angular_momentum_rate"]


def euler_matrices(sm: ModuleType, kin: CardanKinematics, I3: Any) -> tuple[Any, Any]:
    """Mass matrix ``M0`` (eq. 36) and Kronecker gyroscopic matrix ``Cstar0`` (eq. 37).

    Parameters
    ----------
    sm : module
        Symbolic backend.
    kin : CardanKinematics
        Disk kinematics.
    I3 : Matrix
        Inertia tensor about O in the body frame, ``diag(Theta, Theta, Phi)``.

    Returns
    -------
    M0 : Matrix
        3 × 3.
    Cstar0 : Matrix
        3 × 9.
    """
    A, J3, H3 = kin.A, kin.J_R3, kin.H_R3
    AI = A * I3
    M0 = AI * J3  # eq. (36)
    Cstar0 = AI * H3 + A * tilde_matrix(sm, J3) * kron(sm, I3 * J3, sm.eye(3))  # eq. (37)
    return M0, Cstar0


def support_moment(sm: ModuleType, kin: CardanKinematics, k_t: Any, d_t: Any, dq: Sequence[Any]) -> Any:
    """Moment of the rotational supports about O (first two terms of eq. 38).

    ``-x0 (k_t q1 + d_t q1dot) - y1 (k_t q2 + d_t q2dot)``.  The printed eq. (38)
    writes ``k1, d1, k2, d2`` here; the rotational supports ``k_t, d_t`` are
    meant, as eq. (45) and the paper's text show (see ``docs/paper-errata.md``).
    """
    q1, q2 = kin.q[0], kin.q[1]
    x0 = kin.A1[:, 0]
    y1 = kin.A1[:, 1]
    return -x0 * (k_t * q1 + d_t * dq[0]) - y1 * (k_t * q2 + d_t * dq[1])


def angular_momentum_rate(
    sm: ModuleType, kin: CardanKinematics, I3: Any, dq: Sequence[Any], ddq: Sequence[Any]
) -> Any:
    """``d/dt (A I3 J_R3 qdot)`` by the chain rule, without Kronecker products.

    Used only as the comparison route for the Kronecker formulation.
    """
    qd = sm.Matrix(list(dq))
    L0 = kin.A * I3 * kin.J_R3 * qd
    out = sm.zeros(3, 1)
    for i in range(3):
        acc = sm.Integer(0)
        for qk, dqk in zip(kin.q, dq):
            acc += L0[i].diff(qk) * dqk
        for dqk, ddqk in zip(dq, ddq):
            acc += L0[i].diff(dqk) * ddqk
        out[i] = acc
    return out
