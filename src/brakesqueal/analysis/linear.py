r"""Linearization about the silent motion (paper eqs. 47-48) and the linear model.

``Mbar dq_mddot + Dbar dq_mdot + Kbar dq_m = 0`` with the exact Jacobians of
the compiled residuals evaluated at the (numeric) silent motion and the pads'
tangential deformations eliminated quasi-statically (see
:mod:`brakesqueal.symbolic.linearize`).  :func:`pad_rate_eigenvalues` keeps
``ldot`` instead, as a descriptor system, to quantify that choice.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..numeric.compiled import CompiledModel, compiled_model
from ..parameters import Parameters
from .equilibrium import SilentMotion, parameter_vector, silent_motion

__all__ = ["ModalMixin", "LinearModel", "linearize", "jacobian_blocks_at", "pad_rate_eigenvalues", "state_matrix"]

_COLS = {"q": slice(0, 2), "dq": slice(2, 4), "ddq": slice(4, 6), "l": slice(6, 8), "dl": slice(8, 10)}


def state_matrix(M: np.ndarray, D: np.ndarray, K: np.ndarray) -> np.ndarray:
    """First-order state matrix ``[[0, E], [-M^-1 K, -M^-1 D]]`` of eq. (47)."""
    n = M.shape[-1]
    Minv_K = np.linalg.solve(M, K)
    Minv_D = np.linalg.solve(M, D)
    top = np.concatenate([np.zeros((n, n)), np.eye(n)], axis=1)
    bottom = np.concatenate([-Minv_K, -Minv_D], axis=1)
    return np.concatenate([top, bottom], axis=0)


def jacobian_blocks_at(model: CompiledModel, x: list[float], p: list[float]) -> dict[str, np.ndarray]:
    """Exact Jacobian blocks ``psi_q, ..., g_dl`` (each 2 × 2) at state ``x``."""
    jac = np.asarray(model.jacobians(x, p), dtype=float).reshape(2, 2, 10)
    return {f"{res}_{grp}": jac[i][:, sl] for i, res in enumerate(("psi", "g")) for grp, sl in _COLS.items()}


class ModalMixin:
    """State matrix, sorted eigenvalues and stability margin of ``M qddot + D qdot + K q = 0``.

    Mixed into the linear-model dataclasses, which provide ``M``, ``D``, ``K``
    (``n × n`` arrays) and a private list ``_eig`` used as a cache.
    """

    M: np.ndarray
    D: np.ndarray
    K: np.ndarray
    _eig: list[Any]

    @property
    def A(self) -> np.ndarray:
        """First-order state matrix (``2n × 2n``) for the state ``(dq, dqdot)``."""
        return state_matrix(self.M, self.D, self.K)

    @property
    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of :attr:`A` [1/s], sorted by decreasing real part, then imaginary part."""
        if not self._eig:
            lam = np.linalg.eigvals(self.A)
            self._eig.append(lam[np.lexsort((-lam.imag, -lam.real))])
        return self._eig[0]

    @property
    def max_real(self) -> float:
        """Largest real part of the eigenvalues [1/s] (> 0: the silent motion is unstable)."""
        return float(self.eigenvalues.real.max())


@dataclass(frozen=True)
class LinearModel(ModalMixin):
    """Linear model about a silent motion (eq. 47).

    Attributes
    ----------
    params : Parameters
        The parameters it was built for.
    silent : SilentMotion
        The operating point.
    M, D, K : ndarray, shape (2, 2)
        ``Mbar``, ``Dbar``, ``Kbar`` of eq. (48).
    """

    params: Parameters
    silent: SilentMotion
    M: np.ndarray
    D: np.ndarray
    K: np.ndarray
    _eig: list[Any] = field(default_factory=list, repr=False, compare=False)

    @property
    def q_m0(self) -> np.ndarray:
        """Silent-motion tilt angles [rad]."""
        return self.silent.q_m0


    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (the ``brakesqueal linearize --format json`` schema)."""
        return {
            "parameters": self.params.to_json_dict(),
            "q_m0": [float(v) for v in self.q_m0],
            "M": self.M.tolist(),
            "D": self.D.tolist(),
            "K": self.K.tolist(),
            "eigenvalues": [[float(z.real), float(z.imag)] for z in self.eigenvalues],
        }


def linearize(params: Parameters, *, model: CompiledModel | None = None) -> LinearModel:
    """Find the silent motion and linearize about it (eqs. 46-48).

    Parameters
    ----------
    params : Parameters
        Model parameters.
    model : CompiledModel, optional
        Compiled model (default: the cached one).

    Returns
    -------
    LinearModel

    Raises
    ------
    SilentMotionError
        If the silent motion does not exist or a pad loses contact.

    Notes
    -----
    Pads are quasi-static (``ldot = 0``); at the trivial silent motion this is
    exact to first order.  Assumes sliding contact at both pads.
    """
    model = model or compiled_model()
    sm = silent_motion(params, model=model)
    p = parameter_vector(params)
    b = jacobian_blocks_at(model, sm.state(), p)
    P = b["psi_l"] @ np.linalg.inv(b["g_l"])
    M = b["psi_ddq"].copy()
    D = b["psi_dq"] - P @ b["g_dq"]
    K = b["psi_q"] - P @ b["g_q"]
    return LinearModel(params=params, silent=sm, M=M, D=D, K=K)


def pad_rate_eigenvalues(params: Parameters, *, model: CompiledModel | None = None) -> np.ndarray:
    """Finite eigenvalues when the pads' tangential rates ``ldot`` are kept.

    The linearized ``psi`` (eq. 44) and ``g`` (eqs. 33-34) form the descriptor
    system ``E xdot = A x`` in ``x = (dq_m, dq_mdot, dl)``; ``g_dl`` (zero at the
    trivial silent motion) turns each pad's ``l`` into a first-order state, the
    "spurious pad mode".  Comparing with :func:`linearize`, which sets
    ``ldot = 0`` (quasi-static pads), quantifies that modelling choice.

    Parameters
    ----------
    params : Parameters
        Model parameters.
    model : CompiledModel, optional
        Compiled model (default: the cached one of
        :func:`~brakesqueal.numeric.compiled.compiled_model`).

    Returns
    -------
    ndarray of complex, shape (m,)
        The finite generalized eigenvalues [1/s] of ``(A, E)`` (``m <= 6``;
        infinite ones, from a singular ``E``, are dropped), sorted by
        decreasing real part, then decreasing imaginary part.

    Raises
    ------
    SilentMotionError
        If the silent motion does not exist or a pad loses contact.
    """
    import scipy.linalg

    model = model or compiled_model()
    sm = silent_motion(params, model=model)
    b = jacobian_blocks_at(model, sm.state(), parameter_vector(params))
    Z, I2 = np.zeros((2, 2)), np.eye(2)
    E = np.block([[I2, Z, Z], [Z, b["psi_ddq"], b["psi_dl"]], [Z, Z, b["g_dl"]]])
    A = np.block([[Z, I2, Z], [-b["psi_q"], -b["psi_dq"], -b["psi_l"]], [-b["g_q"], -b["g_dq"], -b["g_l"]]])
    lam = scipy.linalg.eigvals(A, E)
    lam = lam[np.isfinite(lam)]
    return lam[np.lexsort((-lam.imag, -lam.real))]
