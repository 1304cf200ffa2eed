r"""Linearization about the silent motion (paper eqs. 47-48) for any model.

The residuals are linearized with their exact compiled Jacobians at the
silent motion ``x0 = (Q0, 0, 0, L0, 0)``:

.. math::
    M\,\delta\ddot Q + D\,\delta\dot Q + K\,\delta Q + R_L\,\delta L + R_{\dot L}\,\delta\dot L = 0,\qquad
    G_Q\,\delta Q + G_{\dot Q}\,\delta\dot Q + G_L\,\delta L + G_{\dot L}\,\delta\dot L = 0 .

**How the pads' tangential rates enter.**  A massless pad with a finite
tangential stiffness has the deformation ``l`` as an unknown whose rate
``ldot`` changes the sliding velocity.  Where its rate columns ``R_Ldot``
and ``G_Ldot`` vanish — constant friction at the *trivial* silent motion,
proved symbolically (``docs/theory.md``) — ``l`` follows quasi-statically
and is eliminated exactly: ``delta L = -G_L^{-1}(G_Q delta Q + G_Qdot delta Qdot)``,
giving the second-order ``M, D, K`` of eq. (47).  Otherwise the pad keeps
its first-order dynamics and the linear model is the descriptor system
``E xi' = A xi`` in ``xi = (delta Q, delta Qdot, delta L)`` (e.g. a falling
friction law gives the pad mode ``lambda = -k_ip/(N0 mu')``; at a tilted
silent motion the pads' normal dampers couple into the tangential balance).
``pad_rates="quasi-static"`` sets ``ldot := 0`` everywhere instead (the
approximation of earlier versions; exact only in the first case).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .equilibrium import SilentMotion, as_parameters, parameter_vector, silent_motion

if TYPE_CHECKING:
    from ..codegen.compiled import CompiledModel
    from ..codegen.engine import Engine

__all__ = ["ModalMixin", "LinearModel", "linearize", "state_matrix", "jacobian_blocks_at", "pad_rate_eigenvalues",
           "PAD_RATES", "accurate_jacobian", "eliminate_algebraic", "descriptor_eigenvalues", "qep_eigenvalues",
           "sort_eigenvalues"]

#: Treatments of the pads' tangential rates (see the module docstring).
PAD_RATES = ("kept", "quasi-static")


def state_matrix(M: np.ndarray, D: np.ndarray, K: np.ndarray) -> np.ndarray:
    """First-order state matrix ``[[0, E], [-M^-1 K, -M^-1 D]]`` of eq. (47)."""
    n = M.shape[-1]
    Minv_K = np.linalg.solve(M, K)
    Minv_D = np.linalg.solve(M, D)
    top = np.concatenate([np.zeros((n, n)), np.eye(n)], axis=1)
    bottom = np.concatenate([-Minv_K, -Minv_D], axis=1)
    return np.concatenate([top, bottom], axis=0)


def qep_eigenvalues(M: np.ndarray, D: np.ndarray, K: np.ndarray, *, finite: bool = True) -> np.ndarray:
    """Every eigenvalue of ``λ² M + λ D + K`` by QZ of the first companion pencil after the scaling of Fan, Lin &
    Van Dooren (SIAM J. Matrix Anal. Appl. 26 (2004) 252-256): ``λ = γ μ`` with ``γ = sqrt(‖K‖/‖M‖)`` and the
    coefficients divided by ``δ = 2/(‖K‖ + γ‖D‖)``.  For models of many DOF it keeps the smallest eigenvalues
    about ten times closer than the eigenvalues of ``[[0, I], [-M⁻¹K, -M⁻¹D]]`` (disk_brake100: 3e-10 against
    3e-9 relative between formulations).

    Parameters
    ----------
    M, D, K : ndarray, shape (n, n)
        Dense coefficient matrices.
    finite : bool
        Drop the infinite eigenvalues of a singular ``M`` (default), or keep them.

    Returns
    -------
    ndarray of complex, shape (2n,)
        The eigenvalues.
    """
    import scipy.linalg

    n = M.shape[0]
    nM, nD, nK = (float(np.linalg.norm(X, 2)) for X in (M, D, K))
    g = math.sqrt(nK / nM) if nM > 0 and nK > 0 else 1.0
    d = 2.0 / (nK + g * nD) if nK + g * nD > 0 else 1.0
    I, Z = np.eye(n), np.zeros((n, n))
    A = np.block([[Z, I], [-K * d, -D * (d * g)]])
    B = np.block([[I, Z], [Z, M * (d * g * g)]])
    with np.errstate(invalid="ignore"):
        lam = scipy.linalg.eigvals(A, B) * g
    return np.asarray(lam[np.isfinite(lam)] if finite else lam)


def pencil_eigenvalues(E: np.ndarray, A: np.ndarray, sweeps: int = 20) -> np.ndarray:
    """Finite eigenvalues of the pencil ``lambda E - A`` by QZ after power-of-two equilibration.

    Rows and columns of ``(E, A)`` are scaled jointly by powers of two (the
    eigenvalues are unchanged, exactly) until their largest entries are near
    one.  A massless pad's tangential rate coefficient can be 1e-13 of its
    stiffness term; without the scaling the QZ algorithm loses digits of both
    the huge pad mode and the slow structural modes (measured against 60-digit
    arithmetic in the tests).

    Parameters
    ----------
    E, A : ndarray, shape (m, m)
        The pencil (e.g. :attr:`LinearModel.descriptor`).
    sweeps : int
        Row/column scaling sweeps.

    Returns
    -------
    ndarray of complex
        The finite generalized eigenvalues (infinite ones dropped).
    """
    import scipy.linalg

    E, A = np.array(E, dtype=float), np.array(A, dtype=float)
    E0, A0 = E.copy(), A.copy()
    for _ in range(sweeps):
        for axis in (1, 0):
            mag = np.maximum(np.abs(E).max(axis=axis), np.abs(A).max(axis=axis))
            mag[~(mag > 0)] = 1.0
            scale = np.exp2(-np.round(np.log2(mag)))
            if axis == 1:
                E, A = E * scale[:, None], A * scale[:, None]
            else:
                E, A = E * scale[None, :], A * scale[None, :]
    lam = scipy.linalg.eigvals(A, E)
    lam = lam[np.isfinite(lam)]
    # a regular index-1 pencil has one finite eigenvalue per nonzero row of E; the scaling can push a huge but
    # finite pad mode (rate coefficient 1e-16 of its stiffness) to beta = 0: take it from the unscaled pencil
    expected = int(np.count_nonzero(np.any(E0 != 0, axis=1)))
    if lam.size < expected:
        try:  # a nonsingular E: balanced QR of E^-1 A (what 60-digit arithmetic confirms for these modes)
            raw = np.linalg.eigvals(np.linalg.solve(E0, A0)) if expected == E0.shape[0] else None
        except np.linalg.LinAlgError:
            raw = None
        if raw is None:
            raw = scipy.linalg.eigvals(A0, E0)
        raw = raw[np.isfinite(raw)]
        extra = raw[np.argsort(-np.abs(raw))][: expected - lam.size]
        lam = np.concatenate([lam, extra])
    return lam


#: Largest descriptor size whose eigenvalues :func:`descriptor_eigenvalues` computes in extended precision.
EXTENDED_MAX_SIZE = 12


def descriptor_eigenvalues(E: np.ndarray, A: np.ndarray, dps: int = 40) -> np.ndarray:
    """Finite eigenvalues of ``lambda E - A`` with the pads' own modes, accurate for every scale at once.

    A massless pad's mode can be 1e15 times the structural modes.  No double-precision route gets both right:
    QZ of the equilibrated pencil (:func:`pencil_eigenvalues`) keeps the slow modes but was measured 4 % off on a
    1.9e15 pad mode, and the balanced ``E^-1 A`` keeps that mode but moved a slow mode's real part by 16 %.  For
    a nonsingular ``E`` of size up to :data:`EXTENDED_MAX_SIZE` the eigenvalues of ``E^-1 A`` are computed with
    mpmath at ``dps`` digits from the float matrices taken exactly (about 10 ms at size 6), otherwise by
    :func:`pencil_eigenvalues`.

    Parameters
    ----------
    E, A : ndarray, shape (m, m)
        The pencil (:attr:`LinearModel.descriptor`).
    dps : int
        Decimal digits of the extended-precision route.

    Returns
    -------
    ndarray of complex
        The finite eigenvalues (unsorted).
    """
    E, A = np.asarray(E, dtype=float), np.asarray(A, dtype=float)
    m = E.shape[0]
    if m > EXTENDED_MAX_SIZE or not (np.all(np.isfinite(E)) and np.all(np.isfinite(A))):
        return pencil_eigenvalues(E, A)
    import mpmath

    from .robust import mp_balanced

    def at(digits: int) -> list[Any] | None:
        with mpmath.workdps(digits):
            try:
                S = mpmath.inverse(mpmath.matrix(E.tolist())) * mpmath.matrix(A.tolist())
                return list(mpmath.eig(mp_balanced(S)[0], left=False, right=False))
            except (ZeroDivisionError, mpmath.libmp.NoConvergence):  # a singular E, or no convergence
                return None

    def close(a: float, b: float) -> bool:
        return abs(a - b) <= 1e-12 * abs(a)

    # the matrices' entries may span 1e100 (extreme but valid parameters): the precision is doubled until two
    # successive ones agree on every eigenvalue's real and imaginary part (each to 1e-12 of itself; the real
    # part decides stability and can be 1e-40 of the imaginary one)
    prev, digits = at(dps), 2 * dps
    if prev is None:
        return pencil_eigenvalues(E, A)
    while True:
        cur = at(digits)
        if cur is None:
            return pencil_eigenvalues(E, A)
        agree = True
        for z in cur:
            w = min(prev, key=lambda v: abs(z - v))
            agree &= close(float(z.real), float(w.real)) and close(float(z.imag), float(w.imag))
        if agree or digits >= 16 * dps:
            break
        prev, digits = cur, 2 * digits
    lam = np.array([complex(z) for z in cur])
    tiny = np.abs(lam.imag) <= 1e-30 * np.abs(lam)  # a real eigenvalue's imaginary part at the dps noise
    lam[tiny] = lam[tiny].real
    return lam


def eliminate_algebraic(E: np.ndarray, A: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Eliminate the algebraic pad equations of a descriptor system (rows of ``E`` that are exactly zero).

    A kept pad whose tangential balance has no rate term at this point
    (e.g. a rigid support, ``1/k_ip = 0``: its row of ``E`` vanishes exactly)
    is an algebraic relation ``A_r xi = 0``; its deformation ``l_a`` is
    solved from it and substituted (with its derivative) into the other
    rows: ``E' = E_rest - E_la A_r,la^-1 A_r,rest``, ``A' = A_rest - A_la
    A_r,la^-1 A_r,rest``.  The finite eigenvalues are unchanged (the pencil
    loses exactly its infinite ones), so ``E'`` is regular where the reduced
    system is.

    Parameters
    ----------
    E, A : ndarray, shape (m, m)
        The descriptor (:attr:`LinearModel.descriptor
        <brakesqueal.analysis.linear.LinearModel.descriptor>`).
    k : int
        Number of pad states (the trailing ``k`` unknowns; only these are eliminated).

    Returns
    -------
    E, A : ndarray
        The reduced descriptor (unchanged when no row of ``E`` vanishes, or
        when the algebraic rows cannot be solved for pad states: the
        verdict is then undecided).
    """
    E, A = np.array(E, dtype=float), np.array(A, dtype=float)
    m = E.shape[0]
    rows = np.flatnonzero(np.all(E == 0.0, axis=1))
    if rows.size == 0 or rows.size > k:
        return E, A
    pads = np.arange(m - k, m)
    # pick as many pad unknowns as algebraic rows: the best-conditioned columns of A[rows, pads]
    import scipy.linalg

    _, _, piv = scipy.linalg.qr(A[np.ix_(rows, pads)], pivoting=True)
    cols = pads[np.sort(piv[:rows.size])]
    keep_r = np.setdiff1d(np.arange(m), rows)
    keep_c = np.setdiff1d(np.arange(m), cols)
    Arl = A[np.ix_(rows, cols)]
    try:
        X = np.linalg.solve(Arl, A[np.ix_(rows, keep_c)])  # l_a = -X xi_rest
    except np.linalg.LinAlgError:
        return E, A
    if not np.all(np.isfinite(X)):
        return E, A
    E2 = E[np.ix_(keep_r, keep_c)] - E[np.ix_(keep_r, cols)] @ X
    A2 = A[np.ix_(keep_r, keep_c)] - A[np.ix_(keep_r, cols)] @ X
    return E2, A2


