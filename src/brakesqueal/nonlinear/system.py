r"""Smooth and piecewise-smooth autonomous systems with one continuation parameter.

A :class:`SmoothSystem` is ``x' = f(x, p)`` with ``x`` in R^n and a scalar
parameter ``p``.  It carries the Jacobian ``jac = f_x`` (required) and,
optionally, exact higher derivatives:

* ``dfdp(x, p) = f_p``, ``jac_p(x, p) = f_xp`` (the Jacobian's p-derivative);
* the multilinear forms of the Taylor expansion at ``x``
  (Kuznetsov, *Elements of Applied Bifurcation Theory*, eq. 3.17)

  .. math::

     f(x+u, p) = f(x, p) + A u + \tfrac12 B(u, u) + \tfrac16 C(u, u, u) + O(|u|^4),

  ``B(x, p, u, v) = sum_jk d^2 f/dx_j dx_k u_j v_k`` and
  ``C(x, p, u, v, w) = sum_jkl d^3 f/dx_j dx_k dx_l u_j v_k w_l``.  They must
  accept complex vectors (they are multilinear, not sesquilinear).

When an optional derivative is missing it is computed by finite differences:
of ``f`` in ``p`` (``dfdp``), of ``jac`` in ``p`` (``jac_p``) and of ``jac``
along ``x`` (``B``, ``C``).  All use fourth-order central formulas with a
Richardson error estimate (the difference between steps ``h`` and ``2h``
divided by 15), see :func:`fd_bilinear` and :func:`fd_trilinear`.  With the
default steps (``eps**(1/5)`` for first, ``eps**(1/6)`` for second
derivatives, times ``max(1, |x|_inf)``) the relative error is about 1e-11 for
``B`` and 1e-9 for ``C`` on well-scaled analytic vector fields
(``tests/nonlinear/test_nl_system.py`` checks both against exact forms, and that the
returned error estimates bound the actual errors).

A :class:`PiecewiseSystem` is a set of smooth modes with guard functions
``h(x, p)`` that switch the mode when they cross zero in a given direction,
optionally applying a reset map ``x+ = g(x-, p)`` (impacts).  The shooting
code (:mod:`.periodic`) integrates through the switchings and propagates the
monodromy matrix with saltation matrices.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from ..errors import ParameterError

__all__ = [
    "step_plateau",
    "SmoothSystem",
    "Transition",
    "PiecewiseSystem",
    "fd_bilinear",
    "fd_trilinear",
    "fd_dp",
]

EPS = float(np.finfo(float).eps)
#: Default relative steps: optimal for fourth-order central first / second derivatives.
H_FIRST = EPS ** (1 / 5)
H_SECOND = EPS ** (1 / 6)

Vec = np.ndarray
Fun = Callable[[np.ndarray, float], np.ndarray]


def _unit(d: np.ndarray) -> tuple[np.ndarray, float]:
    nrm = float(np.max(np.abs(d))) if d.size else 0.0
    return (d / nrm, nrm) if nrm > 0 else (d, 0.0)


def _first_dir(jac: Fun, x: np.ndarray, p: float, d: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """``(D J[d], error estimate)`` for a real direction ``d`` (4th-order central, Richardson check)."""
    dh, nrm = _unit(d)
    if nrm == 0.0:
        z = np.zeros((x.size, x.size))
        return z, z
    J = {k: np.asarray(jac(x + k * h * dh, p), dtype=float) for k in (-4, -2, -1, 1, 2, 4)}
    d1 = (8 * (J[1] - J[-1]) - (J[2] - J[-2])) / (12 * h)
    d2 = (8 * (J[2] - J[-2]) - (J[4] - J[-4])) / (24 * h)
    # empirical: the difference of the two step sizes bounds truncation (15x) and shows the noise
    # of the smaller step (constant entries of J cancel exactly and contribute nothing)
    err = 2 * np.abs(d1 - d2)
    return nrm * (d1 + (d1 - d2) / 15), nrm * err


def _second_dir(
    jac: Fun, x: np.ndarray, p: float, d: np.ndarray, h: float, J0: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``(D^2 J[d, d], error estimate)`` for a real direction ``d``."""
    dh, nrm = _unit(d)
    if nrm == 0.0:
        z = np.zeros_like(J0)
        return z, z
    J = {k: np.asarray(jac(x + k * h * dh, p), dtype=float) for k in (-4, -2, -1, 1, 2, 4)}
    J[0] = J0
    s1 = (-(J[2] + J[-2]) + 16 * (J[1] + J[-1]) - 30 * J0) / (12 * h * h)
    s2 = (-(J[4] + J[-4]) + 16 * (J[2] + J[-2]) - 30 * J0) / (48 * h * h)
    err = 2 * np.abs(s1 - s2)
    return nrm**2 * (s1 + (s1 - s2) / 15), nrm**2 * err


