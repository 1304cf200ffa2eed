r"""Hopf points of a brake model with the pads' true tangential dynamics.

A massless pad with a finite tangential stiffness ``k_ip`` and Coulomb
friction balances its spring against the friction force, whose direction
follows the 3-D relative sliding velocity, pad rate ``ldot`` included (paper
eqs. 33-34).  At the trivial silent motion the sliding is purely tangential
and ``ldot`` drops out of the linearization (``docs/theory.md``), so the
quasi-static pad (``ldot := 0``) of the simulation is exact to first order.
It is not beyond: ``ldot`` enters the radial friction component at second
order and the tangential balance at third order, both within the first
Lyapunov coefficient.  With the pad's rate kept, the pad direction is
infinitely fast at the silent motion (the balance does not determine
``ldot`` there), so the usual ODE route cannot be used.

This module computes the normal form of the model's *implicit* equations
``r(Q, Qdot, Qddot, L, Ldot) = 0`` (eq. 44 and the pads' balances, the
generated residuals with their exact Jacobian) directly.  With ``u = (Q, L)``,
the pencil ``P(lambda) = r_Q + lambda r_Qdot + lambda^2 r_Qddot | r_L +
lambda r_Ldot`` and the centre-manifold ansatz
``u = z phi + conj(z phi) + h20 z^2/2 + h11 |z|^2 + conj(h20 z^2)/2 + ...``,
``z' = i omega0 z + c1 z |z|^2``, matching powers of ``z`` gives (``X(lambda,
v) = (v_Q, lambda v_Q, lambda^2 v_Q, v_L, lambda v_L)``, ``r2``, ``r3`` the
second and third derivatives of ``r``)

.. math::

   P(i\omega_0)\phi = 0,\quad \psi^H P(i\omega_0) = 0,\quad
   h_{20} = -P(2i\omega_0)^{-1} r_2[X_1, X_1],\quad h_{11} = -P(0)^{-1} r_2[X_1, \bar X_1],

   c_1 = -\frac{\psi^H\left(r_3[X_1, X_1, \bar X_1] + 2 r_2[X_1, X_{11}] + r_2[\bar X_1, X_{20}]\right)}
   {2\,\psi^H P'(i\omega_0)\phi},

with ``X1 = X(i omega0, phi)``, ``X20 = X(2 i omega0, h20)``, ``X11 = X(0, h11)``.
For an explicit ODE ``r = ydot - f(y)`` this is Kuznetsov's projection formula
(:func:`~.hopf.first_lyapunov`).  ``phi`` is scaled so that the state vector
``q = (phi_Q, i omega0 phi_Q, phi_L of the kept pads)`` has ``<q, q> = 1``:
the state of :func:`~brakesqueal.analysis.linear.linearize` (``"kept"``
pads), so ``l1 = Re c1 / omega0`` follows MatCont's conventions in it.

``r2`` and ``r3`` are central differences of the exact generated Jacobian in
variables scaled by ``omega0`` (rates and accelerations in units of
``omega0``, ``omega0^2``); the step is chosen from a geometric sequence where
consecutive results agree best (the pads' rate enters on the scale of the
sliding speed, far from the scale of the tilts), and that agreement is the
error estimate.  Checked in the tests against the ODE route on the same
model with a rising friction law ``mu(v) = mu + s v`` (pads with a regular
first-order dynamics): the two agree for every ``s``, and as ``s -> 0`` they
tend to the Coulomb result of this module, not to the quasi-static one.

Also predicted from the normal form (leading order, ``|z|`` from the
amplitude law): where the cycle's smallest normal force reaches zero (contact
loss) and where a pad's sliding velocity, pad rate included, reverses (the
end of the model's validity: Coulomb friction would stick).
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import BrakesquealError, ParameterError
from .hopf import HopfResult, _skeel, hopf_result
from .system import EPS, H_FIRST, H_SECOND, fd_bilinear, fd_trilinear, step_plateau

if TYPE_CHECKING:
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace
    from ..simulation import SimulationModel

__all__ = ["PadHopf", "exact_lyapunov", "lyapunov_at_hopf"]


@dataclass(frozen=True)
class PadHopf:
    """A Hopf point with the pads' true tangential dynamics.

    Attributes
    ----------
    hopf : HopfResult
        The normal form in the state ``(Q, Qdot, L_kept)`` of the exact linearization.
    contact_loss : float or None
        Parameter value where the predicted cycle's smallest normal force reaches zero
        (leading order in the amplitude); ``None`` if it does not fall, there are no cycles, or the
        extrapolation leaves the parameter's allowed range.
    sliding_reversal : float or None
        Parameter value where a pad's sliding velocity (pad rate included) first reverses on the
        predicted cycle: the end of the model's validity range.
    tilt_at_contact_loss, tilt_at_sliding_reversal : float or None
        The largest first-harmonic tilt amplitude [rad] of the predicted cycle there (``None`` for a
        disk that does not tilt or when the event is not predicted).
    """

    hopf: HopfResult
    contact_loss: float | None
    sliding_reversal: float | None
    tilt_at_contact_loss: float | None
    tilt_at_sliding_reversal: float | None


class _Point:
    """The implicit equations at one parameter value: silent motion, Jacobian, exact linear model."""

    def __init__(self, space: ParameterSpace, sim: SimulationModel, name: str, p: float) -> None:
        from ..analysis.equilibrium import silent_motion
        from ..analysis.linear import linearize

        self.p = float(p)
        self.params = space.resolve({name: self.p})
        cm = sim.compiled
        self.cm, self.n, self.m = cm, cm.n, cm.m
        self.pvec = [float(v) for v in sim.parameter_vector(self.params)]
        self.sm = silent_motion(sim.engine, self.params)
        self.x0 = np.asarray(self.sm.state(), dtype=float)
        self.J = cm.zero_jacobian_matrix(self.pvec) if self.sm.trivial else cm.jacobian_matrix(self.x0, self.pvec)
        self.lm = linearize(sim.engine, self.params)
        self.kept = [cm.algebraic.index(s) for s in self.lm.pad_states]

    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of the exact linearization: of ``E^-1 A`` (accurate slow modes) where ``E`` is regular,
        else the pencil's finite ones (rigid pads kept at a tilted silent motion)."""
        try:
            return np.linalg.eigvals(self.lm.A)
        except np.linalg.LinAlgError:
            return np.asarray(self.lm.eigenvalues)

    def P(self, lam: complex, derivative: bool = False) -> np.ndarray:
        """``P(lambda)`` (or ``P'(lambda)``), square ``n + m``."""
        n, m, J = self.n, self.m, self.J
        JQ, JdQ, JddQ = J[:, :n], J[:, n:2 * n], J[:, 2 * n:3 * n]
        JL, JdL = J[:, 3 * n:3 * n + m], J[:, 3 * n + m:]
        if derivative:
            return np.hstack([JdQ + 2 * lam * JddQ, JdL])
        return np.hstack([JQ + lam * JdQ + lam * lam * JddQ, JL + lam * JdL])

    def state(self, u: np.ndarray, lam: complex) -> np.ndarray:
        """The state ``(Q, Qdot, L_kept)`` of a harmonic ``u exp(lambda t)``."""
        n = self.n
        return np.concatenate([u[:n], lam * u[:n], u[n:][self.kept]])

    def y0(self) -> np.ndarray:
        return self.state(np.concatenate([self.sm.q0, self.sm.l0]).astype(complex), 0.0).real