def sort_eigenvalues(lam: np.ndarray) -> np.ndarray:
    """Eigenvalues in the order every linear model lists them: decreasing real part, then decreasing imaginary
    part."""
    return lam[np.lexsort((-lam.imag, -lam.real))]


class ModalMixin:
    """State matrix, sorted eigenvalues and stability margin of a linear model.

    Mixed into :class:`LinearModel`, which provides ``M``, ``D``, ``K`` and
    the optional first-order pad blocks, and a private list ``_eig`` (cache).
    """

    M: np.ndarray
    D: np.ndarray
    K: np.ndarray
    _eig: list[Any]

    @property
    def A(self) -> np.ndarray:
        """First-order state matrix for the state ``(delta Q, delta Qdot[, delta L])``."""
        return state_matrix(self.M, self.D, self.K)

    @property
    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues [1/s], sorted by decreasing real part, then imaginary part."""
        if not self._eig:
            self._eig.append(sort_eigenvalues(np.linalg.eigvals(self.A)))
        return self._eig[0]

    @property
    def max_real(self) -> float:
        """Largest real part of the eigenvalues [1/s] (> 0: the silent motion is unstable)."""
        return float(self.eigenvalues.real.max())


@dataclass(frozen=True)
class LinearModel(ModalMixin):
    """Linear model of a model about its silent motion (eq. 47, generalized).

    Attributes
    ----------
    params : Parameters
        The model and parameter values it was built for.
    silent : SilentMotion
        The operating point.
    M, D, K : ndarray, shape (n, n)
        Mass, damping and stiffness matrices (eq. 48) with the quasi-static
        pads eliminated.
    pad_states : tuple of str
        Pad deformations kept as first-order states (empty when every pad is
        quasi-static; see the module docstring).
    R_L, R_dL : ndarray, shape (n, k)
        Coupling of the kept pad states into the equations of motion.
    G_Q, G_dQ, G_ddQ, G_L, G_dL : ndarray, shape (k, n) / (k, k)
        Linearized tangential balance of the kept pads.
    pad_rates : str
        ``"kept"`` or ``"quasi-static"``.
    engine : Engine or None
        The engine it was computed with (``None`` for a model built by hand); sensitivities linearize again
        with it.
    """

    params: Any
    silent: SilentMotion
    M: np.ndarray
    D: np.ndarray
    K: np.ndarray
    pad_states: tuple[str, ...] = ()
    R_L: np.ndarray | None = None
    R_dL: np.ndarray | None = None
    G_Q: np.ndarray | None = None
    G_dQ: np.ndarray | None = None
    G_ddQ: np.ndarray | None = None
    G_L: np.ndarray | None = None
    G_dL: np.ndarray | None = None
    pad_rates: str = "kept"
    engine: Any = field(default=None, repr=False, compare=False)
    _eig: list[Any] = field(default_factory=list, repr=False, compare=False)

    # ---------------------------------------------------------------- structure
    @property
    def model(self) -> Any:
        """The :class:`~brakesqueal.model.components.ModelSpec`."""
        return self.params.model

    @property
    def coords(self) -> tuple[str, ...]:
        """Names of the coordinates."""
        return self.silent.coords

    @property
    def n(self) -> int:
        """Number of coordinates."""
        return int(self.M.shape[0])

    @property
    def q0(self) -> np.ndarray:
        """Coordinates at the silent motion (tilts [rad], displacements [m])."""
        return self.silent.q0

    @property
    def q_m0(self) -> np.ndarray:
        """Deprecated alias of :attr:`q0`, kept for one release."""
        return self.silent.q0

    @property
    def descriptor(self) -> tuple[np.ndarray, np.ndarray]:
        """``(E, A)`` of ``E xi' = A xi`` in ``xi = (delta Q, delta Qdot, delta L_kept)``."""
        n, k = self.n, len(self.pad_states)
        I, Z = np.eye(n), np.zeros((n, n))
        if k == 0:
            return np.block([[I, Z], [Z, self.M]]), np.block([[Z, I], [-self.K, -self.D]])
        Znk, Zkn = np.zeros((n, k)), np.zeros((k, n))
        assert self.R_L is not None and self.R_dL is not None and self.G_Q is not None and self.G_dQ is not None
        assert self.G_ddQ is not None and self.G_L is not None and self.G_dL is not None
        E = np.block([[I, Z, Znk], [Z, self.M, self.R_dL], [Zkn, self.G_ddQ, self.G_dL]])
        A = np.block([[Z, I, Znk], [-self.K, -self.D, -self.R_L], [-self.G_Q, -self.G_dQ, -self.G_L]])
        return E, A

    @property
    def reduced_descriptor(self) -> tuple[np.ndarray, np.ndarray]:
        """:attr:`descriptor` with the kept pads' algebraic equations eliminated (:func:`eliminate_algebraic`).

        A kept pad whose own balance has no rate term at this point (a rigid
        support, ``1/k_ip = 0``, while its rate still enters the disk's
        equations) makes ``E`` singular; the reduced pencil has the same
        finite eigenvalues and, where the system is regular, a nonsingular
        ``E`` in ``(delta Q, delta Qdot, pad states left)``.
        """
        E, A = self.descriptor
        if not self.pad_states:
            return E, A
        return eliminate_algebraic(E, A, len(self.pad_states))

    @property
    def A(self) -> np.ndarray:
        """First-order state matrix ``E^-1 A`` of :attr:`reduced_descriptor` (``2n + k`` square, less the pads
        eliminated there); its first ``2n`` components are ``(delta Q, delta Qdot)``."""
        if not self.pad_states:
            return state_matrix(self.M, self.D, self.K)
        E, A = self.reduced_descriptor
        return np.linalg.solve(E, A)

    @property
    def eigenvalues(self) -> np.ndarray:
        """Finite eigenvalues [1/s] of the linear model, sorted by decreasing real part, then imaginary part."""
        if not self._eig:
            if self.silent.method == "matrices":  # a model given by coefficient matrices (often many DOF)
                lam = qep_eigenvalues(self.M, self.D, self.K)
            elif not self.pad_states and 2 * self.n > EXTENDED_MAX_SIZE:
                lam = np.linalg.eigvals(self.A)
            else:  # every scale right at once (extreme parameters, huge pad modes): extended precision
                lam = descriptor_eigenvalues(*self.reduced_descriptor)
            self._eig.append(sort_eigenvalues(lam))
        return self._eig[0]

    def characteristic_polynomial(self) -> np.ndarray:
        """Coefficients (highest power first) of ``det(lambda E - A)`` divided by ``det(E)``, from the eigenvalues."""
        return np.real_if_close(np.poly(self.eigenvalues))

    # ---------------------------------------------------------------- views for notebooks and other tools
    def plot(self, ax: Any = None) -> Any:
        """Pole map: the eigenvalues in the complex plane with the verdict in the title; returns the figure.

        The same figure as :meth:`EigenAnalysis.plot <brakesqueal.analysis.eigen.EigenAnalysis.plot>`.
        """
        from .eigen import eigen_analysis

        return eigen_analysis(self, self.engine).plot(ax)

    def to_xarray(self) -> Any:
        """Dataset of the linear model: ``M``, ``D``, ``K`` over ``(dof, dof_j)``, and over ``mode`` the eigenvalues'
        ``real``, ``imag`` [1/s], ``frequency`` [Hz] and ``damping_ratio``; the parameters and the silent motion as
        attributes (``parameters`` as JSON, ``q0``)."""
        import json

        import xarray as xr

        lam = self.eigenvalues
        with np.errstate(invalid="ignore", divide="ignore"):
            zeta = np.where(np.abs(lam) > 0, -lam.real / np.abs(lam), np.nan)
        dofs = list(self.coords)
        mat = ("dof", "dof_j")
        return xr.Dataset(
            {"M": (mat, self.M, {"description": "mass matrix (eq. 48)"}),
             "D": (mat, self.D, {"description": "damping matrix (eq. 48)"}),
             "K": (mat, self.K, {"description": "stiffness matrix (eq. 48)"}),
             "real": ("mode", lam.real, {"units": "1/s"}), "imag": ("mode", lam.imag, {"units": "1/s"}),
             "frequency": ("mode", np.abs(lam.imag) / (2 * math.pi), {"units": "Hz"}),
             "damping_ratio": ("mode", zeta)},
            coords={"dof": dofs, "dof_j": dofs, "mode": np.arange(lam.size)},
            attrs={"model": self.model.name, "parameters": json.dumps(self.params.to_json_dict()),
                   "q0": [float(v) for v in self.q0], "pad_states": ",".join(self.pad_states),
                   "pad_rates": self.pad_rates, "max_real": self.max_real})

    def input_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(A, B, C, D)`` of ``x' = A x + B u``, ``y = C x + D u``: inputs ``u`` are generalized forces on the
        coordinates (torques [N m] on tilts, forces [N] on displacements), outputs ``y`` the coordinates.

        The state is that of :attr:`A` (``(delta Q, delta Qdot[, pad states])``); with kept pad states the input
        enters the disk's rows of the descriptor (:attr:`reduced_descriptor`) and ``B = E^-1 B_E``.
        """
        n = self.n
        if not self.pad_states:
            A = state_matrix(self.M, self.D, self.K)
            B = np.vstack([np.zeros((n, n)), np.linalg.inv(self.M)])
        else:
            E_full, _ = self.descriptor
            E, A_d = self.reduced_descriptor
            B_full = np.zeros((E_full.shape[0], n))
            B_full[n:2 * n] = np.eye(n)
            if E.shape[0] < E_full.shape[0]:  # eliminate_algebraic dropped the pads' algebraic rows (no input)
                B_full = B_full[~np.all(E_full == 0.0, axis=1)]
            A, B = np.linalg.solve(E, A_d), np.linalg.solve(E, B_full)
        C = np.zeros((n, A.shape[0]))
        C[:, :n] = np.eye(n)
        return A, B, C, np.zeros((n, n))

    def to_statespace(self) -> Any:
        """The linear model as a `python-control <https://python-control.readthedocs.io>`_ ``StateSpace``
        (optional: ``pip install 'brakesqueal[control]'``), with :meth:`input_matrices` and named signals:
        inputs ``F_<coord>``, outputs ``<coord>``, states ``<coord>``, ``<coord>_dot`` and the pad states.

        Raises
        ------
        ParameterError
            When python-control is not installed.
        """
        try:
            import control
        except ImportError:
            from ..errors import ParameterError

            raise ParameterError("to_statespace needs python-control: pip install 'brakesqueal[control]'") from None
        A, B, C, D = self.input_matrices()
        c = list(self.coords)
        states = c + [f"{q}_dot" for q in c] + list(self.pad_states)
        if len(states) != A.shape[0]:  # pads eliminated as algebraic: number the remaining states
            states = [f"x{i}" for i in range(A.shape[0])]
        return control.ss(A, B, C, D, inputs=[f"F_{q}" for q in c], outputs=c, states=states,
                          name=self.model.name)

    def _repr_html_(self) -> str:
        """A short HTML summary for notebooks: model, verdict with its carrier, the least stable eigenvalues."""
        import html

        from .eigen import eigen_analysis

        v = eigen_analysis(self, self.engine).verdict()
        lam = self.eigenvalues
        rows = "".join(f"<tr><td>{z.real:.6g}</td><td>{abs(z.imag) / (2 * math.pi):.6g}</td></tr>"
                       for z in lam[:min(lam.size, 8)])
        carrier = f", carried by {html.escape(v.carrier)}" if v.carrier else ""
        return (f"<div><b>LinearModel</b> of {html.escape(self.model.name)} ({self.n} DOF: "
                f"{html.escape(', '.join(self.coords))})<br>verdict: <b>{html.escape(v.status)}</b>, "
                f"max Re λ = {v.max_real:.6g} 1/s{carrier} (route {html.escape(v.method)})"
                f"<table><tr><th>Re λ [1/s]</th><th>f [Hz]</th></tr>{rows}</table>"
                f"{'' if lam.size <= 8 else f'<i>{lam.size - 8} more eigenvalues</i>'}</div>")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (the ``brakesqueal linearize --format json`` schema).

        Keys: ``model``, ``parameters``, ``coords``, ``q0`` (and its deprecated
        alias ``q_m0``), ``l0``, ``M``, ``D``, ``K``, ``pad_states``,
        ``pad_rates``, ``eigenvalues`` (``[re, im]`` pairs).
        """
        q0 = [float(v) for v in self.q0]
        return {
            "model": self.model.name,
            "parameters": self.params.to_json_dict(),
            "coords": list(self.coords),
            "q0": q0,
            "q_m0": q0,
            "l0": [float(v) for v in self.silent.l0],
            "M": self.M.tolist(),
            "D": self.D.tolist(),
            "K": self.K.tolist(),
            "pad_states": list(self.pad_states),
            "pad_rates": self.pad_rates,
            "eigenvalues": [[float(z.real), float(z.imag)] for z in self.eigenvalues],
        }