def _step(x: np.ndarray, rel: float, step: float | None) -> float:
    return float(step) if step is not None else rel * max(1.0, float(np.max(np.abs(x))) if x.size else 1.0)


def fd_bilinear(jac: Fun, x: Vec, p: float, u: Vec, v: Vec, *, step: float | None = None) -> tuple[Vec, float]:
    r"""``B(u, v) = (D_x J(x, p) u) v`` by finite differences of the Jacobian.

    Parameters
    ----------
    jac : callable
        ``jac(x, p) -> (n, n)`` real Jacobian.
    x : ndarray, shape (n,)
        Point of expansion.
    p : float
        Parameter value.
    u, v : ndarray, shape (n,)
        Real or complex vectors (``B`` is bilinear: ``u`` is split into real
        and imaginary parts, each a real direction).
    step : float, optional
        Absolute step along the direction scaled to unit max-norm (default
        ``eps**(1/5) * max(1, |x|_inf)``).

    Returns
    -------
    value : ndarray, shape (n,)
        ``B(u, v)``: fourth-order central differences along ``Re u`` and
        ``Im u`` with steps ``h, 2h`` (and ``2h, 4h``), Richardson-extrapolated.
    error : float
        Max-norm error estimate ``2 |D(h) - D(2h)| |v|`` (entrywise): it bounds the
        truncation error (15 times over) and measures the round-off noise of the
        smaller step; entries of ``J`` that do not vary cancel exactly.
    """
    x = np.asarray(x, dtype=float)
    u = np.asarray(u)
    v = np.asarray(v)
    h = _step(x, H_FIRST, step)
    ur, ui = np.real(u).astype(float), np.imag(u).astype(float)
    Dr, er = _first_dir(jac, x, p, ur, h)
    Di, ei = _first_dir(jac, x, p, ui, h)
    val = Dr @ v + 1j * (Di @ v) if (np.iscomplexobj(u) or np.iscomplexobj(v)) else Dr @ v
    err = float(np.max((er + ei) @ np.abs(v))) if v.size else 0.0
    return val, err


def _mixed(jac: Fun, x: Vec, p: float, a: Vec, b: Vec, h: float, J0: Vec) -> tuple[Vec, Vec]:
    """``D^2 J[a, b]`` for real ``a, b`` by polarisation ``(D2[a+b] - D2[a-b]) / 4``."""
    if not np.any(a) or not np.any(b):
        z = np.zeros_like(J0)
        return z, z
    if np.array_equal(a, b):
        return _second_dir(jac, x, p, a, h, J0)
    sp, ep = _second_dir(jac, x, p, a + b, h, J0)
    sm, em = _second_dir(jac, x, p, a - b, h, J0)
    return (sp - sm) / 4, (ep + em) / 4


def fd_trilinear(jac: Fun, x: Vec, p: float, u: Vec, v: Vec, w: Vec, *, step: float | None = None) -> tuple[Vec, float]:
    r"""``C(u, v, w) = (D_x^2 J(x, p)[u, v]) w`` by finite differences of the Jacobian.

    Parameters
    ----------
    jac : callable
        ``jac(x, p) -> (n, n)`` real Jacobian.
    x : ndarray, shape (n,)
        Point of expansion.
    p : float
        Parameter value.
    u, v, w : ndarray, shape (n,)
        Real or complex vectors.
    step : float, optional
        Absolute step along unit (max-norm) directions (default
        ``eps**(1/6) * max(1, |x|_inf)``).

    Returns
    -------
    value : ndarray, shape (n,)
        ``C(u, v, w)``: mixed second directional derivatives of ``J`` by
        polarisation, each a fourth-order central second difference with
        steps ``h, 2h`` (and ``2h, 4h``), Richardson-extrapolated.
    error : float
        Max-norm error estimate (as in :func:`fd_bilinear`).
    """
    x = np.asarray(x, dtype=float)
    u, v, w = np.asarray(u), np.asarray(v), np.asarray(w)
    h = _step(x, H_SECOND, step)
    J0 = np.asarray(jac(x, p), dtype=float)
    ur, ui = np.real(u).astype(float), np.imag(u).astype(float)
    vr, vi = np.real(v).astype(float), np.imag(v).astype(float)
    rr, err_rr = _mixed(jac, x, p, ur, vr, h, J0)
    ii, err_ii = _mixed(jac, x, p, ui, vi, h, J0)
    ri, err_ri = _mixed(jac, x, p, ur, vi, h, J0)
    ir, err_ir = _mixed(jac, x, p, ui, vr, h, J0)
    D = (rr - ii) + 1j * (ri + ir)
    E = err_rr + err_ii + err_ri + err_ir
    val = D @ w
    if not (np.iscomplexobj(u) or np.iscomplexobj(v) or np.iscomplexobj(w)):
        val = val.real
    return val, float(np.max(E @ np.abs(w))) if w.size else 0.0