def _track(lams: np.ndarray, target: complex) -> complex:
    cand = lams[lams.imag > 0]
    if cand.size == 0:
        raise BrakesquealError("no complex eigenvalue pair near the crossing: not a Hopf point")
    return complex(cand[np.argmin(np.abs(cand - target))])


def exact_lyapunov(engine: Engine, space: ParameterSpace, name: str, p0: float, *, omega: float | None = None,
                   use_cache: bool = True) -> PadHopf:  # fmt: skip
    """First Lyapunov coefficient at a stability crossing with the pads' true tangential dynamics.

    Parameters
    ----------
    engine : Engine
        The model's engine (built by the caller).
    space : ParameterSpace
        The model, preset and overrides (any model).
    name : str
        The path parameter (settable in ``space``).
    p0 : float
        A stability crossing (e.g. from :func:`~brakesqueal.analysis.crossings.crossings`); refined here
        on the exact linearization.
    omega : float, optional
        Select the eigenvalue pair with imaginary part closest to ``omega`` (default: the pair closest to
        the imaginary axis).
    use_cache : bool
        Use the on-disk code cache.

    Returns
    -------
    PadHopf
        The normal form (``hopf.multilinear = "finite-difference"``; ``l1_error`` from the step
        sequence) and the predicted contact loss and sliding reversal.

    Raises
    ------
    ParameterError
        ``name`` is not settable, or ``p0`` is not finite.
    BrakesquealError
        No complex pair, the refinement does not converge, or a zero eigenvalue at the point.
    """
    from ..simulation import simulation_model

    if name not in space.settable():
        space.resolve({name: 1.0})  # the one message for unknown or tied names
    if not math.isfinite(float(p0)):
        raise ParameterError(f"The parameter {name} must be finite; got {p0!r}")
    sim = simulation_model(engine, use_cache=use_cache)
    pt = _Point(space, sim, name, float(p0))
    cand = pt.lm.eigenvalues[pt.lm.eigenvalues.imag > 0]
    if cand.size == 0:
        raise BrakesquealError(f"no complex eigenvalue pair at {name} = {p0:.12g}: not a Hopf point")
    lam = complex(cand[np.argmin(np.abs(cand.real) if omega is None else np.abs(cand.imag - omega))])

    p = float(p0)
    dl = _dlam(space, sim, name, p, lam)
    pt, lam, refined = _refine(space, sim, name, pt, lam, dl)
    if abs(pt.p - p) > 1e-9 * max(abs(pt.p), 1e-3):  # moved: the derivative at the Hopf point itself
        dl = _dlam(space, sim, name, pt.p, lam)
    h, X1, phi = _normal_form(space, sim, name, pt, lam, pt.lm.eigenvalues, dl, refined, silent_derivative=True)
    loss, rev, t_loss, t_rev = _events(pt, sim, h, lam.imag, X1, phi)
    if not _valid(space, name, loss):  # a leading-order extrapolation out of the parameter's range
        loss, t_loss = None, None
    if not _valid(space, name, rev):
        rev, t_rev = None, None
    return PadHopf(h, loss, rev, t_loss, t_rev)


