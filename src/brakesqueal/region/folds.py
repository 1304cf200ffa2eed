"""Fold-of-cycles curves from the generalised-Hopf points of a region diagram (issue 28 item 2).

At a generalised-Hopf (Bautin) point ``GH`` of a Hopf curve ``l1`` changes sign; a curve of folds of cycles
(``LPC``) is born there, tangent to the Hopf curve, on its subcritical side: between the fold and the
subcritical Hopf curve the silent motion is linearly stable while a limit cycle coexists with it ("squeal
possible although linearly stable").

:func:`fold_curves` computes that curve by slices: at a few values of one axis (the *stepping* axis, the one
along which the Hopf curve runs at the GH point), stepping away from GH on the subcritical side at offsets
growing geometrically, it continues the one-parameter cycle branch from the slice's subcritical Hopf point
along the other axis (:func:`brakesqueal.nonlinear.models.limit_cycles`, the route rule of ``brakesqueal
cycles``: shooting, or harmonic balance where the pads require it; where the shooting cannot start next to
the degenerate Hopf point, harmonic balance with the exact pads, recorded in ``route``) and records

* the fold of the branch (a turning point of the parameter along the branch) before any contact loss
  (``kind = "LPC"``), or
* where no fold comes first, the located contact loss (``kind = "contact_loss"``, ``contact_lost = True``):
  the bilateral equations no longer describe the brake beyond it, so the fold, if any, is not computed.

With ``contact="bilateral"`` a slice whose branch loses contact first is followed on through the (ignored) contact
loss to the fold of the smooth bilateral equations, which is what AUTO-07p and other continuation tools compute
(they know nothing of contact loss): shooting from the branch's last orbit, the parameter's scale growing with the
distance covered, to the first turning point (``kind = "LPC_bilateral"``, ``contact_lost = True`` and
``contact_loss`` where the pads would have lifted off).  On the brake models that fold lies orders of magnitude
beyond the contact loss (Fig. 3's set: 600 to 7500 times farther from the Hopf point), and the first folds of
neighbouring slices need not lie on one fold-of-cycles curve (AUTO's two-parameter continuation of one slice's
fold passes other slices at other folds), so the polygons between slices are a sketch there.

Each slice's branch is computed with the slice's only stability crossing inside its range (the range runs
from the previous to the next crossing along the slice, or the box's edges), so the library's "first Hopf point
in the range" is the subcritical one.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import BrakesquealError

if TYPE_CHECKING:
    from ..analysis.maps import Axis
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace
    from .curves import HopfCurve

__all__ = ["FoldPoint", "FoldCurve", "fold_curves", "FOLD_KINDS"]

#: Kinds of the points of a fold-of-cycles curve.
FOLD_KINDS: dict[str, str] = {
    "GH": "the generalised-Hopf point where the curve is born (amplitude 0)",
    "LPC": "fold of cycles: a turning point of the slice's cycle branch, every pad in contact",
    "contact_loss": "the slice's cycle branch loses contact before any fold (the fold is not computed: the "
                    "bilateral equations do not hold beyond)",
    "LPC_bilateral": "fold of cycles of the bilateral equations beyond the slice's contact loss (contact = "
                     "'bilateral'): the pads would have lifted off before it (at contact_loss), so it is a fold of "
                     "the smooth model, not of the brake",
}


@dataclass(frozen=True)
class FoldPoint:
    """One point of a fold-of-cycles curve.

    Attributes
    ----------
    x, y : float
        Where the fold (or the contact loss) is (the axes' SI units).
    kind : str
        A key of :data:`FOLD_KINDS`.
    hopf : float
        The slice's subcritical Hopf point (value of the slice's axis): the region between it and the point is
        where a cycle coexists with the linearly stable silent motion.
    amplitude : dict
        First-harmonic amplitude of each displacement coordinate at the point (SI units; harmonic balance also
        gives the pads' deformations); empty at the GH point.
    period : float
        Period of the cycle there [s].
    route : str
        ``"shooting"``, ``"harmonic balance"`` or ``"normal form"`` (the GH point).
    contact_lost : bool
        The branch lost contact before folding.
    message : str
        How the route was chosen, when not by the rule of ``cycles``.
    contact_loss : float or None
        Where the slice's branch loses contact (value of the slice's axis ``along``), when it does before the
        point (``kind = "contact_loss"`` or ``"LPC_bilateral"``).
    """

    x: float
    y: float
    kind: str
    hopf: float
    amplitude: dict[str, float]
    period: float
    route: str
    contact_lost: bool
    message: str = ""
    contact_loss: float | None = None


@dataclass(frozen=True)
class FoldCurve:
    """The fold-of-cycles curve born at one generalised-Hopf point.

    Attributes
    ----------
    curve : int
        Index of the Hopf curve carrying the GH point.
    gh : tuple of float
        The GH point ``(x, y)``.
    along : str
        The name of the axis each slice's branch is continued along (the other axis steps away from GH).
    axis : str
        ``"x"`` or ``"y"``: which of the region's axes ``along`` is.
    points : tuple of FoldPoint
        The GH point, then one point per slice in order of distance from GH.
    notes : tuple of str
        Slices without a point and why.
    path : tuple of (float, float)
        The subcritical stretch of the Hopf curve sliced (GH first), for the regions' near side.
    """

    curve: int
    gh: tuple[float, float]
    along: str
    axis: str
    points: tuple[FoldPoint, ...]
    notes: tuple[str, ...] = field(default=())
    path: tuple[tuple[float, float], ...] = field(default=(), repr=False)

    def regions(self, kind: str) -> list[list[tuple[float, float]]]:
        """Polygons ``[(x, y), ...]`` between the subcritical Hopf curve and the points of ``kind``.

        ``kind = "LPC"``: "squeal possible although linearly stable" (runs of slices with a fold, from the GH
        point); ``"contact_loss"``: "contact lost" (runs of slices whose branch lost contact before folding,
        from the point before the run).  The near side follows the Hopf curve (:attr:`path`); the far side is
        the Hopf curve shifted along :attr:`along` by the slices' distances, interpolated linearly between the
        slices.

        Parameters
        ----------
        kind : {"LPC", "contact_loss", "LPC_bilateral"}

        Returns
        -------
        list of list of (float, float)
        """
        k = 0 if self.axis == "y" else 1  # index of the stepping coordinate in (x, y)
        pts = list(self.points)
        out: list[list[tuple[float, float]]] = []
        i = 1
        while i < len(pts):
            if pts[i].kind != kind:
                i += 1
                continue
            j = i
            while j < len(pts) and pts[j].kind == kind:
                j += 1
            run = pts[i - 1:j] if (kind == "contact_loss" or pts[i - 1].kind == "GH") else pts[i:j]
            out.append(self._polygon(run, k))
            i = j
        return out

    def _polygon(self, run: list[FoldPoint], k: int) -> list[tuple[float, float]]:
        sv = np.array([(q.x, q.y)[k] for q in run])
        gap = np.array([(q.x, q.y)[1 - k] - q.hopf for q in run])
        lo, hi = float(sv.min()), float(sv.max())
        path = [(float(a), float(b)) for a, b in self.path if lo < (a, b)[k] < hi]
        near = [((q.x, q.y)[k], q.hopf) for q in run] + [((a, b)[k], (a, b)[1 - k]) for a, b in path]
        near.sort(key=lambda t: t[0])
        order = np.argsort(sv)
        far = [(s, h + float(np.interp(s, sv[order], gap[order]))) for s, h in near]
        ring = near + far[::-1]
        return [(s, h) if k == 0 else (h, s) for s, h in ring]


def _unit(ax: Axis, v: float) -> float:
    if ax.log:
        return (math.log10(v) - math.log10(ax.start)) / (math.log10(ax.stop) - math.log10(ax.start))
    return (v - ax.start) / (ax.stop - ax.start)


def _value(ax: Axis, u: float) -> float:
    if ax.log:
        return float(10 ** (math.log10(ax.start) + u * (math.log10(ax.stop) - math.log10(ax.start))))
    return float(ax.start + u * (ax.stop - ax.start))


def _subcritical_path(c: HopfCurve, x: Axis, y: Axis, gx: float, gy: float) -> np.ndarray | None:
    """The curve's points in the unit box from the GH point along its subcritical side (GH first)."""
    u = np.array([[_unit(x, p.x), _unit(y, p.y)] for p in c.points])
    g = np.array([_unit(x, gx), _unit(y, gy)])
    k = int(np.argmin(np.linalg.norm(u - g, axis=1)))
    crit = [p.criticality for p in c.points]
    for step in (1, -1):
        idx = []
        i = k
        while 0 <= i < len(u):
            if crit[i] == "subcritical":
                idx.append(i)
            elif idx:
                break
            i += step
            if not idx and abs(i - k) > 2:
                break
        if len(idx) >= 2:
            return np.vstack([g, u[idx]])
    return None