def step_plateau(evaluate: Callable[[float], tuple[Any, ...]], exponents: range, *, settle: float = 0.0,
                 skip: tuple[type[BaseException], ...] = ()) -> tuple[tuple[Any, ...], float, float]:
    """The finite-difference step ``4**-k`` (``k`` in ``exponents``) where consecutive results agree best.

    Above the plateau truncation changes the result, below it rounding does; the step with the smallest
    change from the previous one is taken.  The scan stops two steps after that minimum once it is below
    ``1e-4`` of the value, or as soon as a change is below ``settle`` of the value.

    Parameters
    ----------
    evaluate : callable
        ``evaluate(factor) -> tuple`` whose first entry is the (complex) value compared.
    exponents : range
        The ``k`` tried, increasing (negative ``k``: steps larger than the default).
    settle : float
        Relative change small enough to stop at once (0: never).
    skip : tuple of exception types
        Failures of ``evaluate`` that are not errors: skipped for ``k < 0`` (a large step left the
        equations' domain), the end of the scan otherwise.

    Returns
    -------
    result, before, after : tuple, float, float
        ``evaluate`` at the chosen step and its changes from the neighbouring steps (``after`` is
        ``before`` at the end of the scan).

    Raises
    ------
    BrakesquealError
        Fewer than two steps gave a result.
    """
    from ..errors import BrakesquealError

    seq: list[tuple[Any, ...]] = []
    best: tuple[float, int] | None = None
    rising = 0
    for k in exponents:
        try:
            seq.append(evaluate(4.0 ** -k))
        except skip:
            if k < 0:
                continue
            break
        if len(seq) < 2:
            continue
        d = abs(seq[-1][0] - seq[-2][0])
        if best is None or d < best[0]:
            best, rising = (d, len(seq) - 1), 0
        else:
            rising += 1
            size = abs(seq[best[1]][0])
            if (rising >= 2 and best[0] <= 1e-4 * size) or best[0] <= settle * size:
                break
    if best is None:
        raise BrakesquealError("no two finite-difference steps gave a result")
    j = best[1]
    after = abs(seq[j + 1][0] - seq[j][0]) if j + 1 < len(seq) else best[0]
    return seq[j], best[0], after


def fd_dp(fun: Callable[[np.ndarray, float], Any], x: Vec, p: float, *, step: float | None = None) -> np.ndarray:
    """``d fun(x, p) / dp`` by the fourth-order central difference.

    Parameters
    ----------
    fun : callable
        ``fun(x, p) -> array`` (e.g. ``f`` or ``jac``).
    x : ndarray
        State.
    p : float
        Parameter value.
    step : float, optional
        Absolute step (default ``eps**(1/5) * max(1, |p|)``).

    Returns
    -------
    ndarray
        The derivative, same shape as ``fun(x, p)``.
    """
    h = float(step) if step is not None else H_FIRST * max(1.0, abs(p))
    a = np.asarray(fun(x, p + h), dtype=float) - np.asarray(fun(x, p - h), dtype=float)
    b = np.asarray(fun(x, p + 2 * h), dtype=float) - np.asarray(fun(x, p - 2 * h), dtype=float)
    return (8 * a - b) / (12 * h)


def _central_dx(fun: Callable[[np.ndarray, float], Any], x: np.ndarray, p: float) -> np.ndarray:
    """``d fun / dx`` by second-order central differences, step ``eps**(1/3) max(1, |x_i|)`` a coordinate.

    Column ``i`` is the derivative in ``x_i``: shape ``(n,)`` for a scalar ``fun``, ``(m, n)`` for ``fun -> (m,)``.
    """
    cols = []
    for i in range(x.size):
        h = EPS ** (1 / 3) * max(1.0, abs(x[i]))
        e = np.zeros(x.size)
        e[i] = h
        cols.append((np.asarray(fun(x + e, p), dtype=float) - np.asarray(fun(x - e, p), dtype=float)) / (2 * h))
    return np.stack(cols, axis=-1)


