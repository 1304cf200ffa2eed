r"""Rigid-body kinematics of the wobbling disk (paper eqs. 2-11).

Conventions
-----------
* Elementary rotations :func:`rot` are the right-handed active rotations
  ``R(x, q)``, ``R(y, q)``, ``R(z, q)``; the direction cosine matrix of the disk
  is ``A = R(x, q1) R(y, q2) R(z, q3)`` (Cardan angles, eq. 4).  Its columns are
  the body axes written in the fixed frame (eq. 5).
* The *partial derivative of a matrix with respect to a vector* (refs. [13, 14]
  of the paper) is the horizontal concatenation
  ``dA/dq = [dA/dq_1, dA/dq_2, ..., dA/dq_n]``.  With it the time derivative of
  ``J(q) qdot`` is ``J qddot + (dJ/dq)(qdot ⊗ qdot)``, so the rotational Hessian
  ``H_R = dJ_R/dq`` (eqs. 10-11) gives ``omegadot = J_R qddot + H_R (qdot ⊗ qdot)``.
* The tilde of a vector is the cross-product matrix, ``tilde(a) b = a × b``.
* The tilde of a ``3 × n`` matrix ``J`` is the ``3 × 3n`` row-block matrix
  ``tilde(J) = [tilde(e1)^T J, tilde(e2)^T J, tilde(e3)^T J]``, which satisfies
  ``tilde(J) (w ⊗ v) = (J v) × w``.  This is the only one of the two common
  conventions with which the gyroscopic term of eq. (37),
  ``A tilde(J_R3) (I J_R3 ⊗ E_3)(qdot ⊗ qdot)``, equals ``A (omega3 × I omega3)``;
  the column-block convention ``[tilde(j1), ..., tilde(jn)]`` would need
  ``(E_3 ⊗ I J_R3)`` instead.  Both facts are checked in the tests.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType
from typing import Any, Sequence

__all__ = [
    "rot",
    "tilde",
    "tilde_matrix",
    "kron",
    "dmat_dvec",
    "CardanKinematics",
    "cardan_kinematics",
]


def rot(sm: ModuleType, axis: str, q: Any) -> Any:
    """Elementary rotation matrix ``R(axis, q)`` (paper eqs. 2-4).

    Parameters
    ----------
    sm : module
        Symbolic backend (``symengine`` or ``sympy``).
    axis : {"x", "y", "z"}
        Rotation axis.
    q : expression
        Rotation angle (rad).

    Returns
    -------
    Matrix
        The 3 × 3 rotation matrix.
    """
    c, s = sm.cos(q), sm.sin(q)
    if axis == "x":
        rows = [[1, 0, 0], [0, c, -s], [0, s, c]]
    elif axis == "y":
        rows = [[c, 0, s], [0, 1, 0], [-s, 0, c]]
    elif axis == "z":
        rows = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    else:
        raise ValueError(f"axis must be 'x', 'y' or 'z'; got {axis!r}")
    return sm.Matrix(rows)


def tilde(sm: ModuleType, a: Any) -> Any:
    """Cross-product matrix of a 3-vector: ``tilde(a) @ b == a × b``."""
    return sm.Matrix([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


def tilde_matrix(sm: ModuleType, J: Any) -> Any:
    """Tilde of a ``3 × n`` matrix, row-block convention (see module notes).

    ``tilde_matrix(J) = [tilde(e1)^T J, tilde(e2)^T J, tilde(e3)^T J]``, so that
    ``tilde_matrix(J) @ kron(w, v) == (J v) × w`` for ``w`` in R^3, ``v`` in R^n.
    For ``n = 1`` it reduces to :func:`tilde`.
    """
    eye = sm.eye(3)
    blocks = [-tilde(sm, eye[:, i]) * J for i in range(3)]
    out = blocks[0]
    for b in blocks[1:]:
        out = out.row_join(b)
    return out


def kron(sm: ModuleType, A: Any, B: Any) -> Any:
    """Kronecker product ``A ⊗ B`` of two matrices."""
    m, n = A.shape
    p, r = B.shape
    out = sm.zeros(m * p, n * r)
    for i in range(m):
        for j in range(n):
            a = A[i, j]
            if a == 0:
                continue
            for k in range(p):
                for l in range(r):
                    out[i * p + k, j * r + l] = a * B[k, l]
    return out


def dmat_dvec(sm: ModuleType, A: Any, q: Sequence[Any]) -> Any:
    """Partial derivative of a matrix with respect to a vector (paper refs. [13, 14]).

    Returns ``[dA/dq_1, ..., dA/dq_n]`` (horizontal concatenation), the
    definition for which ``d/dt (A(q) x) = A xdot + (dA/dq)(qdot ⊗ x)``.
    """
    out = A.diff(q[0])
    for qi in q[1:]:
        out = out.row_join(A.diff(qi))
    return out


@dataclass(frozen=True)
class CardanKinematics:
    """Direction cosines, rotational Jacobians and Hessians of the disk.

    Attributes
    ----------
    A : Matrix
        ``A = 0A3 = R(x,q1) R(y,q2) R(z,q3)`` (eq. 4).
    A1, A2 : Matrix
        Intermediate frames ``0A1``, ``0A2`` (eqs. 2, 3).
    J_R0, J_R3 : Matrix
        Rotational Jacobians in the fixed and body frames (eqs. 8, 9).
    H_R0, H_R3 : Matrix
        Rotational Hessians ``dJ_R/dq`` (eqs. 10, 11), each ``3 × 9``.
    q : tuple
        The Cardan angles ``(q1, q2, q3)``.
    """

    A: Any
    A1: Any
    A2: Any
    J_R0: Any
    J_R3: Any
    H_R0: Any
    H_R3: Any
    q: tuple[Any, ...]


def cardan_kinematics(sm: ModuleType, q: Sequence[Any]) -> CardanKinematics:
    """Kinematics of a body turned by Cardan angles x-y-z (eqs. 2-11).

    Parameters
    ----------
    sm : module
        Symbolic backend.
    q : sequence of 3 symbols
        ``(q1, q2, q3)``: rotations about ``x0``, ``y1`` and ``z2``.

    Returns
    -------
    CardanKinematics
    """
    q1, q2, q3 = q
    A1 = rot(sm, "x", q1)  # eq. (2)
    A2 = A1 * rot(sm, "y", q2)  # eq. (3)
    A = A2 * rot(sm, "z", q3)  # eq. (4)
    # eq. (8): columns x1, y2, z3 of the frames in which each angle acts
    J_R0 = A1[:, 0].row_join(A2[:, 1]).row_join(A[:, 2])
    J_R3 = A.T * J_R0  # eq. (9)
    qv = tuple(q)
    H_R0 = dmat_dvec(sm, J_R0, qv)  # eq. (10)
    H_R3 = dmat_dvec(sm, J_R3, qv)  # eq. (11)
    return CardanKinematics(A=A, A1=A1, A2=A2, J_R0=J_R0, J_R3=J_R3, H_R0=H_R0, H_R3=H_R3, q=qv)