def _branch_point(b: Any) -> tuple[str, float, dict[str, float], float] | None:
    """(kind, parameter value, amplitude of the displacements, period) of a branch's first fold before contact
    loss, else of its contact loss; ``None`` when it has neither."""
    if hasattr(b, "points") and hasattr(b, "folds"):  # harmonic balance
        pts = list(b.points)
        valid = b.valid
        ps = np.array([b.hopf.hopf.p0] + [pt.p for pt in pts])
        for f in b.folds:
            i = int(np.argmin(np.abs(ps[1:] - f)))
            if valid[i]:
                pt = pts[i]
                return "LPC", float(f), dict(pt.amplitude), 2 * math.pi / pt.omega
        if b.contact_loss is not None:
            i = max([j for j, ok in enumerate(valid) if ok], default=len(pts) - 1)
            pt = pts[i]
            return "contact_loss", float(b.contact_loss), dict(pt.amplitude), 2 * math.pi / pt.omega
        return None
    ds = b.data
    coords = [str(c) for c in ds["coord"].values]
    disp = [j for j, c in enumerate(coords) if not (c.startswith("d") and c[1:] in coords)]
    amp = ds["amplitude"].values
    ok = ds["in_contact"].values
    for kind, idx, pv in zip(ds["special_kind"].values, ds["special_index"].values, ds["special_p"].values):
        if str(kind) == "LPC" and bool(ok[int(idx)]):
            i = int(idx)
            return "LPC", float(pv), {coords[j]: float(amp[i, j]) for j in disp}, float(ds["period"].values[i])
    if b.contact_loss is not None:
        last = int(np.flatnonzero(ok)[-1]) if ok.any() else 0
        return ("contact_loss", float(b.contact_loss), {coords[j]: float(amp[last, j]) for j in disp},
                float(ds["period"].values[last]))
    return None