def _central_dp(fun: Callable[[np.ndarray, float], Any], x: np.ndarray, p: float) -> np.ndarray:
    """``d fun / dp`` by the second-order central difference, step ``eps**(1/3) max(1, |p|)``."""
    h = EPS ** (1 / 3) * max(1.0, abs(p))
    return (np.asarray(fun(x, p + h), dtype=float) - np.asarray(fun(x, p - h), dtype=float)) / (2 * h)


@dataclass(frozen=True)
class SmoothSystem:
    r"""A smooth autonomous system ``x' = f(x, p)`` with one continuation parameter ``p``.

    Attributes
    ----------
    f : callable
        ``f(x, p) -> ndarray (n,)``, the vector field (SI units throughout).
    jac : callable
        ``jac(x, p) -> ndarray (n, n)``, the Jacobian ``A = f_x``.
    n : int
        Dimension of the state.
    dfdp : callable, optional
        ``dfdp(x, p) -> (n,)``; finite differences of ``f`` when omitted.
    jac_p : callable, optional
        ``jac_p(x, p) -> (n, n)``, ``d A / d p`` at fixed ``x``; finite
        differences of ``jac`` when omitted.
    B : callable, optional
        ``B(x, p, u, v) -> (n,)``, the second derivative contracted with two
        (complex) vectors; finite differences of ``jac`` when omitted.
    C : callable, optional
        ``C(x, p, u, v, w) -> (n,)``, the third derivative contracted with
        three (complex) vectors; finite differences of ``jac`` when omitted.
    state_names : tuple of str, optional
        Names of the coordinates (default ``x1 ... xn``).
    parameter_name : str
        Name of ``p`` (default ``"p"``), used in datasets and plots.
    fd_step : float, optional
        Absolute finite-difference step of the ``B``/``C`` fallbacks (see
        :func:`fd_bilinear`); ``None`` for the default.
    """

    f: Fun
    jac: Fun
    n: int
    dfdp: Fun | None = None
    jac_p: Fun | None = None
    B: Callable[..., np.ndarray] | None = None
    C: Callable[..., np.ndarray] | None = None
    state_names: tuple[str, ...] | None = None
    parameter_name: str = "p"
    fd_step: float | None = None

    def __post_init__(self) -> None:
        if not (isinstance(self.n, (int, np.integer)) and self.n >= 1):
            raise ParameterError(f"SmoothSystem: 'n' must be a positive integer; got {self.n!r}")
        if self.state_names is None:
            object.__setattr__(self, "state_names", tuple(f"x{i + 1}" for i in range(self.n)))
        elif len(self.state_names) != self.n:
            raise ParameterError(
                f"SmoothSystem: 'state_names' must have n = {self.n} names; got {len(self.state_names)}"
            )

    # ------------------------------------------------------------- evaluation
    @property
    def exact_multilinear(self) -> bool:
        """``True`` when both ``B`` and ``C`` are given exactly."""
        return self.B is not None and self.C is not None

    def rhs(self, x: Vec, p: float) -> Vec:
        """``f(x, p)`` as a float array of shape ``(n,)``.

        Parameters
        ----------
        x : ndarray
            State.
        p : float
            Parameter.

        Returns
        -------
        ndarray
            The vector field.
        """
        return np.asarray(self.f(x, p), dtype=float)

    def jacobian(self, x: Vec, p: float) -> Vec:
        """``A = f_x(x, p)``, shape ``(n, n)``.

        Parameters
        ----------
        x : ndarray
            State.
        p : float
            Parameter.

        Returns
        -------
        ndarray
            The Jacobian.
        """
        return np.asarray(self.jac(x, p), dtype=float)

    def f_p(self, x: Vec, p: float) -> Vec:
        """``df/dp`` (exact when given, else :func:`fd_dp` of ``f``).

        Parameters
        ----------
        x : ndarray
            State.
        p : float
            Parameter.

        Returns
        -------
        ndarray
            Shape ``(n,)``.
        """
        if self.dfdp is not None:
            return np.asarray(self.dfdp(x, p), dtype=float)
        return fd_dp(self.f, x, p)

    def A_p(self, x: Vec, p: float) -> Vec:
        """``dA/dp`` at fixed ``x`` (exact when given, else :func:`fd_dp` of ``jac``).

        Parameters
        ----------
        x : ndarray
            State.
        p : float
            Parameter.

        Returns
        -------
        ndarray
            Shape ``(n, n)``.
        """
        if self.jac_p is not None:
            return np.asarray(self.jac_p(x, p), dtype=float)
        return fd_dp(self.jac, x, p)

    def bilinear(self, x: Vec, p: float, u: Vec, v: Vec, *, step: float | None = None) -> tuple[Vec, float]:
        """``(B(u, v), error estimate)``; the error is 0 for an exact ``B``.

        Parameters
        ----------
        x : ndarray
            Point of expansion.
        p : float
            Parameter.
        u, v : ndarray
            Real or complex vectors.
        step : float, optional
            Finite-difference step (overrides ``fd_step``).

        Returns
        -------
        tuple
            ``(value (n,), error)``.
        """
        if self.B is not None:
            return np.asarray(self.B(x, p, u, v)), 0.0
        return fd_bilinear(self.jac, x, p, u, v, step=step if step is not None else self.fd_step)

    def trilinear(self, x: Vec, p: float, u: Vec, v: Vec, w: Vec, *, step: float | None = None) -> tuple[Vec, float]:
        """``(C(u, v, w), error estimate)``; the error is 0 for an exact ``C``.

        Parameters
        ----------
        x : ndarray
            Point of expansion.
        p : float
            Parameter.
        u, v, w : ndarray
            Real or complex vectors.
        step : float, optional
            Finite-difference step (overrides ``fd_step``).

        Returns
        -------
        tuple
            ``(value (n,), error)``.
        """
        if self.C is not None:
            return np.asarray(self.C(x, p, u, v, w)), 0.0
        step = step if step is not None else (None if self.fd_step is None else self.fd_step * H_SECOND / H_FIRST)
        return fd_trilinear(self.jac, x, p, u, v, w, step=step)

    def as_piecewise(self) -> "PiecewiseSystem":
        """This system as a one-mode :class:`PiecewiseSystem` without transitions.

        Returns
        -------
        PiecewiseSystem
            One mode, no guards.
        """
        return PiecewiseSystem(modes=(self,), transitions=((),), mode_of=lambda x, p: 0)