def _dlam(space: ParameterSpace, sim: SimulationModel, name: str, p: float, target: complex) -> complex:
    """``d lambda / dp`` of the eigenvalue nearest ``target``: fourth-order central differences (step
    ``1e-4 |p|``) of the double-precision eigenvalues."""

    def lam_at(q: float) -> complex:
        return _track(_Point(space, sim, name, q).eigenvalues(), target)

    h = 1e-4 * max(abs(p), 1e-3)
    d1 = lam_at(p + h) - lam_at(p - h)
    d2 = lam_at(p + 2 * h) - lam_at(p - 2 * h)
    return (8 * d1 - d2) / (12 * h)


def _refine(space: ParameterSpace, sim: SimulationModel, name: str, pt: _Point, lam: complex,
            d: complex) -> tuple[_Point, complex, bool]:
    """Chord iterations on ``Re lambda(p) = 0`` from ``pt`` with the derivative ``d`` (a fresh one where they
    stop contracting away from the eigenvalues' rounding level): the point, its eigenvalue, whether refined."""
    if d.real == 0:
        raise BrakesquealError("cannot refine the Hopf point: dRe(lambda)/dp = 0 (not transversal)")
    p, prev = pt.p, math.inf
    for _ in range(30):
        step = -lam.real / d.real
        if abs(step) >= 0.5 * prev:  # not contracting: at the eigenvalues' rounding level, or far away
            if abs(lam.real) <= 1e-9 * abs(lam):
                return pt, lam, True
            d = _dlam(space, sim, name, p, lam)  # Newton step with a fresh derivative
            step = -lam.real / d.real
        pt = _Point(space, sim, name, p + step)
        p, lam, prev = pt.p, _track(pt.eigenvalues(), lam), abs(step)
        if abs(step) <= 8 * EPS * max(1.0, abs(p)) or abs(lam.real) <= 1e-13 * abs(lam):
            return pt, lam, True
    raise BrakesquealError(f"the Hopf point did not converge (last Re lambda = {lam.real:.3g} at "
                           f"{name} = {p:.12g})")  # fmt: skip