def _first_lpc(ds: Any) -> tuple[int, float, dict[str, float], float] | None:
    """(index, parameter, first-harmonic amplitude of the displacements, period) of a shooting branch's first fold
    of cycles (any contact), else ``None``."""
    coords = [str(c) for c in ds["coord"].values]
    disp = [j for j, c in enumerate(coords) if not (c.startswith("d") and c[1:] in coords)]
    amp = ds["amplitude"].values
    for kind, idx, pv in zip(ds["special_kind"].values, ds["special_index"].values, ds["special_p"].values):
        if str(kind) == "LPC":
            i = int(idx)
            return i, float(pv), {coords[j]: float(amp[i, j]) for j in disp}, float(ds["period"].values[i])
    return None


def _bilateral_fold(engine: Engine, space: ParameterSpace, ax: Axis, b: Any, h: float, passes: int = 6,
                    points_per_pass: int = 40) -> tuple[float, dict[str, float], float, str]:
    """The first fold of cycles of the bilateral (smooth) equations on a slice's branch ``b`` past its contact
    loss: the branch's own when it has one, else a shooting continuation of the smooth system from the branch's
    last orbit, restarted with the parameter's scale set to the distance covered from the Hopf point ``h`` (so the
    steps grow geometrically out to a fold far beyond the contact loss).  Returns ``(parameter, amplitude,
    period, how)``; raises :class:`BrakesquealError` when no fold is found in the slice's range."""
    from ..nonlinear.continuation import continue_cycles
    from ..nonlinear.models import model_system
    from ..nonlinear.periodic import ShootingError, find_periodic_orbit

    system = model_system(engine, space, ax.name)
    if hasattr(b, "points") and hasattr(b, "folds"):  # harmonic balance: shoot its last orbit
        from ..nonlinear.harmonic import shooting_flow

        for f in b.folds:
            pts = list(b.points)
            i = int(np.argmin([abs(pt.p - f) for pt in pts]))
            return float(f), dict(pts[i].amplitude), 2 * math.pi / pts[i].omega, "harmonic balance"
        chk = shooting_flow(engine, space, ax, tuple(b.coords), True)
        if chk is None:
            raise BrakesquealError("the bilateral fold needs shooting, which these pads do not allow")
        pt = list(b.points)[-1]
        x0, _sc = chk.state(pt.coefficients, pt.omega)
        try:
            orbit = find_periodic_orbit(system, x0, period=2 * math.pi / pt.omega, p=float(pt.p))
        except ShootingError as exc:
            raise BrakesquealError(f"shooting the harmonic-balance orbit at {ax.name} = {pt.p:.10g} failed: "
                                   f"{exc}") from None
    else:
        r = _first_lpc(b.data)
        if r is not None:
            return r[1], r[2], r[3], "shooting"
        orbit = b.branch.orbits[-1]
    lo, hi = ax.start, ax.stop
    for _ in range(passes):
        d = abs(float(orbit.p) - h)
        direction = 1 if float(orbit.p) > h else -1
        br = None
        # tol 1e-7 (then 1e-6): a state with a large mean (the disk's rate) keeps the shooting's scaled update
        # above 1e-8 at these small amplitudes
        for tol in (1e-7, 1e-6):
            try:
                br = continue_cycles(system, orbit, (lo, hi), direction=direction, p_scale=20 * d, ds_max=1.0,
                                     max_points=points_per_pass, detect=("LPC",), tol=tol)
                break
            except (ShootingError, BrakesquealError) as exc:
                err = exc
        if br is None:
            raise BrakesquealError(f"the bilateral continuation from {ax.name} = {float(orbit.p):.10g} failed: "
                                   f"{err}")
        r = _first_lpc(br.data)
        if r is not None:
            return r[1], r[2], r[3], "shooting"
        if br.status != "max_points" or len(br.orbits) < 2:
            raise BrakesquealError(f"the bilateral branch ended ({br.message}) before a fold")
        orbit = br.orbits[-1]
    raise BrakesquealError(f"no bilateral fold within {passes * points_per_pass} continuation steps past "
                           f"{ax.name} = {float(orbit.p):.10g}")


