r"""Hopf curves in two parameters: continuation, ``l1`` along the curve, codimension-2 points.

A Hopf curve is the set of points ``(x, y)`` of two settable parameters where a
complex pair ``lambda = alpha + i omega`` of the exact linearization of the
silent motion (:func:`brakesqueal.analysis.linear.linearize`, every mode, the
pads' own rates included) crosses the imaginary axis.  It is continued by
pseudo-arclength on the axes scaled to the unit square (``log10`` for a log
axis): Newton on the minimally augmented system

.. math::

   g(u) = \operatorname{Re}\lambda_c(u) / s = 0,\qquad t_k \cdot (u - u_k^{\mathrm{pred}}) = 0,

with ``lambda_c`` the tracked critical eigenvalue (continuity of the
eigenvalue from the predictor, ``omega = Im lambda_c`` along the curve), ``s``
the modulus of ``lambda_c`` at the start, and ``grad g`` by central
differences of the exact eigenvalues (a chord iteration on the previous
point's ``grad g``, refreshed where a step does not contract).  Every point is
on the linear stability boundary to the rounding of the eigenvalues
(``|g| <= 1e-12``).

At each point the first Lyapunov coefficient is the project's
(:func:`brakesqueal.nonlinear.implicit.exact_lyapunov`: the pads' true
tangential rates, MatCont's normalisation), with the parameter whose partial
derivative of ``Re lambda`` is larger as its path.  The point is already on
the boundary and ``d lambda / dp`` is the curve's own difference, so the
normal form is computed there directly
(:func:`~brakesqueal.nonlinear.implicit.lyapunov_at_hopf`: no re-refinement,
double-precision eigenvalues where their error bounds decide the checks).

Between consecutive points the test functions of the codimension-2 points are
watched and a sign change is located by bisection on the chord (each trial
point corrected onto the curve):

* generalised Hopf (``GH``): ``l1`` changes sign (secant/Illinois on ``l1``);
* zero-Hopf (``ZH``): a real eigenvalue crosses 0;
* double Hopf (``HH``): another complex pair crosses the imaginary axis;
* Bogdanov–Takens (``BT``): ``omega -> 0`` (the pair meets on the real axis): the curve ends there.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import BrakesquealError, ParameterError
from ..validation import validated

if TYPE_CHECKING:
    from ..analysis.maps import Axis
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace

__all__ = ["CurvePoint", "SpecialPoint", "HopfCurve", "continue_hopf_curve", "correct_point",
           "SPECIAL_TYPES"]

#: Types of codimension-2 points and what they mean.
SPECIAL_TYPES: dict[str, str] = {
    "GH": "generalised Hopf (Bautin): l1 = 0, a fold-of-cycles curve is born",
    "BT": "Bogdanov-Takens: omega -> 0, the Hopf curve ends on a curve of static divergence",
    "ZH": "zero-Hopf (fold-Hopf): a real eigenvalue crosses 0 on the Hopf curve",
    "HH": "double Hopf: a second complex pair crosses the imaginary axis on the Hopf curve",
}

_NEWTON_TOL = 1e-12
_FD = 1e-6


@dataclass(frozen=True)
class CurvePoint:
    """A point of a Hopf curve.

    Attributes
    ----------
    x, y : float
        The two parameters (SI units of the axes).
    omega : float
        Angular frequency ``Im lambda_c`` at onset [rad/s].
    l1 : float or None
        First Lyapunov coefficient (pads' true rates); ``None`` where not computed (see ``message``).
    l1_error : float or None
        Its error estimate.
    criticality : str
        ``"supercritical"``, ``"subcritical"``, ``"degenerate"`` or ``"unknown"``.
    residual : float
        ``|Re lambda_c| / |lambda_c|`` at the point.
    message : str
        Why ``l1`` is missing, or warnings of the normal form.
    """

    x: float
    y: float
    omega: float
    l1: float | None
    l1_error: float | None
    criticality: str
    residual: float
    message: str = ""

    @property
    def omega_hz(self) -> float:
        """Frequency at onset [Hz]."""
        return self.omega / (2 * math.pi)


@dataclass(frozen=True)
class SpecialPoint:
    """A codimension-2 point on a Hopf curve.

    Attributes
    ----------
    type : str
        A key of :data:`SPECIAL_TYPES`.
    x, y : float
        Where (axes' SI units).
    omega : float
        Frequency of the Hopf pair there [rad/s].
    detail : str
        How it was located (and, for ``ZH``/``HH``, the other eigenvalue).
    """

    type: str
    x: float
    y: float
    omega: float
    detail: str = ""


@dataclass(frozen=True)
class HopfCurve:
    """A continued Hopf curve.

    Attributes
    ----------
    x_name, y_name : str
        The parameters.
    points : tuple of CurvePoint
        In arclength order.
    special_points : tuple of SpecialPoint
        Codimension-2 points located on it.
    ends : tuple of str
        Why the curve ends at its first and last point (``"edge of the box"``, ``"closed loop"``,
        ``"Bogdanov-Takens"``, ``"max_points"``, ``"leaves the allowed parameter range"``, ``"step too small"``).
    """

    x_name: str
    y_name: str
    points: tuple[CurvePoint, ...]
    special_points: tuple[SpecialPoint, ...] = ()
    ends: tuple[str, str] = ("", "")

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """The points' ``(x, y)`` as arrays."""
        return (np.array([p.x for p in self.points]), np.array([p.y for p in self.points]))


class _Field:
    """Eigenvalues of the exact linearization on the unit square of two axes."""

    def __init__(self, engine: Engine, space: ParameterSpace, x: Axis, y: Axis) -> None:
        self.engine, self.space, self.axes = engine, space, (x, y)
        self.cache: dict[tuple[float, float], np.ndarray | None] = {}

    def values(self, u: np.ndarray) -> tuple[float, float]:
        out = []
        for ui, ax in zip(u, self.axes):
            if ax.log:
                a, b = math.log10(ax.start), math.log10(ax.stop)
                out.append(10.0 ** (a + float(ui) * (b - a)))
            else:
                out.append(ax.start + float(ui) * (ax.stop - ax.start))
        return out[0], out[1]

    def unit(self, xv: float, yv: float) -> np.ndarray:
        out = []
        for v, ax in zip((xv, yv), self.axes):
            if ax.log:
                a, b = math.log10(ax.start), math.log10(ax.stop)
                out.append((math.log10(v) - a) / (b - a))
            else:
                out.append((v - ax.start) / (ax.stop - ax.start))
        return np.array(out)

    def eig(self, u: np.ndarray) -> np.ndarray | None:
        key = (float(u[0]), float(u[1]))
        if key not in self.cache:
            if len(self.cache) > 4096:
                self.cache.clear()
            from ..analysis.linear import linearize

            xv, yv = self.values(u)
            try:
                if not (math.isfinite(xv) and math.isfinite(yv)):
                    raise ParameterError("not finite")
                params = self.space.resolve({self.axes[0].name: xv, self.axes[1].name: yv})
                lm = linearize(self.engine, params)
                try:  # E^-1 A where E is regular (as the Lyapunov routine), else the pencil's finite eigenvalues
                    lams = np.linalg.eigvals(lm.A).astype(complex)
                except np.linalg.LinAlgError:
                    lams = np.asarray(lm.eigenvalues, dtype=complex)
                self.cache[key] = lams if np.all(np.isfinite(lams)) else None
            except (BrakesquealError, ValueError, ZeroDivisionError, OverflowError, np.linalg.LinAlgError):
                self.cache[key] = None
        return self.cache[key]

    def track(self, u: np.ndarray, target: complex) -> complex | None:
        lams = self.eig(u)
        if lams is None:
            return None
        cand = lams[lams.imag > 0]
        if cand.size == 0:
            return None
        return complex(cand[np.argmin(np.abs(cand - target))])


def _g(fld: _Field, u: np.ndarray, target: complex, scale: float) -> tuple[float, complex] | None:
    lam = fld.track(u, target)
    if lam is None:
        return None
    return lam.real / scale, lam


def _grad(fld: _Field, u: np.ndarray, target: complex, scale: float) -> np.ndarray | None:
    grad = np.zeros(2)
    for i in range(2):
        e = np.zeros(2)
        e[i] = _FD
        gp, gm = _g(fld, u + e, target, scale), _g(fld, u - e, target, scale)
        if gp is None or gm is None:
            return None
        grad[i] = (gp[0] - gm[0]) / (2 * _FD)
    return grad


def _correct(fld: _Field, u0: np.ndarray, normal: np.ndarray | None, target: complex,
             scale: float, grad0: np.ndarray | None = None) -> tuple[np.ndarray, complex] | None:
    """Newton on ``g(u) = 0`` and ``normal . (u - u0) = 0`` (``normal=None``: least-change step).

    With ``grad0`` (``grad g`` at a curve point a step away, e.g. the one the predictor left) the iteration is
    a chord method on it, one eigenvalue evaluation an iteration instead of five; ``grad g`` is evaluated
    afresh (Newton) wherever a step does not shrink to half the previous one.  Both stop at the same
    tolerance on the step.
    """
    u = np.array(u0, dtype=float)
    lam = target
    grad = None if grad0 is None else np.asarray(grad0, dtype=float)
    prev = math.inf
    for _ in range(16 if grad0 is None else 24):
        gv = _g(fld, u, lam, scale)
        if gv is None:
            return None
        g, lam = gv
        if grad is None:
            grad = _grad(fld, u, lam, scale)
        if grad is None or not np.all(np.isfinite(grad)) or not np.any(grad):
            return None
        if normal is None:
            du = -g * grad / float(grad @ grad)
        else:
            J = np.vstack([grad, normal])
            rhs = -np.array([g, float(normal @ (u - u0))])
            try:
                du = np.linalg.solve(J, rhs)
            except np.linalg.LinAlgError:
                return None
        u = u + du
        size = float(np.max(np.abs(du)))
        if size <= _NEWTON_TOL:
            gv = _g(fld, u, lam, scale)
            if gv is None:
                return None
            return u, gv[1]
        if grad0 is None or size > 0.5 * prev:  # Newton, or a chord step that did not contract: a fresh gradient
            grad = None
        prev = size
    return None


@validated
def correct_point(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, x_value: float, y_value: float,
                  omega: float | None = None, *, hold: str = "x") -> tuple[float, float, float]:
    """A Hopf point near ``(x_value, y_value)``: Newton on ``Re lambda_c = 0`` with ``x`` held fixed, or
    (``hold="nearest"``) by least-change steps in the box scaled to the unit square (the nearest curve point).

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The model, preset and overrides.
    x, y : Axis
        The axes (their ranges scale the unknowns).
    x_value, y_value : float
        The fixed ``x`` and the start for ``y``.
    omega : float, optional
        Select the pair with imaginary part closest to ``omega``.
    hold : {"x", "nearest"}
        What stays fixed.

    Returns
    -------
    (float, float, float)
        ``(x, y, omega)`` of the Hopf point.

    Raises
    ------
    BrakesquealError
        No complex pair there, or Newton does not converge.
    """
    if hold not in ("x", "nearest"):
        raise ParameterError(f"The option 'hold' must be x or nearest; got {hold!r}", parameter="hold")
    fld = _Field(engine, space, x, y)
    u0, lam = _critical_pair(fld, x_value, y_value, omega)
    res = _correct(fld, u0, np.array([1.0, 0.0]) if hold == "x" else None, lam, abs(lam))
    if res is None:
        raise BrakesquealError(f"no Hopf point near {y.name} = {y_value:.12g} at {x.name} = {x_value:.12g}")
    xv, yv = fld.values(res[0])
    return xv, yv, res[1].imag


def _critical_pair(fld: _Field, x_value: float, y_value: float, omega: float | None) -> tuple[np.ndarray, complex]:
    """The start in unit coordinates and the critical eigenvalue there: of the pairs ``Im λ > 0``, the one
    nearest the imaginary axis (or nearest ``omega`` [rad/s] where given)."""
    xa, ya = fld.axes
    u0 = fld.unit(x_value, y_value)
    lams = fld.eig(u0)
    if lams is None:
        raise BrakesquealError(f"no linearization at {xa.name} = {x_value:.12g}, {ya.name} = {y_value:.12g}")
    cand = lams[lams.imag > 0]
    if cand.size == 0:
        raise BrakesquealError(f"no complex eigenvalue pair at {xa.name} = {x_value:.12g}, {ya.name} = "
                               f"{y_value:.12g}: not a Hopf point")
    return u0, complex(cand[np.argmin(np.abs(cand.real) if omega is None else np.abs(cand.imag - omega))])


@dataclass
class _Raw:
    u: np.ndarray
    lam: complex
    tangent: np.ndarray
    grad: np.ndarray | None = None  # grad g at u (the chord corrector's matrix for the next point)


def _counts(lams: np.ndarray, lam: complex, scale: float) -> tuple[int, int]:
    """(real eigenvalues with Re > 0, other complex pairs with Re > 0), the tracked pair left out."""
    tol = 1e-9 * scale
    real = lams[np.abs(lams.imag) <= tol]
    others = lams[(lams.imag > tol) & (np.abs(lams - lam) > 1e-9 * scale)]
    return int(np.sum(real.real > 0)), int(np.sum(others.real > 0))


def _branch(fld: _Field, start: _Raw, direction: float, scale: float, ds0: float, ds_max: float,
            max_points: int, start_u: np.ndarray) -> tuple[list[_Raw], str]:
    """One direction of the curve from ``start``."""
    pts: list[_Raw] = []
    cur = start
    t = start.tangent * direction
    ds = ds0
    travelled = 0.0
    while len(pts) < max_points:
        if ds < 1e-7:
            return pts, "Bogdanov-Takens" if _bt_ahead(start, pts, scale) is not None else "step too small"
        pred = cur.u + ds * t
        lam_pred = cur.lam
        res = _correct(fld, pred, t, lam_pred, scale, cur.grad)
        if res is not None:
            u, lam = res
            ok = (abs(lam - cur.lam) <= 0.2 * abs(cur.lam) and float(np.linalg.norm(u - cur.u)) <= 2 * ds)
        else:
            ok = False
        if not ok:
            if ds < 1e-6:
                if cur.lam.imag < 0.05 * scale or _bt_ahead(start, pts, scale) is not None:
                    return pts, "Bogdanov-Takens"  # the pair meets on the real axis ahead
                if fld.eig(cur.u + 2 * ds * t) is None:
                    return pts, "leaves the allowed parameter range"
            ds *= 0.5
            continue
        assert res is not None
        grad = _grad(fld, u, lam, scale)
        if grad is None:
            ds *= 0.5
            continue
        tn = np.array([-grad[1], grad[0]])
        tn /= np.linalg.norm(tn)
        if float(tn @ t) < 0:
            tn = -tn
        new = _Raw(u, lam, tn, grad)
        inside = bool(np.all(u >= -1e-12) and np.all(u <= 1 + 1e-12))
        if not inside:
            edge = _to_edge(fld, cur, new, scale)
            if edge is not None:
                pts.append(edge)
            return pts, "edge of the box"
        pts.append(new)
        travelled += float(np.linalg.norm(u - cur.u))
        if travelled > 3 * ds_max and float(np.linalg.norm(u - start_u)) < 0.5 * ds:
            return pts, "closed loop"
        cur, t = new, tn
        ds = min(ds * 1.5, ds_max)
    return pts, "max_points"


def _bt_ahead(start: _Raw, pts: list[_Raw], scale: float) -> tuple[np.ndarray, complex] | None:
    """The Bogdanov-Takens point ahead of a branch that stalls as ``omega -> 0``, or ``None``.

    Near BT, ``omega**2`` is a regular function of the arclength that vanishes there (``omega**2 = -b2`` on
    the normal form), while ``omega`` itself falls like a square root and the eigenvalue problem may stop
    being defined just beside the curve (the equilibrium is born on a fold curve tangent to the Hopf curve
    at BT), so the stepping stalls short of it.  The branch's points with ``omega**2`` up to four times the
    last one's are fitted by quadratics in arclength (``omega**2`` and each coordinate); BT is where the fitted
    ``omega**2`` reaches 0.  Accepted only where ``omega`` has fallen below 0.2 of its scale, ``omega**2``
    falls monotonically over at least three fitted points spanning at least half its last value, and the
    zero lies within twice the fitted span (the extrapolation error is then of the order of the fit's
    third-order term).
    """
    chain = [start, *pts]
    w_last = chain[-1].lam.imag
    if w_last <= 0 or w_last > 0.2 * scale:
        return None
    k = len(chain) - 1
    while k > 0 and chain[k - 1].lam.imag ** 2 <= 4 * w_last ** 2:
        k -= 1
    fit = chain[k:]
    w2 = np.array([r.lam.imag ** 2 for r in fit])
    if len(fit) < 3 or not np.all(np.diff(w2) < 0) or w2[0] < 1.5 * w2[-1]:
        return None
    us = np.array([r.u for r in fit])
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(us, axis=0), axis=1))])
    c = np.polyfit(s, w2, 2)
    if float(np.polyval(np.polyder(c), s[-1])) >= 0:
        return None
    roots = [float(r.real) for r in np.roots(c) if abs(r.imag) <= 1e-12 * max(1.0, abs(r)) and r.real > s[-1]]
    if not roots or min(roots) - s[-1] > 2 * s[-1]:
        return None
    s_bt = min(roots)
    u_bt = np.array([np.polyval(np.polyfit(s, us[:, i], 2), s_bt) for i in range(2)])
    return u_bt, complex(0.0, 0.0)