def lyapunov_at_hopf(engine: Engine, space: ParameterSpace, name: str, p: float, eigenvalue: complex,
                     dlambda_dp: complex, *, use_cache: bool = True) -> HopfResult:
    """The normal form at a point already on the stability boundary (a Hopf curve's point), given ``d lambda/dp``.

    :func:`exact_lyapunov` selects the pair in extended precision, refines the crossing by chord iterations
    with a finite-difference ``d lambda / dp`` (four linearizations a derivative, one more at the end) and
    lists the eigenvalues in extended precision again
    (:func:`~brakesqueal.analysis.linear.descriptor_eigenvalues`).  A caller that has corrected the point
    onto ``Re lambda = 0`` and knows ``d lambda / dp`` (:func:`brakesqueal.region.curves.continue_hopf_curve`)
    passes both.  Where ``|Re lambda| <= 1e-12 |lambda|`` (the curve's corrector tolerance) the point is taken
    as it is: the chord iterations there only move ``p`` within the rounding noise of ``Re lambda`` (about
    ``1e-12`` relative), which changes ``l1`` by its finite differences' rounding, far inside ``l1_error``;
    elsewhere they run, with the caller's derivative.  The double-precision eigenvalues replace the extended
    ones where their error bounds decide every check made with them (:func:`_checked_eigenvalues`).  ``l1``,
    its error and the criticality are computed as there; ``dx0_dp`` is NaN (not computed).

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The model, preset and overrides.
    name : str
        The path parameter (settable in ``space``).
    p : float
        Its value at the Hopf point.
    eigenvalue : complex
        The critical eigenvalue there (``Im > 0``), e.g. from the double-precision eigenvalues of the exact
        linearization; the one of the point nearest it is taken.
    dlambda_dp : complex
        ``d lambda / dp`` there (transversality, side, frequency slope).
    use_cache : bool
        Use the on-disk code cache.

    Returns
    -------
    HopfResult
        As ``exact_lyapunov(...).hopf``, with ``dx0_dp`` NaN.

    Raises
    ------
    ParameterError
        ``name`` is not settable, or ``p``, ``eigenvalue`` or ``dlambda_dp`` is not finite.
    BrakesquealError
        No complex pair, the refinement does not converge, or a zero eigenvalue at the point.
    """
    from ..simulation import simulation_model

    if name not in space.settable():
        space.resolve({name: 1.0})  # the one message for unknown or tied names
    for label, v in (("p", p), ("eigenvalue", eigenvalue), ("dlambda_dp", dlambda_dp)):
        if not cmath.isfinite(complex(v)):
            raise ParameterError(f"The argument {label} must be finite; got {v!r}", parameter=label)
    sim = simulation_model(engine, use_cache=use_cache)
    pt = _Point(space, sim, name, float(p))
    lam = _track(pt.eigenvalues(), complex(eigenvalue))
    dl, refined = complex(dlambda_dp), True
    if not abs(lam.real) <= 1e-12 * abs(lam):  # not on the boundary to rounding: exact_lyapunov's refinement
        pt, lam, refined = _refine(space, sim, name, pt, lam, dl)
        if abs(pt.p - float(p)) > 1e-9 * max(abs(pt.p), 1e-3):  # moved: the derivative at the Hopf point
            dl = _dlam(space, sim, name, pt.p, lam)
    return _normal_form(space, sim, name, pt, lam, _checked_eigenvalues(pt, lam), dl, refined,
                        silent_derivative=False)[0]