def _slice_point(engine: Engine, space: ParameterSpace, ax: Axis, h: float, max_branch_points: int,
                 contact: str) -> tuple[str, float, dict[str, float], float, str, str, float | None]:
    """One slice's point: ``(kind, parameter, amplitude, period, route, message, contact loss)`` from the cycle
    branch of the Hopf point ``h``, the only stability crossing in ``ax`` (raises :class:`BrakesquealError` when
    the branch ends before a fold or a contact loss)."""
    from ..nonlinear.models import limit_cycles

    msg = ""
    # the route of `cycles` (limit_cycles owns it, including its fallback to harmonic balance where the shooting
    # cannot start: the branch's own `route` and `message` say which ran)
    b = limit_cycles(engine, space, ax, max_points=max_branch_points)
    route = str(b.to_dict()["route"])
    r = _branch_point(b)
    if route == "harmonic balance" and str(b.message).startswith("shooting did not converge"):
        msg = str(b.message)
    if r is None and route == "shooting":
        msg = (f"the shooting branch ended ({b.to_dict()['message']}) before a fold or a contact loss; harmonic "
               "balance with the exact pads")
        route = "harmonic balance"
        b = limit_cycles(engine, space, ax, pads="exact", max_points=max_branch_points)
        r = _branch_point(b)
    if r is None:
        raise BrakesquealError(f"the branch from {ax.name} = {h:.10g} ended ({b.to_dict()['message']}) before a "
                               "fold or a contact loss")
    kind, pv, amp, period = r
    loss = pv if kind == "contact_loss" else None
    if loss is not None and contact == "bilateral":
        pv, amp, period, how = _bilateral_fold(engine, space, ax, b, h)
        kind = "LPC_bilateral"
        msg = "; ".join(m for m in (msg, f"the pads lift off at {ax.name} = {loss:.10g}; fold of the bilateral "
                                    f"equations ({how})") if m)
        route = how
    return kind, pv, amp, period, route, msg, loss


def _slice_range(engine: Engine, space: ParameterSpace, ax: Axis, h_est: float) -> tuple[float, float, float] | None:
    """The slice's crossing nearest ``h_est`` and a range holding it alone (previous/next crossing or the box)."""
    from ..analysis.crossings import crossings

    r = crossings(engine, space, ax)
    vals = sorted(float(v) for v, _d in r.crossings)
    if not vals:
        return None
    j = int(np.argmin([abs(_unit(ax, v) - _unit(ax, h_est)) for v in vals]))
    h = vals[j]
    lo = ax.start if j == 0 else vals[j - 1] + 1e-6 * (h - vals[j - 1])
    hi = ax.stop if j == len(vals) - 1 else vals[j + 1] - 1e-6 * (vals[j + 1] - h)
    return h, lo, hi


