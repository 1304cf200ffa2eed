r"""Flows with sensitivities: the integrator interface used by shooting.

A *flow* is any callable ``flow(x0, T, p, *, sensitivities, n_samples, scale)
-> FlowResult`` returning the state at time ``T`` from ``x0`` and, when
``sensitivities`` is true, the monodromy ``M = d phi / d x0``, the parameter
sensitivity ``d phi / d p`` and the vector field at the end point.  Any
integrator (e.g. a numba-compiled one) can be plugged into the shooting and
continuation code by implementing this protocol (:class:`Flow`).

:class:`ScipyFlow` is the default: :func:`scipy.integrate.solve_ivp` (DOP853,
``rtol = 1e-11``) on the state augmented with the variational equations

.. math::

   \dot M = A(x, p) M,\quad M(0) = I;\qquad \dot x_p = A(x, p) x_p + f_p(x, p),\quad x_p(0) = 0,

or, with ``monodromy="finite-difference"``, central differences of the flow
(``2 n + 2`` extra integrations; error about ``rtol**(2/3)``).  For a
:class:`~.system.PiecewiseSystem` the integration stops at every guard
crossing (located by SciPy's event root finder to ``4 eps`` in time), applies
the reset, and maps the sensitivities across the switching surface with the
saltation matrix (Leine & Nijmeijer, *Dynamics and Bifurcations of Non-Smooth
Mechanical Systems*, eq. 7.58):

.. math::

   S = G_x + \frac{(f^+ - G_x f^-)\, \nabla h^T}{\nabla h^T f^-},\qquad
   x_p^+ = G_x x_p^- + G_p + \frac{(f^+ - G_x f^-)(\nabla h^T x_p^- + h_p)}{\nabla h^T f^-}.

A grazing crossing (``|grad h . f-|`` tiny) or an immediate re-crossing
(sliding) stops with an explicit status instead of returning wrong sensitivities.

With an implicit method (``"Radau"``, ``"BDF"``, ``"LSODA"``: stiff systems, e.g. pads with a
tangential damper, whose modes decay at ``k_ip / d_ip``) the integrator is given the Jacobian of the
augmented right-hand side (:func:`augmented_jacobian`): with ``Z`` stored row-major,

.. math::

   \frac{\partial (x', Z')}{\partial (x, Z)} = \begin{pmatrix} A & 0 \\ C & A \otimes I_{n+1} \end{pmatrix},
   \qquad C_{(i, j), l} = \sum_k \partial_{x_l} A_{ik} Z_{kj} + \delta_{jn} \partial_p A_{il},

``C`` by central differences of the mode's Jacobian (``augmented_jacobian="full"``) or dropped
(``"block"``, default): the Newton iterations of an implicit method only need an approximation of the
Jacobian, and the dropped block is strictly lower triangular in the (x, Z) blocks, so it delays
their convergence by at most one iteration (the x block does not depend on ``Z``, and ``Z`` is linear).
SciPy would otherwise difference the ``n (n + 2)`` augmented equations.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from collections.abc import Callable
from typing import Any, Literal, Protocol

import numpy as np
from scipy.integrate import solve_ivp

from ..errors import BrakesquealError, ParameterError
from .system import PiecewiseSystem, SmoothSystem, Transition

__all__ = ["Flow", "FlowResult", "ScipyFlow", "FlowError", "Event", "IMPLICIT_METHODS", "augmented_jacobian"]

#: ``solve_ivp`` methods that use a Jacobian (implicit, for stiff systems).
IMPLICIT_METHODS: tuple[str, ...] = ("Radau", "BDF", "LSODA")
#: ``solve_ivp`` methods :class:`ScipyFlow` accepts.
METHODS: tuple[str, ...] = ("DOP853", "RK45", "RK23") + IMPLICIT_METHODS


class FlowError(BrakesquealError):
    """The integration failed (solver failure, grazing, sliding, too many events)."""


@dataclass(frozen=True)
class Event:
    """One switching event during a flow.

    Attributes
    ----------
    t : float
        Time of the event from the start of the flow [s].
    name : str
        The transition's name.
    source, target : int
        Modes before and after.
    transversality : float
        ``grad h . f-`` at the event (small means grazing).
    x : ndarray
        State just before the event.
    """

    t: float
    name: str
    source: int
    target: int
    transversality: float
    x: np.ndarray = field(repr=False)


@dataclass
class FlowResult:
    """Result of one flow evaluation ``phi(x0, T, p)``.

    Attributes
    ----------
    x : ndarray, shape (n,)
        State at time ``T``.
    f_end : ndarray, shape (n,)
        Vector field at the end point (in the final mode).
    monodromy : ndarray, shape (n, n) or None
        ``d phi / d x0`` (with saltation matrices across events).
    dp : ndarray, shape (n,) or None
        ``d phi / d p``.
    t_samples : ndarray or None
        Uniform sample times ``T k / n_samples``, ``k = 0 .. n_samples - 1``.
    x_samples : ndarray, shape (n_samples, n) or None
        States at ``t_samples``.
    events : list of Event
        Switching events in time order.
    modes : list of int
        Mode of each sample (piecewise systems; empty otherwise).
    mode_end : int
        Mode at time ``T``.
    nfev : int
        Right-hand-side evaluations.
    monodromy_method : str
        ``"variational"``, ``"finite-difference"`` or ``"none"``.
    """

    x: np.ndarray
    f_end: np.ndarray
    monodromy: np.ndarray | None
    dp: np.ndarray | None
    t_samples: np.ndarray | None
    x_samples: np.ndarray | None
    events: list[Event]
    modes: list[int]
    mode_end: int
    nfev: int
    monodromy_method: str


class Flow(Protocol):
    """Protocol of a flow with sensitivities (see the module docstring)."""

    def __call__(self, x0: np.ndarray, T: float, p: float, *, sensitivities: bool = True, n_samples: int = 0,
                 scale: np.ndarray | None = None) -> FlowResult:  # fmt: skip
        """Integrate from ``x0`` over ``[0, T]`` at parameter ``p``.

        Parameters
        ----------
        x0 : ndarray
            Initial state.
        T : float
            Duration (> 0).
        p : float
            Parameter.
        sensitivities : bool
            Also return the monodromy matrix and ``d phi / d p``.
        n_samples : int
            Number of uniform output samples over ``[0, T)`` (0: none).
        scale : ndarray, optional
            Typical magnitude of each state component (sets absolute tolerances).

        Returns
        -------
        FlowResult
            End state and sensitivities.
        """
        ...  # pragma: no cover

    @property
    def system(self) -> Any:  # pragma: no cover - protocol
        """The system integrated."""
        ...


@dataclass
class ScipyFlow:
    """Default flow: ``solve_ivp`` with variational equations (or finite differences), events, saltation.

    Parameters
    ----------
    system : SmoothSystem or PiecewiseSystem
        The system.
    method : str
        A ``solve_ivp`` method: explicit ``"DOP853"`` (default), ``"RK45"``, ``"RK23"``, or implicit
        ``"Radau"``, ``"BDF"``, ``"LSODA"`` for stiff systems (given the Jacobian of the augmented system,
        see the module docstring).
    rtol : float
        Relative tolerance (default ``1e-11``), in ``[1e-13, 1e-3]``.
    atol : float or ndarray, optional
        Absolute tolerance of the state; default ``1e-3 rtol scale`` with
        ``scale`` given per call (else ``max(|x0|_inf, 1e-300)``).
    monodromy : str
        ``"variational"`` (default) or ``"finite-difference"``.
    max_events : int
        Maximum number of switching events in one flow (default 1000).
    augmented_jacobian : str
        Implicit methods only: ``"block"`` (default; the blocks ``A`` and ``A (x) I``, without the
        coupling ``dA/dx Z``) or ``"full"`` (with it, by central differences of the mode's Jacobian).
    atol_monodromy : float, optional
        Absolute tolerance of the monodromy's entries (default ``1e-3 rtol``).  A mode whose Jacobian
        is a finite difference with large entries (pads with a stiff damper: ``k_ip / d_ip``) has rounding
        noise in ``A Z`` that this tolerance, not the dynamics, then limits the step to; ``rtol``
        (the monodromy to ``rtol`` of its O(1) scale) removes that limit.
    """

    system: Any
    method: str = "DOP853"
    rtol: float = 1e-11
    atol: Any = None
    monodromy: Literal["variational", "finite-difference"] = "variational"
    max_events: int = 1000
    augmented_jacobian: Literal["block", "full"] = "block"
    atol_monodromy: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.system, (SmoothSystem, PiecewiseSystem)):
            raise ParameterError(
                f"ScipyFlow: 'system' must be a SmoothSystem or PiecewiseSystem; got {type(self.system).__name__}"
            )
        _check_rtol(self.rtol)
        if self.monodromy not in ("variational", "finite-difference"):
            raise ParameterError(
                f"The option 'monodromy' must be 'variational' or 'finite-difference'; got {self.monodromy!r}"
            )
        if self.method not in METHODS:
            raise ParameterError(f"The option 'method' must be one of {', '.join(METHODS)}; got {self.method!r}")
        if self.augmented_jacobian not in ("block", "full"):
            raise ParameterError(
                f"The option 'augmented_jacobian' must be 'block' or 'full'; got {self.augmented_jacobian!r}"
            )
        if self.atol_monodromy is not None and not (
            isinstance(self.atol_monodromy, (int, float)) and 0 < self.atol_monodromy < 1
        ):
            raise ParameterError(f"The option 'atol_monodromy' must be in (0, 1); got {self.atol_monodromy!r}")
        self._pw = self.system.as_piecewise()

    @property
    def implicit(self) -> bool:
        """``True`` for an implicit (stiff) method, which is given the augmented Jacobian."""
        return self.method in IMPLICIT_METHODS

    # ------------------------------------------------------------------ API
    def __call__(self, x0: np.ndarray, T: float, p: float, *, sensitivities: bool = True, n_samples: int = 0,
                 scale: np.ndarray | None = None) -> FlowResult:  # fmt: skip
        """Integrate from ``x0`` over ``[0, T]`` (see :class:`Flow`).

        Parameters
        ----------
        x0 : ndarray
            Initial state.
        T : float
            Duration (> 0).
        p : float
            Parameter.
        sensitivities : bool
            Also return the monodromy matrix and ``d phi / d p``.
        n_samples : int
            Number of uniform output samples over ``[0, T)``.
        scale : ndarray, optional
            Typical magnitude of each state component.

        Returns
        -------
        FlowResult
            End state and sensitivities.
        """
        x0 = np.asarray(x0, dtype=float)
        _check_duration(T)
        if not sensitivities:
            return self._integrate(x0, T, p, False, n_samples, scale)
        if self.monodromy == "variational":
            return self._integrate(x0, T, p, True, n_samples, scale)
        return self._fd(x0, T, p, n_samples, scale)

    # ------------------------------------------------------------ internals
    def _integrate(self, x0: np.ndarray, T: float, p: float, sens: bool, n_samples: int,
                   scale: np.ndarray | None) -> FlowResult:  # fmt: skip
        pw = self._pw
        n = pw.n
        mode = int(pw.mode_of(x0, p))
        y = _flow_start(x0, n, sens)
        atol = _flow_atol(self.atol, self.rtol, n, x0, scale, sens, self.atol_monodromy)
        t_samp = T * np.arange(n_samples) / n_samples if n_samples else None
        xs = np.empty((n_samples, n)) if n_samples else None
        smodes: list[int] = []
        events: list[Event] = []
        t = 0.0
        nfev = 0
        k_next = 0
        sref = np.asarray(scale, dtype=float) if scale is not None else np.abs(x0)
        start_dirs = _start_directions(pw, mode, x0, p, sref, 0.0, None)
        while True:
            msys = pw.modes[mode]
            trans = pw.transitions[mode]
            rhs = _rejecting(_augmented_rhs(msys, p, n) if sens else (lambda _t, yy, _m=msys: _m.rhs(yy, p)))
            jac_opt: dict[str, Any] = {}
            if self.implicit:
                full = self.augmented_jacobian == "full"
                jac_opt["jac"] = _jac_failing(
                    (lambda _t, yy, _m=msys: augmented_jacobian(_m, yy, p, coupling=full)) if sens
                    else (lambda _t, yy, _m=msys: _m.jacobian(yy, p)))
            evs: list[Callable[..., float]] = []
            dirs = [float(start_dirs.get(i, tr.direction)) for i, tr in enumerate(trans)]
            # a guard that is zero at the segment start (just after an event) would report a root there:
            # its event function is shifted by a tiny bias to the side the flow leaves to, and the true
            # crossing is located afterwards on the dense output
            xs0 = y[:n]
            bias = []
            for tr in trans:
                w = 1e-8 * float(np.sum(np.abs(tr.grad(xs0, p)) * np.maximum(np.abs(xs0), sref)))
                bias.append(w if abs(float(tr.guard(xs0, p))) <= 1e-2 * w else 0.0)
            for i, tr in enumerate(trans):
                def ev(_t: float, yy: np.ndarray, _tr: Transition = tr, _b: float = -dirs[i] * bias[i]) -> float:
                    return float(_tr.guard(yy[:n], p)) + _b
                ev.terminal = True  # type: ignore[attr-defined]
                ev.direction = dirs[i]  # type: ignore[attr-defined]
                evs.append(ev)
            # extrema of each guard (dh/dt = 0): a crossing in and out within one step is missed by the
            # sign test; it is found afterwards from the extremum's sign and the dense output
            for i, tr in enumerate(trans):
                def ext(_t: float, yy: np.ndarray, _tr: Transition = tr, _m: SmoothSystem = msys) -> float:
                    xx = yy[:n]
                    return float(_tr.grad(xx, p) @ _m.rhs(xx, p))
                ext.terminal = False  # type: ignore[attr-defined]
                ext.direction = -dirs[i]  # type: ignore[attr-defined]  # a max of h for +1, a min for -1
                evs.append(ext)
            t_eval = None
            if t_samp is not None:
                t_eval = np.append(t_samp[k_next:], T)
            sol = solve_ivp(rhs, (t, T), y, method=self.method, rtol=self.rtol, atol=atol, events=evs or None,
                            t_eval=t_eval, dense_output=bool(trans), **jac_opt)  # fmt: skip
            nfev += int(sol.nfev)
            if sol.status == -1:
                raise FlowError(f"integration failed at t = {t:.6g} s: {sol.message}")
            cands: list[tuple[float, int]] = []
            for i in range(len(trans)):
                if sol.t_events[i].size:
                    te_ = float(sol.t_events[i][0])
                    if bias[i]:
                        te_ = _true_root(sol, trans[i], dirs[i], n, p, t, te_)
                    cands.append((te_, i))
            t_stop = min(cands)[0] if cands else float(sol.t[-1]) if np.size(sol.t) else T
            missed = _missed_crossing(sol, trans, dirs, n, p, t, t_stop) if trans else None
            if missed is not None:
                cands.append(missed)
            if cands:
                t_stop = min(cands)[0]
            if t_eval is not None:
                tt = np.asarray(sol.t, dtype=float)
                m = int(np.count_nonzero((tt < T) & (tt <= t_stop)))
                if m:
                    xs[k_next:k_next + m] = np.asarray(sol.y)[:n, :m].T  # type: ignore[index]
                smodes.extend([mode] * m)
                k_next += m
            if not cands:
                if sol.status != 0:  # pragma: no cover - a terminal event always gives a candidate
                    raise FlowError(f"integration stopped at t = {sol.t[-1]:.6g} s without an event")
                y = sol.y[:, -1]
                break
            # a guard crossed zero: locate, reset, saltation
            te, i = min(cands)
            exact = missed is None and not bias[i] and sol.t_events[i].size and te == float(sol.t_events[i][0])
            ye = sol.y_events[i][0] if exact else sol.sol(te)
            tr = trans[i]
            xm = ye[:n]
            fm = msys.rhs(xm, p)
            gh = tr.grad(xm, p)
            sdot = float(gh @ fm)
            fs = max(float(np.linalg.norm(fm)), 1e-300) * max(float(np.linalg.norm(gh)), 1e-300)
            if abs(sdot) <= 1e-9 * fs:
                raise FlowError(f"grazing at t = {te:.6g} s ({tr.name or 'guard'}: grad h . f = {sdot:.3g}); "
                                "the saltation matrix is unbounded")  # fmt: skip
            xpl, G, Gp = tr.apply(xm, p)
            new_mode = tr.target
            fpl = pw.modes[new_mode].rhs(xpl, p)
            if sens:
                Zm = ye[n:].reshape(n, n + 1)
                Mm, xpm = Zm[:, :n], Zm[:, n]
                jump = fpl - G @ fm
                S = G + np.outer(jump, gh) / sdot
                xpp = G @ xpm + Gp + jump * (float(gh @ xpm) + tr.h_p(xm, p)) / sdot
                y = np.concatenate([xpl, np.column_stack([S @ Mm, xpp]).ravel()])
            else:
                y = xpl.copy()
            events.append(Event(t=te, name=tr.name, source=mode, target=new_mode, transversality=sdot, x=xm.copy()))
            if len(events) > self.max_events:
                raise FlowError(f"more than {self.max_events} events in one flow (chattering or Zeno behaviour)")
            # guards of the new mode that sit at zero: trigger only on the way back, or report sliding
            start_dirs = _start_directions(pw, new_mode, xpl, p, sref, te, tr.name)
            mode = new_mode
            t = te
            if t >= T:
                break
        x_end = y[:n].copy()
        f_end = pw.modes[mode].rhs(x_end, p)
        Z = y[n:].reshape(n, n + 1) if sens else None
        mono = Z[:, :n].copy() if Z is not None else None
        dpv = Z[:, n].copy() if Z is not None else None
        if xs is not None and k_next < n_samples:  # pragma: no cover - solve_ivp writes every t_eval point
            raise FlowError(f"only {k_next} of {n_samples} samples were written")
        return FlowResult(x=x_end, f_end=f_end, monodromy=mono, dp=dpv, t_samples=t_samp, x_samples=xs,
                          events=events, modes=smodes if len(pw.modes) > 1 else [], mode_end=mode, nfev=nfev,
                          monodromy_method="variational" if sens else "none")  # fmt: skip

    def _fd(self, x0: np.ndarray, T: float, p: float, n_samples: int, scale: np.ndarray | None) -> FlowResult:
        base = self._integrate(x0, T, p, False, n_samples, scale)
        n = x0.size
        s = np.asarray(scale, dtype=float) if scale is not None else np.full(n, max(float(np.max(np.abs(x0))), 1e-300))
        h_rel = self.rtol ** (1 / 3)
        M = np.empty((n, n))
        for j in range(n):
            h = h_rel * max(s[j], abs(x0[j]), 1e-300)
            e = np.zeros(n)
            e[j] = h
            a = self._integrate(x0 + e, T, p, False, 0, scale)
            b = self._integrate(x0 - e, T, p, False, 0, scale)
            M[:, j] = (a.x - b.x) / (2 * h)
            base.nfev += a.nfev + b.nfev
        hp = h_rel * max(1.0, abs(p))
        a = self._integrate(x0, T, p + hp, False, 0, scale)
        b = self._integrate(x0, T, p - hp, False, 0, scale)
        base.monodromy = M
        base.dp = (a.x - b.x) / (2 * hp)
        base.nfev += a.nfev + b.nfev
        base.monodromy_method = "finite-difference"
        return base


def _check_rtol(rtol: Any) -> None:
    """Refuse a relative tolerance outside ``[1e-13, 1e-3]`` (one line naming the option)."""
    if not (isinstance(rtol, (int, float)) and 1e-13 <= rtol <= 1e-3):
        raise ParameterError(f"The option 'rtol' must be in [1e-13, 1e-3]; got {rtol!r}")


def _check_duration(T: float) -> None:
    """Refuse a flow duration that is not positive and finite."""
    if not (math.isfinite(T) and T > 0):
        raise FlowError(f"flow duration must be positive and finite; got T = {T!r}")


def _flow_start(x0: np.ndarray, n: int, sens: bool) -> np.ndarray:
    """The initial state of a flow: ``x0``, followed with sensitivities by ``Z = [I | 0]`` (row-major)."""
    return np.concatenate([x0, np.hstack([np.eye(n), np.zeros((n, 1))]).ravel()]) if sens else x0.copy()


def _flow_atol(atol: Any, rtol: float, n: int, x0: np.ndarray, scale: np.ndarray | None, sens: bool,
               atol_monodromy: float | None = None) -> np.ndarray:
    """Absolute tolerances of a flow's state (and with sensitivities of ``Z = [M | x_p]``, row-major).

    The state's: ``atol`` when given, else ``1e-3 rtol scale`` (``scale`` default ``max(|x0|_inf, 1e-300)``);
    the monodromy's entries: ``atol_monodromy`` (default ``1e-3 rtol``); ``x_p``'s: those of the state.
    """
    if atol is not None:
        ax = np.broadcast_to(np.asarray(atol, dtype=float), (n,)).copy()
    else:
        s = np.asarray(scale, dtype=float) if scale is not None else np.full(n, max(float(np.max(np.abs(x0))), 1e-300))
        ax = 1e-3 * rtol * np.maximum(s, 1e-300)
    if not sens:
        return ax
    # Z = [M | x_p]: M entries are O(1); x_p scaled like x per unit of p (rtol dominates in practice)
    am = 1e-3 * rtol if atol_monodromy is None else float(atol_monodromy)
    Z = np.column_stack([np.full((n, n), am), ax])
    return np.concatenate([ax, Z.ravel()])


def _true_root(sol: Any, tr: Transition, direction: float, n: int, p: float, t0: float, te: float) -> float:
    """Zero of the unbiased guard before ``te`` (the biased event), on the dense output."""
    from scipy.optimize import brentq

    side0 = -direction
    hfun = lambda tq: float(tr.guard(sol.sol(tq)[:n], p))  # noqa: E731
    ts = np.linspace(t0, te, 65)[1:]
    hs = np.array([hfun(tq) for tq in ts])
    idx = np.flatnonzero(hs * side0 > 0)
    if idx.size == 0 or idx[-1] + 1 >= ts.size:
        return te
    j = int(idx[-1])
    if hs[j + 1] * side0 > 0:  # pragma: no cover - the biased event lies past the true root
        return te
    return float(brentq(hfun, ts[j], ts[j + 1], xtol=4 * np.finfo(float).eps * max(1.0, abs(te))))


def _missed_crossing(sol: Any, trans: tuple, dirs: list[float], n: int, p: float, t0: float,
                     t_stop: float) -> tuple[float, int] | None:  # fmt: skip
    """Earliest guard crossing hidden inside a step: ``(time, transition index)`` or ``None``.

    At every extremum of a guard before ``t_stop`` whose value has the triggering sign, the guard crossed
    zero unseen; the crossing is located on the dense output (scan + Brent) after the previous extremum.
    """
    from scipy.optimize import brentq

    best: tuple[float, int] | None = None
    k = len(trans)
    for i, tr in enumerate(trans):
        prev = t0
        h0 = float(tr.guard(sol.sol(t0)[:n], p))
        side0 = -dirs[i] if dirs[i] != 0 else np.sign(h0)  # sign of h before a crossing
        for tm in sol.t_events[k + i]:
            if tm >= t_stop:
                break
            hm = float(tr.guard(sol.sol(tm)[:n], p))
            if side0 == 0 or hm * side0 >= 0:
                prev = tm
                continue
            ts = np.linspace(prev, tm, 33)
            hs = np.array([float(tr.guard(sol.sol(tq)[:n], p)) for tq in ts])
            idx = np.flatnonzero(hs * side0 > 0)
            if idx.size == 0:
                break
            j = int(idx[-1])
            hfun = lambda tq: float(tr.guard(sol.sol(tq)[:n], p))  # noqa: E731
            tc = brentq(hfun, ts[j], ts[j + 1], xtol=4 * np.finfo(float).eps * max(1.0, abs(tm)))
            if best is None or tc < best[0]:
                best = (tc, i)
            break
    return best


def _start_directions(pw: PiecewiseSystem, mode: int, x: np.ndarray, p: float, sref: np.ndarray, t: float,
                      after: str | None) -> dict[int, float]:  # fmt: skip
    """Effective directions of the guards of ``mode`` that are zero at ``x`` (start or just after an event).

    A two-sided guard at zero would fire at once; it is made one-sided (fires when the flow comes back).
    After an event, a one-sided guard that the new vector field crosses at once means sliding: an error.
    """
    out: dict[int, float] = {}
    f = pw.modes[mode].rhs(x, p)
    for j, tr in enumerate(pw.transitions[mode]):
        h = float(tr.guard(x, p))
        g = tr.grad(x, p)
        if abs(h) > 1e-8 * float(np.sum(np.abs(g) * np.maximum(np.abs(x), sref))):
            continue
        d = float(g @ f)
        if after is not None and tr.direction != 0 and d * tr.direction > 0:
            raise FlowError(f"sliding motion at t = {t:.6g} s: after {after or 'an event'} the guard "
                            f"{tr.name or j} is crossed again at once (Filippov sliding is not supported)")  # fmt: skip
        if tr.direction == 0 and d != 0:
            out[j] = -float(np.sign(d))
    return out


def _rejecting(rhs: Any) -> Any:
    """``rhs`` returning NaN where the vector field cannot be evaluated (a ``ParameterError``, e.g. a pad
    equation without a solution at a trial stage of a too large step): SciPy's step control then rejects the
    step and retries a smaller one, and an accepted state that cannot be evaluated ends in a failed
    integration (``FlowError``), never in a wrong number."""

    def safe(t: float, y: np.ndarray) -> np.ndarray:
        try:
            return rhs(t, y)
        except ParameterError:
            return np.full(np.shape(y), np.nan)

    return safe


def _augmented_rhs(msys: SmoothSystem, p: float, n: int) -> Any:
    """RHS of ``(x, Z)`` with ``Z = [M | x_p]`` (n x (n+1), row-major): ``Z' = A Z + [0 | f_p]``."""
    f, jac = msys.f, msys.jac
    fp = msys.dfdp if msys.dfdp is not None else msys.f_p
    n1 = n + 1

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        x = y[:n]
        dZ = np.asarray(jac(x, p), dtype=float) @ y[n:].reshape(n, n1)
        dZ[:, n] += fp(x, p)
        return np.concatenate((np.asarray(f(x, p), dtype=float), dZ.ravel()))

    return rhs


def _jac_failing(jac: Any) -> Any:
    """``jac`` raising :class:`FlowError` where the Jacobian cannot be evaluated (no NaN into the LU)."""

    def safe(t: float, y: np.ndarray) -> np.ndarray:
        try:
            J = jac(t, y)
        except ParameterError as exc:
            raise FlowError(f"the Jacobian cannot be evaluated at t = {t:.6g} s: {exc}") from exc
        if not np.all(np.isfinite(J)):
            raise FlowError(f"the Jacobian is not finite at t = {t:.6g} s")
        return J

    return safe


def augmented_jacobian(system: SmoothSystem, y: np.ndarray, p: float, *, coupling: bool = True,
                       step: float | None = None) -> np.ndarray:  # fmt: skip
    r"""Jacobian of the state augmented with the variational equations (see the module docstring).

    The augmented state is ``y = (x, Z)`` with ``Z = [M | x_p]`` (``n x (n + 1)``, row-major) and
    ``y' = (f(x, p), A(x, p) Z + [0 | f_p(x, p)])``.

    Parameters
    ----------
    system : SmoothSystem
        The (mode's) vector field with its Jacobian ``A = f_x``.
    y : ndarray, shape (n (n + 2),)
        Augmented state.
    p : float
        Parameter.
    coupling : bool
        Include the block ``d(A Z + [0 | f_p]) / dx`` (fourth-order central differences of ``A`` along
        each coordinate, step ``eps**(1/5) max(1, |x_l|)``, and ``dA/dp``); without it the Jacobian is
        block diagonal (exact for a linear system).
    step : float, optional
        Relative finite-difference step of the coupling (default ``eps**(1/5)``).

    Returns
    -------
    ndarray, shape (n (n + 2), n (n + 2))
        ``[[A, 0], [C, A (x) I_{n+1}]]``.

    Raises
    ------
    ParameterError
        ``y`` has the wrong size.
    """
    n = system.n
    n1 = n + 1
    y = np.asarray(y, dtype=float)
    if y.shape != (n * (n + 2),):
        raise ParameterError(f"augmented_jacobian: 'y' must have n (n + 2) = {n * (n + 2)} entries; got {y.shape}")
    x = y[:n]
    A = system.jacobian(x, p)
    N = n * (n + 2)
    J = np.zeros((N, N))
    J[:n, :n] = A
    J[n:, n:] = np.kron(A, np.eye(n1))
    if coupling:
        Z = y[n:].reshape(n, n1)
        rel = float(step) if step is not None else float(np.finfo(float).eps) ** (1 / 5)
        C = np.empty((n, n1, n))  # C[i, j, l] = d(A Z)_{ij} / dx_l
        for l_ in range(n):
            h = rel * max(1.0, abs(float(x[l_])))
            e = np.zeros(n)
            e[l_] = h
            Ak = {k: system.jacobian(x + k * e, p) for k in (-2, -1, 1, 2)}
            dA = (8 * (Ak[1] - Ak[-1]) - (Ak[2] - Ak[-2])) / (12 * h)
            C[:, :, l_] = dA @ Z
        C[:, n, :] += system.A_p(x, p)  # d f_p / dx = d A / dp
        J[n:, :n] = C.reshape(n * n1, n)
    return J