def _to_edge(fld: _Field, a: _Raw, b: _Raw, scale: float) -> _Raw | None:
    """The curve's point on the edge of the unit square between ``a`` (inside) and ``b`` (outside)."""
    best: tuple[float, int, float] | None = None
    for i in range(2):
        for bound in (0.0, 1.0):
            d = b.u[i] - a.u[i]
            if d == 0:
                continue
            s = (bound - a.u[i]) / d
            if 0 <= s <= 1 and (best is None or s < best[0]):
                best = (s, i, bound)
    if best is None:
        return None
    s, i, bound = best
    u0 = a.u + s * (b.u - a.u)
    u0[i] = bound
    normal = np.zeros(2)
    normal[i] = 1.0
    res = _correct(fld, u0, normal, a.lam + s * (b.lam - a.lam), scale, a.grad)
    if res is None:
        return None
    u, lam = res
    u[i] = bound
    return _Raw(u, lam, a.tangent)


def _bisect_chord(fld: _Field, a: _Raw, b: _Raw, scale: float,
                  test: Callable[[np.ndarray, complex], float | None], iters: int = 48, tol: float = 1e-13
                  ) -> tuple[np.ndarray, complex] | None:
    """Locate a sign change of ``test`` between ``a`` and ``b``: bisection (Illinois when ``test`` is a
    continuous value) on the chord, every trial point corrected onto the curve normal to the chord."""
    chord = b.u - a.u
    n = chord / np.linalg.norm(chord)
    fa, fb = test(a.u, a.lam), test(b.u, b.lam)
    if fa is None or fb is None or fa * fb > 0:
        return None
    lo, hi, flo, fhi = 0.0, 1.0, fa, fb
    side = 0
    best: tuple[np.ndarray, complex] = (a.u, a.lam)
    for _ in range(iters):
        if flo != fhi and abs(flo) != 1.0 and abs(fhi) != 1.0:
            s = lo - flo * (hi - lo) / (fhi - flo)
            if not lo < s < hi:
                s = 0.5 * (lo + hi)
        else:
            s = 0.5 * (lo + hi)
        res = _correct(fld, a.u + s * chord, n, a.lam + s * (b.lam - a.lam), scale, a.grad)
        if res is None:
            return best
        u, lam = res
        best = (u, lam)
        fs = test(u, lam)
        if fs is None:
            return best
        if fs == 0:
            return best
        if fs * flo < 0:
            hi, fhi = s, fs
            if side == -1:
                flo *= 0.5
            side = -1
        else:
            lo, flo = s, fs
            if side == 1:
                fhi *= 0.5
            side = 1
        if hi - lo < tol:
            break
    return best