def fold_curves(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, curves: list[HopfCurve], *,
                points: int = 6, max_branch_points: int = 60, contact: str = "stop",
                progress: Callable[[float], None] | None = None) -> tuple[list[FoldCurve], list[str]]:
    """The fold-of-cycles curve of every generalised-Hopf point of ``curves`` (see the module's description).

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The model, preset and overrides.
    x, y : Axis
        The region's axes.
    curves : list of HopfCurve
        The Hopf curves (with ``l1``) and their codimension-2 points.
    points : int
        Slices per GH point (each one cycle branch).
    max_branch_points : int
        Largest number of points of each slice's branch.
    contact : {"stop", "bilateral"}
        ``"stop"`` (default): the brake, whose pads lift off: a slice whose branch loses contact before folding
        gives a ``contact_loss`` point.  ``"bilateral"``: the smooth bilateral equations (as AUTO-07p
        and other tools continue them): such a slice is continued through the ignored contact loss to its fold,
        an ``LPC_bilateral`` point (``contact_lost = True``, ``contact_loss`` where the pads would have lifted
        off).
    progress : callable, optional
        ``progress(fraction)`` after each slice.

    Returns
    -------
    (list of FoldCurve, list of str)
        The curves and notes (GH points without a curve and why).
    """
    from ..analysis.maps import Axis as _Axis
    from ..errors import ParameterError

    if contact not in ("stop", "bilateral"):
        raise ParameterError(f"The option 'contact' must be stop or bilateral; got {contact!r}",
                             parameter="contact")

    ghs = [(i, s) for i, c in enumerate(curves) for s in c.special_points if s.type == "GH"]
    out: list[FoldCurve] = []
    notes: list[str] = []
    total = max(len(ghs) * points, 1)
    done = 0
    for ci, s in ghs:
        path = _subcritical_path(curves[ci], x, y, s.x, s.y)
        if path is None:
            notes.append(f"GH point at {x.name} = {s.x:.8g}, {y.name} = {s.y:.8g}: no subcritical stretch of its "
                         "Hopf curve to slice")
            done += points
            continue
        t = path[min(2, len(path) - 1)] - path[0]
        # step along the axis the curve runs along; continue each slice's branch along the other one
        step_i = 0 if abs(t[0]) >= abs(t[1]) else 1
        along = "y" if step_i == 0 else "x"
        sax, bax = (x, y) if step_i == 0 else (y, x)
        sgn = 1.0 if t[step_i] > 0 else -1.0
        sv = path[:, step_i]
        mono = [0]
        for k in range(1, len(sv)):
            if (sv[k] - sv[mono[-1]]) * sgn <= 0:
                break
            mono.append(k)
        seg = path[mono]
        reach = abs(seg[-1, step_i] - seg[0, step_i])
        fpts = [FoldPoint(s.x, s.y, "GH", s.y if along == "y" else s.x, {}, 2 * math.pi / s.omega,
                          "normal form", False)]
        fnotes: list[str] = []
        if reach <= 0:
            notes.append(f"GH point at {x.name} = {s.x:.8g}, {y.name} = {s.y:.8g}: its subcritical stretch does "
                         "not move along either axis")
            done += points
            continue
        # denser next to GH (where the fold is at small amplitude), out to 98 % of the stretch
        offs = [0.98 * reach * ((k + 1) / points) ** 2 for k in range(points)]
        for d in offs:
            us = seg[0, step_i] + sgn * d
            # the Hopf curve's position on this slice (linear interpolation along the monotonic stretch)
            order = np.argsort(seg[:, step_i])
            ub = float(np.interp(us, seg[order, step_i], seg[order, 1 - step_i]))
            v = _value(sax, us)
            h_est = _value(bax, ub)
            sp = space.with_values({sax.name: v})
            where = f"{sax.name} = {v:.8g}"
            try:
                rng = _slice_range(engine, sp, _Axis(bax.name, bax.start, bax.stop, 2, bax.log), h_est)
                if rng is None:
                    raise BrakesquealError("no stability crossing on the slice")
                h, lo, hi = rng
                ax = _Axis(bax.name, lo, hi, 2, bax.log)
                kind, pv, amp, period, route, msg, loss = _slice_point(engine, sp, ax, h, max_branch_points,
                                                                       contact)
                px, py = (v, pv) if step_i == 0 else (pv, v)
                fpts.append(FoldPoint(px, py, kind, h, amp, period, route, kind != "LPC", msg, loss))
            except BrakesquealError as exc:
                fnotes.append(f"slice {where}: {exc}")
            done += 1
            if progress is not None:
                progress(done / total)
        data_path = tuple((_value(x, float(a)), _value(y, float(b))) for a, b in seg)
        out.append(FoldCurve(ci, (s.x, s.y), bax.name, along, tuple(fpts), tuple(fnotes), data_path))
        notes += fnotes
    return out, notes