@dataclass(frozen=True)
class Transition:
    r"""A switching rule of a :class:`PiecewiseSystem`: leave the current mode when a guard crosses zero.

    The event fires when ``h(x(t), p)`` crosses zero in ``direction``
    (``+1``: from negative to positive, ``-1``: from positive to negative,
    ``0``: either).  The state is then mapped by ``reset`` (identity when
    omitted) and the integration continues in mode ``target``.

    Attributes
    ----------
    guard : callable
        ``h(x, p) -> float``.
    target : int
        Index of the mode after the event.
    direction : int
        ``+1``, ``-1`` or ``0`` (see above).
    guard_grad : callable, optional
        ``dh/dx (x, p) -> (n,)``; central differences when omitted.
    guard_dp : callable, optional
        ``dh/dp (x, p) -> float``; central differences when omitted.
    reset : callable, optional
        ``g(x, p) -> (n,)``, the state just after the event (impact law).
    reset_jac : callable, optional
        ``dg/dx (x, p) -> (n, n)``; central differences when omitted.
    reset_dp : callable, optional
        ``dg/dp (x, p) -> (n,)``; central differences when omitted.
    name : str
        Label used in event lists (e.g. ``"contact-loss-pad1"``).
    """

    guard: Callable[[np.ndarray, float], float]
    target: int
    direction: int = 0
    guard_grad: Fun | None = None
    guard_dp: Callable[[np.ndarray, float], float] | None = None
    reset: Fun | None = None
    reset_jac: Fun | None = None
    reset_dp: Fun | None = None
    name: str = ""

    def __post_init__(self) -> None:
        if self.direction not in (-1, 0, 1):
            raise ParameterError(f"Transition: 'direction' must be -1, 0 or +1; got {self.direction!r}")

    def grad(self, x: Vec, p: float) -> Vec:
        """``dh/dx`` (exact or central differences with step ``eps**(1/3) max(1, |x_i|)``).

        Parameters
        ----------
        x : ndarray
            State.
        p : float
            Parameter.

        Returns
        -------
        ndarray
            Shape ``(n,)``.
        """
        if self.guard_grad is not None:
            return np.asarray(self.guard_grad(x, p), dtype=float)
        return _central_dx(self.guard, np.asarray(x, dtype=float), p)

    def h_p(self, x: Vec, p: float) -> float:
        """``dh/dp`` (exact or central differences).

        Parameters
        ----------
        x : ndarray
            State.
        p : float
            Parameter.

        Returns
        -------
        float
            The derivative.
        """
        if self.guard_dp is not None:
            return float(self.guard_dp(x, p))
        return float(_central_dp(self.guard, x, p))

    def apply(self, x: Vec, p: float) -> tuple[Vec, Vec, Vec]:
        """``(g(x), dg/dx, dg/dp)`` of the reset (identity when there is none).

        Parameters
        ----------
        x : ndarray
            State just before the event.
        p : float
            Parameter.

        Returns
        -------
        tuple
            ``(x_plus, G_x (n, n), G_p (n,))``.
        """
        x = np.asarray(x, dtype=float)
        n = x.size
        if self.reset is None:
            return x.copy(), np.eye(n), np.zeros(n)
        xp = np.asarray(self.reset(x, p), dtype=float)
        reset = self.reset
        G = _central_dx(reset, x, p) if self.reset_jac is None else np.asarray(self.reset_jac(x, p), dtype=float)
        Gp = _central_dp(reset, x, p) if self.reset_dp is None else np.asarray(self.reset_dp(x, p), dtype=float)
        return xp, G, Gp