_MP_NAMESPACES: dict[str, dict[str, Any]] = {}

#: Relative agreement of the Jacobian at two precisions that :func:`accurate_jacobian` accepts.
JACOBIAN_AGREEMENT = 1e-15


def accurate_jacobian(cm: CompiledModel, x: Any, p: Any) -> np.ndarray:
    """``d(R, G)/dx`` at ``x`` with every entry correct to rounding, as an ``(n + m, 3n + 2m)`` array.

    At a tilted silent motion several entries are differences of terms that
    cancel to ``O(q^2)``: e.g. the pads' rate coefficient ``G_Ldot`` of
    rate-independent friction without normal dampers is about ``1e-24`` of
    the terms it is computed from.  Evaluated in double precision it is
    rounding noise of either sign (or exactly 0), and the pad mode
    ``-G_L/G_Ldot`` it implies a spurious ``±1e20``.  The generated source
    is therefore evaluated in mpmath from the same float ``x`` and ``p``
    (taken exactly) at 40 and 80 digits, doubling until two successive
    precisions agree to :data:`JACOBIAN_AGREEMENT` in every entry (a few
    milliseconds).

    Raises
    ------
    FloatingPointError
        If no precision up to 640 digits gives agreement (not met in practice).
    """
    import mpmath

    ns = _MP_NAMESPACES.get(cm.source)
    if ns is None:
        ns = dict(sin=mpmath.sin, cos=mpmath.cos, tan=mpmath.tan, sqrt=mpmath.sqrt, exp=mpmath.exp,
                  log=mpmath.log, abs=abs, pi=mpmath.pi)
        exec(compile(cm.source, "<brakesqueal generated model (mpmath)>", "exec"), ns)
        _MP_NAMESPACES[cm.source] = ns
    jac = ns["jacobians"]

    def at(dps: int) -> np.ndarray:
        with mpmath.workdps(dps):
            vals = jac([mpmath.mpf(float(v)) for v in x], [mpmath.mpf(float(v)) for v in p])
            return np.array([float(v) for v in vals], dtype=float)

    prev, dps = at(40), 80
    while dps <= 640:
        cur = at(dps)
        if np.all(np.abs(cur - prev) <= JACOBIAN_AGREEMENT * np.abs(cur)):
            return cur.reshape(cm.n + cm.m, cm.nx)
        prev, dps = cur, 2 * dps
    raise FloatingPointError("the Jacobian at the silent motion could not be evaluated accurately")


