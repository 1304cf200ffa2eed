r"""Pseudo-arclength continuation of periodic orbits in one parameter, with bifurcation detection.

Unknowns ``y = (X_0 .. X_{m-1}, T, p)`` (multiple shooting, see
:mod:`.periodic`), scaled componentwise by ``s = (sigma_x .. sigma_x,
sigma_T, sigma_p)``: ``sigma_p`` is the width of the parameter range,
``sigma_T`` the initial period and ``sigma_x`` a per-coordinate amplitude
scale (the predicted amplitude at the far end of the range when starting from
a Hopf point, the orbit's amplitude otherwise).  In scaled variables
``yhat = y / s`` each step is

* predictor ``yhat_k + ds t_k`` (``t_k``: unit tangent, the null vector of the
  Jacobian of the shooting equations and phase condition, oriented along the
  previous tangent);
* corrector: Newton on the shooting equations, the Poincaré phase condition
  with respect to the previous orbit, and ``t_k . (yhat - yhat_pred) = 0``.

Step control: the step is halved when Newton needs more than ``max_newton``
iterations or the tangent turns by more than ``max_angle``, grown by 1.5
after fast convergence, within ``[ds_min, ds_max]``.

Branch switching at a Hopf point uses the normal-form prediction
(:meth:`.hopf.HopfResult.cycle_guess`): the first orbit is corrected with the
arclength condition along the predicted branch direction (mostly the
amplitude direction), so it is found at a prescribed amplitude rather than at
a prescribed parameter value.

Test functions, evaluated at every point and located by the Illinois
(regula falsi) method on the arclength when they change sign:

========  ==========================================================  ==========================
label     test function                                               event
========  ==========================================================  ==========================
``LPC``   p-component of the tangent                                  fold of cycles
``PD``    ``prod (1 + mu_i)`` over non-trivial multipliers            period doubling (mu = -1)
``NS``    ``prod_{i<j} (mu_i mu_j - 1)``, kept if a complex           Neimark-Sacker (torus)
          pair is on the unit circle (else a neutral saddle)
``BPC``   ``prod (mu_i - 1)`` when the tangent test does not          branch point of cycles
          change
``GR``    the multiset of switching events per period changes         grazing / contact change
          (located by bisection)                                      (piecewise systems)
``EP``    the end of the parameter range                              end point
========  ==========================================================  ==========================
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Iterable, Sequence

import numpy as np

from ..errors import BrakesquealError, ParameterError
from .flow import FlowError
from .hopf import HopfResult
from .periodic import (PeriodicOrbit, _best_phase, _evaluate, _guard_clearance, _make_flow, _orbit_from, _resampled,
                       _scale_from, _system_of, _vector_field)

__all__ = ["CycleBranch", "SpecialPoint", "continue_cycles", "SPECIAL_KINDS"]

#: Labels of the special points that :func:`continue_cycles` can detect.
SPECIAL_KINDS: tuple[str, ...] = ("H", "LPC", "PD", "NS", "BPC", "GR", "EP")
#: Amplitudes tried for the first orbit off a Hopf point (each a quarter of the one before).
FIRST_ORBIT_TRIES = 6


class _NoConvergence(Exception):
    pass


@dataclass(frozen=True)
class SpecialPoint:
    """A special point of a cycle branch.

    Attributes
    ----------
    kind : str
        ``"H"`` (Hopf point, start), ``"LPC"`` (fold of cycles), ``"PD"``
        (period doubling), ``"NS"`` (Neimark–Sacker), ``"BPC"`` (branch point
        of cycles), ``"GR"`` (change of the switching events: grazing),
        ``"EP"`` (end of the parameter range).
    index : int
        Index of the point in the branch arrays.
    p : float
        Parameter value.
    period : float
        Period [s].
    amplitude : ndarray, shape (n,)
        First-harmonic amplitude per coordinate.
    floquet : ndarray, shape (n - 1,), complex
        Non-trivial multipliers.
    description : str
        What was located and how accurately.
    """

    kind: str
    index: int
    p: float
    period: float
    amplitude: np.ndarray
    floquet: np.ndarray
    description: str = ""


@dataclass
class _Point:
    y: np.ndarray
    tangent: np.ndarray
    orbit: PeriodicOrbit
    iterations: int
    label: str = ""
    tests: dict[str, float] = field(default_factory=dict)
    events: tuple[str, ...] = ()


@dataclass
class CycleBranch:
    """A continued branch of periodic orbits.

    Attributes
    ----------
    data : xarray.Dataset
        Per point (dim ``point``): the parameter (named after the system's
        parameter, also as coordinate ``p``), ``period`` [s], ``frequency``
        [Hz], ``omega`` [rad/s], ``amplitude`` (first harmonic), ``mean``,
        ``x_max``, ``x_min``, ``x0`` (the orbit's phase point) per coordinate
        (dim ``coord``), ``stable``, ``n_unstable``, ``floquet_re``,
        ``floquet_im``, ``floquet_abs`` (dim ``floquet``: non-trivial
        multipliers by decreasing modulus), ``trivial_multiplier_error``,
        ``multiplier_accuracy``, ``multiplier_change``, ``largest_multiplier``, ``verdict``
        (``"stable"``, ``"unstable"`` or ``"undecided"``, :mod:`.floquet`),
        ``label`` (special-point kind or ``""``), ``arclength``, ``orbit``
        (dims ``point, phase, coord``: one period, uniformly sampled).
        Special points along dim ``special``: ``special_kind``,
        ``special_index``, ``special_p``, ``special_period``,
        ``special_amplitude``.  ``attrs``: parameter name, status, message,
        Hopf data, ``hysteresis_range`` (when found), integrator settings.
    special : list of SpecialPoint
        Special points (also in ``data``).
    status : str
        Why the continuation stopped: ``"range"`` (end of the parameter
        range), ``"max_points"``, ``"step_underflow"``, ``"equilibrium"``
        (amplitude back to zero), ``"period"`` (period beyond
        ``max_period``), ``"flow_error"``.
    message : str
        Human-readable explanation of ``status``.
    hopf : HopfResult or None
        The Hopf point the branch started from.
    orbits : list of PeriodicOrbit
        The orbit at every point.
    """

    data: Any
    special: list[SpecialPoint]
    status: str
    message: str
    hopf: HopfResult | None
    orbits: list[PeriodicOrbit] = field(repr=False)

    @property
    def hysteresis_range(self) -> tuple[float, float] | None:
        """``(p_lo, p_hi)`` where a stable equilibrium coexists with stable large cycles, or ``None``.

        Found for a subcritical Hopf point whose unstable branch turns at a
        fold of cycles into stable cycles: the range between the fold and the
        Hopf point.
        """
        r = self.data.attrs.get("hysteresis_range")
        return None if r is None or len(r) != 2 else (float(r[0]), float(r[1]))

    def to_xarray(self) -> Any:
        """The branch as an :class:`xarray.Dataset` (same as :attr:`data`).

        Returns
        -------
        xarray.Dataset
            See :attr:`data`.
        """
        return self.data

    def plot(self, coord: str | int | None = None, ax: Any = None) -> Any:
        """Bifurcation diagram: amplitude and frequency against the parameter.

        Stable orbits are drawn solid, unstable ones dashed; the Hopf point,
        folds (LPC), period doublings (PD), Neimark–Sacker (NS), branch points
        and grazing points are marked.

        Parameters
        ----------
        coord : str or int, optional
            Coordinate whose first-harmonic amplitude is drawn (default: the
            first coordinate).
        ax : sequence of two matplotlib Axes, optional
            Draw into these (amplitude, frequency) instead of a new figure.

        Returns
        -------
        matplotlib.figure.Figure
            The figure.
        """
        from ..plotting import new_figure

        ds = self.data
        names = list(ds["coord"].values)
        if coord is None:
            j = 0
        elif isinstance(coord, (int, np.integer)):
            j = int(coord)
        else:
            if coord not in names:
                raise ParameterError(f"The option 'coord' must be one of {names}; got {coord!r}")
            j = names.index(coord)
        if ax is None:
            fig, a0 = new_figure(size=(6.4, 6.4))
            a0.remove()
            axes = fig.subplots(2, 1, sharex=True)
        else:
            axes = list(ax)
            fig = axes[0].figure
        pn = ds.attrs.get("parameter", "p")
        p = ds["p"].values
        amp = ds["amplitude"].values[:, j]
        fr = ds["frequency"].values
        st = ds["stable"].values.astype(bool)
        for a, yv in ((axes[0], amp), (axes[1], fr)):
            start = 0
            for i in range(1, len(p) + 1):
                if i == len(p) or st[i] != st[start]:
                    seg = slice(start, min(i + 1, len(p)))
                    a.plot(p[seg], yv[seg], "-" if st[start] else "--", color="C0" if st[start] else "C3", lw=1.5)
                    start = i
        marks = {"H": ("s", "k"), "LPC": ("o", "C1"), "PD": ("^", "C2"), "NS": ("D", "C4"), "BPC": ("v", "C5"),
                 "GR": ("x", "C6")}  # fmt: skip
        shown: set[str] = set()
        for sp in self.special:
            if sp.kind not in marks:
                continue
            mk, col = marks[sp.kind]
            lab = sp.kind if sp.kind not in shown else None
            shown.add(sp.kind)
            axes[0].plot([sp.p], [sp.amplitude[j]], mk, color=col, ms=7, label=lab, zorder=5)
            axes[1].plot([sp.p], [1.0 / sp.period], mk, color=col, ms=7, zorder=5)
        axes[0].plot([], [], "-", color="C0", label="stable")
        axes[0].plot([], [], "--", color="C3", label="unstable")
        axes[0].legend(loc="best", fontsize="small")
        for a in axes:
            a.ticklabel_format(axis="y", useOffset=False)
        if np.ptp(fr) <= 1e-9 * max(float(np.max(np.abs(fr))), 1e-300):
            axes[1].set_ylim(float(np.mean(fr)) * 0.99, float(np.mean(fr)) * 1.01)
        from ..labels import axis_label, branch_status_text, unit
        from ..model.components import coordinate_unit

        axes[0].set_ylabel(f"first-harmonic amplitude of {names[j]} [{coordinate_unit(str(names[j]))}]")
        axes[1].set_ylabel("frequency [Hz]")
        axes[1].set_xlabel(axis_label(pn, unit(pn) or None))
        fig.suptitle(f"limit cycles (shooting): {branch_status_text(self.status)}")
        return fig


# ----------------------------------------------------------------- the engine
class _Engine:
    def __init__(self, flow: Any, m: int, n: int, sv: np.ndarray, xscale: np.ndarray, tol: float, n_samples: int,
                 max_newton: int) -> None:  # fmt: skip
        self.flow = flow
        self.system = _system_of(flow)
        self.m, self.n = m, n
        self.N = m * n
        self.sv = sv
        self.xscale = xscale
        self.rowscale = np.tile(sv[:n], m)
        self.tol = tol
        self.n_samples = n_samples
        self.max_newton = max_newton
        pw = self.system.as_piecewise()
        self.guarded = any(len(t) for t in pw.transitions)

    def unpack(self, y: np.ndarray) -> tuple[np.ndarray, float, float]:
        return y[: self.N].reshape(self.m, self.n), float(y[self.N]), float(y[self.N + 1])

    def phase_row(self, y: np.ndarray) -> np.ndarray:
        X, _T, p = self.unpack(y)
        w = _vector_field(self.system, X[0], p) * self.sv[: self.n]
        nw = float(np.linalg.norm(w))
        if nw == 0 or not math.isfinite(nw):
            raise _NoConvergence("vector field vanishes at the phase point")
        return w / nw

    def jacobian(self, ev: Any, T: float, prow: np.ndarray) -> np.ndarray:
        N, n = self.N, self.n
        if ev.Jp is None:
            raise BrakesquealError("the flow returned no parameter sensitivity (dp): continuation needs it")
        DG = np.zeros((N + 1, N + 2))
        DG[:N, :N] = ev.JX * self.sv[None, :N]
        DG[:N, N] = ev.JT * self.sv[N]
        DG[:N, N + 1] = ev.Jp * self.sv[N + 1]
        DG[:N] /= self.rowscale[:, None]
        DG[N, :n] = prow
        return DG

    def correct(self, y_pred: np.ndarray, t_ref: np.ndarray, y_ref: np.ndarray,
                relaxed: bool = False) -> tuple[np.ndarray, Any, np.ndarray, int]:  # fmt: skip
        """Newton with phase condition w.r.t. ``y_ref`` and arclength ``t_ref . (yhat - yhat_pred) = 0``.

        ``relaxed``: up to 4 times more iterations and only monotone decrease required (near grazing the
        shooting map is only once differentiable and Newton converges linearly).
        """
        prow = self.phase_row(y_ref)
        Xr = y_ref[: self.n]
        y = y_pred.copy()
        last = np.inf
        max_it = self.max_newton * (4 if relaxed else 1)
        for it in range(1, max_it + 1):
            X, T, p = self.unpack(y)
            if not (T > 0 and math.isfinite(T)):
                raise _NoConvergence("non-positive period")
            try:
                ev = _evaluate(self.flow, X, T, p, self.xscale)
            except FlowError as exc:
                raise _NoConvergence(str(exc)) from None
            DG = self.jacobian(ev, T, prow)
            G = np.concatenate([ev.R / self.rowscale, [prow @ ((X[0] - Xr) / self.sv[: self.n])]])
            arc = float(t_ref @ ((y - y_pred) / self.sv))
            J = np.vstack([DG, t_ref[None, :]])
            try:
                d = -np.linalg.solve(J, np.concatenate([G, [arc]]))
            except np.linalg.LinAlgError:
                raise _NoConvergence("singular Jacobian") from None
            step = float(np.max(np.abs(d)))
            if not math.isfinite(step):
                raise _NoConvergence("non-finite Newton step")
            if step < self.tol:
                return y, ev, DG, it
            if it >= 3 and step > (last if relaxed else 0.5 * last):
                raise _NoConvergence("Newton is not converging")
            y = y + d * self.sv
            last = step
        raise _NoConvergence(f"no convergence in {max_it} iterations")

    def tangent(self, y: np.ndarray, DG: np.ndarray, t_prev: np.ndarray) -> np.ndarray:
        DGn = DG.copy()
        DGn[self.N, :] = 0.0
        DGn[self.N, : self.n] = self.phase_row(y)
        rhs = np.zeros(self.N + 2)
        rhs[-1] = 1.0
        t = np.linalg.solve(np.vstack([DGn, t_prev[None, :]]), rhs)
        t /= np.linalg.norm(t)
        return t if t @ t_prev >= 0 else -t

    def point(self, y_pred: np.ndarray, t_ref: np.ndarray, y_ref: np.ndarray, *, samples: bool = True,
              t_orient: np.ndarray | None = None, relaxed: bool = False) -> _Point:  # fmt: skip
        y, ev, DG, it = self.correct(y_pred, t_ref, y_ref, relaxed)
        X, T, p = self.unpack(y)
        try:
            orbit = _orbit_from(self.flow, X, T, p, ev, self.xscale, it, 0.0, self.n_samples if samples else 0)
        except FlowError as exc:  # the sampling run failed where the corrector's run did not: a failed step
            raise _NoConvergence(str(exc)) from None
        t = self.tangent(y, DG, t_ref if t_orient is None else t_orient)
        pt = _Point(y=y, tangent=t, orbit=orbit, iterations=it)
        pt.tests = _tests(pt)
        pt.events = tuple(sorted(e.name for e in orbit.events))
        return pt

    def rephase(self, pt: _Point) -> _Point:
        """Move the phase point away from switching surfaces (piecewise systems), keeping the orbit.

        The tangent's state block is transported to the new phase by the flow's sensitivities and
        used to orient the tangent recomputed there.
        """
        if not self.guarded:
            return pt
        X, T, p = self.unpack(pt.y)
        c0 = _guard_clearance(self.system, X[0], p, self.xscale)
        S = pt.orbit.samples
        if c0 >= 0.05 or S.shape[0] == 0:
            return pt
        k = _best_phase(self.system, S, p, self.xscale)
        if _guard_clearance(self.system, S[k], p, self.xscale) < 3 * c0 or k == 0:
            return pt
        tau = T * k / S.shape[0]
        fr = self.flow(X[0], tau, p, sensitivities=True, scale=self.xscale)
        n, N = self.n, self.N
        t = pt.tangent * self.sv
        dX0 = fr.monodromy @ t[:n] + fr.f_end * (k / S.shape[0]) * t[N] + fr.dp * t[N + 1]
        Xn = self.flow(fr.x, T, p, sensitivities=False, n_samples=self.m, scale=self.xscale).x_samples
        y_new = np.concatenate([Xn.ravel(), [T, p]])
        t_or = np.zeros_like(t)
        t_or[:n], t_or[N:] = dX0, t[N:]
        t_or /= self.sv
        t_or /= np.linalg.norm(t_or)
        try:
            new = self.point(y_new, t_or, y_new, t_orient=t_or)
        except _NoConvergence:
            return pt
        new.label, new.iterations = pt.label, pt.iterations
        return new

    def with_samples(self, pt: _Point) -> _Point:
        if pt.orbit.samples.shape[0] == 0:
            pt.orbit = _resampled(self.flow, pt.orbit, self.xscale, self.n_samples)
        return pt


def _tests(pt: _Point) -> dict[str, float]:
    mu = pt.orbit.floquet
    big = np.maximum(1.0, np.abs(mu))
    pd = float(np.real(np.prod((1 + mu) / big)))
    bp = float(np.real(np.prod((mu - 1) / big)))
    ns = 1.0
    for i in range(mu.size):
        for j in range(i + 1, mu.size):
            ns *= (mu[i] * mu[j] - 1) / max(1.0, abs(mu[i] * mu[j]))
    return {"LPC": float(pt.tangent[-1]), "PD": pd, "NS": float(np.real(ns)), "BPC": bp}


def _check_special(kind: str, pt: _Point) -> str | None:
    """Validate a located zero of a test function; ``None`` when it is not that bifurcation."""
    mu = pt.orbit.floquet
    if kind == "PD":
        k = int(np.argmin(np.abs(mu + 1)))
        return f"multiplier {mu[k].real:+.10f}{mu[k].imag:+.2e}j (-1 expected)" if abs(mu[k] + 1) < 1e-4 else None
    if kind == "NS":
        cx = [z for z in mu if abs(z.imag) > 1e-6]
        if not cx:
            return None
        z = min(cx, key=lambda z: abs(abs(z) - 1))
        if abs(abs(z) - 1) > 1e-4:
            return None
        return f"multipliers |mu| = {abs(z):.10f}, arg = +-{abs(np.angle(z)):.8f} rad"
    if kind == "BPC":
        k = int(np.argmin(np.abs(mu - 1)))
        return f"second multiplier {mu[k].real:.10f} (1 expected)" if abs(mu[k] - 1) < 1e-4 else None
    if kind == "LPC":
        return f"tangent p-component {pt.tangent[-1]:.2e}"
    return ""


def _locate(eng: _Engine, a: _Point, ds: float, fun: Any, g_hi: float, g_lo: float, gtol: float,
            max_iter: int = 40) -> _Point | None:  # fmt: skip
    """Illinois method on ``s`` in ``[0, ds]`` from point ``a`` along its tangent for a zero of ``fun(point)``.

    Stops when ``|fun| <= gtol``, when the bracket is below ``1e-12 ds`` or after ``max_iter`` corrections;
    returns the last corrected point (``None`` if a correction fails before any succeeded).
    """
    s_lo, s_hi = 0.0, ds
    yhat0 = a.y / eng.sv
    side = 0
    best: _Point | None = None
    for _ in range(max_iter):
        s = (s_lo * g_hi - s_hi * g_lo) / (g_hi - g_lo) if g_hi != g_lo else 0.5 * (s_lo + s_hi)
        if not (s_lo < s < s_hi):
            s = 0.5 * (s_lo + s_hi)
        try:
            pt = eng.point((yhat0 + s * a.tangent) * eng.sv, a.tangent, a.y, samples=False)
        except _NoConvergence:
            return best
        g = fun(pt)
        best = pt
        if abs(g) <= gtol or (s_hi - s_lo) <= 1e-12 * ds:
            break
        if g * g_hi > 0:
            s_hi, g_hi = s, g
            if side == -1:
                g_lo /= 2
            side = -1
        else:
            s_lo, g_lo = s, g
            if side == 1:
                g_hi /= 2
            side = 1
    return best


def _at_parameter(eng: _Engine, a: _Point, b: _Point, bound: float) -> _Point | None:
    """The orbit at ``p = bound`` between ``a`` and ``b`` (natural-parameter correction, Illinois as fallback)."""
    pa, pb = a.y[-1], b.y[-1]
    w = (bound - pa) / (pb - pa)
    y_pred = (1 - w) * a.y + w * b.y
    y_pred[-1] = bound
    e_p = np.zeros_like(a.tangent)
    e_p[-1] = 1.0
    try:
        return eng.point(y_pred, e_p, a.y, samples=False, t_orient=a.tangent)
    except _NoConvergence:
        width = eng.sv[-1]
        ds = float(a.tangent @ ((b.y - a.y) / eng.sv))
        return _locate(eng, a, ds, lambda q: (q.y[-1] - bound) / width, (pb - bound) / width, (pa - bound) / width,
                       1e-13)  # fmt: skip


def _bisect_events(eng: _Engine, a: _Point, b: _Point, ev_a: tuple[str, ...]) -> _Point | None:
    """Bisection for the change of the switching events (grazing) between the branch points ``a`` and ``b``.

    Each trial is predicted at the midpoint of the current bracket and corrected on the hyperplane through
    it normal to the bracket's chord (relaxed Newton: the shooting map is only C^1 at grazing), so the
    predictor stays close to the branch however long the step was; stops when the bracket is below
    ``1e-10`` in scaled arclength.  Returns the located point on the far side (events changed).
    """
    lo, hi = a.y, b.y
    best = None
    for _ in range(60):
        chord = (hi - lo) / eng.sv
        length = float(np.linalg.norm(chord))
        if length <= 1e-10:
            break
        try:
            pt = eng.point(0.5 * (lo + hi), chord / length, a.y, samples=False, relaxed=True, t_orient=a.tangent)
        except _NoConvergence:
            break
        if pt.events == ev_a:
            lo = pt.y
        else:
            hi, best = pt.y, pt
    return best


def _check_progress(progress: Any) -> None:
    """``ParameterError`` naming ``progress`` unless it is ``None`` or callable."""
    if progress is not None and not callable(progress):
        raise ParameterError(f"The option 'progress' must be a callable taking the fraction done, or None; "
                             f"got {progress!r}", parameter="progress")


class _Progress:
    """The fraction of a branch done, reported to ``progress(fraction)`` (``None``: nothing reported).

    The fraction is the running maximum of ``points / max_points`` and of the parameter's distance from
    ``p_start`` towards ``p_far`` over ``|p_far - p_start|`` (a branch can turn at a fold), clipped to
    ``[0, 1]``: it never decreases.  Whatever ``progress`` raises propagates (the explorer's Cancel).
    """

    def __init__(self, progress: Callable[[float], None] | None, max_points: int, p_start: float = 0.0,
                 p_far: float = 0.0) -> None:  # fmt: skip
        self.progress = progress
        self.max_points = max(int(max_points), 1)
        self.p_start = float(p_start)
        self.reach = float(p_far) - float(p_start)
        self.last = 0.0

    def report(self, fraction: float) -> None:
        """Report ``max(fraction, the last fraction)`` clipped to ``[0, 1]``."""
        if math.isfinite(fraction):
            self.last = max(self.last, min(1.0, max(0.0, float(fraction))))
        if self.progress is not None:
            self.progress(self.last)

    def point(self, n_points: int, p: float) -> None:
        """Report after an accepted branch point (``n_points`` so far, the last at parameter ``p``)."""
        f = n_points / self.max_points
        if self.reach != 0 and math.isfinite(p):
            f = max(f, (float(p) - self.p_start) / self.reach)
        self.report(f)

    def again(self) -> None:
        """Report the last fraction again (a long step after the continuation: a cancel is seen there)."""
        self.report(self.last)

    def done(self) -> None:
        """Report 1.0."""
        self.report(1.0)


def _hopf_y(hopf: HopfResult, r: float, m: int) -> np.ndarray:
    dp = hopf.side * r * r * abs(hopf.c1.real / hopf.dRe_lambda_dp)
    g = hopf.cycle_guess(hopf.p0 + dp, n_segments=m)
    return np.concatenate([g.x.ravel(), [g.period, g.p]])


def _hopf_row(hopf: HopfResult, m: int, n_floquet: int) -> tuple[np.ndarray, np.ndarray]:
    """``(y, floquet)`` of the Hopf point as the zero-amplitude end of the branch."""
    T0 = hopf.period0
    lam = hopf.eigenvalues
    k1 = int(np.argmin(np.abs(lam - hopf.eigenvalue)))
    k2 = int(np.argmin(np.abs(lam - np.conj(hopf.eigenvalue))))
    rest = np.delete(lam, sorted({k1, k2}))
    fl = np.concatenate([[1.0 + 0j], np.exp(rest * T0)])
    fl = fl[np.argsort(-np.abs(fl), kind="stable")][:n_floquet]
    y = np.concatenate([np.tile(hopf.x0, m), [T0, hopf.p0]])
    return y, fl


def continue_cycles(system: Any, start: HopfResult | PeriodicOrbit, p_range: Sequence[float], *, max_points: int = 200,
                    ds: float | None = None, ds_min: float = 1e-7, ds_max: float = 0.05, n_segments: int = 1,
                    flow: Any = None, tol: float = 1e-10, n_samples: int = 64, max_newton: int = 7,
                    max_angle: float = 0.3, start_amplitude: float = 0.02, direction: int = 1,
                    max_period: float | None = None, detect: Iterable[str] = ("LPC", "PD", "NS", "BPC", "GR"),
                    p_scale: float | None = None, ds_event: float | None = None,
                    progress: Callable[[float], None] | None = None,
                    ) -> CycleBranch:  # fmt: skip
    r"""Continue a branch of periodic orbits from a Hopf point (or an orbit) in the parameter ``p``.

    Parameters
    ----------
    system : SmoothSystem or PiecewiseSystem
        The system (ignored when ``flow`` is given).
    start : HopfResult or PeriodicOrbit
        A Hopf point from :func:`~.hopf.first_lyapunov` (branch switching with
        the normal-form prediction), or a periodic orbit from
        :func:`~.periodic.find_periodic_orbit`.
    p_range : (float, float)
        ``(p_min, p_max)``; the continuation stops at either end (an ``EP``
        point is located exactly on it).  Must contain the start.
    max_points : int
        Maximum number of points (special points included).
    ds : float, optional
        Initial step in scaled arclength (default ``min(0.02, ds_max)``).
    ds_min, ds_max : float
        Step limits in scaled arclength.
    n_segments : int
        Number of shooting segments.
    flow : Flow, optional
        Integrator with sensitivities (default :class:`~.flow.ScipyFlow` with
        ``rtol = 1e-11``).
    tol : float
        Newton tolerance on the scaled update.
    n_samples : int
        Samples per period for amplitudes, extremes and the stored orbits.
    max_newton : int
        Newton iterations allowed per step before the step is halved.
    max_angle : float
        Largest angle [rad] between consecutive tangents.
    start_amplitude : float
        First orbit from a Hopf point: its amplitude as a fraction of the
        amplitude scale (parameter offset ``start_amplitude**2`` of the range
        on the cycle side).
    direction : int
        ``+1`` or ``-1``: initial direction in ``p`` when starting from an orbit.
    max_period : float, optional
        Stop when the period exceeds this (default 50 times the initial period).
    detect : iterable of str
        Special points to detect, a subset of ``("LPC", "PD", "NS", "BPC", "GR")``.
    p_scale : float, optional
        The parameter distance that sets the scales (default: the width of
        ``p_range``): ``p`` is scaled by it in the arclength and, from a Hopf
        point, the amplitude scale is the predicted amplitude at that distance
        from ``p0`` (at most the end of the range).  Passing the distance of
        an expected event (e.g. the predicted contact loss) makes the steps
        independent of the requested range.
    ds_event : float, optional
        Largest step across an event (a sign change of a test function or a change of the switching
        events): a longer step that crosses one is halved and redone (default ``ds_max / 10``).
    progress : callable, optional
        ``progress(fraction)`` is called after each accepted branch point (special points included) with
        the fraction done in ``[0, 1]``, never decreasing: the running maximum of ``points / max_points``
        and of the distance covered in the parameter from the start towards the far end of ``p_range``
        (the end the cycles grow towards from a Hopf point, the end of ``direction`` from an orbit); and
        with 1.0 at the end.  An exception it raises stops the continuation and propagates (the
        explorer's Cancel).

    Returns
    -------
    CycleBranch
        Points, special points, status, ``plot()`` and the dataset.

    Raises
    ------
    ParameterError
        Bad range, options (``progress`` not callable), or a degenerate Hopf point (no prediction).
    ShootingError
        The first orbit cannot be computed.
    """
    _check_progress(progress)
    flow = _make_flow(system, flow)
    system = _system_of(flow)
    n = system.n
    try:
        lo, hi = (float(v) for v in p_range)
    except (TypeError, ValueError):
        raise ParameterError(f"The option 'p_range' must be two numbers (p_min, p_max); got {p_range!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ParameterError(f"The option 'p_range' must satisfy p_min < p_max (finite); got {p_range!r}")
    if not (isinstance(max_points, (int, np.integer)) and max_points >= 2):
        raise ParameterError(f"The option 'max_points' must be an integer >= 2; got {max_points!r}")
    if not (isinstance(n_segments, (int, np.integer)) and n_segments >= 1):
        raise ParameterError(f"The option 'n_segments' must be a positive integer; got {n_segments!r}")
    if not (0 < ds_min <= ds_max):
        raise ParameterError(f"The options must satisfy 0 < ds_min <= ds_max; got ds_min={ds_min!r}, ds_max={ds_max!r}")
    if not (0 < tol < 1e-3):
        raise ParameterError(f"The option 'tol' must be in (0, 1e-3); got {tol!r}")
    if not (0 < start_amplitude < 1):
        raise ParameterError(f"The option 'start_amplitude' must be in (0, 1); got {start_amplitude!r}")
    if not (isinstance(n_samples, (int, np.integer)) and n_samples >= 8):
        raise ParameterError(f"The option 'n_samples' must be an integer >= 8; got {n_samples!r}")
    detect = set(detect)
    bad = detect - {"LPC", "PD", "NS", "BPC", "GR"}
    if bad:
        raise ParameterError(f"The option 'detect' allows LPC, PD, NS, BPC, GR; got {sorted(bad)}")
    ds = min(0.02, ds_max) if ds is None else float(ds)
    if not (ds_min <= ds <= ds_max):
        raise ParameterError(f"The option 'ds' must be in [ds_min, ds_max] = [{ds_min}, {ds_max}]; got {ds!r}")
    ds_event = ds_max / 10 if ds_event is None else float(ds_event)
    if not (ds_event > 0):
        raise ParameterError(f"The option 'ds_event' must be positive; got {ds_event!r}")
    m = int(n_segments)
    width = hi - lo
    if p_scale is not None:
        if not (isinstance(p_scale, (int, float, np.floating)) and math.isfinite(p_scale) and p_scale > 0):
            raise ParameterError(f"The option 'p_scale' must be a positive finite number; got {p_scale!r}")
        width = float(p_scale)
    hopf = start if isinstance(start, HopfResult) else None
    points: list[_Point] = []

    def add(pt: _Point) -> None:
        """Append a branch point and report the progress (``tracker``: set below, once the start is known)."""
        points.append(pt)
        tracker.point(len(points), pt.y[-1])

    special: list[tuple[str, int, str]] = []  # (kind, point index, description)
    if hopf is not None:
        if hopf.side == 0:
            raise ParameterError(f"cannot continue cycles from a {hopf.criticality} or non-transversal Hopf point "
                                 f"(l1 = {hopf.l1:.3g} +- {hopf.l1_error:.2g}, "
                                 f"dRe_lambda_dp = {hopf.dRe_lambda_dp:.3g})")  # fmt: skip
        if not (lo <= hopf.p0 <= hi):
            raise ParameterError(f"The option 'p_range' must contain the Hopf point "
                                 f"{hopf.parameter_name} = {hopf.p0:.12g}; "
                                 f"got {p_range!r}")  # fmt: skip
        reach = (hi - hopf.p0) if hopf.side > 0 else (hopf.p0 - lo)
        if reach <= 0:
            raise ParameterError(f"the cycles exist for {hopf.parameter_name} {'>' if hopf.side > 0 else '<'} "
                                 f"{hopf.p0:.12g}, outside p_range = {p_range!r}")  # fmt: skip
        tracker = _Progress(progress, max_points, hopf.p0, hi if hopf.side > 0 else lo)
        if p_scale is not None:
            reach = min(reach, float(p_scale))
        acoef = hopf.amplitude_coefficients
        xs = acoef * math.sqrt(reach)
        xs = np.maximum(xs, 1e-4 * float(np.max(xs)))
        T0 = hopf.period0
        sv = np.concatenate([np.tile(xs, m), [T0, width]])
        eng = _Engine(flow, m, n, sv, xs, tol, n_samples, max_newton)
        # first orbit at amplitude start_amplitude * xs, along the predicted branch; where the normal form's
        # prediction is out of its range at that amplitude (a weakly nonlinear Hopf point: a tiny l1 makes the
        # predicted amplitude grow fast), Newton's method does not converge from it, and the first orbit is tried
        # again closer to the Hopf point (the amplitude quartered, up to FIRST_ORBIT_TRIES times)
        r1 = start_amplitude * math.sqrt(reach * abs(hopf.dRe_lambda_dp / hopf.c1.real))
        got: _Point | None = None
        for attempt in range(FIRST_ORBIT_TRIES):
            y1 = _hopf_y(hopf, r1, m)
            dr = 1e-4 * r1
            with np.errstate(all="ignore"):
                tp = (_hopf_y(hopf, r1 + dr, m) - _hopf_y(hopf, r1 - dr, m)) / eng.sv
                tp /= np.linalg.norm(tp)
            try:
                if not np.all(np.isfinite(tp)):
                    raise _NoConvergence("no finite tangent along the predicted branch")
                got = eng.point(y1, tp, y1.copy())
                break
            except _NoConvergence as exc:
                if attempt + 1 == FIRST_ORBIT_TRIES:
                    from .periodic import ShootingError

                    raise ShootingError(f"the first cycle near the Hopf point did not converge: {exc} (tried "
                                        f"{FIRST_ORBIT_TRIES} amplitudes down to {r1:.3g})") from None
                r1 /= 4.0
        assert got is not None
        first = got
        yH, flH = _hopf_row(hopf, m, n - 1)
        hopf_orbit = PeriodicOrbit(
            x=np.tile(hopf.x0, (m, 1)), period=T0, p=hopf.p0, multipliers=np.concatenate([[1.0 + 0j], flH]),
            floquet=flH, monodromy=np.eye(n), stable=first.orbit.stable, n_unstable=first.orbit.n_unstable,
            trivial_multiplier_error=0.0, t=first.orbit.t * (T0 / first.orbit.period),
            samples=np.tile(hopf.x0, (first.orbit.samples.shape[0], 1)), amplitude=np.zeros(n), mean=hopf.x0.copy(),
            x_max=hopf.x0.copy(), x_min=hopf.x0.copy(), state_names=tuple(system.state_names),
            parameter_name=system.parameter_name, multiplier_accuracy=first.orbit.multiplier_accuracy,
            verdict="undecided",  # the critical pair on the unit circle: no side to report
        )  # fmt: skip
        add(_Point(y=yH, tangent=first.tangent, orbit=hopf_orbit, iterations=0, label="H",
                   events=first.events))  # fmt: skip
        special.append(("H", 0, f"Hopf point, l1 = {hopf.l1:.6g} ({hopf.criticality})"))
        add(first)
        base_amp = float(np.max(first.orbit.amplitude / xs))
    else:
        if not isinstance(start, PeriodicOrbit):
            raise ParameterError(f"'start' must be a HopfResult or PeriodicOrbit; got {type(start).__name__}")
        if direction not in (-1, 1):
            raise ParameterError(f"The option 'direction' must be +1 or -1; got {direction!r}")
        if not (lo <= start.p <= hi):
            raise ParameterError(
                f"The option 'p_range' must contain the start orbit's p = {start.p:.12g}; got {p_range!r}"
            )
        tracker = _Progress(progress, max_points, start.p, hi if direction > 0 else lo)
        X0 = np.array(start.x, dtype=float, ndmin=2)
        if X0.shape[0] != m:
            fr = flow(X0[0], start.period, start.p, sensitivities=False, n_samples=m)
            X0 = fr.x_samples.copy()
        xs = _scale_from(X0, start.samples if start.samples.size else None)
        T0 = start.period
        sv = np.concatenate([np.tile(xs, m), [T0, width]])
        eng = _Engine(flow, m, n, sv, xs, tol, n_samples, max_newton)
        y0 = np.concatenate([X0.ravel(), [T0, start.p]])
        t_guess = np.zeros(m * n + 2)
        t_guess[-1] = float(direction)
        try:
            first = eng.point(y0, t_guess, y0)  # fixes p (arclength along p) and gives the tangent
        except _NoConvergence as exc:
            from .periodic import ShootingError

            raise ShootingError(f"the start orbit did not converge: {exc}") from None
        add(eng.rephase(first))
        base_amp = float(np.max(first.orbit.amplitude / xs))
    max_period = 50 * T0 if max_period is None else float(max_period)
    status, message = "max_points", f"reached max_points = {max_points}"
    ds_cur = ds
    while len(points) < max_points:
        a = points[-1]
        yhat = a.y / eng.sv
        try:
            b = eng.point((yhat + ds_cur * a.tangent) * eng.sv, a.tangent, a.y)
            angle = math.acos(min(1.0, max(-1.0, float(a.tangent @ b.tangent))))
            if angle > max_angle:
                raise _NoConvergence(f"tangent turned by {angle:.3g} rad")
        except _NoConvergence as exc:
            ds_cur /= 2
            if ds_cur < ds_min:
                status, message = "step_underflow", f"step below ds_min = {ds_min:g} ({exc})"
                break
            continue
        # an event between a and b (a test function changes sign, the switching events change): cut the
        # step back until the bracket is short, so that the event is located from a nearby point whatever
        # the step that reached it
        lpc = "LPC" in detect and a.label != "H" and a.tests.get("LPC", 0) * b.tests["LPC"] < 0
        event = a.label != "H" and (lpc or ("GR" in detect and a.events != b.events) or any(
            k in detect and a.tests.get(k, 0) * b.tests[k] < 0 for k in ("PD", "NS", "BPC")))
        if event and ds_cur > ds_event and ds_cur / 2 >= ds_min:
            ds_cur /= 2
            continue
        # special points between a and b (test functions), sorted by arclength
        found: list[tuple[float, _Point, str, str]] = []
        if lpc:
            pt = _locate(eng, a, ds_cur, lambda q: q.tests["LPC"], b.tests["LPC"], a.tests["LPC"], 1e-12)
            if pt is not None:
                found.append((_s_of(eng, a, pt), pt, "LPC", _check_special("LPC", pt) or ""))
        for kind in ("PD", "NS", "BPC"):
            if kind not in detect or a.label == "H" or a.tests.get(kind, 0) * b.tests[kind] >= 0:
                continue
            if kind == "BPC" and lpc:
                continue
            gt = 1e-12 * max(abs(a.tests[kind]), abs(b.tests[kind]))
            pt = _locate(eng, a, ds_cur, lambda q, k=kind: q.tests[k], b.tests[kind], a.tests[kind], gt)
            if pt is None:
                continue
            desc = _check_special(kind, pt)
            if desc is not None:
                found.append((_s_of(eng, a, pt), pt, kind, desc))
        if "GR" in detect and a.label != "H" and a.events != b.events:
            pt = _bisect_events(eng, a, b, a.events)
            if pt is not None:
                found.append((_s_of(eng, a, pt), pt, "GR",
                              f"switching events change from {list(a.events)} to {list(b.events)}"))  # fmt: skip
        # end of the range
        pb = b.y[-1]
        crossed = pb < lo or pb > hi
        if crossed:
            bound = lo if pb < lo else hi
            pt = _at_parameter(eng, a, b, bound)
            found = [f for f in found if f[0] < (_s_of(eng, a, pt) if pt is not None else ds_cur)]
            for s, pt_s, kind, desc in sorted(found, key=lambda f: f[0]):
                pt_s.label = kind
                _at_crossing(pt_s)
                add(eng.with_samples(pt_s))
                special.append((kind, len(points) - 1, desc))
            if pt is not None:
                pt.label = "EP"
                add(eng.with_samples(pt))
                special.append(("EP", len(points) - 1, f"end of p_range at {bound:.12g}"))
            status, message = "range", f"reached the end of p_range at {bound:.12g}"
            break
        for s, pt_s, kind, desc in sorted(found, key=lambda f: f[0]):
            pt_s.label = kind
            _at_crossing(pt_s)
            add(eng.with_samples(pt_s))
            special.append((kind, len(points) - 1, desc))
        b = eng.rephase(b)
        add(b)
        # stopping tests
        amp = float(np.max(b.orbit.amplitude / xs))
        if b.orbit.period > max_period:
            status, message = "period", f"period {b.orbit.period:.6g} s exceeds max_period = {max_period:.6g} s"
            break
        ds_next = min(ds_max, ds_cur * 1.5) if b.iterations <= 3 else (ds_cur * 0.7 if b.iterations >= 5 else ds_cur)
        ds_next = max(ds_next, ds_min)
        # the amplitude heads to zero (another Hopf point): stop when the next step would reach it
        amp_a = float(np.max(a.orbit.amplitude / xs)) if a.label != "H" else 0.0
        slope = (amp - amp_a) / max(_s_of(eng, a, b), 1e-300)
        if a.label != "H" and slope < 0 and (amp + ds_next * slope <= 0 or amp < 0.5 * base_amp):
            # near a Hopf point the squared amplitude is linear in p
            p_end = b.y[-1] + (b.y[-1] - a.y[-1]) * amp**2 / max(amp_a**2 - amp**2, 1e-300)
            status, message = "equilibrium", (f"the amplitude returns to zero near {system.parameter_name} = "
                                              f"{p_end:.6g} (another Hopf point)")  # fmt: skip
            break
        ds_cur = ds_next
    tracker.done()
    return _build(eng, points, special, status, message, hopf, system)


def _at_crossing(pt: _Point) -> None:
    """A located fold, period doubling, Neimark-Sacker or branch point is where a multiplier crosses the unit
    circle: its verdict is ``"undecided"`` whatever side the located multiplier is computed on."""
    from dataclasses import replace

    if pt.label in ("LPC", "PD", "NS", "BPC"):
        pt.orbit = replace(pt.orbit, verdict="undecided")


def _s_of(eng: _Engine, a: _Point, b: _Point) -> float:
    return float(a.tangent @ ((b.y - a.y) / eng.sv))


def _build(eng: _Engine, points: list[_Point], special_rows: list[tuple[str, int, str]], status: str, message: str,
           hopf: HopfResult | None, system: Any) -> CycleBranch:  # fmt: skip
    import xarray as xr

    n = eng.n
    names = list(system.state_names)
    orbits = [pt.orbit for pt in points]
    P = len(points)
    ns = max(o.samples.shape[0] for o in orbits)
    fl = np.array([o.floquet[: n - 1] for o in orbits]).reshape(P, n - 1)
    orbit_arr = np.full((P, ns, n), np.nan)
    for i, o in enumerate(orbits):
        orbit_arr[i, : o.samples.shape[0]] = o.samples
    arcl = np.zeros(P)
    for i in range(1, P):
        arcl[i] = arcl[i - 1] + float(np.linalg.norm((points[i].y - points[i - 1].y) / eng.sv))
    p = np.array([o.p for o in orbits])
    T = np.array([o.period for o in orbits])
    pn = system.parameter_name
    ds = xr.Dataset(
        {
            "period": ("point", T, {"units": "s"}),
            "frequency": ("point", 1.0 / T, {"units": "Hz"}),
            "omega": ("point", 2 * np.pi / T, {"units": "rad/s"}),
            "amplitude": (
                ("point", "coord"),
                np.array([o.amplitude for o in orbits]),
                {"long_name": "first-harmonic amplitude"},
            ),
            "mean": (("point", "coord"), np.array([o.mean for o in orbits])),
            "x_max": (("point", "coord"), np.array([o.x_max for o in orbits])),
            "x_min": (("point", "coord"), np.array([o.x_min for o in orbits])),
            "x0": (("point", "coord"), np.array([o.x[0] for o in orbits])),
            "stable": ("point", np.array([o.stable for o in orbits], dtype=bool)),
            "n_unstable": ("point", np.array([o.n_unstable for o in orbits], dtype=int)),
            "floquet_re": (("point", "floquet"), fl.real),
            "floquet_im": (("point", "floquet"), fl.imag),
            "floquet_abs": (("point", "floquet"), np.abs(fl)),
            "trivial_multiplier_error": ("point", np.array([o.trivial_multiplier_error for o in orbits])),
            "multiplier_accuracy": ("point", np.array([o.multiplier_accuracy for o in orbits]),
                                    {"long_name": "distance from the unit circle a multiplier needs for a verdict"}),
            "multiplier_change": ("point", np.array([o.multiplier_change for o in orbits]),
                                  {"long_name": "change of the largest non-trivial |multiplier| at a 100 times "
                                                "smaller tolerance (close calls; NaN: not checked)"}),
            "largest_multiplier": ("point", np.array([float(np.max(np.abs(o.floquet))) if o.floquet.size else 0.0
                                                      for o in orbits]),
                                   {"long_name": "largest non-trivial |multiplier|"}),
            "verdict": ("point", np.array([o.verdict for o in orbits], dtype=object).astype(str),
                        {"long_name": "stable, unstable or undecided (a multiplier within multiplier_accuracy "
                                      "of the unit circle)"}),
            "label": ("point", np.array([pt.label for pt in points], dtype=object).astype(str)),
            "arclength": ("point", arcl),
            "newton_iterations": ("point", np.array([pt.iterations for pt in points], dtype=int)),
            "orbit": (("point", "phase", "coord"), orbit_arr),
            "special_kind": ("special", np.array([k for k, _, _ in special_rows], dtype=object).astype(str)),
            "special_index": ("special", np.array([i for _, i, _ in special_rows], dtype=int)),
            "special_p": ("special", np.array([p[i] for _, i, _ in special_rows])),
            "special_period": ("special", np.array([T[i] for _, i, _ in special_rows])),
            "special_amplitude": (
                ("special", "coord"),
                np.array([orbits[i].amplitude for _, i, _ in special_rows]).reshape(-1, n),
            ),
            "special_description": ("special", np.array([d for _, _, d in special_rows], dtype=object).astype(str)),
        },  # fmt: skip
        coords={
            "point": np.arange(P),
            "coord": names,
            "p": ("point", p),
            "phase": np.arange(ns) / ns,
            "floquet": np.arange(n - 1),
            "special": np.arange(len(special_rows)),
        },  # fmt: skip
    )
    if pn != "p":
        ds[pn] = ("point", p)
    attrs: dict[str, Any] = {
        "parameter": pn,
        "status": status,
        "message": message,
        "n_segments": eng.m,
        "monodromy_method": orbits[-1].monodromy_method if orbits else "",
        "integrator": f"{type(eng.flow).__name__} {getattr(eng.flow, 'method', '')} "
        f"rtol={getattr(eng.flow, 'rtol', '')}",
        "newton_tol": eng.tol,
        "stable_definition": "all non-trivial Floquet multipliers strictly inside the unit circle",
        "verdict_definition": "stable: every non-trivial |mu| < 1 - multiplier_accuracy; unstable: some |mu| > 1 + "
                              "multiplier_accuracy; else undecided; multiplier_accuracy = max(10 "
                              "trivial_multiplier_error, 10 segments rtol)",
        "hopf_point_row": "label H: zero amplitude, multipliers exp(lambda_i T0) with the critical pair as 1; "
                          "'stable' copied from the emerging cycles",
    }  # fmt: skip
    if hopf is not None:
        attrs.update({"hopf_p0": hopf.p0, "hopf_omega0": hopf.omega0, "hopf_l1": hopf.l1,
                      "hopf_l1_error": hopf.l1_error, "hopf_criticality": hopf.criticality})  # fmt: skip
        lpcs = [i for k, i, _ in special_rows if k == "LPC"]
        if hopf.criticality == "subcritical" and lpcs:
            i = lpcs[0]
            after = [j for j in range(i + 1, P) if points[j].label == ""]
            if after and orbits[after[0]].stable:
                attrs["hysteresis_range"] = [float(min(p[i], hopf.p0)), float(max(p[i], hopf.p0))]
    ds.attrs.update(attrs)
    sp = [SpecialPoint(kind=k, index=i, p=float(p[i]), period=float(T[i]), amplitude=orbits[i].amplitude.copy(),
                       floquet=orbits[i].floquet.copy(), description=d) for k, i, d in special_rows]  # fmt: skip
    return CycleBranch(data=ds, special=sp, status=status, message=message, hopf=hopf, orbits=orbits)