def _dlam(fld: _Field, u: np.ndarray, lam: complex, i: int) -> complex | None:
    """``d lambda / d(axis i)`` [SI] at a curve point: the central difference of :func:`_grad` (the same,
    cached eigenvalues) in unit coordinates, times ``du/dp`` of the axis."""
    e = np.zeros(2)
    e[i] = _FD
    lp, lm = fld.track(u + e, lam), fld.track(u - e, lam)
    if lp is None or lm is None:
        return None
    ax, v = fld.axes[i], fld.values(u)[i]
    if ax.log:
        du_dp = 1.0 / (v * math.log(10.0) * (math.log10(ax.stop) - math.log10(ax.start)))
    else:
        du_dp = 1.0 / (ax.stop - ax.start)
    return complex((lp - lm) / (2 * _FD) * du_dp)


def _l1(engine: Engine, space: ParameterSpace, fld: _Field, u: np.ndarray, lam: complex,
        scale: float, use_cache: bool) -> tuple[float | None, float | None, str, str]:
    """l1 with the pads' true rates at a corrected curve point, along the parameter whose partial derivative of
    ``Re lambda`` is larger: :func:`~brakesqueal.nonlinear.implicit.lyapunov_at_hopf` (the point, its
    eigenvalue and ``d lambda / dp`` from the curve; no refinement), the normal form of
    :func:`~brakesqueal.nonlinear.implicit.exact_lyapunov`."""
    from ..nonlinear.implicit import exact_lyapunov, lyapunov_at_hopf

    xv, yv = fld.values(u)
    xa, ya = fld.axes
    grad = _grad(fld, u, lam, scale)
    along_y = grad is None or abs(grad[1]) >= abs(grad[0])
    fixed, path, value = (xa.name, xv) if along_y else (ya.name, yv), ya.name if along_y else xa.name, \
        (yv if along_y else xv)
    dl = _dlam(fld, u, lam, 1 if along_y else 0)
    sub = space.with_values({fixed[0]: fixed[1]})
    try:
        if dl is None:  # no derivative from the curve (a neighbour outside the allowed range): the full route
            h = exact_lyapunov(engine, sub, path, value, omega=lam.imag, use_cache=use_cache).hopf
        else:
            h = lyapunov_at_hopf(engine, sub, path, value, lam, dl, use_cache=use_cache)
    except (BrakesquealError, np.linalg.LinAlgError, ValueError) as exc:
        return None, None, "unknown", f"no l1: {exc}"
    return float(h.l1), float(h.l1_error), h.criticality, "; ".join(h.warnings)