def _blocks(cm: CompiledModel, x: list[float] | None, p: list[float]) -> dict[str, np.ndarray]:
    """Jacobian blocks at ``x`` (``None``: the zero state, with its structural zeros exact; otherwise
    :func:`accurate_jacobian`)."""
    n, m = cm.n, cm.m
    J = cm.zero_jacobian_matrix(p) if x is None else accurate_jacobian(cm, x, p)
    cols = {"Q": slice(0, n), "dQ": slice(n, 2 * n), "ddQ": slice(2 * n, 3 * n), "L": slice(3 * n, 3 * n + m),
            "dL": slice(3 * n + m, 3 * n + 2 * m)}
    out = {}
    for res, rows in (("R", slice(0, n)), ("G", slice(n, n + m))):
        for k, c in cols.items():
            out[f"{res}_{k}"] = J[rows, c]
    return out


def jacobian_blocks_at(cm: CompiledModel, x: list[float], p: list[float]) -> dict[str, np.ndarray]:
    """Exact Jacobian blocks at state ``x``: keys ``R_Q, R_dQ, R_ddQ, R_L, R_dL, G_Q, ..., G_dL``.

    For the paper's model the old keys ``psi_q, psi_dq, psi_ddq, psi_l, psi_dl, g_q, ...`` are
    also present (``psi`` = ``R``, ``g`` = ``G``).
    """
    b = _blocks(cm, x, p)
    for res, old in (("R", "psi"), ("G", "g")):
        for k, o in (("Q", "q"), ("dQ", "dq"), ("ddQ", "ddq"), ("L", "l"), ("dL", "dl")):
            b[f"{old}_{o}"] = b[f"{res}_{k}"]
    return b