def _checked_eigenvalues(pt: _Point, lam: complex) -> np.ndarray:
    r"""The eigenvalues :func:`_normal_form`'s checks read: double precision where it provably decides them.

    The checks are: which eigenvalues are the critical pair (within ``1e-9 |lam|`` of ``lam`` or its
    conjugate), whether one is zero (``|mu| <= 1e-12 |lam|``) and whether another lies on the imaginary axis
    (``|Re mu| <= 1e-8 |lam|``).  The eigenpairs of ``E^-1 A`` (:attr:`LinearModel.reduced_descriptor`) are
    computed in double precision with left vectors and each eigenvalue gets an a-posteriori bound

    .. math::

       \delta_i = 10\,\frac{\left(\|(A - \mu_i E) x_i\| + \|r_i^{\rm rnd}\|\right)\|y_i\|}{|y_i^H E x_i|},
       \qquad r_i^{\rm rnd} = (m + 2)\,\epsilon\,(|A| + |\mu_i| |E|) |x_i|,

    (the residual in the float pencil, its own rounding, the eigenvalue's condition; first order, hence the
    factor 10 and the requirement that ``delta_i`` is below a tenth of the distance to every other
    eigenvalue).  Where every check gives the same answer for every value within the bounds, those
    eigenvalues are returned; otherwise (a huge pad mode spoiling the slow ones, a near-defective pair, a
    singular ``E``, a bound straddling a threshold) the extended-precision list
    (:attr:`LinearModel.eigenvalues <brakesqueal.analysis.linear.LinearModel.eigenvalues>`), as
    :func:`exact_lyapunov` uses everywhere.
    """
    import scipy.linalg

    from ..analysis.linear import sort_eigenvalues

    try:
        E, A = (np.asarray(a, dtype=float) for a in pt.lm.reduced_descriptor)
        if not (np.all(np.isfinite(E)) and np.all(np.isfinite(A))):
            return pt.lm.eigenvalues
        mu, yl, xr = scipy.linalg.eig(np.linalg.solve(E, A), left=True, right=True)
        yl = np.linalg.solve(E.conj().T, yl)  # left vectors of the pencil: y^H A = mu y^H E
    except (np.linalg.LinAlgError, ValueError):
        return pt.lm.eigenvalues
    m = mu.size
    if m == 0 or not np.all(np.isfinite(mu)):
        return pt.lm.eigenvalues
    R = A @ xr - (E @ xr) * mu[None, :]
    rnd = (m + 2) * EPS * (np.abs(A) @ np.abs(xr) + (np.abs(E) @ np.abs(xr)) * np.abs(mu)[None, :])
    den = np.abs(np.einsum("ij,ij->j", np.conj(yl), E @ xr))
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = 10 * (np.linalg.norm(R, axis=0) + np.linalg.norm(rnd, axis=0)) * np.linalg.norm(yl, axis=0) / den
    if not np.all(np.isfinite(delta)):
        return pt.lm.eigenvalues
    gap = np.abs(mu[:, None] - mu[None, :]) + np.diag(np.full(m, np.inf))
    if np.any(delta >= 0.1 * gap.min(axis=1)):
        return pt.lm.eigenvalues
    a = abs(lam)

    def decided(v: np.ndarray, tol: float) -> bool:  # "v <= tol" the same for every value within delta
        return bool(np.all((v - delta > tol) | (v + delta <= tol)))

    crit = np.minimum(np.abs(mu - lam), np.abs(mu - np.conj(lam)))
    other = crit - delta > 1e-9 * a
    if not (decided(crit, 1e-9 * a) and decided(np.abs(mu), 1e-12 * a)
            and decided(np.where(other, np.abs(mu.real), np.inf), 1e-8 * a)):
        return pt.lm.eigenvalues
    lams = mu.astype(complex)
    tiny = np.abs(lams.imag) <= delta  # a real eigenvalue's rounding-level imaginary part, as the extended list
    lams[tiny] = lams[tiny].real
    return sort_eigenvalues(lams)


