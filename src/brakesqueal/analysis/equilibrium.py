r"""The silent motion ``Q(t) = Q0 = const`` of any model (paper eq. 46).

With ``Qdot = Qddot = 0`` and ``Ldot = 0`` the residuals ``R`` (eq. 44,
generalized) and ``G`` (eqs. 33-34) are ``n + m`` equations
``F(Q, L) = 0``.

* **Trivial silent motion.** When ``F(0) = 0`` — for the paper's model when
  ``mu1 h10 = mu2 h20`` (eq. 49) — the silent motion is ``Q0 = 0`` exactly.
  "Zero" is decided to rounding: ``|F_i(0)| <= 64 eps S_i`` with ``S_i`` the
  magnitude of the terms that cancel, ``sum_k |p_k dF_i/dp_k|`` (generated
  with the model, :attr:`CompiledModel.zero_residual_scale
  <brakesqueal.codegen.compiled.CompiledModel.zero_residual_scale>`), so ties
  such as Fig. 3's ``h10 = h mu2/(mu1 + mu2)`` give the exact zero.
* **Otherwise** the silent motion is the solution connected to the trivial
  one: the Newton homotopy ``H(z, s) = F(z) - (1 - s) F(0)`` is followed from
  ``(z, s) = (0, 0)`` to ``s = 1`` by pseudo-arclength continuation with a
  Newton corrector (equilibrated scaling), then polished by Newton's method on
  ``F``.  If the path turns back before ``s = 1`` (a fold) or leaves the
  range where the kinematics is valid, it is *established* that no silent
  motion exists on that branch (:class:`~brakesqueal.errors.NoSilentMotionError`);
  if the continuation cannot proceed (a singular point, step-size
  underflow) the solver reports that it failed
  (:class:`~brakesqueal.errors.SolverFailedError`) — a different status.
* **Validity.** Every pad must touch (``F_n > 0``) and slide (``|v_r| > 0``)
  at the silent motion (:class:`~brakesqueal.errors.ContactLossError`,
  :class:`~brakesqueal.errors.NoSlidingError`).
* **Many points** (:func:`silent_motions`): the Newton stage runs compiled
  for all points in one loop (the engine's batched kernel,
  :mod:`brakesqueal.codegen.silent`: the same iteration and tests); every
  point it does not accept cleanly goes through :func:`silent_motion_vector`,
  so statuses are those of the per-point route.  It hands a point over when
  Newton from the trivial state does not converge cleanly, leaves the
  kinematics' range or meets a singular or non-finite Jacobian, when a pad's
  normal force or sliding speed at the solution is near its limit
  (``F_n <= 1e-7 max(|F_n(0)|, |F_n|)``, the same for ``|v_r|``), and never
  runs at a trivial silent motion (decided to rounding as above).  **Why the
  Newton stage starts from the trivial state, not from a neighbour's
  solution:** the silent motion of a point is the one connected to the
  trivial state; a warm start from a neighbouring grid point converges to the
  root that continues the neighbour's, a property of the grid, not of the
  point (measured: the paper's model with ``general`` values, ``mu1 = 1.68``,
  soft ``k_t``: for ``k_t`` below about 1.1e4 the homotopy folds, while
  Newton warm-started along ``k_t`` converges to admissible tilts all the way
  down to ``k_t = 1``; ``tests/analysis/test_silent_batch.py``).

Triviality is decided in one place for every command: :func:`is_trivial` on
the zero-state residuals (one point: :func:`silent_motion_vector`; many:
:func:`trivial_rows`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ContactLossError, NoSilentMotionError, NoSlidingError, SolverFailedError
from ..status import TRIVIAL_NOISE_FLOOR

if TYPE_CHECKING:
    from ..codegen.compiled import CompiledModel
    from ..codegen.engine import Engine

__all__ = ["SilentMotion", "SilentMotions", "silent_motion", "silent_motion_vector", "silent_motions",
           "parameter_vector", "as_parameters", "is_trivial", "trivial_rows", "zero_state_status", "MAX_TILT",
           "HANDOVER", "COMPILE_MIN"]

_EPS = np.finfo(float).eps
#: A residual row is zero to rounding when ``|F_i| <= NOISE_FLOOR eps S_i`` (``S_i``: its terms' magnitude).
NOISE_FLOOR = TRIVIAL_NOISE_FLOOR
#: Largest tilt angle [rad] for which the kinematics (eq. 42: 1/(cos q1 cos q2)) is used.
MAX_TILT = 1.2
#: Reasons a point is handed to the per-point solver (codes of :attr:`SilentMotions.handover`).
HANDOVER = {
    0: "accepted by the compiled Newton stage",
    1: "Newton from the trivial state did not converge cleanly (per-point globalised solver)",
    2: "a pad's normal force or sliding speed near its limit (per-point solver decides)",
    3: "non-finite residuals or Jacobian (per-point solver decides)",
    4: "trivial silent motion (decided to rounding, no Newton)",
}
#: Fewest points for which the batched route compiles its kernel (numba, seconds on first use per model) when its
#: machine code is not at hand; fewer points go through the per-point solver (~1 ms each).
COMPILE_MIN = 2000


def as_parameters(params: Any) -> Any:
    """A :class:`~brakesqueal.model.parameters.Parameters` (paper-model dataclasses of earlier versions converted)."""
    from ..model.parameters import Parameters

    if isinstance(params, Parameters):
        return params
    if hasattr(params, "as_dict"):  # the 17-field paper parameter set of earlier versions
        from ..model.library import get_model

        return Parameters(get_model("paper"), params.as_dict())
    raise TypeError(f"expected a Parameters object; got {type(params).__name__}")


def parameter_vector(params: Any) -> list[float]:
    """Parameters in packing order (compliances for ``k_ip``): the ``p`` of every generated function."""
    return [float(v) for v in as_parameters(params).vector()]


@dataclass(frozen=True)
class SilentMotion:
    """A silent motion (eq. 46) of a model.

    Attributes
    ----------
    coords : tuple of str
        Names of the coordinates ``Q``.
    q0 : ndarray, shape (n,)
        Coordinates at the silent motion (tilts [rad], displacements [m]).
    l0 : ndarray, shape (m,)
        Tangential deformations of the massless pads [m].
    normal_forces : ndarray, shape (n_pads,)
        Normal contact forces [N] (eqs. 29-30); positive.
    sliding_speeds : ndarray, shape (n_pads,)
        ``|v_r|`` of every pad [m/s]; positive.
    trivial : bool
        ``True`` when ``F(0) = 0`` to rounding and ``q0 = 0`` exactly.
    iterations : int
        Corrector iterations used (0 for the trivial silent motion).
    method : str
        How it was found.
    """

    coords: tuple[str, ...]
    q0: np.ndarray
    l0: np.ndarray
    normal_forces: np.ndarray
    sliding_speeds: np.ndarray
    trivial: bool
    iterations: int
    method: str = "trivial"
    _n: int = field(default=0, repr=False)

    @property
    def q_m0(self) -> np.ndarray:
        """Deprecated alias of :attr:`q0` (the disk tilt of the paper's model); kept for one release."""
        return self.q0

    def state(self) -> list[float]:
        """The full state ``x = (Q0, 0, 0, L0, 0)`` of the generated functions."""
        n, m = self.q0.size, self.l0.size
        return [*map(float, self.q0), *([0.0] * (2 * n)), *map(float, self.l0), *([0.0] * m)]


def is_trivial(residuals: np.ndarray, scale: np.ndarray) -> Any:
    """Whether residuals at ``x = 0`` vanish to rounding (``|F_i| <= 64 eps S_i`` for all rows; vectorized)."""
    r = np.abs(np.asarray(residuals, dtype=float))
    s = np.abs(np.asarray(scale, dtype=float))
    return np.all(r <= NOISE_FLOOR * _EPS * s, axis=0)


def _state(z: np.ndarray, n: int, m: int) -> list[float]:
    return [*map(float, z[:n]), *([0.0] * (2 * n)), *map(float, z[n:]), *([0.0] * m)]


class _System:
    """``F(z)`` and its Jacobian for ``z = (Q, L)``, scaled (rows and unknowns equilibrated at z = 0)."""

    def __init__(self, cm: Any, p: list[float]) -> None:
        self.cm, self.p = cm, p
        n, m = cm.n, cm.m
        self.n, self.m = n, m
        self.cols = list(range(n)) + list(range(3 * n, 3 * n + m))
        J0 = self.jac_raw(np.zeros(n + m))
        row = np.abs(J0).max(axis=1)
        row[~(row > 0)] = 1.0
        Jr = J0 / row[:, None]
        col = np.abs(Jr).max(axis=0)
        col[~(col > 0)] = 1.0
        self.row, self.col = row, col  # z = y / col

    def f_raw(self, z: np.ndarray) -> np.ndarray:
        return np.asarray(self.cm.residuals(_state(z, self.n, self.m), self.p), dtype=float)

    def jac_raw(self, z: np.ndarray) -> np.ndarray:
        return self.cm.jacobian_matrix(_state(z, self.n, self.m), self.p)[:, self.cols]

    def z(self, y: np.ndarray) -> np.ndarray:
        return y / self.col

    def f(self, y: np.ndarray) -> np.ndarray:
        return self.f_raw(self.z(y)) / self.row

    def jac(self, y: np.ndarray) -> np.ndarray:
        return self.jac_raw(self.z(y)) / self.row[:, None] / self.col[None, :]

    def admissible(self, y: np.ndarray) -> bool:
        z = self.z(y)
        if not np.all(np.isfinite(z)):
            return False
        if self.cm.spec.disk.tilting and (abs(z[0]) >= MAX_TILT or abs(z[1]) >= MAX_TILT):
            return False
        return True


def _newton(sysm: _System, y: np.ndarray, g: np.ndarray, max_iter: int = 30,
            monotone: bool = False, tol: np.ndarray | None = None) -> tuple[np.ndarray, int, bool]:
    """Newton on ``f(y) - g = 0`` (scaled unknowns and rows).

    Converged when every component's step is at rounding level relative to
    that component (so a tilt of 1e-12 rad next to a deformation of 1e-5 m is
    still resolved to full relative precision), or when the steps stop
    shrinking at the noise floor of the residual: steps below ``1e-9`` of the
    largest component; or (with ``tol``, per scaled row) a residual that is
    zero to rounding, ``|f_i - g_i| <= tol_i`` (near the trivial silent motion,
    where the solution is itself of the order of the rounding of ``F(0)``); or
    steps below ``1e-6`` of the largest component while the residual no longer
    decreases (by half: near a double root it still drops by four per step) —
    a component fixed by a small difference of large terms, e.g. a tilt of
    1e-17 rad beside one of 1e-10 rad, is known only to that noise.
    With ``monotone`` the iteration is abandoned as soon as a step is not at
    most half the previous one, converged only if it is at that noise floor (a
    converged result is then the root Newton's contraction region around the
    start leads to).

    The compiled batch (:mod:`brakesqueal.codegen.silent`) runs the same iteration.
    """
    last = math.inf
    floor = False
    rlast = math.inf
    for it in range(1, max_iter + 1):
        r = sysm.f(y) - g
        if not np.all(np.isfinite(r)):
            return y, it, False
        resid = tol is not None and bool(np.all(np.abs(r) <= tol))
        rsize = float(np.max(np.abs(r)))
        stalled = rsize >= 0.5 * rlast  # the residual no longer decreases (slow convergence still halves it)
        rlast = rsize
        try:
            step = np.linalg.solve(sysm.jac(y), -r)
        except np.linalg.LinAlgError:
            return y, it, False
        if not np.all(np.isfinite(step)):
            return y, it, False
        y = y + step
        size = float(np.max(np.abs(step)))
        if np.all(np.abs(step) <= 8 * _EPS * np.abs(y)) or size == 0.0:
            return y, it, True
        ymax = float(np.max(np.abs(y)))
        floor = size <= 1e-9 * ymax or resid or (stalled and size <= 1e-6 * ymax)
        if size > 0.9 * last and floor:
            return y, it, True  # no longer contracting: at the noise floor of the residual
        if monotone and it > 1 and size > 0.5 * last:
            return y, it, floor  # no longer contracting: converged only at the noise floor
        last = size
    return y, max_iter, floor


def _continuation(sysm: _System, F0s: np.ndarray, tol: np.ndarray | None = None) -> tuple[np.ndarray, int, str]:
    """Follow ``f(y) - (1 - s) F0s = 0`` from ``(0, 0)`` to ``s = 1`` by pseudo-arclength continuation.

    Returns ``(y at s = 1, corrector iterations, "")``; raises on a fold or a failure.
    """
    N = F0s.size
    y, s = np.zeros(N), 0.0
    h, h_min, h_max = 0.25, 1e-9, 1.0
    total = 0

    def tangent(yv: np.ndarray, prev: np.ndarray | None) -> np.ndarray:
        A = np.hstack([sysm.jac(yv), F0s[:, None]])  # d/d(y, s) of f(y) - (1 - s) F0s
        # null vector of the N x (N+1) matrix
        _, _, vh = np.linalg.svd(A)
        t = vh[-1]
        if prev is not None:
            if t @ prev < 0:
                t = -t
        elif t[-1] < 0:
            t = -t
        return t

    t = tangent(y, None)
    steps = 0
    while True:
        steps += 1
        if steps > 2000:
            raise SolverFailedError("the continuation of the silent motion did not reach the parameters "
                                    "within 2000 steps")
        yp, sp = y + h * t[:-1], s + h * t[-1]
        yc, sc, ok = yp.copy(), sp, False
        for _ in range(12):
            total += 1
            r = np.append(sysm.f(yc) - (1 - sc) * F0s, (yc - y) @ t[:-1] + (sc - s) * t[-1] - h)
            if not np.all(np.isfinite(r)):
                break
            A = np.vstack([np.hstack([sysm.jac(yc), F0s[:, None]]), t])
            try:
                d = np.linalg.solve(A, -r)
            except np.linalg.LinAlgError:
                break
            if not np.all(np.isfinite(d)):
                break
            yc, sc = yc + d[:-1], sc + d[-1]
            if np.max(np.abs(d)) <= 1e-10 * max(1.0, float(np.max(np.abs(yc)))):
                ok = True
                break
        if ok and not sysm.admissible(yc):
            if h <= 2 * h_min or s > 0.0:
                raise NoSilentMotionError(
                    f"the silent motion connected to the trivial one leaves the range of the kinematics "
                    f"(|q1|, |q2| < {MAX_TILT} rad) at {100 * max(s, 0.0):.3g} % of the asymmetry: "
                    "no silent motion on the branch connected to the trivial one (a silent motion on another branch "
                    "is not excluded)")
            ok = False
        if not ok:
            h /= 2
            if h < h_min:
                raise SolverFailedError(f"the continuation of the silent motion stalled at {100 * s:.4g} % of "
                                        "the asymmetry (step size underflow)")
            continue
        t_new = tangent(yc, t)
        if t_new[-1] < 0 and sc < 1.0:
            raise NoSilentMotionError(
                f"the silent motion connected to the trivial one turns back at {100 * sc:.4g} % of the "
                "asymmetry (a fold): no silent motion on this branch (a silent motion on another branch, e.g. one "
                "reached by continuation in a parameter, is not excluded)")
        if sc >= 1.0:
            # land exactly on s = 1 from the bracketing points; if Newton fails there, approach in smaller steps
            frac = (1.0 - s) / (sc - s) if sc > s else 1.0
            yg = y + frac * (yc - y)
            yf, it, conv = _newton(sysm, yg, np.zeros(N), tol=tol)
            total += it
            if conv and sysm.admissible(yf):
                return yf, total, ""
            h /= 2
            if h < h_min:
                raise SolverFailedError("Newton's method failed at the end of the silent-motion continuation")
            continue
        y, s, t = yc, sc, t_new
        h = min(h_max, h * 1.6)


def silent_motion(engine: Engine, params: Any) -> SilentMotion:
    """Find the silent motion of eq. (46) and check that every pad touches and slides.

    Parameters
    ----------
    engine : Engine
        The model's engine (:func:`brakesqueal.codegen.build`).
    params : Parameters
        The model's parameter values.

    Returns
    -------
    SilentMotion

    Raises
    ------
    NoSilentMotionError
        No silent motion exists on the branch connected to the trivial one
        (the continuation folds back or leaves the valid range).
    SolverFailedError
        The solver failed; nothing is established.
    ContactLossError, NoSlidingError
        A pad does not touch, or does not slide, at the silent motion.

    Notes
    -----
    Assumes, as the paper does, that every pad slides in the direction of the
    disk's spin (``Omega > 0``) and stays in contact; both are checked.
    """
    params = as_parameters(params)
    if engine.caps.kind == "matrices":  # the matrices are the linearization about x = 0
        return matrix_silent_motion(engine.caps.coords)
    return silent_motion_vector(engine.compiled, list(map(float, params.vector())))


def matrix_silent_motion(coords: tuple[str, ...]) -> SilentMotion:
    """The silent motion ``x = 0`` of a model given by coefficient matrices (no pads, no contact to check)."""
    z = np.zeros(0)
    return SilentMotion(coords=tuple(coords), q0=np.zeros(len(coords)), l0=z, normal_forces=z, sliding_speeds=z,
                        trivial=True, iterations=0, method="matrices")


def silent_motion_vector(model: CompiledModel, p: list[float]) -> SilentMotion:
    """The per-point solver of :func:`silent_motion` on a packed parameter vector.

    Parameters
    ----------
    model : CompiledModel
        The compiled model.
    p : list of float
        Parameters in packing order (:meth:`Parameters.vector
        <brakesqueal.model.parameters.Parameters.vector>`), assumed valid.

    Returns
    -------
    SilentMotion

    Raises
    ------
    NoSilentMotionError, SolverFailedError, ContactLossError, NoSlidingError
        As :func:`silent_motion`.
    """
    cm = model
    n, m = cm.n, cm.m
    F0 = np.array([float(v) for v in np.broadcast_to(np.asarray(cm.zero_residuals(p), dtype=float), (n + m,))])
    S0 = np.array([float(v) for v in np.broadcast_to(np.asarray(cm.zero_residual_scale(p), dtype=float), (n + m,))])
    if bool(is_trivial(F0, S0)):
        z, its, method, trivial = np.zeros(n + m), 0, "trivial (F(0) = 0 to rounding)", True
    else:
        sysm = _System(cm, p)
        tol = NOISE_FLOOR * _EPS * np.abs(S0) / sysm.row  # a residual zero to rounding (as the triviality test)
        y, its, ok = _newton(sysm, np.zeros(n + m), np.zeros(n + m), max_iter=12, monotone=True, tol=tol)
        if ok and sysm.admissible(y):
            method = "Newton's method from the trivial state"
        else:
            y, its2, _ = _continuation(sysm, F0 / sysm.row, tol)
            its += its2
            method = "pseudo-arclength continuation of the Newton homotopy from the trivial state"
        z, trivial = sysm.z(y), False
    x = _state(z, n, m)
    c = cm.contact_table(x, p)
    fn, speed = c[:, 0], np.sqrt(c[:, 1] ** 2 + c[:, 2] ** 2 + c[:, 3] ** 2)
    for pad, f, v in zip(cm.spec.pads, fn, speed):
        if not (math.isfinite(f) and f > 0.0):
            raise ContactLossError(f"{pad.label} loses contact at the silent motion (normal force {f:.6g} N <= 0)"
                                   + _where(dict(zip(cm.param_names, p))))
        if not v > 0.0:
            raise NoSlidingError(f"{pad.label} does not slide at the silent motion (|v_r| = {v:g} m/s)")
    return SilentMotion(coords=cm.coords, q0=z[:n].copy(), l0=z[n:].copy(), normal_forces=fn.copy(),
                        sliding_speeds=speed, trivial=trivial, iterations=its, method=method)


def _where(params: Any) -> str:
    names = [k for k in ("mu1", "mu2", "h10", "h20", "N0", "k1", "k2") if k in params]
    return (" for " + ", ".join(f"{k}={params[k]:g}" for k in names)) if names else ""


@dataclass(frozen=True)
class SilentMotions:
    """Silent motions of many parameter points (rows of the packed parameter matrix).

    Attributes
    ----------
    status : ndarray of int8, shape (N,)
        :class:`~brakesqueal.status.PointStatus`: ``OK`` (trivial silent
        motion), ``OK_NONTRIVIAL``, or the status of the per-point solver's
        failure (``NO_SILENT_MOTION``, ``CONTACT_LOSS``, ``NO_SLIDING``,
        ``SOLVER_FAILED``).
    q0 : ndarray, shape (N, n)
        Coordinates at the silent motion (NaN where there is none).
    l0 : ndarray, shape (N, m)
        Pad deformations at the silent motion (NaN where there is none).
    trivial : ndarray of bool, shape (N,)
        Trivial silent motion (``q0 = 0`` exactly).
    handover : ndarray of int8, shape (N,)
        Why a point went to the per-point solver (:data:`HANDOVER`; 0: it did not).
    iterations : ndarray of int, shape (N,)
        Newton iterations of the compiled stage.
    """

    status: np.ndarray
    q0: np.ndarray
    l0: np.ndarray
    trivial: np.ndarray
    handover: np.ndarray
    iterations: np.ndarray

    @property
    def z(self) -> np.ndarray:
        """``(Q0, L0)`` per point, shape (N, n + m)."""
        return np.concatenate([self.q0, self.l0], axis=1)


def trivial_rows(cm: CompiledModel, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows whose zero-state residuals vanish to rounding (:func:`is_trivial`, the criterion of
    :func:`silent_motion_vector`), and the residuals' term magnitudes ``S`` (N, n + m).

    Parameters
    ----------
    cm : CompiledModel
        The compiled model.
    P : ndarray, shape (N, n_params)
        Packed parameter vectors.

    Returns
    -------
    trivial : ndarray of bool, shape (N,)
    S : ndarray, shape (N, n + m)
    """
    N = P.shape[0]
    cols = [np.ascontiguousarray(P[:, k]) for k in range(P.shape[1])]
    with np.errstate(all="ignore"):
        F = np.stack([np.broadcast_to(np.asarray(v, dtype=float), (N,)) for v in cm.zero_residuals(cols)])
        S = np.stack([np.broadcast_to(np.asarray(v, dtype=float), (N,))
                      for v in cm.zero_residual_scale(cols)])
    return np.asarray(is_trivial(F, S), dtype=bool) & np.all(np.isfinite(F), axis=0), np.ascontiguousarray(S.T)


def silent_motions(engine: Engine, P: Any, *, use_cache: bool | None = None, compiled: bool = True) -> SilentMotions:
    """Silent motions of many points: compiled Newton stage, the per-point solver wherever it is not clean.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    P : array_like, shape (N, n_params)
        Packed parameter vectors (:meth:`Parameters.vector
        <brakesqueal.model.parameters.Parameters.vector>`, one row per point;
        e.g. :meth:`ParameterSpace.vectors
        <brakesqueal.model.parameters.ParameterSpace.vectors>` stacked).
        Assumed valid.
    use_cache : bool, optional
        Use the on-disk code cache for the compiled kernel (default: the engine's setting).
    compiled : bool, optional
        ``False`` skips the compiled stage: every non-trivial point goes
        through :func:`silent_motion_vector` (the reference the tests
        compare with).

    Returns
    -------
    SilentMotions
        Equal in status to :func:`silent_motion` at every point and in value
        to rounding.
    """
    from ..status import PointStatus, status_of_error

    cm = engine.compiled
    P = np.ascontiguousarray(np.atleast_2d(np.asarray(P, dtype=float)))
    N = P.shape[0]
    n, m, npad = cm.n, cm.m, len(cm.spec.pads)
    K = n + m
    Z = np.full((N, K), np.nan)
    code = np.ones(N, dtype=np.int8)
    iters = np.zeros(N, dtype=np.int64)
    status = np.full(N, int(PointStatus.OK_NONTRIVIAL), dtype=np.int8)
    triv, S = trivial_rows(cm, P) if N else (np.zeros(0, dtype=bool), np.zeros((0, K)))
    code[triv] = 4
    Z[triv] = 0.0
    rest = np.flatnonzero(~triv)
    if compiled and rest.size:
        kern = engine.silent_kernel(use_cache)
        sub = np.ascontiguousarray(P[rest])
        Zs = np.full((rest.size, K), np.nan)
        cs = np.ones(rest.size, dtype=np.int8)
        its = np.zeros(rest.size, dtype=np.int64)
        fn = np.full((rest.size, max(npad, 1)), np.nan)
        sp = np.full((rest.size, max(npad, 1)), np.nan)
        with np.errstate(all="ignore"):
            kern.newton_batch(sub, np.ascontiguousarray(np.abs(S[rest])), NOISE_FLOOR, MAX_TILT, 12, Zs, cs, its,
                              fn, sp)
        engine.mark_silent_ready(use_cache)
        Z[rest], code[rest], iters[rest] = Zs, cs, its
    # the trivial points: contact and sliding at the zero state decide (vectorized, as silent_motion does)
    t = np.flatnonzero(triv)
    if t.size:
        st = zero_state_status(cm, P[t])
        status[t] = st
        Z[t[st != int(PointStatus.OK)]] = np.nan
    for i in np.flatnonzero((code != 0) & (code != 4)):
        try:
            sm = silent_motion_vector(cm, [float(v) for v in P[i]])
        except (NoSilentMotionError, SolverFailedError, ContactLossError, NoSlidingError) as exc:
            status[i] = int(status_of_error(exc))
            Z[i] = np.nan
            continue
        Z[i, :n], Z[i, n:] = sm.q0, sm.l0
        status[i] = int(PointStatus.OK if sm.trivial else PointStatus.OK_NONTRIVIAL)
    handover = np.where(code == 4, 0, code).astype(np.int8)
    handover[triv] = 4
    return SilentMotions(status=status, q0=Z[:, :n].copy(), l0=Z[:, n:].copy(), trivial=triv.copy(),
                         handover=handover, iterations=iters)


def zero_state_status(cm: CompiledModel, P: np.ndarray) -> np.ndarray:
    """``OK``, ``CONTACT_LOSS`` or ``NO_SLIDING`` of trivial silent motions (contact at the zero state), per row
    of the packed parameter matrix ``P`` (int8 :class:`~brakesqueal.status.PointStatus` codes)."""
    from ..codegen.compiled import CONTACT_FIELDS
    from ..status import PointStatus

    N = P.shape[0]
    cols = [np.ascontiguousarray(P[:, k]) for k in range(P.shape[1])]
    with np.errstate(all="ignore"):
        c = [np.broadcast_to(np.asarray(v, dtype=float), (N,)) for v in cm.vectorized.contact([0.0] * cm.nx, cols)]
    nf = len(CONTACT_FIELDS)
    st = np.full(N, int(PointStatus.OK), dtype=np.int8)
    for j in range(len(cm.spec.pads)):
        fn = c[nf * j]
        v = np.sqrt(c[nf * j + 1] ** 2 + c[nf * j + 2] ** 2 + c[nf * j + 3] ** 2)
        lost = ~(np.isfinite(fn) & (fn > 0))
        st = np.where((st == int(PointStatus.OK)) & lost, np.int8(PointStatus.CONTACT_LOSS), st)
        st = np.where((st == int(PointStatus.OK)) & ~(v > 0), np.int8(PointStatus.NO_SLIDING), st)
    return st.astype(np.int8)