@validated
def continue_hopf_curve(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, x_value: float, y_value: float,
                        *, omega: float | None = None, ds: float = 0.02, ds_max: float = 0.05,
                        max_points: int = 200, lyapunov: bool = True, use_cache: bool = True) -> HopfCurve:
    """Continue the Hopf curve through a point of the stability boundary in both directions.

    Parameters
    ----------
    engine : Engine
        The model's engine (with nonlinear equations when ``lyapunov``).
    space : ParameterSpace
        The model, preset and overrides.
    x, y : Axis
        The two parameters and the box the curve is followed in (it stops on its edge).
    x_value, y_value : float
        A point on (or near) the Hopf curve (e.g. a crossing from
        :func:`~brakesqueal.analysis.crossings.crossings`).
    omega : float, optional
        Select the pair with imaginary part closest to ``omega``.
    ds, ds_max : float
        First and largest step in the unit square.
    max_points : int
        Largest number of points in each direction.
    lyapunov : bool
        Compute ``l1`` at every point and locate generalised-Hopf points.
    use_cache : bool
        Use the on-disk code cache.

    Returns
    -------
    HopfCurve

    Raises
    ------
    BrakesquealError
        The start is not near a Hopf point.
    """
    fld = _Field(engine, space, x, y)
    u0, lam0 = _critical_pair(fld, x_value, y_value, omega)
    scale = abs(lam0)
    res = _correct(fld, u0, None, lam0, scale)
    if res is None:
        raise BrakesquealError(f"no Hopf point near {x.name} = {x_value:.12g}, {y.name} = {y_value:.12g}")
    u, lam = res
    grad = _grad(fld, u, lam, scale)
    if grad is None:
        raise BrakesquealError("the Hopf curve's tangent is not defined at the start")
    t = np.array([-grad[1], grad[0]]) / float(np.linalg.norm(grad))
    start = _Raw(u, lam, t, grad)
    fwd, end_f = _branch(fld, start, 1.0, scale, ds, ds_max, max_points, u)
    if end_f == "closed loop":
        bwd: list[_Raw] = []
        end_b = "closed loop"
    else:
        bwd, end_b = _branch(fld, start, -1.0, scale, ds, ds_max, max_points, u)
    raw = [*reversed(bwd), start, *fwd]
    # l1 and criticality at every point
    vals = []
    for r in raw:
        l1, err, crit, msg = _l1(engine, space, fld, r.u, r.lam, scale, use_cache) if lyapunov \
            else (None, None, "unknown", "l1 not computed")
        vals.append((l1, err, crit, msg))
    specials: list[SpecialPoint] = []

    def special(kind: str, where: tuple[np.ndarray, complex] | None, detail: str) -> None:
        if where is None:
            return
        xv, yv = fld.values(where[0])
        specials.append(SpecialPoint(kind, xv, yv, where[1].imag, detail))

    for k in range(len(raw) - 1):
        a, b = raw[k], raw[k + 1]
        la, lb = vals[k][0], vals[k + 1][0]
        if lyapunov and la is not None and lb is not None and la * lb < 0:
            def l1_at(uu: np.ndarray, lam: complex) -> float | None:
                return _l1(engine, space, fld, uu, lam, scale, use_cache)[0]

            # l1 is known to ~1e-6 of its scale: a bracket of 1e-9 of a step is far below what that resolves
            special("GH", _bisect_chord(fld, a, b, scale, l1_at, iters=30, tol=1e-9), "l1 changes sign (secant on l1)")
        ea, eb = fld.eig(a.u), fld.eig(b.u)
        if ea is None or eb is None:
            continue
        (ra, oa), (rb, ob) = _counts(ea, a.lam, scale), _counts(eb, b.lam, scale)
        if ra != rb:
            def real_count(uu: np.ndarray, lam: complex, _r: int = ra) -> float | None:
                e = fld.eig(uu)
                return None if e is None else (1.0 if _counts(e, lam, scale)[0] == _r else -1.0)

            where = _bisect_chord(fld, a, b, scale, real_count)
            special("ZH", where, "a real eigenvalue crosses 0 (bisection on the number of unstable real "
                                 "eigenvalues)")
        if oa != ob:
            def pair_count(uu: np.ndarray, lam: complex, _o: int = oa) -> float | None:
                e = fld.eig(uu)
                return None if e is None else (1.0 if _counts(e, lam, scale)[1] == _o else -1.0)

            where = _bisect_chord(fld, a, b, scale, pair_count)
            detail = "a second complex pair crosses the imaginary axis"
            if where is not None:
                e = fld.eig(where[0])
                if e is not None:
                    other = e[(e.imag > 0) & (np.abs(e - where[1]) > 1e-9 * scale)]
                    if other.size:
                        w2 = other[np.argmin(np.abs(other.real))]
                        detail += f" (omega2 = {w2.imag:.9g} rad/s)"
            special("HH", where, detail)
    for end, r, branch in ((end_b, raw[0], bwd), (end_f, raw[-1], fwd)):
        if end == "Bogdanov-Takens":
            bt = _bt_ahead(start, branch, scale)
            if bt is not None and r.lam.imag >= 0.01 * scale:
                special("BT", bt, f"omega -> 0 ahead of the last converged point (omega = {r.lam.imag:.3g} rad/s "
                                  "there): omega^2, quadratic in arclength over the last points, extrapolated to 0")
            else:
                special("BT", (r.u, r.lam), "omega -> 0 at the end of the curve (last point converged)")
    points = []
    for r, (l1, err, crit, msg) in zip(raw, vals):
        xv, yv = fld.values(r.u)
        lams = fld.eig(r.u)
        resid = abs(r.lam.real) / abs(r.lam)
        if lams is not None:
            resid = abs(fld.track(r.u, r.lam).real) / abs(r.lam)  # type: ignore[union-attr]
        points.append(CurvePoint(xv, yv, r.lam.imag, l1, err, crit, resid, msg))
    return HopfCurve(x.name, y.name, tuple(points), tuple(specials), (end_b, end_f))