def _normal_form(space: ParameterSpace, sim: SimulationModel, name: str, pt: _Point, lam: complex,
                 lams: np.ndarray, dl: complex, refined: bool, *,
                 silent_derivative: bool) -> tuple[HopfResult, np.ndarray, np.ndarray]:
    """The normal form at a Hopf point ``pt`` with critical eigenvalue ``lam`` (on the imaginary axis).

    ``lams`` are the eigenvalues read by the checks (a zero eigenvalue, other eigenvalues on the axis),
    ``dl = d lambda / dp``; ``silent_derivative=False`` leaves ``dx0_dp`` NaN (two silent motions fewer).
    Returns the result, ``X1`` (scaled back) and ``phi`` (for :func:`_events`).
    """
    w0 = lam.imag
    if np.min(np.abs(lams)) <= 1e-12 * abs(lam):
        raise BrakesquealError("a zero eigenvalue at the Hopf point (fold-Hopf): l1 is not defined")
    phi, psi, q, pv = _vectors(pt, w0)
    sv = np.linalg.svd(pt.P(1j * w0), compute_uv=False)
    kvec = float(sv[0] / sv[-2]) if sv.size > 1 else 1.0  # condition of the null vectors phi, psi
    c1, c1_err, h20, h11, X1 = _c1(pt, w0, phi, psi, kvec)
    p = pt.p
    y0 = pt.y0()
    if silent_derivative:  # the silent motion's derivative along the path, in the state
        hp = 1e-6 * max(abs(p), 1e-3)
        dy0 = (_Point(space, sim, name, p + hp).y0() - _Point(space, sim, name, p - hp).y0()) / (2 * hp)
    else:
        dy0 = np.full(y0.size, np.nan)
    warnings: list[str] = []
    others = lams[(np.abs(lams - lam) > 1e-9 * abs(lam)) & (np.abs(lams - np.conj(lam)) > 1e-9 * abs(lam))]
    near = others[np.abs(others.real) <= 1e-8 * abs(lam)]
    if near.size:
        warnings.append(f"other eigenvalues on the imaginary axis: {np.array2string(near, precision=6)} "
                        "(codimension-2 point; the centre manifold is larger than 2-D)")  # fmt: skip
    coords = tuple(sim.coords)
    names = (*coords, *(f"d{c}" for c in coords), *pt.lm.pad_states)
    h = hopf_result(y0, p, lams, lam, q, pv, c1, c1_err, dl, dy0, pt.state(h20, 2j * w0),
                    pt.state(h11.astype(complex), 0.0).real, multilinear="finite-difference", refined=refined,
                    state_names=names, parameter_name=name, warnings=warnings)  # fmt: skip
    return h, X1, phi


def _valid(space: ParameterSpace, name: str, value: float | None) -> bool:
    """Whether ``value`` is an allowed value of the path parameter (bounds of the parameter table)."""
    if value is None:
        return False
    try:
        space.resolve({name: float(value)})
    except ParameterError:
        return False
    return True