@dataclass(frozen=True)
class PiecewiseSystem:
    r"""A piecewise-smooth system: smooth modes, guards that switch between them, reset maps.

    In mode ``i`` the state obeys ``modes[i]``; the transitions
    ``transitions[i]`` are watched and the first guard to cross zero (in its
    direction) switches to its ``target`` mode after applying its reset.
    Sliding motion along a switching surface (Filippov) is not supported: it
    is reported as an error by the integrator.

    Attributes
    ----------
    modes : tuple of SmoothSystem
        The vector field of each mode (same ``n``).
    transitions : tuple of tuple of Transition
        ``transitions[i]``: the guards active in mode ``i``.
    mode_of : callable
        ``mode_of(x, p) -> int``, the mode of a state (used at the start of an
        integration).
    mode_names : tuple of str, optional
        Labels of the modes (default ``mode0, mode1, ...``).
    """

    modes: tuple[SmoothSystem, ...]
    transitions: tuple[tuple[Transition, ...], ...]
    mode_of: Callable[[np.ndarray, float], int]
    mode_names: tuple[str, ...] | None = None
    _n: int = field(default=0, init=False, repr=False)

    def __post_init__(self) -> None:
        modes = tuple(self.modes)
        if not modes:
            raise ParameterError("PiecewiseSystem: 'modes' must hold at least one SmoothSystem")
        ns = {m.n for m in modes}
        if len(ns) != 1:
            raise ParameterError(f"PiecewiseSystem: all modes must have the same dimension n; got {sorted(ns)}")
        if len(self.transitions) != len(modes):
            raise ParameterError(
                f"PiecewiseSystem: 'transitions' must have one tuple per mode ({len(modes)}); "
                f"got {len(self.transitions)}"
            )
        for i, ts in enumerate(self.transitions):
            for t in ts:
                if not 0 <= t.target < len(modes):
                    raise ParameterError(f"PiecewiseSystem: transition {t.name!r} of mode {i} targets mode {t.target}, "
                                         f"allowed 0..{len(modes) - 1}")  # fmt: skip
        object.__setattr__(self, "modes", modes)
        object.__setattr__(self, "transitions", tuple(tuple(t) for t in self.transitions))
        object.__setattr__(self, "_n", modes[0].n)
        if self.mode_names is None:
            object.__setattr__(self, "mode_names", tuple(f"mode{i}" for i in range(len(modes))))

    @property
    def n(self) -> int:
        """State dimension."""
        return self._n

    @property
    def state_names(self) -> tuple[str, ...]:
        """Coordinate names (those of the first mode)."""
        return self.modes[0].state_names  # type: ignore[return-value]

    @property
    def parameter_name(self) -> str:
        """Name of the continuation parameter (that of the first mode)."""
        return self.modes[0].parameter_name

    def as_piecewise(self) -> "PiecewiseSystem":
        """Return ``self`` (for symmetry with :meth:`SmoothSystem.as_piecewise`).

        Returns
        -------
        PiecewiseSystem
            This system.
        """
        return self

