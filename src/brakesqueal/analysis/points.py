r"""The one per-point evaluator: status, verdict, max Re λ and frequency of any model at parameter points.

Maps, sweeps, the numeric routes of crossings and critical speeds and the
plots all classify parameter points through this module, so a point gets the
same status, verdict and eigenvalue summary wherever it is computed.

Routes, chosen per point by what the model allows:

* **Invalid parameters** (:meth:`ParameterSpace.valid
  <brakesqueal.model.parameters.ParameterSpace.valid>`, the one table of
  roles): :attr:`~brakesqueal.status.PointStatus.INVALID`.
* **Trivial silent motion** — the zero-state residuals vanish to rounding
  (:func:`~.equilibrium.is_trivial`, the criterion of
  :func:`~.equilibrium.silent_motion`), or identically on the axes (the
  closed-form route, decided symbolically by
  :func:`~.kernels.quartic_numerators`):

  - models with a closed form (:func:`~.kernels.model_form`: two
    coordinates, rate-free pads): bounded closed-form entries → interval
    quartic → certified Routh → exact rational Routh
    (:func:`~.robust.trivial_verdicts`);
  - otherwise, with every pad rate-free at the zero state, batched ``M, D, K``
    (:meth:`CompiledModel.zero_linear
    <brakesqueal.codegen.compiled.CompiledModel.zero_linear>`) and certified
    eigenvalue verdicts (:func:`~.robust.eigen_verdicts`; for two
    coordinates first the interval quartic, :func:`~.robust.matrix_verdicts`);
  - with pads that keep first-order dynamics (rate-dependent friction or a tangential damper),
    batched descriptor blocks at the zero state and the verdict of every
    eigenvalue of ``E^-1 A`` (:func:`~.robust.descriptor_verdicts`).

  Every pad must touch and slide at the zero state (checked with the
  generated contact function; :attr:`~brakesqueal.status.PointStatus.CONTACT_LOSS`,
  :attr:`~brakesqueal.status.PointStatus.NO_SLIDING`).
* **Non-trivial silent motion** — batched: the silent motions from
  :func:`~.equilibrium.silent_motions` (a compiled Newton stage with the
  per-point globalised solver for every point it does not accept cleanly, so
  statuses are those of :func:`~.equilibrium.silent_motion`), the
  linearization of :func:`~.linear.linearize` at them (exact Jacobians,
  pad states kept where they have rate terms) and the verdict of
  :func:`linear_verdict` on every eigenvalue, all batched; points the batch
  cannot take (a trivial silent motion found there, an algebraic pad row, a
  singular pad block) go through :func:`~.linear.linearize` one by one.  A
  failure of the silent motion gives the status of its type
  (:func:`~brakesqueal.status.status_of_error`).

Consistency by construction: a point with status ``OK`` or ``OK_NONTRIVIAL``
carries a certified verdict and ``stable`` ⇔ ``max_real < 0``
(:func:`~.robust.reconcile`); a verdict that cannot be certified gives
``UNDECIDED``; every other status is never stable.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError, SilentMotionError
from ..status import PointStatus, status_of_error
from .linear import eliminate_algebraic
from .robust import (
    EXTENDED_VERDICT_MAX_SIZE, STABLE, UNDECIDED, UNSTABLE, descriptor_verdicts, eigen_verdicts,
    extended_descriptor_verdict, matrix_verdicts, trivial_verdicts,
)

__all__ = ["PointVerdict", "Points", "evaluate", "evaluate_arrays", "evaluate_point", "linear_verdict",
           "eliminate_algebraic",
           "closed_form_route", "compact", "valid_points", "ROUTES"]

#: Method strings of the routes (recorded in the results' ``method``).
ROUTES = {
    "closed": "closed form: certified Hurwitz test of the exact quartic (generated kernels; exact rational fallback)",
    "points": "per point: certified eigenvalue verdicts (trivial silent motions batched at the zero state, "
              "non-trivial ones batched: compiled Newton silent motions, linearized with the pads' states kept)",
}

_BATCH_CLOSED = 1 << 16
_BATCH_EIGEN = 1 << 12


@dataclass(frozen=True)
class PointVerdict:
    """Status and verdict of one parameter point.

    Attributes
    ----------
    status : PointStatus
        How the point was decided (or why not).
    stable : bool
        Asymptotically stable silent motion (certified); ``False`` unless
        ``status`` is ``OK`` or ``OK_NONTRIVIAL``.
    max_real : float
        Largest real part of the eigenvalues [1/s] (NaN where none was computed).
    frequency : float
        ``|Im λ| / 2π`` of that eigenvalue [Hz].
    """

    status: PointStatus
    stable: bool
    max_real: float
    frequency: float

    @property
    def decided(self) -> bool:
        """Whether the verdict is established (status ``OK`` or ``OK_NONTRIVIAL``)."""
        return self.status in (PointStatus.OK, PointStatus.OK_NONTRIVIAL)


@dataclass(frozen=True)
class Points:
    """Statuses and verdicts of many points (arrays of one shape).

    Attributes
    ----------
    status : ndarray of int8
        :class:`~brakesqueal.status.PointStatus` codes.
    stable : ndarray of bool
        Certified verdicts (never true unless the status is ``OK``/``OK_NONTRIVIAL``).
    max_real, frequency : ndarray of float
        Least-stable eigenvalue summary (NaN where not computed).
    """

    status: np.ndarray
    stable: np.ndarray
    max_real: np.ndarray
    frequency: np.ndarray


def compact(a: Any) -> np.ndarray:
    """The smallest broadcastable array equal to a broadcast view (stride-0 axes reduced to length 1).

    Parameters
    ----------
    a : array_like
        Typically a view returned by :func:`numpy.broadcast_to`.

    Returns
    -------
    ndarray
        Same values, broadcastable to ``a.shape``.
    """
    a = np.asarray(a)
    return a[tuple(slice(0, 1) if st == 0 and n > 1 else slice(None) for st, n in zip(a.strides, a.shape))]


def valid_points(space: Any, arr: Mapping[str, Any]) -> np.ndarray:
    """Validity of broadcast parameter arrays, evaluated on their compact forms (cheap for grids).

    The same conditions as :meth:`ParameterSpace.valid
    <brakesqueal.model.parameters.ParameterSpace.valid>` (every role's
    interval, the disk thickness, pads on the disk, caliper stiffnesses, from
    :func:`brakesqueal.model.roles.parameter_roles`), but combined per array
    shape first, so that a grid whose parameters each depend on one axis costs
    only a few full-size operations.

    Parameters
    ----------
    space : ParameterSpace
        The parameter space.
    arr : Mapping[str, ndarray]
        Model parameter arrays (:meth:`ParameterSpace.arrays`).

    Returns
    -------
    ndarray of bool
        Broadcastable to the arrays' shape.
    """
    roles = space.model.roles()
    parts: dict[tuple[int, ...], np.ndarray] = {}

    def add(c: Any) -> None:
        c = np.asarray(c)
        parts[c.shape] = parts[c.shape] & c if c.shape in parts else c

    def value(v: Any) -> np.ndarray:
        return compact(np.asarray(arr[v], dtype=float)) if isinstance(v, str) else np.asarray(float(v))

    with np.errstate(invalid="ignore"):
        for name, uses in roles.uses.items():
            v = value(name)
            for role, _ in uses:
                add(role.contains(v))
        hu, hl = roles.thickness
        add(value(hu) + value(hl) > 0)
        Rv = value(roles.disk_radius)
        for _, r in roles.pad_radii:
            add(value(r) <= Rv)
        for _, _, k in roles.caliper_dofs:
            add(value(k) > 0)
    ok: Any = np.True_
    for shape in sorted(parts, key=lambda sh: (math.prod(sh), sh)):
        ok = ok & parts[shape]
    return np.asarray(ok)


def closed_form_route(space: Any, names: tuple[str, ...]) -> bool:
    """Whether the closed-form route applies to every point of a grid over ``names``.

    Parameters
    ----------
    space : ParameterSpace
        The parameter space.
    names : tuple of str
        The axes.

    Returns
    -------
    bool
        The model has a closed form (:func:`~.kernels.model_form`) and the
        silent motion is identically trivial on the axes (every zero-state
        residual vanishes under the space's ties).
    """
    from .kernels import closed_route

    return closed_route(space, tuple(names))


class _Model:
    """What the routes need of a model (compiled code, closed form), built once per model."""

    _cache: dict[str, _Model] = {}

    def __init__(self, spec: Any) -> None:
        from ..codegen import compile_model
        from .kernels import has_model_form

        self.spec = spec
        self.cm = compile_model(spec)
        self.has_form = has_model_form(spec)  # read from the on-disk cache: no SymPy on a warm start
        self.rate_free = all(self.cm.rate_free_at_zero)

    @classmethod
    def of(cls, spec: Any) -> _Model:
        from ..codegen import model_key

        key = model_key(spec)
        if key not in cls._cache:
            cls._cache[key] = cls(spec)
        m = cls._cache[key]
        if m.spec is not spec:
            m = cls.__new__(cls)
            m.__dict__.update(cls._cache[key].__dict__)
            m.spec = spec
        return m


def linear_verdict(lm: Any) -> tuple[int, float, float]:
    """Certified verdict of a linear model from every one of its eigenvalues.

    Parameters
    ----------
    lm : LinearModel
        From :func:`~.linear.linearize` (pads kept as states where they matter).

    Returns
    -------
    code, max_real, frequency : int, float, float
        :data:`~.robust.STABLE`, :data:`~.robust.UNSTABLE` or
        :data:`~.robust.UNDECIDED`; the least-stable eigenvalue's real part
        [1/s] and frequency [Hz].  With pad states the descriptor
        ``E xi' = A xi`` is used (:func:`~.robust.descriptor_verdicts`), so
        the pads' own modes count.
    """
    if lm.pad_states:
        E, A = eliminate_algebraic(*lm.descriptor, len(lm.pad_states))
        c, mr, fr = descriptor_verdicts(E[None], A[None])
        if int(c[0]) == UNDECIDED and lm.descriptor[0].shape[0] <= EXTENDED_VERDICT_MAX_SIZE:
            # the norm-wise bound cannot separate slow modes from a huge pad mode: extended precision with
            # componentwise bounds (every eigenvalue at its own scale)
            code, m1, f1, _, lam = extended_descriptor_verdict(*lm.descriptor, len(lm.pad_states))
            if lam.size:
                return code, m1, f1
    elif lm.n == 2:
        c, mr, fr = matrix_verdicts(lm.M, lm.D, lm.K)
    else:
        c, mr, fr = eigen_verdicts(lm.M[None], lm.D[None], lm.K[None])
    if int(c[0]) == UNDECIDED and 2 * lm.n <= EXTENDED_VERDICT_MAX_SIZE:
        # extreme but valid parameters (entries spanning 1e100): the matrices' own eigenvalues in extended
        # precision with componentwise bounds
        code, m1, f1, _, lam = extended_descriptor_verdict(*lm.descriptor, 0)
        if code != UNDECIDED:
            return code, m1, f1
    if int(c[0]) == UNDECIDED and getattr(getattr(lm, "silent", None), "trivial", False):
        # the float matrices cannot decide (a point on the boundary to rounding): the parameter point's own
        # route can (closed forms in exact arithmetic), and maps and sweeps report that verdict
        pv = _point_of(lm)
        size = max(abs(2 * math.pi * float(fr[0])), abs(float(mr[0])), 1.0)
        # only when the matrices are those of the parameters (a LinearModel built by hand may differ)
        if pv is not None and pv.decided and abs(pv.max_real - float(mr[0])) <= 1e-9 * size:
            return (STABLE if pv.stable else UNSTABLE), pv.max_real, pv.frequency
    return int(c[0]), float(mr[0]), float(fr[0])


def _point_of(lm: Any) -> PointVerdict | None:
    """The per-point verdict of a linear model's parameters (``None`` if they cannot be evaluated so)."""
    from ..model.parameters import ParameterSpace

    params = getattr(lm, "params", None)
    if params is None:
        return None
    try:
        return evaluate_point(ParameterSpace.from_parameters(params))
    except (ParameterError, SilentMotionError):
        return None


def _nontrivial_point(model: _Model, values: dict[str, float]) -> tuple[int, bool, float, float]:
    """``(status, stable, max_real, frequency)`` of one point through the numeric linearization."""
    from ..model.parameters import Parameters
    from .linear import linearize

    try:
        lm = linearize(Parameters(model.spec, values), model=model.cm)
    except (SilentMotionError, ParameterError) as exc:
        return int(status_of_error(exc)), False, math.nan, math.nan
    except np.linalg.LinAlgError:
        return int(PointStatus.SOLVER_FAILED), False, math.nan, math.nan
    code, mr, fr = linear_verdict(lm)
    ok = PointStatus.OK if lm.silent.trivial else PointStatus.OK_NONTRIVIAL
    if code == UNDECIDED:
        return int(PointStatus.UNDECIDED), False, mr, fr
    return int(ok), code == STABLE, mr, fr


def _nontrivial_batch(model: _Model, P: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(status, stable, max_real, frequency, redo)`` of points without a trivial zero state (rows of ``P``).

    The silent motions come from :func:`~.equilibrium.silent_motions` (compiled
    Newton stage, the per-point solver wherever it is not clean: statuses as
    :func:`~.equilibrium.silent_motion`); the linearization at them is
    :func:`~.linear.linearize`'s, batched (exact Jacobians from the same
    generated code, quasi-static pads eliminated, pads with rate terms kept as
    states), and the verdict :func:`linear_verdict`'s.  ``redo`` marks the
    points left to the per-point route: all of them when they are fewer than
    :data:`~.silent_batch.COMPILE_MIN` and the kernel is not compiled yet; a
    trivial silent motion found there,
    a kept pad without rate terms (an algebraic row, eliminated per point by
    :func:`eliminate_algebraic`), or a singular pad block.
    """
    from .equilibrium import silent_motions
    from .silent_batch import COMPILE_MIN, kernel_ready

    N = P.shape[0]
    status = np.full(N, int(PointStatus.UNDECIDED), dtype=np.int8)
    stable = np.zeros(N, dtype=bool)
    mr = np.full(N, np.nan)
    fr = np.full(N, np.nan)
    redo = np.zeros(N, dtype=bool)
    if N < COMPILE_MIN and not kernel_ready(model.spec):
        redo[:] = True  # a few points on a cold cache: compiling the kernel would cost more than it saves
        return status, stable, mr, fr, redo
    sms = silent_motions(model.cm, P)
    found = (sms.status == int(PointStatus.OK)) | (sms.status == int(PointStatus.OK_NONTRIVIAL))
    status[~found] = sms.status[~found]
    redo |= sms.status == int(PointStatus.OK)  # trivial after all: zero-state blocks and exact fallbacks per point
    ok = np.flatnonzero(sms.status == int(PointStatus.OK_NONTRIVIAL))
    if ok.size:
        codes, m1, f1, back = _linear_batch(model.cm, np.ascontiguousarray(P[ok]), np.ascontiguousarray(sms.z[ok]))
        done = ok[~back]
        c = codes[~back]
        status[done] = np.where(c == UNDECIDED, int(PointStatus.UNDECIDED), int(PointStatus.OK_NONTRIVIAL))
        stable[done] = c == STABLE
        mr[done], fr[done] = m1[~back], f1[~back]
        redo[ok[back]] = True
    return status, stable, mr, fr, redo


#: Relative agreement of the pads' rate coefficients in double and extended precision that
#: :func:`_unresolved_rates` accepts (the extended values, about 2048 times closer, are then used).
RATE_AGREEMENT = 1e-4


def _unresolved_rates(cm: Any, P: np.ndarray, Z: np.ndarray, Jf: np.ndarray) -> np.ndarray:
    """Points whose pad-rate Jacobian entries (``R_Ldot``, ``G_Ldot``) are not resolved in double precision.

    At a tilted silent motion a pad's rate coefficient can be a difference of terms that cancel to ``O(q^2)``
    (rate-independent friction without normal dampers): in double precision it is rounding noise of either
    sign or exactly 0, posing as a pad mode of ``+-1e20`` (or hiding one).  The entries are evaluated again in
    NumPy's extended precision (``longdouble``, 11 more bits on x86-64) from the same inputs: a resolved entry
    agrees to :data:`RATE_AGREEMENT`, noise does not (it shrinks 2048 times).  The extended values replace
    the double ones in ``Jf`` (in place).  On a platform whose ``longdouble`` is double, every point with pad
    states is reported (the per-point route is accurate).
    """
    N = P.shape[0]
    n, m, nx = cm.n, cm.m, cm.nx
    if np.finfo(np.longdouble).eps >= np.finfo(np.float64).eps:
        return np.ones(N, dtype=bool)
    x: list[Any] = [np.zeros(N, dtype=np.longdouble)] * nx
    for i in range(n):
        x[i] = Z[:, i].astype(np.longdouble)
    for j in range(m):
        x[3 * n + j] = Z[:, n + j].astype(np.longdouble)
    p = [P[:, k].astype(np.longdouble) for k in range(P.shape[1])]
    cols = np.arange(3 * n + m, nx)
    with np.errstate(all="ignore"):
        vals = cm.vectorized.jacobians(x, p)
        J = np.empty((N, n + m, cols.size), dtype=np.longdouble)
        for r in range(n + m):
            for c_i, c in enumerate(cols):
                J[:, r, c_i] = np.broadcast_to(np.asarray(vals[r * nx + c], dtype=np.longdouble), (N,))
        Jd = Jf.reshape(N, n + m, nx)[:, :, cols]
        bad = np.abs(Jd - J) > RATE_AGREEMENT * np.abs(J)
        bad |= ~np.isfinite(J)
    Jf.reshape(N, n + m, nx)[:, :, cols] = J.astype(float)
    return np.any(bad, axis=(1, 2))


def _linear_batch(cm: Any, P: np.ndarray, Z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Batched :func:`~.linear.linearize` at silent motions ``Z = (Q0, L0)`` and :func:`linear_verdict`.

    Returns ``(codes, max_real, frequency, back)``; ``back`` marks points
    the per-point route decides (see :func:`_nontrivial_batch`).
    """
    from .silent_batch import load_kernel

    N = P.shape[0]
    n, m, nx = cm.n, cm.m, cm.nx
    codes = np.full(N, UNDECIDED, dtype=np.uint8)
    mr = np.full(N, np.nan)
    fr = np.full(N, np.nan)
    back = np.zeros(N, dtype=bool)
    Jf = np.empty((N, (n + m) * nx))
    with np.errstate(all="ignore"):
        load_kernel(cm.spec).jacobian_batch(P, Z, Jf)
    J = Jf.reshape(N, n + m, nx)
    M, D, K = J[:, :n, 2 * n:3 * n], J[:, :n, n:2 * n], J[:, :n, :n]
    R_L, R_dL = J[:, :n, 3 * n:3 * n + m], J[:, :n, 3 * n + m:]
    G_Q, G_dQ, G_ddQ = J[:, n:, :n], J[:, n:, n:2 * n], J[:, n:, 2 * n:3 * n]
    G_L, G_dL = J[:, n:, 3 * n:3 * n + m], J[:, n:, 3 * n + m:]

    def second_order(idx: np.ndarray, M: np.ndarray, D: np.ndarray, K: np.ndarray) -> None:
        c, a, f = matrix_verdicts(M, D, K) if n == 2 else eigen_verdicts(M, D, K)
        codes[idx], mr[idx], fr[idx] = c, a, f

    if m == 0:
        second_order(np.arange(N), M, D, K)
        return codes, mr, fr, back
    # a pad's rate coefficients at a tilted silent motion may be differences of terms that cancel to O(q^2)
    # (rate-independent friction without normal dampers): in double precision they are noise of either sign or
    # exactly 0, posing as a pad mode of +-1e20 (or hiding one).  Points where double and extended precision
    # disagree go to the per-point route, which evaluates the Jacobian accurately (linear.accurate_jacobian)
    back |= _unresolved_rates(cm, P, Z, Jf)
    noisy = back.copy()
    dyn_all = np.any(R_dL != 0.0, axis=1) | np.any(G_dL != 0.0, axis=1) | np.any(G_dL != 0.0, axis=2)
    patterns, which = np.unique(dyn_all, axis=0, return_inverse=True)
    for g, dyn in enumerate(patterns):
        idx = np.flatnonzero((which.reshape(-1) == g) & ~noisy)
        if idx.size == 0:
            continue
        qs = ~dyn
        Mg, Dg, Kg = M[idx], D[idx], K[idx]
        RL, RdL, GQ, GdQ, GddQ, GL, GdL = (X[idx] for X in (R_L, R_dL, G_Q, G_dQ, G_ddQ, G_L, G_dL))
        try:
            if qs.any():
                Gss = GL[:, qs][:, :, qs]
                Pq = np.swapaxes(np.linalg.solve(np.swapaxes(Gss, 1, 2), np.swapaxes(RL[:, :, qs], 1, 2)), 1, 2)
                Mg, Dg, Kg = Mg - Pq @ GddQ[:, qs], Dg - Pq @ GdQ[:, qs], Kg - Pq @ GQ[:, qs]
                if not dyn.any():
                    second_order(idx, Mg, Dg, Kg)
                    continue
                Pd = np.swapaxes(np.linalg.solve(np.swapaxes(Gss, 1, 2), np.swapaxes(GL[:, dyn][:, :, qs], 1, 2)),
                                 1, 2)
                RL, RdL = RL[:, :, dyn] - Pq @ GL[:, qs][:, :, dyn], RdL[:, :, dyn]
                GQ, GdQ = GQ[:, dyn] - Pd @ GQ[:, qs], GdQ[:, dyn] - Pd @ GdQ[:, qs]
                GddQ = GddQ[:, dyn] - Pd @ GddQ[:, qs]
                GL, GdL = GL[:, dyn][:, :, dyn] - Pd @ GL[:, qs][:, :, dyn], GdL[:, dyn][:, :, dyn]
        except np.linalg.LinAlgError:
            back[idx] = True  # a singular pad block: the per-point route reports it
            continue
        k, G = int(dyn.sum()), idx.size
        I, Zn = np.broadcast_to(np.eye(n), (G, n, n)), np.zeros((G, n, n))
        Znk, Zkn = np.zeros((G, n, k)), np.zeros((G, k, n))
        E = np.concatenate([np.concatenate([I, Zn, Znk], 2), np.concatenate([Zn, Mg, RdL], 2),
                            np.concatenate([Zkn, GddQ, GdL], 2)], 1)
        A = np.concatenate([np.concatenate([Zn, I, Znk], 2), np.concatenate([-Kg, -Dg, -RL], 2),
                            np.concatenate([-GQ, -GdQ, -GL], 2)], 1)
        zero_rows = np.all(E == 0.0, axis=2)
        alg = np.any(zero_rows, axis=1)
        # every kept pad's row algebraic (rigid supports, 1/k_ip = 0): eliminate_algebraic solves for all pad
        # states, batched here; other patterns of algebraic rows go point by point
        pads_only = alg & np.all(zero_rows[:, 2 * n:], axis=1) & ~np.any(zero_rows[:, :2 * n], axis=1)
        back[idx[alg & ~pads_only]] = True
        keep = ~alg
        if keep.any():
            c, a, f = descriptor_verdicts(E[keep], A[keep])
            codes[idx[keep]], mr[idx[keep]], fr[idx[keep]] = c, a, f
        if pads_only.any():
            sel = np.flatnonzero(pads_only)
            Aa = A[sel]
            try:
                X = np.linalg.solve(Aa[:, 2 * n:, 2 * n:], Aa[:, 2 * n:, :2 * n])
            except np.linalg.LinAlgError:
                back[idx[sel]] = True
                continue
            fin = np.all(np.isfinite(X), axis=(1, 2))
            back[idx[sel[~fin]]] = True
            if fin.any():
                f_ = sel[fin]
                E2 = E[f_, :2 * n, :2 * n] - E[f_, :2 * n, 2 * n:] @ X[fin]
                A2 = A[f_, :2 * n, :2 * n] - A[f_, :2 * n, 2 * n:] @ X[fin]
                c, a, f = descriptor_verdicts(E2, A2)
                codes[idx[f_]], mr[idx[f_]], fr[idx[f_]] = c, a, f
    return codes, mr, fr, back


def _zero_descriptor(cm: Any, cols: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Batched descriptor ``(E, A)`` at the zero state with the rate-free pads eliminated.

    Mirrors :func:`~.linear.linearize` (quasi-static pads: ``L`` eliminated
    through ``G = 0``; the others kept as states), with the rate blocks from
    their simplified symbolic form (:func:`~.kernels.zero_rate_blocks`).
    Returns ``(E, A, kind)``: ``kind`` 0 where every kept pad has rate terms
    (the descriptor applies), 1 where all of them vanish (every pad is
    quasi-static: the second-order ``M, D, K`` of the zero state are exact),
    2 where only some vanish (the per-point route decides).
    """
    from .kernels import zero_rate_blocks

    n, m, nx = cm.n, cm.m, cm.nx
    vals = cm.zero_jacobians(cols)
    N = cols[0].shape[0] if cols else 1
    J = np.stack([np.broadcast_to(np.asarray(v, dtype=float), (N,)) for v in vals], axis=-1).reshape(N, n + m, nx)
    # the rate blocks from their simplified symbolic form: exact zeros instead of cancellation noise
    RdL_c, GdL_c, GddQ_c = zero_rate_blocks(cm.spec).evaluate(cols)
    J[:, :n, 3 * n + m:] = RdL_c
    J[:, n:, 3 * n + m:] = GdL_c
    J[:, n:, 2 * n:3 * n] = GddQ_c
    dyn = ~np.array(cm.rate_free_at_zero, dtype=bool)
    qs = ~dyn
    M, D, K = J[:, :n, 2 * n:3 * n], J[:, :n, n:2 * n], J[:, :n, :n]
    G_Q, G_dQ, G_ddQ = J[:, n:, :n], J[:, n:, n:2 * n], J[:, n:, 2 * n:3 * n]
    G_L, G_dL = J[:, n:, 3 * n:3 * n + m], J[:, n:, 3 * n + m:]
    R_L, R_dL = J[:, :n, 3 * n:3 * n + m], J[:, :n, 3 * n + m:]
    with np.errstate(all="ignore"):
        rates = np.concatenate([R_dL[:, :, dyn], np.swapaxes(G_dL[:, :, dyn], 1, 2), G_dL[:, dyn, :]], axis=2)
        per_pad = np.any(rates != 0.0, axis=2)
        usable = np.where(np.all(per_pad, axis=1), 0, np.where(np.any(per_pad, axis=1), 2, 1))
        if qs.any():
            Gss = G_L[:, qs][:, :, qs]
            P = np.swapaxes(np.linalg.solve(np.swapaxes(Gss, 1, 2), np.swapaxes(R_L[:, :, qs], 1, 2)), 1, 2)
            Pd = np.swapaxes(np.linalg.solve(np.swapaxes(Gss, 1, 2), np.swapaxes(G_L[:, dyn][:, :, qs], 1, 2)), 1, 2)
            M = M - P @ G_ddQ[:, qs]
            D = D - P @ G_dQ[:, qs]
            K = K - P @ G_Q[:, qs]
            RL = R_L[:, :, dyn] - P @ G_L[:, qs][:, :, dyn]
            GQ = G_Q[:, dyn] - Pd @ G_Q[:, qs]
            GdQ = G_dQ[:, dyn] - Pd @ G_dQ[:, qs]
            GddQ = G_ddQ[:, dyn] - Pd @ G_ddQ[:, qs]
            GL = G_L[:, dyn][:, :, dyn] - Pd @ G_L[:, qs][:, :, dyn]
        else:
            RL, GQ, GdQ, GddQ, GL = R_L, G_Q, G_dQ, G_ddQ, G_L
        RdL, GdL = R_dL[:, :, dyn], G_dL[:, dyn][:, :, dyn]
    k = int(dyn.sum())
    I, Z = np.broadcast_to(np.eye(n), (N, n, n)), np.zeros((N, n, n))
    Znk, Zkn = np.zeros((N, n, k)), np.zeros((N, k, n))
    E = np.concatenate([np.concatenate([I, Z, Znk], 2), np.concatenate([Z, M, RdL], 2),
                        np.concatenate([Zkn, GddQ, GdL], 2)], 1)
    A = np.concatenate([np.concatenate([Z, I, Znk], 2), np.concatenate([-K, -D, -RL], 2),
                        np.concatenate([-GQ, -GdQ, -GL], 2)], 1)
    return E, A, usable


def _zero_contact(cm: Any, cols: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Per point: every pad touches (``F_n > 0``) and slides (``|v_r| > 0``) at the zero state."""
    from ..codegen.compiled import CONTACT_FIELDS

    N = cols[0].shape[0] if cols else 1
    x0 = [0.0] * cm.nx
    with np.errstate(all="ignore"):
        c = [np.broadcast_to(np.asarray(v, dtype=float), (N,)) for v in cm.vectorized.contact(x0, cols)]
    nf = len(CONTACT_FIELDS)
    touch = np.ones(N, dtype=bool)
    slide = np.ones(N, dtype=bool)
    for j in range(len(cm.spec.pads)):
        fn = c[nf * j]
        v2 = c[nf * j + 1] ** 2 + c[nf * j + 2] ** 2 + c[nf * j + 3] ** 2
        touch &= np.isfinite(fn) & (fn > 0)
        slide &= v2 > 0
    return touch, slide


def _trivial_batch(model: _Model, P: np.ndarray, eigen: bool, codes: np.ndarray | None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(status, codes, max_real, frequency)`` of points with a trivial silent motion (rows of ``P``)."""
    N = P.shape[0]
    status = np.full(N, int(PointStatus.OK), dtype=np.int8)
    out = np.full(N, UNDECIDED, dtype=np.uint8)
    mr = np.full(N, np.nan)
    fr = np.full(N, np.nan)
    if N == 0:
        return status, out, mr, fr
    if model.has_form:
        for b0 in range(0, N, _BATCH_CLOSED):
            sl = slice(b0, min(N, b0 + _BATCH_CLOSED))
            c, m, f = trivial_verdicts(P[sl], eigen=eigen, codes=None if codes is None else codes[sl],
                                       spec=model.spec)
            out[sl], mr[sl], fr[sl] = c, m, f
    else:
        cm = model.cm
        for b0 in range(0, N, _BATCH_EIGEN):
            sl = slice(b0, min(N, b0 + _BATCH_EIGEN))
            cols = [np.ascontiguousarray(P[sl, k]) for k in range(P.shape[1])]
            touch, slide = _zero_contact(cm, cols)
            st = np.where(~touch, int(PointStatus.CONTACT_LOSS),
                          np.where(~slide, int(PointStatus.NO_SLIDING), int(PointStatus.OK))).astype(np.int8)
            if model.rate_free:
                M, D, K = cm.zero_linear(cols)
                c, m, f = (matrix_verdicts(M, D, K) if cm.n == 2 else eigen_verdicts(M, D, K))
            else:
                E, A, kind = _zero_descriptor(cm, cols)
                c, m, f = descriptor_verdicts(E, A)
                qs = np.flatnonzero(kind == 1)
                if qs.size:  # every kept pad's rate terms vanish here (a falling law at zero slope): quasi-static
                    M, D, K = cm.zero_linear([col[qs] for col in cols])
                    c[qs], m[qs], f[qs] = matrix_verdicts(M, D, K) if cm.n == 2 else eigen_verdicts(M, D, K)
                st = np.where((kind == 2) & (st == int(PointStatus.OK)), -1, st).astype(np.int8)  # -1: per point
            ok = st == int(PointStatus.OK)
            out[sl] = np.where(ok, c, UNDECIDED)
            mr[sl] = np.where(ok, m, np.nan)
            fr[sl] = np.where(ok, f, np.nan)
            status[sl] = st
    und = (status == int(PointStatus.OK)) & (out == UNDECIDED)
    status[und] = int(PointStatus.UNDECIDED)
    return status, out, mr, fr


def evaluate_arrays(space: Any, arr: Mapping[str, Any], *, eigen: bool = True, codes: np.ndarray | None = None,
                    closed: bool = False, valid: np.ndarray | None = None) -> Points:
    """Statuses and verdicts of every point of broadcast parameter arrays.

    Parameters
    ----------
    space : ParameterSpace
        The parameter space (any model).
    arr : Mapping[str, ndarray]
        Every model parameter as arrays broadcastable to one shape
        (:meth:`ParameterSpace.arrays`).
    eigen : bool
        Also compute ``max_real`` and ``frequency`` where a cheaper certified
        verdict exists (the closed-form route with ``codes``); the
        eigenvalue routes always compute them.
    codes : ndarray of uint8, optional
        Verdicts already certified by a generated kernel at every point
        (closed-form route; 2 = recompute).
    closed : bool
        The closed-form route applies to every valid point
        (:func:`closed_form_route`): no residual check.
    valid : ndarray of bool, optional
        Validity mask (default :func:`valid_points`).

    Returns
    -------
    Points
        Arrays of the broadcast shape.
    """
    shape = np.broadcast_shapes(*(np.shape(v) for v in arr.values()))
    model = _Model.of(space.model)
    ok = np.broadcast_to(valid_points(space, arr) if valid is None else valid, shape)
    if closed and model.has_form and codes is not None and not eigen:
        # verdict-only closed-form route: the kernel's certified codes; recompute only its uncertain points
        kc = np.broadcast_to(codes, shape)
        status = np.where(ok, np.int8(PointStatus.OK), np.int8(PointStatus.INVALID))
        stable = ok & (kc == STABLE)
        und = kc == UNDECIDED
        und &= ok
        nan = np.broadcast_to(np.float64(np.nan), shape)  # not computed (read-only)
        if und.any():
            flat = np.flatnonzero(und)
            ix = np.unravel_index(flat, shape)
            vecs = space.vectors({k: compact(v) for k, v in arr.items()})
            P = np.stack([np.broadcast_to(v, shape)[ix] for v in vecs], axis=1)
            st, c, _, _ = _trivial_batch(model, P, False, None)
            status[ix] = st
            stable[ix] = (c == STABLE) & (st == int(PointStatus.OK))
        return Points(status, stable, nan, nan)
    status = np.full(shape, int(PointStatus.INVALID), dtype=np.int8)
    stable = np.zeros(shape, dtype=bool)
    mr = np.full(shape, np.nan)
    fr = np.full(shape, np.nan)
    flat = np.flatnonzero(ok)
    if flat.size == 0:
        return Points(status, stable, mr, fr)
    ix = np.unravel_index(flat, shape)
    vecs = space.vectors({k: compact(v) for k, v in arr.items()})
    P = np.stack([np.broadcast_to(v, shape)[ix] for v in vecs], axis=1) if vecs else np.zeros((flat.size, 0))
    if closed and model.has_form:
        triv = np.ones(flat.size, dtype=bool)
    else:
        triv = _is_trivial(model, P)
    kc = None if codes is None else np.broadcast_to(codes, shape)[ix]
    t = np.flatnonzero(triv)
    if t.size:
        if kc is not None and not eigen:
            sure = kc[t] != UNDECIDED
            tix = tuple(a[t[sure]] for a in ix)
            status[tix] = int(PointStatus.OK)
            stable[tix] = kc[t[sure]] == STABLE
            t = t[~sure]
        st, c, m, f = _trivial_batch(model, P[t], eigen, None if kc is None else kc[t])
        tix = tuple(a[t] for a in ix)
        status[tix] = st
        stable[tix] = (c == STABLE) & (st == int(PointStatus.OK))
        mr[tix], fr[tix] = m, f
        triv[t[st == -1]] = False  # some kept pads without rate terms here: the per-point route decides
    names = list(space.model.parameters)
    nt = np.flatnonzero(~triv)
    if nt.size:
        b_st, b_sb, b_mr, b_fr, redo = _nontrivial_batch(model, P[nt])
        nix = tuple(a[nt] for a in ix)
        status[nix], stable[nix], mr[nix], fr[nix] = b_st, b_sb, b_mr, b_fr
        nt = nt[redo]
    for j in nt:
        i = flat[j]
        pi = np.unravel_index(i, shape)
        values = {n: float(np.broadcast_to(arr[n], shape)[pi]) for n in names}
        s, sb, m1, f1 = _nontrivial_point(model, values)
        status[pi], stable[pi], mr[pi], fr[pi] = s, sb, m1, f1
    return Points(status, stable, mr, fr)


def _is_trivial(model: _Model, P: np.ndarray) -> np.ndarray:
    """Zero-state residuals vanish to rounding (the criterion of ``silent_motion``), per row of ``P``."""
    from .equilibrium import is_trivial

    cm = model.cm
    N = P.shape[0]
    cols = [np.ascontiguousarray(P[:, k]) for k in range(P.shape[1])]
    with np.errstate(all="ignore"):
        F = np.stack([np.broadcast_to(np.asarray(v, dtype=float), (N,)) for v in cm.zero_residuals(cols)])
        S = np.stack([np.broadcast_to(np.asarray(v, dtype=float), (N,)) for v in cm.zero_residual_scale(cols)])
        return np.asarray(is_trivial(F, S), dtype=bool) & np.all(np.isfinite(F), axis=0)


def evaluate(space: Any, values: Mapping[str, Any], *, eigen: bool = True) -> Points:
    """Statuses and verdicts at points given by settable names of a parameter space.

    Parameters
    ----------
    space : ParameterSpace
        The parameter space (any model); tied names follow the values.
    values : Mapping[str, array_like]
        Settable names → values (broadcastable arrays; SI units).
    eigen : bool
        See :func:`evaluate_arrays`.

    Returns
    -------
    Points
        Arrays of the broadcast shape.

    Raises
    ------
    ParameterError
        A name that is not settable in ``space``.
    """
    names = tuple(values)
    arr = space.arrays({k: np.asarray(v, dtype=float) for k, v in values.items()})
    closed = closed_form_route(space, names)
    return evaluate_arrays(space, arr, eigen=eigen, closed=closed)


def evaluate_point(space: Any, values: Mapping[str, float] | None = None) -> PointVerdict:
    """Status and verdict of one point of a parameter space.

    Parameters
    ----------
    space : ParameterSpace
        The parameter space.
    values : Mapping[str, float], optional
        Settable names → values (default: the space's current point).

    Returns
    -------
    PointVerdict
    """
    vals = {k: np.array([float(v)]) for k, v in (values or {}).items()}
    if not vals:
        name = space.settable()[0]
        vals = {name: np.array([space.value(name)])}
    r = evaluate(space, vals)
    return PointVerdict(PointStatus(int(r.status[0])), bool(r.stable[0]), float(r.max_real[0]),
                        float(r.frequency[0]))