def linearize(engine: Engine, params: Any, *, pad_rates: str = "kept") -> LinearModel:
    """Find the silent motion and linearize about it (eqs. 46-48), for any model.

    Parameters
    ----------
    engine : Engine
        The model's engine (:func:`brakesqueal.codegen.build`).
    params : Parameters
        The model's parameter values.
    pad_rates : {"kept", "quasi-static"}
        How the massless pads' tangential rates enter (module docstring).
        ``"kept"`` (default) is exact for the model; ``"quasi-static"`` sets
        ``ldot := 0`` (exact only for rate-independent friction at the trivial
        silent motion).

    Returns
    -------
    LinearModel

    Raises
    ------
    ParameterError
        For an unknown ``pad_rates``.
    SilentMotionError
        A subclass saying why there is no usable silent motion
        (:func:`~brakesqueal.analysis.equilibrium.silent_motion`).

    Notes
    -----
    Assumes sliding contact at every pad at the silent motion (checked).
    """
    from ..errors import ParameterError

    if pad_rates not in PAD_RATES:
        raise ParameterError(f"pad_rates must be one of {', '.join(PAD_RATES)}; got {pad_rates!r}")
    params = as_parameters(params)
    sm = silent_motion(engine, params)
    if engine.caps.kind == "matrices":  # a model given by coefficient matrices: they are the linearization
        engine.require_dense("linearize")  # type: ignore[attr-defined]
        Ms, Ds, Ks = (X.toarray() if hasattr(X, "toarray") else np.array(X, dtype=float)
                      for X in engine.linear_at(params))  # type: ignore[attr-defined]
        return LinearModel(params=params, silent=sm, engine=engine, M=Ms, D=Ds, K=Ks, pad_rates=pad_rates)
    cm = engine.compiled
    p = parameter_vector(params)
    b = _blocks(cm, None if sm.trivial else sm.state(), p)
    m = cm.m
    M, D, K = b["R_ddQ"].copy(), b["R_dQ"].copy(), b["R_Q"].copy()
    if m == 0:
        return LinearModel(params=params, silent=sm, engine=engine, M=M, D=D, K=K, pad_rates=pad_rates)
    if pad_rates == "quasi-static":
        dyn = np.zeros(m, dtype=bool)
    else:
        dyn = np.any(b["R_dL"] != 0.0, axis=0) | np.any(b["G_dL"] != 0.0, axis=0) | np.any(b["G_dL"] != 0.0, axis=1)
    qs = ~dyn
    # eliminate the quasi-static pads: their rows of G and columns of L (their Ldot columns are zero or ignored)
    G_Q, G_dQ, G_ddQ, G_L, G_dL = (b[k] for k in ("G_Q", "G_dQ", "G_ddQ", "G_L", "G_dL"))
    R_L, R_dL = b["R_L"], b["R_dL"]
    if qs.any():
        P = np.linalg.solve(G_L[np.ix_(qs, qs)].T, R_L[:, qs].T).T  # R_L,s G_L,ss^-1
        M = M - P @ G_ddQ[qs]
        D = D - P @ G_dQ[qs]
        K = K - P @ G_Q[qs]
        if dyn.any():
            # the kept pads' balances also see the eliminated ones through G_L[dyn, qs]
            Pd = np.linalg.solve(G_L[np.ix_(qs, qs)].T, G_L[np.ix_(dyn, qs)].T).T
            R_L = R_L[:, dyn] - P @ G_L[np.ix_(qs, dyn)]
            G_Qd = G_Q[dyn] - Pd @ G_Q[qs]
            G_dQd = G_dQ[dyn] - Pd @ G_dQ[qs]
            G_ddQd = G_ddQ[dyn] - Pd @ G_ddQ[qs]
            G_Ld = G_L[np.ix_(dyn, dyn)] - Pd @ G_L[np.ix_(qs, dyn)]
            return LinearModel(params=params, silent=sm, engine=engine, M=M, D=D, K=K,
                               pad_states=tuple(np.array(cm.algebraic)[dyn]), R_L=R_L, R_dL=R_dL[:, dyn],
                               G_Q=G_Qd, G_dQ=G_dQd, G_ddQ=G_ddQd, G_L=G_Ld, G_dL=G_dL[np.ix_(dyn, dyn)],
                               pad_rates=pad_rates)
        return LinearModel(params=params, silent=sm, engine=engine, M=M, D=D, K=K, pad_rates=pad_rates)
    return LinearModel(params=params, silent=sm, engine=engine, M=M, D=D, K=K, pad_states=tuple(cm.algebraic), R_L=R_L,
                       R_dL=R_dL, G_Q=G_Q, G_dQ=G_dQ, G_ddQ=G_ddQ, G_L=G_L, G_dL=G_dL, pad_rates=pad_rates)


def pad_rate_eigenvalues(engine: Engine, params: Any) -> np.ndarray:
    """Finite eigenvalues with the pads' tangential rates kept (the default :func:`linearize`).

    Kept for compatibility: equals ``linearize(engine, params).eigenvalues``.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    params : Parameters
        The model's parameter values.

    Returns
    -------
    ndarray of complex
        The finite eigenvalues [1/s], sorted by decreasing real part.
    """
    return linearize(engine, params, pad_rates="kept").eigenvalues