def _vectors(pt: _Point, w0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``phi, psi`` (null vectors of ``P(i omega0)``) and the state vectors ``q, p`` (MatCont's scaling)."""
    U, _S, Vh = np.linalg.svd(pt.P(1j * w0))
    phi, psi = np.conj(Vh[-1]), U[:, -1]
    q = pt.state(phi, 1j * w0)
    s = 1 / np.linalg.norm(q)
    j = int(np.argmax(np.abs(q)))
    s *= abs(q[j]) / q[j]
    phi, q = phi * s, q * s
    E, A = pt.lm.descriptor
    Ul, _Sl, _Vl = np.linalg.svd(A - 1j * w0 * E)
    pv = E.conj().T @ Ul[:, -1]
    pq = np.vdot(pv, q)
    if abs(pq) == 0:
        raise BrakesquealError("<p, q> = 0: the critical eigenvalue is not simple")
    return phi, psi, q, pv / np.conj(pq)


def _c1(pt: _Point, w0: float, phi: np.ndarray, psi: np.ndarray,
        kvec: float = 1.0) -> tuple[complex, float, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """``(c1, error, h20, h11, X1)`` with the finite-difference step chosen where consecutive steps agree best."""
    n, m = pt.n, pt.m
    T = np.concatenate([np.ones(n), np.full(n, w0), np.full(n, w0 * w0), np.ones(m), np.full(m, w0)])

    def X(v: np.ndarray, lam: complex) -> np.ndarray:  # scaled X(lambda, v)
        r = lam / w0
        return np.concatenate([v[:n], r * v[:n], r * r * v[:n], v[n:], r * v[n:]])

    # the four bilinear forms share the directions Re X1, Im X1 (and X1b's are their mirror images), the
    # trilinear form's mixed directions repeat, and a step 4x smaller reuses a point of the larger one: every
    # distinct point is evaluated once (the values are those of the unshared evaluations, bit for bit; the
    # generated code runs on Python floats, the same IEEE operations and libm calls as on NumPy scalars)
    memo: dict[bytes, np.ndarray] = {}
    shape = (n + m, pt.cm.nx)

    def jac(xi: np.ndarray, _p: float) -> np.ndarray:
        key = xi.tobytes()
        J = memo.get(key)
        if J is None:
            vals = pt.cm.jacobians((pt.x0 + T * xi).tolist(), pt.pvec)
            J = memo[key] = np.asarray(vals, dtype=float).reshape(shape) * T[None, :]
        return J

    z = np.zeros(T.size)
    X1 = X(phi, 1j * w0)
    X1b = np.conj(X1)
    P2, P0 = pt.P(2j * w0), pt.P(0.0)
    den = np.vdot(psi, pt.P(1j * w0, derivative=True) @ phi)

    def at(f: float) -> tuple[complex, np.ndarray, np.ndarray, float]:
        hB, hC = H_FIRST * f, H_SECOND * f
        B11, _ = fd_bilinear(jac, z, 0.0, X1, X1, step=hB)
        B1b, _ = fd_bilinear(jac, z, 0.0, X1, X1b, step=hB)
        h20 = -np.linalg.solve(P2, B11)
        h11 = -np.linalg.solve(P0, B1b.real)
        C, _ = fd_trilinear(jac, z, 0.0, X1, X1, X1b, step=hC)
        B2, _ = fd_bilinear(jac, z, 0.0, X1, X(h11.astype(complex), 0.0), step=hB)
        B3, _ = fd_bilinear(jac, z, 0.0, X1b, X(h20, 2j * w0), step=hB)
        t = (np.vdot(psi, C), 2 * np.vdot(psi, B2), np.vdot(psi, B3))
        # rounding of the two solves (Skeel's condition numbers) and of the null vectors on the terms' magnitudes
        kap = _skeel(P2, h20) + _skeel(P0, h11) + kvec
        rnd = 10 * EPS * kap * sum(abs(v) for v in t) / abs(den) / 2
        return complex(-sum(t) / den / 2), h20, h11, rnd

    (c1, h20, h11, rnd), before, after = step_plateau(at, range(0, 13), settle=1e-8)
    # the agreement with both neighbours of the chosen step (a plateau, not a crossing of two curves)
    err = 2 * max(before, after) + rnd + 1e3 * EPS * abs(c1)
    return c1, err, h20, h11, X1 * T


def _events(pt: _Point, sim: SimulationModel, h: HopfResult, w0: float, X1: np.ndarray,
            phi: np.ndarray) -> tuple[float | None, float | None, float | None, float | None]:  # fmt: skip
    """Leading-order contact loss and sliding reversal on the predicted cycle (parameter values, tilts)."""
    if not h.side or not h.dRe_lambda_dp:
        return None, None, None, None
    C0 = pt.cm.contact_table(pt.x0, pt.pvec)
    scale = float(np.max(np.abs(X1)))
    hstep = 1e-7 / scale

    def deriv(v: np.ndarray) -> np.ndarray:
        return (pt.cm.contact_table(pt.x0 + hstep * v, pt.pvec)
                - pt.cm.contact_table(pt.x0 - hstep * v, pt.pvec)) / (2 * hstep)  # fmt: skip

    dC = deriv(X1.real) + 1j * deriv(X1.imag)  # (pad, field) per unit z: F = F0 + 2 Re(z dF e^{i theta})
    F0, dF = C0[:, 0], dC[:, 0]
    v0, dv = C0[:, 1:4], dC[:, 1:4]
    s0 = np.einsum("pk,pk->p", v0, v0)
    ds = np.einsum("pk,pk->p", dv, v0)
    with np.errstate(divide="ignore", invalid="ignore"):
        z_loss = np.where((F0 > 0) & (np.abs(dF) > 0), F0 / (2 * np.abs(dF)), np.inf)
        z_rev = np.where((s0 > 0) & (np.abs(ds) > 0), s0 / (2 * np.abs(ds)), np.inf)
    ratio = abs(h.c1.real / h.dRe_lambda_dp)
    tilt = 2 * float(np.max(np.abs(phi[:2]))) if sim.tilting else None

    def where(zz: np.ndarray) -> tuple[float | None, float | None]:
        r = float(np.min(zz))
        if not math.isfinite(r):
            return None, None
        return h.p0 + h.side * r * r * ratio, (tilt * r if tilt is not None else None)

    loss, t_loss = where(z_loss)
    rev, t_rev = where(z_rev)
    return loss, rev, t_loss, t_rev
